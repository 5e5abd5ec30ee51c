# Two entry points (see README): `make demo` and `make test`.
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: setup demo test test-slow lint bench figures clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), sys.version' || { echo "need Python >= 3.11 (make PYTHON=/path/to/python3.11)"; exit 2; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[dev]'
	touch $(STAMP)

setup: $(STAMP)

# Main job: the reference against both tuned engines on the built-in chatter scene,
# with a rerun recording of all three side by side.
demo: $(STAMP)
	$(BIN)/harness compare triangle-chatter --engine mujoco --engine pybullet --engine linear \
		--record recordings/triangle-chatter.rrd

test: $(STAMP)
	$(BIN)/python -m pytest

test-slow: $(STAMP)
	$(BIN)/python -m pytest -m slow

lint: $(STAMP)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

bench: $(STAMP)
	$(BIN)/python benchmarks/reference_speed.py

figures: $(STAMP)
	$(BIN)/harness figures --out out/figures

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache
