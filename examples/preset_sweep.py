#!/usr/bin/env python3
"""Sweeps the bake presets on the built-in Cornell box against a path-traced reference and
shows light-field error against bake time: a plot (OUT/preset_sweep.png) when matplotlib is
installed (Debian: python3-matplotlib), a table always.

    python3 examples/preset_sweep.py [--size 128] [--spp 256] [--threads 0] [--out out/examples]
"""
import argparse
import os
import time

import plenoptic


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128, help="image width and height in pixels")
    parser.add_argument("--spp", type=int, default=256, help="samples per pixel of the path-traced reference")
    parser.add_argument("--threads", type=int, default=0, help="worker threads (0 = all)")
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory (the plot)")
    args = parser.parse_args()

    scene = plenoptic.load_scene("cornell")
    reference, stats = plenoptic.trace(scene, width=args.size, height=args.size, spp=args.spp, threads=args.threads)
    print(f"reference: {args.size}x{args.size}, {args.spp} spp, {stats['seconds']:.2f} s")

    rows = []
    for preset in ["draft", "default", "high"]:
        start = time.perf_counter()
        lf = plenoptic.bake(scene, preset=preset, threads=args.threads)
        bake_seconds = time.perf_counter() - start
        # 16 jittered samples per pixel: the path tracer averages over each pixel too.
        image = lf.render(width=args.size, height=args.size, samples=16, threads=args.threads)
        error = plenoptic.compare(image, reference)
        rows.append((preset, bake_seconds, lf.stats["tixels"], error["relmse"], error["mean_luminance_ratio"]))

    print(f"{'preset':8} {'bake s':>8} {'tixels':>8} {'relMSE':>10} {'mean ratio':>10}")
    for preset, seconds, tixels, rel_mse, ratio in rows:
        print(f"{preset:8} {seconds:8.2f} {tixels:8d} {rel_mse:10.3e} {ratio:10.4f}")

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(matplotlib not installed: table only)")
        return
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.loglog([r[1] for r in rows], [r[3] for r in rows], "o-")
    for preset, seconds, _, rel_mse, _ in rows:
        ax.annotate(preset, (seconds, rel_mse), textcoords="offset points", xytext=(5, 5))
    ax.set_xlabel("bake time (s)")
    ax.set_ylabel("relMSE vs path tracer")
    ax.set_title("Cornell box: light-field error against bake time")
    fig.tight_layout()
    os.makedirs(args.out, exist_ok=True)
    plot = os.path.join(args.out, "preset_sweep.png")
    fig.savefig(plot, dpi=120)
    print(f"wrote {plot}")


if __name__ == "__main__":
    main()
