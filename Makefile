# Each target bootstraps .venv (Python >= 3.12, all dependencies) when missing.
PY := .venv/bin/python
OUT ?= out

.PHONY: setup demo demo-printed test bench clean

setup:
	@bash scripts/bootstrap.sh

## The main job: the paper's nominal scene - static equilibrium, 10 s of drilling (summary.json,
## timeseries.h5, fields.xdmf, Figs. 14-19), then the modal analysis (Figs. 10-12, Table 4).
## T_END=1 make demo runs a short version.
T_END ?= 10.0
demo: setup
	$(PY) -m fenics_drill.cli run demos/scenes/paper.toml --set time.t_end=$(T_END) --out $(OUT)/nominal
	$(PY) -m fenics_drill.cli plot $(OUT)/nominal
	$(PY) -m fenics_drill.cli modal demos/scenes/paper.toml --out $(OUT)/paper
	$(PY) demos/modal_distributions.py --out $(OUT)/modal-distributions

## The paper's kinematics (14) as printed: the run that reproduces its shock packages (docs/verification.md).
demo-printed: setup
	$(PY) -m fenics_drill.cli run demos/scenes/paper.toml --set time.t_end=$(T_END) --set model.kinematics=printed --out $(OUT)/nominal-printed
	$(PY) -m fenics_drill.cli plot $(OUT)/nominal-printed

## The test suite (a few minutes on 2 cores).
test: setup
	$(PY) -m pytest -q tests

bench: setup
	$(PY) benchmarks/modal_timing.py
	$(PY) benchmarks/dynamics_convergence.py

clean:
	rm -rf $(OUT) .pytest_cache
