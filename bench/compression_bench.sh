#!/usr/bin/env bash
# Light-field compression figures (issue: light-field compression): for the built-in Cornell
# box and CornellBox-Glossy at the default bake preset, every value mode's file size, ratio,
# encode and decode time, and the error of a render from the compressed file against a
# render from the uncompressed one (relMSE on the HDR image via `plenoptic compare`, PSNR on
# the tone-mapped PNG via bench/png_psnr.py).
#
# Usage: bench/compression_bench.sh [PLENOPTIC_BINARY] [WORK_DIR]
#   PLENOPTIC_BINARY  default: build/plenoptic
#   WORK_DIR          default: a new temporary directory (kept, printed at the end)
# Environment: SCENES_DIR (default: the McGuire scenes in tests/data/cornell-mcguire),
# RENDER_FLAGS (`render` flags; default "--reference": the straightforward renderer of
# src/render, so the figures measure the light field, not a renderer's approximations; "" for
# the fast renderer), MODES (default "lossless bc1 hdr").
#
# Columns: values ratio = raw float32 values / stored VALS section; file ratio = the whole
# .plf stored raw / as written; encode = encode + write + fsync of the whole file (s);
# decode = readLightField of the written file, median of 5 (s), including the scene.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
plenoptic="${1:-build/plenoptic}"
work="${2:-$(mktemp -d -t plenoptic-compression-XXXXXX)}"
scenes_dir="${SCENES_DIR:-$here/../tests/data/cornell-mcguire}"
modes="${MODES:-lossless bc1 hdr}"
read -r -a renderFlags <<< "${RENDER_FLAGS---reference}"
mkdir -p "$work"

json() {  # json FILE KEY: one top-level value of a JSON file
  python3 -c 'import json,sys; v=json.load(open(sys.argv[1]))[sys.argv[2]]; print(v)' "$1" "$2"
}

printf '| scene | mode | file bytes | values ratio | file ratio | encode s | decode s | render relMSE | PNG PSNR dB |\n'
printf '|---|---|---:|---:|---:|---:|---:|---:|---:|\n'
for entry in "cornell:cornell" "glossy:$scenes_dir/CornellBox-Glossy.obj"; do
  name="${entry%%:*}"
  scene="${entry#*:}"
  base="$work/$name"
  "$plenoptic" bake "$scene" -o "$base.plf" --preset default --compress none --quiet > /dev/null 2>&1
  "$plenoptic" render "$base.plf" -o "$base-none.exr" --quiet "${renderFlags[@]}" > /dev/null
  "$plenoptic" render "$base.plf" -o "$base-none.png" --quiet "${renderFlags[@]}" > /dev/null
  for mode in none $modes; do
    out="$base-$mode"
    "$plenoptic" compress "$base.plf" -o "$out.plf" --mode "$mode" --stats "$out.json" --quiet > /dev/null
    "$plenoptic" render "$out.plf" -o "$out.exr" --quiet "${renderFlags[@]}" > /dev/null
    "$plenoptic" render "$out.plf" -o "$out.png" --quiet "${renderFlags[@]}" > /dev/null
    relmse=$("$plenoptic" compare "$out.exr" "$base-none.exr" --json |
             python3 -c 'import json,sys; print("%.3g" % json.load(sys.stdin)["relmse"])')
    psnr=$(python3 "$here/png_psnr.py" "$out.png" "$base-none.png")
    printf '| %s | %s | %s | %.2f:1 | %.2f:1 | %.3f | %.4f | %s | %s |\n' "$name" "$mode" \
      "$(json "$out.json" file_bytes)" "$(json "$out.json" values_ratio)" "$(json "$out.json" file_ratio)" \
      "$(json "$out.json" encode_write_seconds)" "$(json "$out.json" decode_read_seconds)" "$relmse" "$psnr"
  done
done
echo
echo "files, renders and per-mode JSON statistics in $work"
