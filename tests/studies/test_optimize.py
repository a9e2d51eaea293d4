"""Drilling optimisation: the grid is made of ordinary runs, the chance constraint is
its definition, an infeasible window says so, and the robust mode averages its realisations."""

import json

import numpy as np
import pytest

from fenics_drill.cli import main
from fenics_drill.studies.operating_window import chance_constraint

TINY = ["--set", "beam.length=10.0", "--set", "beam.elements=10", "--set", "time.t_end=0.05",
        "--set", "output.field_interval=0", "--set", "reduction.rule='count'", "--set", "reduction.flexural=6",
        "--set", "reduction.torsional=2", "--set", "reduction.axial=2"]
#: The grid points and separate runs are one and the same model only without the element sample: a window
#: trains it once on the scene's own drive, a separate run on the grid point's (1e-5 apart on rop here).
EXACT = ["--set", "reduction.hyper=false"]
WINDOW = ["--set", "optimize.axial_velocity=[0.003, 0.006, 2]", "--set", "optimize.rotation_speed=[5.0, 5.0, 1]"]


@pytest.fixture(scope="module")
def window(tmp_path_factory):
    out = tmp_path_factory.mktemp("window")
    assert main(["optimize", *TINY, *EXACT, *WINDOW, "--quiet", "--out", str(out)]) == 0
    return out, json.loads((out / "optimize.json").read_text())


def test_grid_values_are_those_of_separate_runs(window, tmp_path):
    out, report = window
    for i, v0 in enumerate(report["axial_velocity"]):
        run_dir = tmp_path / f"run{i}"
        assert main(["run", *TINY, *EXACT, "--set", f"drive.axial_velocity={v0}", "--set", "drive.rotation_speed=5.0",
                     "--quiet", "--out", str(run_dir)]) == 0
        summary = json.loads((run_dir / "summary.json").read_text())
        for key in ("rop", "efficiency", "efficiency_torque_magnitude", "signed_rop"):
            assert report[key][i][0] == pytest.approx(summary[key], rel=1e-12), key
        assert report["max_von_mises"][i][0] == pytest.approx(summary["max_von_mises"]["value"], rel=1e-12)


def test_deterministic_optimum_is_the_best_admissible_grid_point(window):
    _, report = window
    rop = np.array(report["rop"])
    assert report["feasible"] and np.all(report["admissible"])
    assert report["optimum"]["objective"] == pytest.approx(rop.max())
    assert report["optimum"]["axial_velocity"] == report["axial_velocity"][int(np.argmax(rop[:, 0]))]


def test_chance_constraint_is_the_fraction_of_realisations_within_the_strength():
    stresses = np.arange(1, 11) * 1e8  # 6 of the 10 are <= 650 MPa
    assert chance_constraint(stresses, 650e6, risk=0.1) == (pytest.approx(0.6), False)
    assert chance_constraint(stresses, 650e6, risk=0.5) == (pytest.approx(0.6), True)
    assert chance_constraint(stresses, 1e10, risk=0.01) == (pytest.approx(1.0), True)


def test_an_infeasible_window_is_reported_as_such(tmp_path, capsys):
    assert main(["optimize", *TINY, *WINDOW, "--set", "optimize.ultimate_strength=1.0", "--quiet",
                 "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "optimize.json").read_text())
    assert report["feasible"] is False and report["optimum"] is None
    assert not any(np.ravel(report["admissible"]))
    assert "infeasible" in capsys.readouterr().out


def test_robust_mode_averages_its_realisations_and_estimates_the_constraint(tmp_path):
    robust = ["--set", "optimize.samples=3", "--set", "uncertainty.limit_force_dispersion=0.3"]
    assert main(["optimize", *TINY, *WINDOW, *robust, "--quiet", "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "optimize.json").read_text())
    draws = [json.loads((tmp_path / "points" / f"0001_{k:04d}.json").read_text()) for k in range(3)]
    assert report["rop"][1][0] == pytest.approx(np.mean([d["rop"] for d in draws]), rel=1e-14)
    # the same three bit-rock draws at every point (common random numbers)
    first = [json.loads((tmp_path / "points" / f"0000_{k:04d}.json").read_text())["bit_rock"] for k in range(3)]
    assert first == [d["bit_rock"] for d in draws]
    assert report["constraint_probability"][1][0] == 1.0 and report["feasible"]
    assert main(["plot", str(tmp_path)]) == 0
    assert (tmp_path / "fig36_rop_map.png").exists()
