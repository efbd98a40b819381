#!/usr/bin/env python3
"""Render Mitsuba 3 reference images of rastergi scenes.

Any scene rastergi renders: the built-in Cornell box (`--scene cornell`, the
default), a Wavefront OBJ + MTL file (`--scene PATH.obj`) or a glTF 2.0 file of
Lambertian materials (`--scene PATH.gltf|.glb`, read by scripts/mitsuba_gltf.py with
its lights and camera; one-sided where the material is not `doubleSided`), seen by rastergi's
camera (or the one given by --eye/--target/--up/--fov), rendered with
Mitsuba's `path` integrator and a box pixel filter, and written as a linear
float32 RGB OpenEXR (3 channels R, G, B, no alpha; row 0 of the image is the
top; PIZ lossless compression) that `rastergi compare` reads.

The scene `cornell` is built here explicitly from the numbers in
cornell-box.md (it is Mitsuba's `mi.cornell_box()` geometry and materials, but
with a box pixel filter and a vertical field of view).

OBJ scenes are read here, not by Mitsuba (whose `obj` loader ignores MTL), the
way rastergi reads them (crates/rastergi/src/scene/obj/mod.rs, through tobj):
`v`, `vn` and `f` lines (`l` lines of three or more vertices count as faces, as in
tobj), relative (negative) indices, polygons triangulated as fans (v0, vi,
vi+1), `mtllib` and `usemtl`; `vt` (read only for faces of a material with `map_d`), `o`,
`g`, `s` and the rest are ignored.
From the MTL, `Kd` is the diffuse reflectance (default 0.5, as for
faces without a material), `Ke` the emitted radiance (a single number means
grey), `d` / `map_d` the opacity (below) and `Pm`, `Pr`, `illum`, `Ks`, `Ni`, `Tf` make
metals and glass (Materials, below); albedo textures (`map_Kd`) are not
reproduced (a warning says so). The
triangles of each material are written to a binary PLY file in a temporary
directory and loaded as a `ply` shape, its BSDF `twosided(diffuse(Kd))` (OBJ
surfaces reflect on both sides in rastergi; metals and glass: Materials, below)
and, where Ke > 0, an `area` emitter,
which Mitsuba makes one-sided: it emits from the front face, the side the
counter-clockwise winding faces (normal (v1-v0) x (v2-v0)), as rastergi does. The
conventions were checked with crates/rastergi/tests/data/obj/emitter_sides.obj: a
CCW quad facing the camera shows its Ke in both renderers, a CW one is black.

Materials: rastergi maps MTL materials to its model as follows, and the script to
Mitsuba BSDFs where Mitsuba can reproduce the model exactly:
- none of `Pm`, `Pr` nor a glass `illum` (4, 6, 7, 9): Lambertian Kd, twosided(diffuse(Kd))
  as ever (such scenes give the same scene, meshes and files as before);
- `Pm m` and/or `Pr r` (each one number in [0, 1]): glTF metallic-roughness, base colour
  Kd, metallic m (default 0), roughness r (default 1), GGX alpha r², and glTF's dielectric
  specular layer (F0 0.04) unless `Ks 0 0 0` (all three zero) removes it; `illum 3`
  without `Pm`: metallic 1, roughness `Pr` (default 0). Mitsuba reproduces these only
  where the base colour is exactly white (Kd 1 1 1, so that the metal's Schlick Fresnel,
  F0 = Kd, is 1 at every angle) and there is no specular layer over a diffuse part:
  metallic 1 -> twosided(`conductor`, material "none": eta 0, k 1, reflectance 1) for
  r = 0, twosided(`roughconductor`, material "none", distribution "ggx", alpha r²,
  sample_visible) for r > 0; 0 < m < 1 with `Ks 0 0 0` -> twosided(`blendbsdf`, weight m,
  bsdf_0 `diffuse` of reflectance 1, bsdf_1 that conductor), i.e. (1 - m)/pi + m GGX(F = 1),
  as rastergi's model is then; metallic 0 with `Ks 0 0 0` is Lambertian Kd. Mitsuba's GGX
  masking-shadowing is the separable Smith G1(wi) G1(wo) (glTF's specification form, not
  the height-correlated one), its microfacet BRDF D G F / (4 cos_i cos_o). A coloured metal
  (metallic > 0, Kd not 1 1 1: Schlick's Fresnel, which no Mitsuba conductor follows) and
  glTF's specular layer over a diffuse part (metallic < 1 without `Ks 0 0 0`: Mitsuba's
  plastic, roughplastic and principled layer differently) are refused with an error
  naming the material, as is a metal that emits (Ke);
- `illum 4`, `6`, `7` or `9`: glass, a refracting solid, of index `Ni` (default 1.5),
  tint `Tf` (default 1 1 1; each in [0, 1]) and roughness `Pr` (default 0; Pm, Kd, Ks are
  ignored): `dielectric` (int_ior Ni, ext_ior 1, specular_transmittance Tf) for r = 0,
  `roughdielectric` (the same, distribution "ggx", alpha r², sample_visible) for r > 0.
  Not two-sided-wrapped (Mitsuba's twosided refuses transmitting BSDFs): the outside,
  ext_ior, is the side of the counter-clockwise front face, so a glass solid must be
  wound outward. Mitsuba's dielectrics use the exact (unpolarised) Fresnel equations, scale
  radiance by 1/eta² when it enters (eta² when it leaves), and multiply by Tf at every
  crossing of the surface (so Tf² through a solid, not an absorption along the path).
  Emitting (Ke) or masked (d < 1, map_d) glass is refused.
Exporters write `Ni`, `Tf` and `Ks` into every material; they are read only where they
matter (Ni and Tf for glass, Ks for the specular layer). `illum` must be a whole number
0..10. Values rastergi would refuse are refused for every material of the libraries; what
Mitsuba cannot reproduce only for materials that faces use.

Opacity (alpha-masked, "cut-out" surfaces): a material with `map_d FILE` (FILE relative to
the .mtl; no texture options) or with `d X`, X < 1 (or, without `d`, `Tr Y`: X = 1 - Y),
gets Mitsuba's `mask` BSDF around its twosided(diffuse(Kd)), with `opacity` a `bitmap`
texture of FILE (`raw: True`: the stored values, no sRGB decoding; the default bilinear
filter and repeat wrap) or the constant X; with both, the image's values times X (one
in-memory bitmap; bilinear interpolation commutes with the factor). The image must have one
grey channel (which channel of a colour image is the opacity is not settled here); a masked
material may not emit (Ke), and its faces must give `vt` at every corner. The `vt` (u, v)
of OBJ, v pointing up the image (v = 0 its bottom row), go to the PLY as (u, 1 - v):
Mitsuba's PLY loader keeps u, v as they are and its bitmap puts v = 0 on the image's top
row (Mitsuba's own OBJ loader flips v the same way, its `flip_tex_coords` defaulting to
true); checked by experiment, see crates/rastergi/tests/data/README.md ("An alpha-masked
card"). The mask is stochastic: a ray that meets the surface passes straight on, unchanged
and uncounted as a bounce, with probability 1 - opacity, and otherwise meets the nested
BSDF. Scenes with a masked material are rendered with `volpath` instead of `path` (printed
as the integrator): Mitsuba's `path` traces shadow rays with scene.ray_test, for which a
mask surface is opaque whatever its opacity (a point light would never shine through a
hole), while `volpath`'s shadow rays cross null surfaces and take 1 - opacity as their
transmittance there (deterministically). Without media the two integrators are otherwise
the same estimator; scenes without masks still use `path` and give the same files as
before.

Normals: faces without normal indices (`f v` or `f v/vt`) are flat: their PLY has
positions only and is loaded with `face_normals: True`. Faces whose every corner
names a `vn` (`f v//vn` or `f v/vt/vn`) are smooth: each corner gets its own PLY
vertex (three per triangle) carrying its `vn`, normalised as read, as nx, ny, nz,
and the shape is loaded with `face_normals: False`, so that Mitsuba interpolates
the three corner normals barycentrically (and renormalises) as the shading normal;
the geometric normal stays the face's. A material with both kinds of faces becomes
two shapes. A face naming a `vn` for only some corners, a `vn` index out of range,
or a `vn` of zero length or with non-numbers, when a face uses it, is an error.
Emitting materials (Ke > 0) keep face normals even where their faces give `vn`:
Mitsuba's `area` emitter would take its side and the density of its samples from
the shading normal, no longer the winding's front. How Mitsuba shades with these
normals (it neither flips nor bends a shading normal that faces away from the
viewer; the facets' own shadows cut the light at their terminator): docs/references.md.

Camera: as in rastergi, the built-in Cornell box has its own camera and an
OBJ file is framed by rastergi's default camera (Scene::framing_camera): it
looks at the centre of the triangles' bounds from +z, at a distance
radius / sin(fov/2) with radius half the bounds' diagonal, up +y, vertical
fov 45 degrees. --eye, --target, --up and --fov (vertical, degrees) replace
the corresponding parts, exactly as `rastergi render` does; give the same
values to both. The near clip is 1e-4 of the bounds' diagonal (rastergi's;
0.001 for the Cornell box, as the committed references were made).

Extra lights, added to either scene: --point x,y,z,r,g,b (repeatable) is a `point` emitter
of that intensity (W/sr, a glTF point light in rastergi); --sun AZ,EL,IRR is a
`directional` emitter of irradiance IRR (W/m^2) from azimuth AZ and elevation EL in
degrees, as rastergi's --sun with --sun-size 0 (a delta direction); --spot
x,y,z,tx,ty,tz,r,g,b,ANGLE (repeatable) is a `spot` emitter at x,y,z aimed at the point
tx,ty,tz, of radiant intensity r,g,b on its axis (W/sr, a glTF spot light's color x
intensity), with a HARD cone of half-angle ANGLE degrees: cutoff_angle = beam_width = ANGLE,
which Mitsuba's spot accepts and turns into a step (full intensity for theta <= ANGLE, 0
beyond). Mitsuba cannot reproduce glTF's smooth falloff between an inner and an outer cone;
give rastergi's spot inner = outer = ANGLE (its falloff then ramps over 1e-3 in cos theta
just inside the edge, about 0.14 degrees at 25); --env FILE (an .exr or .hdr latitude-longitude image, linear
radiance) is an `envmap` emitter
{"filename": FILE, "scale": --env-scale (default 1)} with no to_world transform (the
identity). That is the convention for rastergi's environment maps too: direction
d = (x, y, z) <-> u = atan2(x, -z) / 2pi, v = acos(y) / pi, image row 0 at the zenith +Y;
Mitsuba puts column i of a W x H image at u = (i + 0.5) / W and row j at v = j / (H - 1)
(the first and last rows on the poles) and interpolates bilinearly between these
positions, periodically in u, so one bright pixel is a small extended source with a tent
profile two pixels wide (scripts/make_test_sky.py). Rays that leave the scene see the map.

Make a reference for an OBJ scene and compare a rastergi render with it:

    python3 scripts/mitsuba_reference.py --scene room.obj --width 128 --height 128 --spp 4096 --out room_ref.exr
    rastergi render room.obj --width 128 --height 128 --iterations 1024 --out room.exr
    rastergi compare room.exr room_ref.exr --mask-emitters --diff room_diff.png

Setup (Debian 12, Python 3):

    pip install mitsuba numpy          # tested with mitsuba 3.9.1, drjit 1.5.0
    apt-get install -y libllvm19       # for the llvm_ad_rgb variant; without
                                       # it use --variant scalar_rgb (slower)
    # if Dr.Jit cannot find LLVM:
    #   export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so

Regenerate every committed reference (crates/rastergi/tests/data/), from the
repository root. On a 2-core machine with llvm_ad_rgb a direct-lighting render
takes about 1.5 minutes and a full path-traced one about 2.7 minutes:

    D=crates/rastergi/tests/data
    # pair NAME SEED OPTIONS...: $D/NAME_a.exr with --seed SEED, $D/NAME_b.exr with SEED + 1
    pair() {
        name=$1 seed=$2; shift 2
        python3 scripts/mitsuba_reference.py "$@" --seed $seed --out $D/${name}_a.exr
        python3 scripts/mitsuba_reference.py "$@" --seed $((seed + 1)) --out $D/${name}_b.exr
    }
    pair cornell_direct_128 1 --width 128 --height 128 --spp 32768 --max-depth 2
    pair cornell_path_128   3 --width 128 --height 128 --spp 16384 --max-depth -1
    # the courtyard under the test sky (environment map only; README.md there)
    python3 scripts/make_test_sky.py --out $D/env/sky_64x32.exr
    COURT="--scene $D/obj/courtyard.obj --eye 0,3,5.5 --target 0,0.3,0 --up 0,1,0 --fov 45 --env $D/env/sky_64x32.exr --width 128 --height 128 --spp 4096"
    pair courtyard_env_path_128   11 $COURT --max-depth -1
    pair courtyard_env_direct_128 13 $COURT --max-depth 2
    # smooth (vn) and flat shading normals under the test sky (README.md there)
    python3 scripts/make_sphere_scenes.py
    SPH="--eye 0,1.6,3.2 --target 0,0.6,0 --up 0,1,0 --fov 40 --env $D/env/sky_64x32.exr --width 128 --height 128 --spp 4096 --max-depth -1"
    pair sphere_smooth_path_128 21 --scene $D/obj/sphere_smooth.obj $SPH
    pair sphere_flat_path_128   23 --scene $D/obj/sphere_flat.obj $SPH
    # an alpha-masked card and a 50 % veil under a point light (README.md there)
    python3 scripts/make_alpha_card_scene.py
    CARD="--scene $D/obj/alpha_card.obj --eye 0,2.6,2.4 --target 0,0.35,0 --up 0,1,0 --fov 45 --point 0.15,2.2,0.1,6,6,6 --width 128 --height 128 --spp 4096 --max-depth -1"
    pair alpha_card_path_128 31 $CARD
    # metal and glass: a sphere on a stage in five materials, and the Cornell box with a
    # glass and a mirror sphere (README.md there; about 15-60 s per render)
    python3 scripts/make_material_scenes.py
    MAT="--eye 0,1.2,2.6 --target 0,0.45,0 --up 0,1,0 --fov 40 --width 64 --height 64 --spp 16384 --max-depth -1"
    s=41  # seeds 41, 43, ..., 49
    for m in metal_rough mirror mix glass rough_glass; do
        pair mat_${m}_path_64 $s --scene $D/obj/mat_$m.obj $MAT
        s=$((s + 2))
    done
    CS="--scene $D/obj/cornell_spheres.obj --eye 0,0,3.9 --target 0,0,0 --up 0,1,0 --fov 39.3077 --width 128 --height 128 --spp 8192 --max-depth -1"
    pair cornell_spheres_path_128 51 $CS

(--chunk-spp defaults to 256; the images depend on it through the chunk seeds,
and on the Mitsuba version and variant. Results are not bit-reproducible
across versions, only statistically.)

The two files of a pair use different seeds, so they are independent
estimates; RMSE(a, b) / 2 is the noise of their mean.

Other commands:

    python3 scripts/mitsuba_reference.py --check-scene    # compare cornell with mi.cornell_box()
    python3 scripts/mitsuba_reference.py --stats A.exr [B.exr]   # mean RGB, rel. RMSE

Depth convention (Mitsuba's): max_depth 1 = only directly visible emitters,
2 = emission + direct lighting, -1 = unlimited (Russian roulette from depth 5,
unbiased).

Sampling: the `independent` sampler. --spp is split into chunks of at most
--chunk-spp samples; chunk i is rendered with seed (seed * 1000003 + i) and the
chunks are averaged in linear space (equal weights, since every chunk has the
same spp except possibly the last, which is weighted by its spp). With the box
filter of radius 0.5 every sample lands in exactly one pixel, so the result is
the plain per-pixel mean of the samples.
"""

import argparse
import functools
import math
import os
import sys
import tempfile
import time

import numpy as np

# The scene, in the units of cornell-box.md -----------------------------------

WHITE = [0.885809, 0.698859, 0.666422]
RED = [0.570068, 0.0430135, 0.0443706]
GREEN = [0.105421, 0.37798, 0.076425]
LIGHT_RADIANCE = [18.387, 13.9873, 6.75357]

# Mitsuba's `rectangle` is [-1,1]^2 in the local z = 0 plane, normal +z;
# `cube` is [-1,1]^3 with outward normals. Each transform below is the
# row-major 3x4 matrix [R|t] (world = R * local + t).
#
# Walls: 2 x 2 squares, one-sided, facing into the box.
WALL_MATRICES = {
    # floor y = -1, normal +y: local x -> +x, local y -> -z, local z -> +y
    "floor": [[1, 0, 0, 0], [0, 0, 1, -1], [0, -1, 0, 0]],
    # ceiling y = +1, normal -y: local x -> +x, local y -> +z, local z -> -y
    "ceiling": [[1, 0, 0, 0], [0, 0, -1, 1], [0, 1, 0, 0]],
    # back z = -1, normal +z
    "back": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -1]],
    # left (red) x = -1, normal +x: local x -> -z, local z -> +x
    "red-wall": [[0, 0, 1, -1], [0, 1, 0, 0], [-1, 0, 0, 0]],
    # right (green) x = +1, normal -x: local x -> +z, local z -> -x
    "green-wall": [[0, 0, -1, 1], [0, 1, 0, 0], [1, 0, 0, 0]],
}
WALL_BSDF = {"floor": "white", "ceiling": "white", "back": "white",
             "red-wall": "red", "green-wall": "green"}

# Light: x in [-0.23, 0.23], z in [-0.18, 0.20], y = 0.99, facing -y
# (local x -> 0.23 x, local y -> 0.19 z, local z -> -y; centre (0, 0.99, 0.01)).
LIGHT_MATRIX = [[0.23, 0, 0, 0], [0, 0, -0.19, 0.99], [0, 0.19, 0, 0.01]]

# Boxes, white, exactly as in cornell-box.md.
SMALL_BOX_MATRIX = [[0.28689146, 0, -0.08771151, 0.335],
                    [0, 0.3, 0, -0.7],
                    [0.08771151, 0, 0.28689146, 0.38]]
LARGE_BOX_MATRIX = [[0.28490975, 0, 0.09394914, -0.33],
                    [0, 0.61, 0, -0.4],
                    [-0.09394914, 0, 0.28490975, -0.28]]

CAMERA_EYE = [0, 0, 3.9]
CAMERA_TARGET = [0, 0, 0]
CAMERA_UP = [0, 1, 0]
CAMERA_VFOV_DEG = 39.3077

EMITTER_RED_THRESHOLD = 3.0  # pixels brighter than this in red are the light


def _transform(mi, m34):
    rows = [list(map(float, r)) for r in m34] + [[0.0, 0.0, 0.0, 1.0]]
    return mi.ScalarTransform4f(rows)


CORNELL_CAMERA = {"eye": CAMERA_EYE, "target": CAMERA_TARGET, "up": CAMERA_UP,
                  "fov": CAMERA_VFOV_DEG}


def rgb(v):
    return {"type": "rgb", "value": [float(x) for x in v]}


def sensor_dict(mi, camera, width, height, spp, near_clip, far_clip):
    """rastergi's pinhole camera: vertical fov, box filter, linear RGB film."""
    return {
        "type": "perspective",
        "fov_axis": "y",  # vertical field of view, as rastergi
        "fov": camera["fov"],
        "near_clip": near_clip,
        "far_clip": far_clip,
        "to_world": mi.ScalarTransform4f().look_at(
            origin=camera["eye"], target=camera["target"], up=camera["up"]),
        "sampler": {"type": "independent", "sample_count": int(spp)},
        "film": {
            "type": "hdrfilm",
            "width": int(width),
            "height": int(height),
            "rfilter": {"type": "box"},
            "pixel_format": "rgb",
            "component_format": "float32",
        },
    }


def far_clip_for(camera, lo, hi):
    """A far clip beyond every point of the bounds [lo, hi] (at least 100)."""
    eye = np.asarray(camera["eye"], dtype=np.float64)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])], dtype=np.float64)
    return float(max(100.0, 2.0 * np.linalg.norm(corners - eye, axis=1).max()))


def cornell_scene_dict(mi, width, height, max_depth, spp=1, camera=None):
    """The built-in `cornell` scene as a Mitsuba scene dict."""
    camera = camera or CORNELL_CAMERA

    def ref(name):
        return {"type": "ref", "id": name}

    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": int(max_depth)},
        "sensor": sensor_dict(mi, camera, width, height, spp, 0.001,
                              far_clip_for(camera, [-1, -1, -1], [1, 1, 1])),
        "white": {"type": "diffuse", "reflectance": rgb(WHITE)},
        "red": {"type": "diffuse", "reflectance": rgb(RED)},
        "green": {"type": "diffuse", "reflectance": rgb(GREEN)},
        "light": {
            "type": "rectangle",
            "to_world": _transform(mi, LIGHT_MATRIX),
            "bsdf": ref("white"),
            "emitter": {"type": "area", "radiance": rgb(LIGHT_RADIANCE)},
        },
    }
    for name, m in WALL_MATRICES.items():
        scene[name] = {"type": "rectangle", "to_world": _transform(mi, m),
                       "bsdf": ref(WALL_BSDF[name])}
    scene["small-box"] = {"type": "cube",
                          "to_world": _transform(mi, SMALL_BOX_MATRIX),
                          "bsdf": ref("white")}
    scene["large-box"] = {"type": "cube",
                          "to_world": _transform(mi, LARGE_BOX_MATRIX),
                          "bsdf": ref("white")}
    return scene


# OBJ + MTL scenes, read as rastergi reads them ------------------------------

OBJ_DEFAULT_ALBEDO = 0.5  # faces without a material, materials without Kd


class SceneError(Exception):
    pass


def _rest_of_line(line, keyword_len):
    return line[keyword_len:].strip()


def _colour(words, path, n):
    """`Kd r g b` or `Kd v` (grey), as rastergi completes it for tobj."""
    vals = words[1:]
    if len(vals) == 1:
        vals = vals * 3
    if len(vals) < 3:
        raise SceneError(f"{path}: line {n}: '{words[0]}' needs three numbers (r g b) or one")
    try:
        return [float(np.float32(v)) for v in vals[:3]]
    except ValueError:
        raise SceneError(f"{path}: line {n}: '{words[0]}' holds something other than numbers")


def _unit_number(words, path, n):
    """`Pm X` or `Pr X`: one number in [0, 1]."""
    try:
        v = float(np.float32(words[1])) if len(words) == 2 else None
    except ValueError:
        v = None
    if v is None or not (math.isfinite(v) and 0 <= v <= 1):
        raise SceneError(f"{path}: line {n}: '{words[0]}' needs one number between 0 and 1")
    return v


def _deferred_numbers(line, path):
    """The line number and numbers (rounded to float32, as floats) of an OBJ line kept as
    (line number, words) to be read where it is used; a SceneError naming its keyword if a
    word after the keyword is not a number."""
    ln, words = line
    try:
        return ln, [float(np.float32(w)) for w in words[1:]]
    except ValueError:
        raise SceneError(f"{path}: line {ln}: a '{words[0]}' line does not hold numbers")


def _obj_index(word, count, where, not_a_number, missing):
    """The 0-based index into a list of `count` entries that a face corner's OBJ index `word`
    names: 1-based when positive, counted back from the end when negative. Raises SceneError
    "`where`: `not_a_number`" when `word` is not an integer and "`where`: `missing`" when the
    entry does not exist (0 included)."""
    try:
        i = int(word)
    except ValueError:
        raise SceneError(f"{where}: {not_a_number}")
    i = i - 1 if i > 0 else count + i
    if not 0 <= i < count:
        raise SceneError(f"{where}: {missing}")
    return i


def load_mtl(path):
    """Materials of an MTL file: name -> {"kd": [r,g,b] or None, "ke": [r,g,b] or None,
    "d": opacity in [0, 1] or None, "map_d": absolute path of the opacity image or None,
    "pm": metallic in [0, 1] or None, "pr": roughness in [0, 1] or None, "illum": the
    illumination model (an integer 0..10) or None, and "ks", "ni", "tf": None or the
    (path, line number, words) of the line, parsed by material_model only where they
    matter (Ks for the dielectric specular layer, Ni and Tf for glass), so that the values
    exporters write into every material (`Ni 1.45`, `Tf 1 1 1`, `Ks 0.5 0.5 0.5`) stay
    harmless where they do not}."""
    try:
        text = open(path, encoding="utf-8").read()
    except (OSError, UnicodeDecodeError) as e:
        raise SceneError(f"{path}: the material library (mtllib) cannot be read: "
                         f"{getattr(e, 'strerror', None) or e}")
    materials, current = {}, None
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        words = line.split()
        if not words:
            continue
        if words[0] == "newmtl":
            name = _rest_of_line(line, 6)
            if not name:
                raise SceneError(f"{path}: line {n}: 'newmtl' names no material")
            current = materials[name] = {"kd": None, "ke": None, "d": None, "tr": None,
                                         "map_d": None, "pm": None, "pr": None,
                                         "illum": None, "ks": None, "ni": None, "tf": None}
        elif words[0] in ("Kd", "Ke") and current is not None:
            current[words[0].lower()] = _colour(words, path, n)
        elif words[0] in ("Pm", "Pr") and current is not None:
            # glTF metallic-roughness (module docstring, "Materials").
            current[words[0].lower()] = _unit_number(words, path, n)
        elif words[0] == "illum" and current is not None:
            try:
                illum = int(words[1]) if len(words) == 2 else None
            except ValueError:
                illum = None
            if illum is None or not 0 <= illum <= 10:
                raise SceneError(f"{path}: line {n}: 'illum' needs one whole number from 0 "
                                 "to 10")
            current["illum"] = illum
        elif words[0] in ("Ks", "Ni", "Tf") and current is not None:
            current[words[0].lower()] = (path, n, words)
        elif words[0] in ("d", "Tr") and current is not None:
            # Dissolve: the opacity, 1 solid, 0 invisible (a mask BSDF; module docstring);
            # `Tr` is its complement, used where `d` is absent (as rastergi reads them).
            try:
                d = float(np.float32(words[1])) if len(words) == 2 else None
            except ValueError:
                d = None
            if d is None or not (math.isfinite(d) and 0 <= d <= 1):
                raise SceneError(f"{path}: line {n}: '{words[0]}' needs one number between 0 "
                                 "and 1")
            current["d" if words[0] == "d" else "tr"] = d
        elif words[0] == "map_d" and current is not None:
            # An opacity image, relative to the .mtl file (a mask BSDF; module docstring).
            name = _rest_of_line(line, 5)
            if not name:
                raise SceneError(f"{path}: line {n}: 'map_d' names no file")
            if name.startswith("-"):
                raise SceneError(f"{path}: line {n}: map_d options ({name.split()[0]} ...) "
                                 "are not supported here; give the file name alone")
            current["map_d"] = os.path.abspath(os.path.join(os.path.dirname(path), name))
        elif words[0] == "map_Kd" and current is not None:
            # Albedo textures are not reproduced here (see the module docstring).
            print(f"warning: {path}: line {n}: map_Kd is ignored; the reference uses Kd "
                  "alone and differs from rastergi where the texture shows", file=sys.stderr)
    for m in materials.values():
        tr = m.pop("tr")
        if m["d"] is None and tr is not None:
            m["d"] = float(np.float32(1.0 - tr))
    return materials


def load_obj(path):
    """The triangles of an OBJ file grouped by material, as rastergi loads them.

    Returns a list of (material, triangles, normals, uvs): material is {"name", "kd", "ke",
    "d", "map_d", "model"} (model: material_model's), triangles a float32 array (n, 3, 3)
    of counter-clockwise corners, normals None (the faces give no `vn`: face normals) or a
    float32 array (n, 3, 3) of the corners' unit vertex normals, uvs None (the material has no `map_d`; `vt` is not read) or a
    float32 array (n, 3, 2) of the corners' `vt` (u, v) as written in the file (OBJ
    convention, v up the image). A material whose faces are partly with and partly without
    `vn` comes as two entries (in the order of their first faces in the file).
    """
    try:
        text = open(path, encoding="utf-8").read()
    except (OSError, UnicodeDecodeError) as e:
        raise SceneError(f"{path}: cannot be read: {e}")
    directory = os.path.dirname(path)
    positions = []
    normals = []  # `vn` lines: (line number, words); parsed where a face uses them
    texcoords = []  # `vt` lines: (line number, words); parsed where a masked face uses them
    library = {}  # material name -> material, from the mtllib lines so far
    # (material name (None: no material), with vertex normals) -> list of corner triples,
    # each corner (position index, normal index or None, texture coordinate index or None;
    # read only for materials with map_d)
    groups = {}
    current = None

    # Parsed once, where a face first uses them (functools.cache: an error is not cached).
    @functools.cache
    def unit_normal(j):
        """The `vn` line j, normalised (float32, as read); an error if it is not a normal."""
        ln, vals = _deferred_numbers(normals[j], path)
        if len(vals) != 3:
            raise SceneError(f"{path}: line {ln}: a 'vn' line needs three numbers x y z")
        v = np.array(vals, dtype=np.float64)
        length = float(np.sqrt(v @ v))
        if not (np.isfinite(v).all() and length > 0):
            raise SceneError(f"{path}: line {ln}: a 'vn' normal used by a face is zero "
                             "or not finite")
        return (v / length).astype(np.float32)

    @functools.cache
    def texcoord(j):
        """The `vt` line j as float32 (u, v) (v 0 when absent, as tobj); an error if it is not
        a pair of finite numbers."""
        ln, vals = _deferred_numbers(texcoords[j], path)
        if not 1 <= len(vals) <= 3 or not all(math.isfinite(v) for v in vals):
            raise SceneError(f"{path}: line {ln}: a 'vt' line needs finite numbers u [v [w]]")
        return np.array((vals + [0.0])[:2], dtype=np.float32)

    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        words = line.split()
        if not words:
            continue
        key = words[0]
        if key == "v":
            try:
                vals = [np.float32(w) for w in words[1:]]
            except ValueError:
                raise SceneError(f"{path}: line {n}: a 'v' line does not hold numbers")
            if len(vals) < 3 or len(vals) == 5 or len(vals) > 6:
                raise SceneError(f"{path}: line {n}: a 'v' line needs x y z [w] or x y z r g b")
            p = np.array(vals[:3], dtype=np.float32)
            if len(vals) == 4:  # homogeneous weight, as tobj
                if vals[3] == 0:
                    raise SceneError(f"{path}: line {n}: a 'v' line has a weight w of 0")
                p = p / vals[3]
            positions.append(p)
        elif key == "vn":
            normals.append((n, words))
        elif key == "vt":
            texcoords.append((n, words))
        elif key in ("f", "l"):
            # tobj reads `l` lines as faces too; fewer than three vertices are
            # points and lines, which rastergi ignores.
            if len(words) < 4:
                continue
            masked = current is not None and library[current]["map_d"] is not None
            idx = []
            for w in words[1:]:
                parts = w.split("/")
                i = _obj_index(parts[0], len(positions), f"{path}: line {n}",
                               f"an '{key}' line holds something other than vertex indices",
                               "a face refers to a vertex that does not exist")
                j = None  # v/vt/vn or v//vn: the corner's normal
                if key == "f" and len(parts) >= 3 and parts[2] != "":
                    j = _obj_index(parts[2], len(normals), f"{path}: line {n}",
                                   f"a face's normal index '{parts[2]}' is not a number",
                                   "a face refers to a normal ('vn') that does not exist")
                t = None  # v/vt or v/vt/vn: the corner's texture coordinate (map_d only)
                if masked:
                    if key != "f" or len(parts) < 2 or parts[1] == "":
                        raise SceneError(f"{path}: line {n}: faces of the material "
                                         f"'{current}' (map_d) need texture coordinates "
                                         "(f v/vt) at every corner")
                    t = _obj_index(parts[1], len(texcoords), f"{path}: line {n}",
                                   f"a face's texture coordinate index '{parts[1]}' is not a number",
                                   "a face refers to a texture coordinate ('vt') that does not exist")
                idx.append((i, j, t))
            with_normals = [j is not None for _, j, _ in idx]
            if any(with_normals) and not all(with_normals):
                raise SceneError(f"{path}: line {n}: a face gives normals ('vn') for some "
                                 "of its corners only")
            smooth = all(with_normals)
            tris = groups.setdefault((current, smooth), [])
            for k in range(1, len(idx) - 1):  # fan, as tobj
                tris.append((idx[0], idx[k], idx[k + 1]))
        elif key == "usemtl":
            name = _rest_of_line(line, 6)
            if not name:
                raise SceneError(f"{path}: line {n}: a 'usemtl' line names no material")
            current = name if name in library else None
        elif key == "mtllib":
            name = _rest_of_line(line, 6)
            if not name:
                raise SceneError(f"{path}: line {n}: an mtllib line names no file")
            library.update(load_mtl(os.path.join(directory, name)))
    pos = np.array(positions, dtype=np.float32).reshape(-1, 3)
    # Every material of the libraries, used or not, is checked, as rastergi does.
    models = {}
    for name, m in library.items():
        kd = m["kd"] or [OBJ_DEFAULT_ALBEDO] * 3
        ke = m["ke"] or [0.0] * 3
        models[name] = material_model(m, f"{path}: material '{name}'")
        if max(ke) > 0 and opacity_of(m) is not None:
            raise SceneError(f"{path}: material '{name}' emits (Ke) and is not opaque (d or "
                             "map_d); Mitsuba's area emitter would ignore the mask")
        if not all(math.isfinite(v) and v >= 0 for v in kd + ke):
            raise SceneError(f"{path}: material '{name}' has a negative or non-finite "
                             "albedo or emission")
        if max(kd) > 1:
            raise SceneError(f"{path}: material '{name}' has an albedo above 1 ({kd}), "
                             "which would create energy")
    result = []
    for (name, smooth), tris in groups.items():
        if not tris:
            continue
        m = library.get(name) if name is not None else None
        kd = (m or {}).get("kd") or [OBJ_DEFAULT_ALBEDO] * 3
        ke = (m or {}).get("ke") or [0.0] * 3
        d, map_d = (m or {}).get("d"), (m or {}).get("map_d")
        label = name if m is not None else "default"
        triangles = pos[np.array([[c[0] for c in t] for t in tris], dtype=np.int64)]
        if not np.isfinite(triangles).all():
            raise SceneError(f"{path}: a triangle has a non-finite coordinate")
        vertex_normals = None
        if smooth:
            vertex_normals = np.array([[unit_normal(c[1]) for c in t] for t in tris],
                                      dtype=np.float32).reshape(-1, 3, 3)
        uvs = None
        if map_d is not None:
            uvs = np.array([[texcoord(c[2]) for c in t] for t in tris],
                           dtype=np.float32).reshape(-1, 3, 2)
        material = {"name": label, "kd": kd, "ke": ke, "d": d, "map_d": map_d,
                    "model": models[name] if m is not None else {"kind": "diffuse"}}
        try:  # refuses, before rendering, what Mitsuba cannot reproduce
            bsdf_of(material)
        except SceneError as e:
            raise SceneError(f"{path}: {e}")
        result.append((material, triangles, vertex_normals, uvs))
    if not result:
        raise SceneError(f"{path}: contains no faces; an OBJ scene needs at least one "
                         "triangle ('f' lines)")
    return result


def opacity_of(material):
    """How a material of load_mtl/load_obj is masked: None (opaque: no map_d, d absent or 1),
    ("constant", d) or ("texture", map_d path, d factor (1 when absent))."""
    d, map_d = material.get("d"), material.get("map_d")
    if map_d is not None:
        return ("texture", map_d, 1.0 if d is None else d)
    if d is not None and d < 1:
        return ("constant", d)
    return None


GLASS_ILLUM = (4, 6, 7, 9)  # MTL illumination models with refraction: a glass solid
GLASS_DEFAULT_IOR = 1.5


def _mtl_value(entry, count, what):
    """A lazily parsed `Ks`/`Tf` (count 3: a colour, one number meaning grey) or `Ni` (count
    1) line of load_mtl, as floats; an error naming the line if it is not that."""
    path, n, words = entry
    if count == 3:
        return _colour(words, path, n)
    try:
        v = float(np.float32(words[1])) if len(words) == 2 else None
    except ValueError:
        v = None
    if v is None or not math.isfinite(v):
        raise SceneError(f"{path}: line {n}: '{words[0]}' needs one number ({what})")
    return v


def material_model(m, label):
    """rastergi's material model of an MTL material of load_mtl (module docstring,
    "Materials"), one of
      {"kind": "diffuse"}: Lambertian Kd (no Pm, no Pr, no glass illum);
      {"kind": "metallic_roughness", "metallic": m, "roughness": r, "specular": bool}:
        glTF metallic-roughness with base colour Kd, GGX alpha r², and glTF's dielectric
        specular layer (F0 0.04) unless `Ks 0 0 0`. From `Pm` (default 0) and `Pr`
        (default 1), or from `illum 3` without `Pm`: metallic 1, roughness Pr (default 0);
      {"kind": "glass", "ior": Ni (default 1.5), "tint": Tf (default 1 1 1),
        "roughness": Pr (default 0)}: a refracting solid (illum 4, 6, 7 or 9; Pm, Kd and Ks
        are then ignored).
    Refuses values that make no glass (an Ni that is not a positive number, a Tf outside
    [0, 1]), naming `label` (the file and material); whether Mitsuba can reproduce the model
    is bsdf_of's question."""
    illum, pm, pr = m["illum"], m["pm"], m["pr"]
    if illum in GLASS_ILLUM:
        ior = GLASS_DEFAULT_IOR if m["ni"] is None else _mtl_value(m["ni"], 1, "the index "
                                                                   "of refraction")
        if not ior > 0:
            raise SceneError(f"{label}: a glass's index of refraction (Ni) must be positive, "
                             f"got {ior:g}")
        tint = [1.0] * 3 if m["tf"] is None else _mtl_value(m["tf"], 3, "")
        if not all(math.isfinite(v) and 0 <= v <= 1 for v in tint):
            raise SceneError(f"{label}: a glass's tint (Tf) must lie in [0, 1], "
                             f"got {' '.join(f'{v:g}' for v in tint)}")
        return {"kind": "glass", "ior": ior, "tint": tint,
                "roughness": 0.0 if pr is None else pr}
    if pm is None and pr is None and illum != 3:
        return {"kind": "diffuse"}
    if illum == 3 and pm is None:
        metallic, roughness = 1.0, 0.0 if pr is None else pr
    else:
        metallic, roughness = 0.0 if pm is None else pm, 1.0 if pr is None else pr
    specular = m["ks"] is None or any(v != 0 for v in _mtl_value(m["ks"], 3, ""))
    return {"kind": "metallic_roughness", "metallic": metallic, "roughness": roughness,
            "specular": specular}


def _metal_bsdf(roughness):
    """glTF's metal lobe with base colour 1 (Schlick F = 1 at every angle): a perfect mirror,
    Mitsuba's `conductor` with material "none" (eta 0, k 1: reflectance 1), or for r > 0 the
    GGX `roughconductor` of alpha r² (Mitsuba's masking is separable Smith G1(wi) G1(wo),
    glTF's specification form)."""
    if roughness == 0:
        return {"type": "conductor", "material": "none"}
    return {"type": "roughconductor", "material": "none", "distribution": "ggx",
            "alpha": float(roughness) ** 2, "sample_visible": True}


def bsdf_of(material):
    """The Mitsuba BSDF of a material of load_obj, or a SceneError where Mitsuba cannot
    reproduce rastergi's model (module docstring, "Materials"):
      diffuse -> twosided(diffuse(Kd)), as always;
      metallic 1, Kd 1 1 1 -> twosided(conductor | roughconductor, material "none");
      0 < metallic < 1, Kd 1 1 1, Ks 0 0 0 -> twosided(blendbsdf(weight m, diffuse(1),
        that conductor)): (1 - m)/pi + m GGX(F = 1);
      metallic 0, Ks 0 0 0 -> twosided(diffuse(Kd)) (no specular layer, no metal lobe);
      glass -> dielectric | roughdielectric (int_ior Ni, ext_ior 1, specular_transmittance
        Tf, GGX alpha Pr²), not twosided (its outside is the side of the counter-clockwise
        front face).
    Masked materials (d, map_d) get the `mask` around this (obj_scene_dict); masked glass and
    emitting glass or metal are refused."""
    model, name = material["model"], material["name"]
    kd, emits = material["kd"], max(material["ke"]) > 0
    if model["kind"] == "diffuse":
        diffuse = {"type": "diffuse", "reflectance": rgb(kd)}
        if not material.get("two_sided", True):
            return diffuse  # glTF's one-sided surfaces: black from behind in both renderers
        return {"type": "twosided", "bsdf": diffuse}
    if model["kind"] == "glass":
        if emits:
            raise SceneError(f"material '{name}' is glass (illum) and emits (Ke); an emitting "
                             "glass is not reproduced here")
        if opacity_of(material) is not None:
            raise SceneError(f"material '{name}' is glass (illum) and has an opacity (d < 1 or "
                             "map_d); a cut-out glass is not reproduced here (give glass no "
                             "d, or d 1)")
        bsdf = {"type": "dielectric", "int_ior": float(model["ior"]), "ext_ior": 1.0,
                "specular_transmittance": rgb(model["tint"])}
        if model["roughness"] > 0:
            bsdf.update({"type": "roughdielectric", "distribution": "ggx",
                         "alpha": float(model["roughness"]) ** 2, "sample_visible": True})
        return bsdf
    m, r, specular = model["metallic"], model["roughness"], model["specular"]
    if m == 0 and not specular:
        # glTF with metallic 0 and no specular layer is Lambertian Kd.
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": rgb(kd)}}
    what = f"material '{name}' (Kd {' '.join(f'{v:g}' for v in kd)}, metallic {m:g}, " \
           f"roughness {r:g}{'' if specular else ', Ks 0 0 0'})"
    if emits:
        raise SceneError(f"{what} is metallic-roughness and emits (Ke); an emitting metal is "
                         "not reproduced here")
    white = all(v == 1.0 for v in kd)
    if m > 0 and not white:
        raise SceneError(f"{what}: a coloured metal: rastergi's metal reflects with Schlick's "
                         "Fresnel of F0 = Kd, which no Mitsuba conductor reproduces; only base "
                         "colour Kd 1 1 1 (F = 1) is rendered here")
    if m < 1 and specular:
        raise SceneError(f"{what}: glTF's dielectric specular layer (F0 0.04) over the "
                         "diffuse part has no Mitsuba equivalent (plastic, roughplastic and "
                         "principled layer differently); give Ks 0 0 0 to remove the layer, "
                         "or metallic 1")
    if m == 1:
        return {"type": "twosided", "bsdf": _metal_bsdf(r)}
    return {"type": "twosided", "bsdf": {
        "type": "blendbsdf", "weight": float(m),
        "bsdf_0": {"type": "diffuse", "reflectance": rgb([1.0, 1.0, 1.0])},
        "bsdf_1": _metal_bsdf(r)}}


def describe_bsdf(bsdf):
    """A short description of bsdf_of's answer for the summary lines."""
    if bsdf["type"] == "mask":
        return describe_bsdf(bsdf["bsdf"])
    if bsdf["type"] == "twosided":
        return f"twosided({describe_bsdf(bsdf['bsdf'])})"
    if bsdf["type"] == "blendbsdf":
        return (f"blendbsdf({bsdf['weight']:g}: {describe_bsdf(bsdf['bsdf_0'])}, "
                f"{describe_bsdf(bsdf['bsdf_1'])})")
    if bsdf["type"] == "diffuse":
        return f"diffuse({', '.join(f'{v:.7g}' for v in bsdf['reflectance']['value'])})"
    extra = (f" ior {bsdf['int_ior']:g}, Tf "
             f"({', '.join(f'{v:g}' for v in bsdf['specular_transmittance']['value'])})"
             if "int_ior" in bsdf else " F = 1")
    alpha = f", GGX alpha {bsdf['alpha']:g}" if "alpha" in bsdf else ""
    return f"{bsdf['type']}{extra}{alpha}"


def bounds(groups):
    pts = np.concatenate([g[1].reshape(-1, 3) for g in groups]).astype(np.float32)
    return pts.min(0), pts.max(0)


def framing_camera(lo, hi):
    """rastergi's Scene::framing_camera: the bounds' centre from +z, 45 degrees."""
    fov = 45.0
    extent = np.maximum(hi.astype(np.float64) - lo, 0.0)
    radius = 0.5 * max(float(np.linalg.norm(extent)), 1e-6)
    distance = radius / math.sin(0.5 * math.radians(fov))
    centre = 0.5 * (lo.astype(np.float64) + hi)
    return {"eye": [float(centre[0]), float(centre[1]), float(centre[2] + distance)],
            "target": [float(c) for c in centre], "up": [0.0, 1.0, 0.0], "fov": fov}


def check_camera(camera):
    """rastergi's Camera::validate."""
    eye, target, up = (np.asarray(camera[k], dtype=np.float64)
                       for k in ("eye", "target", "up"))
    forward = target - eye
    if not (np.isfinite(eye).all() and np.isfinite(target).all()
            and np.isfinite(up).all()) or forward @ forward <= 0:
        raise SceneError("invalid camera: eye and target must be distinct finite points")
    c = np.cross(forward / np.linalg.norm(forward), up)
    if c @ c < 1e-12:
        raise SceneError("invalid camera: the up vector must not be parallel to the "
                         "view direction")
    if not 0 < camera["fov"] < 180:
        raise SceneError("invalid camera: the field of view must lie strictly between 0 "
                         f"and 180 degrees, got {camera['fov']}")


def write_ply(path, triangles, normals=None, uvs=None):
    """Triangles (n, 3, 3) as a binary PLY mesh, three vertices per triangle; with normals
    (n, 3, 3), each vertex also carries its corner's normal (properties nx, ny, nz); with uvs
    (n, 3, 2), OBJ `vt` (v up the image), each vertex also carries its corner's texture
    coordinates in Mitsuba's convention (properties u, v): (u, 1 - v). Mitsuba's PLY loader
    takes u, v as they are and its bitmap texture puts v = 0 on the image's top row (row 0),
    so OBJ's v must be flipped here, as Mitsuba's own OBJ loader does (flip_tex_coords,
    default true); checked by experiment (crates/rastergi/tests/data/README.md)."""
    n = len(triangles)
    props = (["x", "y", "z"] + (["nx", "ny", "nz"] if normals is not None else [])
             + (["u", "v"] if uvs is not None else []))
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {3 * n}\n" + "".join(f"property float {p}\n" for p in props)
              + f"element face {n}\nproperty list uchar int vertex_indices\nend_header\n")
    vertices = np.asarray(triangles, dtype="<f4").reshape(3 * n, 3)
    if normals is not None:
        vertices = np.concatenate([vertices, np.asarray(normals, dtype="<f4").reshape(3 * n, 3)],
                                  axis=1)
    if uvs is not None:
        uv = np.asarray(uvs, dtype=np.float64).reshape(3 * n, 2)
        uv = np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1).astype("<f4")
        vertices = np.concatenate([vertices, uv], axis=1)
    faces = np.zeros(n, dtype=[("count", "u1"), ("idx", "<i4", 3)])
    faces["count"] = 3
    faces["idx"] = np.arange(3 * n, dtype=np.int32).reshape(n, 3)
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(vertices, dtype="<f4").tobytes())
        f.write(faces.tobytes())


def smooth_shaded(material, normals):
    """Whether a group of load_obj is rendered with its `vn` normals as shading normals: it
    has them and does not emit. Emitting triangles keep face normals: Mitsuba's `area`
    emitter takes its side, and the area-to-solid-angle density of its samples, from the
    shading normal, which would no longer be the winding's front (module docstring)."""
    return normals is not None and not max(material["ke"]) > 0


def opacity_texture(mi, opacity):
    """The `opacity` of a mask BSDF for opacity_of(material) (not None): a constant, or a
    `bitmap` texture of the map_d image read raw (its stored values, no sRGB decoding),
    bilinear, repeating, and, where the MTL also gives `d`, multiplied by it (the image's
    values times d, as one bitmap; bilinear interpolation commutes with the factor)."""
    if opacity[0] == "constant":
        return float(opacity[1])
    _, filename, factor = opacity
    try:
        bitmap = mi.Bitmap(filename)
    except Exception as e:
        raise SceneError(f"{filename}: the opacity image (map_d) cannot be read: {e}")
    if bitmap.pixel_format() != mi.Bitmap.PixelFormat.Y or bitmap.channel_count() != 1:
        raise SceneError(f"{filename}: an opacity image (map_d) must have one grey channel "
                         f"(PNG colour type 0), not {bitmap.pixel_format()}; which channel of "
                         "a colour image is the opacity is not settled")
    if factor == 1.0:
        return {"type": "bitmap", "filename": filename, "raw": True}
    values = np.array(bitmap)
    if values.dtype.kind == "u":
        values = values.astype(np.float64) / np.iinfo(values.dtype).max
    values = (np.asarray(values, dtype=np.float64) * factor).astype(np.float32)
    scaled = mi.Bitmap(values.reshape(values.shape[0], values.shape[1], 1),
                       mi.Bitmap.PixelFormat.Y)
    scaled.set_srgb_gamma(False)
    return {"type": "bitmap", "bitmap": scaled, "raw": True}


def obj_integrator(groups):
    """`path`, or `volpath` where some material is masked (d < 1 or map_d): Mitsuba's `path`
    traces its shadow rays with scene.ray_test, for which a mask surface is opaque whatever
    its opacity (a point light never shines through a hole), while `volpath` multiplies a
    shadow ray's weight by 1 - opacity at every null (mask) surface it crosses. Without media
    the two are otherwise the same estimator (volpath does not count null crossings as
    bounces for max_depth)."""
    return "volpath" if any(opacity_of(g[0]) is not None for g in groups) else "path"


def obj_scene_dict(mi, groups, camera, width, height, max_depth, spp, mesh_dir):
    """An OBJ scene (from load_obj) as a Mitsuba scene dict; meshes go to mesh_dir."""
    lo, hi = bounds(groups)
    diagonal = float(np.linalg.norm(np.maximum(hi.astype(np.float64) - lo, 0.0)))
    scene = {
        "type": "scene",
        "integrator": {"type": obj_integrator(groups), "max_depth": int(max_depth)},
        "sensor": sensor_dict(mi, camera, width, height, spp,
                              1e-4 * max(diagonal, 1e-3), far_clip_for(camera, lo, hi)),
    }
    for i, (material, triangles, normals, uvs) in enumerate(groups):
        smooth = smooth_shaded(material, normals)
        filename = os.path.join(mesh_dir, f"material_{i}.ply")
        write_ply(filename, triangles, normals if smooth else None, uvs)
        bsdf = bsdf_of(material)
        opacity = opacity_of(material)
        if opacity is not None:
            # Stochastic: a ray meeting the surface passes straight on with probability
            # 1 - opacity (a null event), else it meets the nested BSDF.
            bsdf = {"type": "mask", "opacity": opacity_texture(mi, opacity), "bsdf": bsdf}
        shape = {
            "type": "ply",
            "filename": filename,
            # False: Mitsuba interpolates the PLY's vertex normals (nx, ny, nz) over each
            # triangle as its shading normal. (Without nx, ny, nz in the file it would
            # compute smoothed ones itself, so face normals need True.)
            "face_normals": not smooth,
            "bsdf": bsdf,
        }
        if max(material["ke"]) > 0:
            # One-sided: emits from the front (counter-clockwise) face only.
            shape["emitter"] = {"type": "area", "radiance": rgb(material["ke"])}
        scene[f"material-{i}"] = shape
    return scene


def scene_camera(args, default):
    """The default camera with the command line's --eye/--target/--up/--fov in place."""
    camera = dict(default)
    for key in ("eye", "target", "up", "fov"):
        if getattr(args, key) is not None:
            camera[key] = getattr(args, key)
    check_camera(camera)
    return camera


def check_scene(mi):
    """Compare our dict with mi.cornell_box(); return the largest difference."""
    ours = cornell_scene_dict(mi, 256, 256, 8)
    theirs = mi.cornell_box()
    worst = 0.0
    ok = True
    keys = sorted(set(ours) | set(theirs))
    for k in keys:
        if k not in ours or k not in theirs:
            print(f"  {k}: only in {'ours' if k in ours else 'mi.cornell_box()'}")
            ok = False
            continue
        a, b = ours[k], theirs[k]
        if not isinstance(a, dict):
            continue
        if k == "integrator":
            print(f"  integrator: ours {a}  mi {b}")
            continue
        if k == "sensor":
            ma = np.array(a["to_world"].matrix, dtype=np.float64)
            mb = np.array(b["to_world"].matrix, dtype=np.float64)
            d = float(np.abs(ma - mb).max())
            worst = max(worst, d)
            print(f"  sensor: to_world max |diff| {d:.3g}; fov {a['fov']} vs "
                  f"{b['fov']}; fov_axis {a['fov_axis']} vs {b['fov_axis']}; "
                  f"rfilter {a['film']['rfilter']} vs {b['film']['rfilter']}")
            continue
        if "to_world" in a:
            ma = np.array(a["to_world"].matrix, dtype=np.float64)
            mb = np.array(b["to_world"].matrix, dtype=np.float64)
            d = float(np.abs(ma - mb).max())
            worst = max(worst, d)
            same = (a["type"] == b["type"] and a["bsdf"] == b["bsdf"]
                    and a.get("emitter") == b.get("emitter"))
            ok = ok and same
            print(f"  {k}: {a['type']} bsdf={a['bsdf']['id']} "
                  f"to_world max |diff| {d:.3g} {'ok' if same else 'MISMATCH'}")
            print("    ours:", np.array2string(ma[:3], precision=8,
                                                 suppress_small=True).replace("\n", ""))
            print("    mi:  ", np.array2string(mb[:3], precision=8,
                                                 suppress_small=True).replace("\n", ""))
        else:
            same = a == b
            ok = ok and same
            print(f"  {k}: {a} {'ok' if same else 'MISMATCH vs ' + str(b)}")
    print(f"largest matrix difference: {worst:.3g}; types/materials "
          f"{'identical' if ok else 'DIFFER'}")
    return ok and worst < 1e-6


def spot_dict(mi, v):
    """A hard-cone spot light x,y,z,tx,ty,tz,r,g,b,ANGLE as Mitsuba's `spot`: at x,y,z, its
    axis (local +z) towards tx,ty,tz, `intensity` r,g,b W/sr on the axis, and
    cutoff_angle = beam_width = ANGLE degrees. With beam_width == cutoff_angle spot.cpp's
    falloff is 1 for cos(theta) > cos(cutoff) and 0 otherwise (the linear ramp between
    the two angles is never selected), a step."""
    pos, aim, color, angle = v[:3], v[3:6], v[6:9], v[9]
    axis = [a - p for a, p in zip(aim, pos)]
    length = math.sqrt(sum(c * c for c in axis))
    if not length > 0:
        raise SceneError(f"--spot {','.join(f'{x:g}' for x in v)}: the position and the "
                         "aim point must differ")
    if not 0 < angle < 90:
        raise SceneError(f"--spot: the cone's half-angle must lie strictly between 0 and 90 "
                         f"degrees, got {angle:g}")
    if min(color) < 0:
        raise SceneError(f"--spot: the intensity must not be negative, got {color}")
    # Any up vector not parallel to the axis: the coordinate axis least aligned with it
    # (the cone is round, its roll does not matter).
    k = min(range(3), key=lambda i: abs(axis[i]))
    up = [1.0 if i == k else 0.0 for i in range(3)]
    return {"type": "spot", "intensity": rgb(color), "cutoff_angle": float(angle),
            "beam_width": float(angle),
            "to_world": mi.ScalarTransform4f().look_at(origin=list(pos), target=list(aim),
                                                       up=up)}


def add_lights(mi, d, args):
    """rastergi's point lights (--point, W/sr), hard-cone spot lights (--spot, W/sr on the
    axis) and sun (--sun, W/m², a delta direction: use rastergi's --sun-size 0) as Mitsuba's
    `point`, `spot` and `directional` emitters, and an environment map (--env,
    --env-scale) as an `envmap` emitter with the identity to_world."""
    for k, v in enumerate(args.point or []):
        d[f"point_{k}"] = {"type": "point", "position": list(v[:3]), "intensity": rgb(v[3:])}
    for k, v in enumerate(args.spot or []):
        d[f"spot_{k}"] = spot_dict(mi, v)
    if args.sun:
        az, el, irr = (float(x) for x in args.sun)
        a, e = math.radians(az), math.radians(el)
        towards = [math.sin(a) * math.cos(e), math.sin(e), math.cos(a) * math.cos(e)]
        d["sun"] = {"type": "directional", "direction": [-c for c in towards],
                    "irradiance": rgb([irr, irr, irr])}
    if args.env:
        # No to_world: Mitsuba's own frame is the convention (module docstring).
        d["env"] = {"type": "envmap", "filename": os.path.abspath(args.env),
                    "scale": float(args.env_scale)}
    return d


def check_env(args):
    """--env names a readable .exr or .hdr file; --env-scale is finite and not negative."""
    if not args.env:
        return
    if not args.env.lower().endswith((".exr", ".hdr")):
        raise SceneError(f"{args.env}: an environment map must be an .exr or .hdr "
                         "latitude-longitude image")
    if not os.path.isfile(args.env):
        raise SceneError(f"{args.env}: no such file")
    if not (math.isfinite(args.env_scale) and args.env_scale >= 0):
        raise SceneError(f"--env-scale must be a finite number >= 0, got {args.env_scale}")


def xml_for_mitsuba3(text, width, height, spp, max_depth):
    """A Mitsuba scene file as Mitsuba 3 renders it beside rastergi (issue 47): the file's
    integrator replaced by `path` (max_depth as --max-depth), its film's size and pixel filter
    by width x height and a box filter (rastergi's), its sampler's count by spp, `trilinear`
    texture filtering written `bilinear` (Mitsuba 3 has no trilinear; compare with rastergi's
    --texture-filter bilinear), `extEta` and `maxSmoothAngle` dropped (Mitsuba 3 knows neither; rastergi warns
    that it does not use them) and `phong`
    (which Mitsuba 3 lacks; Sponza's vault) read as `diffuse` of its diffuseReflectance, as
    rastergi reads it: the ../shared/scenes README's list of what Mitsuba 3 needs changed in
    these 0.6 files, and phong; a bitmap's 0.6 `gamma` 1 written as Mitsuba 3's `raw` (other
    gammas dropped: sRGB), and the film's 0.6 display settings (`gamma`, `banner`) dropped.
    Everything else is the file as published."""
    import xml.etree.ElementTree as ET
    root = ET.fromstring(text)
    for parent in root.iter():
        for child in list(parent):
            if child.tag == "integrator":
                parent.remove(child)
            elif child.get("name") in ("extEta", "maxSmoothAngle"):
                parent.remove(child)
            elif child.get("name") == "filterType" and child.get("value") == "trilinear":
                child.set("value", "bilinear")
            elif parent.tag == "texture" and parent.get("type") == "bitmap" and child.get("name") == "gamma":
                # 0.6's gamma 1 is a linear texture: Mitsuba 3's raw (rastergi reads it so);
                # Mitsuba 3 has no gamma, and sRGB is its default.
                parent.remove(child)
                if abs(float(child.get("value", "-1")) - 1.0) < 1e-3:
                    ET.SubElement(parent, "boolean", {"name": "raw", "value": "true"})
        if parent.tag == "bsdf" and parent.get("type") == "phong":
            # Mitsuba 3 has no phong: its diffuse part, as rastergi reads it (with a warning).
            parent.set("type", "diffuse")
            for child in list(parent):
                # 0.6's name, or 3's (a file written in Mitsuba 3's names).
                if child.get("name") in ("diffuseReflectance", "diffuse_reflectance"):
                    child.set("name", "reflectance")
                else:
                    parent.remove(child)
    integrator = ET.Element("integrator", {"type": "path"})
    ET.SubElement(integrator, "integer", {"name": "maxDepth" if root.get("version", "3").startswith("0") else "max_depth",
                                          "value": str(max_depth)})
    root.insert(0, integrator)
    old = root.get("version", "3").startswith("0")
    for sensor in root.iter("sensor"):
        for film in sensor.findall("film"):
            # What Mitsuba 3's hdrfilm takes besides the size and filter set here; 0.6's
            # display settings (`gamma`, `banner`, tone mapping) are for its LDR films and the
            # reference is linear: Mitsuba 3 refuses them as unreferenced.
            keep = {"file_format", "fileFormat", "pixel_format", "pixelFormat", "component_format",
                    "componentFormat", "crop_offset_x", "crop_offset_y", "crop_width", "crop_height",
                    "cropOffsetX", "cropOffsetY", "cropWidth", "cropHeight", "sample_border", "compensate"}
            for child in list(film):
                if child.get("name") not in keep or child.tag == "rfilter":
                    film.remove(child)
            ET.SubElement(film, "integer", {"name": "width", "value": str(width)})
            ET.SubElement(film, "integer", {"name": "height", "value": str(height)})
            ET.SubElement(film, "rfilter", {"type": "box"})
        for sampler in sensor.findall("sampler"):
            for child in list(sampler):
                if child.get("name") in ("sampleCount", "sample_count"):
                    sampler.remove(child)
            ET.SubElement(sampler, "integer", {"name": "sampleCount" if old else "sample_count", "value": str(spp)})
    return ET.tostring(root, encoding="unicode")


def load_xml_scene(mi, args, spp):
    """A Mitsuba scene file (`--scene X.xml`) as Mitsuba 3 loads it, after xml_for_mitsuba3,
    from a string with the file's folder first on the file resolver's path (meshes and
    textures are found relative to it; the folder may be read-only). The camera options do
    not apply: the file's own sensor is used, as rastergi uses it."""
    if not os.path.isfile(args.scene):
        raise SceneError(f"{args.scene}: no such file")
    if args.eye or args.target or args.up or args.fov or args.point or args.spot or args.sun or args.env:
        raise SceneError("--eye/--target/--up/--fov and extra lights do not apply to a .xml scene")
    with open(args.scene, encoding="utf-8") as f:
        text = xml_for_mitsuba3(f.read(), args.width, args.height, spp, args.max_depth)
    folder = os.path.dirname(os.path.abspath(args.scene))
    mi.file_resolver().prepend(folder)
    return mi.load_string(text)


def load_scene(mi, args, spp):
    """The Mitsuba scene of --scene with the camera options and extra lights applied."""
    check_env(args)
    if args.env and not args.quiet:
        print(f"  environment map: {os.path.abspath(args.env)}, scale {args.env_scale}, "
              "identity to_world", file=sys.stderr)
    if args.scene == "cornell":
        camera = scene_camera(args, CORNELL_CAMERA)
        return mi.load_dict(add_lights(mi, cornell_scene_dict(mi, args.width, args.height,
                                                              args.max_depth, spp, camera), args))
    if args.scene.lower().endswith(".xml"):
        return load_xml_scene(mi, args, spp)
    if not args.scene.lower().endswith((".obj", ".gltf", ".glb")):
        raise SceneError(f"unknown scene '{args.scene}': use the built-in 'cornell' "
                         "or a path to a .obj, .gltf, .glb or Mitsuba .xml file")
    if not os.path.isfile(args.scene):
        raise SceneError(f"{args.scene}: no such file")
    file_lights = []
    if args.scene.lower().endswith(".obj"):
        groups, file_camera = load_obj(args.scene), None
    else:
        from mitsuba_gltf import GltfError, load_gltf
        try:
            groups, file_lights, file_camera = load_gltf(args.scene)
        except GltfError as e:
            raise SceneError(str(e))
    camera = scene_camera(args, file_camera or framing_camera(*bounds(groups)))
    if not args.quiet:
        for material, triangles, normals, uvs in groups:
            kd, ke = (", ".join(f"{v:.7g}" for v in material[k]) for k in ("kd", "ke"))
            shading = ("vertex normals (vn)" if smooth_shaded(material, normals) else
                       "face normals" + (" (vn ignored: an emitter)" if normals is not None
                                         else ""))
            opacity = opacity_of(material)
            mask = ("" if opacity is None else
                    f", mask opacity {opacity[1]:g}" if opacity[0] == "constant" else
                    f", mask opacity {os.path.basename(opacity[1])}"
                    + (f" x {opacity[2]:g}" if opacity[2] != 1 else "") + " (vt as u, 1 - v)")
            bsdf = ("" if material["model"]["kind"] == "diffuse" else
                    f", {describe_bsdf(bsdf_of(material))}")
            sides = ", one-sided" if not material.get("two_sided", True) else ""
            print(f"  {material['name']}: {len(triangles)} triangles, Kd ({kd}), Ke ({ke}), "
                  f"{shading}{mask}{bsdf}{sides}", file=sys.stderr)
        for light in file_lights:
            print(f"  light from the file: {light['type']} "
                  f"{ {k: v for k, v in light.items() if k != 'to_world'} }", file=sys.stderr)
        print(f"  integrator: {obj_integrator(groups)}", file=sys.stderr)
        print(f"  camera: eye {camera['eye']}, target {camera['target']}, up "
              f"{camera['up']}, fov {camera['fov']}", file=sys.stderr)
    with tempfile.TemporaryDirectory(prefix="rastergi-mitsuba-") as mesh_dir:
        # Mitsuba reads the meshes while loading; the files can go afterwards.
        d = obj_scene_dict(mi, groups, camera, args.width, args.height, args.max_depth, spp,
                           mesh_dir)
        for k, light in enumerate(file_lights):
            d[f"file_light_{k}"] = light
        return mi.load_dict(add_lights(mi, d, args))


def render(mi, args):
    spp_total = int(args.spp)
    chunk = max(1, min(int(args.chunk_spp), spp_total))
    scene = load_scene(mi, args, chunk)
    acc = np.zeros((args.height, args.width, 3), dtype=np.float64)
    done = 0
    i = 0
    t0 = time.time()
    while done < spp_total:
        n = min(chunk, spp_total - done)
        seed = (int(args.seed) * 1000003 + i) & 0xFFFFFFFF
        img = np.array(mi.render(scene, seed=seed, spp=n), dtype=np.float64)
        if img.shape != acc.shape:
            sys.exit(f"unexpected image shape {img.shape}")
        acc += img * n
        done += n
        i += 1
        if not args.quiet:
            el = time.time() - t0
            print(f"  chunk {i}: {done}/{spp_total} spp, {el:.1f} s "
                  f"({done * args.width * args.height / el / 1e6:.2f} Msamples/s)",
                  file=sys.stderr)
    return (acc / spp_total).astype(np.float32), time.time() - t0


def write_exr(mi, path, img):
    img = np.ascontiguousarray(img, dtype=np.float32)
    assert img.ndim == 3 and img.shape[2] == 3
    bmp = mi.Bitmap(img, mi.Bitmap.PixelFormat.RGB)
    bmp.set_srgb_gamma(False)
    bmp.write(path)  # OpenEXR, lossless PIZ, float32, channels R, G, B
    back = mi.Bitmap(path)
    if (back.pixel_format() != mi.Bitmap.PixelFormat.RGB
            or back.component_format() != mi.Struct.Type.Float32
            or back.channel_count() != 3):
        sys.exit(f"{path}: written as {back}, not float32 RGB")
    if not np.array_equal(np.array(back), img):
        sys.exit(f"{path}: read-back differs")


def read_exr(mi, path):
    bmp = mi.Bitmap(path)
    return np.array(bmp, dtype=np.float64)


def stats(a, b=None):
    """Mean RGB, and relative RMSE between two images (emitter excluded)."""
    out = {}
    if b is None:
        out["mean_rgb"] = a.reshape(-1, 3).mean(0)
        return out
    m = (a + b) / 2
    out["mean_rgb"] = m.reshape(-1, 3).mean(0)
    emit = (a[..., 0] > EMITTER_RED_THRESHOLD) | (b[..., 0] > EMITTER_RED_THRESHOLD)
    dil = emit.copy()
    h, w = emit.shape
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            sh = np.zeros_like(emit)
            sh[max(0, dy):h + min(0, dy), max(0, dx):w + min(0, dx)] = \
                emit[max(0, -dy):h + min(0, -dy), max(0, -dx):w + min(0, -dx)]
            dil |= sh
    keep = ~dil
    d = (a - b)[keep]
    ref = m[keep]
    out["excluded_pixels"] = int(dil.sum())
    out["rel_rmse_a_b"] = float(np.sqrt((d ** 2).mean()) / ref.mean())
    out["rel_rmse_mean"] = out["rel_rmse_a_b"] / 2
    return out


def parse_floats(n):
    """An argparse type: n comma-separated finite numbers."""
    def parse(s):
        parts = s.split(",")
        try:
            v = [float(x) for x in parts]
        except ValueError:
            v = []
        if len(v) != n or not all(math.isfinite(x) for x in v):
            raise argparse.ArgumentTypeError(f"expected {n} comma-separated numbers, got '{s}'")
        return v
    return parse


# `x,y,z` as three finite floats (the format of rastergi's camera options).
parse_vec3 = parse_floats(3)


def _join_camera_values(argv):
    """`--target -1,0,2` as `--target=-1,0,2`: argparse takes a value starting with
    '-' for an option, rastergi's command line does not; the same options work in both."""
    out, i = [], 0
    while i < len(argv):
        if argv[i] in ("--eye", "--target", "--up", "--fov") and i + 1 < len(argv):
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
        else:
            out.append(argv[i])
            i += 1
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default="cornell",
                   help="the built-in 'cornell' (default), a Wavefront .obj file (+ .mtl), a glTF "
                        ".gltf/.glb file (scripts/mitsuba_gltf.py) or a Mitsuba .xml scene file "
                        "(rendered as published: xml_for_mitsuba3)")
    p.add_argument("--eye", type=parse_vec3, help="camera position x,y,z (as rastergi's --eye)")
    p.add_argument("--target", type=parse_vec3, help="point looked at, x,y,z")
    p.add_argument("--up", type=parse_vec3, help="camera up vector x,y,z")
    p.add_argument("--fov", type=float, help="vertical field of view in degrees")
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--spp", type=int, default=1024)
    p.add_argument("--point", type=parse_floats(6), action="append",
                   help="add a point light x,y,z,r,g,b (intensity W/sr, as a glTF point light "
                        "in rastergi); repeatable")
    p.add_argument("--spot", type=parse_floats(10), action="append",
                   metavar="X,Y,Z,TX,TY,TZ,R,G,B,ANGLE",
                   help="add a hard-cone spot light at x,y,z aimed at tx,ty,tz, intensity "
                        "r,g,b W/sr on its axis (a glTF spot's color x intensity), half-angle "
                        "ANGLE degrees (Mitsuba spot, cutoff_angle = beam_width = ANGLE: a "
                        "step; give rastergi's spot inner = outer cone = ANGLE); repeatable")
    p.add_argument("--sun", type=parse_floats(3),
                   help="add rastergi's --sun AZIMUTH,ELEVATION,IRRADIANCE as a directional "
                        "light (a delta: render rastergi with --sun-size 0)")
    p.add_argument("--env", metavar="FILE",
                   help="add an environment map (.exr or .hdr, latitude-longitude, linear) as "
                        "Mitsuba's envmap emitter with the identity transform")
    p.add_argument("--env-scale", type=float, default=1.0, metavar="S",
                   help="radiance scale of --env (default 1)")
    p.add_argument("--max-depth", type=int, default=-1,
                   help="Mitsuba path depth: -1 unlimited, 2 = direct lighting")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--chunk-spp", type=int, default=256,
                   help="samples per pixel per render call (memory)")
    p.add_argument("--out", help="output .exr")
    p.add_argument("--variant", default=None,
                   help="Mitsuba variant (default: llvm_ad_rgb if usable, else scalar_rgb)")
    p.add_argument("--check-scene", action="store_true",
                   help="print our scene against mi.cornell_box() and exit")
    p.add_argument("--stats", nargs="+", metavar="EXR",
                   help="print mean RGB (and rel. RMSE of a pair) and exit")
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args(_join_camera_values(sys.argv[1:]))

    import mitsuba as mi
    if args.variant:
        mi.set_variant(args.variant)
    else:
        try:
            mi.set_variant("llvm_ad_rgb")
        except Exception as e:  # no libLLVM
            print(f"llvm_ad_rgb unavailable ({e}); using scalar_rgb", file=sys.stderr)
            mi.set_variant("scalar_rgb")
    print(f"mitsuba {mi.__version__}, variant {mi.variant()}", file=sys.stderr)

    if args.check_scene:
        if args.scene != "cornell":
            p.error("--check-scene compares the built-in cornell scene with mi.cornell_box()")
        sys.exit(0 if check_scene(mi) else 1)
    if args.stats:
        imgs = [read_exr(mi, f) for f in args.stats[:2]]
        s = stats(*imgs)
        for k, v in s.items():
            print(f"{k}: {np.round(v, 6) if isinstance(v, np.ndarray) else v}")
        return
    if not args.out:
        p.error("--out is required")

    try:
        img, secs = render(mi, args)
    except SceneError as e:
        sys.exit(f"error: {e}")
    write_exr(mi, args.out, img)
    mean = img.reshape(-1, 3).mean(0)
    print(f"{args.out}: {args.scene}, {args.width}x{args.height}, {args.spp} spp, max_depth "
          f"{args.max_depth}, seed {args.seed}, {secs:.1f} s, mean RGB "
          f"({mean[0]:.5f}, {mean[1]:.5f}, {mean[2]:.5f}), mitsuba "
          f"{mi.__version__} {mi.variant()}")


if __name__ == "__main__":
    main()
