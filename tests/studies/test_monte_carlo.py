"""Uncertainty quantification: the laws of Section 5, and a Monte Carlo study that does
not depend on the number of MPI ranks and survives being killed."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import scene_with

from fenics_drill.cli import main
from fenics_drill.studies.statistics import convergence_metric
from fenics_drill.scene import SceneError
from fenics_drill.studies.uncertainty import BitRockLaws, InadmissibleLaw, beta_law, gamma_law

TINY = ["--set", "beam.length=10.0", "--set", "beam.elements=10", "--set", "time.t_end=0.05",
        "--set", "output.field_interval=0", "--set", "reduction.rule='count'", "--set", "reduction.flexural=6",
        "--set", "reduction.torsional=2", "--set", "reduction.axial=2",
        "--set", "uncertainty.output_interval=0.005", "--set", "uncertainty.rate_dispersion=0.2",
        "--set", "uncertainty.limit_force_dispersion=0.2", "--set", "uncertainty.friction_dispersion=0.2"]
SAMPLES = 6
MPIEXEC = Path(sys.executable).parent / "mpiexec"


def test_gamma_and_beta_laws_have_the_requested_mean_and_dispersion_exactly():
    """(81), (86): shape 1/delta^2, scale m delta^2; (90)-(92): beta with a, b from m, delta."""
    for law, m, d in ((gamma_law(400.0, 0.3, "a"), 400.0, 0.3), (gamma_law(3e4, 0.01, "g"), 3e4, 0.01),
                      (beta_law(0.4, 0.3, "mu"), 0.4, 0.3), (beta_law(0.4, 0.005, "mu"), 0.4, 0.005)):
        assert law.mean() == pytest.approx(m, rel=1e-12)
        assert law.std() / law.mean() == pytest.approx(d, rel=1e-10)


def test_sampled_parameters_match_their_laws_within_monte_carlo_error_and_respect_supports():
    n = 4000
    scene = scene_with("bit_rock.rate=400.0", "bit_rock.limit_force=3e4", "bit_rock.friction=0.4",
                       "uncertainty.rate_dispersion=0.3", "uncertainty.limit_force_dispersion=0.2",
                       "uncertainty.friction_dispersion=0.5", "uncertainty.seed=7")
    laws = BitRockLaws(scene.bit_rock, scene.uncertainty)
    draws = [laws.sample(k) for k in range(n)]
    for key, mean, dispersion in (("rate", 400.0, 0.3), ("limit_force", 3e4, 0.2), ("friction", 0.4, 0.5)):
        x = np.array([d[key] for d in draws])
        sigma = dispersion * mean
        assert abs(x.mean() - mean) < 4 * sigma / np.sqrt(n)  # 4 standard errors of the mean
        # the standard error of a sample deviation is sigma sqrt((kurtosis - 1) / 4n) <= sigma * 2.5/sqrt(n) here
        assert abs(x.std() - sigma) < 4 * 2.5 * sigma / np.sqrt(n)
        assert x.min() > 0
    assert max(d["friction"] for d in draws) < 1
    assert laws.sample(11) == laws.sample(11)  # realisation k is reproducible on its own


@pytest.mark.parametrize("override, where", [
    ("uncertainty.rate_dispersion=0.71", "uncertainty.rate_dispersion"),
    ("uncertainty.limit_force_dispersion=-0.1", "uncertainty.limit_force_dispersion"),
])
def test_inadmissible_gamma_dispersions_are_refused_when_the_scene_is_read(override, where):
    with pytest.raises(SceneError, match=where):
        scene_with(override)


def test_inadmissible_beta_laws_are_refused_before_computing(tmp_path, capsys):
    with pytest.raises(InadmissibleLaw, match="sqrt"):
        beta_law(0.4, 1.3, "bit_rock.friction")
    assert main(["mc", *TINY, "--set", "bit_rock.friction=0.0", "--samples", "2", "--out", str(tmp_path)]) == 2
    assert "bit_rock.friction" in capsys.readouterr().err
    assert not (tmp_path / "realisations").exists()


def _mc(out: Path, *extra: str, ranks: int = 1) -> subprocess.Popen:
    command = [sys.executable, "-m", "fenics_drill.cli", "mc", *TINY, "--samples", str(SAMPLES), "--quiet",
               "--out", str(out), *extra]
    if ranks > 1:
        command = [str(MPIEXEC), "-n", str(ranks), *command]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)


def _statistics(out: Path) -> dict:
    data = {}
    with h5py.File(out / "statistics.h5", "r") as f:
        f.visititems(lambda name, obj: data.update({name: obj[()]}) if isinstance(obj, h5py.Dataset) else None)
    return data


@pytest.fixture(scope="module")
def serial_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("mc_serial")
    process = _mc(out)
    assert process.wait(timeout=600) == 0, process.stderr.read().decode()
    return out


def test_serial_study_writes_statistics_and_the_summary(serial_study):
    summary = json.loads((serial_study / "summary.json").read_text())
    assert summary["realisations"] == SAMPLES and summary["failed"] == 0
    for key in ("rop", "efficiency"):
        assert set(summary[key]) == {"mean", "std", "p2.5", "p50", "p97.5"}
        assert summary[key]["p2.5"] <= summary[key]["p50"] <= summary[key]["p97.5"]
    stats = _statistics(serial_study)
    q = [h5py.File(p, "r").attrs["q_norm_integral"] for p in sorted((serial_study / "realisations").glob("*.h5"))]
    np.testing.assert_allclose(stats["convergence_metric"], convergence_metric(np.array(q)), rtol=1e-14)
    assert stats["convergence_metric"][-1] == pytest.approx(summary["convergence_metric"])
    env = stats["bit_velocity/p2.5"] <= stats["bit_velocity/p97.5"]
    assert env.all()
    # a KDE is a density: it integrates to 1 over its support (3 deviations of margin on each side)
    pdf = stats["pdf/rop/density"], stats["pdf/rop/points"]
    assert np.trapezoid(*pdf) == pytest.approx(1.0, abs=1e-2)
    assert main(["plot", str(serial_study)]) == 0
    for stem in ("fig28_convergence", "fig29_bit_axial_envelope", "fig30_pdf_bit_velocity_at_t_end",
                 "fig31_bit_rotation_envelope", "fig33_section_lateral_envelope", "fig34_pdf_efficiency",
                 "fig35_pdf_rop"):
        assert (serial_study / f"{stem}.png").stat().st_size > 10_000, stem


@pytest.mark.skipif(not MPIEXEC.exists(), reason="no mpiexec next to the interpreter")
def test_two_ranks_give_bit_identical_statistics(serial_study, tmp_path):
    process = _mc(tmp_path, ranks=2)
    assert process.wait(timeout=600) == 0, process.stderr.read().decode()
    serial, parallel = _statistics(serial_study), _statistics(tmp_path)
    assert serial.keys() == parallel.keys()
    for name in serial:
        assert np.array_equal(serial[name], parallel[name]), name


def test_a_killed_study_resumed_gives_the_statistics_of_an_uninterrupted_one(serial_study, tmp_path):
    process = _mc(tmp_path)
    deadline = time.time() + 300
    while len(list((tmp_path / "realisations").glob("*.h5"))) < 2 and time.time() < deadline:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    done = len(list((tmp_path / "realisations").glob("*.h5")))
    assert 2 <= done < SAMPLES, "the study finished before it could be killed"
    assert not (tmp_path / "statistics.h5").exists()
    again = _mc(tmp_path)
    assert again.wait(timeout=600) == 2  # without --resume an existing study is refused
    resumed = _mc(tmp_path, "--resume")
    assert resumed.wait(timeout=600) == 0, resumed.stderr.read().decode()
    serial, after = _statistics(serial_study), _statistics(tmp_path)
    for name in serial:
        assert np.array_equal(serial[name], after[name]), name


def test_a_realisation_without_the_energy_budget_drills_exactly_as_a_run_with_it():
    """A Monte Carlo realisation keeps no energy budget (none of its outputs reads it).  The budget only
    books the motion and never feeds back into it, so every history of the realisation equals, bit for
    bit, the same run with the budget kept, and that run's budget closes."""
    from fenics_drill.solvers.time_loop import Simulation
    from fenics_drill.studies.prepare import HISTORIES, RealisationRecorder, prepare, run_realisation

    scene = scene_with("beam.length=20.0", "beam.elements=40", "time.t_end=0.1", "output.field_interval=0",
                       "uncertainty.output_interval=0.005")
    prepared = prepare(scene)
    realisation = run_realisation(prepared, scene)
    simulation = Simulation(prepared.model, scene)  # the budget kept (the default)
    recorder = RealisationRecorder(prepared.model, scene)
    simulation.run(simulation.initial_state(prepared.equilibrium.q), scene.time.t_end, recorder)
    t = np.asarray(recorder.series["time"])
    assert realisation["steps"] == simulation.stats["steps"]
    for name in HISTORIES:
        np.testing.assert_array_equal(realisation["histories"][name],
                                      np.interp(realisation["time"], t, np.asarray(recorder.series[name])))
    assert np.isfinite(recorder.series["kinetic_energy"]).all()
    # the energy balance of the 20 m string over 0.1 s closes to 1e-2 of the energy exchanged, as the
    # budget tests of tests/solvers/test_dynamics.py require of such runs
    assert simulation.budget.balance_error < 1e-2
