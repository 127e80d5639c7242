# Tessera: `make demo` (the main job), `make test` (every tier, on the newest Blender this machine's Pythons run)
# and `make test-all` (every tier on each supported Blender: 4.2, 4.5, 5.0, 5.1, 5.2). Each sets up its venvs.
PY := .venv/bin/python
# Keep Blender's user folder and caches out of $HOME for the demo and the build.
export BLENDER_USER_RESOURCES ?= $(CURDIR)/out/.blender_user
export XDG_CACHE_HOME ?= $(CURDIR)/out/.cache

.PHONY: setup demo test test-all lint build bench clean

setup:
	@bash tools/setup.sh

demo: setup
	$(PY) samples/demo.py

lint: setup
	$(PY) -m ruff check .

test: setup
	$(PY) -m ruff check .
	$(PY) -m pytest
	TESSERA_GPU_BACKEND=VULKAN $(PY) -m pytest -q -m gpu

test-all:
	@bash tools/matrix.sh

build: setup
	$(PY) tools/build_extension.py

bench: setup
	$(PY) -m pip install -q -r requirements/bench.txt
	$(PY) tools/bench_report.py --run

clean:
	rm -rf out dist wheels .pytest_cache .ruff_cache
