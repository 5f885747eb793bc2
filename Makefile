# Thin wrapper over CMake presets. `make demo` and `make test` set up a fresh Debian 12 machine.
# `make install PREFIX=DIR` installs there (default /usr/local); `make package` builds the .deb
# files in build/release (docs/install.md).
JOBS ?= $(shell nproc)
PREFIX ?= /usr/local
BUILD := build/release
GLINT := $(BUILD)/apps/glint/glint
DATA ?= $(or $(GLINT_DATA),../shared/data)
FUZZ_SECONDS ?= 60

.PHONY: deps build install package demo test bench asan fuzz format-check clean

deps:
	bash scripts/install-deps.sh

build: deps
	cmake --preset release
	cmake --build --preset release -j $(JOBS)

install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

package: build
	cmake --build $(BUILD) --target package

demo: build
	bash scripts/demo.sh $(GLINT) $(DATA)

test: build
	ctest --preset release -j $(JOBS)

bench: build
	bash scripts/bench.sh $(BUILD) $(DATA)

asan: deps
	cmake --preset asan
	cmake --build --preset asan -j $(JOBS)
	ctest --preset asan -j $(JOBS)

# Each libFuzzer target of fuzz/ for FUZZ_SECONDS, one after the other (docs/fuzzing.md); finds
# go to build/fuzz/crashes/.
fuzz:
	bash scripts/install-deps.sh --fuzz
	cmake --preset fuzz
	cmake --build --preset fuzz -j $(JOBS)
	bash scripts/fuzz.sh build/fuzz $(FUZZ_SECONDS)

format-check:
	git ls-files '*.h' '*.cpp' | xargs clang-format --dry-run --Werror

clean:
	rm -rf build
