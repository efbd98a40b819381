#!/usr/bin/env python3
"""Write the test scene `small_object.obj` + `.mtl`: a small detailed object in a large hall.

The fitted photon grid spends its cells on the scene's bounds, so a 30 cm object in a
16 × 6 × 16 m hall gets cells of about 25 cm: the case where a coarse map hurts most
(crates/rastergi/tests/photon_passes.rs compares it with a Mitsuba 3 reference). The hall
(white, one red wall) is lit by a 2 × 2 m ceiling light; at its centre a green box 30 × 20 ×
30 cm carries a white UV sphere of radius 10 cm (16 × 12 segments) touching its top. Every
quad is wound counter-clockwise seen from the side its normal faces: the hall's faces
inward, the object's outward, the light downward.

    python3 scripts/small_object_scene.py crates/rastergi/tests/data/obj/small_object.obj
"""
import math
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "small_object.obj"
mtl = out[:-4] + ".mtl"
verts, faces = [], []  # faces: (material, [vertex indices 1-based])


def quad(material, corners):
    base = len(verts) + 1
    verts.extend(corners)
    faces.append((material, [base, base + 1, base + 2, base + 3]))


def box(material, lo, hi, inward):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    # Each face: corners counter-clockwise seen from outside (normal outward).
    sides = [
        [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],  # +x
        [(x0, y0, z1), (x0, y1, z1), (x0, y1, z0), (x0, y0, z0)],  # -x
        [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],  # +y
        [(x0, y0, z1), (x0, y0, z0), (x1, y0, z0), (x1, y0, z1)],  # -y
        [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],  # +z
        [(x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)],  # -z
    ]
    for i, c in enumerate(sides):
        m = material(i) if callable(material) else material
        quad(m, c[::-1] if inward else c)


# The hall, inward; its -x wall red.
box(lambda i: "red" if i == 1 else "white", (-8, 0, -8), (8, 6, 8), inward=True)
# The light, 2 cm under the ceiling, facing down (counter-clockwise seen from below).
y = 5.98
quad("light", [(-1, y, -1), (1, y, -1), (1, y, 1), (-1, y, 1)])
# The object: a green box and a white sphere resting on it.
box("green", (-0.15, 0, -0.15), (0.15, 0.2, 0.15), inward=False)
r, cy, seg, rings = 0.1, 0.3, 16, 12
ring0 = len(verts) + 1
for j in range(rings + 1):
    th = math.pi * j / rings
    for i in range(seg):
        ph = 2 * math.pi * i / seg
        verts.append((r * math.sin(th) * math.cos(ph), cy + r * math.cos(th), r * math.sin(th) * math.sin(ph)))
for j in range(rings):
    for i in range(seg):
        a = ring0 + j * seg + i
        b = ring0 + j * seg + (i + 1) % seg
        c, d = a + seg, b + seg
        # Outward: (a, b, d, c) runs counter-clockwise seen from outside.
        if j == 0:
            faces.append(("white", [a, d, c]))
        elif j == rings - 1:
            faces.append(("white", [a, b, c]))
        else:
            faces.append(("white", [a, b, d, c]))

with open(out, "w") as f:
    f.write("# A small detailed object in a large hall: scripts/small_object_scene.py\n")
    f.write(f"mtllib {mtl.split('/')[-1]}\n")
    for v in verts:
        f.write("v %.6f %.6f %.6f\n" % v)
    current = None
    for m, idx in faces:
        if m != current:
            f.write(f"usemtl {m}\n")
            current = m
        f.write("f " + " ".join(map(str, idx)) + "\n")
with open(mtl, "w") as f:
    f.write("# scripts/small_object_scene.py\n")
    for name, kd, ke in [("white", "0.7 0.7 0.7", None), ("red", "0.7 0.15 0.1", None),
                         ("green", "0.15 0.6 0.2", None), ("light", "0.7 0.7 0.7", "12 12 12")]:
        f.write(f"\nnewmtl {name}\nKd {kd}\n")
        if ke:
            f.write(f"Ke {ke}\n")
print(f"{out}: {len(verts)} vertices, {len(faces)} faces")
