"""Stick-slip of the scene's well on its axial-torsional string, run until its limit cycle or steady rotation.

:func:`start` sets the string of :mod:`~fenics_drill.model.axial_torsional_string` at the scene's start (its static
state on bottom at ``drive.weight_on_bit``, or hanging off bottom, moving at the drive's V0 and Omega) for the
compiled steps of :mod:`~fenics_drill.solvers.axial_torsional_step`.  :func:`limit_cycle` steps it window by window
(each two of the string's first torsional periods 4 L / c_T, held at the top and free at the bit) until the bit's
spin repeats over the last :data:`SETTLED_WINDOWS` windows (its extremes within :data:`SPIN_TOLERANCE` of the
drive's speed, its stuck share within :data:`SHARE_TOLERANCE`, the mean surface torque within
:data:`TORQUE_TOLERANCE`), or until a time limit, and reports the cycle over those windows (:func:`cycle_metrics`).

Signs: ``top_force`` is the force the drive applies to the top along the string (down-hole), so the hook load is
its negative; ``top_torque`` is the torque it applies (positive while it turns the string); ``bit_force`` and
``bit_torque`` are the rock's on the string (negative while cutting).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fenics_drill.model.axial_torsional_string import AxialTorsionalString, axial_torsional_string
from fenics_drill.model.forces.cutting_bit import CuttingBit
from fenics_drill.model.top_drive import controller_gains
from fenics_drill.model.well import hanging_tension
from fenics_drill.scene import LAW_SIGN
from fenics_drill.solvers.axial_torsional_step import (CONVERGED, CUTTING, NO_BIT, PAPER, RECORDED, advance,
                                                      band_solve)
from fenics_drill.solvers.newmark import newmark_parameters

#: A bit turning slower than this share of the drive's speed is stuck.
STUCK_SHARE = 0.01
#: The windows over which a limit cycle must repeat, and how closely.
SETTLED_WINDOWS = 3
SPIN_TOLERANCE = 0.02  # of the drive's speed, for the bit's fastest and slowest spin
SHARE_TOLERANCE = 0.02  # of the time, for the stuck share
TORQUE_TOLERANCE = 0.01  # of the mean surface torque
#: Newton's stop (the residual's largest entry against the string's weight) and its iterations per step.
TOLERANCE, MAX_ITERATIONS = 1e-10, 40
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

    @property
    def time(self) -> float:
        return float(self.state[3][0])

    def run(self, duration: float) -> dict:
        """Step ``duration`` [s] further; the rows recorded over it, by name (:data:`RECORDED`)."""
        steps = max(1, int(round(duration / self.dt)))
        rows = np.empty((steps // self.stride + 1, len(RECORDED)))
        status, written = advance(*self.constants, self.drive, self.dt, self.newmark, TOLERANCE, MAX_ITERATIONS,
                                  steps, self.stride, *self.state, rows)
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


def default_step(string: AxialTorsionalString) -> float:
    """The shortest element's axial wave transit time h / c_L [s] (``time.dt = -1``)."""
    return float(np.min(np.diff(string.x[string.wall_dofs[:, 0]])) / string.axial_wave_speed)


def _bit_law(scene, string: AxialTorsionalString) -> tuple[int, np.ndarray]:
    if not scene.model.bit_rock:
        return NO_BIT, np.zeros(9)
    bit = scene.bit_rock
    if bit.law == "detournay":
        constants = CuttingBit.__new__(CuttingBit)
        constants._set_parameters(bit)
        return CUTTING, np.array([*constants.law_constants, 2.0 * math.pi / bit.blades])
    sign = LAW_SIGN[scene.law(bit.torque_law)]
    return PAPER, np.array([bit.limit_force, bit.rate, sign * bit.friction, scene.borehole.radius, 0, 0, 0, 0, 0])


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
    state = (q, v, np.zeros(n), np.zeros(1), np.stack([q[wall[:, 0]], q[wall[:, 1]]], axis=1),
             np.zeros((len(wall), 2)), surface, np.array([1.0, 0.0, feed]))
    constants = (mass, string.damping, string.stiffness, w, string.gravity, string.top, string.bit, wall,
                 string.wall_normal, string.wall_arm,
                 (scene.contact.friction, scene.contact.stick_stiffness), bit_kind, bit_law)
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
    """The bit's spin and the drive's loads over recorded rows."""
    t = series["time"]
    spin = series["bit_angular_velocity"]
    span = t[-1] - t[0] if t.size > 1 else 1.0

    def mean(values):
        return float(np.trapezoid(values, t) / span) if t.size > 1 else float(values[-1])

    return {"max_spin": float(spin.max()), "min_spin": float(spin.min()), "mean_spin": mean(spin),
            "stuck_share": float(np.mean(spin < STUCK_SHARE * rotation_speed)),
            "surface_torque": mean(series["top_torque"]), "hook_load": -mean(series["top_force"]),
            "weight_on_bit": -mean(series["bit_force"]), "bit_torque": -mean(series["bit_torque"]),
            "bit_power": -mean(series["bit_torque"] * spin), "rop": mean(series["bit_velocity"])}


def settled(windows: list[dict], rotation_speed: float) -> bool:
    """Whether the last :data:`SETTLED_WINDOWS` windows repeat one another (module doc), or the last turns
    steadily (its spin within :data:`SPIN_TOLERANCE` of the drive's speed from end to end)."""
    if windows and windows[-1]["max_spin"] - windows[-1]["min_spin"] <= SPIN_TOLERANCE * rotation_speed:
        return True
    if len(windows) < SETTLED_WINDOWS:
        return False
    last = windows[-SETTLED_WINDOWS:]

    def spread(key):
        values = [w[key] for w in last]
        return max(values) - min(values)

    torque = max(abs(w["surface_torque"]) for w in last)
    return (spread("max_spin") <= SPIN_TOLERANCE * rotation_speed
            and spread("min_spin") <= SPIN_TOLERANCE * rotation_speed
            and spread("stuck_share") <= SHARE_TOLERANCE
            and spread("surface_torque") <= TORQUE_TOLERANCE * max(torque, 1e-30))


def cycle_period(t: np.ndarray, spin: np.ndarray) -> float | None:
    """The mean time between the bit's spin rising through its mean, or None with fewer than two such crossings."""
    above = spin > spin.mean()
    rising = np.flatnonzero(~above[:-1] & above[1:])
    if rising.size < 2:
        return None
    return float((t[rising[-1]] - t[rising[0]]) / (rising.size - 1))


def cycle_metrics(series: dict, rotation_speed: float, bit_area: float) -> dict:
    """The cycle over ``series``: severity (max - min) / (2 mean) of the bit's spin, its period, the stuck share,
    the means of the rop, the surface torque, the hook load and the weight on bit, and the mechanical specific
    energy at the bit, W / A + <T omega> / (A rop) (Teale 1965, with the bit's torque and spin) [Pa]."""
    m = window_metrics(series, rotation_speed)
    steady = m["max_spin"] - m["min_spin"] <= SPIN_TOLERANCE * rotation_speed
    mean_spin = m["mean_spin"]
    return {
        "severity": float((m["max_spin"] - m["min_spin"]) / (2.0 * mean_spin)) if mean_spin > 0 else math.inf,
        "period_s": None if steady else cycle_period(series["time"], series["bit_angular_velocity"]),
        "stuck_share": m["stuck_share"], "max_bit_spin_rad_s": m["max_spin"], "min_bit_spin_rad_s": m["min_spin"],
        "mean_bit_spin_rad_s": mean_spin, "rop_m_s": m["rop"], "surface_torque_N_m": m["surface_torque"],
        "hook_load_N": m["hook_load"], "weight_on_bit_N": m["weight_on_bit"], "bit_torque_N_m": m["bit_torque"],
        "mechanical_specific_energy_Pa": (m["weight_on_bit"] / bit_area + m["bit_power"] / (bit_area * m["rop"])
                                          if m["rop"] > 0 else math.inf),
        "steady_rotation": bool(steady)}


def bit_area(scene) -> float:
    """The area the bit drills [m^2]: pi a^2 of the cutting bit, or of the hole for the paper's law."""
    radius = scene.bit_rock.bit_radius if scene.bit_rock.law == "detournay" else scene.borehole.radius
    return math.pi * radius**2


def limit_cycle(scene, time_limit: float, dt: float | None = None, simulation: Simulation | None = None,
                progress=None) -> dict:
    """Step the scene's string until its limit cycle or steady rotation has settled (module doc), or to
    ``time_limit`` [s]: the cycle's metrics over the last windows, with ``settled``, the time run and the
    windows' length."""
    simulation = start(scene, dt=dt) if simulation is None else simulation
    window = 2.0 * first_torsional_period(simulation.string)
    omega = scene.drive.rotation_speed
    windows, kept = [], []
    while simulation.time < time_limit - 1e-9:
        rows = simulation.run(min(window, time_limit - simulation.time))
        windows.append(window_metrics(rows, omega))
        kept = (kept + [rows])[-SETTLED_WINDOWS:]
        if progress is not None:
            progress(simulation.time)
        if simulation.time >= 2.0 * window and settled(windows, omega):
            break
    series = {name: np.concatenate([rows[name] for rows in kept]) for name in RECORDED}
    out = cycle_metrics(series, omega, bit_area(scene))
    out.update(settled=bool(settled(windows, omega)), time_s=simulation.time, window_s=window,
               dt_s=simulation.dt)
    return out
