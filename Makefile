# Two entry points (see README): `make demo` and `make test`.
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
# what is installed: the core (the demo's needs: reference, harness, MuJoCo, PyBullet) and,
# for the tests, every engine's extra with the dev tools (pyproject.toml; README "Install
# sizes")
STAMP  := $(VENV)/.installed
STAMP_ALL := $(VENV)/.installed-all
# the reference's compiled core, built ahead of time by the package's own build step
# (setup.py, during `pip install -e`; skipped without a C compiler: it is then compiled just
# in time on first use); `python -m reference.core.aot` rebuilds it when its sources
# change and does nothing when it is fresh
AOT    := $(VENV)/.aot
CORE   := $(wildcard reference/core/*.py)

.PHONY: setup demo test test-slow lint bench figures docs-figures browser clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), sys.version' || { echo "need Python >= 3.11 (make PYTHON=/path/to/python3.11)"; exit 2; }
	@echo "set-up 1/4: a virtual environment in $(VENV) (Python: $(PYTHON))"
	$(PYTHON) -m venv $(VENV)
	@echo "set-up 2/4: pip, then the package and its core dependencies (numpy, numba, MuJoCo,"
	@echo "  PyBullet, rerun, ...; the package's build compiles the reference's core, about 80 s)"
	$(BIN)/pip install --progress-bar off --upgrade pip
	$(BIN)/pip install --progress-bar off -e .
	touch $(STAMP)

# every extra ([all]: drake, dart, mjx, dask) and the dev tools
$(STAMP_ALL): $(STAMP)
	@echo "set-up 3/4: every extra (Drake, DART, MJX, dask) and the dev tools (2.5 GB in all)"
	$(BIN)/pip install --progress-bar off -e '.[all,dev]'
	touch $(STAMP_ALL)

$(AOT): $(STAMP) $(CORE)
	@echo "set-up 4/4: the reference's compiled core, rebuilt if its sources changed"
	$(BIN)/python -m reference.core.aot
	touch $(AOT)

setup: $(STAMP_ALL) $(AOT)

# Main job: the reference against both tuned engines on the built-in chatter scene,
# with a rerun recording of all three side by side (--force: the demo's own recording is
# replaced when the demo runs again).
demo: $(STAMP) $(AOT)
	$(BIN)/harness compare triangle-chatter --engine mujoco --engine pybullet --engine linear \
		--record recordings/triangle-chatter.rrd --force

# every engine's tests, on every core (pytest-xdist; TEST_WORKERS=1: one process); an
# engine whose extra is missing has its tests skipped with the reason, and under CI=true
# (.ci/run) such a skip fails the run (tests/conftest.py)
TEST_WORKERS ?= auto
test: $(STAMP_ALL) $(AOT)
	$(BIN)/python -m pytest -n $(TEST_WORKERS)

test-slow: $(STAMP_ALL) $(AOT)
	$(BIN)/python -m pytest -m slow

lint: $(STAMP_ALL)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

bench: $(STAMP_ALL) $(AOT)
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
	rm -rf $(VENV) .pytest_cache .ruff_cache build reference/core/_aot*
