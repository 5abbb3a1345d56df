# kinestat: every set-up step lives here. `make run` and `make test` build the
# virtual environment themselves from the pinned requirements files.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
RUN_STAMP := $(VENV)/.run-installed
DEV_STAMP := $(VENV)/.dev-installed
BENCH_STAMP := $(VENV)/.bench-installed

.PHONY: run test lint bench startup clean browser vendor-three docs release

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip

$(RUN_STAMP): $(BIN)/python requirements/run.txt pyproject.toml
	$(BIN)/pip install -q -r requirements/run.txt
	$(BIN)/pip install -q --no-deps -e .
	$(BIN)/kinestat warmup
	touch $@

# The tests use every kernel group: compile them once here, not in each test worker.
$(DEV_STAMP): $(RUN_STAMP) requirements/dev.txt requirements/docs.txt
	$(BIN)/pip install -q -r requirements/dev.txt
	$(BIN)/kinestat warmup --all >/dev/null
	touch $@

# The main job, on the embedded defaults. The kernels it runs compile once, at install
# (kinestat warmup), or here when the cache is cold (the warm-up is quick when they are cached);
# another command compiles what it uses on first use and says so.
run: $(RUN_STAMP)
	$(BIN)/kinestat warmup >/dev/null
	$(BIN)/kinestat control

# Headless Chromium for the viewer's browser tests (tests/viz/test_browser.py): the Debian
# package `chromium`, installed with apt-get when it is missing and we are root. Otherwise the
# browser tests skip and say why (set KINESTAT_BROWSER to use another Chromium/Chrome).
browser:
	@if [ -n "$$KINESTAT_BROWSER" ] || command -v chromium >/dev/null 2>&1 \
	    || command -v chromium-browser >/dev/null 2>&1 || command -v google-chrome >/dev/null 2>&1; then \
	  :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "make browser: installing chromium (apt-get)"; \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	    || echo "make browser: chromium could not be installed; the browser tests will skip"; \
	else \
	  echo "make browser: no chromium and not root (or no apt-get); the browser tests will skip"; \
	fi

# Re-vendor three.js into kinestat/data/viewer/ (needs node/npm; see docs/viewer.md).
THREE_VERSION ?= 0.187.0
ESBUILD_VERSION ?= 0.28.2
vendor-three:
	rm -rf build/three && mkdir -p build/three
	cd build/three && npm install --no-save --silent three@$(THREE_VERSION) esbuild@$(ESBUILD_VERSION) \
	  && printf "export * from 'three';\nexport { OrbitControls } from 'three/addons/controls/OrbitControls.js';\nexport { TransformControls } from 'three/addons/controls/TransformControls.js';\nexport { STLLoader } from 'three/addons/loaders/STLLoader.js';\nexport { ColladaLoader } from 'three/addons/loaders/ColladaLoader.js';\nexport { OBJLoader } from 'three/addons/loaders/OBJLoader.js';\n" > entry.js \
	  && node_modules/.bin/esbuild entry.js --bundle --minify --format=iife --global-name=THREE \
	       --legal-comments=none --outfile=../../kinestat/data/viewer/vendor/three.min.js
	cp build/three/node_modules/three/LICENSE kinestat/data/viewer/vendor/LICENSE-three.txt

# The whole test suite: lint, the layer contract (.importlinter, docs/architecture.md), the
# docs site built with --strict (any warning, broken page link or anchor fails), then pytest
# (which fails when no test runs; it runs every module's doctests and the tutorials too).
test: $(DEV_STAMP) browser
	$(BIN)/ruff check kinestat tests $(wildcard benchmarks scripts)
	$(BIN)/lint-imports
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet
	$(BIN)/pytest

# The documentation site (MkDocs + Material + mkdocstrings) into build/site; open
# build/site/index.html, or `.venv/bin/mkdocs serve` to preview while editing.
docs: $(DEV_STAMP)
	$(BIN)/python scripts/api_pages.py
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

# The release: sdist and wheel in build/release/dist, installed into a fresh venv and
# smoke-tested (CI runs this after make test).
release: $(DEV_STAMP)
	bash scripts/wheel_smoke.sh

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
	$(BIN)/ruff check kinestat tests $(wildcard benchmarks scripts)

clean:
	rm -rf $(VENV) build *.egg-info
