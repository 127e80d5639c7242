# Tessera: `make demo` (the main job) and `make test` (every tier). Both set up .venv first.
PY := .venv/bin/python
# Keep Blender's user folder and caches out of $HOME for the demo and the build.
export BLENDER_USER_RESOURCES ?= $(CURDIR)/out/.blender_user
export XDG_CACHE_HOME ?= $(CURDIR)/out/.cache

.PHONY: setup demo test lint build bench clean

setup:
	@bash tools/setup.sh

demo: setup
	$(PY) samples/demo.py

lint: setup
	$(PY) -m ruff check .

test: setup
	$(PY) -m ruff check .
	$(PY) -m pytest

build: setup
	$(PY) tools/build_extension.py

bench: setup
	@for f in bench/*.py; do $(PY) $$f || exit 1; done

clean:
	rm -rf out dist wheels .pytest_cache .ruff_cache
