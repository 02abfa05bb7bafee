#!/usr/bin/env bash
# One case of the conformance matrix as a test (tests/conformance/CMakeLists.txt registers it):
# writes the case's scene with bench/conformance/make_scenes.py, bakes it, renders the light
# field, path-traces the reference at the same size, compares them, and fails unless
#   RATIO_MIN ≤ mean-luminance ratio (light field / path trace) ≤ RATIO_MAX  and  relMSE ≤ RELMSE_MAX.
# relMSE is compare's raw figure, the reference's own noise included (printed beside it as
# "ref noise", mean var/(ref²+0.01) from `trace --variance`, with "ratio sigma", the reference
# mean luminance's relative standard error, which the ratio bounds' margins are based on).
# Every command runs with --threads 1 (and the default seed), so the figures do not depend on
# the machine: the same binary gives the same numbers.
#
# Usage: tests/conformance/run_case.sh PLENOPTIC CASE PRESET SIZE REF_SPP LF_SAMPLES RATIO_MIN RATIO_MAX RELMSE_MAX
# Environment: PYTHON (default /usr/bin/python3 when present, else python3), KEEP_DIR (a directory
# to keep the files in instead of a temporary one), EXTRA_BAKE_FLAGS (appended to the bake: a
# way to check that a test fails on a worse light field, e.g. "--tixels-across 2").
set -euo pipefail

if [[ $# -ne 9 ]]; then
  sed -n 's/^# Usage: //p' "$0" >&2
  exit 2
fi
plenoptic=$1 name=$2 preset=$3 size=$4 ref_spp=$5 lf_samples=$6 ratio_min=$7 ratio_max=$8 relmse_max=$9
here=$(cd "$(dirname "$0")" && pwd)
python=${PYTHON:-$([[ -x /usr/bin/python3 ]] && echo /usr/bin/python3 || echo python3)}

if [[ -n "${KEEP_DIR:-}" ]]; then
  work=$KEEP_DIR
  mkdir -p "$work"
else
  work=$(mktemp -d "${TMPDIR:-/tmp}/conformance-$name.XXXXXX")
  trap 'rm -rf "$work"' EXIT
fi

"$python" "$here/../../bench/conformance/make_scenes.py" "$work" "$name"
scene="$work/$name.json"
common=(--quiet --threads 1)
size_flags=(--width "$size" --height "$size")
# shellcheck disable=SC2086  # EXTRA_BAKE_FLAGS is a list of flags
"$plenoptic" "${common[@]}" bake "$scene" -o "$work/lf.plf" --preset "$preset" ${EXTRA_BAKE_FLAGS:-}
"$plenoptic" "${common[@]}" render "$work/lf.plf" -o "$work/lf.pfm" --spp "$lf_samples" "${size_flags[@]}"
"$plenoptic" "${common[@]}" trace "$scene" -o "$work/ref.pfm" --variance "$work/refvar.pfm" --spp "$ref_spp" \
  "${size_flags[@]}"
"$plenoptic" --quiet compare "$work/lf.pfm" "$work/ref.pfm" --json >"$work/compare.json"

"$python" - "$work" "$name" "$ratio_min" "$ratio_max" "$relmse_max" "$here/../../bench" <<'PY'
import json, math, sys

work, name, ratio_min, ratio_max, relmse_max, bench = sys.argv[1], sys.argv[2], *map(float, sys.argv[3:6]), sys.argv[6]
sys.path.insert(0, bench)
from pfm import read_pfm

cmp = json.load(open(f"{work}/compare.json"))
ref, var = read_pfm(f"{work}/ref.pfm"), read_pfm(f"{work}/refvar.pfm")
w = (0.2126, 0.7152, 0.0722)
n = len(ref) // 3
mean_y = sum(w[0] * ref[i] + w[1] * ref[i + 1] + w[2] * ref[i + 2] for i in range(0, len(ref), 3)) / n
var_mean_y = sum(w[0] ** 2 * var[i] + w[1] ** 2 * var[i + 1] + w[2] ** 2 * var[i + 2] for i in range(0, len(var), 3)) / n ** 2
noise = sum(v / (r * r + 0.01) for r, v in zip(ref, var)) / len(ref)
ratio, relmse = cmp["mean_luminance_ratio"], cmp["relmse"]
print(f"{name}: mean-luminance ratio {ratio:.4f} (bounds [{ratio_min}, {ratio_max}], ratio sigma "
      f"{math.sqrt(var_mean_y) / mean_y:.4f}), relMSE {relmse:.3e} (bound {relmse_max}, ref noise {noise:.2e}), "
      f"reference mean luminance {mean_y:.4f}")
ok = ratio_min <= ratio <= ratio_max and relmse <= relmse_max
if not ok:
    print(f"{name}: FAIL: outside the bounds")
sys.exit(0 if ok else 1)
PY
