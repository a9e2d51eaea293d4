"""Wall impacts at the mesh vertices, Eqs. (16)-(19), (40), (50), with their tangents.

Every vertex carries the Hunt-Crossley normal force (17) (damper c |delta|^3 delta_dot),
the axial friction force (18) and the friction torque (19) in their physically
consistent form (docs/errata.md): the normal force never pulls the string towards the
wall, and friction never does positive work.  The pointwise laws come first, then
:class:`WallContact` projects them on the solution space and differentiates them
for the Newton tangent.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from fenics_drill.model.discretization import THETA_X as TX_FIELD
from fenics_drill.model.discretization import U as U_FIELD
from fenics_drill.model.discretization import V as V_FIELD
from fenics_drill.model.discretization import W as W_FIELD
from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.forces.protocol import ForceEvaluation
from fenics_drill.scene import LAW_SIGN

FIELDS = (U_FIELD, V_FIELD, W_FIELD, TX_FIELD)  # the fields the wall acts on: F_a, F_v, F_w, T_FS


def indentation(v, w, gap):
    """delta_FS = r - gap, r = sqrt(v^2 + w^2), Eq. (16); positive in contact."""
    return np.hypot(v, w) - gap


def hunt_crossley_damper(delta, delta_rate, damping, law="consistent"):
    """The damper of Eq. (17) and its derivatives (F_d, dF_d/d delta, dF_d/d delta_dot).

    'consistent': -c |delta|^3 delta_dot, Hunt and Crossley's damper, a force with c in N s/m^4;
    'printed': -c |delta_dot|^3 delta_dot as printed, which has no force's unit (docs/errata.md) and
    grows with the impact speed instead of the indentation.  Both dissipate."""
    delta, delta_rate = np.asarray(delta, dtype=float), np.asarray(delta_rate, dtype=float)
    if law == "printed":
        cubed = np.abs(delta_rate) ** 3
        return -damping * cubed * delta_rate, np.zeros_like(delta), -4.0 * damping * cubed
    cubed = np.abs(delta) ** 3
    return -damping * cubed * delta_rate, -3.0 * damping * delta**2 * delta_rate, -damping * cubed


def hunt_crossley_normal_force(delta, delta_rate, stiffness_linear, stiffness_cubic, damping, law="consistent"):
    """Radial force on the string (<= 0: towards the axis), Eq. (17) with the damper of ``law``
    (:func:`hunt_crossley_damper`).

    Zero out of contact, and clipped at zero so the damper never makes the wall pull.
    """
    delta = np.asarray(delta, dtype=float)
    in_contact = delta > 0
    d = np.where(in_contact, delta, 0.0)
    force = -stiffness_linear * d - stiffness_cubic * d**3 + hunt_crossley_damper(d, delta_rate, damping, law)[0]
    return np.where(in_contact, np.minimum(force, 0.0), 0.0)


def regularised_sign(x, velocity_scale):
    """tanh(x / velocity_scale): Coulomb's sgn, smoothed so Newton can converge."""
    return np.tanh(np.asarray(x, dtype=float) / velocity_scale)


def wall_friction(normal_force, axial_velocity, spin_rate, friction, borehole_radius, velocity_scale,
                  torque_friction=None):
    """Axial friction force (18) and friction torque (19) with the magnitude |F_n|:
    F_a = -mu |F_n| sgn(u_dot), T = -mu_T |F_n| R_bh sgn(theta_x_dot) (mu_T = ``torque_friction``, mu if None).

    Both signs are regularised on a sliding speed: u_dot and R_bh theta_x_dot.  As printed, (18) and
    (19) read -mu F_n sgn with F_n <= 0: the same laws with mu -> -mu, which push along the motion."""
    torque_friction = friction if torque_friction is None else torque_friction
    magnitude = np.abs(normal_force)
    force = -friction * magnitude * regularised_sign(axial_velocity, velocity_scale)
    torque = -torque_friction * magnitude * borehole_radius * regularised_sign(
        borehole_radius * np.asarray(spin_rate), velocity_scale)
    return force, torque


class ProjectedLaws(Mapping):
    """The generalised forces of the non-conservative wall laws (the damper of (17), (18), (19)),
    projected on first use: the energy budget reads them at accepted steps only, not at Newton's
    iterates."""

    NAMES = ("wall_damper", "wall_axial_friction", "wall_friction_torque")

    def __init__(self, flat, loads: np.ndarray | None, size: int):
        self._flat, self._loads, self._size, self._projected = flat, loads, size, None

    def _laws(self) -> dict[str, np.ndarray]:
        if self._projected is None:
            if self._loads is None:
                self._projected = dict.fromkeys(self.NAMES, np.zeros(self._size))
            else:
                projected = np.asarray(self._flat.T @ self._loads.reshape(-1, len(self.NAMES)))
                self._projected = {name: projected[:, k] for k, name in enumerate(self.NAMES)}
        return self._projected

    def __getitem__(self, name: str) -> np.ndarray:
        return self._laws()[name]

    def __iter__(self):
        return iter(self.NAMES)

    def __len__(self) -> int:
        return len(self.NAMES)


@dataclass
class WallForces(ForceEvaluation):
    """Nodal state and forces of one evaluation (arrays over the vertices).

    ``generalised`` is [Phi]^T of (50); ``laws`` splits its non-conservative part into the damper of
    (17), the axial friction (18) and the friction torque (19); ``potential`` is the sum of
    k1 delta^2 / 2 + k2 delta^4 / 4 over the vertices in contact."""

    indentation: np.ndarray = None
    in_contact: np.ndarray = None
    normal: np.ndarray = None  # F_n (<= 0)
    axial: np.ndarray = None  # F_a
    torque: np.ndarray = None  # T_FS
    derivatives: dict | None = None


class WallContact:
    """Impact and friction forces of the borehole wall on the vertices of the mesh."""

    name: ClassVar[str] = "wall"
    switch: ClassVar[str] = "contact"
    conservative: ClassVar[bool] = False
    recorded: ClassVar[dict] = {
        "vertices_in_contact": ("1", "vertices in contact with the wall at the end of the step"),
    }

    def __init__(self, disc: BeamDiscretization, space, contact, borehole_radius: float,
                 law_sign: tuple[float, float] = (1.0, 1.0), damper_law: str = "consistent"):
        """``contact``: the scene's [contact] section; ``law_sign``: +1 (consistent) or -1 (as printed) for
        the axial friction (18) and the friction torque (19); ``damper_law``: the damper of (17)."""
        self.x = disc.vertex_x
        self.gap = borehole_radius - disc.properties.outer_radius
        self.borehole_radius = borehole_radius
        self.k1, self.k2 = contact.stiffness_linear, contact.stiffness_cubic
        self.c = contact.damping
        self.damper_law = damper_law
        # the friction coefficient of each law, negative for a law taken as printed (scene.LAW_SIGN)
        self.mu_axial = law_sign[0] * contact.friction
        self.mu_torque = law_sign[1] * contact.friction
        self.v_s = contact.sliding_velocity_scale
        # the rows of [Phi] of (u, v, w, theta_x) at every vertex, interleaved: row 4 i + k is field k at
        # vertex i, so one product gives all four fields at all vertices and projects all their forces
        by_field = [space.rows(disc.vertex_dofs(f)) for f in FIELDS]
        n = len(self.x)
        order = (np.arange(len(FIELDS))[None, :] * n + np.arange(n)[:, None]).ravel()
        if space.sparse:
            self.flat = sp.vstack(by_field, format="csr")[order]
        else:
            self.flat = np.ascontiguousarray(np.vstack(by_field)[order])
        # the rows of (v, w) alone, interleaved the same way: who touches the wall is known from these
        lateral = (len(FIELDS) * np.arange(n)[:, None] + np.array([1, 2])).ravel()
        self.lateral_rows = self.flat[lateral] if space.sparse else np.ascontiguousarray(self.flat[lateral])

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "WallContact":
        signs = (LAW_SIGN[scene.law(scene.contact.axial_friction_law)],
                 LAW_SIGN[scene.law(scene.contact.friction_torque_law)])
        return cls(disc, space, scene.contact, scene.borehole.radius, signs, scene.law(scene.contact.damper_law))

    def with_stiffness_scale(self, factor: float) -> "WallContact":
        """A copy whose wall springs k_FS1, k_FS2 are scaled by ``factor`` (the static continuation)."""
        scaled = copy.copy(self)
        scaled.k1, scaled.k2 = factor * self.k1, factor * self.k2
        return scaled

    def record(self, forces: "WallForces") -> dict[str, float]:
        return {"vertices_in_contact": int(forces.in_contact.sum())}

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> WallForces:
        """The wall force at (q, qd).  The rows of (v, w) find the vertices in contact; the law and its
        projection touch those only, and the law-by-law split is projected only when read."""
        lateral = (self.lateral_rows @ q).reshape(-1, 2)
        delta = indentation(lateral[:, 0], lateral[:, 1], self.gap)
        in_contact = delta > 0
        active = np.flatnonzero(in_contact)
        if active.size == 0:
            empty = np.zeros(0)
            return WallForces(np.zeros_like(q), 0.0, ProjectedLaws(self.flat, None, q.size), delta, in_contact,
                              empty, empty, empty, {} if with_tangent else None)
        du, dv, dw, dtx = (self.flat @ qd).reshape(-1, len(FIELDS))[active].T
        va, wa = lateral[active, 0], lateral[active, 1]
        radius = delta[active] + self.gap
        n_v, n_w = va / radius, wa / radius
        d = delta[active]
        d_rate = n_v * dv + n_w * dw
        normal = hunt_crossley_normal_force(d, d_rate, self.k1, self.k2, self.c, self.damper_law)
        axial, torque = wall_friction(normal, du, dtx, self.mu_axial, self.borehole_radius, self.v_s, self.mu_torque)
        nodal = np.zeros((len(delta), len(FIELDS)))  # (F_a, F_v, F_w, T) at every vertex
        nodal[active] = np.column_stack([axial, normal * n_v, normal * n_w, torque])
        # nodal loads of each non-conservative law: the damper (the clip that keeps the wall from pulling
        # included), the axial friction and the friction torque
        damper = normal + self.k1 * d + self.k2 * d**3
        laws = np.zeros((len(delta), len(FIELDS), len(ProjectedLaws.NAMES)))
        laws[active, 1, 0], laws[active, 2, 0] = damper * n_v, damper * n_w
        laws[active, 0, 1] = axial
        laws[active, 3, 2] = torque
        potential = float(np.sum(0.5 * self.k1 * d**2 + 0.25 * self.k2 * d**4))
        out = WallForces(np.asarray(self.flat.T @ nodal.ravel()), potential, ProjectedLaws(self.flat, laws, q.size),
                         delta, in_contact, normal, axial, torque)
        if with_tangent:  # what the tangent needs, differentiated only if Newton asks for it
            out.derivatives = {"at": (active, n_v, n_w, radius, d, d_rate, dv, dw, du, dtx, normal)}
        return out

    def _blocks(self, active, n_v, n_w, radius, d, d_rate, dv, dw, du, dtx, normal,
                c_u: float, c_v: float) -> np.ndarray:
        """c_u d(F_a, F_v, F_w, T)/d(u, v, w, theta_x) + c_v d(...)/d(velocities) at every vertex in
        contact: one 4 x 4 block per vertex, rows and columns in the order of FIELDS."""
        pushing = normal < 0  # where the clip of (17) is active the force and its derivatives vanish
        _, damper_by_delta, damper_by_rate = hunt_crossley_damper(d, d_rate, self.c, self.damper_law)
        spring = np.where(pushing, -self.k1 - 3 * self.k2 * d**2 + damper_by_delta, 0.0)
        damper = np.where(pushing, damper_by_rate, 0.0)
        # F_n as a function of (v, w, v_dot, w_dot): d delta / d(v, w) = n, d delta_rate / d(v, w) =
        # (v_dot - delta_rate n) / r, d delta_rate / d(v_dot, w_dot) = n; combined with c_u and c_v
        dFn_v = c_u * (spring * n_v + damper * (dv - d_rate * n_v) / radius) + c_v * damper * n_v
        dFn_w = c_u * (spring * n_w + damper * (dw - d_rate * n_w) / radius) + c_v * damper * n_w
        R, mu_a, mu_t = self.borehole_radius, self.mu_axial, self.mu_torque
        s_a = regularised_sign(du, self.v_s)
        s_t = regularised_sign(R * dtx, self.v_s)
        fa, ft = mu_a * s_a, mu_t * R * s_t  # F_a = fa F_n and T = ft F_n, since |F_n| = -F_n
        curv = c_u * normal / radius  # the turn of the normal n = (v, w) / r with the position
        blocks = np.zeros((active.size, len(FIELDS), len(FIELDS)))
        blocks[:, 1, 1] = dFn_v * n_v + curv * n_w**2
        blocks[:, 1, 2] = dFn_w * n_v - curv * n_v * n_w
        blocks[:, 2, 1] = dFn_v * n_w - curv * n_v * n_w
        blocks[:, 2, 2] = dFn_w * n_w + curv * n_v**2
        blocks[:, 0, 1], blocks[:, 0, 2] = fa * dFn_v, fa * dFn_w
        blocks[:, 3, 1], blocks[:, 3, 2] = ft * dFn_v, ft * dFn_w
        blocks[:, 0, 0] = c_v * mu_a * normal * (1 - s_a**2) / self.v_s
        blocks[:, 3, 3] = c_v * mu_t * R * normal * (1 - s_t**2) * R / self.v_s
        return blocks

    def tangent(self, forces: WallForces, c_u: float, c_v: float):
        """c_u d f/dq + c_v d f/dqd of the generalised wall force (None without contact):
        sum over the vertices in contact of R_i^T A_i R_i, with R_i the four rows of [Phi] of
        vertex i and A_i the 4 x 4 block of the pointwise derivatives."""
        if not forces.derivatives:
            return None
        active = forces.derivatives["at"][0]
        weights = self._blocks(*forces.derivatives["at"], c_u, c_v)
        rows = (len(FIELDS) * active[:, None] + np.arange(len(FIELDS))).ravel()
        block = self.flat[rows]
        if sp.issparse(block):
            diagonal = sp.bsr_matrix((weights, np.arange(active.size), np.arange(active.size + 1)),
                                     shape=(rows.size, rows.size))
            return sp.csr_matrix(block.T @ (diagonal @ block))
        size = block.shape[1]
        return block.T @ np.matmul(weights, block.reshape(active.size, len(FIELDS), size)).reshape(rows.size, size)
