# Thin wrapper over CMake.  `make demo` and `make test` are all a new user
# needs on a fresh Debian 12 machine: both install missing packages first.

BUILD      ?= build
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= build-fuzz
JOBS       ?= $(shell nproc)
CMAKE_ARGS ?=

# Debian packages the build, the tests and the demo need.
PKGS := cmake make gcc g++ pkg-config clang libclang-rt-14-dev \
        glslang-dev glslang-tools spirv-tools \
        libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools \
        libglfw3-dev libstb-dev libjansson-dev libcmocka-dev libxxhash-dev \
        gnuplot-nox xvfb xauth graphviz

SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build test test-asan demo bench bench-smoke fuzz clean

all: build

deps:
	@missing=$$(for p in $(PKGS); do \
	    dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || echo $$p; \
	  done); \
	if [ -n "$$missing" ]; then \
	  echo "installing missing Debian packages:" $$missing; \
	  $(SUDO) apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q --no-install-recommends $$missing; \
	fi

$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(CMAKE_ARGS)

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# The whole suite, then the unit tests again under ASan + UBSan.
test: build
	cd $(BUILD) && SPLAT_VALIDATE=1 ctest --output-on-failure -j $(JOBS)
	$(MAKE) test-asan

test-asan: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DSPLAT_SANITIZE=ON $(CMAKE_ARGS)
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure -j $(JOBS) -L unit

demo: build
	@sh examples/demo.sh $(BUILD)

bench: build
	@sh tests/bench/run.sh $(BUILD)

bench-smoke: build
	@sh tests/bench/run.sh $(BUILD) --smoke

# libFuzzer on the lexer and parser; FUZZ_SECONDS=600 for the 10-minute run.
FUZZ_SECONDS ?= 60
fuzz: deps
	CC=clang cmake -S . -B $(FUZZ_BUILD) -DSPLAT_FUZZ=ON -DCMAKE_BUILD_TYPE=Debug
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_parse
	mkdir -p $(FUZZ_BUILD)/corpus && cp nodes/*.sg graphs/*.sg examples/*/*.sg $(FUZZ_BUILD)/corpus/ 2>/dev/null || true
	$(FUZZ_BUILD)/tests/fuzz_parse -max_total_time=$(FUZZ_SECONDS) -max_len=65536 $(FUZZ_BUILD)/corpus

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) out
