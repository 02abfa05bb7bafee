#!/usr/bin/env python3
"""Where a light field's error against a path trace is (docs/benchmarks.md, McGuire's boxes).

Usage: bench/lf_error_breakdown.py LF.pfm REF.pfm REFVAR.pfm [--bright Y] [--top N]

Both images are scaled so that the reference's mean luminance (Rec. 709 Y) is 0.16, the built-in
box's, and relMSE = mean (a − b)²/(b² + 0.01) over pixels and channels is taken (relMSE's +0.01
is absolute, so dim scenes need the scaling); "ref noise" is the reference's own share, mean
var/(b² + 0.01) from `trace --variance`, and "LF error" = relMSE − ref noise. Prints those, the
mean-luminance ratio (light field / reference), the same ratio over the bright region — the
pixels within one pixel of where the reference's luminance exceeds --bright (default 0.2: a
lamp of radiance 1 and its images) — and over the rest, and the N pixels (default 8) that carry
most of the relMSE. Needs NumPy (Debian's python3-numpy)."""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pfm import read_pfm_sized  # noqa: E402

REC709 = np.array([0.2126, 0.7152, 0.0722])


def read_image(path):
    """A colour PFM as an (h, w, 3) float64 array, top row first."""
    w, h, values = read_pfm_sized(path)
    return np.array(values, dtype=np.float64).reshape(h, w, 3)[::-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("lf")
    ap.add_argument("ref")
    ap.add_argument("refvar")
    ap.add_argument("--bright", type=float, default=0.2)
    ap.add_argument("--top", type=int, default=8)
    a = ap.parse_args()
    lf, ref, var = read_image(a.lf), read_image(a.ref), read_image(a.refvar)
    if lf.shape != ref.shape or var.shape != ref.shape:
        raise SystemExit(f"sizes differ: {lf.shape[1::-1]}, {ref.shape[1::-1]}, {var.shape[1::-1]}")
    ly, ry = lf @ REC709, ref @ REC709
    k = 0.16 / ry.mean()
    err = ((k * lf - k * ref) ** 2 / ((k * ref) ** 2 + 0.01)).mean(axis=2)
    noise = (k * k * var / ((k * ref) ** 2 + 0.01)).mean(axis=2)
    print(f"mean-luminance ratio {ly.sum() / ry.sum():.4f}; at mean luminance 0.16: relMSE {err.mean():.3e}, "
          f"ref noise {noise.mean():.3e}, LF error {err.mean() - noise.mean():.3e}")
    bright = np.zeros(ry.shape, bool)
    for y, x in zip(*np.nonzero(ry > a.bright)):
        bright[max(y - 1, 0):y + 2, max(x - 1, 0):x + 2] = True
    if bright.any():
        print(f"bright region ({bright.sum()} px near Y > {a.bright}): {100 * ry[bright].sum() / ry.sum():.0f} % of the "
              f"reference's light, ratio {ly[bright].sum() / ry[bright].sum():.4f}; the rest: ratio "
              f"{ly[~bright].sum() / ry[~bright].sum():.4f}")
    order = np.argsort(err.ravel())[::-1][:a.top]
    for i in order:
        y, x = divmod(int(i), err.shape[1])
        print(f"  pixel ({x}, {y}) from the top left: {100 * err[y, x] / err.sum():.1f} % of the relMSE, "
              f"light field Y {ly[y, x]:.3f}, reference Y {ry[y, x]:.3f} ± {np.sqrt(var[y, x] @ REC709 ** 2):.3f}")


if __name__ == "__main__":
    main()
