# Two entry points (see README): `make demo` and `make test`.
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# the reference's compiled core, built ahead of time by the package's own build step
# (setup.py, during `pip install -e`; skipped without a C compiler: it is then compiled just
# in time on first use); `python -m reference.core.aot` rebuilds it when its sources
# change and does nothing when it is fresh
AOT    := $(VENV)/.aot
CORE   := $(wildcard reference/core/*.py)

.PHONY: setup demo test test-slow lint bench figures docs-figures browser clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), sys.version' || { echo "need Python >= 3.11 (make PYTHON=/path/to/python3.11)"; exit 2; }
	@echo "set-up 1/3: a virtual environment in $(VENV) (Python: $(PYTHON))"
	$(PYTHON) -m venv $(VENV)
	@echo "set-up 2/3: pip, then the package and its dependencies (about 2 GB: numpy, numba,"
	@echo "  MuJoCo, PyBullet, Drake, rerun, ...; a few minutes on a cold pip cache);"
	@echo "  the package's build compiles the reference's core (about 80 s)"
	$(BIN)/pip install --progress-bar off --upgrade pip
	$(BIN)/pip install --progress-bar off -e '.[dev]'
	touch $(STAMP)

$(AOT): $(STAMP) $(CORE)
	@echo "set-up 3/3: the reference's compiled core, rebuilt if its sources changed"
	$(BIN)/python -m reference.core.aot
	touch $(AOT)

setup: $(STAMP) $(AOT)

# Main job: the reference against both tuned engines on the built-in chatter scene,
# with a rerun recording of all three side by side (--force: the demo's own recording is
# replaced when the demo runs again).
demo: $(STAMP) $(AOT)
	$(BIN)/harness compare triangle-chatter --engine mujoco --engine pybullet --engine linear \
		--record recordings/triangle-chatter.rrd --force

# the default suite on every core (pytest-xdist; TEST_WORKERS=1 runs it in one process)
TEST_WORKERS ?= auto
test: $(STAMP) $(AOT)
	$(BIN)/python -m pytest -n $(TEST_WORKERS)

test-slow: $(STAMP) $(AOT)
	$(BIN)/python -m pytest -m slow

lint: $(STAMP)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

bench: $(STAMP) $(AOT)
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
