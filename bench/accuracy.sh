#!/usr/bin/env bash
# Accuracy of the light field against the path tracer (issue 4's figures), and the
# reuse-visibility check.
#
# For the built-in Cornell box and McGuire's CornellBox-Glossy and CornellBox-Mirror, at the
# default bake preset:
#   1. plenoptic bake SCENE -o NAME.plf --stats NAME.bake.json
#   2. plenoptic render NAME.plf --spp 16 (SIZE×SIZE) -o NAME.lf.pfm           light field
#   3. plenoptic trace SCENE --spp REF_SPP (SIZE×SIZE) -o NAME.ref.pfm         reference,
#      with --variance NAME.refvar.pfm (the reference's own squared standard error per pixel)
#   4. plenoptic compare NAME.lf.pfm NAME.ref.pfm --json --heatmap NAME.heat.png
# and prints one row per scene:
#   bake s, tixels, .plf bytes, mean-luminance ratio (light field / reference, Rec.709 Y; the
#   issue asks for 1 ± 0.02), relMSE (compare.h: mean (a−b)²/(b²+0.01)), and "ref noise": the
#   part of that relMSE the reference's own Monte Carlo noise accounts for, mean var/(b²+0.01)
#   over pixels and channels (E[(a−b)²] = bias² + var_b when a is noise-free, so the light
#   field's own error is relMSE − ref noise, printed as "LF error"; a ref-noise column far below
#   relMSE means the reference is converged enough for the figure), and "relMSE@0.18": the relMSE after scaling
#   both images so that the reference's mean luminance is 0.18 (mid-grey). relMSE's +0.01 in the
#   denominator is an absolute radiance, so the raw figure depends on the scene's brightness:
#   McGuire's Glossy and Mirror boxes have a light of radiance 1 (mean image luminance ≈ 0.006)
#   where the built-in box's light is ≈ 14 (mean ≈ 0.16); the normalised columns (relMSE and
#   reference noise at mean luminance 0.18) compare them.
#
# Then the reuse-visibility check (issue 4, item 2): a JSON scene of McGuire's CornellBox-Original
# with the light recoloured is baked twice — once reusing the visibility field saved by a bake of the
# original colour (--reuse-visibility --no-warm-start --visibility: propagated from zero), once from scratch — and the two light
# fields' renders are compared (relMSE ≈ 0 expected; the bake is deterministic for a seed).
#
# Usage: bench/accuracy.sh [PLENOPTIC] [WORKDIR]
#   PLENOPTIC  the executable (default: build/plenoptic)
#   WORKDIR    where every file goes (default: out/accuracy)
# Environment: SIZE (image side, default 256), REF_SPP (reference samples per pixel, default
# 2048: about 40–90 s per scene on 2 cores), LF_SAMPLES (light-field camera samples per
# pixel, default 16), SCENES_DIR (default: the McGuire scenes in tests/data/cornell-mcguire),
# SCENES (which of "cornell glossy mirror sphere water sphere-rough water-rough" to measure,
# default the first three; empty = only the reuse-visibility check). sphere-rough and
# water-rough are McGuire's Sphere and Water with their glass made rough (bench/scenes/*.json).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
plenoptic=${1:-build/plenoptic}
workdir=${2:-out/accuracy}
size=${SIZE:-256}
ref_spp=${REF_SPP:-2048}
lf_samples=${LF_SAMPLES:-16}
scenes_dir=${SCENES_DIR:-$here/../tests/data/cornell-mcguire}

if [[ ! -x "$plenoptic" ]]; then
  echo "$0: $plenoptic is not an executable (build it: cmake --build build --target plenoptic)" >&2
  exit 1
fi
for f in CornellBox-Glossy.obj CornellBox-Mirror.obj CornellBox-Original.obj; do
  if [[ ! -f "$scenes_dir/$f" ]]; then
    echo "$0: $scenes_dir/$f not found (set SCENES_DIR)" >&2
    exit 1
  fi
done
mkdir -p "$workdir"

all_names=(cornell glossy mirror sphere water sphere-rough water-rough)
all_scenes=(cornell "$scenes_dir/CornellBox-Glossy.obj" "$scenes_dir/CornellBox-Mirror.obj"
            "$scenes_dir/CornellBox-Sphere.obj" "$scenes_dir/CornellBox-Water.obj"
            "$here/scenes/CornellBox-Sphere-rough.json" "$here/scenes/CornellBox-Water-rough.json")
names=()
scenes=()
for i in "${!all_names[@]}"; do
  if [[ " ${SCENES-cornell glossy mirror} " == *" ${all_names[$i]} "* ]]; then
    names+=("${all_names[$i]}")
    scenes+=("${all_scenes[$i]}")
  fi
done
size_flags=(--width "$size" --height "$size")

for i in ${names[@]+"${!names[@]}"}; do
  name=${names[$i]}
  scene=${scenes[$i]}
  out="$workdir/$name"
  echo "== $name: bake (default preset)" >&2
  "$plenoptic" --quiet bake "$scene" -o "$out.plf" --stats "$out.bake.json" >&2
  echo "== $name: light-field render ($lf_samples samples per pixel)" >&2
  "$plenoptic" --quiet render "$out.plf" -o "$out.lf.pfm" --spp "$lf_samples" "${size_flags[@]}" >&2
  echo "== $name: reference ($ref_spp spp)" >&2
  "$plenoptic" --quiet trace "$scene" -o "$out.ref.pfm" --variance "$out.refvar.pfm" --spp "$ref_spp" \
    "${size_flags[@]}" --stats "$out.trace.json" >&2
  "$plenoptic" --quiet compare "$out.lf.pfm" "$out.ref.pfm" --json --heatmap "$out.heat.png" >"$out.compare.json"
done

# ---- reuse-visibility check ------------------------------------------------------------------
echo "== reuse-visibility check" >&2
# McGuire's CornellBox-Original through two JSON scenes that differ only in the light's
# emission: its .mtl has "light" with Kd 0.78 and Ke (17, 12, 4); the JSON material of the same
# name replaces it. Both files define the material, so the scenes' material lists (and with
# them the charts' material indices, which the visibility hash covers) are the same.
# (The JSON scene's same-name replacement applies to loaded mesh files, not to
# "include_cornell", hence the OBJ box here.)
original_obj=$(realpath "$scenes_dir/CornellBox-Original.obj")
for variant in "original 17 12 4" "recoloured 4 12 17"; do
  read -r label r g b <<<"$variant"
  cat >"$workdir/light_$label.json" <<EOF
{"meshes": [{"file": "$original_obj"}],
 "materials": {"light": {"type": "lambert", "albedo": [0.78, 0.78, 0.78], "emission": [$r, $g, $b]}}}
EOF
done
reuse="$workdir/reuse"
"$plenoptic" --quiet bake "$workdir/light_original.json" -o "$reuse.original.plf" --visibility "$reuse.plv" \
  --stats "$reuse.original.json" >&2
"$plenoptic" --quiet bake "$workdir/light_recoloured.json" -o "$reuse.reused.plf" --visibility "$reuse.plv" \
  --reuse-visibility --no-warm-start --stats "$reuse.reused.json" >&2
"$plenoptic" --quiet bake "$workdir/light_recoloured.json" -o "$reuse.full.plf" --visibility "$reuse.full.plv" \
  --stats "$reuse.full.json" >&2
for kind in reused full original; do
  "$plenoptic" --quiet render "$reuse.$kind.plf" -o "$reuse.$kind.exr" --spp "$lf_samples" "${size_flags[@]}" >&2
done
"$plenoptic" --quiet compare "$reuse.reused.exr" "$reuse.full.exr" --json >"$reuse.compare.json"
"$plenoptic" --quiet compare "$reuse.original.exr" "$reuse.full.exr" --json >"$reuse.changed.json"

# ---- table ---------------------------------------------------------------------------------
BENCH_DIR="$(cd "$(dirname "$0")" && pwd)" python3 - "$workdir" "$size" "$ref_spp" "$lf_samples" ${names[@]+"${names[@]}"} <<'PY'
import json, os, sys

sys.path.insert(0, os.environ["BENCH_DIR"])
from pfm import read_pfm

workdir, size, ref_spp, lf_samples, names = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:]

rows = []
for name in names:
    out = os.path.join(workdir, name)
    bake = json.load(open(out + ".bake.json"))
    trace = json.load(open(out + ".trace.json"))
    cmp = json.load(open(out + ".compare.json"))
    ref, var = read_pfm(out + ".ref.pfm"), read_pfm(out + ".refvar.pfm")
    noise = sum(v / (r * r + 0.01) for r, v in zip(ref, var)) / len(ref)
    lf = read_pfm(out + ".lf.pfm")
    mean_y = sum(0.2126 * ref[i] + 0.7152 * ref[i + 1] + 0.0722 * ref[i + 2] for i in range(0, len(ref), 3)) / (len(ref) / 3)
    k = 0.18 / mean_y
    normalised = sum((k * (a - b)) ** 2 / ((k * b) ** 2 + 0.01) for a, b in zip(lf, ref)) / len(ref)
    normalised_noise = sum(k * k * v / ((k * b) ** 2 + 0.01) for b, v in zip(ref, var)) / len(ref)
    rows.append((name, bake["seconds"], bake["tixels"], bake["file_bytes"], cmp["mean_luminance_ratio"],
                 cmp["relmse"], noise, normalised, normalised_noise, trace["seconds"], out + ".heat.png"))

if rows:
    print(f"light field (render --spp {lf_samples}) vs path-traced reference ({ref_spp} spp), {size}x{size}, default preset")
    header = ("scene", "bake s", "tixels", ".plf bytes", "mean Y ratio", "relMSE", "ref noise", "LF error", "relMSE@0.18", "noise@0.18", "ref s", "heat map")
    print(f"{header[0]:<8} {header[1]:>7} {header[2]:>8} {header[3]:>11} {header[4]:>12} {header[5]:>9} {header[6]:>9} {header[7]:>9} {header[8]:>11} {header[9]:>10} {header[10]:>7}  {header[11]}")
    for r in rows:
        print(f"{r[0]:<8} {r[1]:7.2f} {r[2]:8d} {r[3]:11d} {r[4]:12.4f} {r[5]:9.2e} {r[6]:9.1e} {r[5] - r[6]:9.2e} {r[7]:11.2e} {r[8]:10.1e} {r[9]:7.1f}  {r[10]}")
    print()

reuse = os.path.join(workdir, "reuse")
orig = json.load(open(reuse + ".original.json"))
reused = json.load(open(reuse + ".reused.json"))
full = json.load(open(reuse + ".full.json"))
same = json.load(open(reuse + ".compare.json"))
changed = json.load(open(reuse + ".changed.json"))
print("reuse-visibility check (CornellBox-Original, light (17, 12, 4) recoloured to (4, 12, 17)):")
print(f"  bake original colour          {orig['seconds']:6.2f} s  (visibility saved)")
print(f"  re-bake, --reuse-visibility   {reused['seconds']:6.2f} s  reused_visibility={str(reused['reused_visibility']).lower()}"
      f"  ({100.0 * reused['seconds'] / full['seconds']:.0f} % of the full bake)")
print(f"  full bake of the changed scene {full['seconds']:5.2f} s")
print(f"  render(reused) vs render(full):  relMSE {same['relmse']:.3e}, max |diff| {same['max_abs_error']:.3e}, identical {str(same['identical']).lower()}")
print(f"  (for scale: original colour vs changed, relMSE {changed['relmse']:.3e})")
if not reused["reused_visibility"]:
    print("  WARNING: the visibility field was NOT reused (see the bake's message without --quiet)")
PY
