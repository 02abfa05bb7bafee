#!/usr/bin/env bash
# Before/after check of a change that must not change bake results: bakes SCENE with two
# builds of plenoptic (same preset, seed 5) and compares the .plf sections but META (which
# holds timings) by their XXH64 checksums, and the .plv byte for byte when both builds write the
# same .plv format version (else the .plf sections only: the light field is what must not change).
# Both bake with `--compress none`: float32 values and raw sections, compared bit for bit (the
# default, lossy hdr codes, could hide a change smaller than a code step).
#   bench/compare_bakes.sh NEW_PLENOPTIC OLD_PLENOPTIC SCENE [PRESET]
# NEW_FLAGS: extra bake flags for the new build only, e.g. NEW_FLAGS="--visibility-precision
# exact" against a build from before the compact fractions (whose fields were all exact).
set -euo pipefail
NEW=$1; OLD=$2; SCENE=$3; PRESET=${4:-draft}
D=$(mktemp -d)
trap 'rm -rf "$D"' EXIT
# shellcheck disable=SC2086  # NEW_FLAGS is split into flags on purpose
"$NEW" bake "$SCENE" -o "$D/new.plf" --preset "$PRESET" --seed 5 --compress none --quiet ${NEW_FLAGS:-} >/dev/null
"$OLD" bake "$SCENE" -o "$D/old.plf" --preset "$PRESET" --seed 5 --compress none --quiet >/dev/null
sums() {
  # The new build reads both files (it also reads the older build's format version).
  "$NEW" info "$1" --json | python3 -c \
    "import json,sys; print([(s['id'], s['checksum_xxh64']) for s in json.load(sys.stdin)['sections'] if s['id'] != 'META'])"
}
a=$(sums "$D/new.plf"); b=$(sums "$D/old.plf")
plvVersion() { od -An -tu4 -j8 -N4 "$1" | tr -d ' '; }
vNew=$(plvVersion "$D/new.plv"); vOld=$(plvVersion "$D/old.plv")
if [ "$vNew" = "$vOld" ]; then plvSame() { cmp -s "$D/new.plv" "$D/old.plv"; }; else plvSame() { true; }; fi
if [ "$a" = "$b" ] && plvSame; then
  if [ "$vNew" = "$vOld" ]; then echo "identical: $SCENE ($PRESET)"
  else echo "identical: $SCENE ($PRESET) (.plf sections; .plv format $vNew vs $vOld not compared)"; fi
else
  echo "DIFFERENT: $SCENE ($PRESET)"; echo "  new $a"; echo "  old $b"; exit 1
fi
