#!/usr/bin/env python3
"""Write the material test scenes: a sphere on a stage in five materials (`mat_*.obj` + `.mtl`)
and the Cornell box with a glass and a mirror sphere (`cornell_spheres.obj` + `.mtl`).

The stage (every `mat_*.obj`): a floor quad (y = 0, x and z in [-2, 2], `floor`, Kd 0.6,
facing +y); a back wall (z = -1.5, x in [-2, 2], y in [0, 2.5], `back`, Kd 0.7 0.3 0.2, facing
+z); a left wall (x = -1.5, z in [-2, 2], y in [0, 2.5], `left`, Kd 0.2 0.45 0.7, facing +x);
and a one-sided light, a 0.8 x 0.8 quad at y = 2.2 centred at (0.3, 2.2, 0.4) (x in
[-0.1, 0.7], z in [0, 0.8]), facing down (-y), `light`, Ke 12 12 12, Kd 0. The walls end where
they meet, the floor runs on behind and left of them; the stage is open to +x, +z and above
(no environment: rays that leave it see black). On the floor stands a UV sphere of radius 0.5
centred at (0, 0.5, 0) (its lower pole touches the floor at the origin), 48 segments around
the y axis x 24 rings from pole to pole (fans at the poles, quads split into two triangles
elsewhere: 2208 triangles, 1106 vertices), FLAT: no `vn`, so every facet shows. Its material
`sphere` is the one thing that differs between the files:

    mat_metal_rough   Kd 1 1 1, Pm 1, Pr 0.5            white rough metal (GGX alpha 0.25)
    mat_mirror        Kd 1 1 1, Pm 1, Pr 0              a perfect mirror
    mat_mix           Kd 1 1 1, Pm 0.5, Pr 0.4, Ks 0 0 0 half white diffuse, half metal (alpha 0.16)
    mat_glass         illum 7, Ni 1.5                   smooth glass, a refracting solid
    mat_rough_glass   illum 7, Ni 1.5, Pr 0.3           rough glass (alpha 0.09)

`cornell_spheres.obj`: the built-in Cornell box (crates/rastergi/src/scene/cornell.rs,
../shared/cornell-box.md; the same quads, corner order, materials `white`, `red`, `green` and
`light` (Kd white, Ke (18.387, 13.9873, 6.75357)) as its OBJ export) with its two boxes
replaced by two spheres of radius 0.3 (the box is [-1, 1]^3, so 0.6 across is the small box's
width) standing on the floor (y = -1) where the boxes stood, as in Jensen's photon-mapping
scene: a glass sphere (`glass`, illum 7, Ni 1.5) at the small box's place, front right, centre
(0.335, -0.7, 0.38), and a mirror sphere (`mirror`, Kd 1 1 1, Pm 1, Pr 0) at the large box's,
back left, centre (-0.33, -0.7, -0.28); the same 48 x 24 flat UV sphere. Their gaps: the
glass sphere is 0.365 from the right wall, the mirror 0.37 from the left and 0.42 from the
back wall, and the spheres are 0.34 apart. View it with the built-in camera (eye 0 0 3.9,
target 0 0 0, up +y, vertical fov 39.3077): an OBJ file is otherwise framed by its bounds.

Every face is wound counter-clockwise seen from the side its normal faces: floors up, walls
into the room, lights down, spheres outward (the glass's outside is its front). Plain Python,
no dependencies.

    python3 scripts/make_material_scenes.py                  # into crates/rastergi/tests/data/obj
    python3 scripts/make_material_scenes.py --out-dir DIR
"""
import math
import os

from obj_geometry import add, cross, dot, normal, num, out_dir_args, scale, sub, uv_sphere

SEGMENTS = 48  # around the y axis
RINGS = 24  # bands from the upper pole to the lower one

STAGE_SPHERE = ((0.0, 0.5, 0.0), 0.5)  # centre, radius

STAGE_MTL = """newmtl floor
Kd 0.6 0.6 0.6

newmtl back
Kd 0.7 0.3 0.2

newmtl left
Kd 0.2 0.45 0.7

newmtl light
Kd 0 0 0
Ke 12 12 12
"""

SPHERE_MATERIALS = {
    "mat_metal_rough": ("white rough metal", "Kd 1 1 1\nPm 1\nPr 0.5\n"),
    "mat_mirror": ("a perfect mirror", "Kd 1 1 1\nPm 1\nPr 0\n"),
    "mat_mix": ("half white diffuse, half white metal, no specular layer",
                "Kd 1 1 1\nPm 0.5\nPr 0.4\nKs 0 0 0\n"),
    "mat_glass": ("smooth glass", "illum 7\nNi 1.5\n"),
    "mat_rough_glass": ("rough glass", "illum 7\nNi 1.5\nPr 0.3\n"),
}

# The Cornell box, as cornell.rs builds it.
CORNELL_MTL = """newmtl white
Kd 0.885809 0.698859 0.666422

newmtl red
Kd 0.570068 0.0430135 0.0443706

newmtl green
Kd 0.105421 0.37798 0.076425

newmtl light
Kd 0.885809 0.698859 0.666422
Ke 18.387 13.9873 6.75357

newmtl glass
illum 7
Ni 1.5

newmtl mirror
Kd 1 1 1
Pm 1
Pr 0
"""
CORNELL_RADIUS = 0.3
CORNELL_SPHERES = [("glass", (0.335, -1.0 + CORNELL_RADIUS, 0.38)),  # the small box's place
                   ("mirror", (-0.33, -1.0 + CORNELL_RADIUS, -0.28))]  # the large box's


def quad(c, u, v):
    """cornell.rs's quad: the corners of c ± u ± v, counter-clockwise about u x v."""
    return [sub(sub(c, u), v), sub(add(c, u), v), add(add(c, u), v), add(sub(c, u), v)]


def sphere(centre, radius):
    """The vertices of a UV sphere and its triangles (0-based indices), outward."""
    dirs, tris = uv_sphere(RINGS, SEGMENTS)
    points = [add(centre, scale(radius, d)) for d in dirs]
    for t in tris:  # counter-clockwise seen from outside
        a, b, c = (points[k] for k in t)
        centroid = scale(1 / 3, add(add(a, b), c))
        assert dot(normal(a, b, c), sub(centroid, centre)) > 0, t
    return points, tris


class Obj:
    """An OBJ file being written: vertices numbered from 1, faces grouped by usemtl."""

    def __init__(self, header, mtl):
        self.lines = [f"# {h}" for h in header] + [f"mtllib {mtl}"]
        self.count = 0

    def part(self, comment, material, points, faces):
        """Vertices `points` and faces (0-based indices into points)."""
        first = self.count + 1
        self.lines += ["", f"# {comment}: v {first}-{first + len(points) - 1}"]
        self.lines += [f"v {num(x)} {num(y)} {num(z)}" for x, y, z in points]
        self.lines.append(f"usemtl {material}")
        self.lines += ["f " + " ".join(str(first + k) for k in f) for f in faces]
        self.count += len(points)

    def quad(self, comment, material, corners, facing):
        """A quad, its corners counter-clockwise seen from `facing` (checked)."""
        for k in (1, 2):  # both fan triangles (0, 1, 2) and (0, 2, 3) face the same way
            n = normal(corners[0], corners[k], corners[k + 1])
            assert dot(n, facing) > 0 and max(map(abs, cross(n, facing))) < 1e-12, (comment, n)
        self.part(comment, material, corners, [(0, 1, 2, 3)])

    def write(self, path):
        with open(path, "w") as f:
            f.write("\n".join(self.lines) + "\n")


def stage_obj(name, description, mtl):
    (cx, cy, cz), r = STAGE_SPHERE
    o = Obj([f"{name}.obj, written by scripts/make_material_scenes.py: the material stage (a",
             "floor, a back and a left wall, a 0.8 x 0.8 light at y = 2.2 facing down) and a",
             f"flat UV sphere of radius {r:g} centred at ({cx:g}, {cy:g}, {cz:g}), {SEGMENTS} "
             f"segments x {RINGS} rings, counter-clockwise",
             f"seen from outside, no vn; sphere material: {description}."], mtl)
    o.quad("floor, y = 0, facing +y", "floor",
           [(-2.0, 0.0, 2.0), (2.0, 0.0, 2.0), (2.0, 0.0, -2.0), (-2.0, 0.0, -2.0)], (0, 1, 0))
    o.quad("back wall, z = -1.5, facing +z", "back",
           [(-2.0, 0.0, -1.5), (2.0, 0.0, -1.5), (2.0, 2.5, -1.5), (-2.0, 2.5, -1.5)], (0, 0, 1))
    o.quad("left wall, x = -1.5, facing +x", "left",
           [(-1.5, 0.0, 2.0), (-1.5, 0.0, -2.0), (-1.5, 2.5, -2.0), (-1.5, 2.5, 2.0)], (1, 0, 0))
    o.quad("light, 0.8 x 0.8 at y = 2.2 centred at (0.3, 2.2, 0.4), facing -y (emits down)",
           "light", quad((0.3, 2.2, 0.4), (0.4, 0.0, 0.0), (0.0, 0.0, 0.4)), (0, -1, 0))
    points, tris = sphere(*STAGE_SPHERE)
    o.part("sphere: the upper pole, rings from the top, the lower pole", "sphere", points, tris)
    return o, len(tris)


def cornell_obj():
    o = Obj(["cornell_spheres.obj, written by scripts/make_material_scenes.py: the built-in "
             "Cornell box", "(cornell-box.md, cornell.rs) with a glass sphere (front right) and a "
             f"mirror sphere (back left) of radius {CORNELL_RADIUS:g}",
             "in place of its boxes. Camera: --eye 0,0,3.9 --target 0,0,0 --up 0,1,0 "
             "--fov 39.3077"], "cornell_spheres.mtl")
    x, y, z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
    neg = lambda a: scale(-1.0, a)  # noqa: E731
    o.quad("floor, y = -1, facing +y", "white", quad(neg(y), z, x), y)
    o.quad("ceiling, y = 1, facing -y", "white", quad(y, x, z), neg(y))
    o.quad("back wall, z = -1, facing +z", "white", quad(neg(z), x, y), z)
    o.quad("left wall, x = -1, facing +x", "red", quad(neg(x), y, z), x)
    o.quad("right wall, x = 1, facing -x", "green", quad(x, z, y), neg(x))
    o.quad("light: x in [-0.23, 0.23], z in [-0.18, 0.20], y = 0.99, facing -y", "light",
           quad((0.0, 0.99, 0.01), scale(0.23, x), scale(0.19, z)), neg(y))
    n = 0
    for material, centre in CORNELL_SPHERES:
        points, tris = sphere(centre, CORNELL_RADIUS)
        o.part(f"{material} sphere, centre ({', '.join(f'{c:g}' for c in centre)}), radius "
               f"{CORNELL_RADIUS:g}", material, points, tris)
        n += len(tris)
    # Clear of the walls and of each other.
    (_, a), (_, b) = CORNELL_SPHERES
    assert math.dist(a, b) > 2 * CORNELL_RADIUS + 0.3
    for c in (a, b):
        assert all(1 - abs(c[k]) - CORNELL_RADIUS > 0.3 for k in (0, 2))
    return o, n


def main():
    args = out_dir_args(__doc__)
    os.makedirs(args.out_dir, exist_ok=True)

    for name, (description, sphere_mtl) in SPHERE_MATERIALS.items():
        with open(os.path.join(args.out_dir, f"{name}.mtl"), "w") as f:
            f.write(f"# {name}.mtl, written by scripts/make_material_scenes.py: the stage's "
                    f"materials and the sphere's,\n# {description}\n\n{STAGE_MTL}\n"
                    f"newmtl sphere\n{sphere_mtl}")
        o, n = stage_obj(name, description, f"{name}.mtl")
        o.write(os.path.join(args.out_dir, f"{name}.obj"))
        print(f"{os.path.join(args.out_dir, name + '.obj')}: {o.count} vertices, 4 quads and "
              f"{n} sphere triangles")
    with open(os.path.join(args.out_dir, "cornell_spheres.mtl"), "w") as f:
        f.write("# cornell_spheres.mtl, written by scripts/make_material_scenes.py: the "
                "Cornell box's materials,\n# a glass (illum 7, Ni 1.5) and a mirror (white "
                "metal, roughness 0)\n\n" + CORNELL_MTL)
    o, n = cornell_obj()
    o.write(os.path.join(args.out_dir, "cornell_spheres.obj"))
    print(f"{os.path.join(args.out_dir, 'cornell_spheres.obj')}: {o.count} vertices, 6 quads "
          f"and {n} sphere triangles")


if __name__ == "__main__":
    main()
