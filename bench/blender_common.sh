# Sourced by the bench scripts that compare with Blender Cycles (bench/vs_cycles.sh,
# bench/gltf_vs_cycles.sh, bench/sss_vs_cycles.sh): Blender is optional — without it the script says so and exits 0 —
# while plenoptic must be built.
#   require_blender_and_plenoptic BLENDER PLENOPTIC
require_blender_and_plenoptic() {
  if ! command -v "$1" > /dev/null 2>&1; then
    echo "$0: Blender is not installed ('$1' not found; apt-get install -y blender): skipping the Cycles comparison"
    exit 0
  fi
  if [[ ! -x "$2" ]]; then
    echo "$0: $2 is not an executable (build it first: make build)" >&2
    exit 1
  fi
}
