# Thin wrappers over CMake/CTest: `make demo` and `make test` are the two commands of the README.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release
# A compiler cache where one is installed (scripts/setup-deps.sh installs ccache): a rebuild, or a
# fresh clone of sources built before on this machine, reuses the objects. CCACHE_BASEDIR makes
# the paths it hashes relative to the checkout, wherever the clone is.
CCACHE := $(shell command -v ccache 2>/dev/null)
LAUNCHER := $(if $(CCACHE),-DCMAKE_CXX_COMPILER_LAUNCHER=$(CCACHE) -DCMAKE_C_COMPILER_LAUNCHER=$(CCACHE))
export CCACHE_BASEDIR := $(CURDIR)
export CCACHE_DIR ?= $(if $(HOME),$(HOME)/.cache/ccache,$(CURDIR)/.ccache)
# The sanitized and fuzz builds carry -g: without this, ccache would hash the build directory too.
export CCACHE_NOHASHDIR := 1

.PHONY: deps configure build demo test test-sanitize fuzz bench clean

deps:
	@./scripts/setup-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -G Ninja $(CMAKE_FLAGS) $(LAUNCHER) -DGYRODRIFT_BUILD_TESTS=ON -DGYRODRIFT_BUILD_BENCH=ON >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	./$(BUILD)/apps/gyrodrift/gyrodrift demo

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The whole test suite under AddressSanitizer (with leak checks) and UndefinedBehaviorSanitizer,
# built by clang at -O1 with assertions on (issue 14). Any report fails the test that caused it.
# Excluded: the label "install" (it builds examples/find_package with the consumer's own flags
# against the instrumented static libraries, which cannot link without -fsanitize; `make test`
# runs it), and the Python package (an instrumented module cannot load into an uninstrumented
# interpreter; `make test` runs its tests). GYRODRIFT_SANITIZE=1 tells the few intrinsically slow tests to use smaller sizes.
SANITIZE_FLAGS = -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
SANITIZE_ENV = ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 GYRODRIFT_SANITIZE=1
test-sanitize: deps
	@CC=clang CXX=clang++ cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=Debug $(LAUNCHER) \
		"-DCMAKE_CXX_FLAGS_DEBUG=$(SANITIZE_FLAGS)" -DGYRODRIFT_BUILD_TESTS=ON \
		-DGYRODRIFT_BUILD_PYTHON=OFF >/dev/null
	@cmake --build build-sanitize -j $(JOBS)
	cd build-sanitize && $(SANITIZE_ENV) ctest --output-on-failure -j $(JOBS) -LE '^install$$'

# libFuzzer on the CSV reader, the model-file loader, the option parsers, the calibration
# manifest and the ULog reader, FUZZ_SECONDS each,
# with AddressSanitizer and UndefinedBehaviorSanitizer; the corpora grow in build-fuzz/ (issue 14).
FUZZ_SECONDS ?= 30
FUZZ_SEED ?= 1
FUZZ_FLAGS = -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
fuzz: deps
	@CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE= $(LAUNCHER) \
		-DGYRODRIFT_BUILD_TESTS=OFF -DGYRODRIFT_BUILD_APPS=OFF -DGYRODRIFT_BUILD_FUZZ=ON \
		-DGYRODRIFT_BUILD_PYTHON=OFF \
		"-DCMAKE_CXX_FLAGS=$(FUZZ_FLAGS)" >/dev/null
	@cmake --build build-fuzz -j $(JOBS) --target fuzz_csv fuzz_model_file fuzz_options fuzz_manifest fuzz_ulog
	@for h in csv model_file options manifest ulog; do \
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
