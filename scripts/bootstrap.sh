#!/usr/bin/env bash
# Installs the Debian 12 packages plenoptic needs to build, test and run its demo.
# Idempotent and quiet when everything is already present; run as root (or with sudo).
# --fuzz: also clang and its runtime libraries (libclang_rt.fuzzer, ASan, UBSan) for `make fuzz`.
# --examples: also matplotlib, which the Python examples plot with (examples/; not the tests).
set -euo pipefail

packages=(
  build-essential cmake pkg-config ccache git
  libembree-dev libtbb-dev libglm-dev libtinyobjloader-dev libtinygltf-dev libdraco-dev libmeshoptimizer-dev
  libopenexr-dev libstb-dev libzstd-dev libsquish-dev libsdl2-dev libxxhash-dev
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev
  libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libgl1 libglx-mesa0
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin
  xvfb xauth bash-completion
  python3-dev pybind11-dev python3-numpy python3-pytest
  python3-pip python3-venv python3-setuptools python3-wheel
)
case "${1:-}" in
  --fuzz) packages+=(clang libclang-rt-14-dev) ;;
  --examples) packages+=(python3-matplotlib) ;;
esac
# Optional: ffmpeg turns rendered walk-throughs into MP4. Installed when it is available.
optional_packages=(ffmpeg)

missing=()
for p in "${packages[@]}" "${optional_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "bootstrap: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
echo "bootstrap: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# Required packages must install; the optional ones may fail without stopping the build.
$SUDO apt-get install -y -qq --no-install-recommends "${packages[@]}" >/dev/null
$SUDO apt-get install -y -qq --no-install-recommends "${optional_packages[@]}" >/dev/null 2>&1 \
  || echo "bootstrap: optional packages not installed: ${optional_packages[*]}" >&2
