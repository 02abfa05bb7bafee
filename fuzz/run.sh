#!/usr/bin/env bash
# Runs the libFuzzer targets built by `make fuzz`: fuzz/run.sh BUILD_DIR SECONDS TARGET...
# Each target runs for SECONDS (or until FUZZ_RUNS=N executions when set, if sooner), niced, starting from its
# regression corpus tests/data/fuzz/<target>/ plus the matching sample files of tests/data.
# New coverage goes to BUILD_DIR/corpus/<target>/ (kept between runs), crashing inputs to
# BUILD_DIR/findings/<target>/, the log to BUILD_DIR/logs/<target>.log. A crash found here
# belongs, once fixed, in tests/data/fuzz/<target>/ (replayed by fuzz_replay_test).
set -uo pipefail
build=$1
seconds=$2
shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
data=$root/tests/data

# Sample files of tests/data that seed each target (besides tests/data/fuzz/<target>/).
seed_pattern() {
  case $1 in
    obj) echo '*.obj' ;;
    gltf) echo '*.gltf *.glb' ;;
    json_scene) echo '*.json' ;;
    hdr) echo '*.hdr' ;;
    exr) echo '*.exr' ;;
    plf | plf_fixed) echo '*.plf' ;;
    *) echo '' ;;
  esac
}

status=0
for target in "$@"; do
  binary=$build/fuzz/fuzz_$target
  [ -x "$binary" ] || { echo "fuzz: $binary not built" >&2; exit 1; }
  corpus=$build/corpus/$target seeds=$build/seeds/$target findings=$build/findings/$target
  scratch=$build/tmp/$target log=$build/logs/$target.log
  rm -rf "$seeds" "$scratch"
  mkdir -p "$corpus" "$seeds" "$findings" "$scratch" "$(dirname "$log")"
  for pattern in $(seed_pattern "$target"); do
    find "$data" -path "$data/fuzz" -prune -o -name "$pattern" -type f -print | while read -r f; do
      cp "$f" "$seeds/$(echo "${f#$data/}" | tr / _)"
    done
  done
  [ -d "$data/fuzz/$target" ] && cp "$data/fuzz/$target"/* "$seeds/" 2>/dev/null
  limit=(-max_total_time="$seconds")
  [ -n "${FUZZ_RUNS:-}" ] && limit+=(-runs="$FUZZ_RUNS")
  echo "fuzz $target: $seconds s${FUZZ_RUNS:+ or $FUZZ_RUNS executions, whichever comes first} ..." >&2
  # 64 KiB inputs at most; 2 GB of memory and FUZZ_TIMEOUT seconds per input (default 10) before
  # libFuzzer calls it a bug. On a loaded machine a niced fuzzer can be starved for longer than
  # 10 s on one input (a 272 ms EXR input was reported at load 18): raise it there.
  TMPDIR=$scratch nice -n 10 "$binary" "${limit[@]}" -max_len=65536 -rss_limit_mb=2048 -timeout="${FUZZ_TIMEOUT:-10}" \
    -print_final_stats=1 -artifact_prefix="$findings/" "$corpus" "$seeds" >"$log" 2>&1
  rc=$?
  executions=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  crashes=$(find "$findings" -type f | wc -l)
  echo "fuzz $target: ${executions:-?} executions, exit $rc, $crashes file(s) in $findings" >&2
  [ "$rc" -eq 0 ] || status=1
  rm -rf "$scratch"
done
exit $status
