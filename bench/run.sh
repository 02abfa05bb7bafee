#!/usr/bin/env bash
# Runs every Google Benchmark binary of a build directory (BUILD_DIR/bench/*_bench) with 5
# repetitions and prints the median of each benchmark (rates such as Mrays/s, paths_per_s
# are in the counters column). Extra arguments are passed to every binary, e.g.
#   bench/run.sh build --benchmark_filter=Primary
# Usage: bench/run.sh BUILD_DIR [benchmark flags...]
# Environment: VS_CYCLES=1 also runs bench/vs_cycles.sh (plenoptic against Blender Cycles);
# PRODUCTION=1 also runs bench/production.sh (Sponza and the Cornell box at every preset).
set -euo pipefail

if [[ $# -lt 1 ]]; then
  echo "usage: $0 BUILD_DIR [benchmark flags...]" >&2
  exit 2
fi
build_dir=$1
shift
bench_dir="$build_dir/bench"
if [[ ! -d "$bench_dir" ]]; then
  echo "$0: $bench_dir does not exist (configure and build the benchmarks first:" >&2
  echo "  cmake --build $build_dir --target ray_bench trace_bench ...)" >&2
  exit 1
fi

shopt -s nullglob
binaries=()
for candidate in "$bench_dir"/*_bench; do
  [[ -f "$candidate" && -x "$candidate" ]] && binaries+=("$candidate")
done
if [[ ${#binaries[@]} -eq 0 ]]; then
  echo "$0: no *_bench executables in $bench_dir (build them first)" >&2
  exit 1
fi

status=0
for binary in "${binaries[@]}"; do
  echo "== $(basename "$binary")"
  # Aggregates only; keep the header line and the medians.
  if ! output=$("$binary" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true "$@" 2>&1); then
    echo "$output" >&2
    echo "$0: $(basename "$binary") failed" >&2
    status=1
    continue
  fi
  echo "$output" | grep -E '^(Benchmark|-{10,}|.*_median)' || true
done
# Optional: plenoptic against Blender Cycles (many minutes; says so and skips when Blender is
# not installed). Only with VS_CYCLES=1, e.g. `make bench VS_CYCLES=1`.
if [[ ${VS_CYCLES:-0} == 1 ]]; then
  echo "== vs_cycles"
  bash "$(dirname "$0")/vs_cycles.sh" "$build_dir/plenoptic" || status=1
fi
# Optional: the production-scene benchmark (tens of minutes; measures the Cornell box alone when
# Sponza is absent). Only with PRODUCTION=1, e.g. `make bench PRODUCTION=1`.
if [[ ${PRODUCTION:-0} == 1 ]]; then
  echo "== production"
  bash "$(dirname "$0")/production.sh" "$build_dir/plenoptic" || status=1
fi
exit $status
