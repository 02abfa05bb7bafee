#!/usr/bin/env bash
# What a re-bake with --reuse-visibility costs against a full bake of the built-in Cornell box
# (its JSON form, `"include_cornell": true`), user CPU and wall time, medians of REPEAT runs
# interleaved (full, then each re-bake, REPEAT times):
#   full         plenoptic bake box.json -o full.plf --fresh                (traces the field)
#   light        the area light's colour changed, warm-started from the previous box.plf
#   albedo       the red wall's albedo changed, warm-started
#   nothing      the same scene again, warm-started
#   light-cold   the light's colour changed, --no-warm-start (propagated from zero: bit-identical
#                to a full bake)
# Every re-bake starts from the same previous bake (its .plf, .plv, .plt and .pls, the first shot
# by source, copied back first).
# Prints one line per case: median user s, median wall s, and the share of the full bake's.
# Usage: bench/rebake_share.sh [PLENOPTIC] [WORKDIR]   (default build/plenoptic, out/rebake_share)
# Environment: PRESET (default "default"), REPEAT (default 3).
set -euo pipefail

plenoptic=$(realpath "${1:-build/plenoptic}")
workdir=${2:-out/rebake_share}
preset=${PRESET:-default}
repeat=${REPEAT:-3}
mkdir -p "$workdir"
cd "$workdir"

scene() {  # scene FILE LIGHT_EMISSION RED_ALBEDO
  cat >"$1" <<EOF
{"include_cornell": true,
 "materials": {"light": {"type": "lambert", "albedo": [0.885809, 0.698859, 0.666422], "emission": $2},
               "red": {"type": "lambert", "albedo": $3}}}
EOF
}
scene original.json "[18.387, 13.9873, 6.75357]" "[0.570068, 0.0430135, 0.0443706]"
scene light.json "[9.0, 14.0, 18.0]" "[0.570068, 0.0430135, 0.0443706]"
scene albedo.json "[18.387, 13.9873, 6.75357]" "[0.2, 0.5, 0.7]"
cp original.json nothing.json
cp light.json light-cold.json

"$plenoptic" --quiet bake original.json -o prev.plf --preset "$preset"
cases=(full light albedo nothing light-cold)
declare -A user wall
for ((i = 0; i < repeat; ++i)); do
  for c in "${cases[@]}"; do
    if [[ $c == full ]]; then
      args=(original.json -o full.plf --fresh)
    else
      cp prev.plf box.plf && cp prev.plv box.plv && cp prev.plt box.plt
      rm -f box.pls && if [[ -f prev.pls ]]; then cp prev.pls box.pls; fi
      args=("$c.json" -o box.plf --reuse-visibility)
      [[ $c == light-cold ]] && args+=(--no-warm-start)
    fi
    /usr/bin/time -f "%U %e" -o time.txt "$plenoptic" --quiet bake "${args[@]}" --preset "$preset" --stats "$c.json.stats"
    read -r u w <time.txt
    user[$c]+="$u "
    wall[$c]+="$w "
  done
done
median() { tr ' ' '\n' | sed '/^$/d' | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
fu=$(echo "${user[full]}" | median)
fw=$(echo "${wall[full]}" | median)
printf "%-11s %9s %9s %8s %8s %s\n" case user_s wall_s user% wall% warm_start
for c in "${cases[@]}"; do
  u=$(echo "${user[$c]}" | median)
  w=$(echo "${wall[$c]}" | median)
  warm=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get('warm_start', '-'))" "$c.json.stats")
  printf "%-11s %9s %9s %7.1f%% %7.1f%% %s\n" "$c" "$u" "$w" "$(echo "100*$u/$fu" | bc -l)" \
    "$(echo "100*$w/$fw" | bc -l)" "$warm"
done
