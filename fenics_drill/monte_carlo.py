"""``fenics-drill mc``: Monte Carlo over the random bit-rock laws (Sections 5 and 6.11).

Every process builds the model and its static equilibrium once (neither depends on
the bit-rock parameters), then runs its share of the realisations: realisation k on
rank k mod P, with parameters drawn from ``default_rng([seed, k])``.  Each finished
realisation is written at once to ``DIR/realisations/NNNNNN.h5`` (a temporary file
renamed into place, so a killed run leaves no half-written result;
:mod:`fenics_drill.study_directory`); ``--resume`` skips those present.  When all are done, rank 0 reads them in index order and writes
the statistics, so the result does not depend on the number of processes.

A realisation file holds, on the common grid of ``uncertainty.output_interval``:
the histories of HISTORIES; and as attributes its bit-rock parameters, status, rop,
efficiency, mean bit velocity, max von Mises stress and int ||q||^2 dt (for (101)).
"""

from __future__ import annotations

import sys
import time
from collections import defaultdict
from pathlib import Path

import h5py
import numpy as np
from mpi4py import MPI

from fenics_drill.drilling_quantities import drilling_quantities
from fenics_drill.drilling_run import PreparedScene, prepare
from fenics_drill.simulation import Simulation
from fenics_drill.step_control import StepTooSmall
from fenics_drill.step_rows import StepRows
from fenics_drill.study_directory import all_done, claim, write_atomic
from fenics_drill.uncertainty import BitRockLaws

#: Time histories kept per realisation (Figs. 29, 31, 33).
HISTORIES = ("bit_displacement", "bit_velocity", "bit_rotation", "bit_angular_velocity", "section_w",
             "section_w_velocity")
#: Scalars kept per realisation.
SCALARS = ("rop", "efficiency", "signed_rop", "mean_bit_velocity", "max_von_mises", "q_norm_integral")
NOMINAL = "nominal.h5"


class RealisationRecorder:
    """Keeps the rows of one realisation in memory and integrates ||q||^2 (Eq. 101)."""

    def __init__(self, prepared: PreparedScene, scene: dict):
        self.model = prepared.model
        self.rows = StepRows(prepared.model, scene)
        self.series: dict[str, list] = defaultdict(list)
        self.q_norm_integral = 0.0
        self._last: tuple[float, float] | None = None

    def __call__(self, record) -> None:
        s = record.state
        for key, value in self.rows(record, self.model.space.expand(s.q)).items():
            self.series[key].append(value)
        q2 = float(s.q @ s.q)
        if self._last is not None:
            t0, q20 = self._last
            self.q_norm_integral += 0.5 * (q20 + q2) * (s.t - t0)
        self._last = (s.t, q2)


def run_realisation(prepared: PreparedScene, scene: dict, bit_rock: dict) -> dict:
    """One drilling run from the shared static state with the scene's drive speeds and the given
    bit-rock parameters."""
    model = prepared.model
    model.set_drive(scene["drive"]["axial_velocity"], scene["drive"]["rotation_speed"])
    model.set_bit_rock(bit_rock)
    simulation = Simulation(model, scene)
    start = simulation.initial_state(prepared.equilibrium.q, prepared.equilibrium.mu)
    recorder = RealisationRecorder(prepared, scene)
    clock = time.perf_counter()
    status, message = "finished", "reached time.t_end"
    try:
        simulation.run(start, scene["time"]["t_end"], recorder)
    except StepTooSmall as failure:
        status, message = "failed", str(failure)
    series = {k: np.asarray(v, dtype=float) for k, v in recorder.series.items()}
    t = series["time"]
    grid = np.arange(0.0, scene["time"]["t_end"] + 1e-9, scene["uncertainty"]["output_interval"])
    drive = scene["drive"]
    result = {"status": status, "message": message, "wall_time_s": time.perf_counter() - clock,
              "steps": simulation.stats["steps"], "time": grid,
              "histories": {name: np.interp(grid, t, series[name]) for name in HISTORIES},
              "bit_rock": bit_rock, "q_norm_integral": recorder.q_norm_integral}
    q = drilling_quantities(series, drive["axial_velocity"], drive["rotation_speed"]) if len(t) > 1 else {}
    result["rop"], result["efficiency"] = q.get("rop", np.nan), q.get("efficiency", np.nan)
    result["signed_rop"] = q.get("signed_rop", np.nan)
    result["mean_bit_velocity"] = (series["bit_displacement"][-1] - series["bit_displacement"][0]) / t[-1] \
        if t[-1] > 0 else np.nan
    stress = series["max_von_mises"]
    result["max_von_mises"] = float(np.nanmax(stress)) if np.isfinite(stress).any() else np.nan
    return result


def write_realisation(path: Path, result: dict) -> None:
    """Write atomically: a temporary file renamed into place."""

    def write(tmp: Path) -> None:
        with h5py.File(tmp, "w") as f:
            f["time"] = result["time"]
            f["time"].attrs["units"] = "s"
            for name, values in result["histories"].items():
                f[name] = values
            for key in ("status", "message", "wall_time_s", "steps", *SCALARS):
                f.attrs[key] = result[key]
            for key, value in result["bit_rock"].items():
                f.attrs[f"bit_rock.{key}"] = value

    write_atomic(path, write)


def read_realisation(path: Path, histories: bool = True) -> dict:
    with h5py.File(path, "r") as f:
        out = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
        if histories:
            out["time"] = f["time"][()]
            out["histories"] = {name: f[name][()] for name in HISTORIES}
    return out


def realisation_path(out: Path, k: int) -> Path:
    return out / "realisations" / f"{k:06d}.h5"


def _progress(out: Path, samples: int, started: float, done_at_start: int) -> None:
    files = sorted((out / "realisations").glob("*.h5"))
    done = len(files)
    total_q = sum(read_realisation(p, histories=False)["q_norm_integral"] for p in files)
    metric = np.sqrt(total_q / done) if done else float("nan")
    rate = (done - done_at_start) / (time.perf_counter() - started)
    eta = (samples - done) / rate if rate > 0 else float("nan")
    sys.stderr.write(f"\r  realisations {done:5d} / {samples}  conv_MC {metric:.6e}  eta {eta:8.0f} s ")
    sys.stderr.flush()


def monte_carlo(scene: dict, samples: int, out: str | Path, resume: bool = False, progress: bool = True,
                comm=MPI.COMM_WORLD) -> dict | None:
    """Run (or finish) the study; rank 0 returns the summary, the other ranks None."""
    out = Path(out)
    laws = BitRockLaws(scene["bit_rock"], scene["uncertainty"])  # refuses inadmissible laws
    claim(out, scene, "realisations", "*.h5", resume, comm)
    prepared = prepare(scene)
    if comm.rank == 0 and not (out / NOMINAL).exists():
        write_realisation(out / NOMINAL, run_realisation(prepared, scene, dict(scene["bit_rock"])))
    done_at_start = len(list((out / "realisations").glob("*.h5")))
    started = time.perf_counter()
    for k in range(comm.rank, samples, comm.size):
        path = realisation_path(out, k)
        if path.exists():
            continue
        write_realisation(path, run_realisation(prepared, scene, laws.sample(k)))
        if progress and comm.rank == 0:
            _progress(out, samples, started, done_at_start)
    if not all_done(comm, progress):
        return None
    from fenics_drill.mc_statistics import write_statistics

    return write_statistics(out, samples)
