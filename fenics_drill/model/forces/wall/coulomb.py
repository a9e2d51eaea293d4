"""One Coulomb force at the contact point (the default friction): the slip of the contact point since the step's
start and the return mapping onto the friction cone (Simo & Hughes 1998, Sec. 1.2; Wriggers 2006, Sec. 5.2), with
the 4 x 4 block of its derivatives at a vertex (module doc of :mod:`~fenics_drill.model.forces.wall_contact`)."""

from __future__ import annotations

import numpy as np
from numba import njit

from fenics_drill.model.kernels.compiled import kernel


@njit(cache=True, inline="always")
def _return_map(normal_force, held_axial, held_tangential, axial_slip, tangential_slip, friction, stick_stiffness):
    """The Coulomb force at the contact point after a slip (g_a, g_t) of the contact point since the step's start,
    by return mapping: the trial force of the stuck contact, F* = F_n - k_t g (F_n: the force at the step's start),
    kept if |F*| <= mu |F_n| (stick), else scaled back onto the cone, mu |F_n| F* / |F*| (slip).  Returns
    (F_a, F_t, |F*|)."""
    trial_a = held_axial - stick_stiffness * axial_slip
    trial_t = held_tangential - stick_stiffness * tangential_slip
    size = np.hypot(trial_a, trial_t)
    cap = friction * abs(normal_force)
    if size <= cap:
        return trial_a, trial_t, size
    return cap * trial_a / size, cap * trial_t / size, size


def coulomb_friction(normal_force, held_axial, held_tangential, axial_slip, tangential_slip, friction,
                     stick_stiffness):
    """One Coulomb force at the contact point, by return mapping (:func:`_return_map`): (F_a, F_t) with
    |F| <= mu |F_n|, the stuck contact's spring k_t below it and the cone's surface, opposing the trial's slip,
    above; the arguments broadcast as NumPy's arrays do."""
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (normal_force, held_axial, held_tangential,
                                                                          axial_slip, tangential_slip, friction)))
    flat = [np.ascontiguousarray(a).ravel() for a in arrays]
    axial, tangential = _return_maps(*flat, float(stick_stiffness))
    return axial.reshape(arrays[0].shape), tangential.reshape(arrays[0].shape)


@kernel
def _return_maps(normal_force, held_axial, held_tangential, axial_slip, tangential_slip, friction, stick_stiffness):
    """:func:`_return_map` at each entry of the arrays (``friction`` too: each contact's factor)."""
    axial, tangential = np.empty(normal_force.size), np.empty(normal_force.size)
    for i in range(normal_force.size):
        axial[i], tangential[i], _ = _return_map(normal_force[i], held_axial[i], held_tangential[i], axial_slip[i],
                                                 tangential_slip[i], friction[i], stick_stiffness)
    return axial, tangential


@njit(cache=True, inline="always")
def _contact_slip(i, v, w, n_v, n_w, positions, anchor, arm):
    """(g_a, g_t): the contact point's slip since the step's start, axial and along the wall's tangent
    t = (-n_w, n_v): the axial move, and t . (v, w) plus the pipe's surface turned, R_ext theta_x, from the
    anchor (the vertex's (u, v, w, theta_x) at the step's start)."""
    g_a = positions[i, 0] - anchor[i, 0]
    g_t = -n_w * (v - anchor[i, 1]) + n_v * (w - anchor[i, 2]) + arm[i] * (positions[i, 3] - anchor[i, 3])
    return g_a, g_t


@njit(cache=True, inline="always")
def _coulomb_block(b, i, normal, dfn_v, dfn_w, n_v, n_w, r, positions, anchor, held, sticking, mu, arm,
                   stick_stiffness, c_u):
    """The 4 x 4 block of the normal force and the Coulomb force at the contact point of vertex i, c_u d/dq +
    c_v d/dq_dot of (F_a, F_v, F_w, T) by (u, v, w, theta_x) (the c_v part is the damper's, in ``dfn_v``,
    ``dfn_w``), written into ``b``.  With t = (-n_w, n_v), d t / d(v, w) = (n_v n_w, -n_v^2; n_w^2, -n_v n_w) / r
    and the slip g of :func:`_contact_slip`, the trial force F* = F_n - k_t g moves by dF* = -k_t dg; stuck,
    dF = dF*; slipping (F = M e, M = mu |F_n|, e = F* / |F*|), dF = dM e + M (I - e e^T) dF* / |F*|."""
    t_v, t_w = -n_w, n_v
    magnitude = -mu * normal
    sticking = sticking and magnitude > 0.0  # no friction: the normal force's block alone
    f_a = f_t = size = 0.0
    g_v = g_w = 0.0
    if sticking:
        g_v, g_w = positions[i, 1] - anchor[i, 1], positions[i, 2] - anchor[i, 2]
        g_a, g_t = _contact_slip(i, positions[i, 1], positions[i, 2], n_v, n_w, positions, anchor, arm)
        f_a, f_t, size = _return_map(normal, held[i, 0], held[i, 1], g_a, g_t, mu, stick_stiffness)
    slipping = sticking and size > magnitude
    e_a, e_t = (f_a / magnitude, f_t / magnitude) if slipping else (0.0, 0.0)
    shrink = magnitude / size if slipping else 1.0
    turn = c_u / r
    for j in range(4):
        if j == 1:
            dfn, dn_v, dn_w = dfn_v, turn * n_w * n_w, -turn * n_v * n_w
        elif j == 2:
            dfn, dn_v, dn_w = dfn_w, -turn * n_v * n_w, turn * n_v * n_v
        else:
            dfn, dn_v, dn_w = 0.0, 0.0, 0.0
        df_a = df_t = 0.0
        if sticking:
            # d g = (du, t . d(v, w) + d t . (v - v0, w - w0) + R d theta_x), dt = (-dn_w, dn_v)
            dg_a = c_u if j == 0 else 0.0
            dg_t = -dn_w * g_v + dn_v * g_w
            if j == 1:
                dg_t += c_u * t_v
            elif j == 2:
                dg_t += c_u * t_w
            elif j == 3:
                dg_t += c_u * arm[i]
            df_a, df_t = -stick_stiffness * dg_a, -stick_stiffness * dg_t
            if slipping:
                along = e_a * df_a + e_t * df_t
                d_magnitude = -mu * dfn
                df_a = d_magnitude * e_a + shrink * (df_a - along * e_a)
                df_t = d_magnitude * e_t + shrink * (df_t - along * e_t)
        b[0, j] = df_a
        b[1, j] = dfn * n_v + normal * dn_v + df_t * t_v - f_t * dn_w
        b[2, j] = dfn * n_w + normal * dn_w + df_t * t_w + f_t * dn_v
        b[3, j] = arm[i] * df_t
