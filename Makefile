# Thin wrappers over CMake/CTest: `make demo` and `make test` are the two commands of the README.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

.PHONY: deps configure build demo test fuzz bench clean

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

# libFuzzer on the CSV reader, the model-file loader, the option parsers and the calibration
# manifest, FUZZ_SECONDS each,
# with AddressSanitizer and UndefinedBehaviorSanitizer; the corpora grow in build-fuzz/ (issue 14).
FUZZ_SECONDS ?= 30
FUZZ_SEED ?= 1
FUZZ_FLAGS = -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
fuzz: deps
	@CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE= \
		-DGYRODRIFT_BUILD_TESTS=OFF -DGYRODRIFT_BUILD_APPS=OFF -DGYRODRIFT_BUILD_FUZZ=ON \
		"-DCMAKE_CXX_FLAGS=$(FUZZ_FLAGS)" >/dev/null
	@cmake --build build-fuzz -j $(JOBS) --target fuzz_csv fuzz_model_file fuzz_options fuzz_manifest
	@for h in csv model_file options manifest; do \
		mkdir -p build-fuzz/corpus/$$h && cp tests/fuzz/corpus/$$h/* build-fuzz/corpus/$$h/ && \
		./build-fuzz/tests/fuzz/fuzz_$$h -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -seed=$(FUZZ_SEED) -artifact_prefix=build-fuzz/ \
			-print_final_stats=1 build-fuzz/corpus/$$h > build-fuzz/fuzz_$$h.log 2>&1 \
			|| { tail -n 40 build-fuzz/fuzz_$$h.log; exit 1; }; \
		echo "fuzz_$$h: $$(grep -E 'number_of_executed_units' build-fuzz/fuzz_$$h.log)"; \
	done

# Full benchmark runs (the figures quoted in docs and closing notes come from these).
bench: build
	@for b in $(BUILD)/bench/bench_*; do echo "== $$b"; $$b; done

clean:
	rm -rf $(BUILD)
