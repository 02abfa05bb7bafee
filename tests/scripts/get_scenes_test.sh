#!/usr/bin/env bash
# ctest get_scenes_test: the offline parts of scripts/get-scenes.sh, with no network. Mirrors
# made here stand in for the public sources (--source, a directory or a file:// URL): the
# Cornell boxes from tests/data (the unchanged originals, so the lock file's known digests must
# pass), a stand-in Sponza archive and sky. Checks argument handling, --dry-run, verification
# against known digests, digests recorded on first use and verified after, refusal of changed
# files with nothing put in place, and the Sponza adaptation (Windows texture paths, the
# cameras for either orientation of the model).
#   get_scenes_test.sh REPO
set -uo pipefail
repo=$(cd "${1:?usage: get_scenes_test.sh REPO}" && pwd)
script="$repo/scripts/get-scenes.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
# expect STATUS PATTERN COMMAND...: runs COMMAND, checks its exit status and that its output
# (stdout and stderr) matches the extended regular expression PATTERN.
expect() {
  local status=$1 pattern=$2 output code
  shift 2
  output=$("$@" 2>&1); code=$?
  [ "$code" -eq "$status" ] || fail "'$*' exited $code, expected $status: $output"
  echo "$output" | grep -Eq -- "$pattern" || fail "'$*' printed no /$pattern/: $output"
}
zip_dir() {  # zip_dir ARCHIVE DIR: a zip of DIR's files under DIR's own name
  (cd "$(dirname "$2")" && python3 -m zipfile -c "$1" "$(basename "$2")") || fail "cannot make $1"
}

# Arguments.
expect 0 "Usage: scripts/get-scenes.sh" "$script" --help
expect 2 "unknown option '--bogus'" "$script" --bogus
expect 2 "unknown scene 'moon'" "$script" moon
expect 2 "--dest needs a directory" "$script" --dest
expect 1 "no such lock file" "$script" --lock "$work/none.sha256" --dest "$work/x" cornell

# --dry-run: says what and where, writes nothing; sponza brings the sky along.
expect 0 "sponza: would fetch https://casual-effects.com/.*/sponza.zip" "$script" --dry-run --dest "$work/dry" sponza
expect 0 "sky: would fetch https://dl.polyhaven.org/.*pedestrian_overpass_1k.hdr" "$script" --dry-run --dest "$work/dry" sponza
expect 0 "CornellBox-Original.obj: verify SHA-256 6e2b8b91" "$script" --dry-run --dest "$work/dry" cornell
expect 0 "would fetch $work/mirror/CornellBox.zip" "$script" --dry-run --source "$work/mirror/" --dest "$work/dry" cornell
[ ! -e "$work/dry" ] || fail "--dry-run created $work/dry"

# The Cornell boxes from a mirror directory: the known digests pass, the archive's is recorded.
mkdir -p "$work/mirror" "$work/src/CornellBox"
cp "$repo"/tests/data/cornell-mcguire/CornellBox-* "$work/src/CornellBox/"
zip_dir "$work/mirror/CornellBox.zip" "$work/src/CornellBox"
cp "$repo/scripts/scenes.sha256" "$work/lock"
expect 0 "cornell-mcguire/CornellBox-Water.mtl: SHA-256 verified" \
  "$script" --source "$work/mirror" --dest "$work/scenes" --lock "$work/lock" cornell
cmp -s "$work/scenes/cornell-mcguire/CornellBox-Original.obj" "$repo/tests/data/cornell-mcguire/CornellBox-Original.obj" \
  || fail "CornellBox-Original.obj is not the original"
grep -q "  downloads/CornellBox.zip$" "$work/lock" || fail "the archive's digest was not recorded"
[ -z "$(find "$work/scenes" -name '.get-scenes.*' -o -name '*.part')" ] || fail "temporary files left behind"
# Again, now through a file:// URL: the kept download is verified against the recorded digest.
rm "$work/scenes/downloads/CornellBox.zip"
expect 0 "downloads/CornellBox.zip: SHA-256 verified" \
  "$script" --source "file://$work/mirror" --dest "$work/scenes" --lock "$work/lock" cornell

# A changed archive against its recorded digest: refused, and the download is not kept.
echo "# changed" >>"$work/src/CornellBox/CornellBox-Original.obj"
zip_dir "$work/mirror2.zip" "$work/src/CornellBox"
mkdir -p "$work/mirror2" && mv "$work/mirror2.zip" "$work/mirror2/CornellBox.zip"
rm "$work/scenes/downloads/CornellBox.zip"
expect 1 "downloads/CornellBox.zip: SHA-256 mismatch" \
  "$script" --source "$work/mirror2" --dest "$work/scenes" --lock "$work/lock" cornell
[ ! -e "$work/scenes/downloads/CornellBox.zip" ] || fail "a refused download was kept"
# ... and with no recorded archive digest, the changed file itself is refused by its known
# digest: the boxes installed before stay as they were.
cp "$repo/scripts/scenes.sha256" "$work/lock2"
expect 1 "cornell-mcguire/CornellBox-Original.obj: SHA-256 mismatch" \
  "$script" --source "$work/mirror2" --dest "$work/scenes" --lock "$work/lock2" cornell
cmp -s "$work/scenes/cornell-mcguire/CornellBox-Original.obj" "$repo/tests/data/cornell-mcguire/CornellBox-Original.obj" \
  || fail "a refused fetch changed the installed boxes"
[ -z "$(find "$work/scenes" -name '.get-scenes.*')" ] || fail "the refused fetch left its scratch folder"

# A stand-in Sponza (a quad at the corners of Crytek's bounding box, z mirrored from the docs'
# copy, a texture named with a Windows separator and in the wrong case) and sky.
mkdir -p "$work/src/crytek/textures" "$work/mirror3"
printf 'mtllib sponza.mtl\nv -1920.95 -126.44 -1182.81\nv 1799.91 -126.44 -1182.81\nv 1799.91 1429.43 1105.43\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl floor\nf 1/1 2/2 3/3\n' \
  >"$work/src/crytek/sponza.obj"
printf 'newmtl floor\r\nKd 1 1 1\r\nmap_Kd textures\\Floor_Diff.png\r\nmap_bump textures\\floor_bump.png\r\n' \
  >"$work/src/crytek/sponza.mtl"
printf 'png' >"$work/src/crytek/textures/floor_diff.png"
zip_dir "$work/mirror3/sponza.zip" "$work/src/crytek"
printf '#?RADIANCE\n' >"$work/mirror3/pedestrian_overpass_1k.hdr"
expect 0 "sponza.obj: Crytek's axes" \
  "$script" --source "$work/mirror3" --dest "$work/scenes" --lock "$work/lock" sponza
json="$work/scenes/sponza/sponza.json"
grep -q '"eye": \[-1200, 220, -40\]' "$json" || fail "the main camera was not mirrored: $(cat "$json")"
grep -q '"direction": \[0.25, -1.0, -0.3\]' "$json" || fail "the sun was not mirrored: $(cat "$json")"
grep -q '"file": "../envmaps/pedestrian_overpass_1k.hdr"' "$json" || fail "sponza.json does not name the sky"
[ -f "$work/scenes/envmaps/pedestrian_overpass_1k.hdr" ] || fail "the sky was not fetched with sponza"
grep -q 'map_Kd textures/floor_diff.png' "$work/scenes/sponza/sponza.mtl" || fail "texture path not adapted: $(cat "$work/scenes/sponza/sponza.mtl")"
grep -q "  downloads/sponza.zip$" "$work/lock" && grep -q "  downloads/pedestrian_overpass_1k.hdr$" "$work/lock" \
  || fail "sponza.zip's and the sky's digests were not recorded"
# The missing bump texture is reported.
expect 0 "names textures/floor_bump.png, which the archive does not hold" \
  "$script" --source "$work/mirror3" --dest "$work/scenes" --lock "$work/lock" sponza
# A model in the docs' copy's axes keeps the docs' cameras as they are.
mkdir -p "$work/mirror4"
sed -i 's/-1182.81/-1105.43/; s/1105.43$/1182.81/' "$work/src/crytek/sponza.obj"
zip_dir "$work/mirror4/sponza.zip" "$work/src/crytek"
cp "$work/mirror3/pedestrian_overpass_1k.hdr" "$work/mirror4/"
: >"$work/lock4"
expect 0 "Crytek Sponza: " "$script" --source "$work/mirror4" --dest "$work/scenes4" --lock "$work/lock4" sponza
grep -q '"eye": \[-1200, 220, 40\]' "$work/scenes4/sponza/sponza.json" || fail "the docs' cameras were changed"

if [ $failures -ne 0 ]; then
  echo "get_scenes_test: $failures failure(s)" >&2
  exit 1
fi
echo "get_scenes_test: all checks passed"
