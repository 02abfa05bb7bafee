#!/usr/bin/env bash
# The conformance matrix (issue 31, item 1): the light field against the path tracer over small
# scenes spanning materials x lights x geometry (bench/conformance/make_scenes.py writes them;
# `make_scenes.py --list` names each case and what it varies).
#
# For each case and each preset:
#   1. plenoptic bake CASE.json -o CASE.PRESET.plf --preset PRESET --stats CASE.PRESET.bake.json
#   2. plenoptic render CASE.PRESET.plf --spp LF_SAMPLES (SIZE×SIZE) -o CASE.PRESET.lf.pfm
#   3. plenoptic trace CASE.json --spp REF_SPP --variance CASE.refvar.pfm (SIZE×SIZE)
#      -o CASE.ref.pfm      (once per case, shared by the presets)
#   4. plenoptic compare CASE.PRESET.lf.pfm CASE.ref.pfm --json --heatmap CASE.PRESET.heat.png
# and prints a Markdown table (also written to WORKDIR/conformance.md): case, preset,
# mean-luminance ratio (light field / path trace, Rec.709 Y), relMSE (compare.h: mean
# (a−b)²/(b²+0.01)), "ref noise" — the part of that relMSE the reference's own Monte Carlo
# noise accounts for, mean var/(b²+0.01) over pixels and channels from `trace --variance`, as in
# bench/accuracy.sh —, "LF error" = relMSE − ref noise (the light field's own error against a
# converged trace), the reference's mean luminance, bake seconds, and PASS/FAIL against the
# targets of issue 31:
#   default, high: |ratio − 1| ≤ 0.02 and LF error ≤ 0.01
#   draft:         |ratio − 1| ≤ 0.05
# A case whose bake, render or trace fails (a bake the memory guard refuses, a scene the loader
# rejects) is a row saying so (ERROR and the command's message), and the run goes on. Stopped by
# SIGINT or SIGTERM, the run finishes the command at hand and prints the table of what is done.
#
# Usage: bench/conformance.sh [PLENOPTIC] [WORKDIR]
#   PLENOPTIC  the executable (default: build/plenoptic)
#   WORKDIR    where every file goes (default: out/conformance); the scenes go to WORKDIR/scenes
# Environment: CASES (space-separated subset of the case names; default all), PRESETS (default
# "draft default"), SIZE (image side, default 128), REF_SPP (reference samples per pixel,
# default 1024), LF_SAMPLES (light-field camera samples per pixel, default 16), THREADS (passed
# as --threads; default: the program's own, all hardware threads), PYTHON (default /usr/bin/python3
# when present, else python3).
set -uo pipefail

here=$(cd "$(dirname "$0")" && pwd)
plenoptic=${1:-build/plenoptic}
workdir=${2:-out/conformance}
presets=${PRESETS:-draft default}
size=${SIZE:-128}
ref_spp=${REF_SPP:-1024}
lf_samples=${LF_SAMPLES:-16}
python=${PYTHON:-$([[ -x /usr/bin/python3 ]] && echo /usr/bin/python3 || echo python3)}

if [[ ! -x "$plenoptic" ]]; then
  echo "$0: $plenoptic is not an executable (build it: cmake --build build --target plenoptic)" >&2
  exit 1
fi
mkdir -p "$workdir/scenes"
generator="$here/conformance/make_scenes.py"
# shellcheck disable=SC2086  # CASES is a list of names
"$python" "$generator" --list ${CASES:-} >"$workdir/cases.tsv" || exit 1
# shellcheck disable=SC2086
"$python" "$generator" "$workdir/scenes" ${CASES:-} || exit 1
mapfile -t cases < <(cut -f1 "$workdir/cases.tsv")

global=(--quiet)
[[ -n "${THREADS:-}" ]] && global+=(--threads "$THREADS")
size_flags=(--width "$size" --height "$size")

# run STATUSFILE CMD...: runs the command with its output in STATUSFILE.log; on failure writes
# the last "error" line of that output (else its last line) to STATUSFILE and returns 1.
run() {
  local status=$1
  shift
  "$@" >"$status.log" 2>&1
  local rc=$?
  ((rc == 0)) && return 0
  { grep -i "error" "$status.log" | tail -n 1 || true; } >"$status"
  [[ -s "$status" ]] || tail -n 1 "$status.log" >"$status"
  [[ -s "$status" ]] || echo "exit status $rc" >"$status"
  return 1
}

# SIGINT/SIGTERM: stop after the current command and print the table of what is done (the rest
# "not run").
interrupted=
trap 'interrupted=1' INT TERM
for name in "${cases[@]}"; do  # no stale results of an earlier run in the table
  rm -f "$workdir/$name".*.failed "$workdir/$name".*.compare.json "$workdir/$name".*.bake.json
done
start=$SECONDS
for name in "${cases[@]}"; do
  [[ -n "$interrupted" ]] && break
  scene="$workdir/scenes/$name.json"
  out="$workdir/$name"
  echo "== $name: reference ($ref_spp spp, ${size}x$size)" >&2
  run "$out.ref.failed" "$plenoptic" "${global[@]}" trace "$scene" -o "$out.ref.pfm" --variance "$out.refvar.pfm" \
    --spp "$ref_spp" "${size_flags[@]}" --stats "$out.trace.json" && rm -f "$out.ref.failed"
  for preset in $presets; do
    [[ -n "$interrupted" ]] && break
    o="$out.$preset"
    echo "== $name: bake ($preset), render ($lf_samples samples per pixel), compare" >&2
    run "$o.failed" "$plenoptic" "${global[@]}" bake "$scene" -o "$o.plf" --preset "$preset" --stats "$o.bake.json" &&
      run "$o.failed" "$plenoptic" "${global[@]}" render "$o.plf" -o "$o.lf.pfm" --spp "$lf_samples" "${size_flags[@]}" &&
      [[ ! -e "$out.ref.failed" ]] &&
      { "$plenoptic" "${global[@]}" compare "$o.lf.pfm" "$out.ref.pfm" --json --heatmap "$o.heat.png" \
          >"$o.compare.json" 2>"$o.failed.log" ||
        { echo "compare: $(tail -n 1 "$o.failed.log")" >"$o.failed"; false; }; } &&
      rm -f "$o.failed"
    rm -f "$o.plf"  # the light fields are large (glossy maps) and not needed for the table
  done
done
elapsed=$((SECONDS - start))

BENCH_DIR="$here" "$python" - "$workdir" "$size" "$ref_spp" "$lf_samples" "$elapsed" "$presets" <<'PY'
import json, os, sys

sys.path.insert(0, os.environ["BENCH_DIR"])
from pfm import read_pfm

workdir, size, ref_spp, lf_samples, elapsed, presets = sys.argv[1:7]
presets = presets.split()
TARGETS = {"draft": (0.05, None), "default": (0.02, 0.01), "high": (0.02, 0.01)}
cases = [line.rstrip("\n").split("\t", 1) for line in open(os.path.join(workdir, "cases.tsv")) if line.strip()]


def text(path):
    with open(path) as f:
        return " ".join(f.read().split()).replace("|", "/")


lines = [
    f"Light field (`render --spp {lf_samples}`) against the path tracer (`trace --spp {ref_spp} --variance`), "
    f"{size}×{size}; targets: draft |ratio − 1| ≤ 0.05; default and high |ratio − 1| ≤ 0.02 and LF error "
    f"(relMSE − ref noise) ≤ 0.01.",
    "",
    "| case | preset | mean Y ratio | relMSE | ref noise | LF error | ref mean Y | bake s | result |",
    "|---|---|---|---|---|---|---|---|---|",
]
passed = failed = errors = not_run = 0
noise_cache = {}
for name, varies in cases:
    out = os.path.join(workdir, name)
    for preset in presets:
        o = f"{out}.{preset}"
        failure = None
        if os.path.exists(out + ".ref.failed"):
            failure = "reference failed: " + text(out + ".ref.failed")
        elif os.path.exists(o + ".failed"):
            failure = text(o + ".failed")
        bake_s = "–"
        if os.path.exists(o + ".bake.json"):
            bake_s = f"{json.load(open(o + '.bake.json'))['seconds']:.2f}"
        if not failure and not os.path.exists(o + ".compare.json"):
            failure = "not run (interrupted)"
        if failure:
            not_run += failure.startswith("not run")
            errors += not failure.startswith("not run")
            label = failure if failure.startswith("not run") else "ERROR: " + failure
            lines.append(f"| {name} | {preset} | | | | | | {bake_s} | {label} |")
            continue
        cmp = json.load(open(o + ".compare.json"))
        if name not in noise_cache:
            ref, var = read_pfm(out + ".ref.pfm"), read_pfm(out + ".refvar.pfm")
            noise = sum(v / (r * r + 0.01) for r, v in zip(ref, var)) / len(ref)
            mean_y = sum(0.2126 * ref[i] + 0.7152 * ref[i + 1] + 0.0722 * ref[i + 2]
                         for i in range(0, len(ref), 3)) / (len(ref) / 3)
            noise_cache[name] = (noise, mean_y)
        noise, mean_y = noise_cache[name]
        ratio, relmse = cmp["mean_luminance_ratio"], cmp["relmse"]
        lf_error = relmse - noise
        max_dev, max_err = TARGETS.get(preset, TARGETS["default"])
        why = []
        if not abs(ratio - 1) <= max_dev:
            why.append(f"ratio off by {100 * (ratio - 1):+.1f} %")
        if max_err is not None and not lf_error <= max_err:
            why.append(f"LF error > {max_err}")
        result = "PASS" if not why else "FAIL (" + "; ".join(why) + ")"
        passed += not why
        failed += bool(why)
        lines.append(f"| {name} | {preset} | {ratio:.4f} | {relmse:.2e} | {noise:.1e} | {lf_error:.2e} | "
                     f"{mean_y:.3f} | {bake_s} | {result} |")
lines += ["", f"{passed} passed, {failed} failed, {errors} errors" + (f", {not_run} not run" if not_run else "") + "; "
          f"{int(elapsed) // 60} min {int(elapsed) % 60} s "
          f"for the whole run (bakes, renders, references).", "",
          "| case | what it varies |", "|---|---|"]
lines += [f"| {name} | {varies} |" for name, varies in cases]
table = "\n".join(lines) + "\n"
sys.stdout.write(table)
with open(os.path.join(workdir, "conformance.md"), "w") as f:
    f.write(table)
PY
