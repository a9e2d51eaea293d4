"""The wall where the lateral fields are not solved (``model.lateral_length``): one Coulomb force at each vertex's
contact point, pressed by the normal force the soft string's static state gives there.

Above the lateral length the string lies on the well's axis (its lateral fields held at zero), so the wall's
springs (17) never press it; the wall acts through its friction on the axial and torsional motion.  At vertex i the
normal force is N_i, the soft string's wall force per length (:mod:`~fenics_drill.model.soft_string`, the scene's
operation: rotating on bottom for a run that starts on bottom, off bottom otherwise, with the wall's friction
``contact.friction``) integrated over the half elements beside the vertex.  The contact point slips axially by
u_i and around the pipe by R_i theta_x,i (R_i the contact radius); the Coulomb force F = (F_a, F_t) follows by the
return mapping of the FE wall (:func:`~fenics_drill.model.forces.wall.coulomb.coulomb_friction`): from the force
held at the step's start, the trial F* = F_0 - k_t g of the slip g since then, kept while |F*| <= mu N_i (stuck: no
creep under a force below the cone), scaled onto the cone above it (sliding against the slip, so that rotation
takes the axial drag away).  On the string it acts as F_a on u_i and R_i F_t on theta_x,i.

With ``contact.normal_force = 'dynamic'`` N_i follows the string's own axial force instead (:class:`TensionPress`):
pressed anew at each accepted state by the tension the axial displacements give, turned by the well's axis at the
vertex, and by the weight of its half elements; held through the next step's Newton iterations.  At the static
state of the operation it is the soft string's (on the build-and-hold demo well's 90 elements the sums agree within
0.17 %: tests/model/test_lateral_length.py).

The cone's factor mu is the kinetic ``contact.friction`` at a vertex that slid at the last accepted state at a slip
speed of at least ``contact.static_slip_speed``, and the static ``contact.static_friction`` elsewhere (at rest, stuck,
or slipping slower): a stuck string breaks loose at the static factor and slides at the kinetic one (the wall law of
Aarsnes & Shor 2018, whose threshold is on the pipe's spin).  The factor is set at each accepted state and held
through the next step's Newton iterations.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from fenics_drill.model.discretization import THETA_X, U, BeamDiscretization
from fenics_drill.model.forces.protocol import ForceEvaluation
from fenics_drill.model.kernels.banded_saddle import Triplets
from fenics_drill.model.kernels.compiled import kernel
from fenics_drill.model.forces.wall.coulomb import _return_maps
from fenics_drill.model.soft_string import operations, soft_string, string_mesh
from fenics_drill.model.string_sections import section_at
from fenics_drill.model.well import string_in_well


@dataclass
class AxialTorsionalWallForces(ForceEvaluation):
    """The friction at the vertices at one state: (F_a, F_t) each, whether each vertex slides, and its trial size."""

    axial: np.ndarray = None
    tangential: np.ndarray = None
    trial: np.ndarray = None


@dataclass(frozen=True)
class TensionPress:
    """What presses each vertex on the wall for the string's own axial force (``contact.normal_force = 'dynamic'``,
    module doc): N_i = |P_i (T_i (a_i+ - a_i-) - W_i e_z)|, a_i- and a_i+ the axis' unit tangents (down-hole) over the
    elements above and below vertex i (its own at the ends), W_i the buoyed weight of its half elements, P_i the
    projection across its axis, and T_i the elements' mean axial forces E A (u_k+1 - u_k) / h_k beside it, weighted by
    their lengths: the soft string's equilibrium across the axis (:mod:`~fenics_drill.model.soft_string`) at the
    vertex."""

    turn: np.ndarray  # (vertices, 3): a_i+ - a_i- [-]
    weight: np.ndarray  # (vertices,): W_i [N]
    axis: np.ndarray  # (vertices, 3): the unit tangent at the vertex
    rigidity: np.ndarray  # (vertices - 1,): E A of each element [N]
    lengths: np.ndarray  # (vertices - 1,): h of each element [m]

    def normal_forces(self, u: np.ndarray) -> np.ndarray:
        """|N_i| [N] at the vertices for their axial displacements ``u`` [m]."""
        out = np.empty(self.weight.size)
        _pressed_normals(np.ascontiguousarray(u, dtype=float), self.turn, self.weight, self.axis, self.rigidity,
                         self.lengths, out)
        return out


def tension_press(scene, x: np.ndarray) -> TensionPress:
    """The :class:`TensionPress` of the scene's string at vertices ``x`` (measured depths, increasing) in its well."""
    x = np.asarray(x, dtype=float)
    if np.any(np.diff(x) <= 0):
        raise ValueError("the vertices must be ordered down the string")
    resolved = string_in_well(scene)
    sections, trajectory = resolved.sections, resolved.well.trajectory
    g = scene.environment.gravity if scene.model.gravity else 0.0
    middle = 0.5 * (x[1:] + x[:-1])
    index = section_at(list(sections), middle)
    per_length = np.array([s.buoyed_weight(g, scene.fluid.density, scene.inner_fluid_density) for s in sections])
    rigidity = np.array([s.young_modulus * math.pi * (s.outer_radius**2 - s.inner_radius**2) * s.stiffness_factors[0]
                         for s in sections])
    lengths = np.diff(x)
    half = 0.5 * per_length[index] * lengths
    elements = trajectory.tangents(middle)
    ends = trajectory.tangents(x[[0, -1]])
    turn = np.vstack([elements, ends[1:]]) - np.vstack([ends[:1], elements])
    return TensionPress(turn=np.ascontiguousarray(turn), weight=np.append(half, 0.0) + np.insert(half, 0, 0.0),
                        axis=np.ascontiguousarray(trajectory.tangents(x)), rigidity=rigidity[index], lengths=lengths)


@njit(cache=True)
def _pressed_normals(u, turn, weight, axis, rigidity, lengths, out):
    """:meth:`TensionPress.normal_forces` into ``out``."""
    n = u.size
    for k in range(n):
        if k == 0:
            tension = rigidity[0] * (u[1] - u[0]) / lengths[0]
        elif k == n - 1:
            tension = rigidity[n - 2] * (u[n - 1] - u[n - 2]) / lengths[n - 2]
        else:
            above, below = lengths[k - 1], lengths[k]
            tension = (rigidity[k - 1] * (u[k] - u[k - 1]) + rigidity[k] * (u[k + 1] - u[k])) / (above + below)
        l0, l1, l2 = tension * turn[k, 0], tension * turn[k, 1], tension * turn[k, 2] - weight[k]
        along = l0 * axis[k, 0] + l1 * axis[k, 1] + l2 * axis[k, 2]
        l0, l1, l2 = l0 - along * axis[k, 0], l1 - along * axis[k, 1], l2 - along * axis[k, 2]
        out[k] = math.sqrt(l0 * l0 + l1 * l1 + l2 * l2)


def vertex_normal_forces(scene, x: np.ndarray) -> np.ndarray:
    """N_i [N] at vertices ``x`` (measured depths along the string): the soft string's wall force per length of the
    scene's operation at its drive's set points (module doc), integrated over the half elements beside each
    vertex."""
    resolved = string_in_well(scene)  # the paper's straight horizontal hole without a survey
    sections, well = resolved.sections, resolved.well
    g = scene.environment.gravity if scene.model.gravity else 0.0
    weights = np.array([s.buoyed_weight(g, scene.fluid.density, scene.inner_fluid_density) for s in sections])
    mu = scene.contact.friction
    mesh = string_mesh(well, sections, min(scene.torque_drag.element_length, float(np.diff(x).min())),
                       weights, mu, mu)
    name = "rotating_on_bottom" if scene.starts_on_bottom else "rotating_off_bottom"
    # the run's own drive, not the set points a [torque_drag] section may give for its study
    drive = scene.with_changes(torque_drag={"weight_on_bit": -1.0, "rotation_speed": -1.0, "rate_of_penetration": -1.0})
    per_length = soft_string(mesh, operations(drive, [name])[0])["wall_force_per_length"]
    carried = np.concatenate([[0.0], np.cumsum(per_length * np.diff(mesh.md))])  # the wall's force above each node
    middle = np.concatenate([[x[0]], 0.5 * (x[1:] + x[:-1]), [x[-1]]])
    return np.diff(np.interp(middle, mesh.md, carried))


class AxialTorsionalWall:
    """The Coulomb friction of the wall at the vertices whose lateral fields are held (module doc)."""

    name: ClassVar[str] = "axial_torsional_wall"
    switch: ClassVar[str] = "contact"
    conservative: ClassVar[bool] = False
    recorded: ClassVar[dict] = {"vertices_stuck_on_the_wall": ("-", "vertices whose wall friction sticks "
                                                                    "(axial-torsional length)")}

    def __init__(self, disc: BeamDiscretization, space, normal: np.ndarray, arm: np.ndarray, friction: float,
                 stick_stiffness: float, static_friction: float | None = None, static_slip_speed: float = 0.0,
                 press: TensionPress | None = None):
        self.vertices = np.flatnonzero(disc.vertex_x < disc.lateral_top - 1e-9 * disc.properties.length) \
            if disc.lateral_length != 0 else np.arange(len(disc.vertex_x))
        self.rows = space.point_rows(np.concatenate([disc.vertex_dofs(U)[self.vertices],
                                                     disc.vertex_dofs(THETA_X)[self.vertices]]))
        self.arm = arm[self.vertices]
        self.friction, self.stick_stiffness = friction, stick_stiffness
        self.static_friction = friction if static_friction is None else static_friction
        self.static_slip_speed = static_slip_speed
        # the normal force pressed anew at each accepted state from the axial displacements of every vertex, or held
        self.press = press
        self._every_u = space.point_rows(disc.vertex_dofs(U)) if press is not None else None
        self._press(normal[self.vertices])
        self._stick_stiffness = float(stick_stiffness)
        self.space = space
        # (u, theta_x), (F_a, F_t) and each vertex's factor for the next step (module doc) at the last accepted
        # state; None outside a run
        self._history = None

    @classmethod
    def chosen(cls, scene) -> bool:
        """Only where some lateral fields are not solved."""
        return scene.model.lateral_length >= 0

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "AxialTorsionalWall":
        contact_radius, _ = disc.vertex_radii(scene.borehole.radius)
        contact = scene.contact
        press = tension_press(scene, disc.vertex_x) if contact.normal_force == "dynamic" else None
        return cls(disc, space, vertex_normal_forces(scene, disc.vertex_x), contact_radius, contact.friction,
                   contact.stick_stiffness, contact.static_factor, contact.static_slip_speed, press)

    def _press(self, normal: np.ndarray) -> None:
        self.normal = normal
        # the return mapping's argument as its compiled kernel takes it
        self._normal_force = np.ascontiguousarray(-normal, dtype=float)

    def _pressed_at(self, q: np.ndarray) -> None:
        """The normal forces of the string's axial force at state ``q`` (``contact.normal_force = 'dynamic'``)."""
        if self.press is not None:
            self._press(self.press.normal_forces(self._every_u.values(q))[self.vertices])

    def fresh(self) -> "AxialTorsionalWall":
        """A copy whose friction has no memory yet (a simulation's results never depend on another's)."""
        changed = copy.copy(self)
        changed._history = None
        return changed

    def _positions(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        values = self.rows.values(q)
        n = self.vertices.size
        return values[:n], values[n:]

    def begin(self, t: float, q: np.ndarray) -> None:
        """Anchor the friction at the initial state, holding no force yet."""
        self._pressed_at(q)
        u, theta = self._positions(q)
        self._history = (u, theta, np.zeros_like(u), np.zeros_like(u), np.full(u.size, float(self.static_friction)))

    def accept(self, t: float, q: np.ndarray, qd: np.ndarray) -> None:
        """Anchor the friction at an accepted state, holding the force each vertex feels there, and set each
        vertex's factor for the next step (module doc)."""
        if self._history is None:
            return
        forces = self.evaluate(q, qd)
        u, theta = self._positions(q)
        axial_speed, spin = self._positions(qd)
        sliding = forces.trial > self._history[4] * np.abs(self.normal)
        fast = np.hypot(axial_speed, self.arm * spin) >= self.static_slip_speed
        factor = np.where(sliding & fast, float(self.friction), float(self.static_friction))
        self._history = (u, theta, forces.axial, forces.tangential, factor)
        self._pressed_at(q)

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> AxialTorsionalWallForces:
        n = self.vertices.size
        if self._history is None or n == 0:  # at rest (a static state): no friction
            zero = np.zeros(n)
            return AxialTorsionalWallForces(np.zeros(self.space.size), 0.0, {self.name: np.zeros(self.space.size)},
                                            zero, zero, zero)
        u, theta = self._positions(q)
        u0, theta0, held_a, held_t, factor = self._history
        axial_slip, tangential_slip = u - u0, self.arm * (theta - theta0)
        trial_a = held_a - self.stick_stiffness * axial_slip
        trial_t = held_t - self.stick_stiffness * tangential_slip
        f_a, f_t = _return_maps(self._normal_force, held_a, held_t, axial_slip, tangential_slip, factor,
                                self._stick_stiffness)
        generalised = self.rows.spread(np.concatenate([f_a, self.arm * f_t]))
        return AxialTorsionalWallForces(generalised, 0.0, {self.name: generalised}, f_a, f_t,
                                        np.hypot(trial_a, trial_t))

    def tangent(self, forces: AxialTorsionalWallForces, c_u: float, c_v: float):
        """c_u d/dq of (F_a, R F_t) by (u, R theta_x) per vertex: stuck, -k_t; sliding on the cone (F = M e,
        e = F* / |F*|), -k_t M (I - e e^T) / |F*|."""
        n = self.vertices.size
        if self._history is None or n == 0:
            return None
        uu, ut, tt = _vertex_blocks(forces.trial, forces.axial, forces.tangential, self.normal, self._history[4],
                                    self._stick_stiffness, float(c_u), self.arm)
        if self.space.sparse:
            where = self.rows.positions
            return Triplets(*_diagonal_block_entries(where[:n], where[n:], uu, ut, tt), (self.space.size,) * 2)
        rows = self.rows.dense()
        ru, rt = rows[:n], rows[n:]
        return (ru.T @ (uu[:, None] * ru) + ru.T @ (ut[:, None] * rt) + rt.T @ (ut[:, None] * ru)
                + rt.T @ (tt[:, None] * rt))

    def record(self, forces: AxialTorsionalWallForces) -> dict[str, float]:
        factor = self.static_friction if self._history is None else self._history[4]  # at rest: static
        cap = factor * np.abs(self.normal)
        stuck = np.count_nonzero((forces.trial <= cap) & (cap > 0)) if forces.trial is not None else 0
        return {"vertices_stuck_on_the_wall": int(stuck)}


@kernel
def _vertex_blocks(trial, axial, tangential, normal, friction, stick_stiffness, c_u, arm):
    """Each vertex's 2 x 2 block [[uu, ut], [ut, tt]] of c_u d(F_a, R F_t)/d(u, theta_x), ``friction`` its factor
    (:meth:`AxialTorsionalWall.tangent`): d(F_a, F_t)/d(g_a, g_t) = k (I - s e e^T) with k = -c_u k_t |F|/|F*| and
    s = 1 sliding (k = -c_u k_t, s = 0 stuck), g = (u, R theta_x): the rows of theta_x carry R, its columns R."""
    n = trial.size
    uu, ut, tt = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        cap = friction[i] * abs(normal[i])
        sliding = trial[i] > cap
        shrink = cap / max(trial[i], 1e-300) if sliding else 1.0
        e_a = axial[i] / max(cap, 1e-300) if sliding else 0.0
        e_t = tangential[i] / max(cap, 1e-300) if sliding else 0.0
        s = 1.0 if sliding else 0.0
        k = -c_u * stick_stiffness * shrink
        uu[i] = k * (1 - s * e_a * e_a)
        ut[i] = -k * s * e_a * e_t * arm[i]
        tt[i] = arm[i] * arm[i] * (k * (1 - s * e_t * e_t))
    return uu, ut, tt


@kernel
def _diagonal_block_entries(at_u, at_theta, uu, ut, tt):
    """The entries (value, row, column) of the 2 x 2 blocks at each vertex's dofs (u, theta_x) (-1: held, left out):
    the uu entries, then ut, tu and tt."""
    n = at_u.size
    data, rows, cols = np.empty(4 * n), np.empty(4 * n, dtype=np.int64), np.empty(4 * n, dtype=np.int64)
    m = 0
    for block in range(4):
        for i in range(n):
            row = at_u[i] if block < 2 else at_theta[i]
            column = at_u[i] if block % 2 == 0 else at_theta[i]
            if row >= 0 and column >= 0:
                data[m] = uu[i] if block == 0 else (tt[i] if block == 3 else ut[i])
                rows[m], cols[m] = row, column
                m += 1
    return data[:m], rows[:m], cols[:m]
