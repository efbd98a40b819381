#!/usr/bin/env python3
"""Write the test scene `alpha_card.obj` + `alpha_card.mtl` + `alpha_card_mask.png`.

An alpha-masked ("cut-out") card test. Three parts:

- Floor: a quad at y = 0, x and z in [-2, 2], material `floor` (Kd 0.6), counter-clockwise
  seen from above (normal +y), no texture coordinates.
- Card A: a horizontal square at y = 0.8, x and z in [-0.6, 0.6], material `card` (Kd 0.8 0.7
  0.5, `map_d alpha_card_mask.png`), two triangles wound counter-clockwise seen from above
  (normal +y). Its corners carry texture coordinates (`f v/vt`) in the OBJ convention (v
  points up the image):

      corner (x, z)       vt (u, v)
      (-0.6, +0.6)        (0, 0)      image bottom left
      (+0.6, +0.6)        (1, 0)      image bottom right
      (+0.6, -0.6)        (1, 1)      image top right
      (-0.6, -0.6)        (0, 1)      image top left

  so u grows with +x and v grows with -z: seen from above with -z at the top of the view
  (+x to the right), the card shows the mask exactly as the image file is drawn, row 0 of the
  PNG along the card's far edge z = -0.6, column 0 along x = -0.6.
- Card B (the "veil"): a vertical square in the plane x = 1.2, y in [0.1, 1.1], z in
  [-0.5, 0.5], material `veil` (Kd 0.5 0.6 0.8, `d 0.5`: a constant 50 % opacity, no
  texture), two triangles wound counter-clockwise seen from -x (normal -x), no texture
  coordinates.

The mask `alpha_card_mask.png`: 8 x 8, grayscale (PNG colour type 0), 8 bits, no alpha, each
texel 0 (a hole) or 255 (solid). Row 0 is the top of the image, column 0 its left; '#' is
solid (255), '.' a hole (0):

      column  01234567
      row 0   ########
      row 1   #......#
      row 2   #..#####
      row 3   #.....##
      row 4   #..###.#
      row 5   #..##..#
      row 6   #..#...#
      row 7   ########

a solid border one texel wide around an 'F' of holes (its stem two texels wide in columns 1-2,
its top bar along row 1, its middle bar along row 3) and a staircase of holes in the lower
right (row 4 column 6, row 5 columns 5-6, row 6 columns 4-6): 25 holes of 64 (39 %). The pattern is not symmetric under flipping
the rows, the columns or both, nor under swapping u and v, so a v-flip, u-flip or transposition
mistake shows in the image: read correctly, the F's top bar lies along the card's far edge
(z = -0.6) and its stem along the left edge (x = -0.6).

No emitters: light the scene with a point light (crates/rastergi/tests/data/README.md).
Plain Python, standard library only (the PNG is written by hand with zlib and struct).

    python3 scripts/make_alpha_card_scene.py                  # into crates/rastergi/tests/data/obj
    python3 scripts/make_alpha_card_scene.py --out-dir DIR
"""
import os
import struct
import zlib

from obj_geometry import cross, num, out_dir_args, sub

MASK_ROWS = [  # row 0 = the top of the image; '#' solid (255), '.' hole (0)
    "########",
    "#......#",
    "#..#####",
    "#.....##",
    "#..###.#",
    "#..##..#",
    "#..#...#",
    "########",
]
MASK_NAME = "alpha_card_mask.png"

FLOOR_HALF = 2.0
CARD_Y = 0.8
CARD_HALF = 0.6
VEIL_X = 1.2
VEIL_Y = (0.1, 1.1)
VEIL_Z = (-0.5, 0.5)

MTL = f"""# scripts/make_alpha_card_scene.py: the materials of alpha_card.obj

newmtl floor
Kd 0.6 0.6 0.6

newmtl card
Kd 0.8 0.7 0.5
map_d {MASK_NAME}

newmtl veil
Kd 0.5 0.6 0.8
d 0.5
"""


def mask_values():
    rows = [[255 if c == "#" else 0 for c in r] for r in MASK_ROWS]
    assert len(rows) == 8 and all(len(r) == 8 for r in rows)
    assert all(c in "#." for r in MASK_ROWS for c in r)
    # Asymmetric: a flip of rows, of columns, of both, or a transposition changes it.
    flips = [rows[::-1], [r[::-1] for r in rows], [r[::-1] for r in rows[::-1]],
             [list(c) for c in zip(*rows)]]
    assert all(f != rows for f in flips)
    return rows


def png_grey8(rows):
    """A grayscale (colour type 0), 8-bit, non-interlaced PNG of the rows (row 0 on top)."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    height, width = len(rows), len(rows[0])
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    raw = b"".join(b"\x00" + bytes(r) for r in rows)  # filter type 0 (None) on every row
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9))
            + chunk(b"IEND", b""))


def read_png_grey8(data):
    """Decode what png_grey8 writes (a check of the file, not a general PNG reader)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = ihdr
    assert (depth, colour, interlace) == (8, 0, 0)
    raw = zlib.decompress(idat)
    stride = width + 1
    assert len(raw) == height * stride
    return [list(raw[i * stride + 1:(i + 1) * stride]) for i in range(height)
            if raw[i * stride] == 0]


def main():
    args = out_dir_args(__doc__)

    h, c = FLOOR_HALF, CARD_HALF
    floor = [(-h, 0.0, h), (h, 0.0, h), (h, 0.0, -h), (-h, 0.0, -h)]
    card = [(-c, CARD_Y, c), (c, CARD_Y, c), (c, CARD_Y, -c), (-c, CARD_Y, -c)]
    card_uv = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    (y0, y1), (z0, z1) = VEIL_Y, VEIL_Z
    veil = [(VEIL_X, y0, z0), (VEIL_X, y0, z1), (VEIL_X, y1, z1), (VEIL_X, y1, z0)]

    # Windings: the floor and card A face +y, the veil faces -x.
    for quad, axis, sign in ((floor, 1, 1), (card, 1, 1), (veil, 0, -1)):
        for t in ((0, 1, 2), (0, 2, 3)):
            a, b, d = (quad[k] for k in t)
            n = cross(sub(b, a), sub(d, a))
            assert n[axis] * sign > 0 and all(n[k] == 0 for k in range(3) if k != axis)
    # u grows with +x, v (OBJ, up the image) with -z.
    for (x, _, z), (u, v) in zip(card, card_uv):
        assert u == (x + c) / (2 * c) and v == (c - z) / (2 * c)

    rows = mask_values()
    png = png_grey8(rows)
    assert read_png_grey8(png) == rows
    holes = sum(v == 0 for r in rows for v in r)

    lines = [
        "# alpha_card.obj, written by scripts/make_alpha_card_scene.py: a floor quad (y = 0,"
        f" x, z in [-{h:g}, {h:g}]),",
        f"# card A: a horizontal square at y = {CARD_Y:g}, x, z in [-{c:g}, {c:g}], alpha-masked by"
        f" {MASK_NAME} (map_d),",
        "#   vt: u grows with +x, v (OBJ convention, up the image) grows with -z,",
        f"# card B (veil): a vertical square at x = {VEIL_X:g}, y in [{y0:g}, {y1:g}], z in "
        f"[{z0:g}, {z1:g}], d 0.5, facing -x.",
        "# Every face is counter-clockwise seen from the side its normal faces.",
        "mtllib alpha_card.mtl",
        "",
        "# floor, 1-4",
    ]
    lines += [f"v {num(x)} {num(y)} {num(z)}" for x, y, z in floor]
    lines.append("# card A, 5-8")
    lines += [f"v {num(x)} {num(y)} {num(z)}" for x, y, z in card]
    lines.append("# card B (veil), 9-12")
    lines += [f"v {num(x)} {num(y)} {num(z)}" for x, y, z in veil]
    lines.append("# card A's texture coordinates, 1-4: vt k belongs to v k+4")
    lines += [f"vt {num(u)} {num(v)}" for u, v in card_uv]
    lines += ["", "usemtl floor", "f 1 2 3 4",
              "", "usemtl card", "f 5/1 6/2 7/3", "f 5/1 7/3 8/4",
              "", "usemtl veil", "f 9 10 11", "f 9 11 12"]

    os.makedirs(args.out_dir, exist_ok=True)
    with open(os.path.join(args.out_dir, "alpha_card.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(args.out_dir, "alpha_card.mtl"), "w") as f:
        f.write(MTL)
    with open(os.path.join(args.out_dir, MASK_NAME), "wb") as f:
        f.write(png)
    print(f"{os.path.join(args.out_dir, 'alpha_card.obj')}: 12 vertices, 4 texture "
          f"coordinates, 5 faces; {MASK_NAME}: 8 x 8 grey, {holes} holes of 64")


if __name__ == "__main__":
    main()
