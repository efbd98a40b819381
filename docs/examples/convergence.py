"""Convergence of rastergi against a Mitsuba 3 reference, from Python.

Renders the Cornell box progressively with the photon map + final gather and with the
reference path tracer, compares each with the mean of the two committed Mitsuba 3 path-traced
references (crates/rastergi/tests/data/cornell_path_128_{a,b}.exr, 16384 spp each) after 1, 2,
4, ... iterations, and plots the relative RMSE and the block-mean error (noise averages out of
it, bias stays) against the iterations.

    pip install ./python matplotlib     # in a virtual environment
    python docs/examples/convergence.py --iterations 256 --out convergence.png
"""

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import rastergi  # noqa: E402

DATA = Path(__file__).resolve().parents[2] / "crates" / "rastergi" / "tests" / "data"


def converge(renderer: rastergi.Renderer, reference: np.ndarray, iterations: int):
    """(iterations, relative RMSE, block-mean error, seconds) at powers of two."""
    rows, start = [], time.perf_counter()
    n = 1
    while n <= iterations:
        renderer.iterate(n - renderer.samples)
        c = rastergi.compare(renderer.image(), reference, mask_emitters=True)
        rows.append((n, c.relative_rmse, c.block_mean_error, time.perf_counter() - start))
        print(f"{renderer.method:6} {n:5} iterations  relative RMSE {c.relative_rmse:.4f}  "
              f"block-mean error {c.block_mean_error:.4f}  {rows[-1][-1]:6.1f} s")
        n *= 2
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=256)
    parser.add_argument("--out", default="convergence.png")
    args = parser.parse_args()

    # The references: 128 x 128, the scene's own camera, unlimited depth.
    a = rastergi.read_image(DATA / "cornell_path_128_a.exr")
    b = rastergi.read_image(DATA / "cornell_path_128_b.exr")
    print("the references differ by", round(rastergi.compare(a, b, mask_emitters=True).relative_rmse, 4))
    reference = (a + b) / 2

    # The traced gather: `gather="auto"` (the default) would choose by timing.
    options = dict(width=128, height=128, seed=1, gather="trace")
    runs = {
        "photon map + gather": converge(rastergi.Renderer("cornell", **options), reference, args.iterations),
        "path tracer": converge(rastergi.Renderer("cornell", method="path", **options), reference, args.iterations),
    }

    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=100)
    for (name, rows), colour in zip(runs.items(), ("tab:blue", "tab:orange")):
        n = [r[0] for r in rows]
        ax.loglog(n, [r[1] for r in rows], "o-", color=colour, label=f"{name}: relative RMSE")
        ax.loglog(n, [r[2] for r in rows], "s--", color=colour, label=f"{name}: block-mean error")
    ax.set_xlabel("iterations (samples per pixel)")
    ax.set_ylabel("error against Mitsuba 3")
    ax.set_title("Cornell box 128², rastergi from Python")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
