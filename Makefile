# motorbus developer entry points.  `make demo` and `make test` set up everything
# they need on a fresh Debian/Ubuntu machine (system packages, a venv, the build).
SHELL := /bin/bash
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
BUILD  := build/dev
JOBS   ?= $(shell nproc)
APT_PACKAGES := cmake ninja-build g++ libeigen3-dev libgtest-dev clang libclang-rt-14-dev ccache tmux ser2net
# Only the tests and benchmarks need a browser (the web page's, driven by selenium): `make demo` does not
# install one.
TEST_APT_PACKAGES := chromium chromium-driver
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# ccache (when installed) with paths relative to the checkout, so a fresh clone
# in another directory reuses earlier compilations.  Whether it is installed is
# asked in the build recipe, not when make reads this file: `deps` installs it
# during this same run on a fresh machine, and the first build must use it too.
export CCACHE_BASEDIR := $(CURDIR)
export CCACHE_NOHASHDIR := 1
CCACHE_LAUNCHER = $$(command -v ccache >/dev/null && echo -Ccmake.define.CMAKE_CXX_COMPILER_LAUNCHER=ccache)

.PHONY: demo test deps test-deps venv build cpp-test py-test sanitize fuzz fuzz-smoke bench soak stubs clean

demo: build
	$(PY) -m motorbus demo

test: build cpp-test py-test sanitize fuzz-smoke stubs-check
	@echo "== all test stages passed"

deps: $(VENV)/.deps
# The Debian packages of $(1) that are missing, installed (nothing asked when all are there).
define apt_install
@missing=$$(for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
if [ -n "$$missing" ]; then echo "installing: $$missing"; \
  $(SUDO) apt-get update -qq && $(SUDO) DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; fi
endef

$(VENV)/.deps: requirements-dev.txt
	$(call apt_install,$(APT_PACKAGES))
	[ -x $(PY) ] || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -r requirements-dev.txt
	touch $@

# One CMake build serves pip (the extension, installed editable into the venv
# with the python-can entry point) and ctest (the GoogleTest suites).
build: deps
	$(PY) -m pip install -q --no-build-isolation --no-deps -e . \
	  -Cbuild-dir=$(BUILD) -Ccmake.define.MOTORBUS_TESTS=ON -Ccmake.define.MOTORBUS_BENCH=ON -Ccmake.define.MOTORBUS_EXAMPLES=ON \
	  -Cbuild.tool-args=-j$(JOBS) $(CCACHE_LAUNCHER)

cpp-test: build
	ctest --test-dir $(BUILD) --output-on-failure -j$(JOBS)

# Three workers (pytest-xdist), a module per worker at a time: most tests wait on simulated
# motion and transports (a worker uses ~40% of a core), so three on a 2-core machine cut the
# wall time further than two.
PYTEST_WORKERS ?= 3
test-deps: deps
	$(call apt_install,$(TEST_APT_PACKAGES))

py-test: build test-deps
	$(PY) -m pytest -q -p no:cacheprovider -n $(PYTEST_WORKERS) --dist loadfile

# C++ suites and the threaded Python tests under ASan+UBSan; C++ suites under TSan.
sanitize: deps
	bash tools/sanitize.sh $(PY)

fuzz: deps
	bash tools/fuzz.sh runs 10000000

fuzz-smoke: deps
	bash tools/fuzz.sh run 3

# tests/reliability scaled up (long; the default pytest run holds their bounded form).
soak: build
	MOTORBUS_SOAK=1 $(PY) -m pytest -q -p no:cacheprovider tests/reliability

bench: build test-deps
	bash tools/bench.sh $(PY)

stubs: build
	$(PY) tools/gen_stubs.py write

stubs-check: build
	$(PY) tools/gen_stubs.py check

clean:
	rm -rf build $(VENV) python/motorbus/_core*.so
