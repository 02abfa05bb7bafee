#!/usr/bin/env python3
"""Path tracer against light field: traces a reference, bakes the light field, renders it from the
same camera and shows where the two differ: a figure (trace, light field, relative error, and the
luminance along the middle row) when matplotlib is installed (Debian: python3-matplotlib), the
numbers always.

    python3 examples/trace_vs_bake.py [--scene cornell] [--size 256] [--spp 256] [--preset default]
                                      [--samples 16] [--out out/examples]

Writes OUT/trace_vs_bake.png (the figure), OUT/trace.exr and OUT/lightfield.exr.
"""
import argparse
import os
import time

import numpy as np

import plenoptic


def luminance(image):
    """Rec.709 luminance of a (height, width, 3) linear image."""
    return image @ np.array([0.2126, 0.7152, 0.0722], dtype=image.dtype)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="cornell", help="'cornell' or a .obj/.gltf/.glb/.json scene")
    parser.add_argument("--size", type=int, default=256, help="image height in pixels (width: 4/3 of it)")
    parser.add_argument("--spp", type=int, default=256, help="samples per pixel of the path-traced reference")
    parser.add_argument("--preset", default="default", help="bake preset: draft, default, high")
    parser.add_argument("--samples", type=int, default=16, help="light-field samples per pixel")
    parser.add_argument("--threads", type=int, default=0, help="worker threads (0 = all)")
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    width, height = args.size * 4 // 3, args.size

    scene = plenoptic.load_scene(args.scene)
    print(scene)
    reference, stats = plenoptic.trace(scene, width=width, height=height, spp=args.spp, threads=args.threads)
    print(f"path tracer: {width}x{height}, {args.spp} spp, {stats['seconds']:.2f} s")

    start = time.perf_counter()
    lf = plenoptic.bake(scene, preset=args.preset, threads=args.threads)
    bake_seconds = time.perf_counter() - start
    start = time.perf_counter()
    # Jittered samples over each pixel, as the path tracer averages over each pixel too.
    image = lf.render(width=width, height=height, samples=args.samples, threads=args.threads)
    render_seconds = time.perf_counter() - start
    print(f"light field: {lf.stats['tixels']} tixels, bake {bake_seconds:.2f} s, "
          f"render ({args.samples} samples/pixel) {render_seconds * 1e3:.1f} ms")

    error = plenoptic.compare(image, reference)
    print(f"relMSE {error['relmse']:.3e}, mean luminance ratio {error['mean_luminance_ratio']:.4f}, "
          f"largest error {error['max_abs_error']:.3g} at pixel {error['max_abs_error_pixel']}")
    plenoptic.write_image(os.path.join(args.out, "trace.exr"), reference)
    plenoptic.write_image(os.path.join(args.out, "lightfield.exr"), image)

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(matplotlib not installed: no figure)")
        return
    # One exposure for both pictures: the reference's log-average luminance brought to 0.18
    # (Reinhard's key, what tone_map would choose for each image on its own).
    log_average = float(np.exp(np.mean(np.log(luminance(reference) + 1e-4))))
    ev = float(np.log2(0.18 / log_average))
    shown = [plenoptic.tone_map(reference, ev=ev), plenoptic.tone_map(image, ev=ev)]
    # Per-pixel relative error |a - b| / (b + 0.01) of the luminance (compare's relMSE, unsquared).
    relative = np.abs(luminance(image) - luminance(reference)) / (luminance(reference) + 0.01)
    fig, axes = plt.subplots(2, 2, figsize=(9, 7))
    axes[0, 0].imshow(shown[0])
    axes[0, 0].set_title(f"path tracer, {args.spp} spp ({stats['seconds']:.1f} s)")
    axes[0, 1].imshow(shown[1])
    axes[0, 1].set_title(f"light field, {args.samples} samples ({render_seconds * 1e3:.0f} ms)")
    heat = axes[1, 0].imshow(relative, cmap="magma", vmin=0.0, vmax=max(0.2, float(np.percentile(relative, 99))))
    axes[1, 0].set_title(f"relative luminance error (relMSE {error['relmse']:.2e})")
    fig.colorbar(heat, ax=axes[1, 0], fraction=0.046)
    for ax in (axes[0, 0], axes[0, 1], axes[1, 0]):
        ax.axis("off")
    row = height // 2
    axes[1, 1].plot(luminance(reference)[row], label="path tracer")
    axes[1, 1].plot(luminance(image)[row], label="light field")
    axes[1, 1].set_xlabel("x (pixels)")
    axes[1, 1].set_ylabel("luminance, W/(sr m²)")
    axes[1, 1].set_title(f"row {row}")
    axes[1, 1].legend()
    fig.tight_layout()
    figure = os.path.join(args.out, "trace_vs_bake.png")
    fig.savefig(figure, dpi=100)
    print(f"wrote {figure}")


if __name__ == "__main__":
    main()
