#!/usr/bin/env python3
"""Denoises a rastergi render with Intel Open Image Denoise, guided by its albedo and normal AOVs.

    rastergi render SCENE --out IMAGE.exr --albedo ALBEDO.exr --normal NORMAL.exr [...]
    scripts/oidn.py IMAGE.exr ALBEDO.exr NORMAL.exr OUT.exr [--quality high|balanced|fast]

rastergi's own denoiser is `rastergi render --denoise` (docs/denoiser.md); this is the recipe for
an external one and how docs/denoiser.md's comparison with OIDN was measured. Needs
`pip install pyoidn OpenEXR` (OIDN 2.x's CPU device, bundled by pyoidn).

- IMAGE: the raw render, linear radiance (HDR), RGB.
- ALBEDO: the mean albedo of the visible points (`--albedo`), in [0, 1].
- NORMAL: their mean world-space shading normal (`--normal`), re-normalised here; OIDN accepts
  world-space normals in [-1, 1]. Pixels that see nothing carry 0.
The output is OIDN's "RT" filter in HDR mode, written as RGB float32 (.exr).
"""
import argparse
import os
import sys

import numpy as np


def read_rgb(path):
    import OpenEXR

    try:
        f = OpenEXR.File(path)
    except Exception as e:  # OpenEXR raises RuntimeError for a missing or unreadable file
        sys.exit(f"{path}: cannot read it as an EXR image ({e})")
    with f:
        channels = f.channels()
        if "RGB" in channels:
            return np.ascontiguousarray(channels["RGB"].pixels, dtype=np.float32)
        try:
            return np.ascontiguousarray(np.stack([channels[c].pixels for c in "RGB"], -1), dtype=np.float32)
        except KeyError:
            sys.exit(f"{path}: no R, G, B channels (found {', '.join(channels)})")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("image")
    p.add_argument("albedo")
    p.add_argument("normal")
    p.add_argument("out")
    p.add_argument("--quality", default="high", choices=["high", "balanced", "fast"])
    a = p.parse_args()
    try:
        import OpenEXR
        import pyoidn
    except ImportError as e:
        sys.exit(f"{e}: install them with `pip install pyoidn OpenEXR`")
    if not a.out.endswith(".exr"):
        sys.exit(f"{a.out}: the output is linear radiance; give it a .exr name")
    color, albedo, normal = (read_rgb(x) for x in (a.image, a.albedo, a.normal))
    if not (color.shape == albedo.shape == normal.shape):
        sys.exit(f"the images differ in size: {color.shape}, {albedo.shape}, {normal.shape}")
    length = np.linalg.norm(normal, axis=-1, keepdims=True)
    normal = np.where(length > 0, normal / np.where(length > 0, length, 1), 0).astype(np.float32)
    out = pyoidn.denoise(color, np.clip(albedo, 0, 1), normal, hdr=True, quality=a.quality)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    # Written whole or not at all.
    part = a.out + ".part.exr"
    with OpenEXR.File(header, {"RGB": out}) as f:
        f.write(part)
    os.replace(part, a.out)


if __name__ == "__main__":
    main()
