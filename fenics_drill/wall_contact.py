"""Wall impacts at the mesh vertices, Eqs. (16)-(19), (40), (50), with their tangents.

Every vertex carries the Hunt-Crossley normal force (17) (damper c |delta|^3 delta_dot),
the axial friction force (18) and the friction torque (19) in their physically
consistent form (docs/errata.md); their generalised forces are projected on the
solution space and their derivatives give the Newton tangent.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fenics_drill.discretization import BeamDiscretization
from fenics_drill.force_laws import hunt_crossley_normal_force, indentation, regularised_sign, wall_friction
from fenics_drill.reduced_space import weighted_product

#: Field index of u, v, w, theta_x in the mixed space.
U_FIELD, V_FIELD, W_FIELD, TX_FIELD = 0, 1, 2, 3


@dataclass
class WallForces:
    """Nodal state and forces of one evaluation (arrays over the vertices)."""

    indentation: np.ndarray
    in_contact: np.ndarray
    normal: np.ndarray  # F_n (<= 0)
    axial: np.ndarray  # F_a
    torque: np.ndarray  # T_FS
    generalised: np.ndarray  # [Phi]^T of (50)
    dissipative: np.ndarray  # [Phi]^T of (50) without the elastic springs -k1 delta - k2 delta^3
    potential: float  # sum of k1 delta^2 / 2 + k2 delta^4 / 4 over the vertices in contact
    derivatives: dict | None = None


class WallContact:
    """Impact and friction forces of the borehole wall on the vertices of the mesh."""

    def __init__(self, disc: BeamDiscretization, space, contact: dict, borehole_radius: float):
        self.x = disc.vertex_x
        self.gap = borehole_radius - disc.properties.outer_radius
        self.borehole_radius = borehole_radius
        self.k1, self.k2 = contact["stiffness_linear"], contact["stiffness_cubic"]
        self.c, self.mu = contact["damping"], contact["friction"]
        self.v_s = contact["sliding_velocity_scale"]
        self.rows = {f: space.rows(disc.vertex_dofs(f)) for f in (U_FIELD, V_FIELD, W_FIELD, TX_FIELD)}

    def lateral(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """v and w at every vertex."""
        return self.rows[V_FIELD] @ q, self.rows[W_FIELD] @ q

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_derivatives: bool = False) -> WallForces:
        v, w = self.lateral(q)
        delta = indentation(v, w, self.gap)
        active = np.flatnonzero(delta > 0)
        r = self.rows
        zero = np.zeros_like(q)
        if active.size == 0:
            empty = np.zeros(0)
            return WallForces(delta, delta > 0, empty, empty, empty, zero, zero, 0.0, {} if with_derivatives else None)
        rows = {f: r[f][active] for f in r}
        va, wa = v[active], w[active]
        dv, dw = rows[V_FIELD] @ qd, rows[W_FIELD] @ qd
        du, dtx = rows[U_FIELD] @ qd, rows[TX_FIELD] @ qd
        radius = np.hypot(va, wa)
        n_v, n_w = va / radius, wa / radius
        d = delta[active]
        d_rate = n_v * dv + n_w * dw
        normal = hunt_crossley_normal_force(d, d_rate, self.k1, self.k2, self.c)
        axial, torque = wall_friction(normal, du, dtx, self.mu, self.borehole_radius, self.v_s)
        elastic = -self.k1 * d - self.k2 * d**3
        generalised = (
            rows[U_FIELD].T @ axial + rows[V_FIELD].T @ (normal * n_v)
            + rows[W_FIELD].T @ (normal * n_w) + rows[TX_FIELD].T @ torque
        )
        dissipative = generalised - rows[V_FIELD].T @ (elastic * n_v) - rows[W_FIELD].T @ (elastic * n_w)
        potential = float(np.sum(0.5 * self.k1 * d**2 + 0.25 * self.k2 * d**4))
        out = WallForces(delta, delta > 0, normal, axial, torque, generalised, dissipative, potential)
        if with_derivatives:
            out.derivatives = self._derivatives(rows, n_v, n_w, radius, d, d_rate, dv, dw, du, dtx, normal)
        return out

    def _derivatives(self, rows, n_v, n_w, radius, d, d_rate, dv, dw, du, dtx, normal) -> dict:
        """Pointwise derivatives of (F_a, F_v, F_w, T) w.r.t. vertex displacements and velocities."""
        pushing = normal < 0  # where the clip of (17) is active the force and its derivatives vanish
        spring = np.where(pushing, -self.k1 - 3 * self.k2 * d**2 - 3 * self.c * d**2 * d_rate, 0.0)
        damper = np.where(pushing, -self.c * d**3, 0.0)
        # d delta / d(v, w) = n ; d delta_rate / d(v, w) = (v_dot - delta_rate n) / r
        dFn_dv = spring * n_v + damper * (dv - d_rate * n_v) / radius
        dFn_dw = spring * n_w + damper * (dw - d_rate * n_w) / radius
        dFn_ddv, dFn_ddw = damper * n_v, damper * n_w
        R, mu = self.borehole_radius, self.mu
        s_a = regularised_sign(du, self.v_s)
        s_t = regularised_sign(R * dtx, self.v_s)
        # F_a = mu F_n s_a and T = mu R F_n s_t since |F_n| = -F_n
        fa, ft = mu * s_a, mu * R * s_t
        curv = normal / radius
        U, V, W, TX = U_FIELD, V_FIELD, W_FIELD, TX_FIELD
        position = {  # (output field, input field): d F_out / d y_in
            (V, V): dFn_dv * n_v + curv * n_w**2, (V, W): dFn_dw * n_v - curv * n_v * n_w,
            (W, V): dFn_dv * n_w - curv * n_v * n_w, (W, W): dFn_dw * n_w + curv * n_v**2,
            (U, V): fa * dFn_dv, (U, W): fa * dFn_dw, (TX, V): ft * dFn_dv, (TX, W): ft * dFn_dw,
        }
        velocity = {
            (V, V): dFn_ddv * n_v, (V, W): dFn_ddw * n_v, (W, V): dFn_ddv * n_w, (W, W): dFn_ddw * n_w,
            (U, V): fa * dFn_ddv, (U, W): fa * dFn_ddw, (TX, V): ft * dFn_ddv, (TX, W): ft * dFn_ddw,
            (U, U): mu * normal * (1 - s_a**2) / self.v_s,
            (TX, TX): mu * R * normal * (1 - s_t**2) * R / self.v_s,
        }
        return {"rows": rows, "position": position, "velocity": velocity}

    @staticmethod
    def tangent(forces: WallForces, c_u: float, c_v: float):
        """c_u d f/dq + c_v d f/dqd of the generalised wall force (None without contact):
        sum over (out, in) of rows_out^T diag(c_u w_pos + c_v w_vel) rows_in."""
        if not forces.derivatives:
            return None
        rows = forces.derivatives["rows"]
        position, velocity = forces.derivatives["position"], forces.derivatives["velocity"]
        weights: dict = {}
        for scale, block in ((c_u, position), (c_v, velocity)):
            for pair, w in block.items():
                weights[pair] = weights.get(pair, 0.0) + scale * w
        if sp.issparse(rows[U_FIELD]):
            terms = (weighted_product(rows[out], w, rows[inp]) for (out, inp), w in weights.items())
            return sum(terms)
        # dense [Phi]: combine the inputs first, then one product per output field
        total = None
        for out in (U_FIELD, V_FIELD, W_FIELD, TX_FIELD):
            combined = None
            for (o, inp), w in weights.items():
                if o == out:
                    term = w[:, None] * rows[inp]
                    combined = term if combined is None else combined + term
            if combined is not None:
                product = rows[out].T @ combined
                total = product if total is None else total + product
        return total
