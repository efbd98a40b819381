#!/usr/bin/env python3
"""Writes a binary glTF (.glb) of about N triangles (default 100 000): a grid of UV spheres on
a floor, lit by an emissive quad above them, with a camera. The web page's test drops it on the
page (scripts/web-test.sh --file): a real-sized glTF through the browser's loader.

Usage: make_big_glb.py OUT.glb [--triangles N]
"""
import argparse
import json
import math
import struct


def sphere(cx, cy, cz, r, rings, segments):
    """Triangles of a UV sphere, counter-clockwise seen from outside."""
    tris = []
    def p(i, j):
        th, ph = math.pi * i / rings, 2 * math.pi * j / segments
        return (cx + r * math.sin(th) * math.cos(ph), cy + r * math.cos(th), cz + r * math.sin(th) * math.sin(ph))
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)
            if i > 0:
                tris.append((a, d, c))
            if i < rings - 1:
                tris.append((a, c, b))
    return tris


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--triangles", type=int, default=100_000)
    a = ap.parse_args()
    side = 5  # spheres per row
    per_sphere = a.triangles // (side * side)
    rings = max(3, int(math.sqrt(per_sphere / 2)))
    segments = max(3, -(-per_sphere // (2 * (rings - 1))))
    groups = {"floor": [], "spheres": [], "light": []}
    s = 10.0
    groups["floor"] += [((-s, 0, -s), (-s, 0, s), (s, 0, s)), ((-s, 0, -s), (s, 0, s), (s, 0, -s))]
    for i in range(side):
        for k in range(side):
            groups["spheres"] += sphere(-6 + 3 * i, 1.0, -6 + 3 * k, 1.0, rings, segments)
    h, l = 8.0, 3.0  # the light faces down
    groups["light"] += [((-l, h, -l), (l, h, -l), (l, h, l)), ((-l, h, -l), (l, h, l), (-l, h, l))]

    materials = [
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1], "metallicFactor": 0}},
        {"name": "spheres", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.4, 0.2, 1], "metallicFactor": 0}},
        {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0},
         "emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 20}}},
    ]
    binary, views, accessors, primitives = b"", [], [], []
    for m, name in enumerate(groups):
        points = [c for t in groups[name] for c in t]
        data = b"".join(struct.pack("<3f", *c) for c in points)
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)})
        binary += data
        lo = [min(c[i] for c in points) for i in range(3)]
        hi = [max(c[i] for c in points) for i in range(3)]
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(points),
                          "type": "VEC3", "min": lo, "max": hi})
        primitives.append({"attributes": {"POSITION": len(accessors) - 1}, "material": m})
    triangles = sum(len(g) for g in groups.values())
    doc = {
        "asset": {"version": "2.0", "generator": f"rastergi scripts/make_big_glb.py ({triangles} triangles)"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 6, 16],
                                "rotation": [-math.sin(0.175), 0, 0, math.cos(0.175)]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "meshes": [{"primitives": primitives}],
        "materials": materials,
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(binary))
    glb += struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    with open(a.out, "wb") as f:
        f.write(glb)
    print(f"{a.out}: {triangles} triangles")


if __name__ == "__main__":
    main()
