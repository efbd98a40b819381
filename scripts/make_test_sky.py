#!/usr/bin/env python3
"""Write the test sky crates/rastergi/tests/data/env/sky_64x32.exr.

A 64 x 32 latitude-longitude environment map, linear float32 RGB OpenEXR (3 channels R, G,
B, no alpha), in the convention of Mitsuba 3's `envmap` emitter with the identity to_world,
which rastergi follows:

    direction d = (x, y, z)  <->  u = atan2(x, -z) / 2pi,  v = acos(y) / pi

with image row 0 at the zenith +Y. Mitsuba places the pixels (it interpolates bilinearly
between these positions, periodically in u):

    column i (0..W-1) at azimuth phi   = 2pi (i + 0.5) / W   (a half-texel shift in u),
    row    j (0..H-1) at polar angle theta = pi j / (H - 1)  (rows 0 and H-1 on the poles),
    direction (sin phi sin theta, cos theta, -cos phi sin theta).

Content, per row j at theta_j and column i:

    sky (theta_j < 90 deg): (0.35, 0.55, 1.0) * (0.4 + 0.6 cos theta_j)
    ground (theta_j >= 90 deg): (0.08, 0.07, 0.06)
    the sun: the single pixel at row 8, column 8: (1000, 900, 800)

(Rows 0..15 are sky, 16..31 ground: row 15 lies at 87.10 deg, row 16 at 92.90 deg, so the
interpolated horizon is a band between them.)

Printed by the script (Mitsuba's bilinear radiance, exact in phi, Gauss-Legendre in theta;
a 3100 x 1280 midpoint grid and Mitsuba's own sample_direction agree):

    sun pixel (row 8, column 8): theta 46.4516 deg, phi 47.8125 deg,
        direction (0.537036, 0.688967, -0.486741), elevation 43.5484 deg
    irradiance on an up-facing plane (normal +Y):
        sky and ground, without the sun pixel:        (0.879203, 1.381530, 2.511782)
        the sun pixel alone (above the sky it replaced): (4.949820, 4.453891, 3.956956)
        the whole map:                                (5.829023, 5.835421, 6.468739)
    the sun pixel's tent (its bilinear weight: +-1 row = +-5.81 deg in theta, +-1 column =
        +-5.625 deg in phi) integrates to 7.204937e-03 sr (a disc of that solid angle has a
        2.74 deg radius): the sun's excess over the sky, integrated over solid angle, is
        (7.202886, 6.481221, 5.758090) W/m^2; a soft, extended sun, not a delta

(The continuous sky (0.4 + 0.6 cos theta) over the upper hemisphere would give
2 pi * 0.4 * (0.35, 0.55, 1.0) = (0.879646, 1.382301, 2.513274); the pixelation and the
interpolated horizon band take 0.05 % off.)

--check also loads the file as a Mitsuba envmap emitter and compares Emitter.eval at random
directions with the model above, and estimates the irradiance by Mitsuba's own
sample_direction (importance sampled) as an independent check.

    python3 scripts/make_test_sky.py [--out PATH] [--check]

Needs numpy and mitsuba (pip install mitsuba numpy; export
DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so if Dr.Jit cannot find LLVM).
"""

import argparse
import math
import os

import numpy as np

W, H = 64, 32
SKY = np.array([0.35, 0.55, 1.0])
GROUND = np.array([0.08, 0.07, 0.06])
SUN_ROW, SUN_COL = 8, 8
SUN = np.array([1000.0, 900.0, 800.0])
DEFAULT_OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "crates",
                           "rastergi", "tests", "data", "env", "sky_64x32.exr")


def theta_of_row(j):
    return math.pi * j / (H - 1)


def phi_of_col(i):
    return 2.0 * math.pi * (i + 0.5) / W


def direction(theta, phi):
    return np.array([math.sin(phi) * math.sin(theta), math.cos(theta),
                     -math.cos(phi) * math.sin(theta)])


def make_sky(with_sun=True):
    img = np.zeros((H, W, 3), dtype=np.float64)
    for j in range(H):
        t = theta_of_row(j)
        # theta < 90 deg, decided on the row index (floating point puts no row at 90 deg)
        img[j, :] = SKY * (0.4 + 0.6 * math.cos(t)) if 2 * j < H - 1 else GROUND
    if with_sun:
        img[SUN_ROW, SUN_COL] = SUN
    return img.astype(np.float32)


def eval_bilinear(img, d):
    """Mitsuba's envmap radiance (identity to_world) in the unit directions d (n, 3)."""
    img = img.astype(np.float64)
    u = np.arctan2(d[:, 0], -d[:, 2]) / (2 * math.pi)
    v = np.arccos(np.clip(d[:, 1], -1, 1)) / math.pi
    x = (u - 0.5 / W) % 1.0 * W  # column position, periodic
    y = v * (H - 1)
    i0 = np.minimum(np.floor(x).astype(int), W - 1)
    j0 = np.minimum(np.floor(y).astype(int), H - 2)
    fx, fy = (x - i0)[:, None], (y - j0)[:, None]
    i1 = (i0 + 1) % W
    return ((1 - fy) * ((1 - fx) * img[j0, i0] + fx * img[j0, i1])
            + fy * ((1 - fx) * img[j0 + 1, i0] + fx * img[j0 + 1, i1]))


def irradiance_up(img, order=32):
    """Irradiance on a plane with normal +Y: the integral of L cos(theta) over theta < 90 deg.

    The bilinear radiance is piecewise linear in phi, so its integral over phi is exact as
    (2pi / W) * the sum over the columns; in theta each row interval (split at 90 deg) is
    integrated by Gauss-Legendre of the given order (the integrand is smooth there).
    """
    rows = img.astype(np.float64).sum(axis=1) * (2 * math.pi / W)  # (H, 3): phi-integrals
    x, w = np.polynomial.legendre.leggauss(order)
    total = np.zeros(3)
    for j in range(H - 1):
        a, b = theta_of_row(j), min(theta_of_row(j + 1), math.pi / 2)
        if a >= math.pi / 2:
            break
        t = 0.5 * (b - a) * x + 0.5 * (a + b)
        f = (t - theta_of_row(j)) / (theta_of_row(j + 1) - theta_of_row(j))
        weight = w * 0.5 * (b - a) * np.cos(t) * np.sin(t)
        total += ((1 - f) @ weight) * rows[j] + (f @ weight) * rows[j + 1]
    return total


def sun_solid_angle_integral(order=64):
    """The integral over solid angle of the sun pixel's tent (its interpolation weight)."""
    x, w = np.polynomial.legendre.leggauss(order)
    total = 0.0
    for j in (SUN_ROW - 1, SUN_ROW):
        a, b = theta_of_row(j), theta_of_row(j + 1)
        t = 0.5 * (b - a) * x + 0.5 * (a + b)
        tent = 1 - abs(t - theta_of_row(SUN_ROW)) / (b - a)
        total += (w * 0.5 * (b - a) * tent * np.sin(t)).sum()
    return total * (2 * math.pi / W)  # the tent in phi integrates to one pixel width


def write(path, img):
    import mitsuba as mi
    bmp = mi.Bitmap(np.ascontiguousarray(img, dtype=np.float32), mi.Bitmap.PixelFormat.RGB)
    bmp.set_srgb_gamma(False)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    bmp.write(path)
    back = mi.Bitmap(path)
    arr = np.array(back)
    names = [back.struct_()[k].name for k in range(back.channel_count())]
    print(f"{path}: read back as {back.pixel_format()}, {back.component_format()}, "
          f"channels {names}, shape {arr.shape}")
    if (back.pixel_format() != mi.Bitmap.PixelFormat.RGB
            or back.component_format() != mi.Struct.Type.Float32
            or arr.shape != (H, W, 3) or not np.array_equal(arr, img)):
        raise SystemExit(f"{path}: not written as float32 RGB {W}x{H} with the same values")


def _vec(mi, d):
    """Unit directions (n, 3) as a Mitsuba Vector3f."""
    return mi.Vector3f(np.ascontiguousarray(d.T, dtype=np.float32))


def _rgb(x):
    """A Mitsuba colour array as (n, 3) float64."""
    a = np.array(x, dtype=np.float64)
    return a.T if a.ndim == 2 and a.shape[0] == 3 else a.reshape(-1, 3)


def check(path, img, n=1 << 20):
    """Mitsuba's envmap against the bilinear model and its sampled irradiance estimate."""
    import drjit as dr
    import mitsuba as mi
    emitter = mi.load_dict({"type": "envmap", "filename": os.path.abspath(path)})
    rng = np.random.default_rng(1)
    d = rng.normal(size=(n, 3)).astype(np.float32).astype(np.float64)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    si = dr.zeros(mi.SurfaceInteraction3f)
    si.wi = _vec(mi, -d)  # eval looks up the direction -wi
    theirs = _rgb(emitter.eval(si))
    ours = eval_bilinear(img, d)
    sun_only = np.zeros_like(img)
    sun_only[SUN_ROW, SUN_COL] = 1
    in_tent = eval_bilinear(sun_only, d)[:, 0] > 0
    rel = (np.abs(theirs - ours) / ours)[~in_tent].max()
    sun = (np.abs(theirs - ours) / SUN)[in_tent].max()
    print(f"check: Mitsuba Emitter.eval against the bilinear model at {n} random directions: "
          f"max relative difference {rel:.1e} outside the sun pixel's tent, max difference "
          f"{sun:.1e} of the sun's value within it ({in_tent.sum()} directions; float32)")
    sd = direction(theta_of_row(SUN_ROW), phi_of_col(SUN_COL))[None]
    si1 = dr.zeros(mi.SurfaceInteraction3f)
    si1.wi = _vec(mi, -sd)
    print(f"check: Mitsuba's radiance in the sun pixel's direction: "
          f"{_rgb(emitter.eval(si1))[0]}")
    # irradiance by Mitsuba's sample_direction from a point at the origin
    it = dr.zeros(mi.Interaction3f)
    est = np.zeros(3)
    m, runs = 1 << 22, 4
    for k in range(runs):
        sampler = mi.load_dict({"type": "independent"})
        sampler.seed(k, m)
        ds, weight = emitter.sample_direction(it, sampler.next_2d())
        cos = np.maximum(np.array(ds.d.y, dtype=np.float64), 0.0)
        est += (_rgb(weight) * cos[:, None]).mean(axis=0) / runs
    print(f"check: irradiance on an up-facing plane by Mitsuba's sample_direction "
          f"({runs * m} samples): ({est[0]:.6f}, {est[1]:.6f}, {est[2]:.6f})")


def main():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default=os.path.normpath(DEFAULT_OUT))
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--check", action="store_true",
                   help="compare with Mitsuba's envmap emitter after writing")
    args = p.parse_args()
    import mitsuba as mi
    mi.set_variant(args.variant)

    img = make_sky()
    write(args.out, img)

    t, ph = theta_of_row(SUN_ROW), phi_of_col(SUN_COL)
    d = direction(t, ph)
    print(f"sun pixel (row {SUN_ROW}, column {SUN_COL}): theta {math.degrees(t):.4f} deg, "
          f"phi {math.degrees(ph):.4f} deg, direction ({d[0]:.6f}, {d[1]:.6f}, {d[2]:.6f}), "
          f"elevation {90 - math.degrees(t):.4f} deg")
    e_sky = irradiance_up(make_sky(with_sun=False))
    e_all = irradiance_up(img)
    fmt = lambda v: "(" + ", ".join(f"{x:.6f}" for x in v) + ")"
    print("irradiance on an up-facing plane (normal +Y):")
    print(f"  sky and ground, without the sun pixel: {fmt(e_sky)}")
    print(f"  the sun pixel alone (above the sky it replaced): {fmt(e_all - e_sky)}")
    print(f"  the whole map: {fmt(e_all)}")
    omega = sun_solid_angle_integral()
    replaced = img[SUN_ROW, SUN_COL + 1].astype(np.float64)  # the sky value of that row
    print(f"  the sun pixel's tent: {omega:.6e} sr; its radiance above the sky integrated "
          f"over solid angle {fmt((SUN - replaced) * omega)}, times cos theta "
          f"{fmt((SUN - replaced) * omega * math.cos(t))}")
    print(f"  continuous sky 2pi*0.4*(0.35, 0.55, 1.0) = {fmt(2 * math.pi * 0.4 * SKY)}")
    if args.check:
        check(args.out, img)


if __name__ == "__main__":
    main()
