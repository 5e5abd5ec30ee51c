# Two entry points (see README): `make demo` and `make test`.
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
# Every command here writes Python's bytecode, also where the environment sets
# PYTHONDONTWRITEBYTECODE: the set-up's steps, the demo and the test suite start hundreds
# of Python processes, and each then reads the modules (and pytest its rewritten tests)
# compiled once instead of compiling them again.
unexport PYTHONDONTWRITEBYTECODE
VENV   := .venv
BIN    := $(VENV)/bin
# what is installed: the core (the demo's needs: reference, harness, MuJoCo, PyBullet) and,
# for the tests, every engine's extra with the dev tools (pyproject.toml; README "Install
# sizes")
STAMP  := $(VENV)/.installed
STAMP_ALL := $(VENV)/.installed-all
# the build's own requirements (pyproject.toml [build-system]: numba, numpy, setuptools),
# installed first: the reference's compiled core needs nothing else to build
BUILD_DEPS := $(VENV)/.build-deps
# the reference's compiled core, built ahead of time by `python -m reference.core.aot`
# (skipped without a C compiler: it is then compiled just in time on first use); it
# rebuilds the module when its sources change and does nothing when it is fresh.  The
# installs leave it out of pip's build (EULER_DISK_BUILD_CORE=0, setup.py) so that it
# compiles on one core while pip installs the packages on the other (make -j2).
AOT    := $(VENV)/.aot
CORE   := $(wildcard reference/core/*.py)
LINEAR := $(wildcard reference/linear/*.py)
WARM   := $(VENV)/.warm
NO_CORE_BUILD := EULER_DISK_BUILD_CORE=0
# (read once, where first needed: each reading starts a Python)
BUILD_REQUIRES = $(eval BUILD_REQUIRES := $(shell $(PYTHON) -c 'import shlex, tomllib; \
	print(shlex.join(tomllib.load(open("pyproject.toml", "rb"))["build-system"]["requires"]))'))$(BUILD_REQUIRES)

.PHONY: setup demo test test-slow lint bench figures docs-figures browser clean

$(BUILD_DEPS): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), sys.version' || { echo "need Python >= 3.11 (make PYTHON=/path/to/python3.11)"; exit 2; }
	@echo "set-up 1/3: a virtual environment in $(VENV) and what the reference's compiled core"
	@echo "  is built with ($(BUILD_REQUIRES)); Python:"
	@echo "  $(PYTHON)"
	@echo "  installer: $(INSTALLER_NOTE)"
	$(PYTHON) -m venv $(if $(PIP_CAN_TARGET),--without-pip) $(VENV)
	$(GET_INSTALLER)
	$(INSTALL) $(BUILD_REQUIRES)
	touch $(BUILD_DEPS)

# The venv is made without pip (ensurepip takes 6 s, all on the set-up's longest path)
# where the system's pip can install into it (`pip --python`, pip >= 22.3): that pip
# installs uv into it (INSTALLER=pip: the build's requirements and then, beside the
# build, the venv's own pip).
# (asked once, when first needed, and passed on to the make that runs the steps side by
# side: asked there, make would ask while the core's build waits to start)
PIP_CAN_TARGET = $(eval PIP_CAN_TARGET := $(shell $(PYTHON) -m pip --python $(PYTHON) --version \
	> /dev/null 2>&1 && echo yes))$(PIP_CAN_TARGET)
VENV_PIP = $(if $(PIP_CAN_TARGET),$(PYTHON) -m pip --python $(BIN)/python,$(BIN)/pip)

# The installer: uv (pip installs it into the venv; `uv pip install`), or pip with
# `make setup INSTALLER=pip`.  uv installs every extra in 13 s where pip takes 31 s on an
# idle machine and 42-46 s beside the core's build, and the set-up ends 15-20 s sooner
# (docs/performance.md).  uv reads none of pip's configuration (pip.conf,
# PIP_INDEX_URL): where packages must come from an index set there, use INSTALLER=pip,
# or uv's own UV_INDEX_URL.
# Both install the packages without their bytecode (uv by default, pip with
# --no-compile): pip would byte-compile all 12,000 of their modules (42 CPU-s); the
# ~3,000 that the project and its tests import are compiled by the set-up step after the
# install (tests/warm_bytecode.py) or where first imported, and their bytecode written
# then, so that every later process reads them compiled.
INSTALLER ?= uv
ifeq ($(INSTALLER),uv)
GET_INSTALLER = $(VENV_PIP) install --progress-bar off --no-compile 'uv>=0.5'
INSTALL = $(BIN)/uv pip install --python $(BIN)/python
INSTALL_PACKAGES = $(INSTALL)
# printed at the set-up's start, so that a failed install is read beside it
INSTALLER_NOTE = uv (it reads none of pip's configuration; INSTALLER=pip installs with pip)
# beside the core's build: the venv's own pip, for the user's later installs
BESIDE_BUILD = $(INSTALL) pip
else ifeq ($(INSTALLER),pip)
GET_INSTALLER = @:
INSTALL = $(VENV_PIP) install --progress-bar off --no-compile
INSTALL_PACKAGES = $(BIN)/pip install --progress-bar off --no-compile
INSTALLER_NOTE = pip (INSTALLER=pip; without it, uv installs)
# beside the core's build, not before it: the venv's own pip, current (installed, or
# brought up to date), and the build's requirements byte-compiled (--no-compile above:
# 7.5 of their 12.7 s install)
BESIDE_BUILD = $(INSTALL) --upgrade pip && $(BIN)/python -m compileall -q $(VENV)/lib
else
$(error INSTALLER is uv or pip, not '$(INSTALLER)')
endif

# the package and its core dependencies: the demo's needs
$(STAMP): $(BUILD_DEPS)
	@echo "set-up 3/3: the package and its core dependencies (MuJoCo, PyBullet, rerun, ...),"
	@echo "  beside step 2/3"
	$(BESIDE_BUILD)
	$(NO_CORE_BUILD) $(INSTALL_PACKAGES) -e .
	touch $(STAMP)

# every extra ([all]: drake, dart, mjx, dask) and the dev tools
$(STAMP_ALL): $(BUILD_DEPS)
	@echo "set-up 3/3: the package, every extra (Drake, DART, MJX, dask) and the dev tools"
	@echo "  (2.5 GB in all), beside step 2/3"
	$(BESIDE_BUILD)
	$(NO_CORE_BUILD) $(INSTALL_PACKAGES) -e '.[all,dev]'
	touch $(STAMP) $(STAMP_ALL)

$(AOT): $(BUILD_DEPS) $(CORE)
	@echo "set-up 2/3: the reference's compiled core (about 2 min on one core, beside step"
	@echo "  3/3; rebuilt when its sources change)"
	$(BIN)/python -m reference.core.aot
	touch $(AOT)

# numba's cache of the linear model's kernel (compiled just in time: reference/warm.py),
# filled once the packages are in (PACKAGES: the install it waits for), while the core's
# build still runs
PACKAGES ?= $(STAMP)
$(WARM): $(PACKAGES) $(CORE) $(LINEAR) reference/warm.py
	@echo "set-up 3/3, then: the linear model's kernel into numba's cache"
	$(BIN)/python -m reference.warm
	touch $(WARM)

# the bytecode of the installed modules the project and its tests import, written once
# the packages are in, so that the tests' processes do not each compile them
BYTECODE_WARM := $(VENV)/.bytecode
$(BYTECODE_WARM): $(STAMP_ALL) tests/warm_bytecode.py
	@echo "set-up 3/3, then: the bytecode of the modules the tests import"
	nice -n 19 $(BIN)/python -m tests.warm_bytecode
	touch $(BYTECODE_WARM)

# JAX's compilation cache (.cache/jax) filled with the three programs MJX's tests compile
# (tests/warm_mjx.py): on the core that the installs and the linear kernel leave idle
# while the core's build still runs, at the lowest priority so that the build keeps its
# core (XLA compiles on several threads); the tests' workers then load the programs
JAX_WARM := $(VENV)/.jax-warm
$(JAX_WARM): $(STAMP_ALL) engines/mjx.py tests/warm_mjx.py
	@echo "set-up 3/3, last: MJX's scans, for its tests, into JAX's cache"
	nice -n 19 $(BIN)/python -m tests.warm_mjx
	touch $(JAX_WARM)

# pytest's bytecode of the test modules (their asserts rewritten), written once: each of
# the tests' workers collects every test module, and without it each rewrites them all
# (3 of the 7 s before a worker's first test).  After the installed modules' bytecode
# (it imports them too), at the lowest priority, on whichever core is free first: after
# the warm-ups on the second core when they end before the core's build (uv), else on
# the build's core once the build is done (pip).  A module that cannot be collected is
# left to the tests, which report it.
TESTS_COLLECTED := $(VENV)/.tests-collected
$(TESTS_COLLECTED): $(STAMP_ALL) $(BYTECODE_WARM) $(wildcard tests/*.py tests/*/*.py)
	@echo "set-up 3/3, then: the test modules' bytecode (pytest --collect-only)"
	-nice -n 19 $(BIN)/python -m pytest --collect-only -q -p no:cacheprovider > /dev/null
	touch $(TESTS_COLLECTED)

# everything the tests need: the installs and the core's build side by side
setup: $(BUILD_DEPS)
	@$(MAKE) --no-print-directory -j2 PACKAGES=$(STAMP_ALL) PIP_CAN_TARGET=$(PIP_CAN_TARGET) \
		$(AOT) $(STAMP_ALL) $(BYTECODE_WARM) $(WARM) $(JAX_WARM) $(TESTS_COLLECTED)
	@echo "set-up: done"

# Main job: the reference against both tuned engines on the built-in chatter scene,
# with a rerun recording of all three side by side (--force: the demo's own recording is
# replaced when the demo runs again).
demo: $(BUILD_DEPS)
	@$(MAKE) --no-print-directory -j2 PIP_CAN_TARGET=$(PIP_CAN_TARGET) $(AOT) $(STAMP) $(WARM)
	$(BIN)/harness compare triangle-chatter --engine mujoco --engine pybullet \
		--engine linear --record recordings/triangle-chatter.rrd --force

# every engine's tests, on every core (pytest-xdist; TEST_WORKERS=1: one process); an
# engine whose extra is missing has its tests skipped with the reason, and under CI=true
# (.ci/run) they fail instead (tests/conftest.py)
# --dist loadfile: each test file runs whole on one worker, so that its module-scoped
# fixtures (the report's documents), the compilations its tests share (the integrator's
# tests, MJX's scans) and its imports are done once, not once per worker;
# --no-loadscope-reorder: the files are handed out in the order tests/schedule.py gives
# them (pool-starting files before JAX's, then the longest first).
TEST_WORKERS ?= auto
test: setup
	$(BIN)/python -m pytest -n $(TEST_WORKERS) --dist loadfile \
		--no-loadscope-reorder

test-slow: setup
	$(BIN)/python -m pytest -m slow

lint: $(STAMP_ALL)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

bench: setup
	$(BIN)/python benchmarks/reference_speed.py

# every figure the README and docs/api.md quote, re-measured and written between their
# markers (tests/test_docs_figures.py checks the README's copies against the code)
docs-figures: $(STAMP) $(AOT)
	$(BIN)/python scripts/docs_figures.py

figures: $(STAMP)
	$(BIN)/harness figures --out out/figures --force

# Headless Chromium, which tests/test_report.py uses to open a report the way a person
# does (the test is skipped without it).  Debian/Ubuntu package, installed as root.
browser:
	@command -v chromium >/dev/null 2>&1 || { apt-get update && apt-get install -y chromium; }

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache .cache build reference/core/_aot*
