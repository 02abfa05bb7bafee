#!/usr/bin/env python3
"""Relighting sweep with reused visibility: bakes the Cornell box once, saving its visibility
field, then sweeps the ceiling light from warm to cool white and re-bakes for each colour with
reuse_visibility=True — only the propagation runs again, since the geometry did not change —
and lays the renders side by side in one picture.

    python3 examples/relight_sweep.py [--steps 5] [--size 192] [--preset default] [--out out/examples]

Writes OUT/relight_sweep.png and OUT/cornell.plv (the visibility field all bakes share).
"""
import argparse
import os
import time

import numpy as np

import plenoptic

# The light's colour at the two ends of the sweep, as a radiance in W/(sr m^2): the box's own
# warm light (18.4, 14.0, 6.8) and a cool white of about the same luminance.
WARM = np.array([18.387, 13.9873, 6.75357])
COOL = np.array([11.0, 13.5, 17.0])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=5, help="colours in the sweep (at least 2)")
    parser.add_argument("--size", type=int, default=192, help="width and height of each render in pixels")
    parser.add_argument("--preset", default="default", help="bake preset: draft, default, high")
    parser.add_argument("--threads", type=int, default=0, help="worker threads (0 = all)")
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory")
    args = parser.parse_args()
    if args.steps < 2:
        parser.error("--steps must be at least 2")
    os.makedirs(args.out, exist_ok=True)
    visibility = os.path.join(args.out, "cornell.plv")

    scene = plenoptic.load_scene("cornell")
    start = time.perf_counter()
    plenoptic.bake(scene, preset=args.preset, threads=args.threads, visibility=visibility)
    full_seconds = time.perf_counter() - start
    print(f"full bake (visibility traced and saved to {visibility}): {full_seconds:.2f} s")

    renders = []
    for step in range(args.steps):
        t = step / (args.steps - 1)
        colour = (1.0 - t) * WARM + t * COOL
        scene.set_emission("light", colour.tolist())
        start = time.perf_counter()
        lf = plenoptic.bake(scene, preset=args.preset, threads=args.threads, visibility=visibility,
                            reuse_visibility=True)
        seconds = time.perf_counter() - start
        assert lf.stats["reused_visibility"], "the visibility field should have been reused"
        image = lf.render(width=args.size, height=args.size, samples=4, threads=args.threads)
        mean = image.reshape(-1, 3).mean(axis=0)
        print(f"light ({colour[0]:5.2f}, {colour[1]:5.2f}, {colour[2]:5.2f}): re-bake {seconds:.2f} s, "
              f"image mean R/G/B {mean[0]:.3f} / {mean[1]:.3f} / {mean[2]:.3f}")
        renders.append(image)

    # One picture, so one exposure (Reinhard's automatic key over the whole strip): the colours
    # compare.
    path = os.path.join(args.out, "relight_sweep.png")
    plenoptic.write_image(path, np.concatenate(renders, axis=1))
    print(f"wrote {path} ({args.steps} renders side by side)")


if __name__ == "__main__":
    main()
