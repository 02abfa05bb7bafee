#!/usr/bin/env bash
# Subsurface scattering checked against an independent renderer: plenoptic's path tracer and
# Blender Cycles render bench/scenes/sss-cornell.json (McGuire's Cornell box with a subsurface
# sphere and a thin subsurface slab; written by bench/scenes/make_sss_cornell.py). Optional:
# needs the Debian `blender` package (3.4.1 here; `apt-get install -y blender`); without it the
# script says so and exits 0. Never part of `make test`.
#
# Cycles renders as in bench/vs_cycles.sh (bench/cycles_common.py: CPU, box filter 1 px, no
# denoising, adaptive sampling or clamping, bounce limits 1024, black world, linear EXR; the
# walls and light from the .mtl, Lambertian and one-sided emission), the subsurface materials
# with its Subsurface Scattering node, Random Walk (Fixed Radius), scale 1, anisotropy 0, colour
# and radius set so that Cycles has plenoptic's medium (bench/sss_vs_cycles_blender.py) — the
# model plenoptic follows (a random walk, diffuse boundary without Fresnel). Two differences of
# Cycles remain, both documented in docs/benchmarks.md: a walk ends after 256 steps
# (BSSRDF_MAX_BOUNCES; plenoptic's after 4096), and a path that already bounced off a diffuse
# surface sees subsurface materials as Lambertian of their albedo (no walk).
# Blender then draws each object in a flat colour of its own; the object regions are the
# pixels whose colour and four neighbours' are within 0.02 of one object's.
#
# SCENE=bench/scenes/sss-furnace.json renders the sphere and the slab alone under a white sky
# of radiance 1 instead: each pixel is then the albedo of one walk, with no light between the
# objects, which isolates the walk from Cycles' two differences.
#
# Printed (and written to WORKDIR/sss_vs_cycles.md): per region (sphere, slab, walls, whole
# image), mean luminance of plenoptic's path trace with its standard error (`trace
# --variance`), Cycles' mean and their ratio (target: within 3 %), and the light field's mean
# and its ratio to the path trace (target: within 2 %; `bake --preset PRESET`, `render --spp
# LF_SPP`). WORKDIR/side_by_side.png: plenoptic's path trace (left), its light field (middle)
# and Cycles (right), tone-mapped together (`plenoptic tonemap`, Reinhard).
#
# MAX_DEPTH=D limits both renderers to D scattering events (plenoptic `--max-depth D`, Cycles
# max_bounces D − 1: its bounces do not count the first hit); MAX_DEPTH=1 is direct light only,
# where no path has a diffuse surface before a subsurface one. STANDINS=SCENE also traces SCENE
# with plenoptic (e.g. bench/scenes/sss-cornell-standins.json: the objects Lambertian of the
# colours Cycles' SSS nodes get) and adds its column: what Cycles shows wherever it renders the
# objects as Lambertian. SHORTCUT=1 also traces the scene with `--subsurface-after-diffuse
# lambert` (Cycles' own shortcut: the subsurface materials shaded as Lambertian of their albedo
# once a path has bounced off a diffuse surface) and adds its column: plenoptic rendering what
# Cycles renders, so that the ratio isolates everything but the shortcut.
#
# Usage: bench/sss_vs_cycles.sh [PLENOPTIC] [WORKDIR]
#   PLENOPTIC  default build/plenoptic; WORKDIR default out/sss_vs_cycles
# Environment: SCENE (default bench/scenes/sss-cornell.json), WIDTH (256), HEIGHT (256),
# SPP (both renderers, default 1024), THREADS (2), BLENDER (default blender), PRESET (the
# light field's bake preset, default `default`), LF_SPP (its render's samples, default 16).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
plenoptic=${1:-build/plenoptic}
work=${2:-out/sss_vs_cycles}
scene=${SCENE:-$here/scenes/sss-cornell.json}
width=${WIDTH:-256}
height=${HEIGHT:-256}
spp=${SPP:-1024}
threads=${THREADS:-2}
blender=${BLENDER:-blender}

source "$here/blender_common.sh"
require_blender_and_plenoptic "$blender" "$plenoptic"
mkdir -p "$work"
echo "Blender: $("$blender" --version 2> /dev/null | head -1); $threads threads; ${width}x${height}; $spp spp" >&2

echo "== plenoptic trace, $spp spp" >&2
depth=${MAX_DEPTH:--1}
if [ "$depth" != -1 ]; then export CYCLES_MAX_BOUNCES=$((depth - 1)); fi
"$plenoptic" --quiet --threads "$threads" --seed 1 trace "$scene" -o "$work/pt.pfm" --variance "$work/pt_var.pfm" \
  --spp "$spp" --width "$width" --height "$height" --camera main --stats "$work/pt.json" --max-depth "$depth"
echo "== plenoptic light field: bake --preset ${PRESET:-default}, render --spp ${LF_SPP:-16}" >&2
"$plenoptic" --quiet --threads "$threads" --seed 1 bake "$scene" -o "$work/lf.plf" --preset "${PRESET:-default}" --fresh
"$plenoptic" --quiet --threads "$threads" render "$work/lf.plf" -o "$work/lf.pfm" --spp "${LF_SPP:-16}" \
  --width "$width" --height "$height" --camera main
rm -f "$work/standins.pfm" "$work/shortcut.pfm"
if [ -n "${SHORTCUT:-}" ]; then
  echo "== plenoptic trace with --subsurface-after-diffuse lambert, $spp spp" >&2
  "$plenoptic" --quiet --threads "$threads" --seed 1 trace "$scene" -o "$work/shortcut.pfm" --subsurface-after-diffuse lambert \
    --spp "$spp" --width "$width" --height "$height" --camera main --max-depth "$depth"
fi
if [ -n "${STANDINS:-}" ]; then
  echo "== plenoptic trace of $STANDINS, $spp spp" >&2
  "$plenoptic" --quiet --threads "$threads" --seed 1 trace "$STANDINS" -o "$work/standins.pfm" \
    --spp "$spp" --width "$width" --height "$height" --camera main --max-depth "$depth"
fi
echo "== Cycles, $spp spp" >&2
"$blender" --background --factory-startup --python "$here/sss_vs_cycles_blender.py" -- "$scene" "$work/cy.exr" \
  "$spp" 1 "$width" "$height" "$threads" > "$work/cy.log" 2>&1 || { cat "$work/cy.log" >&2; exit 1; }
grep -E "^(MATERIAL|CYCLES_SECONDS)" "$work/cy.log" >&2

/usr/bin/python3 - "$work" "$scene" "$spp" "$here" <<'PY' | tee "$work/sss_vs_cycles.md"
import json, os, struct, sys

import numpy as np

work, scene, spp, bench = sys.argv[1:5]
sys.path.insert(0, bench)
from pfm import read_pfm  # noqa: E402

weights = np.array([0.2126, 0.7152, 0.0722])  # Rec. 709 luminance


def image(name):
    path = os.path.join(work, name + ".pfm")
    with open(path, "rb") as f:
        f.readline()
        w, h = (int(v) for v in f.readline().split())
    return np.array(read_pfm(path), dtype=np.float64).reshape(h, w, 3)  # bottom row first, as both store


pt, var, lf, cy, ids = image("pt"), image("pt_var"), image("lf"), image("cy"), image("cy.ids")
# The optional columns: (heading, image) of each extra plenoptic trace that was made.
extras = [(heading, image(name)) for name, heading in (("shortcut", "plenoptic with Cycles' shortcut"),
                                                       ("standins", "plenoptic, stand-ins"))
          if os.path.exists(os.path.join(work, name + ".pfm"))]
colours = json.load(open(os.path.join(work, "cy.ids.json")))
regions, walls = [], np.zeros(ids.shape[:2], bool)
for name, colour in sorted(colours.items()):
    near = np.pad(np.abs(ids - np.array(colour)).max(axis=2) < 0.02, 1)
    mask = near[1:-1, 1:-1] & near[:-2, 1:-1] & near[2:, 1:-1] & near[1:-1, :-2] & near[1:-1, 2:]
    if name in ("sphere", "slab"):
        regions.append((name, mask))
    else:
        walls |= mask
regions += [("walls and light", walls), ("whole image", np.ones(ids.shape[:2], bool))]
stats = json.load(open(os.path.join(work, "pt.json")))
print(f"Scene {os.path.basename(scene)}, {ids.shape[1]}x{ids.shape[0]}, both renderers {spp} spp "
      f"(plenoptic trace {stats.get('seconds', float('nan')):.1f} s):")
print()
extra = "".join(f" {heading} Y | Cycles / it |" for heading, _ in extras)
print("| region | pixels | plenoptic Y (± s.e.) | Cycles Y | Cycles / plenoptic | light field / plenoptic |" + extra)
print("|---|---:|---:|---:|---:|---:|" + "---:|---:|" * len(extras))
for name, mask in regions:
    n = int(mask.sum())
    if n == 0:  # e.g. no walls in the furnace
        continue
    y_pt, y_cy = float((pt[mask] @ weights).mean()), float((cy[mask] @ weights).mean())
    se = float(np.sqrt((var[mask] @ (weights ** 2)).sum()) / n)  # pixels independent
    y_lf = float((lf[mask] @ weights).mean())
    row = f"| {name} | {n} | {y_pt:.4f} ± {se:.4f} | {y_cy:.4f} | {y_cy / y_pt:.4f} | {y_lf / y_pt:.4f} |"
    for _, other in extras:
        y_other = float((other[mask] @ weights).mean())
        row += f" {y_other:.4f} | {y_cy / y_other:.4f} |"
    print(row)
print()
print("Y = mean luminance (Rec. 709) of linear radiance over the region's pixels.")
side = np.concatenate([pt, lf, cy], axis=1).astype("<f4")
with open(os.path.join(work, "side_by_side.pfm"), "wb") as f:
    f.write(f"PF\n{side.shape[1]} {side.shape[0]}\n-1.0\n".encode())
    f.write(side.tobytes())
PY
"$plenoptic" --quiet tonemap "$work/side_by_side.pfm" -o "$work/side_by_side.png"
echo "Outputs in $work: pt.pfm (plenoptic), lf.pfm (its light field), cy.pfm (Cycles), side_by_side.png, sss_vs_cycles.md" >&2
