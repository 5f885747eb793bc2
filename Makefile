# Thin wrapper over CMake presets. `make demo` and `make test` set up a fresh Debian 12 machine.
JOBS ?= $(shell nproc)
BUILD := build/release
GLINT := $(BUILD)/apps/glint/glint
DATA ?= $(or $(GLINT_DATA),../shared/data)

.PHONY: deps build demo test bench asan format-check clean

deps:
	bash scripts/install-deps.sh

build: deps
	cmake --preset release
	cmake --build --preset release -j $(JOBS)

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

format-check:
	git ls-files '*.h' '*.cpp' | xargs clang-format --dry-run --Werror

clean:
	rm -rf build
