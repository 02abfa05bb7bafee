# plenoptic — top-level entry points. Each target installs missing Debian packages first
# (scripts/bootstrap.sh), configures a Release build in build/ and builds what it needs.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

PREFIX ?= /usr/local
FUZZ_BUILD_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?= obj gltf json_scene camera_path hdr exr plf plf_fixed plv plv_fixed plt plt_fixed pls pls_fixed

.PHONY: all bootstrap configure build python examples scenes test demo bench fuzz install clean

all: build

bootstrap:
	@bash scripts/bootstrap.sh

configure: bootstrap
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The Python package alone (build/python/plenoptic/; `build` makes it too). To install it: docs/python.md.
python: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target plenoptic_python

# The worked Python examples (examples/, with matplotlib for their plots), written to out/examples/.
examples: python
	@bash scripts/bootstrap.sh --examples
	@for example in trace_vs_bake relight_sweep camera_path_video; do \
	  PYTHONPATH=$(BUILD_DIR)/python /usr/bin/python3 examples/$$example.py --out out/examples || exit 1; done

# The scenes the documentation uses, from their public sources into scenes/ (needs a network;
# scripts/get-scenes.sh --help).
scenes:
	@bash scripts/get-scenes.sh

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# The program, its bash completion and man page, and the documentation under $(PREFIX)
# (cmake/install.cmake); e.g. `make install PREFIX=~/.local`.
install: build
	@cmake --install $(BUILD_DIR) --prefix $(PREFIX)

demo: build
	@$(BUILD_DIR)/plenoptic demo --output-dir out/demo

bench: build
	@bash bench/run.sh $(BUILD_DIR)

# libFuzzer targets (fuzz/) built with clang, ASan and UBSan in $(FUZZ_BUILD_DIR), each run for
# FUZZ_SECONDS; crashes are saved as $(FUZZ_BUILD_DIR)/findings/<target>/crash-*.
fuzz:
	@bash scripts/bootstrap.sh --fuzz
	@cmake -S . -B $(FUZZ_BUILD_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
	  -DPLENOPTIC_FUZZ=ON -DPLENOPTIC_WERROR=OFF -DBUILD_TESTING=OFF -DPLENOPTIC_BENCHMARKS=OFF >/dev/null
	@cmake --build $(FUZZ_BUILD_DIR) -j $(JOBS) --target fuzz_targets
	@bash fuzz/run.sh $(FUZZ_BUILD_DIR) $(FUZZ_SECONDS) $(FUZZ_TARGETS)

clean:
	@rm -rf $(BUILD_DIR) $(FUZZ_BUILD_DIR)
