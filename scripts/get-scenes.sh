#!/usr/bin/env bash
# Fetches the scenes the documentation uses from their public sources, checks their SHA-256
# digests, and lays them out ready to render (docs/scenes.md, "Scenes from their sources"):
#
#   cornell  Morgan McGuire's Cornell box variants (Computer Graphics Archive, CornellBox.zip)
#            → DEST/cornell-mcguire/CornellBox-{Original,Glossy,Mirror,Sphere,Water}.{obj,mtl}
#   sponza   Crytek Sponza, McGuire's OBJ/MTL (Computer Graphics Archive, sponza.zip)
#            → DEST/sponza/ (sponza.obj, sponza.mtl, textures) and DEST/sponza/sponza.json, the
#            docs' scene (sun through the roof, the sky below, cameras main and gallery)
#   sky      Poly Haven's "Pedestrian Overpass" HDRI, 1k → DEST/envmaps/pedestrian_overpass_1k.hdr
#            (sponza needs it and fetches it too)
#
# Digests: the lock file (default scripts/scenes.sha256, sha256sum format, paths relative to
# DEST) holds what is known. Every file it lists is verified; a download it does not list yet
# is accepted and its digest recorded in it ("trust on first use": commit the lock file, and
# later fetches, yours and others', must give the same bytes). A mismatch stops the script
# with status 1 before anything is put in place: downloads go to a temporary name and
# archives are unpacked into a temporary folder, moved into DEST only once verified.
#
# Usage: scripts/get-scenes.sh [options] [cornell] [sponza] [sky]     (default: all)
#   --dest DIR      where the scenes go (default: scenes/ in the repository, git-ignored)
#   --source BASE   fetch every file from BASE/<file name> instead of its public address:
#                   a directory, or a file://, http:// or https:// URL (a mirror; the tests)
#   --lock FILE     the digest lock file (default: scripts/scenes.sha256)
#   --dry-run       print what would be fetched and checked; fetch and write nothing
#   -h, --help      this text
# Needs curl or wget (for URLs), sha256sum, and unzip or python3 (to unpack the archives).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
dest="$repo/scenes"
lock="$here/scenes.sha256"
source_base=""
dry_run=0
scenes=()

usage() { sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; }
die() { echo "get-scenes: $*" >&2; exit 1; }
usage_error() { echo "get-scenes: $*" >&2; echo "get-scenes: see --help" >&2; exit 2; }
say() { echo "get-scenes: $*"; }

while [ $# -gt 0 ]; do
  case "$1" in
    --dest) [ $# -ge 2 ] || usage_error "--dest needs a directory"; dest=$2; shift 2 ;;
    --source) [ $# -ge 2 ] || usage_error "--source needs a directory or URL"; source_base=${2%/}; shift 2 ;;
    --lock) [ $# -ge 2 ] || usage_error "--lock needs a file"; lock=$2; shift 2 ;;
    --dry-run) dry_run=1; shift ;;
    -h|--help) usage; exit 0 ;;
    cornell|sponza|sky) scenes+=("$1"); shift ;;
    -*) usage_error "unknown option '$1'" ;;
    *) usage_error "unknown scene '$1' (expected cornell, sponza or sky)" ;;
  esac
done
[ ${#scenes[@]} -gt 0 ] || scenes=(cornell sponza sky)
# sponza's JSON scene uses the sky.
case " ${scenes[*]} " in *" sponza "*) case " ${scenes[*]} " in *" sky "*) ;; *) scenes+=(sky) ;; esac ;; esac
[ -f "$lock" ] || [ $dry_run -eq 1 ] || die "$lock: no such lock file (give one with --lock, or create an empty file)"

# The public addresses. The digest of the sky as the documentation's figures were made with it,
# for information only (the file Poly Haven serves may have been re-exported since).
cornell_url=https://casual-effects.com/g3d/data10/common/model/CornellBox/CornellBox.zip
sponza_url=https://casual-effects.com/g3d/data10/common/model/crytek_sponza/sponza.zip
sky_url=https://dl.polyhaven.org/file/ph-assets/HDRIs/hdr/1k/pedestrian_overpass_1k.hdr
sky_docs_sha256=f092df4f1110e9df719ade928861a1ade22d3b8507f3303e55d35da4c0d8dc5d
cornell_files=(CornellBox-Original CornellBox-Glossy CornellBox-Mirror CornellBox-Sphere CornellBox-Water)

url_for() {  # url_for PUBLIC_URL → where to fetch it from
  if [ -n "$source_base" ]; then echo "$source_base/$(basename "$1")"; else echo "$1"; fi
}

# The digest the lock file gives for PATH (relative to DEST), or nothing.
locked_digest() { [ -f "$lock" ] && awk -v p="$1" '!/^#/ && NF >= 2 && $2 == p { print $1; exit }' "$lock" || true; }

# check FILE NAME: verifies FILE against the lock file's entry NAME, or records its digest there.
check() {
  local file=$1 name=$2 expected actual
  actual=$(sha256sum "$file" | cut -d' ' -f1)
  expected=$(locked_digest "$name")
  if [ -z "$expected" ]; then
    printf '%s  %s\n' "$actual" "$name" >>"$lock"
    say "$name: no digest in $lock yet: recorded $actual (commit the lock file to pin it)"
  elif [ "$expected" != "$actual" ]; then
    die "$name: SHA-256 mismatch: $actual, but $lock says $expected (a changed or corrupted file: nothing new was put in place; remove a stale download from $dest/downloads to fetch it again)"
  else
    say "$name: SHA-256 verified"
  fi
}

# fetch PUBLIC_URL: DEST/downloads/NAME, verified (or recorded). A file already there is checked again, not fetched.
fetch() {
  local from name target partial
  from=$(url_for "$1")
  name=$(basename "$1")
  target="$dest/downloads/$name"
  mkdir -p "$dest/downloads"
  if [ ! -f "$target" ]; then
    partial="$dest/downloads/.$name.part"
    rm -f "$partial"
    say "fetching $from"
    case "$from" in
      http://*|https://*|file://*)
        if command -v curl >/dev/null; then
          curl -fL --retry 3 --silent --show-error -o "$partial" "$from" || { rm -f "$partial"; die "$from: download failed"; }
        elif command -v wget >/dev/null && [ "${from#file://}" = "$from" ]; then
          wget -q -O "$partial" "$from" || { rm -f "$partial"; die "$from: download failed"; }
        else
          die "$from: needs curl (or wget for http/https): apt-get install curl"
        fi ;;
      *) [ -f "$from" ] || die "$from: no such file"; cp "$from" "$partial" ;;
    esac
    ( check "$partial" "downloads/$name" ) || { rm -f "$partial"; exit 1; }
    mv "$partial" "$target"
  else
    check "$target" "downloads/$name"
  fi
}

# unpack ARCHIVE DIR: extracts a zip into DIR.
unpack() {
  if command -v unzip >/dev/null; then
    unzip -q -o "$1" -d "$2" || die "$1: cannot unpack"
  else
    python3 -m zipfile -e "$1" "$2" || die "$1: cannot unpack (install unzip or python3)"
  fi
}

# A scratch folder inside DEST (same file system, so the final moves are renames), removed on exit.
scratch=""
cleanup() { [ -z "$scratch" ] || rm -rf "$scratch"; }
trap cleanup EXIT
new_scratch() { cleanup; scratch=$(mktemp -d "$dest/.get-scenes.XXXXXX"); }

# install_dir FROM NAME: replaces DEST/NAME by the verified folder FROM.
install_dir() {
  rm -rf "$dest/$2.old"
  [ ! -e "$dest/$2" ] || mv "$dest/$2" "$dest/$2.old"
  mv "$1" "$dest/$2"
  rm -rf "$dest/$2.old"
}

get_cornell() {
  fetch "$cornell_url"
  new_scratch
  unpack "$dest/downloads/CornellBox.zip" "$scratch/unpacked"
  mkdir "$scratch/cornell-mcguire"
  local base file found
  for base in "${cornell_files[@]}"; do
    for file in "$base.obj" "$base.mtl"; do
      found=$(find "$scratch/unpacked" -type f -name "$file" | head -n 1)
      [ -n "$found" ] || die "CornellBox.zip holds no $file"
      cp "$found" "$scratch/cornell-mcguire/$file"
      check "$scratch/cornell-mcguire/$file" "cornell-mcguire/$file"
    done
  done
  install_dir "$scratch/cornell-mcguire" cornell-mcguire
  say "McGuire's Cornell boxes: $dest/cornell-mcguire/ (e.g. plenoptic bake $dest/cornell-mcguire/CornellBox-Original.obj)"
}

get_sky() {
  fetch "$sky_url"
  local digest
  digest=$(sha256sum "$dest/downloads/pedestrian_overpass_1k.hdr" | cut -d' ' -f1)
  [ "$digest" != "$sky_docs_sha256" ] || say "pedestrian_overpass_1k.hdr: the same bytes as the documentation's copy"
  mkdir -p "$dest/envmaps"
  cp "$dest/downloads/pedestrian_overpass_1k.hdr" "$dest/envmaps/.pedestrian_overpass_1k.hdr.part"
  mv "$dest/envmaps/.pedestrian_overpass_1k.hdr.part" "$dest/envmaps/pedestrian_overpass_1k.hdr"
  say "the sky: $dest/envmaps/pedestrian_overpass_1k.hdr"
}

# The documentation's Sponza (docs/scenes.md) is a conversion of Away3D's copy whose z axis
# points the other way from Crytek's OBJ as McGuire distributes it. Its bounding box is
# x -1920.95..1799.91, z -1105.43..1182.81; Crytek's OBJ, mirrored, has z -1182.81..1105.43.
# The cameras and the sun of sponza.json are given for the former; for the latter their z is
# negated. Prints "same", "mirrored" or "unknown" for the OBJ file $1.
sponza_frame() {
  awk '$1 == "v" { if (n++ == 0) { x0 = x1 = $2; z0 = z1 = $4 }
                   if ($2 < x0) x0 = $2; if ($2 > x1) x1 = $2; if ($4 < z0) z0 = $4; if ($4 > z1) z1 = $4 }
       function near(a, b) { return a - b < 1 && b - a < 1 }
       END { if (!(near(x0, -1920.95) && near(x1, 1799.91))) print "unknown"
             else if (near(z0, -1105.43) && near(z1, 1182.81)) print "same"
             else if (near(z0, -1182.81) && near(z1, 1105.43)) print "mirrored"
             else print "unknown" }' "$1"
}

# The docs' sponza.json, for the files as fetched; $1 = 1 or -1, the sign of every z.
write_sponza_json() {
  local s=$1
  cat >"$2" <<EOF
{
  "meshes": [ {"file": "sponza.obj"} ],
  "lights": [ {"type": "directional", "direction": [0.25, -1.0, $(awk "BEGIN{print $s * 0.3}")], "irradiance": [9.0, 8.5, 7.5]} ],
  "environment": {"file": "../envmaps/pedestrian_overpass_1k.hdr", "scale": 1.0},
  "cameras": [ {"name": "main", "eye": [-1200, 220, $((s * 40))], "target": [600, 480, $((s * 40))], "up": [0,1,0], "fov": 60},
               {"name": "gallery", "eye": [900, 650, $((s * -300))], "target": [-700, 520, $((s * 350))], "up": [0,1,0], "fov": 55} ],
  "settings": {"width": 640, "height": 480, "camera": "main"}
}
EOF
}

get_sponza() {
  fetch "$sponza_url"
  new_scratch
  unpack "$dest/downloads/sponza.zip" "$scratch/unpacked"
  local obj folder mtl frame sign=1 missing=0 name resolved
  obj=$(find "$scratch/unpacked" -type f -name sponza.obj | head -n 1)
  [ -n "$obj" ] || die "sponza.zip holds no sponza.obj"
  folder=$(dirname "$obj")
  mtl="$folder/sponza.mtl"
  [ -f "$mtl" ] || die "sponza.zip holds no sponza.mtl beside sponza.obj"
  # The MTL names its textures with Windows separators (textures\x.png): made portable. A name
  # whose case differs from the file's is pointed at the file.
  sed -i 's#\\#/#g' "$mtl"
  while read -r name; do
    [ -f "$folder/$name" ] && continue
    resolved=$(cd "$folder" && find "$(dirname "$name")" -maxdepth 1 -iname "$(basename "$name")" 2>/dev/null | head -n 1)
    if [ -n "$resolved" ]; then
      sed -i "s#\([[:space:]]\)$name\([[:space:]]*\)\$#\1${resolved#./}\2#" "$mtl"
    else
      echo "get-scenes: warning: sponza.mtl names $name, which the archive does not hold" >&2
      missing=$((missing + 1))
    fi
  done < <(awk '$1 ~ /^(map_|bump|norm|disp)/ { print $NF }' "$mtl" | tr -d '\r' | sort -u)
  frame=$(sponza_frame "$obj")
  case "$frame" in
    same) ;;
    mirrored) sign=-1; say "sponza.obj: Crytek's axes (z mirrored from the docs' copy): the cameras and sun follow" ;;
    *) echo "get-scenes: warning: sponza.obj's bounding box is not the one the docs' cameras were placed in; they may need moving" >&2 ;;
  esac
  write_sponza_json "$sign" "$folder/sponza.json"
  install_dir "$folder" sponza
  say "Crytek Sponza: $dest/sponza/sponza.json (e.g. plenoptic bake $dest/sponza/sponza.json --preset draft)"
  [ $missing -eq 0 ] || echo "get-scenes: warning: $missing texture(s) missing: loading sponza.json will fail until they are there" >&2
}

if [ $dry_run -eq 1 ]; then
  for scene in "${scenes[@]}"; do
    case "$scene" in
      cornell) url=$cornell_url; files=(downloads/CornellBox.zip)
               for base in "${cornell_files[@]}"; do files+=("cornell-mcguire/$base.obj" "cornell-mcguire/$base.mtl"); done ;;
      sponza) url=$sponza_url; files=(downloads/sponza.zip) ;;
      sky) url=$sky_url; files=(downloads/pedestrian_overpass_1k.hdr) ;;
    esac
    echo "$scene: would fetch $(url_for "$url") into $dest"
    for file in "${files[@]}"; do
      digest=$(locked_digest "$file")
      echo "  $file: ${digest:+verify SHA-256 $digest}${digest:-record its SHA-256 in $lock (not known yet)}"
    done
  done
  exit 0
fi

mkdir -p "$dest"
for scene in "${scenes[@]}"; do
  "get_$scene"
done
