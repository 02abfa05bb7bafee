#!/usr/bin/env bash
# Time to equal error: plenoptic's path tracer against Blender Cycles on the same OBJ scenes
# (issue 17, item 3). Optional: needs the Debian `blender` package (3.4.1 here; `apt-get
# install -y blender`); without it the script says so and exits 0. Never part of `make test`.
#
# Scenes: McGuire's CornellBox-Original (its two "Bottom Face" quads, which repeat a side face
# of each box, removed: any face whose vertex positions repeat an earlier face is dropped)
# and CornellBox-Glossy, both from $SHARED_DIR/scenes/cornell-mcguire. Camera eye 0,1,3.5,
# target 0,1,0, vertical fov 40°, SIZE² pixels (default 256).
#
# Cycles settings (bench/vs_cycles_blender.py): CPU, THREADS threads (default 2), box pixel
# filter 1 px wide, no denoising, no adaptive sampling, no clamping, its default sampling
# pattern (3.4: progressive multi-jitter), every bounce limit 1024 (the most Cycles accepts:
# effectively unbounded, Russian roulette ends the paths as in plenoptic), black world, linear
# 32-bit EXR (no view transform: 'Standard', look None, exposure 0, gamma 1). Materials are
# rebuilt from the .mtl as plenoptic reads it: Kd → Lambertian Diffuse BSDF; Ks, Ns → plus a
# GGX Glossy BSDF of colour Ks and roughness (2/(Ns+2))^¼ (Cycles' roughness r has α = r²;
# α² = 2/(Ns+2) matches the Blinn-Phong lobe's width, not its exact shape: CornellBox-Glossy's
# glossy surfaces are an approximation, so its means differ a little); Kd + Ks scaled to ≤ 1
# per channel as plenoptic does; Ke → an Emission shader of colour Ke and strength 1 (radiance
# Ke: checked below on the light's pixels), black on the back face (Geometry.Backfacing), i.e.
# one-sided emission as plenoptic's.
#
# plenoptic: `trace` with the default sampler (sobol) and, for comparison, `--sampler
# independent`, the same camera and size, default settings otherwise.
#
# Error: for each renderer and spp, two renders with different seeds a and b; relMSE is
# compare.h's, mean over pixels and channels of (x − y)²/(ref² + 0.01), always with the
# reference's value in the denominator (a noisy denominator would bias it at low spp):
#   * relMSE against the reference (plenoptic trace --sampler independent at REF_SPP spp,
#     seed 1), minus the reference's own noise (its mean variance/(ref² + 0.01), exact for
#     independent samples); for CornellBox-Original this also checks Cycles' mean against ours
#     (as does the radiance ratio on the light's pixels printed at the end);
#   * noise = relMSE(a, b)/2: the error of one render without any reference (the two renders
#     are independent, so E|a − b|² = 2·variance), which is what the equal-error comparison
#     uses — it is fair to both renderers even where their materials differ a little.
# time = render seconds (plenoptic: trace --stats "seconds", without loading and BVH build;
# Cycles: its status log's time from "Sample 0/N" to "Finished", without start-up, scene
# sync and kernel set-up, ≈ 0.6 s here). time × noise is constant
# for a Monte Carlo renderer whose error falls as 1/spp; the equal-error speed ratio is Cycles'
# time × noise over plenoptic's (> 1: plenoptic is faster at equal error).
#
# Usage: bench/vs_cycles.sh [PLENOPTIC] [WORKDIR]
#   PLENOPTIC  default build/plenoptic; WORKDIR default out/vs_cycles
# Environment: SPP (default "16 64 256"), REF_SPP (default 4096), SIZE (256), THREADS (2),
# SHARED_DIR (default /work/shared), BLENDER (default blender).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
plenoptic=${1:-build/plenoptic}
work=${2:-out/vs_cycles}
spps=${SPP:-16 64 256}
ref_spp=${REF_SPP:-4096}
size=${SIZE:-256}
threads=${THREADS:-2}
shared=${SHARED_DIR:-/work/shared}
blender=${BLENDER:-blender}

source "$here/blender_common.sh"
require_blender_and_plenoptic "$blender" "$plenoptic"
mkdir -p "$work"
camera=(--eye 0,1,3.5 --target 0,1,0 --fov 40 --width "$size" --height "$size")
echo "Blender: $("$blender" --version 2> /dev/null | head -1); $threads threads; ${size}x${size}"

for name in CornellBox-Original CornellBox-Glossy; do
  dir="$work/$name"
  mkdir -p "$dir"
  # The scene without repeated faces, and its materials.
  python3 - "$shared/scenes/cornell-mcguire/$name.obj" "$dir/scene.obj" <<'PY'
import sys
src, dst = sys.argv[1], sys.argv[2]
positions, seen, out, dropped = [], set(), [], 0
for line in open(src):
    parts = line.split()
    if parts and parts[0] == "v":
        positions.append(tuple(float(x) for x in parts[1:4]))
    if parts and parts[0] == "f":
        ids = [int(p.split("/")[0]) for p in parts[1:]]
        key = frozenset(positions[i - 1] if i > 0 else positions[len(positions) + i] for i in ids)
        if key in seen:
            dropped += 1
            continue
        seen.add(key)
    out.append(line)
open(dst, "w").writelines(out)
print(f"{src}: {dropped} repeated face(s) dropped", file=sys.stderr)
PY
  cp "$shared/scenes/cornell-mcguire/$name.mtl" "$dir/"

  echo "== $name: reference, plenoptic --sampler independent, $ref_spp spp" >&2
  if [[ ! -f "$dir/ref.json" ]] || ! grep -q "\"spp\": $ref_spp," "$dir/ref.json"; then
    nice -n 10 "$plenoptic" --quiet --seed 1 trace "$dir/scene.obj" -o "$dir/ref.pfm" --variance "$dir/refvar.pfm" \
      --sampler independent --spp "$ref_spp" "${camera[@]}" --stats "$dir/ref.json" >&2
  fi
  for spp in $spps; do
    for seed in 2 3; do
      for sampler in sobol independent; do
        "$plenoptic" --quiet --threads "$threads" --seed "$seed" trace "$dir/scene.obj" -o "$dir/pl_${sampler}_${spp}_$seed.pfm" \
          --sampler "$sampler" --spp "$spp" "${camera[@]}" --stats "$dir/pl_${sampler}_${spp}_$seed.json" > /dev/null
      done
      echo "== $name: Cycles $spp spp, seed $seed" >&2
      "$blender" --background --factory-startup --python "$here/vs_cycles_blender.py" -- "$dir/scene.obj" \
        "$dir/cy_${spp}_$seed.exr" "$spp" "$seed" "$size" "$threads" > "$dir/cy_${spp}_$seed.log" 2>&1 ||
        { cat "$dir/cy_${spp}_$seed.log" >&2; exit 1; }
      # Sampling time: from Cycles' "Sample 0/N" status line to its "Finished" line (its
      # own clock; excludes Blender's start-up, the scene sync and kernel set-up, as
      # plenoptic's "seconds" excludes loading and the BVH build).
      python3 - "$dir/cy_${spp}_$seed.log" > "$dir/cy_${spp}_$seed.seconds" <<'PY'
import re, sys
def seconds(line):
    m = re.search(r"\| Time:(\d+):(\d+\.\d+) \|", line)
    return 60 * int(m.group(1)) + float(m.group(2))
lines = open(sys.argv[1]).read().splitlines()
start = next(seconds(l) for l in lines if re.search(r"\| Sample 0/\d+$", l))
end = next(seconds(l) for l in lines if l.endswith("| Finished"))
print(end - start)
PY
    done
  done
done

BENCH_DIR="$here" python3 - "$work" "$ref_spp" "$spps" <<'PY'
import json, os, sys

sys.path.insert(0, os.environ["BENCH_DIR"])
from pfm import read_pfm

work, ref_spp, spps = sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3].split()]

def relmse(a, b, ref):
    """compare.h's relMSE of a against b, with the reference's (b²+0.01) in the denominator."""
    return sum((x - y) ** 2 / (r * r + 0.01) for x, y, r in zip(a, b, ref)) / len(ref)

names = {"pl_sobol": "plenoptic (sobol)", "pl_independent": "plenoptic (independent)", "cy": "Cycles 3.4"}
print()
print("| scene | renderer | spp | time s | relMSE vs ref | noise (relMSE a,b / 2) | time × noise | equal-error speed vs Cycles |")
print("|---|---|---:|---:|---:|---:|---:|---:|")
notes = []
for name in ["CornellBox-Original", "CornellBox-Glossy"]:
    d = os.path.join(work, name)
    ref, var = read_pfm(os.path.join(d, "ref.pfm")), read_pfm(os.path.join(d, "refvar.pfm"))
    ref_noise = sum(v / (r * r + 0.01) for r, v in zip(ref, var)) / len(ref)
    for spp in spps:
        rows = {}
        for r in names:
            if r == "cy":
                t = [float(open(os.path.join(d, f"cy_{spp}_{s}.seconds")).read()) for s in (2, 3)]
            else:
                t = [json.load(open(os.path.join(d, f"{r}_{spp}_{s}.json")))["seconds"] for s in (2, 3)]
            a, b = (read_pfm(os.path.join(d, f"{r}_{spp}_{s}.pfm")) for s in (2, 3))
            seconds = sum(t) / 2
            vs_ref = (relmse(a, ref, ref) + relmse(b, ref, ref)) / 2 - ref_noise
            noise = relmse(a, b, ref) / 2
            rows[r] = (seconds, vs_ref, noise, seconds * noise)
            if r == "cy" and spp == spps[-1]:
                # Cycles' emission against ours: the light seen directly (pixels brighter than
                # half the brightest reference pixel) must have the same radiance.
                peak = max(ref)
                lit = [i for i, v in enumerate(ref) if v > 0.5 * peak]
                ratio = sum(a[i] + b[i] for i in lit) / (2 * sum(ref[i] for i in lit))
                notes.append(f"{name}: reference {ref_spp} spp (its own noise {ref_noise:.1e}, subtracted from relMSE "
                             f"vs ref); Cycles / plenoptic radiance on the light's {len(lit) // 3} pixels: {ratio:.4f}")
        for r, (seconds, vs_ref, noise, product) in rows.items():
            ratio = rows["cy"][3] / product
            print(f"| {name} | {names[r]} | {spp} | {seconds:.2f} | {vs_ref:.2e} | {noise:.2e} | {product:.2e} | {ratio:.2f}× |")
print()
for note in notes:
    print(note)
print("equal-error speed = (Cycles time × noise) / (this renderer's time × noise); relMSE = mean over pixels and "
      "channels of (a − b)²/(ref² + 0.01), as `plenoptic compare` with the reference's denominator")
PY
