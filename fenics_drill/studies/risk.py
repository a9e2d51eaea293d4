"""``fenics-drill torque-drag SCENE --samples N``: torque and drag under uncertainty, the paper's method (Section 5)
applied to the soft string: maximum-entropy laws for what is uncertain, and Monte Carlo over MPI ranks.

* The friction factors (cased, open hole): on their bounds, the maximum-entropy law of what is stated - uniform
  (bounds only), the truncated exponential of the stated mean (p ~ exp(lambda x), lambda solving the mean), or, with
  a dispersion too, the beta law of that mean and standard deviation on the bounds (the law (90)-(92) of the
  paper's bit friction).
* The survey: the systematic and global terms of an ISCWSA error model, and the tortuosity model
  (:mod:`fenics_drill.model.survey_errors`).

Realisation k draws from numpy ``default_rng([risk.seed, k])``, whatever the ranks.  At every bit depth of the chart
(:mod:`fenics_drill.studies.broomstick`) every realisation's operations are one compiled soft-string pass.  Outputs
along the well: the P10/P50/P90 of the indicated hook load and the surface torque of each operation, the probability
of exceeding the rig's hook-load and torque limits, the probability of helical buckling while slacking off (tripping
in), and the distribution of the lock-up depth while sliding (the shallowest bit depth at which the hook would have
to push to slide on).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from fenics_drill.io.files import UnreadableFile, usable_result, write_atomic, write_json
from fenics_drill.io.study_directory import all_done, claim, polled_barrier, stopped_rank
from fenics_drill.model.soft_string import operations, soft_string_batch
from fenics_drill.model.survey_errors import SurveyErrors, tortuous
from fenics_drill.model.well import Trajectory
from fenics_drill.observables.buckling import helical_load
from fenics_drill.scene import SceneError
from fenics_drill.studies.broomstick import BLOCK_MOTION, ChartString, chart_depths, indicator_factor
from fenics_drill.studies.lifecycle import scene_record, stop_if_requested, study_run

#: The quantiles of the envelopes.
QUANTILES = (0.1, 0.5, 0.9)
#: Most realisations a study takes.
MAX_RISK_SAMPLES = 1_000_000


class FrictionLaw:
    """The maximum-entropy law of a friction factor on [low, high] with an optional mean and dispersion (module doc)."""

    def __init__(self, name: str, low: float, high: float, mean: float = -1.0, dispersion: float = -1.0):
        self.low, self.high, self.mean, self.dispersion = low, high, mean, dispersion
        if dispersion != -1.0 and mean == -1.0:
            raise SceneError(f"risk.{name}_dispersion = {dispersion:g} is not admissible without risk.{name}_mean: "
                             "a dispersion is relative to a mean")
        if mean != -1.0 and not (low < mean < high or low == mean == high):
            raise SceneError(f"risk.{name}_mean = {mean:g} is not admissible: must lie inside the bounds "
                             f"risk.{name} = [{low:g}, {high:g}]")
        if dispersion != -1.0:
            variance, room = (dispersion * mean) ** 2, (mean - low) * (high - mean)
            if not variance < room:
                raise SceneError(f"risk.{name}_dispersion = {dispersion:g} is not admissible: a law on [{low:g}, "
                                 f"{high:g}] with mean {mean:g} has a dispersion below {np.sqrt(room) / mean:.4g}")
            shape = room / variance - 1.0
            self.alpha = shape * (mean - low) / (high - low)
            self.beta = shape * (high - mean) / (high - low)
        self.rate = 0.0
        if mean != -1.0 and dispersion == -1.0 and high > low:
            self.rate = _exponential_rate(low, high, mean)

    def draw(self, rng: np.random.Generator) -> float:
        width = self.high - self.low
        if width == 0.0:
            return self.low
        if self.dispersion != -1.0:
            return self.low + width * rng.beta(self.alpha, self.beta)
        u = rng.uniform()
        if self.rate == 0.0:
            return self.low + width * u
        # the inverse of the truncated exponential's distribution function
        return self.low + np.log1p(u * np.expm1(self.rate * width)) / self.rate


def _exponential_rate(low: float, high: float, mean: float) -> float:
    """lambda of p ~ exp(lambda x) on [low, high] with the mean ``mean`` (0 at the midpoint)."""
    width = high - low
    target = (mean - low) / width  # the mean on [0, 1]

    def mean_of(rate):
        if abs(rate) < 1e-9:
            return 0.5 + rate / 12.0
        return 1.0 / (-np.expm1(-rate)) - 1.0 / rate

    if abs(target - 0.5) < 1e-12:
        return 0.0
    bound = 1.0
    while not (mean_of(-bound) < target < mean_of(bound)):
        bound *= 2.0
    return brentq(lambda r: mean_of(r) - target, -bound, bound) / width


def realisations(scene, string: ChartString, indices) -> list[tuple[float, float, Trajectory | None]]:
    """(cased factor, open factor, trajectory or None for the nominal one) of each realisation index."""
    risk = scene.risk
    cased = FrictionLaw("friction_cased", *risk.friction_cased, risk.friction_cased_mean, risk.friction_cased_dispersion)
    open_hole = FrictionLaw("friction_open", *risk.friction_open, risk.friction_open_mean, risk.friction_open_dispersion)
    survey = string.well.trajectory.survey
    errors = SurveyErrors.of(survey, risk.survey_error, tuple(risk.magnetic_field)) \
        if risk.survey_error != "none" else None
    out = []
    for k in indices:
        rng = np.random.default_rng([risk.seed, k])
        pair = (cased.draw(rng), open_hole.draw(rng))
        moved = survey
        if errors is not None:
            moved = errors.drawn(moved, rng)
        moved = tortuous(moved, risk.tortuosity_amplitude, risk.tortuosity_period, rng)
        out.append((*pair, None if moved is survey else Trajectory(moved)))
    return out


def sample_loads(scene, string: ChartString, depths: np.ndarray, names: list[str], drawn) -> dict[str, np.ndarray]:
    """For the realisations ``drawn`` (:func:`realisations`): at each bit depth, each operation's indicated hook load
    and surface torque (depth, operation, sample), whether slacking off (tripping in) buckles the string helically
    and whether sliding locks up (depth, sample)."""
    bs = scene.broomstick
    factors = np.array([indicator_factor(bs.lines, bs.sheave_efficiency, BLOCK_MOTION[n]) for n in names])
    chart_ops = operations(scene, names)
    slack = operations(scene, ["tripping_in", "sliding"])
    pairs = np.array([(c, o) for c, o, _ in drawn])
    count = len(drawn)
    hook = np.empty((depths.size, len(names), count))
    torque = np.empty_like(hook)
    helical = np.empty((depths.size, count), dtype=bool)
    locked = np.empty((depths.size, count), dtype=bool)
    perturbed = any(t is not None for _, _, t in drawn)
    for i, depth in enumerate(depths):
        mesh, sections, cased = string.made_up(depth)
        frictions = np.where(cased[None, :], pairs[:, :1], pairs[:, 1:])
        middle = 0.5 * (mesh.md[1:] + mesh.md[:-1])
        tangents = None
        if perturbed:
            tangents = np.array([(t if t is not None else string.well.trajectory).tangents(mesh.md)
                                 for _, _, t in drawn])
        batch = [op for op in [*chart_ops, *slack] for _ in range(count)]
        rows = len(names) + 2
        loads = soft_string_batch(mesh, batch, np.tile(frictions, (rows, 1)),
                                  tangents=None if tangents is None else np.tile(tangents, (rows, 1, 1)))
        tension = loads["tension"].reshape(rows, count, -1)
        hook[i] = factors[:, None] * (tension[:len(names), :, 0] + bs.block_weight)
        torque[i] = loads["torque"].reshape(rows, count, -1)[:len(names), :, 0]
        stiffness = np.array([sections[k].bending_stiffness for k in mesh.section])
        clearance = string.well.hole.radius(middle) - mesh.contact_radius
        trajectories = [t if t is not None else string.well.trajectory for _, _, t in drawn] if perturbed else \
            [string.well.trajectory]
        f_hel = np.array([helical_load(stiffness, mesh.weight, t.inclination(middle), clearance, t.curvature(middle))
                          for t in trajectories])
        compression = -0.5 * (tension[len(names), :, 1:] + tension[len(names), :, :-1])
        helical[i] = np.any(compression > f_hel, axis=1)
        locked[i] = tension[len(names) + 1, :, 0] < 0.0
    return {"hook_load": hook, "surface_torque": torque, "helical_slack_off": helical, "locked_sliding": locked,
            "friction": pairs}


#: Realisations per result file: a file is the unit a rank computes, writes whole and a resumed study skips.
CHUNK = 50


def _chunk_path(out: Path, chunk: int) -> Path:
    return out / "samples" / f"{chunk:06d}.npz"


def _read_chunk(path: Path) -> dict:
    """A chunk's arrays; UnreadableFile where it is truncated or not one."""
    try:
        with np.load(path) as data:
            return {key: data[key] for key in data.files}
    except Exception as err:  # numpy's errors of a truncated or foreign file
        raise UnreadableFile(f"{path} is not a whole result ({type(err).__name__})") from None


def _write_chunk(path: Path, indices: np.ndarray, loads: dict) -> None:
    def write(tmp):
        with open(tmp, "wb") as f:
            np.savez(f, indices=indices, **loads)

    write_atomic(path, write)


def write_risk(scene, samples: int, out: str | Path, resume: bool = False, overwrite: bool = False,
               progress: bool = True, comm=None) -> dict | None:
    """``fenics-drill torque-drag --samples N``: the realisations in chunks of CHUNK spread over the ranks of
    ``comm`` (MPI's world by default), each chunk a file of DIR/samples (a resumed study skips those done); then
    DIR/risk.nc, risk.json and summary.json.  The first rank returns ``report`` and ``risk`` (an
    ``xarray.Dataset``), the others None."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD if comm is None else comm
    if isinstance(samples, bool) or not isinstance(samples, int) or not 1 <= samples <= MAX_RISK_SAMPLES:
        raise SceneError(f"the number of realisations (--samples) {samples!r} is not admissible: must be an integer in "
                         f"[1, {MAX_RISK_SAMPLES}]")
    out = Path(out)
    clock = time.perf_counter()
    string = ChartString(scene)
    realisations(scene, string, [])  # refuses inadmissible laws and error models before the directory is taken
    depths = chart_depths(scene, string.well.depth)
    names = list(scene.broomstick.operations)
    chunks = (samples + CHUNK - 1) // CHUNK

    def counts() -> dict:
        return {"samples": samples, "chunks_done": len(list((out / "samples").glob("*.npz")))}

    record = {"scene": scene.to_dict(), "samples": samples}
    with claim(out, record, "torque-drag", resume, overwrite, comm, counts), \
            study_run(out, "torque-drag", comm, counts):
        if comm.rank == 0:
            (out / "samples").mkdir(exist_ok=True)
        polled_barrier(comm)
        for chunk in range(comm.rank, chunks, comm.size):
            stop_if_requested()
            if (stop := stopped_rank(out, comm.rank)) is not None:
                raise stop
            path = _chunk_path(out, chunk)
            if usable_result(path, _read_chunk):
                continue
            indices = np.arange(chunk * CHUNK, min((chunk + 1) * CHUNK, samples))
            _write_chunk(path, indices, sample_loads(scene, string, depths, names,
                                                     realisations(scene, string, indices)))
            if progress and comm.rank == 0:
                done = len(list((out / "samples").glob("*.npz")))
                sys.stderr.write(f"\r  realisations {min(done * CHUNK, samples):7d} / {samples}  wall "
                                 f"{time.perf_counter() - clock:7.1f} s ")
                sys.stderr.flush()
        if not all_done(out, comm, progress):
            return None
        parts = [_read_chunk(_chunk_path(out, chunk)) for chunk in range(chunks)]
        joined = {key: np.concatenate([p[key] for p in parts], axis=0 if key in ("friction", "indices") else -1)
                  for key in parts[0]}
        study = _summarised(scene, depths, names, joined, time.perf_counter() - clock, comm.size)
        write_atomic(out / "risk.nc", lambda tmp: study["risk"].to_netcdf(tmp, engine="h5netcdf"))
        write_json(out / "risk.json", study["report"])
        write_json(out / "summary.json", {"command": "torque-drag", "status": "finished", "message": "risk.json",
                                          "samples": samples, "wall_time_s": time.perf_counter() - clock,
                                          **scene_record(scene)})
    return study


def lock_up_depths(depths: np.ndarray, locked: np.ndarray) -> np.ndarray:
    """Each realisation's lock-up depth while sliding (``locked``: depth x sample): the first bit depth at which the
    hook would have to push, below a depth at which sliding went (a string too short to carry the weight on bit
    near the surface has not locked up: it is not yet heavy enough); NaN where sliding reaches the bottom."""
    free = ~locked
    started = np.maximum.accumulate(free, axis=0)  # sliding went at this depth or above
    stuck = locked & np.roll(started, 1, axis=0)
    stuck[0] = locked[0] & ~free.any(axis=0)  # never free: locked from the first depth
    return np.where(stuck.any(axis=0), depths[np.argmax(stuck, axis=0)], np.nan)


def _summarised(scene, depths, names, loads, seconds, ranks) -> dict:
    """The envelopes, probabilities and lock-up depths of the gathered realisations."""
    import xarray

    bs = scene.broomstick
    hook, torque = loads["hook_load"], loads["surface_torque"]
    samples = hook.shape[-1]
    quantiles = np.array(QUANTILES)
    hook_q = np.quantile(hook, quantiles, axis=-1)  # (quantile, depth, operation)
    torque_q = np.quantile(torque, quantiles, axis=-1)
    over_hook = np.mean(hook > bs.hook_load_limit, axis=-1) if bs.hook_load_limit > 0 else np.full(hook.shape[:2],
                                                                                                   np.nan)
    over_torque = np.mean(torque > bs.torque_limit, axis=-1) if bs.torque_limit > 0 else np.full(hook.shape[:2],
                                                                                                 np.nan)
    first = lock_up_depths(depths, loads["locked_sliding"])
    dataset = xarray.Dataset(
        {"hook_load": (("quantile", "depth", "operation"), hook_q, {"units": "N", "long_name": "indicated hook load"}),
         "surface_torque": (("quantile", "depth", "operation"), torque_q, {"units": "N m"}),
         "probability_over_hook_load_limit": (("depth", "operation"), over_hook),
         "probability_over_torque_limit": (("depth", "operation"), over_torque),
         "probability_helical_slack_off": (("depth",), np.mean(loads["helical_slack_off"], axis=-1)),
         "lock_up_depth_sliding": (("sample",), first, {"units": "m", "long_name": "NaN: no lock-up to the bottom"}),
         "friction_cased": (("sample",), loads["friction"][:, 0]),
         "friction_open": (("sample",), loads["friction"][:, 1])},
        coords={"quantile": quantiles, "depth": ("depth", depths, {"units": "m"}), "operation": names,
                "sample": np.arange(samples)},
        attrs={"hook_load_limit_N": bs.hook_load_limit, "torque_limit_Nm": bs.torque_limit, "samples": samples})
    reached = float(np.mean(np.isnan(first)))
    found = first[np.isfinite(first)]
    report = {"samples": samples, "ranks": ranks, "depths": depths.size, "operations": names,
              "seed": scene.risk.seed, "survey_error": scene.risk.survey_error,
              "tortuosity_amplitude_deg": scene.risk.tortuosity_amplitude,
              "max_probability_over_hook_load_limit": None if bs.hook_load_limit <= 0 else float(over_hook.max()),
              "max_probability_over_torque_limit": None if bs.torque_limit <= 0 else float(over_torque.max()),
              "probability_helical_slack_off_at_bottom": float(np.mean(loads["helical_slack_off"][-1])),
              "probability_sliding_to_bottom": reached,
              "lock_up_depth_sliding_m": None if not found.size else
              {f"p{int(100 * q)}": float(np.quantile(found, q)) for q in QUANTILES},
              "at_bottom": {name: {"hook_load_N": [float(v) for v in hook_q[:, -1, j]],
                                   "surface_torque_Nm": [float(v) for v in torque_q[:, -1, j]]}
                            for j, name in enumerate(names)},
              "wall_time_s": seconds}
    return {"report": report, "risk": dataset}
