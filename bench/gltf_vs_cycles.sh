#!/usr/bin/env bash
# glTF materials as authored, checked against an independent renderer: Blender's own glTF
# importer and Cycles render the same .gltf (default bench/scenes/gltf-check.gltf, written by
# bench/scenes/make_gltf_check.py: textured and tiled/rotated base colours, roughness and metal
# ramps as metallicRoughness textures, a vertex-coloured cube, an emissive-textured panel), and
# plenoptic path-traces and bakes it. Optional: needs the Debian `blender` package (3.4.1 here;
# `apt-get install -y blender`); without it the script says so and exits 0. Never part of
# `make test`.
#
# Both renderers take the camera from the file (its "main" node, vertical fov as glTF defines
# it), render WIDTH × HEIGHT linear radiance with a 1-pixel box filter and a black world, and
# Cycles' set-up is bench/vs_cycles.sh's (bench/cycles_common.py) with the materials exactly as
# the importer made them (Principled BSDF). Blender then draws each object in a flat colour of
# its own; a pixel whose colour is within 0.02 of one object's belongs to that object's region
# (pixels on an edge, mixing two objects, belong to none).
#
# Cycles renders twice: the materials as the importer made them (Principled BSDF), and with
# each Principled BSDF replaced by glTF's reference BRDF built from Cycles nodes (see
# bench/gltf_vs_cycles_blender.py), which separates what the Principled BSDF adds (Burley
# diffuse, its Fresnel) from what the two renderers do differently.
#
# Printed (and written to WORKDIR/gltf_vs_cycles.md): per region, mean luminance of plenoptic's
# path trace (with its standard error from `trace --variance`), and the ratios to it of both
# Cycles renders (target: within 3 %) and of plenoptic's light field (`bake --preset PRESET`,
# `render --spp LF_SAMPLES`; target: within 2 % for the whole image), and the whole image's.
#
# Usage: bench/gltf_vs_cycles.sh [PLENOPTIC] [WORKDIR]
#   PLENOPTIC  default build/plenoptic; WORKDIR default out/gltf_vs_cycles
# Environment: SCENE (default bench/scenes/gltf-check.gltf), WIDTH (320), HEIGHT (240),
# SPP (both path tracers, default 1024), PRESET (default), LF_SAMPLES (16), THREADS (2),
# BLENDER (default blender).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
plenoptic=${1:-build/plenoptic}
work=${2:-out/gltf_vs_cycles}
scene=${SCENE:-$here/scenes/gltf-check.gltf}
width=${WIDTH:-320}
height=${HEIGHT:-240}
spp=${SPP:-1024}
preset=${PRESET:-default}
lf_samples=${LF_SAMPLES:-16}
threads=${THREADS:-2}
blender=${BLENDER:-blender}

source "$here/blender_common.sh"
require_blender_and_plenoptic "$blender" "$plenoptic"
mkdir -p "$work"
size=(--width "$width" --height "$height")
echo "Blender: $("$blender" --version 2> /dev/null | head -1); $threads threads; ${width}x${height}; $spp spp" >&2

furnace=$here/scenes/gltf-furnace.json
echo "== plenoptic trace, $spp spp" >&2
"$plenoptic" --quiet --threads "$threads" --seed 1 trace "$scene" -o "$work/pt.pfm" --variance "$work/pt_var.pfm" \
  --spp "$spp" "${size[@]}" --stats "$work/pt.json"
"$plenoptic" --quiet --threads "$threads" --seed 1 trace "$furnace" -o "$work/furnace-pt.pfm" \
  --variance "$work/furnace-pt_var.pfm" --spp "$spp" "${size[@]}"
echo "== plenoptic bake --preset $preset, render $lf_samples samples" >&2
"$plenoptic" --quiet --threads "$threads" bake "$scene" -o "$work/lf.plf" --preset "$preset" --stats "$work/bake.json"
"$plenoptic" --quiet --threads "$threads" render "$work/lf.plf" -o "$work/lf.pfm" --spp "$lf_samples" "${size[@]}"
for variant in principled gltf-brdf; do
  for what in scene furnace; do
    if [[ $what == scene ]]; then input=$scene sky=0 out=$work/cy-$variant; else input=${furnace%.json}.gltf sky=1 out=$work/furnace-cy-$variant; fi
    echo "== Cycles ($variant), $what, $spp spp" >&2
    "$blender" --background --factory-startup --python "$here/gltf_vs_cycles_blender.py" -- "$input" "$out.exr" \
      "$spp" 1 "$width" "$height" "$threads" "$variant" "$sky" > "$out.log" 2>&1 || { cat "$out.log" >&2; exit 1; }
  done
  grep -E "^(CAMERA|MATERIAL)" "$work/cy-$variant.log" >&2
done

/usr/bin/python3 - "$work" "$scene" "$preset" "$lf_samples" "$spp" <<'PY' | tee "$work/gltf_vs_cycles.md"
import json, os, sys

import numpy as np

work, scene, preset, lf_samples, spp = sys.argv[1:6]
weights = np.array([0.2126, 0.7152, 0.0722])  # Rec. 709 luminance


def pfm(path):
    with open(path, "rb") as f:
        kind, dims, scale = f.readline().split(), f.readline().split(), float(f.readline())
        w, h = int(dims[0]), int(dims[1])
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1]  # top row first


def table(prefix, with_light_field):
    """Per object region and for the whole image: the path trace's mean luminance (± its
    standard error) and the ratios of both Cycles renders (and the light field) to it."""
    read = lambda name: pfm(os.path.join(work, prefix + name + ".pfm"))
    pt, var, cy, cy_gltf = read("pt"), read("pt_var"), read("cy-principled"), read("cy-gltf-brdf")
    lf = read("lf") if with_light_field else None
    ids = read("cy-principled.ids")
    colours = json.load(open(os.path.join(work, prefix + "cy-principled.ids.json")))
    # A pixel belongs to an object when it and its four neighbours have that object's colour
    # (so a pixel on an edge, whose mix of two colours might come close to a third's, belongs
    # to none).
    rows, assigned = [], np.zeros(ids.shape[:2], bool)
    for name, colour in sorted(colours.items()):
        near = np.pad(np.abs(ids - np.array(colour)).max(axis=2) < 0.02, 1)
        mask = near[1:-1, 1:-1] & near[:-2, 1:-1] & near[2:, 1:-1] & near[1:-1, :-2] & near[1:-1, 2:]
        if mask.any():
            assigned |= mask
            rows.append((name, mask))
    rows.append(("whole image", np.ones(ids.shape[:2], bool)))
    print(f"{assigned.sum()} of {assigned.size} pixels in an object region.")
    print()
    print("| region | pixels | path trace Y (± s.e.) | Cycles / PT | Cycles, glTF BRDF / PT | light field / PT |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, mask in rows:
        n = int(mask.sum())
        y_pt, y_cy, y_gltf = (float((img[mask] @ weights).mean()) for img in (pt, cy, cy_gltf))
        y_lf = f"{float((lf[mask] @ weights).mean()) / y_pt:.4f}" if with_light_field else "—"
        se = float(np.sqrt((var[mask] @ (weights ** 2)).sum()) / n)  # pixels independent
        print(f"| {name} | {n} | {y_pt:.4f} ± {se:.4f} | {y_cy / y_pt:.4f} | {y_gltf / y_pt:.4f} | {y_lf} |")
    print()


bake = json.load(open(os.path.join(work, "bake.json")))
print(f"Scene {os.path.basename(scene)}, path traces {spp} spp, light field --preset {preset} ({bake['tixels']} "
      f"tixels, bake {bake['seconds']:.1f} s) rendered with {lf_samples} samples:", end=" ")
table("", True)
print("The furnace (gltf-furnace.gltf: the same BRDFs, untextured, alone under a white sky of radiance 1):", end=" ")
table("furnace-", False)
print("Objects not in a table are not seen by the camera. Y = mean luminance (Rec. 709) of linear radiance; "
      "PT = plenoptic's path trace; Cycles = Blender's glTF importer as it is (Principled BSDF); "
      "Cycles, glTF BRDF = the same with glTF's reference BRDF from Cycles nodes (bench/gltf_vs_cycles_blender.py).")
PY
echo "Outputs in $work: pt.pfm (plenoptic trace), lf.pfm (light field), cy-principled.pfm and cy-gltf-brdf.pfm (Cycles), the furnace's furnace-*.pfm, gltf_vs_cycles.md" >&2
