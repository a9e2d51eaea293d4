"""One run on two MPI ranks (fenics_drill/studies/shared_run.py, fenics_drill/model/kernels/split_band.py): the
split saddle solve against the one-rank banded solve, a two-rank run against the one-rank run, a Ctrl-C that stops
both ranks after the same step, and a refused third rank.  Every MPI process runs under a timeout."""

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
MPIEXEC = Path(sys.executable).parent / "mpiexec"
PAPER = ROOT / "demos" / "scenes" / "paper.toml"
FULL_ORDER = ["--set", "reduction.rule=none", "--set", "output.field_interval=0"]

# the mpi4py wheel that the bootstrap installs puts mpiexec beside the interpreter; an environment without it cannot
# start two ranks at all
pytestmark = pytest.mark.skipif(not MPIEXEC.exists(), reason="no mpiexec next to the interpreter")


def _run(out: Path, ranks: int, *settings: str) -> subprocess.Popen:
    command = [sys.executable, "-m", "fenics_drill.cli", "run", str(PAPER), *FULL_ORDER, *settings, "--quiet",
               "--out", str(out)]
    return subprocess.Popen([str(MPIEXEC), "-n", str(ranks), *command], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, start_new_session=True)


def _finished(process: subprocess.Popen, timeout: float) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``process``, killed if it outlives ``timeout`` seconds."""
    try:
        out, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        process.kill()
        raise
    return process.returncode, out.decode(), err.decode()


SPLIT_SOLVE = r"""
import dolfinx_solver
import numpy as np
from mpi4py import MPI
from fenics_drill.model.drillstring import build_model
from fenics_drill.scene import load_scene

comm = MPI.COMM_WORLD
model = build_model(load_scene(None, ["reduction.rule=none", "beam.length=20", "beam.elements=40", *SETTINGS]))
split = model.split_over(comm)
rng = np.random.default_rng(0)
# a deflected, moving string: most vertices pressed into the wall (k = 1e10 N/m), the drive held
q = 1e-3 * rng.standard_normal(model.size)
qd, qdd, mu = rng.standard_normal(model.size), rng.standard_normal(model.size), np.zeros(2)
coefficients = (1.0, 800.0, 2.5e5)
whole, shared = (m.evaluate(q, qd, qdd, mu, coefficients) for m in (model, split))
rhs_q, rhs_c = rng.standard_normal(model.size), rng.standard_normal(2)
x, m = model.space.saddle_solve(whole.tangent, model.constraints, rhs_q, rhs_c)
xs, ms = split.space.saddle_solve(shared.tangent, split.constraints, rhs_q, rhs_c)
reports = comm.gather({"rank": comm.rank, "residual": float(np.abs(whole.residual - shared.residual).max()
                                                             / np.abs(whole.residual).max()),
                       "x": float(np.abs(x - xs).max() / np.abs(x).max()),
                       "mu": float(np.abs(m - ms).max() / np.abs(m).max())})
if comm.rank == 0:
    print(json.dumps(reports))
"""


@pytest.mark.parametrize("settings", [[], ["model.lateral_length=5"]])
def test_the_split_saddle_solve_equals_the_one_rank_banded_solve(settings):
    """Each rank assembles half the elements; the sum of the halves is the whole residual, and the Schur
    complement on the cut vertex gives the one-rank solution on both ranks; also where the lateral fields are solved
    over the bottom 5 m only (the ranks' halves hold the energies of u and theta_x alone above them).  Tolerances:
    both are direct solves of one system (its band's condition number 5e10 here, measured) whose elimination orders
    differ only across the cut: measured 1.1e-14 apart; 1e-10 leaves room for another BLAS, not for a wrong block (a
    transposed Schur complement gave 1.6e-6)."""
    script = f"import json\nSETTINGS = {settings!r}\n" + SPLIT_SOLVE
    process = subprocess.Popen([str(MPIEXEC), "-n", "2", sys.executable, "-c", script],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    code, out, err = _finished(process, 300)
    assert code == 0, err
    reports = json.loads(out.splitlines()[-1])
    assert sorted(r["rank"] for r in reports) == [0, 1]
    for report in reports:
        assert report["residual"] < 1e-12, report  # each entry is one half's, or the sum of two at the cut
        assert report["x"] < 1e-10 and report["mu"] < 1e-10, report


def test_a_run_on_two_ranks_equals_the_run_on_one(tmp_path):
    """The paper's string in the full order, 0.05 s: the same steps and Newton iterations, and every number of the
    summary the same to 1e-9 relative (measured 2e-13 at most: the halves' sums and the Schur elimination round
    off otherwise than one band; Newton's tolerance, time.newton_tolerance, is 1e-8 of the forces); the first
    rank writes the files, and they hold the same rows."""
    settings = ["--set", "time.t_end=0.05"]
    runs = {ranks: _run(tmp_path / f"ranks{ranks}", ranks, *settings) for ranks in (1, 2)}
    for ranks, process in runs.items():
        code, _, err = _finished(process, 600)
        assert code == 0, (ranks, err)
    one, two = (json.loads((tmp_path / f"ranks{r}" / "summary.json").read_text()) for r in (1, 2))
    assert two["ranks"] == {"ranks": 2, "split": True}
    assert (two["steps"], two["newton_iterations"]) == (one["steps"], one["newton_iterations"])
    # 1e-9: the ranks solve the same equations with other round-off (the halves' sums, the Schur elimination), which
    # the band's conditioning (about 5e10 with the wall's springs) amplifies to at most ~1e-6 of the state; measured
    # 2e-13 on these summaries, so 1e-9 still catches a missing half or a wrong block, which moves them by percents
    for key in ("rop", "efficiency", "mean_bit_velocity", "impacts_total"):
        assert two[key] == pytest.approx(one[key], rel=1e-9, abs=0.0), key
    assert two["max_von_mises"]["value"] == pytest.approx(one["max_von_mises"]["value"], rel=1e-9)
    for load in ("hook_load", "surface_torque"):
        assert two["torque_and_drag"][load]["mean_second_half"] == pytest.approx(
            one["torque_and_drag"][load]["mean_second_half"], rel=1e-9)
    with h5py.File(tmp_path / "ranks1" / "timeseries.h5") as a, h5py.File(tmp_path / "ranks2" / "timeseries.h5") as b:
        for name in ("time", "bit_velocity", "bit_angular_velocity", "lambda_4", "max_von_mises"):  # as above
            assert np.allclose(b[name][()], a[name][()], rtol=1e-9, atol=1e-9 * np.abs(a[name][()]).max()), name
    assert sorted(p.name for p in (tmp_path / "ranks2").iterdir()) == sorted(
        p.name for p in (tmp_path / "ranks1").iterdir())


def test_ctrl_c_stops_both_ranks_after_the_same_step(tmp_path):
    """SIGINT to mpiexec (which passes it to both ranks): exit 130, the summary "interrupted" with the steps its
    time series holds, within a few seconds."""
    process = _run(tmp_path / "run", 2, "--set", "time.t_end=5")
    summary = tmp_path / "run" / "summary.json"
    deadline = time.time() + 300
    while time.time() < deadline:
        if summary.exists() and json.loads(summary.read_text()).get("rows", 0) > 20:
            break
        time.sleep(0.5)
    else:
        process.kill()
        pytest.fail("the run did not start writing rows")
    process.send_signal(signal.SIGINT)
    code, _, err = _finished(process, 120)
    assert code == 130, err
    final = json.loads(summary.read_text())
    assert final["status"] == "interrupted"
    with h5py.File(tmp_path / "run" / "timeseries.h5") as f:
        assert f["time"].shape[0] == final["steps"] + 1


def test_a_third_rank_is_refused_before_any_computation(tmp_path):
    code, _, err = _finished(_run(tmp_path / "run", 3), 300)
    assert code == 2
    assert "1 or 2 MPI ranks" in err


def test_a_string_too_short_to_split_runs_on_the_first_rank_alone(tmp_path):
    """Two elements: the drive's dofs lie within a band's width of the middle vertex, so the string cannot be cut
    there; the first rank runs it alone and says why, the second writes nothing, and both end."""
    code, _, err = _finished(_run(tmp_path / "run", 2, "--set", "beam.elements=2", "--set", "time.t_end=0.01"), 300)
    assert code == 0, err
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["ranks"]["split"] is False and "too short to split" in summary["ranks"]["why"]
    assert summary["steps"] > 0
