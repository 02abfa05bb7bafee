#!/usr/bin/env bash
# Packs what bench/gpu_device.sh needs on a lent machine with a graphics card that has nothing
# installed (a bare image of another distribution, no network): this build of `plenoptic` with
# every shared library it loads — the C library and its loader too, so that it runs on an older
# glibc — the Sponza scene, Debian's OpenGL dispatch libraries (glvnd: libEGL, libOpenGL, …;
# the card's driver brings the vendor's EGL), and run.sh, which unpacks them and runs the
# measurements. Everything goes into device-bundle/ (ignored by git), compressed, within the
# 64 MiB a working tree may carry there:
#   bench/device_bundle.sh                 # here, after `make build`
#   bash device-bundle/run.sh              # there, from the repository root; with OUT set
#                                          # (the device tool's folder of files to bring
#                                          # back) the summary and a tarball of the stats go there
# PLENOPTIC=build/plenoptic names the binary; SHARED=../shared the folder holding
# scenes/sponza and the envmaps/ its environment is read from.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${PLENOPTIC:-$ROOT/build/plenoptic}
SHARED=${SHARED:-$ROOT/../shared}
OUTDIR=$ROOT/device-bundle
[ -x "$BIN" ] || { echo "device_bundle: $BIN is not built (make build, or set PLENOPTIC)" >&2; exit 1; }
[ -f "$SHARED/scenes/sponza/sponza.json" ] || { echo "device_bundle: no scenes/sponza in $SHARED (set SHARED)" >&2; exit 1; }
STAGE=$(mktemp -d)
trap 'rm -rf "$STAGE"' EXIT
mkdir -p "$STAGE/plenoptic/bin" "$STAGE/plenoptic/lib"
cp "$BIN" "$STAGE/plenoptic/bin/plenoptic.bin"
# The display pass's benchmark (gpu_device.sh runs it from bin/bench/), where it is built.
DISPLAY_BENCH=$(dirname "$BIN")/bench/gpu_display_bench
BINARIES=("$BIN")
if [ -x "$DISPLAY_BENCH" ]; then
  mkdir -p "$STAGE/plenoptic/bin/bench"
  cp "$DISPLAY_BENCH" "$STAGE/plenoptic/bin/bench/gpu_display_bench.bin"
  BINARIES+=("$DISPLAY_BENCH")
fi
# The libraries the binaries load, by ldd, but the OpenGL and EGL dispatch (glvnd, which must
# find the card's driver: from the packages below) and the kernel's vDSO.
for binary in "${BINARIES[@]}"; do ldd "$binary"; done |
  awk '$3 ~ /^\// {print $3} $1 ~ /^\/.*ld-linux/ {print $1}' | sort -u | while read -r lib; do
  case "$(basename "$lib")" in
    libEGL.so*|libGL.so*|libGLX.so*|libGLdispatch.so*|libOpenGL.so*|libGLESv2.so*) continue ;;
  esac
  cp -L "$lib" "$STAGE/plenoptic/lib/"
done
[ -f "$STAGE/plenoptic/lib/ld-linux-x86-64.so.2" ] || { echo "device_bundle: no ld-linux-x86-64.so.2 among the libraries" >&2; exit 1; }
# The wrapper gpu_device.sh calls as `plenoptic`: the binary through the bundled loader and
# libraries (system paths after them: the driver's).
cat > "$STAGE/plenoptic/bin/plenoptic" <<'SH'
#!/bin/sh
here=$(dirname "$(readlink -f "$0")")
exec "$here/../lib/ld-linux-x86-64.so.2" --library-path "$here/../lib:/usr/lib/x86_64-linux-gnu:/usr/local/nvidia/lib64:/usr/lib64" \
  "$here/plenoptic.bin" "$@"
SH
chmod +x "$STAGE/plenoptic/bin/plenoptic"
if [ -f "$STAGE/plenoptic/bin/bench/gpu_display_bench.bin" ]; then
  cat > "$STAGE/plenoptic/bin/bench/gpu_display_bench" <<'SH'
#!/bin/sh
here=$(dirname "$(readlink -f "$0")")
exec "$here/../../lib/ld-linux-x86-64.so.2" --library-path "$here/../../lib:/usr/lib/x86_64-linux-gnu:/usr/local/nvidia/lib64:/usr/lib64" \
  "$here/gpu_display_bench.bin" "$@"
SH
  chmod +x "$STAGE/plenoptic/bin/bench/gpu_display_bench"
fi
rm -rf "$OUTDIR"
mkdir -p "$OUTDIR/gl"
tar -C "$STAGE" -cJf "$OUTDIR/plenoptic.tar.xz" plenoptic
# Sponza with the folders its file names are relative to (its environment: ../../envmaps/…).
tar -C "$SHARED" -cJf "$OUTDIR/sponza.tar.xz" scenes/sponza envmaps
# Debian's glvnd dispatch libraries (the device notes' list), unpacked there over /.
(cd "$OUTDIR/gl" && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 >/dev/null)
cat > "$OUTDIR/run.sh" <<'SH'
#!/usr/bin/env bash
# On the machine with the card, from the repository root: unpack and measure (device_bundle.sh).
set -euo pipefail
BUNDLE=$(cd "$(dirname "$0")" && pwd)
WORK=${TMPDIR:-/tmp}/plenoptic-device
mkdir -p "$WORK"
if ! ldconfig -p | grep -q 'libEGL.so.1 '; then
  for deb in "$BUNDLE"/gl/*.deb; do dpkg -x "$deb" /; done
  ldconfig
fi
tar -C "$WORK" -xJf "$BUNDLE/plenoptic.tar.xz"
mkdir -p "$WORK/shared"
tar -C "$WORK/shared" -xJf "$BUNDLE/sponza.tar.xz"
"$WORK/plenoptic/bin/plenoptic" --version
RESULTS=${OUT:-}
status=0
PLENOPTIC=$WORK/plenoptic/bin/plenoptic OUT=$WORK/out bash bench/gpu_device.sh "$WORK/shared/scenes/sponza/sponza.json" ||
  status=$?
if [ -n "$RESULTS" ]; then  # a few small files: the summary, the stats JSONs
  cp "$WORK/out/gpu_device.txt" "$RESULTS/" 2>/dev/null || true
  (cd "$WORK/out" && tar -czf "$RESULTS/stats.tar.gz" -- *.json) 2>/dev/null || true
fi
exit "$status"
SH
chmod +x "$OUTDIR/run.sh"
du -sh "$OUTDIR"/* | sed 's/^/device_bundle: /'
echo "device_bundle: $(du -sh "$OUTDIR" | cut -f1) in $OUTDIR (carry device-bundle; run: bash device-bundle/run.sh)"
