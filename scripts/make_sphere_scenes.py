#!/usr/bin/env python3
"""Write the test scenes `sphere_smooth.obj` and `sphere_flat.obj` (+ the shared `sphere.mtl`).

A grey floor quad (y = 0, x and z in [-2, 2], Kd 0.6) carrying a low-poly UV sphere of radius
0.7 centred at (0, 0.7, 0) (Kd 0.8 0.5 0.3): 12 segments around the y axis and 6 rings from
pole to pole, triangles at the poles and quads split into two triangles elsewhere (120
triangles, 62 vertices; the lower pole touches the floor at the origin). Every face is wound
counter-clockwise seen from the side its normal faces: the floor's up, the sphere's outward.

`sphere_smooth.obj` gives every sphere corner its vertex's exact unit radial normal through
`vn` (faces `f v//vn`; one `vn` per sphere vertex), for smooth shading normals; the floor's
face has no `vn`. `sphere_flat.obj` is the same geometry without any `vn` (face normals: the
facets show). No emitters: light them with an environment map (crates/rastergi/tests/data/
README.md). Plain Python, no dependencies.

    python3 scripts/make_sphere_scenes.py                  # into crates/rastergi/tests/data/obj
    python3 scripts/make_sphere_scenes.py --out-dir DIR
"""
import os

from obj_geometry import cross, dot, num, out_dir_args, sub, uv_sphere

RADIUS = 0.7
CENTRE = (0.0, 0.7, 0.0)
SEGMENTS = 12  # around the y axis
RINGS = 6  # bands from the upper pole to the lower one
FLOOR_HALF = 2.0

MTL = """# scripts/make_sphere_scenes.py: the materials of sphere_smooth.obj and sphere_flat.obj

newmtl floor
Kd 0.6 0.6 0.6

newmtl sphere
Kd 0.8 0.5 0.3
"""


def main():
    args = out_dir_args(__doc__)

    h = FLOOR_HALF
    floor = [(-h, 0.0, h), (h, 0.0, h), (h, 0.0, -h), (-h, 0.0, -h)]
    dirs, tris = uv_sphere(RINGS, SEGMENTS)
    points = [tuple(c + RADIUS * d for c, d in zip(CENTRE, dv)) for dv in dirs]

    # Counter-clockwise seen from outside: every face normal points away from the centre,
    # and up for the floor.
    n = cross(sub(floor[1], floor[0]), sub(floor[2], floor[0]))
    assert n[1] > 0 and n[0] == n[2] == 0
    for t in tris:
        a, b, c = (points[k] for k in t)
        centroid = tuple((x + y + z) / 3 for x, y, z in zip(a, b, c))
        assert dot(cross(sub(b, a), sub(c, a)), sub(centroid, CENTRE)) > 0, t
    assert all(abs(dot(d, d) - 1) < 1e-15 for d in dirs)

    os.makedirs(args.out_dir, exist_ok=True)
    with open(os.path.join(args.out_dir, "sphere.mtl"), "w") as f:
        f.write(MTL)
    for smooth in (True, False):
        name = "sphere_smooth" if smooth else "sphere_flat"
        lines = [
            f"# {name}.obj, written by scripts/make_sphere_scenes.py: a floor quad (y = 0,"
            f" x, z in [-{h:g}, {h:g}]) and",
            f"# a UV sphere of radius {RADIUS:g} centred at ({', '.join(f'{c:g}' for c in CENTRE)}),"
            f" {SEGMENTS} segments x {RINGS} rings, {len(tris)} triangles,",
            ("# counter-clockwise seen from outside; every sphere corner has its vertex's exact "
             "unit radial normal (vn)." if smooth else
             "# counter-clockwise seen from outside; no vertex normals (the same geometry as "
             "sphere_smooth.obj)."),
            "mtllib sphere.mtl",
            "",
            "# floor, 1-4",
        ]
        lines += [f"v {num(x)} {num(y)} {num(z)}" for x, y, z in floor]
        lines.append(f"# sphere, 5-{4 + len(points)}: the upper pole, {RINGS - 1} rings of "
                     f"{SEGMENTS} from the top, the lower pole")
        lines += [f"v {num(x)} {num(y)} {num(z)}" for x, y, z in points]
        if smooth:
            lines.append(f"# the sphere's unit radial normals, 1-{len(dirs)}: vn k is the normal "
                         "of v k+4")
            lines += [f"vn {num(x)} {num(y)} {num(z)}" for x, y, z in dirs]
        lines += ["", "usemtl floor", "f 1 2 3 4", "", "usemtl sphere"]
        for t in tris:
            if smooth:
                lines.append("f " + " ".join(f"{k + 5}//{k + 1}" for k in t))
            else:
                lines.append("f " + " ".join(f"{k + 5}" for k in t))
        with open(os.path.join(args.out_dir, f"{name}.obj"), "w") as f:
            f.write("\n".join(lines) + "\n")
        print(f"{os.path.join(args.out_dir, name + '.obj')}: {4 + len(points)} vertices, "
              f"{1 + len(tris)} faces{f', {len(dirs)} normals' if smooth else ''}")


if __name__ == "__main__":
    main()
