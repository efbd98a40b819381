#!/usr/bin/env python3
"""Render Mitsuba 3 reference images of rastergi's built-in Cornell box.

The scene `cornell` is built here explicitly from the numbers in
cornell-box.md (it is Mitsuba's `mi.cornell_box()` geometry and materials, but
with a box pixel filter and a vertical field of view), rendered with Mitsuba's
`path` integrator and written as a linear float32 RGB OpenEXR (3 channels R, G,
B, no alpha; row 0 of the image is the top; PIZ lossless compression).

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
    python3 scripts/mitsuba_reference.py --width 128 --height 128 --spp 32768 --max-depth 2  --seed 1 --out $D/cornell_direct_128_a.exr
    python3 scripts/mitsuba_reference.py --width 128 --height 128 --spp 32768 --max-depth 2  --seed 2 --out $D/cornell_direct_128_b.exr
    python3 scripts/mitsuba_reference.py --width 128 --height 128 --spp 16384 --max-depth -1 --seed 3 --out $D/cornell_path_128_a.exr
    python3 scripts/mitsuba_reference.py --width 128 --height 128 --spp 16384 --max-depth -1 --seed 4 --out $D/cornell_path_128_b.exr

(--chunk-spp defaults to 256; the images depend on it through the chunk seeds,
and on the Mitsuba version and variant. Results are not bit-reproducible
across versions, only statistically.)

The two files of a pair use different seeds, so they are independent
estimates; RMSE(a, b) / 2 is the noise of their mean.

Other commands:

    python3 scripts/mitsuba_reference.py --check-scene    # compare with mi.cornell_box()
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
import math
import sys
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


def cornell_scene_dict(mi, width, height, max_depth, spp=1):
    """The built-in `cornell` scene as a Mitsuba scene dict."""
    T = mi.ScalarTransform4f

    def rgb(v):
        return {"type": "rgb", "value": list(v)}

    def ref(name):
        return {"type": "ref", "id": name}

    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": int(max_depth)},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",  # vertical field of view, as rastergi
            "fov": CAMERA_VFOV_DEG,
            "near_clip": 0.001,
            "far_clip": 100.0,
            "to_world": T().look_at(origin=CAMERA_EYE, target=CAMERA_TARGET,
                                    up=CAMERA_UP),
            "sampler": {"type": "independent", "sample_count": int(spp)},
            "film": {
                "type": "hdrfilm",
                "width": int(width),
                "height": int(height),
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
                "component_format": "float32",
            },
        },
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


def render(mi, args):
    spp_total = int(args.spp)
    chunk = max(1, min(int(args.chunk_spp), spp_total))
    scene = mi.load_dict(cornell_scene_dict(mi, args.width, args.height,
                                            args.max_depth, chunk))
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


def main():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--spp", type=int, default=1024)
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
    args = p.parse_args()

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
        sys.exit(0 if check_scene(mi) else 1)
    if args.stats:
        imgs = [read_exr(mi, f) for f in args.stats[:2]]
        s = stats(*imgs)
        for k, v in s.items():
            print(f"{k}: {np.round(v, 6) if isinstance(v, np.ndarray) else v}")
        return
    if not args.out:
        p.error("--out is required")

    img, secs = render(mi, args)
    write_exr(mi, args.out, img)
    mean = img.reshape(-1, 3).mean(0)
    print(f"{args.out}: {args.width}x{args.height}, {args.spp} spp, max_depth "
          f"{args.max_depth}, seed {args.seed}, {secs:.1f} s, mean RGB "
          f"({mean[0]:.5f}, {mean[1]:.5f}, {mean[2]:.5f}), mitsuba "
          f"{mi.__version__} {mi.variant()}")


if __name__ == "__main__":
    main()
