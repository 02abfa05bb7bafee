#!/usr/bin/env bash
# The light field's error and frame time next to the path tracer's time to reach the same
# error (issue 5, item 6), for the built-in Cornell box at 640×480.
#
#   1. plenoptic bake cornell (default preset)
#   2. a converged reference: plenoptic trace cornell --spp REF_SPP --seed 1 (with --variance,
#      to state how much of every relMSE below is the reference's own noise)
#   3. the light field: plenoptic render cornell.plf --frames FRAMES --stats (median ms per
#      frame; fast renderer) for each camera-sample count in LF_SAMPLES, and its relMSE
#      against the reference (plenoptic compare --json)
#   4. the path tracer at 1, 2, 4, … spp (seed 2: independent of the reference's samples),
#      its render seconds (trace --stats "seconds": the tracing only, no scene load or BVH,
#      as the render's ms per frame excludes them too) and relMSE against the same reference,
#      until its relMSE is at or below the light field's (or MAX_SPP is reached).
# The time to reach the light field's error is read off the doubling series by log-log
# interpolation between the two spp values that bracket it (relMSE of a Monte Carlo image
# falls as 1/spp; time grows as spp).
#
# relMSE is compare.h's: mean over pixels and channels of (a − b)²/(b² + 0.01). Against a
# reference with its own noise, E[relMSE] = (error of the test image) + "ref noise" (the mean
# of var_ref/(b² + 0.01), printed); the reference is converged enough when that is small
# against the figures compared.
#
# Usage: bench/time_to_error.sh [PLENOPTIC] [WORKDIR]
#   PLENOPTIC  the executable (default: build/plenoptic); WORKDIR default out/time_to_error
# Environment: WIDTH/HEIGHT (640/480), REF_SPP (default 1024, ≈ 3–4 min on 2 cores),
# LF_SAMPLES (default "1 4 16"), FRAMES (timed render frames, default 30), MAX_SPP (1024).
set -euo pipefail

plenoptic=${1:-build/plenoptic}
workdir=${2:-out/time_to_error}
width=${WIDTH:-640}
height=${HEIGHT:-480}
ref_spp=${REF_SPP:-1024}
lf_samples=${LF_SAMPLES:-1 4 16}
frames=${FRAMES:-30}
max_spp=${MAX_SPP:-1024}

if [[ ! -x "$plenoptic" ]]; then
  echo "$0: $plenoptic is not an executable (build it: cmake --build build --target plenoptic)" >&2
  exit 1
fi
mkdir -p "$workdir"
size_flags=(--width "$width" --height "$height")
w=$workdir

echo "== bake (default preset)" >&2
"$plenoptic" --quiet bake cornell -o "$w/cornell.plf" --stats "$w/bake.json" >&2
if [[ ! -f "$w/ref.pfm" || ! -f "$w/ref.json" ]] || ! grep -q "\"spp\": $ref_spp," "$w/ref.json"; then
  echo "== reference ($ref_spp spp; set REF_SPP to change)" >&2
  "$plenoptic" --quiet --seed 1 trace cornell -o "$w/ref.pfm" --variance "$w/refvar.pfm" --spp "$ref_spp" \
    "${size_flags[@]}" --stats "$w/ref.json" >&2
else
  echo "== reference: reusing $w/ref.pfm ($ref_spp spp)" >&2
fi

for s in $lf_samples; do
  echo "== light-field render, $s sample(s) per pixel, $frames frames" >&2
  "$plenoptic" --quiet render "$w/cornell.plf" -o "$w/lf_s$s.exr" --spp "$s" --frames "$frames" \
    "${size_flags[@]}" --stats "$w/lf_s$s.json" >&2
  "$plenoptic" --quiet compare "$w/lf_s$s.exr" "$w/ref.pfm" --json >"$w/lf_s$s.compare.json"
done
# The error to reach: the smallest light-field relMSE measured.
target=$(python3 -c '
import json, sys
print(min(json.load(open(f"{sys.argv[1]}/lf_s{s}.compare.json"))["relmse"] for s in sys.argv[2:]))' "$w" $lf_samples)

spp=1
rm -f "$w"/pt_spp*.json
while :; do
  echo "== path tracer, $spp spp" >&2
  "$plenoptic" --quiet --seed 2 trace cornell -o "$w/pt_spp$spp.exr" --spp "$spp" "${size_flags[@]}" \
    --stats "$w/pt_spp$spp.json" >&2
  "$plenoptic" --quiet compare "$w/pt_spp$spp.exr" "$w/ref.pfm" --json >"$w/pt_spp$spp.compare.json"
  reached=$(python3 -c '
import json, sys
print(int(json.load(open(sys.argv[1]))["relmse"] <= float(sys.argv[2])))' "$w/pt_spp$spp.compare.json" "$target")
  if [[ $reached == 1 || $spp -ge $max_spp ]]; then break; fi
  spp=$((spp * 2))
done

BENCH_DIR="$(cd "$(dirname "$0")" && pwd)" python3 - "$w" "$width" "$height" "$ref_spp" "$lf_samples" <<'PY'
import glob, json, math, os, sys

sys.path.insert(0, os.environ["BENCH_DIR"])
from pfm import read_pfm

w, width, height, ref_spp, lf_samples = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5].split()

ref, var = read_pfm(os.path.join(w, "ref.pfm")), read_pfm(os.path.join(w, "refvar.pfm"))
ref_noise = sum(v / (r * r + 0.01) for r, v in zip(ref, var)) / len(ref)
ref_stats = json.load(open(os.path.join(w, "ref.json")))
bake = json.load(open(os.path.join(w, "bake.json")))

print(f"Cornell box {width}x{height}; reference {ref_spp} spp ({ref_stats['seconds']:.0f} s), its own noise in every "
      f"relMSE below: {ref_noise:.1e}")
print(f"bake (default preset): {bake['seconds']:.2f} s, {bake['tixels']} tixels")
print()
print(f"{'renderer':<28} {'relMSE':>9} {'ms/frame':>10} {'fps':>8}")
lf = []
for s in lf_samples:
    st = json.load(open(os.path.join(w, f"lf_s{s}.json")))
    c = json.load(open(os.path.join(w, f"lf_s{s}.compare.json")))
    lf.append((s, c["relmse"], st["ms_per_frame_median"]))
    print(f"{'light field, ' + s + ' spp':<28} {c['relmse']:9.3e} {st['ms_per_frame_median']:10.2f} {st['fps']:8.1f}")
pt = []
for path in glob.glob(os.path.join(w, "pt_spp*.json")):
    if path.endswith(".compare.json"):
        continue
    st = json.load(open(path))
    c = json.load(open(path[:-5] + ".compare.json"))
    pt.append((st["spp"], c["relmse"], 1000.0 * st["seconds"]))
pt.sort()
for spp, e, ms in pt:
    print(f"{'path tracer, ' + str(spp) + ' spp':<28} {e:9.3e} {ms:10.1f} {1000.0 / ms:8.2f}")
print()
for s, target, ms in lf:
    # First spp at or below the target, and log-log interpolation with the one before it.
    hit = next((i for i, p in enumerate(pt) if p[1] <= target), None)
    if hit is None:
        print(f"light field {s} spp (relMSE {target:.3e}, {ms:.2f} ms): the path tracer did not reach it by "
              f"{pt[-1][0]} spp ({pt[-1][2] / 1000.0:.1f} s, relMSE {pt[-1][1]:.3e})")
        continue
    if hit == 0:
        t = pt[0][2]
    else:
        (s0, e0, t0), (s1, e1, t1) = pt[hit - 1], pt[hit]
        f = math.log(e0 / target) / math.log(e0 / e1) if e0 != e1 else 1.0
        t = math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    print(f"light field {s} spp (relMSE {target:.3e}, {ms:.2f} ms/frame): the path tracer needs ≈ {t:.0f} ms "
          f"(reached at {pt[hit][0]} spp, {pt[hit][2]:.0f} ms) — {t / ms:.0f}× the light-field frame time")
PY
