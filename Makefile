# Each target bootstraps .venv (Python >= 3.12, all dependencies) when missing.
PY := .venv/bin/python
OUT ?= out

.PHONY: setup demo test modal-figures bench clean

setup:
	@bash scripts/bootstrap.sh

## The main job: the paper's nominal scene (modal analysis, reduced basis, Figs. 10-12, Table 4).
demo: setup
	$(PY) -m fenics_drill.cli modal demos/scenes/paper.toml --out $(OUT)/paper
	$(PY) demos/modal_distributions.py --out $(OUT)/modal-distributions

## The test suite (a few minutes on 2 cores).
test: setup
	$(PY) -m pytest -q tests

bench: setup
	$(PY) benchmarks/modal_timing.py

clean:
	rm -rf $(OUT) .pytest_cache
