#!/usr/bin/env bash
# Bake speed and memory (issue 4's targets): for each preset, bakes a scene from scratch and
# re-bakes it reusing the saved visibility field (--reuse-visibility), alternately, RUNS times,
# and prints the medians of the whole-command time (`seconds` in --stats), their ratio (the
# re-propagation share of a full bake, target ≤ 20 % at default), the iterations, peak RSS,
# the .plf and .plv sizes and the visibility ray rate.
#
# Alternating the two kinds of run, and comparing medians of the same run, keeps the ratio
# meaningful on a shared, noisy machine; the absolute times still drift with its load.
#
# Usage: bench/bake_bench.sh [PLENOPTIC] [WORKDIR] [RUNS] [SCENE] [PRESETS...]
#   PLENOPTIC  the executable (default: build/plenoptic)
#   WORKDIR    where the files go (default: out/bake-bench)
#   RUNS       runs of each kind per preset (default: 9)
#   SCENE      what to bake (default: cornell, the built-in Cornell box)
#   PRESETS    default: draft default high
set -euo pipefail

plenoptic=${1:-build/plenoptic}
workdir=${2:-out/bake-bench}
runs=${3:-9}
scene=${4:-cornell}
shift $(($# < 4 ? $# : 4))
presets=("$@")
[[ ${#presets[@]} -gt 0 ]] || presets=(draft default high)

if [[ ! -x "$plenoptic" ]]; then
  echo "$0: $plenoptic is not an executable (build it first: make build)" >&2
  exit 1
fi
mkdir -p "$workdir"

for preset in "${presets[@]}"; do
  base="$workdir/$preset"
  echo "== $scene, preset $preset: $runs full bakes and $runs re-propagations, alternating" >&2
  for ((i = 1; i <= runs; ++i)); do
    "$plenoptic" --quiet bake "$scene" --preset "$preset" -o "$base.plf" --visibility "$base.plv" \
      --stats "$base.full.$i.json" >/dev/null
    "$plenoptic" --quiet bake "$scene" --preset "$preset" -o "$base.plf" --visibility "$base.plv" \
      --reuse-visibility --stats "$base.reuse.$i.json" >/dev/null
  done
  python3 - "$base" "$runs" "$preset" <<'PY'
import json, os, statistics, sys
base, runs, preset = sys.argv[1], int(sys.argv[2]), sys.argv[3]
full = [json.load(open(f"{base}.full.{i}.json")) for i in range(1, runs + 1)]
reuse = [json.load(open(f"{base}.reuse.{i}.json")) for i in range(1, runs + 1)]
if not all(r["reused_visibility"] for r in reuse):
    sys.exit(f"{preset}: a --reuse-visibility run did not reuse the field")
med = lambda runs, key: statistics.median(r[key] for r in runs)
f, r = med(full, "seconds"), med(reuse, "seconds")
print(f"{preset:8s} full {f:.3f} s (visibility {med(full, 'visibility_seconds'):.3f} s at "
      f"{med(full, 'visibility_rays_per_second') / 1e6:.1f} Mrays/s, propagation {med(full, 'propagation_seconds'):.3f} s, "
      f"{full[0]['iterations']} iterations, residual {full[0]['residual']:.1e})")
print(f"{'':8s} re-propagation {r:.3f} s = {100 * r / f:.1f} % of the full bake "
      f"(min {min(x['seconds'] for x in reuse):.3f}, max {max(x['seconds'] for x in reuse):.3f} s; "
      f"full min {min(x['seconds'] for x in full):.3f}, max {max(x['seconds'] for x in full):.3f} s)")
print(f"{'':8s} peak RSS {max(x['peak_rss_bytes'] for x in full) / 2**20:.0f} MiB, {full[0]['tixels']} tixels, "
      f".plf {full[0]['file_bytes'] / 1e3:.0f} kB, .plv {os.path.getsize(base + '.plv') / 1e6:.1f} MB")
PY
done
