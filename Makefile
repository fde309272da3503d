# glslppm: `make demo` renders the demo scene, `make test` runs every test.
# Both install the Debian packages they need and build first.
PYTHON ?= /usr/bin/python3
BUILD  ?= build
JOBS   ?= $(shell nproc)

.PHONY: all deps build test test-native test-python test-blender demo install clean
.PHONY: test-sanitize fuzz-build test-fuzz-replay fuzz

all: build

deps:
	@scripts/install-deps.sh build

build: deps
	@cmake -S . -B $(BUILD) -G Ninja -DPython3_EXECUTABLE=$(PYTHON) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

test:
	@scripts/install-deps.sh test
	@$(MAKE) --no-print-directory build
	@scripts/test-all.sh

test-native:
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-python:
	PYTHONPATH=$(CURDIR)/$(BUILD) $(PYTHON) -m pytest -q -rs tests/python tests/scripts

# Each glslppm-bench subcommand once on a tiny configuration, its JSON checked.
.PHONY: test-bench test-mutations
test-bench:
	GLSLPPM_SHADER_DIR=$(CURDIR)/shaders $(PYTHON) tests/bench/check_bench.py $(BUILD)/glslppm-bench

# Deliberate bugs planted in a copy of the shaders, one at a time: which tests catch each
# (scripts/mutations.py; 4-14 minutes a mutation, so not part of `make test`).
test-mutations: build
	$(PYTHON) scripts/mutations.py --build $(BUILD)

test-blender:
	@scripts/test-blender.sh

# The rendered viewport and material previews in Blender's UI under Xvfb (3.4, 4.3, 5.2).
.PHONY: test-viewport
test-viewport:
	@scripts/test-viewport.sh

# The path every user takes first, in Blender's real UI under Xvfb with real key presses:
# F12, Esc, F12, an edit, a file closed mid-render, Ctrl+S, Ctrl+Q; then F12 / Esc / F12 /
# Ctrl+Q ten times in a row, each in a fresh Blender (3.4 and 4.3).
.PHONY: test-user-path
test-user-path:
	@scripts/test-user-path.sh

# The one extension zip for Blender 4.2+ (official builds and Debian's): the module for
# CPython 3.11, 3.13 and 3.14 with the libraries each links, build/dist/glslppm-<v>-linux-x64.zip.
.PHONY: extension dist test-extension
extension dist:
	@scripts/make-extension.sh

# That zip checked with ldd and installed into a fresh Blender 4.3 and 5.2, rendering.
test-extension:
	@scripts/test-extension.sh

# The native tests again under AddressSanitizer + UndefinedBehaviorSanitizer, in a second
# build without the Python module. Mesa's DRI driver is preloaded
# (after libasan, which must come first) so that its globals stay mapped until
# LeakSanitizer runs: see tests/sanitize/lsan.supp. The resident-memory test is left out:
# ASan's quarantine and shadow memory grow RSS by themselves, and LeakSanitizer checks
# the same leaks exactly. So are the largest cases of three suites, which ran 8 of the
# suite's 15 minutes under ASan (CI is near its 90-minute limit): the two 1,000-instance
# brute forces and the 10,000- and 100,000-triangle soups run the same host code as the
# smaller cases kept here, on more rays; the BSDF chi-squared fits sample on the GPU (Mesa,
# not instrumented) and only bin on the host. All of them still run in `test-native`.
ASAN_BUILD ?= build-asan
DRI_DRIVER := $(wildcard /usr/lib/$(shell gcc -print-multiarch 2>/dev/null)/dri/swrast_dri.so)
SANITIZE_ENV = LD_PRELOAD="$(shell gcc -print-file-name=libasan.so) $(DRI_DRIVER)" \
	ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:check_initialization_order=1 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitize/lsan.supp \
	UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
test-sanitize:
	@cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		-DGLSLPPM_SANITIZE=ON -DGLSLPPM_PYTHON=OFF >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS) --target glslppm-tests
	$(SANITIZE_ENV) ctest --test-dir $(ASAN_BUILD) --output-on-failure -j $(JOBS) \
		-E 'HundredCreateDestroyCyclesDoNotLeak|TwoLevelBruteForce.*/[45]$$|BruteForce/soup_10000|Sampling(Matches|Match)(Its|Their)Density'

# libFuzzer targets fuzz/<target>_fuzz.cpp, built by clang.
# test-fuzz-replay runs each once on every kept input in tests/fuzz/<target>/;
# `make fuzz FUZZ_TARGET=scene FUZZ_SECONDS=1800 [FUZZ_FLAGS=-dict=...]` fuzzes one
# target, niced (corpus in $(FUZZ_BUILD)/corpus/<target>, seeded from tests/fuzz/<target>;
# crashes in $(FUZZ_BUILD)/artifacts/<target>/).
FUZZ_BUILD ?= build-fuzz
FUZZ_TARGET ?= scene
FUZZ_SECONDS ?= 60
FUZZ_FLAGS ?=
fuzz-build:
	@CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		-DGLSLPPM_FUZZ=ON -DGLSLPPM_PYTHON=OFF -DGLSLPPM_TESTS=OFF >/dev/null
	@cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzzers

test-fuzz-replay: fuzz-build
	@status=0; for source in fuzz/*_fuzz.cpp; do \
		[ -e "$$source" ] || continue; \
		target=$$(basename $$source _fuzz.cpp); \
		inputs=$$(find tests/fuzz/$$target -type f ! -name '*.py' ! -name '*.md' 2>/dev/null | sort); \
		[ -n "$$inputs" ] || { echo "fuzz $$target: no kept inputs"; continue; }; \
		log=$(FUZZ_BUILD)/replay-$$target.log; \
		if UBSAN_OPTIONS=print_stacktrace=1 $(FUZZ_BUILD)/fuzz/$${target}_fuzz $$inputs >$$log 2>&1; then \
			echo "fuzz $$target: $$(echo $$inputs | wc -w) kept inputs replayed, no crash"; \
		else cat $$log; echo "fuzz $$target: FAILED (log: $$log)"; status=1; fi; \
	done; exit $$status

fuzz: fuzz-build
	@mkdir -p $(FUZZ_BUILD)/corpus/$(FUZZ_TARGET) $(FUZZ_BUILD)/artifacts/$(FUZZ_TARGET)
	nice -n 19 $(FUZZ_BUILD)/fuzz/$(FUZZ_TARGET)_fuzz -max_total_time=$(FUZZ_SECONDS) \
		-artifact_prefix=$(FUZZ_BUILD)/artifacts/$(FUZZ_TARGET)/ -print_final_stats=1 \
		$(FUZZ_FLAGS) $(FUZZ_BUILD)/corpus/$(FUZZ_TARGET) tests/fuzz/$(FUZZ_TARGET)

install: build
	@scripts/install-addon.sh

# The demo needs the Python module alone: not the tests, the CLI or the benchmarks. On a
# fresh 2-core machine `make build` takes 442 CPU-s, the module alone 231 (session 20).
demo:
	@scripts/install-deps.sh demo
	@cmake -S . -B $(BUILD) -G Ninja -DPython3_EXECUTABLE=$(PYTHON) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target _glslppm
	@scripts/demo.sh

clean:
	rm -rf $(BUILD) out
