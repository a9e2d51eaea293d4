"""``fenics-drill optimize``: the operating window of Sections 6.9, 6.10 and 6.12.

The window (V0, Omega) is a structured grid (``optimize.axial_velocity``,
``optimize.rotation_speed``).  Deterministic mode (``optimize.samples = 0``): one
drilling run per point with the nominal bit-rock law; objective rop (99) or
efficiency (96); admissible where UTS - max sigma_VM >= 0 (100).  Robust mode
(``samples = N``): N realisations per point of the random bit-rock laws (Section 5),
the same N parameter draws at every point (common random numbers, so that the map
compares operating points and not samples); objective E[objective] (102); admissible
where the estimate of P{UTS - max sigma_VM >= 0} is >= 1 - P_risk (103)-(104).

Every point also gets the stick-slip map's indicators (:data:`OSCILLATIONS`, over the second half of
its run): stick-slip severity (max - min) omega_bit / 2 Omega, the fraction of time stuck, and the
fraction off the bottom; ``smooth_drilling`` marks where the bit neither sticks nor bounces off.

Work is spread over MPI ranks by (point, realisation) pairs, each result written at
once to ``DIR/points/PPPP_KKKK.json`` (atomically); ``--resume`` skips those present,
exactly like ``fenics-drill mc``.  Rank 0 assembles ``DIR/optimize.json``.

The model and its static equilibrium are built once per rank: neither depends on the
drive speeds nor on the bit-rock parameters.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI
from scipy import interpolate, optimize

from fenics_drill.io.files import read_json, usable_result, write_json
from fenics_drill.io.study_directory import all_done, claim, polled_barrier, stopped_rank
from fenics_drill.model.resources import check_memory
from fenics_drill.scene import check_history_grid
from fenics_drill.studies.lifecycle import stop_if_requested, study_run
from fenics_drill.studies.prepare import prepare, run_realisation
from fenics_drill.studies.uncertainty import BitRockLaws

NOMINAL_DRAW = -1

#: The stick-slip map's indicators of a run, over its second half (:mod:`fenics_drill.studies.prepare`).
OSCILLATIONS = ("stick_slip_severity", "stick_fraction", "off_bottom_fraction")


def grid_axis(spec: list) -> np.ndarray:
    low, high, n = spec
    return np.linspace(low, high, int(n))


def chance_constraint(max_stress: np.ndarray, ultimate_strength: float, risk: float) -> tuple[float, bool]:
    """(estimate of P{UTS - max sigma_VM >= 0}, whether it is >= 1 - P_risk), Eqs. (103)-(104)."""
    probability = float(np.mean(np.asarray(max_stress) <= ultimate_strength))
    return probability, probability >= 1.0 - risk


def _task_path(out: Path, point: int, draw: int) -> Path:
    return out / "points" / f"{point:04d}_{'nominal' if draw == NOMINAL_DRAW else f'{draw:04d}'}.json"


def _evaluate(prepared, scene, v0: float, omega: float, bit_rock: dict) -> dict:
    point_scene = scene.with_changes(drive={"axial_velocity": v0, "rotation_speed": omega}, bit_rock=bit_rock)
    r = run_realisation(prepared, point_scene)
    return {"status": r["status"], "message": r["message"], "rop": r["rop"], "signed_rop": r["signed_rop"],
            "efficiency": r["efficiency"], "efficiency_torque_magnitude": r["efficiency_torque_magnitude"],
            "max_von_mises": r["max_von_mises"], "bit_rock": bit_rock,
            **{key: r[key] for key in OSCILLATIONS},
            "wall_time_s": r["wall_time_s"]}


def _refine(v0: np.ndarray, omega: np.ndarray, values: np.ndarray, start: tuple[int, int]) -> dict | None:
    """Maximise a cubic (or lower) spline interpolant of the objective over the window, from the grid optimum."""
    if len(v0) < 2 or len(omega) < 2 or not np.isfinite(values).all():
        return None
    spline = interpolate.RectBivariateSpline(v0, omega, values, kx=min(3, len(v0) - 1), ky=min(3, len(omega) - 1))
    scale = np.array([v0[-1] - v0[0], omega[-1] - omega[0]])
    lower = np.array([v0[0], omega[0]])

    def negative(z):
        x = lower + z * scale
        return -float(spline(x[0], x[1])[0, 0])

    z0 = (np.array([v0[start[0]], omega[start[1]]]) - lower) / scale
    best = optimize.minimize(negative, z0, bounds=[(0, 1), (0, 1)], method="L-BFGS-B")
    x = lower + best.x * scale
    return {"axial_velocity": float(x[0]), "rotation_speed": float(x[1]), "objective": -float(best.fun)}


def assemble(scene, out: Path) -> dict:
    """Read every point's results and write DIR/optimize.json: grids, maps, admissible mask, optimum."""
    opt = scene.optimize
    v0, omega = grid_axis(opt.axial_velocity), grid_axis(opt.rotation_speed)
    check_history_grid(scene)
    draws = [NOMINAL_DRAW] if opt.samples == 0 else list(range(opt.samples))
    shape = (len(v0), len(omega))
    maps = {key: np.full(shape, np.nan) for key in ("rop", "signed_rop", "efficiency", "efficiency_torque_magnitude",
                                                     "max_von_mises",
                                                     "constraint_probability", *OSCILLATIONS)}
    failed = 0
    for i in range(len(v0)):
        for j in range(len(omega)):
            results = [read_json(_task_path(out, i * len(omega) + j, d)) for d in draws]
            finished = [r for r in results if r["status"] == "finished"]
            failed += len(results) - len(finished)
            if not finished:
                continue
            for key in ("rop", "signed_rop", "efficiency", "efficiency_torque_magnitude", *OSCILLATIONS):
                # E[.] of (102); the value itself if N = 0 (results of earlier versions lack the oscillations)
                maps[key][i, j] = np.mean([r.get(key, np.nan) for r in finished])
            stresses = np.array([r["max_von_mises"] for r in finished])
            maps["max_von_mises"][i, j] = stresses.max()
            maps["constraint_probability"][i, j] = chance_constraint(stresses, opt.ultimate_strength,
                                                                     opt.risk)[0]
    if opt.samples == 0:
        admissible = maps["max_von_mises"] <= opt.ultimate_strength  # (100)
    else:
        admissible = maps["constraint_probability"] >= 1.0 - opt.risk  # (104)
    objective = maps[opt.objective]
    candidates = np.where(admissible & np.isfinite(objective), objective, -np.inf)
    report = {
        "mode": "deterministic" if opt.samples == 0 else f"robust ({opt.samples} realisations per point)",
        "objective": opt.objective, "ultimate_strength": opt.ultimate_strength, "risk": opt.risk,
        "axial_velocity": v0.tolist(), "rotation_speed": omega.tolist(), "t_end": scene.time.t_end,
        **{key: value.tolist() for key, value in maps.items()},
        "admissible": admissible.tolist(), "failed_runs": failed,
        # the stick-slip map: where the bit neither sticks nor leaves the bottom in the second half of the run
        "smooth_drilling": ((maps["stick_fraction"] == 0) & (maps["off_bottom_fraction"] == 0)).tolist(),
    }
    if np.isfinite(candidates).any():
        i, j = np.unravel_index(int(np.argmax(candidates)), shape)
        report["feasible"] = True
        report["optimum"] = {"axial_velocity": float(v0[i]), "rotation_speed": float(omega[j]),
                             "objective": float(objective[i, j]), "max_von_mises": float(maps["max_von_mises"][i, j])}
        report["refined_optimum"] = _refine(v0, omega, objective, (i, j)) if admissible.all() else None
    else:
        report["feasible"] = False
        report["optimum"] = None
        report["message"] = ("no admissible point in the window: the von Mises constraint "
                             f"({'(100)' if opt.samples == 0 else '(104)'}) fails everywhere")
    write_json(out / "optimize.json", report)
    write_json(out / "summary.json", {"command": "optimize", "status": "finished", "feasible": report["feasible"],
                                      "optimum": report["optimum"], "failed_runs": failed})
    return report


def _tasks(n_v0: int, n_omega: int, draws: int):
    """(task number, point, i, j, draw) of every run of the window, in order, without storing them."""
    n = 0
    for i in range(n_v0):
        for j in range(n_omega):
            for draw in range(draws) if draws else (NOMINAL_DRAW,):
                yield n, i * n_omega + j, i, j, draw
                n += 1


def run_optimize(scene, out: str | Path, resume: bool = False, progress: bool = True,
                 comm=MPI.COMM_WORLD, overwrite: bool = False) -> dict | None:
    """Evaluate the window (spread over the ranks) and assemble the report on rank 0."""
    out = Path(out)
    opt = scene.optimize
    laws = BitRockLaws(scene.bit_rock, scene.uncertainty) if opt.samples > 0 else None
    v0, omega = grid_axis(opt.axial_velocity), grid_axis(opt.rotation_speed)
    check_history_grid(scene)
    total = len(v0) * len(omega) * max(opt.samples, 1)
    check_memory(scene.beam.elements, scene.beam.element_degree)
    def counts() -> dict:
        return {"runs": total, "runs_done": len(list((out / "points").glob("*.json")))}

    with claim(out, scene.to_dict(), "optimize", resume, overwrite, comm, counts), \
            study_run(out, "optimize", comm, counts):
        if comm.rank == 0:
            (out / "points").mkdir(exist_ok=True)
        polled_barrier(comm)
        prepared = prepare(scene)
        started = time.perf_counter()
        for n, point, i, j, draw in _tasks(len(v0), len(omega), opt.samples):
            path = _task_path(out, point, draw)
            if n % comm.size != comm.rank or usable_result(path, read_json):
                continue
            stop_if_requested()
            if (stop := stopped_rank(out, comm.rank)) is not None:
                raise stop
            bit_rock = dataclasses.asdict(scene.bit_rock) if draw == NOMINAL_DRAW else laws.sample(draw)
            result = _evaluate(prepared, scene, v0[i], omega[j], bit_rock)
            write_json(path, result)
            if progress and comm.rank == 0:
                done = len(list((out / "points").glob("*.json")))
                sys.stderr.write(f"\r  runs {done:5d} / {total}  wall {time.perf_counter() - started:8.1f} s ")
                sys.stderr.flush()
        if not all_done(out, comm, progress):
            return None
        return assemble(scene, out)
