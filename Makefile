# Thin wrappers over CMake/CTest: `make demo` and `make test` are the two commands of the README.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: deps configure build demo test bench clean

deps:
	@./scripts/setup-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -G Ninja $(CMAKE_FLAGS) -DGYRODRIFT_BUILD_TESTS=ON -DGYRODRIFT_BUILD_BENCH=ON >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	./$(BUILD)/apps/gyrodrift/gyrodrift demo

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# Full benchmark runs (the figures quoted in docs and closing notes come from these).
bench: build
	@for b in $(BUILD)/bench/bench_*; do echo "== $$b"; $$b; done

clean:
	rm -rf $(BUILD)
