#!/usr/bin/env python3
"""Writes the seed corpus of each fuzz target into fuzz/corpus/TARGET/ (not committed: it
copies files of ../shared/scenes): the suite's own files (crates/rastergi/tests/data), the
published scenes of ../shared/scenes where that folder exists, and small files generated here
for the formats the suite has few of (PLY, .serialized, Radiance HDR, checkpoints). Inputs
that hold several files join them as rastergi::fuzzing::files_of reads them: the first file,
then for each further one a line "#file NAME" and its bytes.

    python3 fuzz/seeds.py            # then: cd fuzz && cargo +nightly fuzz run TARGET

Files too large for a quick fuzzer (over MAX_FILE bytes) are left out; the meshes and images
a shared scene names beyond that are replaced by a small one, so the scene loads past them.
"""

import os
import re
import struct
import sys
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, 'crates', 'rastergi', 'tests', 'data')
SHARED = os.path.join(os.path.dirname(ROOT), 'shared', 'scenes')
OUT = os.path.join(ROOT, 'fuzz', 'corpus')
MAX_FILE = 64 << 10
MAX_INPUT = 256 << 10


def read(path):
    with open(path, 'rb') as f:
        return f.read()


def join(main, others):
    """main bytes, then each (name, bytes) after a line '#file NAME'."""
    out = main
    for name, data in others:
        out += b'\n#file ' + name.encode() + b'\n' + data
    return out


def write(target, name, data):
    if len(data) > MAX_INPUT:
        print(f'  {target}/{name}: {len(data)} bytes, left out', file=sys.stderr)
        return
    folder = os.path.join(OUT, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), 'wb') as f:
        f.write(data)


def png(w, h, rgba=False):
    """A small PNG: a gradient, RGB or RGBA."""
    channels = 4 if rgba else 3
    def row(y):
        return b'\0' + b''.join(bytes((x * 255 // max(w - 1, 1), y * 255 // max(h - 1, 1), 128, 200)[:channels])
                                 for x in range(w))
    raw = b''.join(row(y) for y in range(h))

    def chunk(t, d):
        return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    ihdr = struct.pack('>IIBBBBB', w, h, 8, 6 if rgba else 2, 0, 0, 0)
    return b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', ihdr) + chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b'')


QUAD_OBJ = b'v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n'
SMALL_PNG = png(4, 4)

# --- Mitsuba XML ------------------------------------------------------------------------------

NAMED = re.compile(rb'(?:value|filename)="([^"$]+\.(?:obj|ply|serialized|png|jpg|jpeg|JPG|PNG|xml|exr|hdr|tga))"')


def mitsuba(path, substitute):
    """A scene file and the files it names (includes too), small ones as they are; with
    `substitute`, larger or missing meshes and images become small ones of the same kind."""
    folder = os.path.dirname(path)
    main = read(path)
    files, seen, todo = [], set(), [main]
    while todo:
        text = todo.pop()
        for name in NAMED.findall(text):
            name = name.decode()
            if name in seen:
                continue
            seen.add(name)
            full = os.path.join(folder, name.replace('\\', '/'))
            size = os.path.getsize(full) if os.path.isfile(full) else None
            room = not substitute or sum(len(d) for _, d in files) + (size or 0) <= 48 << 10
            if size is not None and size <= MAX_FILE and room:
                data = read(full)
                files.append((name, data))
                if name.endswith('.xml'):
                    todo.append(data)
            elif substitute:
                # Named instead: one small file of its kind.
                kind = name.lower().rsplit('.', 1)[-1]
                kind = 'png' if kind in ('jpg', 'jpeg', 'tga') else kind
                small = {'obj': QUAD_OBJ, 'png': SMALL_PNG, 'ply': ply_ascii(), 'serialized': serialized_mesh(4)}
                if kind in small:
                    main = main.replace(b'"' + name.encode() + b'"', f'"small.{kind}"'.encode())
                    if ('small.' + kind) not in seen:
                        seen.add('small.' + kind)
                        files.append(('small.' + kind, small[kind]))
    return main, files


def mitsuba_seeds():
    folder = os.path.join(DATA, 'mitsuba')
    for name in sorted(os.listdir(folder)):
        if name.endswith('.xml'):
            main, files = mitsuba(os.path.join(folder, name), False)
            write('mitsuba_xml', name, join(main, files))
    for scene in ('classroom', 'staircase', 'sponza'):
        path = os.path.join(SHARED, scene, 'scene.xml')
        if os.path.isfile(path):
            main, files = mitsuba(path, True)
            write('mitsuba_xml', f'shared_{scene}.xml', join(main, files))
    head = b'<scene version="3.0.0">\n'
    write('mitsuba_xml', 'defaults_and_include.xml', join(
        head + b'<default name="r" value="0.5"/><default name="f" value="part"/>\n<include filename="$f.xml"/>\n'
        b'<shape type="sphere"><float name="radius" value="$r"/><bsdf type="roughplastic"><float name="alpha" value="0.2"/>'
        b'<texture type="bitmap" name="diffuse_reflectance"><string name="filename" value="t.png"/></texture></bsdf></shape>\n'
        b'<emitter type="envmap"><string name="filename" value="sky.exr"/></emitter></scene>\n',
        [('part.xml', head + b'<shape type="obj"><string name="filename" value="quad.obj"/>'
                             b'<emitter type="area"><rgb name="radiance" value="1 2 3"/></emitter></shape></scene>\n'),
         ('quad.obj', QUAD_OBJ), ('t.png', SMALL_PNG),
         ('sky.exr', read(os.path.join(DATA, 'env', 'sky_64x32.exr')))]))
    write('mitsuba_xml', 'entity.xml', b'<?xml version="1.0"?>\n<!DOCTYPE scene [<!ENTITY r "0.25"><!ENTITY s "&r; &r;">]>\n'
          + head + b'<shape type="cube"><bsdf type="diffuse"><rgb name="reflectance" value="&s; &r;"/></bsdf></shape>'
          b'<emitter type="constant"><spectrum name="radiance" value="400:1, 700:2"/></emitter></scene>\n')
    write('mitsuba_xml', 'instances.xml', head + b'<shape type="shapegroup" id="g"><shape type="rectangle"/></shape>'
          b'<shape type="instance"><ref id="g"/><transform name="to_world"><rotate y="1" angle="30"/></transform></shape>'
          b'<emitter type="point"><point name="position" x="0" y="2" z="0"/></emitter>'
          b'<sensor type="perspective"><float name="fov" value="45"/><film type="hdrfilm"><integer name="width" value="8"/>'
          b'<integer name="height" value="8"/></film></sensor></scene>\n')

# --- PLY --------------------------------------------------------------------------------------


def ply_ascii():
    return (b'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n'
            b'property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n'
            b'element face 1\nproperty list uchar int vertex_indices\nend_header\n'
            b'0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n')


def ply_binary(endian):
    fmt = '<' if endian == 'little' else '>'
    head = (f'ply\nformat binary_{endian}_endian 1.0\ncomment a comment\nelement vertex 3\nproperty double x\n'
            'property double y\nproperty double z\nproperty uchar red\nelement face 1\n'
            'property list uchar uint vertex_indices\nelement extra 1\nproperty short s\nend_header\n').encode()
    body = b''
    for v in ((0, 0, 0), (1, 0, 0), (0, 1, 0)):
        body += struct.pack(fmt + 'dddB', *v, 200)
    body += struct.pack(fmt + 'BIII', 3, 0, 1, 2) + struct.pack(fmt + 'h', 7)
    return head + body


def ply_seeds():
    write('ply', 'quad.ply', read(os.path.join(DATA, 'mitsuba', 'quad.ply')))
    write('ply', 'ascii.ply', ply_ascii())
    write('ply', 'little.ply', ply_binary('little'))
    write('ply', 'big.ply', ply_binary('big'))

# --- .serialized ------------------------------------------------------------------------------


def serialized_mesh(n, version=4, flags=0x1000 | 0x0001 | 0x0002):
    """One mesh of an n-gon fan (n ≥ 3 vertices) with normals and uvs, and its dictionary."""
    body = struct.pack('<I', flags) + (b'fan\0' if version >= 4 else b'') + struct.pack('<QQ', n, n - 2)
    import math
    pos = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n), 0.0) for k in range(n)]
    body += b''.join(struct.pack('<fff', *p) for p in pos)
    if flags & 1:
        body += b''.join(struct.pack('<fff', 0, 0, 1) for _ in pos)
    if flags & 2:
        body += b''.join(struct.pack('<ff', p[0], p[1]) for p in pos)
    body += b''.join(struct.pack('<III', 0, k, k + 1) for k in range(1, n - 1))
    mesh = struct.pack('<HH', 0x041C, version) + zlib.compress(body)
    offsets = struct.pack('<Q', 0) if version >= 4 else struct.pack('<I', 0)
    return mesh + offsets + struct.pack('<I', 1)


def serialized_seeds():
    write('serialized', 'fan_v4.bin', b'\0' + serialized_mesh(6))
    write('serialized', 'fan_v3.bin', b'\0' + serialized_mesh(5, 3, 0x1000))
    path = os.path.join(SHARED, 'sponza', 'sponza.serialized')
    if not os.path.isfile(path):
        return
    data = read(path)
    count = struct.unpack('<I', data[-4:])[0]
    offsets = list(struct.unpack(f'<{count}Q', data[-4 - 8 * count:-4]))
    ends = offsets[1:] + [len(data) - 4 - 8 * count]
    # Each of the smallest meshes alone, and three of them together (shape_index 2).
    sizes = sorted(range(count), key=lambda k: ends[k] - offsets[k])
    for k in sizes[:6]:
        mesh = data[offsets[k]:ends[k]]
        write('serialized', f'sponza_mesh_{k}.bin', b'\0' + mesh + struct.pack('<QI', 0, 1))
    three = b''
    table = []
    for k in sizes[:3]:
        table.append(len(three))
        three += data[offsets[k]:ends[k]]
    write('serialized', 'sponza_three.bin', b'\2' + three + struct.pack('<3QI', *table, 3))

# --- OBJ + MTL --------------------------------------------------------------------------------

MTL_NAMES = re.compile(rb'^\s*mtllib\s+(.+)$', re.M)
MAP_NAMES = re.compile(rb'^\s*(?:map_\w+|bump|disp)\s+(?:-\S+\s+(?:[-\d.]+\s+)*)*(\S+)\s*$', re.M)


def obj(path):
    folder = os.path.dirname(path)
    main, files = read(path), []
    for line in MTL_NAMES.findall(main):
        for name in line.split():
            full = os.path.join(folder, name.decode(errors='replace'))
            if os.path.isfile(full) and os.path.getsize(full) <= MAX_FILE:
                mtl = read(full)
                files.append((name.decode(), mtl))
                for tex in MAP_NAMES.findall(mtl):
                    t = os.path.join(folder, tex.decode(errors='replace'))
                    small = os.path.isfile(t) and os.path.getsize(t) <= MAX_FILE
                    files.append((tex.decode(errors='replace'), read(t) if small else SMALL_PNG))
    return join(main, files)


def obj_seeds():
    folder = os.path.join(DATA, 'obj')
    for name in sorted(os.listdir(folder)):
        if name.endswith('.obj'):
            write('obj_mtl', name, obj(os.path.join(folder, name)))
    path = os.path.join(SHARED, 'cornell-box-original', 'CornellBox-Original.obj')
    if os.path.isfile(path):
        write('obj_mtl', 'shared_cornell.obj', obj(path))
    for scene in ('staircase', 'classroom'):
        models = os.path.join(SHARED, scene, 'models')
        if os.path.isdir(models):
            meshes = sorted((os.path.getsize(os.path.join(models, m)), m) for m in os.listdir(models))
            for size, m in [x for x in meshes if 2000 < x[0] <= 24 << 10][:4]:
                write('obj_mtl', f'shared_{scene}_{m}', read(os.path.join(models, m)))
    write('obj_mtl', 'smoothing.obj', b'mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\nvt 0 0\nvt 1 1\n'
          b's 1\nusemtl a\nf 1/1 2/2 3/1\nf 1 3 4\ns off\nf -1 -2 -3\n'
          b'\n#file m.mtl\nnewmtl a\nKd 0.5 0.5 0.5\nKe 1\nd 0.5\nPr 0.3\nPm 0.1\nPc 1\nmap_Kd -s 2 2 -o 0.5 0 t.png\n'
          b'map_d a.png\nillum 2\nnewmtl g\nillum 7\nNi 1.33\nTf 0.9 1 1\n'
          b'\n#file t.png\n' + SMALL_PNG + b'\n#file a.png\n' + png(3, 2, True))

# --- glTF -------------------------------------------------------------------------------------


def gltf(path, as_glb):
    import json
    folder = os.path.dirname(path)
    doc = json.loads(read(path))
    files = []
    for image in doc.get('images', []):
        uri = image.get('uri')
        if uri and not uri.startswith('data:'):
            files.append((uri, SMALL_PNG))
    bins = []
    for buf in doc.get('buffers', []):
        uri = buf.get('uri')
        if uri and not uri.startswith('data:'):
            full = os.path.join(folder, uri)
            if not os.path.isfile(full) or os.path.getsize(full) > 300 << 10:
                return None
            bins.append((uri, read(full)))
    if as_glb and len(bins) == 1:
        del doc['buffers'][0]['uri']
        js = json.dumps(doc).encode()
        js += b' ' * (-len(js) % 4)
        bin_ = bins[0][1] + b'\0' * (-len(bins[0][1]) % 4)
        body = struct.pack('<I4s', len(js), b'JSON') + js + struct.pack('<I4s', len(bin_), b'BIN\0') + bin_
        return join(b'glTF' + struct.pack('<II', 2, 12 + len(body)) + body, files)
    return join(read(path), bins + files)


def gltf_seeds():
    write('gltf', 'thick_room.gltf', read(os.path.join(DATA, 'gltf', 'thick_room.gltf')))
    corpus = os.path.join(DATA, 'gltf', 'corpus')
    for name in sorted(os.listdir(corpus)):
        if name.endswith(('.gltf', '.glb')):
            write('gltf', 'corpus_' + name, read(os.path.join(corpus, name)))
    folder = os.path.join(SHARED, 'gltf')
    if os.path.isdir(folder):
        for model in sorted(os.listdir(folder)):
            path = os.path.join(folder, model, 'glTF', model + '.gltf')
            if not os.path.isfile(path):
                continue
            for as_glb in (False, True):
                seed = gltf(path, as_glb)
                if seed is not None and len(seed) <= MAX_INPUT:
                    write('gltf', f'shared_{model}.{"glb" if as_glb else "gltf"}', seed)
                elif not as_glb:
                    write('gltf', f'shared_{model}_json_only.gltf', read(path))

# --- EXR and HDR ------------------------------------------------------------------------------


def rgbe(r, g, b):
    import math
    v = max(r, g, b)
    if v < 1e-32:
        return bytes(4)
    m, e = math.frexp(v)
    s = m * 256.0 / v
    return bytes((int(r * s), int(g * s), int(b * s), e + 128))


def hdr(w, h, rle):
    head = f'#?RADIANCE\n# rastergi seed\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n-Y {h} +X {w}\n'.encode()
    out = head
    for y in range(h):
        px = [rgbe(0.1 + x / w, 0.5 * y / h + 0.01, 2.0 if x == 3 else 0.2) for x in range(w)]
        if not rle:
            out += b''.join(px)
            continue
        out += bytes((2, 2, w >> 8, w & 255))
        for c in range(4):
            data = bytes(p[c] for p in px)
            i = 0
            while i < w:
                run = 1
                while i + run < w and run < 127 and data[i + run] == data[i]:
                    run += 1
                if run > 2:
                    out += bytes((128 + run, data[i]))
                    i += run
                else:
                    n = min(128, w - i)
                    out += bytes((n,)) + data[i:i + n]
                    i += n
    return out


def image_seeds():
    write('exr', 'sky_64x32.exr', read(os.path.join(DATA, 'env', 'sky_64x32.exr')))
    refs = sorted((os.path.getsize(os.path.join(DATA, n)), n) for n in os.listdir(DATA) if n.endswith('.exr'))
    for size, n in refs[:3]:
        write('exr', n, read(os.path.join(DATA, n)))
    write('hdr', 'flat_16x8.hdr', hdr(16, 8, False))
    write('hdr', 'rle_64x32.hdr', hdr(64, 32, True))
    write('hdr', 'rle_7x3.hdr', hdr(7, 3, True))
    env = os.path.join(SHARED, 'env')
    if os.path.isdir(env):
        for n in sorted(os.listdir(env)):
            # The header and the first rows of a published sky.
            write('hdr', 'shared_head_' + n, read(os.path.join(env, n))[:48 << 10])

# --- Checkpoints ------------------------------------------------------------------------------


def checkpoint(w, h, settings, gather=(0, 0)):
    """A checkpoint of a w × h film; its last 8 bytes (the checksum) zero: the target makes
    them right for its second reading."""
    text = ''.join(f'{k}={v}\n' for k, v in settings).encode()
    count = 4 * 3 * w * h
    body = b'RGICKPT\0' + struct.pack('<IQI', 1, 0x1234_5678_9abc_def0, 7) + struct.pack('<I', len(text)) + text
    body += struct.pack('<8I', 2, 5, *gather, w, h, 16, 8) + struct.pack('<Q', count)
    body += b''.join(struct.pack('<f', 0.25 * (k % 7)) for k in range(2 * count))
    return body + bytes(8)


def checkpoint_seeds():
    write('checkpoint', 'one_pixel.ckpt', checkpoint(1, 1, [('method', 'gather'), ('width', '1')]))
    write('checkpoint', 'two_by_three.ckpt', checkpoint(2, 3, [('photons', '1024'), ('gather', 'trace')], (3, 1)))
    write('checkpoint', 'no_settings.ckpt', checkpoint(1, 2, []))


def main():
    if not os.path.isdir(SHARED):
        print(f'{SHARED} is absent: the seeds are the suite\'s files alone', file=sys.stderr)
    for seeds in (mitsuba_seeds, ply_seeds, serialized_seeds, obj_seeds, gltf_seeds, image_seeds, checkpoint_seeds):
        seeds()
    for target in sorted(os.listdir(OUT)):
        files = os.listdir(os.path.join(OUT, target))
        print(f'{target}: {len(files)} seeds')


if __name__ == '__main__':
    main()
