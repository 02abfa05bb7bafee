#!/usr/bin/env bash
# A bake of a scene of a few million triangles on one machine: COPIES copies of Crytek Sponza
# (262 k triangles each; 8 copies: 2.10 M) placed side by side in one JSON scene, with
# Sponza's sun and sky, baked at a preset (default: default). The memory guard chooses whether
# the visibility field is held or streamed from the .plv; the script prints the bake's own
# log lines that say so, then wall time, user CPU, peak RSS (`/usr/bin/time -v`), the tixel,
# entry and triangle counts and the file sizes.
#
# Usage: bench/large_scene.sh [PLENOPTIC] [WORKDIR] [COPIES] [PRESET] [THREADS]
#   PLENOPTIC  the executable (default: build/plenoptic; copy it first if you keep building)
#   WORKDIR    where the scene and the files go (default: out/large-scene; the .plv of 8
#              copies at default takes about 17 GB)
#   COPIES     Sponzas placed in rows of four, 4 000 units apart in x and 2 600 in z (default 8)
#   PRESET     draft, default or high (default: default)
#   THREADS    --threads (default: all cores)
# Needs ../shared/scenes/sponza (the Crytek Sponza of the project's scene collection) beside
# the repository, or SPONZA=/path/to/sponza.obj.
set -euo pipefail

plenoptic=${1:-build/plenoptic}
workdir=${2:-out/large-scene}
copies=${3:-8}
preset=${4:-default}
threads=${5:-$(nproc)}
here=$(cd "$(dirname "$0")/.." && pwd)
sponza=${SPONZA:-$here/../shared/scenes/sponza/sponza.obj}
envmap=$(dirname "$sponza")/../../envmaps/pedestrian_overpass_1k.hdr

if [[ ! -x "$plenoptic" ]]; then
  echo "$0: $plenoptic is not an executable (build it first: make build)" >&2
  exit 1
fi
if [[ ! -f "$sponza" ]]; then
  echo "$0: $sponza: no such file (set SPONZA=/path/to/sponza.obj)" >&2
  exit 1
fi
mkdir -p "$workdir"
sponza=$(realpath "$sponza")
scene="$workdir/sponza-x$copies.json"
/usr/bin/python3 - "$sponza" "$(realpath -m "$envmap")" "$copies" >"$scene" <<'PY'
import json, os, sys
sponza, envmap, copies = sys.argv[1], sys.argv[2], int(sys.argv[3])
meshes = [{"file": sponza, "transform": {"translate": [4000.0 * (i % 4), 0.0, 2600.0 * (i // 4)]}}
          for i in range(copies)]
scene = {
    "meshes": meshes,
    "lights": [{"type": "directional", "direction": [0.25, -1.0, 0.3], "irradiance": [9.0, 8.5, 7.5]}],
    "cameras": [{"name": "main", "eye": [-1200, 220, 40], "target": [600, 480, 40], "up": [0, 1, 0], "fov": 60}],
    "settings": {"width": 640, "height": 480, "camera": "main"},
}
if os.path.exists(envmap):
    scene["environment"] = {"file": envmap, "scale": 1.0}
json.dump(scene, sys.stdout, indent=1)
PY

out="$workdir/sponza-x$copies-$preset"
echo "== $copies Sponzas ($scene), preset $preset, $threads threads" >&2
/usr/bin/time -v -o "$out.time" "$plenoptic" --threads "$threads" bake "$scene" -o "$out.plf" --preset "$preset" \
  --stats "$out.json" 2>&1 | tee "$out.log" | grep -E "visibility|memory|estimate|streamed|iteration" || true
"$plenoptic" info --json --no-verify "$out.plf" >"$out.info.json"
/usr/bin/python3 - "$out" <<'PY'
import json, os, re, sys
out = sys.argv[1]
stats = json.load(open(out + ".json"))
info = json.load(open(out + ".info.json"))
timing = open(out + ".time").read()
field = lambda name: re.search(re.escape(name) + r": (.*)", timing).group(1).strip()
rss = int(field("Maximum resident set size (kbytes)")) * 1024
print(f"triangles {info['scene']['triangles']}, tixels {stats['tixels']}, "
      f"visibility entries {stats['visibility_rays'] / 1e9:.2f} G ({info['settings']['gather_directions']} per tixel), "
      f"visibility field {stats['visibility_memory']}")
print(f"wall {field('Elapsed (wall clock) time (h:mm:ss or m:ss)')}, user {float(field('User time (seconds)')):.0f} s, "
      f"peak RSS {rss / 2**30:.2f} GiB")
print(f"visibility {stats['visibility_seconds']:.0f} s, propagation {stats['propagation_seconds']:.0f} s, "
      f"{stats['iterations']} iterations, residual {stats['residual']:.1e}")
print(f".plf {os.path.getsize(out + '.plf') / 1e6:.1f} MB, .plv {os.path.getsize(out + '.plv') / 1e9:.2f} GB")
PY
