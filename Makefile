# glslppm: `make demo` renders the demo scene, `make test` runs every test.
# Both install the Debian packages they need and build first.
PYTHON ?= /usr/bin/python3
BUILD  ?= build
JOBS   ?= $(shell nproc)

.PHONY: all deps build test test-native test-python test-blender demo install clean

all: build

deps:
	@scripts/install-deps.sh build

build: deps
	@cmake -S . -B $(BUILD) -G Ninja -DPython3_EXECUTABLE=$(PYTHON) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

test:
	@scripts/install-deps.sh test
	@$(MAKE) --no-print-directory build
	@$(MAKE) --no-print-directory test-native test-python test-blender

test-native:
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-python:
	PYTHONPATH=$(CURDIR)/$(BUILD) $(PYTHON) -m pytest -q tests/python

test-blender:
	@if [ -x scripts/test-blender.sh ]; then scripts/test-blender.sh; fi

install: build
	@scripts/install-addon.sh

demo:
	@scripts/install-deps.sh demo
	@$(MAKE) --no-print-directory build
	@scripts/demo.sh

clean:
	rm -rf $(BUILD) out
