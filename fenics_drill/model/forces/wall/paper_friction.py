"""The paper's wall friction, Eqs. (18)-(19): an axial force -mu |F_n| sgn(u_dot) and a torque
-mu |F_n| R_bh sgn(theta_x_dot), two separate laws with Coulomb's sign regularised by tanh on a sliding speed, the
borehole's radius as the torque's arm (docs/errata.md); their signs as printed are a further option
(``contact.axial_friction_law``, ``contact.friction_torque_law``)."""

from __future__ import annotations

import numpy as np
from numba import njit


SATURATED = 19.5


@njit(cache=True, inline="always")
def _regularised_sign(x, velocity_scale):
    """tanh(x / velocity_scale): Coulomb's sgn, smoothed so Newton can converge."""
    ratio = x / velocity_scale
    if abs(ratio) > SATURATED:
        return 1.0 if ratio > 0.0 else -1.0
    return np.tanh(ratio)


@njit(cache=True, inline="always")
def _friction(normal_force, axial_velocity, spin_rate, friction, torque_friction, borehole_radius, velocity_scale):
    """(18) and (19) at one vertex: -mu |F_n| sgn(u_dot) and -mu_T |F_n| R_bh sgn(R_bh theta_x_dot)."""
    magnitude = abs(normal_force)
    return (-friction * magnitude * _regularised_sign(axial_velocity, velocity_scale),
            -torque_friction * magnitude * borehole_radius
            * _regularised_sign(borehole_radius * spin_rate, velocity_scale))


def wall_friction(normal_force, axial_velocity, spin_rate, friction, borehole_radius, velocity_scale,
                  torque_friction=None):
    """Axial friction force (18) and friction torque (19) with the magnitude |F_n|:
    F_a = -mu |F_n| sgn(u_dot), T = -mu_T |F_n| R_bh sgn(theta_x_dot) (mu_T = ``torque_friction``, mu if None).

    Both signs are tanh(x / velocity_scale): Coulomb's sgn, regularised on a sliding speed (u_dot and
    R_bh theta_x_dot) so Newton can converge.  As printed, (18) and (19) read -mu F_n sgn with F_n <= 0:
    the same laws with mu -> -mu, which push along the motion."""
    torque_friction = friction if torque_friction is None else torque_friction
    return _FRICTION(normal_force, axial_velocity, spin_rate, friction, torque_friction, borehole_radius,
                     velocity_scale)


_FRICTION = np.vectorize(_friction, otypes=(float, float))


@njit(cache=True, inline="always")
def _paper_block(b, normal, dfn_v, dfn_w, n_v, n_w, r, axial_velocity, spin_rate, mu_axial, mu_torque, radius_bh, v_s,
                 c_u, c_v):
    """The 4 x 4 block of the normal force and of (18)-(19) at one vertex, c_u d/dq + c_v d/dq_dot of
    (F_a, F_v, F_w, T) by (u, v, w, theta_x), written into ``b``; ``dfn_v``, ``dfn_w``: the normal force's
    derivatives by v and w (both parts), ``r``: the vertex's radius."""
    s_a = _regularised_sign(axial_velocity, v_s)
    s_t = _regularised_sign(radius_bh * spin_rate, v_s)
    fa, ft = mu_axial * s_a, mu_torque * radius_bh * s_t  # F_a = fa F_n, T = ft F_n
    curv = c_u * normal / r  # the turn of the normal n = (v, w) / r with the position
    b[1, 1] = dfn_v * n_v + curv * n_w * n_w
    b[1, 2] = dfn_w * n_v - curv * n_v * n_w
    b[2, 1] = dfn_v * n_w - curv * n_v * n_w
    b[2, 2] = dfn_w * n_w + curv * n_v * n_v
    b[0, 1], b[0, 2] = fa * dfn_v, fa * dfn_w
    b[3, 1], b[3, 2] = ft * dfn_v, ft * dfn_w
    b[0, 0] = c_v * mu_axial * normal * (1.0 - s_a * s_a) / v_s
    b[3, 3] = c_v * mu_torque * radius_bh * normal * (1.0 - s_t * s_t) * radius_bh / v_s
