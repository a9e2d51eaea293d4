# Each target bootstraps .venv (Python >= 3.12, all dependencies) when missing.
PY := .venv/bin/python
OUT ?= out

.PHONY: setup docs demo demo-printed demo-as-printed reproduction test bench bench-ross campbell wells drilling drill-vbh risk mc optimize stick-slip well-maps clean

setup:
	@bash scripts/bootstrap.sh

## The main job: the paper's nominal scene - static equilibrium, 10 s of drilling (summary.json,
## timeseries.h5, fields.xdmf, Figs. 13-23, spectra.json, animation.gif), then the modal analysis (Figs. 10-12, Table 4).
## T_END=1 make demo runs a short version.
T_END ?= 10.0
demo: setup
	$(PY) -m fenics_drill.cli run demos/scenes/paper.toml --set time.t_end=$(T_END) --overwrite --out $(OUT)/nominal
	$(PY) -m fenics_drill.cli plot $(OUT)/nominal
	$(PY) -m fenics_drill.cli modal demos/scenes/paper.toml --overwrite --out $(OUT)/paper
	$(PY) demos/modal_distributions.py --out $(OUT)/modal-distributions

## The paper's kinematics (14) as printed, with its friction laws (18)-(19): the reduced run that reproduces its
## shock packages (docs/reproduction.md).
demo-printed: setup
	$(PY) -m fenics_drill.cli run demos/scenes/paper.toml --set time.t_end=$(T_END) --set model.kinematics=printed \
		--set contact.friction_model=paper --set contact.sliding_velocity_scale=1e-3 --overwrite --out $(OUT)/nominal-printed
	$(PY) -m fenics_drill.cli plot $(OUT)/nominal-printed

## Every law as printed (kinematics (14), friction (18)-(19), bit torque (21)): the paper's Figs. 14-23 as
## published (demos/scenes/paper_as_printed.toml; docs/errata.md says why these laws are not the default).
## Over the full 10 s the as-printed model runs away after about 8 s (docs/reproduction.md): T_END=3 shows
## the published phenomena before it.
demo-as-printed: setup
	$(PY) -m fenics_drill.cli run demos/scenes/paper_as_printed.toml --set time.t_end=$(T_END) --overwrite --out $(OUT)/as-printed
	$(PY) -m fenics_drill.cli plot $(OUT)/as-printed

## Section 6 as printed and consistent, side by side (docs/reproduction.md): the nominal runs, the three
## windows and a Monte Carlo of each model on RANKS processes (about 50 min on 2 ranks, measured at the paper's
## step; the consistent model now runs at the finer default step, 2.2x the nominal scene's cost); resumes where it stopped.
reproduction: setup
	$(PY) benchmarks/reproduction.py --ranks $(RANKS)

## The test suite (617 tests on 2 cores, AMD EPYC, Python 3.13: pytest reported 443 s).
test: setup
	$(PY) -m pytest -q tests

## The manual into docs/_build/html: warnings (a broken internal link, a bad reference) are errors, the
## gallery's scripts run (about 2 minutes), and the equations render offline (MathJax shipped with the site).
docs: setup
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html
	@# the equations render offline: MathJax is served from the site itself, no page asks a CDN for it
	@test -f docs/_build/html/_static/mathjax/tex-chtml.js
	@! grep -l "cdn.jsdelivr.net/npm/mathjax" docs/_build/html/*.html docs/_build/html/*/*.html

## Speed against an older revision (benchmarks/results/speed.md, about 5 min), the cost of each part of an evaluation,
## the reduced models against the full order (benchmarks/results/reduced_accuracy.md), then the fidelity studies
## (benchmarks/README.md lists every script).
bench: setup
	$(PY) benchmarks/speed.py --workers 1
	$(PY) benchmarks/speed_table.py --before 50d35ac
	$(PY) benchmarks/evaluation_costs.py
	$(PY) benchmarks/reduced_accuracy.py --t-end 2 --runs $(OUT)/accuracy
	$(PY) benchmarks/modal_timing.py
	$(PY) benchmarks/tradeoff.py demos/scenes/paper.toml --t-end 0.5

## Campbell diagram against ROSS (benchmarks/results/campbell_ross.md).  ROSS lives in its own .venv-ross: its
## dependencies (CoolProp, pyarrow, ...) are not the project's, and once installed beside DOLFINx they broke
## h5py's import here (measured: "ValueError: Not a datatype").
bench-ross: setup
	@test -x .venv-ross/bin/python || ($$(head -1 .venv/pyvenv.cfg | sed 's/home = //')/python3 -m venv .venv-ross \
		&& .venv-ross/bin/pip install -q ross-rotordynamics==3.1.0)
	$(PY) benchmarks/campbell_ross.py --ross-python .venv-ross/bin/python --elements 200 --rounds 2

## Critical speeds of the paper's string on the wall, without and with the weight on bit (docs/guide/campbell.md).
campbell: setup
	$(PY) -m fenics_drill.cli campbell demos/scenes/campbell_paper.toml --overwrite --out $(OUT)/campbell
	$(PY) -m fenics_drill.cli campbell demos/scenes/campbell_paper.toml --set campbell.weight_on_bit=true \
		--overwrite --out $(OUT)/campbell-wob

## The two demo wells (docs/wells.md): soft-string torque and drag, buckling, figures; the manual's copies of the
## figures, the convergence-and-cost table (benchmarks/results/torque_drag_wells.md) and the FE string at rest against
## the soft string (benchmarks/results/fe_wells.md, a few minutes).
wells: setup
	$(PY) -m fenics_drill.cli torque-drag demos/scenes/well_vbh.toml --overwrite --out $(OUT)/well-vbh
	$(PY) -m fenics_drill.cli torque-drag demos/scenes/well_3d.toml --overwrite --out $(OUT)/well-3d
	for w in vbh 3d; do for f in well_loads well_path well_3d; do cp $(OUT)/well-$$w/$$f.png docs/figures/$${f}_$$w.png; done; done
	$(PY) -m fenics_drill.cli static demos/scenes/well_vbh.toml --set beam.elements=1000 --overwrite --out $(OUT)/well-vbh-static
	cp $(OUT)/well-vbh-static/static_loads.png docs/figures/static_loads_vbh.png
	$(PY) benchmarks/torque_drag_wells.py
	$(PY) benchmarks/fe_wells.py

## Drilling your well (docs/drilling.md): the build-and-hold demo well from its survey to a stick-slip run on bottom,
## each command of the page, and the page's figures copied into docs/figures (about 5 minutes).
drilling: setup
	$(PY) -m fenics_drill.cli scene demos/scenes/well_build_hold.toml > /dev/null
	$(PY) -m fenics_drill.cli torque-drag demos/scenes/well_build_hold.toml --overwrite --out $(OUT)/bh-td
	$(PY) -m fenics_drill.cli static demos/scenes/well_build_hold.toml --overwrite --out $(OUT)/bh-static
	$(PY) -m fenics_drill.cli modal demos/scenes/well_build_hold.toml --overwrite --out $(OUT)/bh-modal
	$(PY) -m fenics_drill.cli run demos/scenes/well_build_hold.toml --overwrite --out $(OUT)/bh-run
	$(PY) -m fenics_drill.cli plot $(OUT)/bh-run --no-gif
	cp $(OUT)/bh-static/static_loads.png docs/figures/drilling_static_loads.png
	cp $(OUT)/bh-modal/modes.png docs/figures/drilling_modes.png
	cp $(OUT)/bh-run/fig15_bit_rotation.png docs/figures/drilling_bit_rotation.png
	cp $(OUT)/bh-run/torque_drag.png docs/figures/drilling_torque_drag.png
	cp $(OUT)/bh-run/fig16b_orbit.png docs/figures/drilling_orbit.png

## Torque and drag as the rig uses it (docs/torque_drag_practice.md): the VBH well's broomstick chart, its friction
## factors calibrated from the synthetic measured file, and 1000 realisations of friction and survey uncertainty on
## RANKS processes; the page's figures copied into docs/figures.
risk: setup
	$(PY) -m fenics_drill.cli broomstick demos/scenes/well_vbh.toml --overwrite --out $(OUT)/vbh-chart
	$(PY) -m fenics_drill.cli calibrate demos/scenes/well_vbh.toml demos/scenes/well_vbh_measured.csv --overwrite \
		--out $(OUT)/vbh-calibration
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli torque-drag demos/scenes/well_vbh.toml --samples 1000 \
		--set "risk.survey_error='ISCWSA MWD Rev5.11'" --set risk.tortuosity_amplitude=0.5 --overwrite --out $(OUT)/vbh-risk
	cp $(OUT)/vbh-chart/broomstick.png docs/figures/broomstick_vbh.png
	cp $(OUT)/vbh-calibration/calibration.png docs/figures/calibration_vbh.png
	cp $(OUT)/vbh-risk/risk.png docs/figures/risk_vbh.png

## Drilling the 3 km VBH demo well for VBH_SECONDS (default 60) on 2000 elements from the string at rest off bottom
## (the run docs/wells.md shows), the full order: its
## bit speed, the whirl orbit at the BHA, the hook load and the surface torque (docs/wells.md gives its cost).
VBH_SECONDS ?= 60
drill-vbh: setup
	$(PY) -m fenics_drill.cli run demos/scenes/well_vbh.toml --set beam.elements=2000 --set time.t_end=$(VBH_SECONDS) \
		--set drive.start=off_bottom --out $(OUT)/vbh-drilling --overwrite
	$(PY) -m fenics_drill.cli plot $(OUT)/vbh-drilling --no-gif
	cp $(OUT)/vbh-drilling/fig15_bit_rotation.png docs/figures/vbh_drilling_bit_rotation.png
	cp $(OUT)/vbh-drilling/fig16b_orbit.png docs/figures/vbh_drilling_orbit.png
	cp $(OUT)/vbh-drilling/torque_drag.png docs/figures/vbh_drilling_torque_drag.png
	cp $(OUT)/vbh-drilling/surface_loads.png docs/figures/vbh_drilling_surface_loads.png

## The paper's Monte Carlo study (Section 6.11) at SAMPLES realisations on RANKS processes (with the default Coulomb
## friction each realisation of 10 s runs the full order: 8 took 327 s on 2 ranks here, docs/performance.md).
SAMPLES ?= 32
RANKS ?= 2
## A study's directory is continued (--resume) when an earlier run of it left its summary there, and started
## afresh otherwise (the command refuses --resume of a directory that holds no study).
resume = $(if $(wildcard $(1)/summary.json),--resume,)
mc: setup
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli mc demos/scenes/paper.toml --samples $(SAMPLES) --out $(OUT)/mc $(call resume,$(OUT)/mc)
	$(PY) -m fenics_drill.cli plot $(OUT)/mc

## The paper's operating windows (Sections 6.9, 6.10, 6.12) at the resolution of demos/scenes/window*.toml.
optimize: setup
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli optimize demos/scenes/window_rop.toml --out $(OUT)/window-rop $(call resume,$(OUT)/window-rop)
	$(PY) -m fenics_drill.cli plot $(OUT)/window-rop
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli optimize demos/scenes/window_efficiency.toml --out $(OUT)/window-efficiency $(call resume,$(OUT)/window-efficiency)
	$(PY) -m fenics_drill.cli plot $(OUT)/window-efficiency
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli optimize demos/scenes/window_robust.toml --out $(OUT)/window-robust $(call resume,$(OUT)/window-robust)
	$(PY) -m fenics_drill.cli plot $(OUT)/window-robust

## Stick-slip maps of the paper's string with the cutting law, stiff drive and soft-torque top drive
## (docs/guide/drilling_control.md), and the linear stability of steady drilling.
stick-slip: setup
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli optimize demos/scenes/stick_slip_map.toml --out $(OUT)/stick-slip-stiff $(call resume,$(OUT)/stick-slip-stiff)
	$(PY) -m fenics_drill.cli plot $(OUT)/stick-slip-stiff
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli optimize demos/scenes/stick_slip_map_soft_torque.toml --out $(OUT)/stick-slip-soft $(call resume,$(OUT)/stick-slip-soft)
	$(PY) -m fenics_drill.cli plot $(OUT)/stick-slip-soft
	$(PY) benchmarks/stick_slip_table.py $(OUT)/stick-slip-stiff $(OUT)/stick-slip-soft
	$(PY) benchmarks/stick_slip_stability.py

## Stick-slip maps of the demo wells on their axial-torsional strings (docs/guide/stick_slip_maps.md): weight on bit x
## rotation speed, 8 x 8 points, the stiff drive and the soft-torque top drive, each point to its limit cycle or 200 s,
## on RANKS processes; the figures copied into docs/figures.
WELL_MAP = --set drive.mode=\'hook_load\' --set bit_rock.law=\'detournay\' --set "bit_rock.bit_radius='4.25 in'" \
	--set "stick_slip_map.weight_on_bit=['20 kN', '90 kN', 8]" --set "stick_slip_map.rotation_speed=['40 rpm', '180 rpm', 8]" \
	--set "stick_slip_map.controllers=['stiff', 'soft_torque']"
well-maps: setup
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli stick-slip-map demos/scenes/well_vbh.toml $(WELL_MAP) \
		--overwrite --out $(OUT)/vbh-map
	.venv/bin/mpiexec -n $(RANKS) $(PY) -m fenics_drill.cli stick-slip-map demos/scenes/well_build_hold.toml $(WELL_MAP) \
		--overwrite --out $(OUT)/build-hold-map
	cp $(OUT)/vbh-map/stick_slip_map.png docs/figures/stick_slip_map_vbh.png
	cp $(OUT)/build-hold-map/stick_slip_map.png docs/figures/stick_slip_map_build_hold.png

clean:
	rm -rf $(OUT) .pytest_cache docs/_build docs/gallery docs/reference/api.md docs/reference/scene_keys.md
