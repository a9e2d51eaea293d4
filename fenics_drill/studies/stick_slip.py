"""Stick-slip of the scene's well on its axial-torsional string, run until its limit cycle or steady rotation.

:func:`start` sets the string of :mod:`~fenics_drill.model.axial_torsional_string` at the scene's start (its static
state on bottom at ``drive.weight_on_bit``, or hanging off bottom, moving at the drive's V0 and Omega) for the
compiled steps of :mod:`~fenics_drill.solvers.axial_torsional_step`.  :func:`limit_cycle` steps it window by window
(each two of the string's first torsional periods 4 L / c_T, held at the top and free at the bit) until, past the
start's transient, the bit's spin stays within :data:`SPIN_TOLERANCE` of the drive's speed (steady rotation), or its
last block of cycles (from one rise of the spin through the drive's speed to the next; :data:`SETTLED_CYCLES` of
them, or more until they span a window) repeats the block before it: their fastest and slowest spin within
:data:`SPIN_TOLERANCE` of the drive's speed, their stuck shares within :data:`SHARE_TOLERANCE`, their mean surface
torques within :data:`TORQUE_TOLERANCE` and their mean periods within :data:`PERIOD_TOLERANCE` (a stick-slip whose
cycles differ a little from one to the next settles in its statistics).  Or until a time limit; the report says
which (:func:`cycle_metrics`).

Signs: ``top_force`` is the force the drive applies to the top along the string (down-hole), so the hook load is
its negative; ``top_torque`` is the torque it applies (positive while it turns the string); ``bit_force`` and
``bit_torque`` are the rock's on the string (negative while cutting).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fenics_drill.model.axial_torsional_string import AxialTorsionalString, axial_torsional_string, mesh_viscosity
from fenics_drill.model.forces.axial_torsional_wall import tension_press
from fenics_drill.model.forces.cutting_bit import cutting_law_constants
from fenics_drill.model.top_drive import controller_gains
from fenics_drill.model.well import hanging_tension
from fenics_drill.observables.spectra import dominant_period
from fenics_drill.scene import LAW_SIGN
from fenics_drill.solvers.axial_torsional_step import (CONVERGED, CUTTING, NO_BIT, PAPER, RECORDED, advance,
                                                      band_solve)
from fenics_drill.solvers.newmark import newmark_parameters

#: A bit turning slower than this share of the drive's speed is stuck.
STUCK_SHARE = 0.01
#: The cycles of a block: a limit cycle has settled when the last block of cycles repeats the one before it, within
#: the tolerances below; the windows (two first torsional periods each) taken as the start's transient, and those
#: searched for cycles.
SETTLED_CYCLES, TRANSIENT_WINDOWS, HISTORY_WINDOWS = 3, 2, 8
SPIN_TOLERANCE = 0.03  # of the drive's speed, for the bit's fastest and slowest spin
SHARE_TOLERANCE = 0.03  # of the time, for the stuck share
TORQUE_TOLERANCE = 0.02  # of the mean surface torque
PERIOD_TOLERANCE = 0.03  # of the cycle's mean duration
#: Newton's stop (the residual's largest entry against the string's weight) and its iterations per step.
TOLERANCE, MAX_ITERATIONS = 1e-8, 40
#: What the steps take for ``press`` where the wall's normal force is held (``contact.normal_force = 'static'``).
NO_PRESS = (np.empty((0, 3)), np.empty(0), np.empty((0, 3)), np.empty(0), np.empty(0))
#: The cut bottom's memory: (angle, surface) entries kept (more than two revolutions of accepted steps).
SURFACE_CAPACITY = 1 << 16


class StepFailed(RuntimeError):
    """Newton did not converge in a step of the axial-torsional string."""


@dataclass
class Simulation:
    """An axial-torsional string being stepped: its constants, its state and its records so far."""

    string: AxialTorsionalString
    dt: float
    newmark: tuple[float, float]
    constants: tuple  # the arguments of :func:`advance` before ``drive``
    drive: np.ndarray  # (axial held, V0, top force, rotation held, Omega, k_p, k_i, T_max, z)
    state: tuple  # q, v, a, clock, anchor, held, surface, surface_state
    stride: int = 1
    records: list = field(default_factory=list)
    #: Steps taken (halves included), Newton iterations, steps halved.
    counters: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.int64))

    @property
    def time(self) -> float:
        return float(self.state[3][0])

    def run(self, duration: float) -> dict:
        """Step ``duration`` [s] further; the rows recorded over it, by name (:data:`RECORDED`)."""
        steps = max(1, int(round(duration / self.dt)))
        rows = np.empty((steps // self.stride + 1, len(RECORDED)))
        status, written = advance(*self.constants, self.drive, self.dt, self.newmark, TOLERANCE, MAX_ITERATIONS,
                                  steps, self.stride, *self.state, rows, self.counters)
        if status != CONVERGED:
            raise StepFailed(f"Newton did not converge in {MAX_ITERATIONS} iterations after t = {self.time:.6g} s "
                             f"(step {self.dt:.3g} s); a smaller time.dt may")
        self.records.append(rows[:written])
        return columns(rows[:written])

    def series(self) -> dict:
        """Every row recorded so far, by name."""
        return columns(np.concatenate(self.records) if self.records else np.empty((0, len(RECORDED))))


def columns(rows: np.ndarray) -> dict:
    return {name: rows[:, i] for i, name in enumerate(RECORDED)}


def first_torsional_period(string: AxialTorsionalString) -> float:
    """4 L / c_T of the top section: the first torsional period, held at the top and free at the bit [s]."""
    return 4.0 * string.length / string.torsional_wave_speed_at_top


#: The default step's share of the mean element's axial wave transit time.  At the whole transit, three of the twelve
#: points of a grid of weight on bit x rotation speed next to bit bounce settled on a calm cycle where the distributed
#: model solved exactly bounces; at half of it none did, and the fastest spin and the stuck share came closer to the
#: exact ones (benchmarks/results/stick_slip_waves.md, docs/guide/stick_slip_maps.md).
TRANSIT_SHARE = 0.5


def default_step(string: AxialTorsionalString) -> float:
    """TRANSIT_SHARE of the mean element's axial wave transit time, (L / elements) / c_L [s] (``time.dt = -1``): short
    elements (a stabiliser's 2 m) do not set it, for the scheme is implicit (its accuracy is measured in
    docs/performance.md)."""
    return float(TRANSIT_SHARE * string.length / (len(string.wall_dofs) - 1) / string.axial_wave_speed)


def _bit_law(scene, string: AxialTorsionalString) -> tuple[int, np.ndarray]:
    if not scene.model.bit_rock:
        return NO_BIT, np.zeros(10)
    bit = scene.bit_rock
    if bit.law == "detournay":
        return CUTTING, np.array([*cutting_law_constants(bit), 2.0 * math.pi / bit.blades])
    sign = LAW_SIGN[scene.law(bit.torque_law)]
    return PAPER, np.array([bit.limit_force, bit.rate, sign * bit.friction, scene.hole_at_bit[0], 0, 0, 0, 0, 0, 0])


def start(scene, string: AxialTorsionalString | None = None, dt: float | None = None,
          stride: int = 1) -> Simulation:
    """The scene's string at its start (module doc), ready to step at ``dt`` (default: ``time.dt``, or
    :func:`default_step`), recording every ``stride`` steps."""
    string = axial_torsional_string(scene) if string is None else string
    drive = scene.drive
    dt = dt or (scene.time.dt if scene.time.dt > 0 else default_step(string))
    w, n = string.half_width, string.size
    tu, tt = string.top
    bu, bt = string.bit
    on_bottom = scene.starts_on_bottom and scene.model.bit_rock
    set_weight = drive.weight_on_bit if on_bottom else 0.0
    # the static state: K q = F_G - W e_bit, the top held at the origin, untwisted
    stiffness = string.stiffness.copy()
    load = string.gravity.copy()
    load[bu] -= set_weight
    for i in (tu, tt):
        stiffness[i, :] = 0.0
        stiffness[i, w] = 1.0
        load[i] = 0.0
    q = band_solve(stiffness, w, load)
    q[string.angle] = 0.0
    v = np.where(string.angle, drive.rotation_speed, drive.axial_velocity)
    axial_held = drive.mode == "velocity"
    rotation_held = drive.controller == "stiff"
    mass = string.mass.copy()
    k_p = k_i = 0.0
    if not rotation_held:
        mass[tt, w] += drive.top_drive_inertia
        k_p, k_i = controller_gains(drive, _top_section(string))
    hook_load = float(hanging_tension(scene, [0.0], set_weight)[0])
    bit_kind, bit_law = _bit_law(scene, string)
    surface = np.zeros((2, SURFACE_CAPACITY))
    surface[:, 0] = q[bt], q[bu]
    feed = drive.axial_velocity / drive.rotation_speed if drive.rotation_speed > 0 else 0.0
    wall = string.wall_dofs
    contact = scene.contact
    held = np.zeros((len(wall), 4))  # (F_a, F_t, factor, sliding) of each vertex: at rest, stuck at the static factor
    held[:, 2] = contact.static_factor
    state = (q, v, np.zeros(n), np.zeros(1), np.stack([q[wall[:, 0]], q[wall[:, 1]]], axis=1), held, surface,
             np.array([1.0, 0.0, feed]))
    wall_law = np.array([contact.friction, contact.stick_stiffness, contact.static_factor, contact.static_slip_speed])
    damping = string.damping
    if scene.stick_slip_map.mesh_viscosity > 0:
        damping = damping + mesh_viscosity(string, scene.stick_slip_map.mesh_viscosity)
    normal, press = string.wall_normal.copy(), NO_PRESS
    if contact.normal_force == "dynamic" and scene.model.contact:
        pressing = tension_press(scene, string.x[wall[:, 0]])
        normal = pressing.normal_forces(q[wall[:, 0]])
        press = (pressing.turn, pressing.weight, pressing.axis, pressing.rigidity, pressing.lengths)
    constants = (mass, damping, string.stiffness, w, string.gravity, string.top, string.bit, wall, normal,
                 string.wall_arm, press, wall_law, bit_kind, bit_law)
    drive_state = np.array([float(axial_held), drive.axial_velocity, -hook_load, float(rotation_held),
                            drive.rotation_speed, k_p, k_i, drive.torque_limit, 0.0])
    return Simulation(string, float(dt), newmark_parameters(scene.time.newmark_alpha), constants, drive_state, state,
                      stride)


@dataclass(frozen=True)
class _TopSection:
    """What :func:`~fenics_drill.model.top_drive.controller_gains` reads of a section: the top one's."""

    polar_inertia_per_length: float
    torsional_wave_speed: float
    length: float


def _top_section(string: AxialTorsionalString) -> _TopSection:
    return _TopSection(string.polar_inertia_at_top, string.torsional_wave_speed_at_top, string.length)


def window_metrics(series: dict, rotation_speed: float) -> dict:
    """The bit's spin and the drive's loads over recorded rows (means in time)."""
    t = series["time"]
    spin = series["bit_angular_velocity"]
    span = t[-1] - t[0] if t.size > 1 else 1.0

    def mean(values):
        return float(np.trapezoid(values, t) / span) if t.size > 1 else float(values[-1])

    return {"max_spin": float(spin.max()), "min_spin": float(spin.min()), "mean_spin": mean(spin),
            "stuck_share": mean((spin < STUCK_SHARE * rotation_speed).astype(float)),
            "surface_torque": mean(series["top_torque"]), "hook_load": -mean(series["top_force"]),
            "weight_on_bit": -mean(series["bit_force"]), "bit_torque": -mean(series["bit_torque"]),
            "bit_power": -mean(series["bit_torque"] * spin), "rop": mean(series["bit_velocity"])}


def cycles(series: dict, rotation_speed: float) -> list[slice]:
    """The rows of each whole cycle of the bit's spin: from one rise through the drive's speed to the next, a rise
    counting only after the spin has fallen a quarter of its range below that speed (a chattering crossing is not
    a cycle), or, where that is below its slowest, to a quarter of the way from its slowest to that speed (a spin
    that peaks above three times the drive's speed still has cycles)."""
    spin = series["bit_angular_velocity"]
    if spin.size < 2:
        return []
    slowest = spin.min()
    low = max(rotation_speed - 0.25 * np.ptp(spin), slowest + 0.25 * (rotation_speed - slowest))
    rises, armed = [], False
    for i in range(1, spin.size):
        if spin[i] < low:
            armed = True
        elif armed and spin[i - 1] <= rotation_speed < spin[i]:
            rises.append(i)
            armed = False
    return [slice(a, b + 1) for a, b in zip(rises[:-1], rises[1:])]


def _part(series: dict, rows: slice) -> dict:
    return {name: values[rows] for name, values in series.items()}


def repeating(blocks: list[dict], rotation_speed: float) -> bool:
    """Whether the metrics of two blocks of cycles (:func:`window_metrics` and the mean cycle's duration each)
    agree (module doc)."""
    def spread(key):
        values = [b[key] for b in blocks]
        return max(values) - min(values)

    torque = max(abs(b["surface_torque"]) for b in blocks)
    period = max(b["period"] for b in blocks)
    return (spread("max_spin") <= SPIN_TOLERANCE * rotation_speed
            and spread("min_spin") <= SPIN_TOLERANCE * rotation_speed
            and spread("stuck_share") <= SHARE_TOLERANCE
            and spread("surface_torque") <= TORQUE_TOLERANCE * max(torque, 1e-30)
            and spread("period") <= PERIOD_TOLERANCE * period)


def settled_cycle(series: dict, rotation_speed: float, after: float, block: float = 0.0
                  ) -> tuple[str | None, dict | None]:
    """('steady', rows) where the spin after ``after`` [s] stays within :data:`SPIN_TOLERANCE` of the drive's speed;
    ('cycle', rows of the last block of cycles, from a rise to a rise) where it repeats the block before it
    (:func:`repeating`); else (None, None).  A block is the last :data:`SETTLED_CYCLES` cycles, or more until they
    span ``block`` seconds (an irregular stick-slip of short cycles settles in the statistics of longer blocks)."""
    t, spin = series["time"], series["bit_angular_velocity"]
    late = t > after
    if not np.any(late):
        return None, None
    if np.ptp(spin[late]) <= SPIN_TOLERANCE * rotation_speed:
        return "steady", _part(series, late)
    late_series = _part(series, late)
    whole = cycles(late_series, rotation_speed)
    times = late_series["time"]
    count = SETTLED_CYCLES  # a block: at least SETTLED_CYCLES cycles, and at least ``block`` seconds of them
    while count < len(whole) and times[whole[-1].stop - 1] - times[whole[-count].start] < block:
        count += 1
    if len(whole) < 2 * count:
        return None, None
    blocks = []
    for part in (whole[-2 * count:-count], whole[-count:]):
        rows = slice(part[0].start, part[-1].stop)
        blocks.append(dict(window_metrics(_part(late_series, rows), rotation_speed),
                           period=float(np.ptp(times[rows]) / count)))
    if not repeating(blocks, rotation_speed):
        return None, None
    return "cycle", _part(late_series, slice(whole[-count].start, whole[-1].stop))


def mean_period(series: dict, rotation_speed: float) -> float | None:
    """The mean duration of the whole cycles in ``series`` (:func:`cycles`), None without one."""
    whole = cycles(series, rotation_speed)
    if not whole:
        return None
    return float(np.mean([np.ptp(series["time"][c]) for c in whole]))


def median_cycle_peak(series: dict, rotation_speed: float) -> float | None:
    """The median over the whole cycles in ``series`` (:func:`cycles`) of each cycle's fastest spin of the bit, None
    without one: an irregular cycle's typical slip, where the fastest spin over all the cycles is the extreme of
    their spread."""
    whole = cycles(series, rotation_speed)
    if not whole:
        return None
    return float(np.median([series["bit_angular_velocity"][c].max() for c in whole]))


def cycle_metrics(series: dict, rotation_speed: float, bit_area: float, steady: bool) -> dict:
    """The cycle over ``series``: severity (max - min) / (2 mean) of the bit's spin, its period (the mean duration
    of the whole cycles in ``series``) and its dominant period, over which a cycle of several unequal slips repeats
    (:func:`~fenics_drill.observables.spectra.dominant_period` of the bit's spin), the stuck share, the median
    cycle's fastest spin (:func:`median_cycle_peak`), the means of the rop, the surface torque, the hook load and the
    weight on bit, and the mechanical specific energy at the bit, W / A + <T omega> / (A rop) (Teale 1965, with the
    bit's torque and spin) [Pa]."""
    m = window_metrics(series, rotation_speed)
    mean_spin = m["mean_spin"]
    return {
        "severity": float((m["max_spin"] - m["min_spin"]) / (2.0 * mean_spin)) if mean_spin > 0 else math.inf,
        "period_s": None if steady else mean_period(series, rotation_speed),
        "dominant_period_s": None if steady else dominant_period(series["time"], series["bit_angular_velocity"]),
        "stuck_share": m["stuck_share"], "max_bit_spin_rad_s": m["max_spin"], "min_bit_spin_rad_s": m["min_spin"],
        "median_cycle_max_bit_spin_rad_s": None if steady else median_cycle_peak(series, rotation_speed),
        "mean_bit_spin_rad_s": mean_spin, "rop_m_s": m["rop"], "surface_torque_N_m": m["surface_torque"],
        "hook_load_N": m["hook_load"], "weight_on_bit_N": m["weight_on_bit"], "bit_torque_N_m": m["bit_torque"],
        "mechanical_specific_energy_Pa": (m["weight_on_bit"] / bit_area + m["bit_power"] / (bit_area * m["rop"])
                                          if m["rop"] > 0 else math.inf),
        "steady_rotation": bool(steady)}


def bit_area(scene) -> float:
    """The area the bit drills [m^2]: pi a^2 of the cutting bit, or of the hole for the paper's law."""
    radius = scene.bit_rock.bit_radius if scene.bit_rock.law == "detournay" else scene.hole_at_bit[0]
    return math.pi * radius**2


def limit_cycle(scene, time_limit: float, dt: float | None = None, simulation: Simulation | None = None,
                progress=None) -> dict:
    """Step the scene's string window by window (two first torsional periods each) until its steady rotation or
    its limit cycle has settled after the first :data:`TRANSIENT_WINDOWS` windows (:func:`settled_cycle`), or to
    ``time_limit`` [s]: the cycle's metrics (:func:`cycle_metrics`; at the limit, over the last
    :data:`TRANSIENT_WINDOWS` windows), with ``settled``, the time run, the window and the step.  A step whose Newton
    fails ends the run there: ``failed`` says why, and the metrics are those of the windows before it (StepFailed
    where there were none)."""
    simulation = start(scene, dt=dt) if simulation is None else simulation
    window = 2.0 * first_torsional_period(simulation.string)
    omega = scene.drive.rotation_speed
    kind, rows, failed = None, None, None
    while simulation.time < time_limit - 1e-9:
        try:
            simulation.run(min(window, time_limit - simulation.time))
        except StepFailed as err:  # reported with what was run before it
            failed = str(err)
            break
        if progress is not None:
            progress(simulation.time)
        if simulation.time >= (TRANSIENT_WINDOWS + 1) * window * (1.0 - 1e-9):  # a whole window past the transient
            series = simulation.series()
            kind, rows = settled_cycle(series, omega, max(TRANSIENT_WINDOWS * window,
                                                          simulation.time - HISTORY_WINDOWS * window), window)
            if kind is not None:
                break
    if kind is None:
        series = simulation.series()
        if series["time"].size < 2:
            raise StepFailed(failed)
        rows = _part(series, series["time"] > series["time"][-1] - TRANSIENT_WINDOWS * window)
    out = cycle_metrics(rows, omega, bit_area(scene), kind == "steady")
    out["failed"] = failed
    steps, iterations, halved = (int(c) for c in simulation.counters)
    out.update(settled=kind is not None, time_s=simulation.time, window_s=window, dt_s=simulation.dt, steps=steps,
               newton_iterations_per_step=iterations / max(steps, 1), steps_halved=halved)
    return out
