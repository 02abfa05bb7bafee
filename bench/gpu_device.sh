#!/usr/bin/env bash
# The GPU renderer on a graphics card, in one run: the frame rate of `render --renderer gpu`
# on the built-in Cornell box and on Sponza at 1920×1080 (each camera; rasterised ids, then
# every camera ray through the BVH: PLENOPTIC_GPU_VISIBILITY=rays), the viewer's on the
# box and on Sponza's `main` (`view --renderer gpu` flying a path, headless), the display pass
# alone per tone curve (bench/gpu_display_bench, where it is built beside the binary, as
# build/bench/), and the GPU-vs-CPU
# comparison of bench/gpu_vs_cpu.sh on both light fields — so that minutes on a lent machine
# go to measuring. It bakes what it is not given (draft preset: the box in seconds, Sponza in
# a minute or two on 16 cores) and refuses to measure a software rasteriser (llvmpipe) unless
# PLENOPTIC_ALLOW_SOFTWARE=1 (how it is checked on a machine without a graphics card).
#   bench/gpu_device.sh [SPONZA]     SPONZA: a Sponza .plf, or the scene to bake it from
#                                    (default /work/shared/scenes/sponza/sponza.json)
#   PLENOPTIC=build/plenoptic (default) names the binary; FRAMES=200 frames per measurement;
#   WIDTH=1920 HEIGHT=1080 the frame size; COMPARE_WIDTH=160 COMPARE_HEIGHT=120 the
#   comparison's; OUT (a folder) keeps the light fields, the stats and the summary.
# NVIDIA's EGL is found through its glvnd vendor file: __EGL_VENDOR_LIBRARY_FILENAMES is set to
# /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json where that file exists.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${PLENOPTIC:-$ROOT/build/plenoptic}
SPONZA=${1:-/work/shared/scenes/sponza/sponza.json}
FRAMES=${FRAMES:-200}; WIDTH=${WIDTH:-1920}; HEIGHT=${HEIGHT:-1080}
COMPARE_WIDTH=${COMPARE_WIDTH:-160}; COMPARE_HEIGHT=${COMPARE_HEIGHT:-120}
[ -x "$BIN" ] || { echo "gpu_device: $BIN is not built (make build, or set PLENOPTIC)" >&2; exit 1; }
NVIDIA_EGL=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] && [ -f "$NVIDIA_EGL" ]; then
  export __EGL_VENDOR_LIBRARY_FILENAMES=$NVIDIA_EGL
fi
if [ -n "${OUT:-}" ]; then D=$OUT; mkdir -p "$D"; else D=$(mktemp -d); trap 'rm -rf "$D"' EXIT; fi
SUMMARY=$D/gpu_device.txt
: > "$SUMMARY"
say() { echo "$@" | tee -a "$SUMMARY"; }

command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader |
  sed 's/^/nvidia-smi: /' | tee -a "$SUMMARY" || true

# The light fields: the built-in box always baked here, Sponza given or baked.
"$BIN" bake cornell --preset draft -o "$D/cornell.plf" --quiet >/dev/null
case "$SPONZA" in
  *.plf) SPONZA_PLF=$SPONZA ;;
  *)
    [ -f "$SPONZA" ] || { echo "gpu_device: $SPONZA is absent (give a Sponza .plf or scene)" >&2; exit 1; }
    SPONZA_PLF=$D/sponza.plf
    start=$(date +%s)
    "$BIN" bake "$SPONZA" --preset draft -o "$SPONZA_PLF" --quiet >/dev/null
    say "Sponza draft bake: $(( $(date +%s) - start )) s"
    ;;
esac

# One measurement: `render --renderer gpu` of FRAMES frames; prints the device and frame rate.
measure() {  # name plf camera width height
  local stats=$D/$1.json
  "$BIN" render "$2" --camera "$3" -o "$D/$1.pfm" --renderer gpu --width "$4" --height "$5" --frames "$FRAMES" \
    --stats "$stats" --quiet >/dev/null
  python3 - "$1" "$stats" "${PLENOPTIC_ALLOW_SOFTWARE:-0}" <<'PY' | tee -a "$SUMMARY"
import json, sys
name, path, allow_software = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
s = json.load(open(path))
if any(w in s["device"].lower() for w in ("llvmpipe", "softpipe", "software rasterizer")) and not allow_software:
    sys.exit(f"gpu_device: {s['device']} is a software rasteriser, not a graphics card "
             "(PLENOPTIC_ALLOW_SOFTWARE=1 measures it anyway)")
print(f"{name} {s['width']}x{s['height']}: {s['fps']:.1f} fps ({s['ms_per_frame_median']:.3f} ms/frame median, "
      f"min {s['ms_per_frame_min']:.3f}, read-back included; GPU time alone {s.get('gpu_ms_median', 0):.3f} ms: "
      f"visibility {s.get('gpu_visibility_ms_median', 0):.3f}, resolve {s.get('gpu_resolve_ms_median', 0):.3f}, "
      f"shading {s.get('gpu_shading_ms_median', 0):.3f} ms; visibility pass alone {s['primary_ms_median']:.3f} ms; "
      f"{100 * s.get('gpu_bvh_ray_share_median', 0):.1f} % of the camera rays cast through the BVH), "
      f"{s['frames']} frames, GPU memory {s['gpu_bytes'] / 2**20:.1f} MiB, on {s['device']}")
PY
}
cameras() { "$BIN" info "$1" --json | python3 -c "import json,sys; print(' '.join(json.load(sys.stdin)['scene']['cameras']))"; }

measure cornell "$D/cornell.plf" default "$WIDTH" "$HEIGHT"
measure cornell-640x480 "$D/cornell.plf" default 640 480
for camera in $(cameras "$SPONZA_PLF"); do
  measure "sponza-$camera" "$SPONZA_PLF" "$camera" "$WIDTH" "$HEIGHT"
done
# The GPU renderer's picture against the CPU fast renderer's (bench/gpu_vs_cpu.sh).
for plf in "$D/cornell.plf" "$SPONZA_PLF"; do
  PLENOPTIC=$BIN "$ROOT/bench/gpu_vs_cpu.sh" "$plf" "$COMPARE_WIDTH" "$COMPARE_HEIGHT" 3 | tee -a "$SUMMARY"
done
# The same frames with every camera ray cast through the BVH and no rasterised ids
# (PLENOPTIC_GPU_VISIBILITY=rays): whether the rasteriser or the ray casting is the cheaper
# visibility on this card (on NVIDIA's Hopper, a compute GPU, few units rasterise).
# (These come last, each allowed to fail: the figures above are in the summary first.)
PLENOPTIC_GPU_VISIBILITY=rays measure cornell-rays "$D/cornell.plf" default "$WIDTH" "$HEIGHT" ||
  say "cornell-rays: failed"
for camera in $(cameras "$SPONZA_PLF"); do
  PLENOPTIC_GPU_VISIBILITY=rays measure "sponza-$camera-rays" "$SPONZA_PLF" "$camera" "$WIDTH" "$HEIGHT" ||
    say "sponza-$camera-rays: failed"
done
# The viewer's frames with the GPU renderer, on SDL's dummy video driver (no window): the box
# flown along a path, so that every frame is drawn — the render, the display pass (tone mapping
# on the GPU) and the read-back of its 8-bit pixels, the HUD and SDL's blit; then Sponza.
python3 - "$D/box-walk.json" "$FRAMES" <<'PY'
import json, sys
frames = int(sys.argv[2])
json.dump({"fps": 30, "keyframes": [
    {"time": 0, "eye": [278, 273, -800], "target": [278, 273, 0]},
    {"time": frames / 30, "eye": [200, 300, -500], "target": [300, 250, 300]}]}, open(sys.argv[1], "w"))
PY
# Sponza's `main` flown the same way: from its camera a tenth of the way towards its target
# (the scene's JSON gives them; skipped when Sponza came as a .plf).
case "$SPONZA" in
  *.json) python3 - "$SPONZA" "$D/sponza-walk.json" "$FRAMES" <<'PY' ;;
import json, sys
cameras = {c["name"]: c for c in json.load(open(sys.argv[1])).get("cameras", [])}
frames = int(sys.argv[3])
if "main" in cameras:
    c = cameras["main"]
    eye, target = c["eye"], c["target"]
    ahead = [e + 0.1 * (t - e) for e, t in zip(eye, target)]
    json.dump({"fps": 30, "keyframes": [
        {"time": 0, "eye": eye, "target": target, "fov": c.get("fov", 60)},
        {"time": frames / 30, "eye": ahead, "target": target}]}, open(sys.argv[2], "w"))
PY
esac
# One viewer measurement: `view --renderer gpu` along a path, headless; prints its frame rate.
view_measure() {  # name plf path
  SDL_VIDEODRIVER=dummy "$BIN" view "$2" --renderer gpu --width "$WIDTH" --height "$HEIGHT" \
    --path "$3" --stats "$D/view-$1.json" --quiet >/dev/null 2>&1 || true
  python3 - "$1" "$D/view-$1.json" <<'PY' | tee -a "$SUMMARY" || say "view $1: failed"
import json, sys
s = json.load(open(sys.argv[2]))
print(f"view {sys.argv[1]} {s['width']}x{s['height']} (GPU renderer, display pass on the GPU, shown by "
      f"{s.get('presentation', 'sdl')}): {s['fps']:.1f} fps "
      f"({s['ms_per_frame_median']:.3f} ms/frame median, render and read-back {s['render_ms_median']:.3f} ms, "
      f"GPU time alone {s.get('gpu_ms_median', 0):.3f} ms), "
      f"{s['frames']} frames, on {s.get('device', s['renderer'])}")
PY
}
view_measure cornell "$D/cornell.plf" "$D/box-walk.json"
[ -f "$D/sponza-walk.json" ] && view_measure sponza-main "$SPONZA_PLF" "$D/sponza-walk.json"
# The display pass alone per tone curve (bench/gpu_display_bench), where it is built beside.
DISPLAY_BENCH=${GPU_DISPLAY_BENCH:-$(dirname "$BIN")/bench/gpu_display_bench}
if [ -x "$DISPLAY_BENCH" ]; then
  "$DISPLAY_BENCH" --benchmark_min_time=1 --benchmark_format=json --benchmark_out="$D/gpu_display_bench.json" \
    >/dev/null 2>&1 || say "gpu_display_bench: failed"
  python3 - "$D/gpu_display_bench.json" <<'PY' | tee -a "$SUMMARY" || true
import json, sys
for b in json.load(open(sys.argv[1]))["benchmarks"]:
    extra = (f", statistics {b['statistics_ms_median']:.3f} ms (CPU {b['statistics_cpu_ms_median']:.3f} ms)"
             if "statistics_ms_median" in b else "")
    print(f"{b['name']}: {b['ms_median']:.3f} ms median, calling thread's CPU {b['cpu_ms_median']:.3f} ms{extra}")
PY
fi
echo "summary: $SUMMARY"
