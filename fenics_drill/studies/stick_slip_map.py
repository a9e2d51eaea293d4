"""``fenics-drill stick-slip-map SCENE``: where stick-slip stops in weight on bit x rotation speed, for each rotary
drive of ``stick_slip_map.controllers``, on the scene's axial-torsional string.

Each point is the scene with ``drive.weight_on_bit``, ``drive.rotation_speed`` and ``drive.controller`` set to it,
run by :func:`~fenics_drill.studies.stick_slip.limit_cycle` until its cycle has settled or to
``stick_slip_map.time_limit``.  The points are shared over the MPI ranks, one file each in DIR/points (a resumed map
skips those written); then DIR/map.nc (``controller`` x ``weight_on_bit`` x ``rotation_speed``), map.csv, map.json and
summary.json.  Every point is checked before any is run: a weight on bit the drive cannot set refuses the map.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from fenics_drill.io.files import UnreadableFile, read_json, usable_result, write_atomic, write_json
from fenics_drill.io.study_directory import all_done, claim, polled_barrier, stopped_rank
from fenics_drill.model.axial_torsional_string import axial_torsional_string, pressed_for
from fenics_drill.model.well import check_weight_on_bit
from fenics_drill.scene import SceneError
from fenics_drill.studies.lifecycle import scene_record, stop_if_requested, study_run
from fenics_drill.studies.stick_slip import StepFailed, first_torsional_period, limit_cycle, start

#: What each point reports, with its unit, in map.nc and map.csv.
REPORTED = {"severity": "-", "period_s": "s", "dominant_period_s": "s", "stuck_share": "-",
            "max_bit_spin_rad_s": "rad/s", "min_bit_spin_rad_s": "rad/s", "median_cycle_max_bit_spin_rad_s": "rad/s",
            "mean_bit_spin_rad_s": "rad/s", "rop_m_s": "m/s",
            "surface_torque_N_m": "N m", "hook_load_N": "N", "weight_on_bit_N": "N", "bit_torque_N_m": "N m",
            "mechanical_specific_energy_Pa": "Pa", "time_s": "s", "wall_time_s": "s"}
#: What a point checked at half its step (``stick_slip_map.step_check``) reports of that run, as ``half_step_<name>``.
HALF_STEP = {"severity": "-", "period_s": "s", "stuck_share": "-", "max_bit_spin_rad_s": "rad/s",
             "min_bit_spin_rad_s": "rad/s"}


def reported(scene) -> dict:
    """Each reported quantity's unit: REPORTED, and the half step's with ``stick_slip_map.step_check``."""
    if not scene.stick_slip_map.step_check:
        return REPORTED
    return {**REPORTED, **{f"half_step_{name}": unit for name, unit in HALF_STEP.items()}}


def grid(axis: tuple) -> np.ndarray:
    low, high, n = axis
    return np.linspace(low, high, int(n))


def map_scene(scene):
    """The scene whose string the map steps: ``stick_slip_map.element_length`` sets its mesh."""
    return scene.with_changes(beam={"elements": max(1, math.ceil(scene.string_length
                                                                 / scene.stick_slip_map.element_length))})


def map_points(scene) -> list[tuple[str, float, float]]:
    """(controller, weight on bit, rotation speed) of every point, controller by controller."""
    m = scene.stick_slip_map
    return [(c, float(w), float(o)) for c in m.controllers for w in grid(m.weight_on_bit)
            for o in grid(m.rotation_speed)]


def point_scene(scene, controller: str, weight_on_bit: float, rotation_speed: float):
    """The scene at one point of the map; SceneError naming the point where its drive cannot start there."""
    try:
        point = scene.with_changes(drive={"weight_on_bit": weight_on_bit, "rotation_speed": rotation_speed,
                                          "controller": controller}, model={"lateral_length": 0.0})
        check_weight_on_bit(point)
    except SceneError as err:
        raise SceneError(f"the stick-slip map's point (weight on bit {weight_on_bit:g} N, rotation speed "
                         f"{rotation_speed:g} rad/s, {controller}) cannot start: {err}") from None
    if rotation_speed <= 0.0:
        raise SceneError("stick_slip_map.rotation_speed must be > 0 at every point (a map of a string that does not "
                         "turn has no stick-slip); its minimum is 0")
    if weight_on_bit <= 0.0 and scene.starts_on_bottom:
        raise SceneError("stick_slip_map.weight_on_bit must be > 0 at every point of a map on bottom; its minimum is 0")
    return point


def check_weight_axis(scene) -> None:
    """Refuse a grid of several weights on bit where none reaches the bit: a scene rotating off bottom (no bit law,
    or a velocity drive that starts off bottom) would give the same point at each, labelled with weights it never
    felt."""
    drive = scene.drive
    pressed = scene.model.bit_rock and (drive.mode == "hook_load" or scene.starts_on_bottom)
    low, high, count = scene.stick_slip_map.weight_on_bit
    if not pressed and (count > 1 and high != low):
        why = "model.bit_rock = false" if not scene.model.bit_rock else "a velocity drive that starts off bottom"
        raise SceneError(f"stick_slip_map.weight_on_bit = {list(scene.stick_slip_map.weight_on_bit)!r} is not "
                         f"admissible: the scene rotates off bottom ({why}), so no weight reaches the bit; give it "
                         "one point, [w, w, 1] (any w > 0, unused), and map the rotation speed")


def _point_path(out: Path, index: int) -> Path:
    return out / "points" / f"{index:06d}.json"


def _read_point(path: Path) -> dict:
    data = read_json(path)
    if "severity" not in data:
        raise UnreadableFile(f"{path} is not a whole result")
    return data


def _cycle(point, string, dt: float | None = None) -> dict:
    """The point's cycle at the step ``dt`` (None: its default); a Newton that fails in the first window reports it
    (``failed``) with NaN metrics."""
    try:
        simulation = start(point, string=pressed_for(string, point), dt=dt)
        return limit_cycle(point, point.stick_slip_map.time_limit, simulation=simulation)
    except StepFailed as err:  # in the first window
        out = {name: float("nan") for name in REPORTED}
        out.update(settled=False, steady_rotation=False, failed=str(err))
        return out


#: A cycle has moved at half the step when its period or stuck share, or its fastest or slowest spin (against the
#: drive's speed), changed by more than the settled cycle's own tolerances (studies/stick_slip.py, settled_cycle).
MOVED_PERIOD, MOVED_SPIN, MOVED_STUCK = 0.03, 0.03, 0.03


def step_moved(cycle: dict, half_step: dict, rotation_speed: float) -> bool:
    """Whether the cycle at half the step differs from ``cycle`` by more than MOVED_*; a failed or NaN run, or steady
    rotation at one step and a cycle at the other, counts as moved."""
    if cycle.get("failed") or half_step.get("failed") or cycle["steady_rotation"] != half_step["steady_rotation"]:
        return True
    spins = [abs(half_step[k] - cycle[k]) / rotation_speed for k in ("max_bit_spin_rad_s", "min_bit_spin_rad_s")]
    moved = not (max(spins) <= MOVED_SPIN and abs(half_step["stuck_share"] - cycle["stuck_share"]) <= MOVED_STUCK)
    if not cycle["steady_rotation"] and cycle["period_s"] is not None and half_step["period_s"] is not None:
        moved = moved or not abs(half_step["period_s"] / cycle["period_s"] - 1.0) <= MOVED_PERIOD
    return moved


def run_point(scene, string, controller: str, weight_on_bit: float, rotation_speed: float) -> dict:
    """One point's cycle (:func:`~fenics_drill.studies.stick_slip.limit_cycle`), with its wall time; a point whose
    Newton fails reports it (``failed``), with the metrics of the windows before (NaN in its first), rather than
    ending the map.  With ``stick_slip_map.step_check`` the point is run again at half its step: the half step's
    period, fastest spin and stuck share, and ``step_moved`` (:func:`step_moved`)."""
    clock = time.perf_counter()
    point = point_scene(scene, controller, weight_on_bit, rotation_speed)
    out = _cycle(point, string)
    if scene.stick_slip_map.step_check:
        half = _cycle(point, string, 0.5 * out["dt_s"]) if "dt_s" in out else {"failed": out["failed"]}
        out.update({f"half_step_{name}": half.get(name) for name in HALF_STEP},
                   step_moved=step_moved(out, half, rotation_speed))
    out["wall_time_s"] = time.perf_counter() - clock
    return out


def write_stick_slip_map(scene, out: str | Path, resume: bool = False, overwrite: bool = False,
                         progress: bool = True, comm=None) -> dict | None:
    """The map over the ranks of ``comm`` (MPI's world by default), module doc.  The first rank returns its
    ``report`` and ``map`` (an ``xarray.Dataset``), the others None."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD if comm is None else comm
    out = Path(out)
    clock = time.perf_counter()
    scene = map_scene(scene)
    check_weight_axis(scene)
    points = map_points(scene)
    for controller, w, o in points:  # every point checked before the directory is taken
        point_scene(scene, controller, w, o)
    string = axial_torsional_string(scene)  # one band for every point; its wall pressed for each point's weight

    def counts() -> dict:
        return {"points": len(points), "points_done": len(list((out / "points").glob("*.json")))}

    with claim(out, {"scene": scene.to_dict()}, "stick-slip-map", resume, overwrite, comm, counts), \
            study_run(out, "stick-slip-map", comm, counts):
        if comm.rank == 0:
            (out / "points").mkdir(exist_ok=True)
        polled_barrier(comm)
        for index in range(comm.rank, len(points), comm.size):
            stop_if_requested()
            if (stop := stopped_rank(out, comm.rank)) is not None:
                raise stop
            path = _point_path(out, index)
            if usable_result(path, _read_point):
                continue
            write_json(path, run_point(scene, string, *points[index]))
            if progress and comm.rank == 0:
                done = len(list((out / "points").glob("*.json")))
                sys.stderr.write(f"\r  points {done:4d} / {len(points)}  wall {time.perf_counter() - clock:7.1f} s ")
                sys.stderr.flush()
        if not all_done(out, comm, progress):
            return None
        results = [_read_point(_point_path(out, i)) for i in range(len(points))]
        study = _assembled(scene, string, results, time.perf_counter() - clock, comm.size)
        write_atomic(out / "map.nc", lambda tmp: study["map"].to_netcdf(tmp, engine="h5netcdf"))
        write_atomic(out / "map.csv", lambda tmp: Path(tmp).write_text(_csv(scene, points, results)))
        write_json(out / "map.json", study["report"])
        write_json(out / "summary.json", {"command": "stick-slip-map", "status": "finished", "message": "map.json",
                                          "points": len(points), "wall_time_s": time.perf_counter() - clock,
                                          **scene_record(scene)})
    return study


def _csv(scene, points, results) -> str:
    units = reported(scene)
    checked = scene.stick_slip_map.step_check
    header = ["controller", "weight_on_bit (N)", "rotation_speed (rad/s)", "settled", "steady_rotation"] + \
        [f"{name} ({unit})" for name, unit in units.items()] + (["step_moved"] if checked else []) + ["failed"]
    lines = [",".join(header)]
    for (controller, w, o), r in zip(points, results):
        values = [r.get(name) for name in units]
        failed = (r.get("failed") or "").replace(",", ";")
        lines.append(",".join([controller, f"{w:.9g}", f"{o:.9g}", str(r["settled"]), str(r["steady_rotation"])]
                              + ["" if v is None else f"{v:.9g}" for v in values]
                              + ([str(r["step_moved"])] if checked else []) + [f'"{failed}"' if failed else ""]))
    return "\n".join(lines) + "\n"


def _assembled(scene, string, results: list[dict], seconds: float, ranks: int) -> dict:
    import xarray as xr

    m = scene.stick_slip_map
    weights, speeds = grid(m.weight_on_bit), grid(m.rotation_speed)
    shape = (len(m.controllers), weights.size, speeds.size)

    def field(name, default=np.nan):
        values = [default if r.get(name) is None else r[name] for r in results]
        return np.array(values, dtype=float).reshape(shape)

    dims = ("controller", "weight_on_bit", "rotation_speed")
    data = {name: (dims, field(name), {"units": unit}) for name, unit in reported(scene).items()}
    data["settled"] = (dims, field("settled").astype(bool))
    if m.step_check:
        data["step_moved"] = (dims, field("step_moved").astype(bool))
    data["failed"] = (dims, np.array([bool(r.get("failed")) for r in results]).reshape(shape))
    data["steady_rotation"] = (dims, field("steady_rotation").astype(bool))
    dataset = xr.Dataset(data, coords={"controller": list(m.controllers),
                                       "weight_on_bit": ("weight_on_bit", weights, {"units": "N"}),
                                       "rotation_speed": ("rotation_speed", speeds, {"units": "rad/s"})},
                         attrs={"time_limit_s": m.time_limit, "drive_mode": scene.drive.mode,
                                "bit_rock_law": scene.bit_rock.law, "wall_normal_force": scene.contact.normal_force})
    report = {"points": len(results), "ranks": ranks, "wall_time_s": seconds,
              "settled_points": int(sum(bool(r["settled"]) for r in results)),
              "failed_points": [i for i, r in enumerate(results) if r.get("failed")],
              "drive_mode": scene.drive.mode, "bit_rock_law": scene.bit_rock.law,
              "wall_normal_force": scene.contact.normal_force,
              "controllers": {c: {"stick_slip_points": int(np.sum(field("stuck_share")[k] > 0.0)),
                                  "steady_points": int(np.sum(field("steady_rotation")[k] > 0.5))}
                              for k, c in enumerate(m.controllers)}}
    advice = []
    if scene.contact.static_factor > scene.contact.friction:
        advice.append(STATIC_FRICTION_ADVICE.format(length=m.element_length))
    if m.mesh_viscosity > 0:
        advice.append(viscosity_advice(scene, string))
    report["irregular_points"] = [i for i, r in enumerate(results) if r["settled"] and irregular(r)]
    if report["irregular_points"]:
        advice.append(IRREGULAR_ADVICE.format(count=len(report["irregular_points"]), share=100 * IRREGULAR_PERIOD))
    if m.step_check:
        report["step_moved_points"] = [i for i, r in enumerate(results) if r["step_moved"]]
        if report["step_moved_points"]:
            advice.append((STEP_MOVED_ADVICE if m.mesh_viscosity == 0 else STEP_MOVED_VISCOUS_ADVICE).format(
                count=len(report["step_moved_points"])))
    if advice:
        report["advice"] = advice
    return {"report": report, "map": dataset}


#: A cycle whose period between rises through the drive's speed and whose dominant period differ by more than this
#: share is irregular, or repeats over several unequal slips.
IRREGULAR_PERIOD = 0.1
IRREGULAR_ADVICE = (
    "{count} settled point(s) have a cycle whose period between rises through the drive's speed (period_s) and whose "
    "dominant period (dominant_period_s) differ by more than {share:g} %: the cycle repeats over several unequal "
    "slips or is irregular; read both, and median_cycle_max_bit_spin_rad_s beside max_bit_spin_rad_s (the stick-slip "
    "guide, 'The limit cycle')")


def irregular(result: dict) -> bool:
    """Whether a point's period_s and dominant_period_s differ by more than IRREGULAR_PERIOD (False where either is
    missing)."""
    period, dominant = result.get("period_s"), result.get("dominant_period_s")
    if period is None or dominant is None or not (period > 0 and dominant > 0):
        return False
    return abs(dominant / period - 1.0) > IRREGULAR_PERIOD


#: What a map with the wall's static friction is told (docs/guide/stick_slip_maps.md, "Against the authors' published
#: model").
STATIC_FRICTION_ADVICE = (
    "the wall's static friction above the kinetic one makes the cycle and the stuck share move with the mesh: on "
    "Aarsnes & Shor's case side by side, the stuck share read 0.46, 0.29 and 0.44 on 10, 5 and 2.5 m elements, while "
    "the mean and peak torque held within 0.6 % and the fastest spin within 1.2 %; check a point at half the "
    "elements' {length:g} m (stick_slip_map.element_length) before reading its cycle and stuck share")

#: What a map with the mesh viscosity is told (docs/guide/stick_slip_maps.md, "The mesh viscosity").
VISCOSITY_ADVICE = (
    "stick_slip_map.mesh_viscosity = {zeta:g} damps the torsional waves by {first:.3f} % of critical at the string's "
    "first torsional mode and {at_5_hz:.2f} % at 5 Hz, where the string's own damping (38) gives {own_first:.3f} % and "
    "{own_5_hz:.3f} %: a stick-slip it removes hangs on damping the scene can only estimate; compare with the map at "
    "0 (the stick-slip guide, 'The mesh viscosity')")


def viscosity_advice(scene, string) -> str:
    """VISCOSITY_ADVICE for the scene's string: the viscosity's ratio zeta h omega / (4 c_T) and (38)'s c / (2 omega)
    at the first torsional mode held at the top (omega = 2 pi / (4 L / c_T)) and at 5 Hz, in %."""
    zeta, h, c = scene.stick_slip_map.mesh_viscosity, scene.stick_slip_map.element_length, \
        string.torsional_wave_speed_at_top
    first, at_5_hz = 2.0 * math.pi / first_torsional_period(string), 2.0 * math.pi * 5.0
    return VISCOSITY_ADVICE.format(zeta=zeta, first=100 * zeta * h * first / (4 * c),
                                   at_5_hz=100 * zeta * h * at_5_hz / (4 * c),
                                   own_first=100 * scene.beam.damping / (2 * first),
                                   own_5_hz=100 * scene.beam.damping / (2 * at_5_hz))


#: What a map whose points' cycles moved at half their step is told (docs/guide/stick_slip_maps.md, "The mesh
#: viscosity").
STEP_MOVED_ADVICE = (
    "{count} point(s) moved at half their step (map.csv's step_moved): their cycle is not yet the scheme's answer; "
    "check them with a shorter time.dt. stick_slip_map.mesh_viscosity = 1 holds such a cycle with the step but damps "
    "a marginal stick-slip away (on the VBH well's map it left none in the first torsional mode's cycle): the "
    "stick-slip guide, 'The mesh viscosity'")
STEP_MOVED_VISCOUS_ADVICE = (
    "{count} point(s) moved at half their step (map.csv's step_moved) even with the mesh viscosity: their cycle is "
    "irregular or not resolved at this step; check them with a shorter time.dt before reading their cycle")
