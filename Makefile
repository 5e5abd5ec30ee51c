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

.PHONY: setup demo test test-slow lint bench figures browser clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), sys.version' || { echo "need Python >= 3.11 (make PYTHON=/path/to/python3.11)"; exit 2; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e .
	touch $(STAMP)

# every extra ([all]: drake, dart, mjx, dask) and the dev tools
$(STAMP_ALL): $(STAMP)
	$(BIN)/pip install --quiet -e '.[all,dev]'
	touch $(STAMP_ALL)

$(AOT): $(STAMP) $(CORE)
	$(BIN)/python -m reference.core.aot
	touch $(AOT)

setup: $(STAMP_ALL) $(AOT)

# Main job: the reference against both tuned engines on the built-in chatter scene,
# with a rerun recording of all three side by side (--force: the demo's own recording is
# replaced when the demo runs again).
demo: $(STAMP) $(AOT)
	$(BIN)/harness compare triangle-chatter --engine mujoco --engine pybullet --engine linear \
		--record recordings/triangle-chatter.rrd --force

# every engine's tests; an engine whose extra is missing has its tests skipped with the
# reason, and under CI=true (.ci/run) such a skip fails the run (tests/conftest.py)
test: $(STAMP_ALL) $(AOT)
	$(BIN)/python -m pytest

test-slow: $(STAMP_ALL) $(AOT)
	$(BIN)/python -m pytest -m slow

lint: $(STAMP_ALL)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

bench: $(STAMP_ALL) $(AOT)
	$(BIN)/python benchmarks/reference_speed.py

figures: $(STAMP)
	$(BIN)/harness figures --out out/figures --force

# Headless Chromium, which tests/test_report.py uses to open a report the way a person
# does (the test is skipped without it).  Debian/Ubuntu package, installed as root.
browser:
	@command -v chromium >/dev/null 2>&1 || { apt-get update && apt-get install -y chromium; }

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache build reference/core/_aot*
