#!/usr/bin/env bash
# Overhead of a trace called from Python against the command line doing the same work:
# `plenoptic trace cornell` at 256x256 (default 64 spp) vs plenoptic.trace(...) with the same
# settings, both measured by the tracer's own render time (the stats' `seconds`) and by the
# whole call (process or function), REPEATS times each, interleaved; prints the medians. Both
# draw their progress bar to stderr (the module told to with set_progress(True), as the command
# always does).
#   bench/python_overhead.sh [BUILD_DIR] [REPEATS] [SPP]
set -euo pipefail
BUILD=${1:-build}
REPEATS=${2:-5}
SPP=${3:-64}
PYTHON=${PYTHON:-$(command -v /usr/bin/python3 || command -v python3)}  # Debian python3 has numpy
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cli_wall=(); cli_render=(); py_wall=(); py_render=()
for ((i = 0; i < REPEATS; i++)); do
  start=$(date +%s.%N)
  "$BUILD/plenoptic" trace cornell -o "$TMP/t.pfm" --width 256 --height 256 --spp "$SPP" --stats "$TMP/s.json" >/dev/null
  end=$(date +%s.%N)
  cli_wall+=("$(echo "$end - $start" | bc)")
  cli_render+=("$("$PYTHON" -c "import json; print(json.load(open('$TMP/s.json'))['seconds'])")")
  out=$(PYTHONPATH="$BUILD/python" "$PYTHON" - "$SPP" <<'PY'
import sys, time
start = time.perf_counter()
import plenoptic
plenoptic.set_progress(True)
scene = plenoptic.load_scene("cornell")
image, stats = plenoptic.trace(scene, width=256, height=256, spp=int(sys.argv[1]))
print(time.perf_counter() - start, stats["seconds"])
PY
)
  py_wall+=("${out% *}"); py_render+=("${out#* }")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
cw=$(median "${cli_wall[@]}"); cr=$(median "${cli_render[@]}")
pw=$(median "${py_wall[@]}"); pr=$(median "${py_render[@]}")
echo "trace cornell 256x256, $SPP spp, $REPEATS runs each (medians)"
echo "  CLI:    whole process $cw s, render $cr s"
echo "  Python: import+load+trace $pw s, render $pr s"
echo "  overhead of the whole call: $(echo "scale=2; 100 * ($pw - $cw) / $cw" | bc) %"
