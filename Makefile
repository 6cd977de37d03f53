# SPDX-License-Identifier: GPL-3.0-or-later
# `make demo` and `make test` each install missing Debian packages, build (Release, all cores), then run.

BUILD_DIR ?= build
JOBS      ?= $(shell nproc)
DEMO_DIR  ?= out/demo

# Libraries the build needs (libjs-three: three.js, inlined into viewer.html at build time).
BUILD_PACKAGES := cmake g++ make libopenvdb-dev libtbb-dev libeigen3-dev libdraco-dev libtinygltf-dev \
                  libstb-dev libboost-iostreams-dev doctest-dev libmaxflow-dev liblinear-dev libcli11-dev nlohmann-json3-dev zlib1g-dev \
                  libjs-three
# Real checkers the tests run on the outputs: admesh (STL manifold check), draco_decoder, prusa-slicer;
# what the batch tests run the docs' recipes on: a single-node Slurm (slurm-wlm, munge), GNU parallel;
# chromium (headless) opens viewer.html offline and screenshots it.
TEST_PACKAGES  := admesh draco prusa-slicer slurm-wlm munge parallel chromium
# The Khronos glTF-Validator (npm), installed once into $(BUILD_DIR)/node; the GLB tests run it with node.
GLTF_VALIDATOR := gltf-validator@2.0.0-dev.3.10

.PHONY: all build test demo deps test-deps clean fuzz sweep

all: build

deps:
	@./tools/install-deps.sh $(BUILD_PACKAGES)

test-deps:
	@./tools/install-deps.sh $(BUILD_PACKAGES) $(TEST_PACKAGES)
	@if command -v npm > /dev/null && [ ! -f $(BUILD_DIR)/node/node_modules/gltf-validator/package.json ]; then \
	  npm install --prefix $(BUILD_DIR)/node --no-save --no-audit --no-fund $(GLTF_VALIDATOR); fi

$(BUILD_DIR)/CMakeCache.txt:
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: test-deps $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS)
	ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS) -LE sweep

# The size sweep at 700 mm (tools/size-sweep.sh; 200 and 400 mm run with `make test`): about half an hour
sweep: test-deps $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS)
	ctest --test-dir $(BUILD_DIR) --output-on-failure -L sweep

demo: build
	./tools/demo.sh $(BUILD_DIR) $(DEMO_DIR)

# libFuzzer targets for every reader of an untrusted file (clang, ASan + UBSan); tools/fuzz-all.sh runs them
fuzz:
	@./tools/install-deps.sh $(BUILD_PACKAGES) clang libclang-rt-14-dev
	CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZOMEFAB_FUZZ=ON \
	  -DZOMEFAB_BUILD_TESTS=OFF -DZOMEFAB_BUILD_TOOLS=OFF
	cmake --build build-fuzz -j $(JOBS) --target fuzz_all

clean:
	rm -rf $(BUILD_DIR) build-fuzz out
