# Thin wrapper over CMake.  `make demo` and `make test` are all a new user
# needs on a fresh Debian 12 machine: both install missing packages first.
#
#   make test        deps, build (build/), the whole CTest suite with
#                    SPLAT_VALIDATE=1, then the unit tests again under
#                    ASan + UBSan (build-asan/)
#   make test-asan   only the ASan + UBSan part
#   make demo        deps, build, render the demo pictures (examples/demo.sh)
#   make bench       benchmarks (tests/bench/run.sh); bench-smoke: a few frames
#   make fuzz        every libFuzzer target (tests/fuzz), FUZZ_SECONDS each

BUILD      ?= build
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= build-fuzz
JOBS       ?= $(shell nproc)
CMAKE_ARGS ?=

# Debian packages the build, the tests and the demo need.
PKGS := cmake make gcc g++ pkg-config clang libclang-rt-14-dev \
        glslang-dev glslang-tools spirv-tools libspirv-cross-c-shared-dev \
        libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools \
        libglfw3-dev libstb-dev libjansson-dev libcmocka-dev libxxhash-dev \
        libzstd-dev zstd \
        libgdal-dev libtinyobjloader-dev \
        gnuplot-nox xvfb xauth graphviz time

SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

# Leak checking stays on under ASan; what the Vulkan loader, the Mesa
# drivers (lavapipe, LLVM) and the validation layers keep for the process's
# lifetime is suppressed by library name (.ci/lsan.supp), not our code.
# lavapipe is dlclose'd with the Vulkan instance: what it still holds then
# shows as an "<unknown module>" leak that no suppression can name, so the
# tests that render under ASan preload it (it stays mapped, its memory
# reachable); libasan then need not come first (verify_asan_link_order=0).
# The validation layer likewise: what its synchronization checks keep
# (SPLAT_VALIDATE=1) is then named, and suppressed, as the layer's.
LVP_SO   := $(firstword $(wildcard /usr/lib/*/libvulkan_lvp.so))
VVL_SO   := $(firstword $(wildcard /usr/lib/*/libVkLayer_khronos_validation.so))
ASAN_ENV := ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:verify_asan_link_order=0 \
            LSAN_OPTIONS=suppressions=$(CURDIR)/.ci/lsan.supp:print_suppressions=0 \
            UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
            $(if $(LVP_SO)$(VVL_SO),LD_PRELOAD="$(strip $(LVP_SO) $(VVL_SO))")

.PHONY: all deps configure build test test-asan demo gallery bench bench-smoke fuzz clean

all: build

# Only packages that are missing are installed; nothing runs when all are.
deps:
	@missing=$$(for p in $(PKGS); do \
	    dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || echo $$p; \
	  done); \
	if [ -n "$$missing" ]; then \
	  echo "installing missing Debian packages:" $$missing; \
	  $(SUDO) apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q --no-install-recommends $$missing; \
	fi

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(CMAKE_ARGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# The whole suite, then the unit tests again under ASan + UBSan.
test: build
	cd $(BUILD) && SPLAT_VALIDATE=1 ctest --output-on-failure -j $(JOBS)
	$(MAKE) test-asan

# The unit tests (label `unit`) and the tests that load packs and render
# them (label `asan`: the corrupt-pack suite, the device limits, hot reload,
# the render cases final/bad_packs/reference_multipass/real_minimal,
# destruction's craters) under ASan + UBSan; the rest of the GPU tests run
# in the main build only, where lavapipe's JIT is not slowed down by ASan.
test-asan: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DSPLAT_SANITIZE=ON $(CMAKE_ARGS)
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && $(ASAN_ENV) ctest --output-on-failure -j $(JOBS) -L 'unit|asan'

demo: build
	@if [ ! -f examples/demo.sh ]; then \
	  echo "make demo: examples/demo.sh is missing"; exit 1; fi
	@sh examples/demo.sh $(BUILD)

# colorado and billingsley from six camera presets each into docs/gallery
# (docs/gallery/before holds the pictures issue 31 started from)
gallery: build
	@sh tests/gallery.sh $(BUILD) docs/gallery

bench: build
	@if [ ! -f tests/bench/run.sh ]; then \
	  echo "make bench: tests/bench/run.sh is missing"; exit 1; fi
	@sh tests/bench/run.sh $(BUILD)

bench-smoke: build
	@if [ ! -f tests/bench/run.sh ]; then \
	  echo "make bench-smoke: tests/bench/run.sh is missing"; exit 1; fi
	@sh tests/bench/run.sh $(BUILD) --smoke

# Every libFuzzer target (tests/fuzz/suite.cmake) for FUZZ_SECONDS each
# (600 for the 10-minute runs); FUZZ_TARGETS to pick some.  clang for both
# languages: the link step must understand -fsanitize=fuzzer.
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?=
fuzz: deps
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -DSPLAT_FUZZ=ON -DCMAKE_BUILD_TYPE=Debug
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_targets splatc_cli
	sh tests/fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) $(FUZZ_TARGETS)

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) out
