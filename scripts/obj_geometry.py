"""What the OBJ test-scene writers share (make_material_scenes.py, make_sphere_scenes.py,
make_alpha_card_scene.py): 3-vectors as tuples, numbers as OBJ text, a UV sphere's topology and
the `--out-dir` option. Plain Python, no dependencies."""
import argparse
import math
import os


def clean(x):
    """Rounding residue of sin/cos (1e-16 for an exact 0) written as 0."""
    return 0.0 if abs(x) < 1e-12 else x


def num(x):
    """A coordinate as OBJ text: nine significant digits, sin/cos residue as 0."""
    return f"{clean(x):.9g}"


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def scale(s, a):
    return tuple(s * x for x in a)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def normal(a, b, c):
    """The (unnormalised) normal of triangle a, b, c: counter-clockwise about it."""
    return cross(sub(b, a), sub(c, a))


def uv_sphere(rings, segments):
    """A UV sphere: the unit radial directions of its vertices (the upper pole, rings - 1 rings
    of `segments` from the top, the lower pole) and its triangles (0-based indices; fans at
    the poles, quads split into two triangles elsewhere), counter-clockwise seen from outside."""
    dirs = [(0.0, 1.0, 0.0)]  # upper pole
    for i in range(1, rings):
        th = math.pi * i / rings
        for j in range(segments):
            ph = 2 * math.pi * j / segments
            dirs.append((clean(math.sin(th) * math.sin(ph)), clean(math.cos(th)),
                         clean(math.sin(th) * math.cos(ph))))
    dirs.append((0.0, -1.0, 0.0))  # lower pole
    top, bottom = 0, len(dirs) - 1

    def ring(i, j):  # vertex j of ring i (1 .. rings-1)
        return 1 + (i - 1) * segments + j % segments

    tris = []
    for j in range(segments):
        tris.append((top, ring(1, j), ring(1, j + 1)))
        for i in range(1, rings - 1):
            a, b = ring(i, j), ring(i, j + 1)
            c, d = ring(i + 1, j), ring(i + 1, j + 1)
            tris.append((a, c, d))
            tris.append((a, d, b))
        tris.append((ring(rings - 1, j), bottom, ring(rings - 1, j + 1)))
    assert len(dirs) == 2 + (rings - 1) * segments and len(tris) == 2 * segments * (rings - 1)
    return dirs, tris


def out_dir_args(doc):
    """The writers' command line: `--out-dir` (default crates/rastergi/tests/data/obj)."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    here = os.path.dirname(os.path.abspath(__file__))
    p.add_argument("--out-dir", default=os.path.relpath(os.path.join(
        here, "..", "crates", "rastergi", "tests", "data", "obj")))
    return p.parse_args()
