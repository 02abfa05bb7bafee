#!/usr/bin/env bash
# The GPU renderer against the CPU fast renderer on a baked light field: for each of the
# scene's cameras, `render --renderer gpu` and `--renderer cpu` at WIDTH × HEIGHT (one sample
# per pixel), compared (relMSE, mean ratio, max error), with the GPU's memory against the
# decoded light field and textures, and the two renderers' frame times (FRAMES frames each).
# Without a .plf it bakes Sponza's draft light field first (several minutes on two cores).
#   bench/gpu_vs_cpu.sh [PLF] [WIDTH] [HEIGHT] [FRAMES]
#   PLENOPTIC=build/plenoptic (default) names the binary.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${PLENOPTIC:-$ROOT/build/plenoptic}
PLF=${1:-}; WIDTH=${2:-160}; HEIGHT=${3:-120}; FRAMES=${4:-5}
D=$(mktemp -d)
trap 'rm -rf "$D"' EXIT
if [ -z "$PLF" ]; then
  SPONZA=${SPONZA:-/work/shared/scenes/sponza/sponza.json}
  [ -f "$SPONZA" ] || { echo "gpu_vs_cpu: no PLF given and $SPONZA is absent" >&2; exit 1; }
  PLF=$D/sponza.plf
  echo "baking $SPONZA (draft) ..."
  "$BIN" bake "$SPONZA" --preset draft -o "$PLF" --quiet >/dev/null
fi
cameras=$("$BIN" info "$PLF" --json | python3 -c \
  "import json,sys; print(' '.join(json.load(sys.stdin)['scene']['cameras']))")
for camera in $cameras; do
  for renderer in gpu cpu; do
    "$BIN" render "$PLF" --camera "$camera" -o "$D/$renderer.pfm" --width "$WIDTH" --height "$HEIGHT" \
      --renderer "$renderer" --frames "$FRAMES" --stats "$D/$renderer.json" --quiet >/dev/null
  done
  "$BIN" compare "$D/gpu.pfm" "$D/cpu.pfm" --json > "$D/compare.json"
  python3 - "$camera" "$WIDTH" "$HEIGHT" "$D" <<'PY'
import json, sys
camera, width, height, d = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
c = json.load(open(f"{d}/compare.json"))
g = json.load(open(f"{d}/gpu.json"))
p = json.load(open(f"{d}/cpu.json"))
mib = 1 << 20
print(f"{camera} {width}x{height}: relMSE {c['relmse']:.3g}, mean luminance ratio {c['mean_luminance_ratio']:.5f}, "
      f"max |difference| {c['max_abs_error']:.3g}")
print(f"  GPU memory: light field {g['gpu_light_field_bytes'] / mib:.2f} MiB = "
      f"{g['gpu_light_field_bytes'] / g['light_field_bytes']:.2f} x the decoded light field and textures "
      f"({g['light_field_bytes'] / mib:.2f} MiB); with the frame's targets {g['gpu_bytes'] / mib:.2f} MiB")
print(f"  frame: gpu {g['ms_per_frame_median']:.1f} ms ({g['device']}), cpu {p['ms_per_frame_median']:.1f} ms "
      f"({p['threads']} threads): gpu / cpu {g['ms_per_frame_median'] / p['ms_per_frame_median']:.2f}")
PY
done
