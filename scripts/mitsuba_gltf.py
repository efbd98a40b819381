"""glTF 2.0 scenes for scripts/mitsuba_reference.py (`--scene PATH.gltf` or `.glb`).

Mitsuba 3 has no glTF loader, so the file is read here, independently of rastergi's loader
(crates/rastergi/src/scene/gltf/mod.rs) but by the same rules, into the groups that
mitsuba_reference.py renders for OBJ files, plus the file's lights and camera:
- the displayed scene (`scene`, else the first; without scenes every root node), walked
  depth first from its root nodes in order; a node's world transform is parent x local
  (`matrix`, or translation x rotation x scale); a transform with a negative determinant
  mirrors its meshes, so their corners are swapped to keep the counter-clockwise front;
- triangle-list primitives (mode 4, indexed or not) with float POSITION; float NORMAL
  (through the inverse transpose of the world transform) gives the shading normals;
- materials that Mitsuba reproduces exactly: Lambertian ones, i.e. metallicFactor 0 with
  `KHR_materials_specular` specularFactor 0 (without it glTF puts a dielectric specular layer
  over the diffuse base, which Mitsuba's BSDFs layer differently), base colour
  baseColorFactor.rgb, emitted radiance emissiveFactor x KHR_materials_emissive_strength,
  `doubleSided` -> twosided(diffuse), else a one-sided `diffuse` (black from behind, as
  rastergi's one-sided surfaces); textures, alpha modes other than OPAQUE, transmission and
  metals are refused with an error naming the material; a primitive without a material is
  grey Lambertian 0.5, two-sided false (glTF's default material is one-sided);
- `KHR_lights_punctual`, read 1:1 as radiometric (color x intensity: W/sr for point and spot
  lights, W/m^2 for directional ones, as rastergi and Mitsuba's `point`, `spot` and
  `directional` take them): a point light at its node's origin, a directional light shining
  along its node's -z; a spot only with equal inner and outer cones (a hard edge: glTF's
  smooth falloff is not Mitsuba's); `range` is ignored (rastergi ignores it too);
- the camera: the first perspective camera met in the walk, at its node's origin looking down
  its -z with its +y up, yfov as the vertical field of view.
"""

import base64
import json
import math
import os
import struct

import numpy as np


class GltfError(Exception):
    pass


COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
DTYPES = {5120: "<i1", 5121: "<u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}


def _split_glb(data, path):
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2:
        raise GltfError(f"{path}: not a glTF 2.0 binary file")
    at, doc, bin_chunk = 12, None, None
    while at + 8 <= min(length, len(data)):
        size, kind = struct.unpack_from("<II", data, at)
        chunk = data[at + 8:at + 8 + size]
        if kind == 0x4E4F534A:
            doc = json.loads(chunk.decode("utf-8"))
        elif kind == 0x004E4942 and bin_chunk is None:
            bin_chunk = chunk
        at += 8 + size
    if doc is None:
        raise GltfError(f"{path}: the binary file has no JSON chunk")
    return doc, bin_chunk


def _buffers(doc, directory, bin_chunk, path):
    out = []
    for i, b in enumerate(doc.get("buffers", [])):
        uri = b.get("uri")
        if uri is None:
            if bin_chunk is None:
                raise GltfError(f"{path}: buffer {i} has no uri and there is no binary chunk")
            data = bin_chunk
        elif uri.startswith("data:"):
            data = base64.b64decode(uri.split(",", 1)[1])
        else:
            from urllib.parse import unquote
            name = os.path.join(directory, unquote(uri))
            try:
                with open(name, "rb") as f:
                    data = f.read()
            except OSError as e:
                raise GltfError(f"{path}: buffer {i} ({name}) cannot be read: {e}")
        out.append(data)
    return out


def _accessor(doc, buffers, index, path):
    """Accessor `index` as a float64 array (count, components)."""
    a = doc["accessors"][index]
    if "sparse" in a:
        raise GltfError(f"{path}: accessor {index} is sparse, which is not read here")
    n, comps = a["count"], COMPONENTS[a["type"]]
    dtype = np.dtype(DTYPES[a["componentType"]])
    if "bufferView" not in a:
        return np.zeros((n, comps))
    view = doc["bufferViews"][a["bufferView"]]
    data = buffers[view["buffer"]]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = view.get("byteStride") or dtype.itemsize * comps
    rows = np.empty((n, comps), dtype=np.float64)
    raw = np.frombuffer(data, dtype=np.uint8)
    for k in range(comps):
        offsets = start + np.arange(n) * stride + k * dtype.itemsize
        bytes_ = raw[offsets[:, None] + np.arange(dtype.itemsize)]
        rows[:, k] = np.frombuffer(bytes_.tobytes(), dtype=dtype)
    if a.get("normalized"):
        raise GltfError(f"{path}: accessor {index} is normalized (quantized), not read here")
    return rows


def _local(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major
    t = np.array(node.get("translation", [0.0, 0.0, 0.0]), dtype=np.float64)
    x, y, z, w = node.get("rotation", [0.0, 0.0, 0.0, 1.0])
    q = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / q, y / q, z / q, w / q
    r = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    s = np.array(node.get("scale", [1.0, 1.0, 1.0]), dtype=np.float64)
    m = np.eye(4)
    m[:3, :3] = r * s[None, :]
    m[:3, 3] = t
    return m


def _material(doc, index, path):
    """A material of mitsuba_reference.load_obj's form, with `two_sided`."""
    if index is None:
        return {"name": "default", "kd": [0.5] * 3, "ke": [0.0] * 3, "d": None, "map_d": None,
                "model": {"kind": "diffuse"}, "two_sided": False}
    m = doc["materials"][index]
    name = m.get("name") or f"material {index}"
    pbr = m.get("pbrMetallicRoughness", {})
    ext = m.get("extensions", {})
    for key, where in (("baseColorTexture", pbr), ("metallicRoughnessTexture", pbr),
                       ("emissiveTexture", m), ("normalTexture", m), ("occlusionTexture", m)):
        if key in where and key != "occlusionTexture":
            raise GltfError(f"{path}: material '{name}' has a {key}; textures are not "
                            "reproduced here")
    if m.get("alphaMode", "OPAQUE") != "OPAQUE":
        raise GltfError(f"{path}: material '{name}' has alphaMode {m['alphaMode']}; only "
                        "OPAQUE is reproduced here")
    if pbr.get("metallicFactor", 1.0) != 0.0:
        raise GltfError(f"{path}: material '{name}' is metallic (metallicFactor "
                        f"{pbr.get('metallicFactor', 1.0)}, glTF's default is 1); only "
                        "Lambertian materials (metallicFactor 0) are reproduced here")
    if ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0) != 0.0:
        raise GltfError(f"{path}: material '{name}' has glTF's dielectric specular layer; give "
                        "it KHR_materials_specular specularFactor 0 (Lambertian), the only "
                        "dielectric reproduced here")
    if ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0) > 0:
        raise GltfError(f"{path}: material '{name}' transmits; glass is not reproduced here")
    kd = [float(v) for v in pbr.get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])[:3]]
    strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    ke = [float(v) * strength for v in m.get("emissiveFactor", [0.0, 0.0, 0.0])]
    return {"name": name, "kd": kd, "ke": ke, "d": None, "map_d": None,
            "model": {"kind": "diffuse"}, "two_sided": bool(m.get("doubleSided", False))}


def load_gltf(path):
    """(groups, lights, camera) of a glTF file: groups as mitsuba_reference.load_obj returns
    them (material with `two_sided`, triangles (n, 3, 3), normals or None, uvs None), lights
    Mitsuba emitter dicts, camera {eye, target, up, fov} or None."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise GltfError(f"{path}: cannot be read: {e}")
    try:
        if data[:4] == b"glTF":
            doc, bin_chunk = _split_glb(data, path)
        else:
            doc, bin_chunk = json.loads(data.decode("utf-8")), None
    except (ValueError, struct.error) as e:  # JSONDecodeError and UnicodeDecodeError too
        raise GltfError(f"{path}: not a valid glTF file ({e})")
    buffers = _buffers(doc, os.path.dirname(path), bin_chunk, path)
    nodes = doc.get("nodes", [])
    scenes = doc.get("scenes", [])
    if scenes:
        roots = scenes[doc.get("scene", 0)].get("nodes", [])
    else:
        children = {c for n in nodes for c in n.get("children", [])}
        roots = [i for i in range(len(nodes)) if i not in children]
    lights_ext = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])

    groups = {}  # material index -> [triangles], [normals or None]
    lights, camera = [], None
    stack = [(i, np.eye(4)) for i in reversed(roots)]
    while stack:
        i, parent = stack.pop()
        node = nodes[i]
        world = parent @ _local(node)
        if "mesh" in node:
            _add_mesh(doc, buffers, node["mesh"], world, groups, path)
        if "camera" in node and camera is None:
            cam = doc["cameras"][node["camera"]]
            if cam.get("type") == "perspective":
                eye = world[:3, 3]
                forward = world[:3, :3] @ np.array([0.0, 0.0, -1.0])
                up = world[:3, :3] @ np.array([0.0, 1.0, 0.0])
                forward /= np.linalg.norm(forward)
                camera = {"eye": [float(v) for v in eye],
                          "target": [float(v) for v in eye + forward],
                          "up": [float(v) for v in up / np.linalg.norm(up)],
                          "fov": math.degrees(cam["perspective"]["yfov"])}
        light = node.get("extensions", {}).get("KHR_lights_punctual", {}).get("light")
        if light is not None:
            lights.append(_light(lights_ext[light], world, path))
        stack.extend((c, world) for c in reversed(node.get("children", [])))

    result = []
    for index, (tris, normals) in groups.items():
        material = _material(doc, index, path)
        triangles = np.concatenate(tris).astype(np.float32)
        vertex_normals = None
        if all(n is not None for n in normals):
            vertex_normals = np.concatenate(normals).astype(np.float32)
        result.append((material, triangles, vertex_normals, None))
    if not result:
        raise GltfError(f"{path}: the displayed scene has no triangles")
    return result, lights, camera


def _add_mesh(doc, buffers, mesh_index, world, groups, path):
    mirrored = np.linalg.det(world[:3, :3]) < 0
    normal_matrix = np.linalg.inv(world[:3, :3]).T
    for p in doc["meshes"][mesh_index]["primitives"]:
        if p.get("mode", 4) != 4:
            raise GltfError(f"{path}: mesh {mesh_index} has a primitive of mode {p['mode']}; "
                            "only triangle lists (4) are read here")
        attributes = p["attributes"]
        pos = _accessor(doc, buffers, attributes["POSITION"], path)
        pos = pos @ world[:3, :3].T + world[:3, 3]
        if "indices" in p:
            idx = _accessor(doc, buffers, p["indices"], path)[:, 0].astype(np.int64)
        else:
            idx = np.arange(len(pos))
        idx = idx[:len(idx) // 3 * 3].reshape(-1, 3)
        if mirrored:
            idx = idx[:, [0, 2, 1]]
        normals = None
        if "NORMAL" in attributes:
            n = _accessor(doc, buffers, attributes["NORMAL"], path) @ normal_matrix.T
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
            normals = n[idx]
        tris, ns = groups.setdefault(p.get("material"), ([], []))
        tris.append(pos[idx])
        ns.append(normals)


def _light(light, world, path):
    colour = [float(c) * float(light.get("intensity", 1.0))
              for c in light.get("color", [1.0, 1.0, 1.0])]
    rgb = {"type": "rgb", "value": colour}
    origin = world[:3, 3]
    axis = world[:3, :3] @ np.array([0.0, 0.0, -1.0])
    axis /= np.linalg.norm(axis)
    kind = light["type"]
    if kind == "point":
        return {"type": "point", "position": [float(v) for v in origin], "intensity": rgb}
    if kind == "directional":
        return {"type": "directional", "direction": [float(v) for v in axis], "irradiance": rgb}
    if kind == "spot":
        spot = light.get("spot", {})
        inner = spot.get("innerConeAngle", 0.0)
        outer = spot.get("outerConeAngle", math.pi / 4)
        if inner != outer:
            raise GltfError(f"{path}: a spot light with inner cone {inner} and outer cone "
                            f"{outer}: glTF's smooth falloff is not Mitsuba's; only equal "
                            "cones (a hard edge) are reproduced here")
        import mitsuba as mi
        target = origin + axis
        k = int(np.argmin(np.abs(axis)))
        up = [1.0 if j == k else 0.0 for j in range(3)]
        return {"type": "spot", "intensity": rgb, "cutoff_angle": math.degrees(outer),
                "beam_width": math.degrees(outer),
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=[float(v) for v in origin], target=[float(v) for v in target], up=up)}
    raise GltfError(f"{path}: a light of unknown type '{kind}'")
