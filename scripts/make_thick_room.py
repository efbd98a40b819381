#!/usr/bin/env python3
"""Write the thick-walled glTF room of issue 34: crates/rastergi/tests/data/gltf/thick_room.gltf.

A room as an architect's exporter writes one, with the particulars that a real interior has
and the repository's other scenes lack:
- one watertight shell with walls, floor and ceiling 0.2 m thick: an inner box facing in, an
  outer box facing out, and a window cut through the left wall (x = -2) whose four reveals
  join the two, so every face looks into free space;
- every material one-sided (`doubleSided` absent: glTF's default false), Lambertian
  (metallicFactor 0 and KHR_materials_specular's specularFactor 0: no specular layer), flat `NORMAL`s equal to the face normals, no environment;
- a cabinet (a closed box, faces out) standing on the floor;
- a point light under a two-level node hierarchy (parent translated and rotated 90 degrees
  about +y, child translated in the parent's frame), `range` absent;
- a directional light (the sun) at 35 degrees elevation shining in through the window, so its
  light reaches the room only through the hole.

The file is small (base64-embedded buffer). Usage (from the repository root):

    python3 scripts/make_thick_room.py [--out PATH] [--lights point,sun]

--lights picks which lights the file holds (both by default): the per-light references and
renders of the investigation use `point` and `sun` alone.
"""

import argparse
import base64
import json
import math
import struct

INNER = ((-2.0, 0.0, -2.0), (2.0, 2.6, 2.0))
THICKNESS = 0.2
# The window: a hole through the left wall (x from -2.2 to -2.0), y and z ranges.
WINDOW_Y = (0.9, 1.9)
WINDOW_Z = (-0.7, 0.5)
CABINET = ((0.6, 0.0, -1.6), (1.4, 0.8, -0.8))

MATERIALS = [
    # name, base colour (linear)
    ("wall", (0.8, 0.8, 0.8)),
    ("floor", (0.7, 0.6, 0.5)),
    ("red_wall", (0.7, 0.3, 0.25)),
    ("outside", (0.5, 0.5, 0.5)),
    ("cabinet", (0.3, 0.5, 0.7)),
]
M = {name: i for i, (name, _) in enumerate(MATERIALS)}

# The point light: the parent node's translation and rotation (90 degrees about +y), the
# child's translation in the parent's frame. World position = T_p + R_y(90)(T_c)
#   = (0.4, 1.2, -0.2) + (0.4, 1.0, -0.6) = (0.8, 2.2, -0.8), 0.4 m under the ceiling.
POINT_PARENT_T = (0.4, 1.2, -0.2)
POINT_CHILD_T = (0.6, 1.0, 0.4)
POINT_WORLD = (0.8, 2.2, -0.8)
POINT_COLOR, POINT_INTENSITY = (1.0, 0.9, 0.8), 6.0
SUN_ELEVATION, SUN_AZIMUTH = 35.0, 12.0  # degrees; azimuth about +y from the +x axis
SUN_COLOR, SUN_INTENSITY = (1.0, 0.95, 0.9), 30.0
CAMERA_EYE, CAMERA_TARGET, CAMERA_YFOV = (1.6, 1.5, 1.8), (-0.8, 1.0, -1.0), 1.25


def quad(corners, normal):
    """Two triangles of the planar quad `corners` (in order around it), wound
    counter-clockwise about `normal`."""
    a, b, c, d = corners
    e1 = [b[i] - a[i] for i in range(3)]
    e2 = [c[i] - a[i] for i in range(3)]
    n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
    if sum(n[i] * normal[i] for i in range(3)) < 0:
        a, b, c, d = d, c, b, a
    return [(a, b, c), (a, c, d)]


def rect(axis, at, lo, hi, normal_sign):
    """The axis-aligned rectangle {x[axis] = at} x [lo, hi] over the other two axes (lo, hi
    their 2D ranges), facing normal_sign along the axis."""
    u, v = [k for k in range(3) if k != axis]

    def point(pu, pv):
        p = [0.0, 0.0, 0.0]
        p[axis], p[u], p[v] = at, pu, pv
        return tuple(p)

    corners = [point(lo[0], lo[1]), point(hi[0], lo[1]), point(hi[0], hi[1]), point(lo[0], hi[1])]
    normal = [0.0, 0.0, 0.0]
    normal[axis] = float(normal_sign)
    return quad(corners, normal)


def rect_with_hole(axis, at, lo, hi, hole_lo, hole_hi, normal_sign):
    """The rectangle of `rect` less the hole [hole_lo, hole_hi]: the 3 x 3 grid of its cuts
    without the middle, so the pieces share their corners (no T-junctions)."""
    us = (lo[0], hole_lo[0], hole_hi[0], hi[0])
    vs = (lo[1], hole_lo[1], hole_hi[1], hi[1])
    tris = []
    for i in range(3):
        for j in range(3):
            if (i, j) != (1, 1):
                tris += rect(axis, at, (us[i], vs[j]), (us[i + 1], vs[j + 1]), normal_sign)
    return tris


def box_faces(lo, hi, inward):
    """The six faces of the box [lo, hi], each (axis, side, triangles), facing out or in."""
    faces = []
    for axis in range(3):
        u, v = [k for k in range(3) if k != axis]
        for side, at in ((-1, lo[axis]), (1, hi[axis])):
            sign = -side if inward else side
            faces.append((axis, side, rect(axis, at, (lo[u], lo[v]), (hi[u], hi[v]), sign)))
    return faces


def geometry():
    """Triangles per material name: the shell (inner faces by role, outer faces 'outside',
    the window's reveals 'wall') and the cabinet."""
    lo, hi = INNER
    t = THICKNESS
    olo = tuple(c - t for c in lo)
    ohi = tuple(c + t for c in hi)
    groups = {name: [] for name, _ in MATERIALS}
    # y, z ranges of the window in the wall x = const: (u, v) = (y, z) for axis 0.
    hole_lo, hole_hi = (WINDOW_Y[0], WINDOW_Z[0]), (WINDOW_Y[1], WINDOW_Z[1])
    for axis, side, tris in box_faces(lo, hi, inward=True):
        if axis == 0 and side == -1:
            tris = rect_with_hole(0, lo[0], (lo[1], lo[2]), (hi[1], hi[2]), hole_lo, hole_hi, 1)
            groups["wall"] += tris
        elif axis == 1 and side == -1:
            groups["floor"] += tris
        elif axis == 0 and side == 1:
            groups["red_wall"] += tris
        else:
            groups["wall"] += tris
    for axis, side, tris in box_faces(olo, ohi, inward=False):
        if axis == 0 and side == -1:
            tris = rect_with_hole(0, olo[0], (olo[1], olo[2]), (ohi[1], ohi[2]), hole_lo, hole_hi, -1)
        groups["outside"] += tris
    # The reveals, from the outer face (x = -2.2) to the inner one (x = -2), facing into the
    # hole.
    x0, x1 = olo[0], lo[0]
    (y0, y1), (z0, z1) = WINDOW_Y, WINDOW_Z
    groups["wall"] += rect(1, y0, (x0, z0), (x1, z1), 1)  # sill, facing up
    groups["wall"] += rect(1, y1, (x0, z0), (x1, z1), -1)  # lintel, facing down
    groups["wall"] += rect(2, z0, (x0, y0), (x1, y1), 1)
    groups["wall"] += rect(2, z1, (x0, y0), (x1, y1), -1)
    for _, _, tris in box_faces(*CABINET, inward=False):
        groups["cabinet"] += tris
    return groups


def face_normal(tri):
    a, b, c = tri
    e1 = [b[i] - a[i] for i in range(3)]
    e2 = [c[i] - a[i] for i in range(3)]
    n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
    length = math.sqrt(sum(x * x for x in n))
    return tuple(x / length for x in n)


def quat_between(a, b):
    """The unit quaternion (x, y, z, w) turning unit vector a onto unit vector b."""
    cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    dot = sum(a[i] * b[i] for i in range(3))
    q = (*cross, 1.0 + dot)
    length = math.sqrt(sum(x * x for x in q))
    return tuple(x / length for x in q)


def look_rotation(eye, target):
    """The rotation of a glTF camera node at eye looking at target with +y up (the camera
    looks down its local -z), as a quaternion (x, y, z, w)."""
    f = [target[i] - eye[i] for i in range(3)]
    fl = math.sqrt(sum(x * x for x in f))
    f = [x / fl for x in f]
    z = [-x for x in f]  # local +z points backwards
    up = (0.0, 1.0, 0.0)
    x = (up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2], up[0] * z[1] - up[1] * z[0])
    xl = math.sqrt(sum(c * c for c in x))
    x = [c / xl for c in x]
    y = (z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0])
    # Rotation matrix columns x, y, z -> quaternion.
    m00, m01, m02 = x[0], y[0], z[0]
    m10, m11, m12 = x[1], y[1], z[1]
    m20, m21, m22 = x[2], y[2], z[2]
    tr = m00 + m11 + m22
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        return ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s)
    if m00 > m11 and m00 > m22:
        s = math.sqrt(1.0 + m00 - m11 - m22) * 2
        return (0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    if m11 > m22:
        s = math.sqrt(1.0 + m11 - m00 - m22) * 2
        return ((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
    s = math.sqrt(1.0 + m22 - m00 - m11) * 2
    return ((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)


def sun_travel():
    """The unit direction the sunlight travels: down at SUN_ELEVATION, towards +x turned by
    SUN_AZIMUTH about +y."""
    e, a = math.radians(SUN_ELEVATION), math.radians(SUN_AZIMUTH)
    return (math.cos(e) * math.cos(a), -math.sin(e), -math.cos(e) * math.sin(a))


def build(lights):
    groups = geometry()
    data = bytearray()
    buffer_views, accessors, primitives = [], [], []
    for name, _ in MATERIALS:
        tris = groups[name]
        if not tris:
            continue
        positions = [c for tri in tris for c in tri]
        normals = [face_normal(tri) for tri in tris for _ in range(3)]
        for values in (positions, normals):
            offset = len(data)
            for v in values:
                data += struct.pack("<3f", *v)
            buffer_views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data) - offset})
            acc = {"bufferView": len(buffer_views) - 1, "componentType": 5126, "count": len(values),
                   "type": "VEC3"}
            if values is positions:
                acc["min"] = [min(p[k] for p in values) for k in range(3)]
                acc["max"] = [max(p[k] for p in values) for k in range(3)]
            accessors.append(acc)
        primitives.append({"attributes": {"POSITION": len(accessors) - 2, "NORMAL": len(accessors) - 1},
                           "material": M[name]})
    materials = [{"name": name,
                  "pbrMetallicRoughness": {"baseColorFactor": [*colour, 1.0], "metallicFactor": 0.0,
                                           "roughnessFactor": 1.0},
                  # Lambertian: no dielectric specular layer over the diffuse base.
                  "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}
                 for name, colour in MATERIALS]
    nodes = [{"name": "room", "mesh": 0},
             {"name": "camera", "camera": 0, "translation": list(CAMERA_EYE),
              "rotation": list(look_rotation(CAMERA_EYE, CAMERA_TARGET))}]
    punctual = []
    if "point" in lights:
        punctual.append({"type": "point", "name": "bulb", "color": list(POINT_COLOR),
                         "intensity": POINT_INTENSITY})
        s = math.sqrt(0.5)
        nodes.append({"name": "lamp_mount", "translation": list(POINT_PARENT_T), "rotation": [0.0, s, 0.0, s],
                      "children": [len(nodes) + 1]})
        nodes.append({"name": "bulb", "translation": list(POINT_CHILD_T),
                      "extensions": {"KHR_lights_punctual": {"light": len(punctual) - 1}}})
    if "sun" in lights:
        punctual.append({"type": "directional", "name": "sun", "color": list(SUN_COLOR),
                         "intensity": SUN_INTENSITY})
        nodes.append({"name": "sun", "rotation": list(quat_between((0.0, 0.0, -1.0), sun_travel())),
                      "extensions": {"KHR_lights_punctual": {"light": len(punctual) - 1}}})
    gltf = {
        "asset": {"version": "2.0", "generator": "rastergi scripts/make_thick_room.py"},
        "extensionsUsed": ["KHR_materials_specular"],
        "scene": 0,
        "scenes": [{"nodes": [i for i, n in enumerate(nodes) if n["name"] != "bulb"]}],
        "nodes": nodes,
        "meshes": [{"name": "room", "primitives": primitives}],
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": CAMERA_YFOV, "znear": 0.01}}],
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()}],
    }
    if punctual:
        gltf["extensionsUsed"].append("KHR_lights_punctual")
        gltf["extensions"] = {"KHR_lights_punctual": {"lights": punctual}}
    return gltf


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="crates/rastergi/tests/data/gltf/thick_room.gltf")
    p.add_argument("--lights", default="point,sun", help="comma-separated: point, sun")
    args = p.parse_args()
    lights = set(args.lights.split(","))
    if not lights <= {"point", "sun"}:
        p.error(f"--lights: unknown light in {args.lights!r} (point, sun)")
    with open(args.out, "w") as f:
        json.dump(build(lights), f, indent=1)
        f.write("\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
