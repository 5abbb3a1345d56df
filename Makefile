# kinestat: every set-up step lives here. `make run` and `make test` build the
# virtual environment themselves from the pinned requirements files.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
RUN_STAMP := $(VENV)/.run-installed
DEV_STAMP := $(VENV)/.dev-installed
BENCH_STAMP := $(VENV)/.bench-installed

.PHONY: run test lint bench startup clean

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip

$(RUN_STAMP): $(BIN)/python requirements/run.txt pyproject.toml
	$(BIN)/pip install -q -r requirements/run.txt
	$(BIN)/pip install -q --no-deps -e .
	$(BIN)/kinestat warmup
	touch $@

$(DEV_STAMP): $(RUN_STAMP) requirements/dev.txt
	$(BIN)/pip install -q -r requirements/dev.txt
	touch $@

# The main job, on the embedded defaults. Kernels compile once, at install (kinestat warmup),
# or here when the cache is cold (the warm-up is quick when they are cached).
run: $(RUN_STAMP)
	$(BIN)/kinestat warmup >/dev/null
	$(BIN)/kinestat control

# The whole test suite: lint, the layer contract (.importlinter, docs/architecture.md), then
# pytest (which fails when no test runs).
test: $(DEV_STAMP)
	$(BIN)/ruff check kinestat tests $(wildcard benchmarks)
	$(BIN)/lint-imports
	$(BIN)/pytest

$(BENCH_STAMP): $(DEV_STAMP) requirements/bench.txt
	$(BIN)/pip install -q -r requirements/bench.txt
	touch $@

# Side-by-side speed comparison with the peer libraries (prints a table; JSON with ARGS=--json).
bench: $(BENCH_STAMP)
	$(BIN)/python benchmarks/bench.py $(ARGS)

# Start-up time side by side (import numpy / import kinestat / kinestat --help / a command).
startup: $(RUN_STAMP)
	$(BIN)/python benchmarks/startup.py $(ARGS)

lint: $(DEV_STAMP)
	$(BIN)/ruff check kinestat tests $(wildcard benchmarks)

clean:
	rm -rf $(VENV) build *.egg-info
