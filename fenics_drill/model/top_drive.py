"""How the top of the string (x = 0) is driven: held by the multipliers of (72), or by applied loads.

Axial (``drive.mode``):

* ``"velocity"`` - u(0, t) = V0 t, held by lambda_1 (the paper).
* ``"hook_load"`` - u(0) is free and the top pushes with the set weight on bit W: the hook load is
  the string's axial weight component minus W, and the string of this (horizontal) hole has none,
  so the drive applies +W along x.  V0 is then only the initial feed.

Rotation (``drive.controller``):

* ``"stiff"`` - theta_x(0, t) = Omega t, held by lambda_4 (the paper).
* ``"pi"`` - a top drive of inertia J_td on theta_x(0), driven by the motor torque
  T_m = k_p (Omega - theta_x_dot(0)) + k_i z, limited to |T_m| <= T_max, where
  z = int (Omega - theta_x_dot(0)) dt is the speed error's integral, integrated only while the
  motor is not at its limit (conditional integration: no wind-up).
* ``"soft_torque"`` - the same PI tuned to absorb torsional waves (Kyllingstad & Nessjoen 2009):
  k_p = Z = rho I_xx c_T, the torsional impedance of the pipe, and k_i = omega_s^2 J_td with
  omega_s = 2 pi c_T / (4 L), the string's first torsional quarter wave (stuck bit).  The motor and
  inertia then load the string like an infinite pipe at omega_s, so the waves that carry stick-slip
  are not reflected back down.

The multipliers' rows are :attr:`TopDrive.constraints`; the applied loads are generalised forces
(:class:`DriveLoads`) whose work the energy budget books as the drive's input, and the top-drive
inertia adds J_td theta_x_dot(0)^2 / 2 to the kinetic energy.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np

from fenics_drill.model.discretization import THETA_X, U
from fenics_drill.model.well import hanging_tension

AXIAL, ROTATION = 0, 1


@dataclass
class DriveLoads:
    """The loads the drive applies at one state, beyond its multipliers."""

    generalised: np.ndarray  # [Phi]^T of the applied force and torque
    axial_force: float  # force applied at x = 0 along +x when the axial motion is free [N]
    torque: float  # motor torque applied to theta_x(0) when the rotation is free [N m]
    d_torque_angle: float = 0.0  # dT_m / d theta_x(0)
    d_torque_speed: float = 0.0  # dT_m / d theta_x_dot(0)


def controller_gains(drive, properties) -> tuple[float, float]:
    """(k_p [N m s/rad], k_i [N m/rad]) of the speed controller: the scene's for ``"pi"``, the
    impedance-matching tuning for ``"soft_torque"`` (module doc)."""
    if drive.controller != "soft_torque":
        return drive.proportional_gain, drive.integral_gain
    c_t = properties.torsional_wave_speed
    impedance = properties.polar_inertia_per_length * c_t
    omega_s = 2.0 * math.pi * c_t / (4.0 * properties.length)
    return impedance, omega_s**2 * drive.top_drive_inertia


class TopDrive:
    """The drive of a scene in a solution space: multiplier rows for what it holds, loads for the rest."""

    def __init__(self, drive, disc, space, top_force: float = 0.0):
        """``top_force``: the axial force applied at the top when the drive leaves it free (``drive.mode =
        'hook_load'``), along x (down-hole), N: minus the hook load (:meth:`from_scene`)."""
        self.rows = space.point_rows([disc.end_dof(U, 0), disc.end_dof(THETA_X, 0)])  # q -> u(0), theta_x(0)
        self.top = self.rows.subset([1])  # q -> theta_x(0)
        self.rate = np.array([drive.axial_velocity, drive.rotation_speed])  # V0, Omega
        self.held = np.array([drive.mode == "velocity", drive.controller == "stiff"])
        self.top_force = top_force
        self.inertia = 0.0 if self.held[ROTATION] else drive.top_drive_inertia
        self.gains = controller_gains(drive, disc.properties)
        self.torque_limit = drive.torque_limit
        self._integral = 0.0  # z at the last accepted step [rad]
        self._last = (0.0, 0.0)  # (t, theta_x(0)) at the last accepted step
        self._t_next = 0.0
        self._no_loads = None  # the loads of a drive that holds both dofs (read-only: shared by every evaluation)

    @classmethod
    def from_scene(cls, scene, disc, space) -> "TopDrive":
        """The scene's drive.  A hook-load drive holds the string with the hook load that leaves
        ``drive.weight_on_bit`` on the bit: H = int_0^L w cos(I) ds - W_set, the buoyed weight along the axis less the
        weight on bit (:func:`~fenics_drill.model.well.hanging_tension` at the top, no wall friction); its top force
        is -H.  In the straight horizontal hole the weight has no share along the axis, and the top pushes with
        W_set."""
        top_force = -float(hanging_tension(scene, [0.0], scene.drive.weight_on_bit)[0]) \
            if scene.drive.mode == "hook_load" else 0.0
        return cls(scene.drive, disc, space, top_force)

    # --- what the multipliers hold -------------------------------------------------------------------------

    @property
    def constraints(self):
        """[B] of (72): the rows of the dofs the drive holds (k x N_red, k = 0, 1 or 2)."""
        return self.rows.subset(np.flatnonzero(self.held)).dense()

    @property
    def held_rate(self) -> np.ndarray:
        """h_dot of (71) for the held rows."""
        return self.rate[self.held]

    def with_speeds(self, axial_velocity: float, rotation_speed: float) -> "TopDrive":
        """The same drive with other set speeds V0, Omega (a point of an operating window)."""
        changed = copy.copy(self)
        changed.rate = np.array([axial_velocity, rotation_speed])
        return changed

    def at_rest(self) -> "TopDrive":
        """A drive that holds both top dofs (what the static equilibrium of Section 6.4 uses)."""
        held = copy.copy(self)
        held.held, held.inertia = np.array([True, True]), 0.0
        return held

    # --- the controller's memory ---------------------------------------------------------------------------

    def fresh(self) -> "TopDrive":
        """A copy with its own controller memory (one per simulation)."""
        return copy.copy(self)

    def begin(self, t: float, q: np.ndarray) -> None:
        """Start the controller at the initial state: z = 0."""
        self._integral, self._last, self._t_next = 0.0, (t, self._top(q)), t

    def start_step(self, t_next: float) -> None:
        self._t_next = t_next

    def accept(self, t: float, q: np.ndarray, qd: np.ndarray) -> None:
        """Integrate z over the accepted step, unless the motor was at its limit."""
        if self.held[ROTATION]:
            return
        integral = self._current_integral(self._top(q), t)
        if abs(self._unlimited_torque(integral, self._top(qd))) <= self.torque_limit:
            self._integral = integral
        self._last = (t, self._top(q))

    def _top(self, vector: np.ndarray) -> float:
        """theta_x(0) of a displacement (or its rate of a velocity)."""
        return float(self.top.values(vector)[0])

    def _current_integral(self, angle: float, t: float) -> float:
        """z at time t: z_n + int (Omega - theta_x_dot(0)) dt = z_n + Omega (t - t_n) - (theta - theta_n)."""
        t_n, angle_n = self._last
        return self._integral + self.rate[ROTATION] * (t - t_n) - (angle - angle_n)

    def _unlimited_torque(self, integral: float, speed: float) -> float:
        k_p, k_i = self.gains
        return k_p * (self.rate[ROTATION] - speed) + k_i * integral

    # --- loads ---------------------------------------------------------------------------------------------

    def evaluate(self, q: np.ndarray, qd: np.ndarray) -> DriveLoads:
        """The applied weight on bit and motor torque at (q, qd) at the time of the step being solved."""
        if self.held.all():  # the multipliers carry all the drive's loads: none applied, the same at every state
            if self._no_loads is None or self._no_loads.generalised.size != len(q):
                self._no_loads = DriveLoads(np.zeros(len(q)), 0.0, 0.0)
                self._no_loads.generalised.flags.writeable = False
            return self._no_loads
        force = 0.0 if self.held[AXIAL] else self.top_force
        torque = d_angle = d_speed = 0.0
        if not self.held[ROTATION]:
            angle, speed = self._top(q), self._top(qd)
            unlimited = self._unlimited_torque(self._current_integral(angle, self._t_next), speed)
            torque = float(np.clip(unlimited, -self.torque_limit, self.torque_limit))
            if abs(unlimited) < self.torque_limit:
                d_angle, d_speed = -self.gains[1], -self.gains[0]
        return DriveLoads(self.rows.spread(np.array([force, torque])), force, torque, d_angle, d_speed)

    def constant_loads(self, size: int) -> np.ndarray | None:
        """The generalised loads of :meth:`evaluate` where they do not depend on the state (the rotation held: no
        load, or the top force of a hook load), else None (a speed controller's torque)."""
        if not self.held[ROTATION]:
            return None
        return np.zeros(size) if self.held.all() else self.rows.spread(np.array([self.top_force, 0.0]))

    def tangent(self, loads: DriveLoads, c_u: float, c_v: float):
        """c_u df/dq + c_v df/dqd of the applied loads (None when the drive holds everything)."""
        if self.held[ROTATION]:
            return None
        return self.top.block(np.array([[c_u * loads.d_torque_angle + c_v * loads.d_torque_speed]]))

    def applied(self, mu: np.ndarray, loads: DriveLoads) -> tuple[float, float]:
        """(force along x, torque) the drive applies at x = 0: -lambda for a held dof, the load otherwise."""
        axial_held, rotation_held = self.held.tolist()
        multipliers = iter(mu.tolist())  # in the order of the held rows
        force = -next(multipliers) if axial_held else loads.axial_force
        return force, -next(multipliers) if rotation_held else loads.torque

    # --- inertia of the top drive --------------------------------------------------------------------------

    def inertia_force(self, qdd: np.ndarray) -> np.ndarray:
        """[Phi]^T J_td theta_x_ddot(0) (zero without a top drive)."""
        if self.inertia == 0.0:
            return np.zeros_like(qdd)
        return self.top.spread(self.inertia * self.top.values(qdd))

    def inertia_tangent(self, c_a: float):
        return self.top.block(np.array([[c_a * self.inertia]])) if self.inertia else None

    def kinetic_energy(self, qd: np.ndarray) -> float:
        return 0.5 * self.inertia * self._top(qd) ** 2 if self.inertia else 0.0

    def velocities(self, qd: np.ndarray) -> tuple[float, float]:
        """u_dot(0), theta_x_dot(0)."""
        u, tx = self.rows.values(qd)
        return float(u), float(tx)
