"""Wall impacts at the mesh vertices, Eqs. (16)-(19), (40), (50), with their tangents.

Every vertex in contact carries the Hunt-Crossley normal force (17) (damper c |delta|^3 delta_dot) and friction,
by one of two laws (``contact.friction_model``):

- ``coulomb`` (the default): one Coulomb force at the contact point, opposing the slip velocity of the pipe's
  surface against the wall, s = (u_dot, t . (v_dot, w_dot) + R_ext theta_x_dot), with t the wall's tangent in
  the cross-section, with |F| <= mu |F_n|.  It is computed by return mapping (Simo & Hughes 1998, Sec. 1.2;
  Wriggers 2006, Sec. 5.2): over a step the contact point's slip g since the step's start loads a stiff tangential
  spring k_t (``contact.stick_stiffness``) from the force F_0 the vertex held then, F* = F_0 - k_t g, and the force
  is F* while |F*| <= mu |F_n| (stick; the spring's give is mu |F_n| / k_t, 0.6 um on the paper's string) and
  mu |F_n| F* / |F*| otherwise (slip, opposing it).  It acts as an axial force, a lateral force along t and a
  torque R_ext F_t about the pipe's axis.  So rotation takes the drag away (the axial share is u_dot / |s|), and
  the string can climb the wall, roll and whirl.  Stick and slip are each linear or constant in the step's
  unknowns, where a velocity regularisation tanh(|s| / v_s) is neither on the scale of v_s.  k_t = 1e8 N/m puts
  the switch between them on the scale of a Newton update (1e-7 - 1e-6 m): at 1e10 N/m, as stiff as the wall,
  a 1000 m string whose far part stops spinning under friction all at once (0.16-0.26 s after the start) had
  hundreds of vertices switch within 1e-8 m, Newton's line search stalled on the switches and the step
  collapsed (over 0.16-0.25 s: 194 steps, 190 failed Newton solves and 3479 iterations, where 1e8 N/m takes 33
  steps and 433 iterations); the paper's nominal scene gives the same rop and efficiency at both to 1e-6.
- ``paper``: (18) and (19) as two separate laws, -mu |F_n| sgn(u_dot) and -mu |F_n| R_bh sgn(theta_x_dot), with
  the borehole radius as the torque's arm (docs/errata.md); their signs as printed are a further option.

The pointwise laws come first, then :class:`WallContact` projects them on the solution space and differentiates
them for the Newton tangent.
"""

from __future__ import annotations

import copy
import functools
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import scipy.sparse as sp
from numba import njit

from fenics_drill.model.kernels.compiled import REASSOCIATE, kernel
from fenics_drill.model.discretization import THETA_X as TX_FIELD
from fenics_drill.model.discretization import U as U_FIELD
from fenics_drill.model.discretization import V as V_FIELD
from fenics_drill.model.discretization import W as W_FIELD
from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.forces.protocol import ForceEvaluation
from fenics_drill.model.kernels.packed_rows import FieldPackedRows, add_row, dot_row_twice, gathered, scatter
from fenics_drill.scene import LAW_SIGN

FIELDS = (U_FIELD, V_FIELD, W_FIELD, TX_FIELD)  # the fields the wall acts on: F_a, F_v, F_w, T_FS


@njit(cache=True, inline="always")
def _damper(delta, delta_rate, damping, printed):
    """The damper of (17) at one vertex and its derivatives (F_d, dF_d/d delta, dF_d/d delta_dot)."""
    if printed:
        cubed = abs(delta_rate) ** 3
        return -damping * cubed * delta_rate, 0.0, -4.0 * damping * cubed
    cubed = abs(delta) ** 3
    return -damping * cubed * delta_rate, -3.0 * damping * delta * delta * delta_rate, -damping * cubed


@njit(cache=True, inline="always")
def _normal_force(delta, delta_rate, stiffness_linear, stiffness_cubic, damping, printed):
    """Radial force (17) at one vertex: zero out of contact, and clipped at zero."""
    if delta <= 0.0:
        return 0.0
    force = (-stiffness_linear * delta - stiffness_cubic * delta**3
             + _damper(delta, delta_rate, damping, printed)[0])
    return min(force, 0.0)


#: Above this |x|, tanh(x) rounds to +-1 in double precision (from 18.99): the friction torque of a spinning
#: string is there at every vertex, and the sign costs less than the call.
SATURATED = 19.5


@njit(cache=True, inline="always")
def _regularised_sign(x, velocity_scale):
    """tanh(x / velocity_scale): Coulomb's sgn, smoothed so Newton can converge."""
    ratio = x / velocity_scale
    if abs(ratio) > SATURATED:
        return 1.0 if ratio > 0.0 else -1.0
    return np.tanh(ratio)


def hunt_crossley_damper(delta, delta_rate, damping, law="consistent"):
    """The damper of Eq. (17) and its derivatives (F_d, dF_d/d delta, dF_d/d delta_dot).

    'consistent': -c |delta|^3 delta_dot, Hunt and Crossley's damper, a force with c in N s/m^4;
    'printed': -c |delta_dot|^3 delta_dot as printed, which has no force's unit (docs/errata.md) and
    grows with the impact speed instead of the indentation.  Both dissipate."""
    return _DAMPER(delta, delta_rate, damping, law == "printed")


def hunt_crossley_normal_force(delta, delta_rate, stiffness_linear, stiffness_cubic, damping, law="consistent"):
    """Radial force on the string (<= 0: towards the axis), Eq. (17) with the damper of ``law``
    (:func:`hunt_crossley_damper`).

    Zero out of contact, and clipped at zero so the damper never makes the wall pull.
    """
    return _NORMAL_FORCE(delta, delta_rate, stiffness_linear, stiffness_cubic, damping, law == "printed")


_DAMPER = np.vectorize(_damper, otypes=(float, float, float))
_NORMAL_FORCE = np.vectorize(_normal_force, otypes=(float,))


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
    above."""
    return _COULOMB(normal_force, held_axial, held_tangential, axial_slip, tangential_slip, friction,
                    stick_stiffness)[:2]


_COULOMB = np.vectorize(_return_map, otypes=(float, float, float))


@njit(cache=True, inline="always")
def _contact_slip(i, v, w, n_v, n_w, positions, anchor, arm):
    """(g_a, g_t): the contact point's slip since the step's start, axial and along the wall's tangent
    t = (-n_w, n_v): the axial move, and t . (v, w) plus the pipe's surface turned, R_ext theta_x, from the
    anchor (the vertex's (u, v, w, theta_x) at the step's start)."""
    g_a = positions[i, 0] - anchor[i, 0]
    g_t = -n_w * (v - anchor[i, 1]) + n_v * (w - anchor[i, 2]) + arm[i] * (positions[i, 3] - anchor[i, 3])
    return g_a, g_t


@njit(cache=True, inline="always")
def _vertex_law(i, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                stick_stiffness, anchor, held, sticking, delta, nodal, laws):
    """Eqs. (16)-(19) at vertex i with position (u, v, w, theta_x) (row i of ``positions``) and rates (their
    time derivatives, row i of ``rates``; both read in place: a row view per vertex costs more than the law out of
    contact): its indentation, nodal loads and the loads of each law (the damper; the axial friction; the
    friction torque, or with ``coulomb`` the tangential part of the one friction force, lateral and torque);
    returns the springs' energy.  ``gap``: each vertex's clearance; ``arm``: each vertex's friction torque's arm,
    its contact radius for the Coulomb force at the contact point, R_bh in (19).  The Coulomb force
    (:func:`_return_map`) starts from each vertex's ``anchor`` and ``held`` force at the step's start; without
    ``sticking`` (no step under way: a static state) it is zero."""
    v, w = positions[i, 1], positions[i, 2]
    r = np.hypot(v, w)
    d = r - gap[i]
    delta[i] = d
    if d <= 0.0:
        return 0.0
    n_v, n_w = v / r, w / r
    normal = _normal_force(d, n_v * rates[i, 1] + n_w * rates[i, 2], k1, k2, damping, printed)
    damper = normal + k1 * d + k2 * d**3  # with the clip that keeps the wall from pulling
    laws[i, 1, 0], laws[i, 2, 0] = damper * n_v, damper * n_w
    if coulomb:  # t = (-n_w, n_v): the wall's tangent, the direction the contact point turns with theta_x
        axial = tangential = 0.0
        if sticking:
            g_a, g_t = _contact_slip(i, v, w, n_v, n_w, positions, anchor, arm)
            axial, tangential, _ = _return_map(normal, held[i, 0], held[i, 1], g_a, g_t, mu_axial, stick_stiffness)
        nodal[i, 0], nodal[i, 3] = axial, arm[i] * tangential
        nodal[i, 1], nodal[i, 2] = normal * n_v - tangential * n_w, normal * n_w + tangential * n_v
        laws[i, 0, 1] = axial
        laws[i, 1, 2], laws[i, 2, 2], laws[i, 3, 2] = -tangential * n_w, tangential * n_v, arm[i] * tangential
    else:
        axial, torque = _friction(normal, rates[i, 0], rates[i, 3], mu_axial, mu_torque, arm[i], v_s)
        nodal[i, 0], nodal[i, 1], nodal[i, 2], nodal[i, 3] = axial, normal * n_v, normal * n_w, torque
        laws[i, 0, 1] = axial
        laws[i, 3, 2] = torque
    return 0.5 * k1 * d**2 + 0.25 * k2 * d**4


@kernel
def _vertex_loads(positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                  stick_stiffness, anchor, held, sticking):
    """Eqs. (16)-(19) at every vertex of (u, v, w, theta_x) ``positions`` and their ``rates``: indentation, nodal
    loads (F_a, F_v, F_w, T), the loads of the damper and of the two parts of friction (vertex, field, law), and
    the springs' energy."""
    n = positions.shape[0]
    delta, nodal, laws = np.empty(n), np.zeros((n, 4)), np.zeros((n, 4, 3))
    potential = 0.0
    for i in range(n):
        potential += _vertex_law(i, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm,
                                 v_s, coulomb, stick_stiffness, anchor, held, sticking, delta, nodal, laws)
    return delta, nodal, laws, potential


@kernel(fastmath=REASSOCIATE)
def _modal_pass(packed, size, q, qd, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                stick_stiffness, anchor, held, sticking):
    """:func:`_vertex_loads` in a modal space (``size`` coordinates), in one pass over the rows of [Phi] of
    (u, v, w, theta_x) at each vertex, interleaved and packed by field (``packed``: :meth:`~fenics_drill.model.
    packed_rows.FieldPackedRows.kernel_data`, groups in the order of FIELDS): each vertex's positions and
    rates, its law, and [Phi]^T of its nodal loads, while its rows are in cache.  Also returns the positions
    and rates.  The split by law is left to :func:`_projected_laws` (the budget reads it at accepted steps
    only: in the pass it cost a sixth of the pass at every Newton iterate)."""
    values, _, columns, counts = packed
    n = values.shape[0] // 4
    q_at, qd_at = gathered(q, columns), gathered(qd, columns)
    q_u, q_v, q_w, q_t = q_at[0], q_at[1], q_at[2], q_at[3]
    qd_u, qd_v, qd_w, qd_t = qd_at[0], qd_at[1], qd_at[2], qd_at[3]
    c_u, c_v, c_w, c_t = counts[0], counts[1], counts[2], counts[3]
    loads = np.zeros(columns.shape)
    load_u, load_v, load_w, load_t = loads[0], loads[1], loads[2], loads[3]
    delta, nodal, laws = np.empty(n), np.zeros((n, 4)), np.zeros((n, 4, 3))
    positions, rates = np.empty((n, 4)), np.empty((n, 4))
    potential = 0.0
    for i in range(n):
        r = 4 * i
        positions[i, 0], rates[i, 0] = dot_row_twice(values, r, q_u, qd_u, c_u)
        positions[i, 1], rates[i, 1] = dot_row_twice(values, r + 1, q_v, qd_v, c_v)
        positions[i, 2], rates[i, 2] = dot_row_twice(values, r + 2, q_w, qd_w, c_w)
        positions[i, 3], rates[i, 3] = dot_row_twice(values, r + 3, q_t, qd_t, c_t)
        potential += _vertex_law(i, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s,
                                 coulomb, stick_stiffness, anchor, held, sticking, delta, nodal, laws)
        if delta[i] > 0.0:
            add_row(load_u, values, r, nodal[i, 0], c_u)
            add_row(load_v, values, r + 1, nodal[i, 1], c_v)
            add_row(load_w, values, r + 2, nodal[i, 2], c_w)
            add_row(load_t, values, r + 3, nodal[i, 3], c_t)
    generalised = np.zeros(size)
    scatter(generalised, columns, counts, loads)
    return delta, nodal, laws, potential, generalised, positions, rates


#: :func:`_modal_pass` itself, for compiled code that evaluates the wall (solvers/compiled_residual.py).
MODAL_PASS = _modal_pass.compiled


@kernel(fastmath=REASSOCIATE)
def _projected_laws(packed, size, delta, laws):
    """[Phi]^T of the loads of each law (the damper and the two parts of friction: rows of the result), over the
    vertices in contact (delta > 0) of the packed rows of :func:`_modal_pass`."""
    values, _, columns, counts = packed
    by_law = np.zeros((3,) + columns.shape)  # each law's packed sums, by field
    for i in range(delta.size):
        if delta[i] > 0.0:
            r = 4 * i
            for law in range(3):
                for f in range(4):
                    if laws[i, f, law] != 0.0:
                        add_row(by_law[law, f], values, r + f, laws[i, f, law], counts[f])
    projected = np.zeros((3, size))
    for law in range(3):
        scatter(projected[law], columns, counts, by_law[law])
    return projected


@kernel
def _contact_blocks(active, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                    stick_stiffness, anchor, held, sticking, c_u, c_v):
    """c_u d(F_a, F_v, F_w, T)/d(u, v, w, theta_x) + c_v d(...)/d(velocities) at every vertex in contact:
    one 4 x 4 block per vertex, rows and columns in the order of FIELDS."""
    blocks = np.zeros((active.size, 4, 4))
    for k in range(active.size):
        i = active[k]
        v, w = positions[i, 1], positions[i, 2]
        r = np.hypot(v, w)
        d = r - gap[i]
        n_v, n_w = v / r, w / r
        dv, dw = rates[i, 1], rates[i, 2]
        d_rate = n_v * dv + n_w * dw
        normal = _normal_force(d, d_rate, k1, k2, damping, printed)
        if normal >= 0.0:  # where the clip of (17) is active the force and its derivatives vanish
            continue
        _, damper_by_delta, damper_by_rate = _damper(d, d_rate, damping, printed)
        spring = -k1 - 3.0 * k2 * d * d + damper_by_delta
        # F_n of (v, w, v_dot, w_dot): d delta / d(v, w) = n, d delta_rate / d(v, w) = (v_dot - delta_rate n) / r,
        # d delta_rate / d(v_dot, w_dot) = n
        dfn_v = c_u * (spring * n_v + damper_by_rate * (dv - d_rate * n_v) / r) + c_v * damper_by_rate * n_v
        dfn_w = c_u * (spring * n_w + damper_by_rate * (dw - d_rate * n_w) / r) + c_v * damper_by_rate * n_w
        if coulomb:
            _coulomb_block(blocks[k], i, normal, dfn_v, dfn_w, n_v, n_w, r, positions, anchor, held, sticking,
                           mu_axial, arm, stick_stiffness, c_u)
            continue
        radius_bh = arm[i]
        s_a = _regularised_sign(rates[i, 0], v_s)
        s_t = _regularised_sign(radius_bh * rates[i, 3], v_s)
        fa, ft = mu_axial * s_a, mu_torque * radius_bh * s_t  # F_a = fa F_n, T = ft F_n
        curv = c_u * normal / r  # the turn of the normal n = (v, w) / r with the position
        b = blocks[k]
        b[1, 1] = dfn_v * n_v + curv * n_w * n_w
        b[1, 2] = dfn_w * n_v - curv * n_v * n_w
        b[2, 1] = dfn_v * n_w - curv * n_v * n_w
        b[2, 2] = dfn_w * n_w + curv * n_v * n_v
        b[0, 1], b[0, 2] = fa * dfn_v, fa * dfn_w
        b[3, 1], b[3, 2] = ft * dfn_v, ft * dfn_w
        b[0, 0] = c_v * mu_axial * normal * (1.0 - s_a * s_a) / v_s
        b[3, 3] = c_v * mu_torque * radius_bh * normal * (1.0 - s_t * s_t) * radius_bh / v_s
    return blocks


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


@kernel
def _weighted_rows(packed, active, blocks):
    """R and A R by field, in single precision, from the rows of (u, v, w, theta_x) at the vertices ``active``,
    packed by field (:meth:`~fenics_drill.model.kernels.packed_rows.FieldPackedRows.kernel_data`, groups in the order of
    FIELDS), and the blocks A of :func:`_contact_blocks`.  With the fields' columns concatenated (field g's at
    ``offsets[g]``), ``rows[f]`` holds each vertex's row of field f on its own columns and ``weighted[f]`` its
    row f of A R on all of them; the wall's tangent is the sum over f of rows[f]^T weighted[f] (block row f),
    scattered onto the columns (:func:`_scattered_square`): a quarter of the dense product R^T (A R)."""
    values, _, columns, counts = packed
    offsets = np.zeros(5, dtype=np.int64)
    for f in range(4):
        offsets[f + 1] = offsets[f] + counts[f]
    rows = np.zeros((4, active.size, columns.shape[1]), dtype=np.float32)
    weighted = np.zeros((4, active.size, offsets[4]), dtype=np.float32)
    for k in range(active.size):
        base = 4 * active[k]
        for f in range(4):
            for c in range(counts[f]):
                rows[f, k, c] = values[base + f, c]
        for o in range(4):
            for f in range(4):
                a = blocks[k, o, f]
                if a != 0.0:
                    for c in range(counts[f]):
                        weighted[o, k, offsets[f] + c] += a * values[base + f, c]
    return rows, weighted, offsets


@kernel
def _scattered_square(matrix, columns, counts, packed):
    """matrix[i, j] += packed[a, b] with i, j the columns of the packed rows' concatenated fields a, b."""
    index = np.empty(packed.shape[0], dtype=np.int64)
    at = 0
    for f in range(counts.size):
        for c in range(counts[f]):
            index[at] = columns[f, c]
            at += 1
    for a in range(index.size):
        for b in range(index.size):
            matrix[index[a], index[b]] += packed[a, b]
    return matrix


@kernel
def _moved_blocks(vertices, blocks, kept, tolerance):
    """The vertices whose block moved by more than ``tolerance`` times the largest block, (vertex, field,
    field) ``kept`` against the ``blocks`` of the ``vertices`` in contact (zero elsewhere): their indices,
    the increments of their blocks, and the kept blocks with theirs replaced.  Scalar loops, without
    temporaries or views: it runs at every wall tangent."""
    n, fields = kept.shape[0], kept.shape[1]
    at = np.full(n, -1)  # each vertex's block among ``blocks`` (-1: out of contact, a zero block)
    for k in range(vertices.size):
        at[vertices[k]] = k
    scale = 0.0
    for value in kept.reshape(-1):
        scale = max(scale, abs(value))
    for value in blocks.reshape(-1):
        scale = max(scale, abs(value))
    limit = tolerance * scale
    moved = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        k = at[i]
        for a in range(fields):
            for b in range(fields):
                if abs((blocks[k, a, b] if k >= 0 else 0.0) - kept[i, a, b]) > limit:
                    moved[i] = True
    changed = np.flatnonzero(moved)
    increments = np.empty((changed.size, fields, fields))
    updated = kept.copy()
    for j in range(changed.size):
        i = changed[j]
        k = at[i]
        for a in range(fields):
            for b in range(fields):
                current = blocks[k, a, b] if k >= 0 else 0.0
                increments[j, a, b] = current - kept[i, a, b]
                updated[i, a, b] = current
    return changed, increments, updated


def _selection(rows: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
    """(column, value) of each row of a full space's [Phi] rows, which hold one entry or none (a dof held by
    a support: column -1, value 0)."""
    counts = np.diff(rows.indptr)
    if counts.max(initial=0) > 1:
        raise ValueError("rows of the full space's [Phi] hold one entry each")
    columns, values = np.full(rows.shape[0], -1, dtype=np.int64), np.zeros(rows.shape[0])
    first = rows.indptr[:-1][counts == 1]
    columns[counts == 1], values[counts == 1] = rows.indices[first], rows.data[first]
    return columns, values


class ProjectedLaws(Mapping):
    """The generalised forces of the non-conservative wall laws (the damper of (17) and the two parts of friction:
    axial and tangential for the Coulomb force, (18) and (19) for the paper's), projected on first use: the energy
    budget reads them at accepted steps only, not at Newton's iterates."""

    def __init__(self, vertex_set: "VertexSet", delta: np.ndarray, loads: np.ndarray, names: tuple[str, ...]):
        """``vertex_set``: the vertices evaluated, with their rows; ``delta``, ``loads``: their indentations and the
        loads of each law (vertex, field, law), named ``names``."""
        self._rows, self._delta, self._loads, self._projected = vertex_set, delta, loads, None
        self.NAMES = names

    def _laws(self) -> dict[str, np.ndarray]:
        if self._projected is None:
            rows = self._rows
            if sp.issparse(rows.flat):
                projected = np.asarray(rows.flat.T @ self._loads.reshape(-1, len(self.NAMES))).T
            else:
                projected = _projected_laws(rows.packed.kernel_data(), rows.flat.shape[1], self._delta,
                                            self._loads)
            self._projected = dict(zip(self.NAMES, projected))
        return self._projected

    def __getitem__(self, name: str) -> np.ndarray:
        return self._laws()[name]

    def __iter__(self):
        return iter(self.NAMES)

    def __len__(self) -> int:
        return len(self.NAMES)


@dataclass
class WallForces(ForceEvaluation):
    """Nodal state and forces of one evaluation.

    ``generalised`` is [Phi]^T of (50); ``laws`` splits its non-conservative part into the damper of
    (17), the axial friction (18) and the friction torque (19); ``potential`` is the sum of
    k1 delta^2 / 2 + k2 delta^4 / 4 over the vertices in contact.  The arrays over the vertices are
    derived on first read (Newton's iterates read none of them)."""

    vertex_count: int = 0
    vertices: np.ndarray = None  # the vertices evaluated
    delta: np.ndarray = None  # their indentations
    nodal: np.ndarray = None  # their loads (F_a, F_v, F_w, T)
    tangent_data: tuple | None = None  # what :meth:`WallContact.tangent` needs, if asked for
    tangential_arm: np.ndarray | None = None  # Coulomb force: each vertex's torque arm (T = R F_t); None: no lateral part

    @functools.cached_property
    def indentation(self) -> np.ndarray:
        """delta of (16) at every vertex; -inf at the vertices left out (too far from the wall)."""
        out = np.full(self.vertex_count, -np.inf)
        out[self.vertices] = self.delta
        return out

    @functools.cached_property
    def in_contact(self) -> np.ndarray:
        """Whether each vertex touches the wall (delta > 0)."""
        out = np.zeros(self.vertex_count, dtype=bool)
        out[self.vertices[self.delta > 0]] = True
        return out

    @functools.cached_property
    def _active(self) -> np.ndarray:
        return self.nodal[self.delta > 0]

    @property
    def normal(self) -> np.ndarray:
        """F_n (<= 0) at the vertices in contact: the lateral load less its friction part along the wall, which is
        normal to it (|F_lateral|^2 = F_n^2 + F_t^2, F_t = T / R_ext)."""
        lateral = np.hypot(self._active[:, 1], self._active[:, 2])
        if self.tangential_arm is None:
            return -lateral
        tangential = self._active[:, 3] / self.tangential_arm[self.vertices[self.delta > 0]]
        return -np.sqrt(np.maximum(lateral**2 - tangential**2, 0.0))

    @property
    def axial(self) -> np.ndarray:
        """F_a at the vertices in contact."""
        return self._active[:, 0]

    @property
    def torque(self) -> np.ndarray:
        """T_FS at the vertices in contact."""
        return self._active[:, 3]


@dataclass(frozen=True)
class VertexSet:
    """Vertices the wall law is evaluated at, with their rows of [Phi]: all of them, or those that can
    reach the wall while q stays near ``q_ref`` (:meth:`WallContact._near_vertices`)."""

    vertices: np.ndarray
    lateral_rows: object  # (v, w) of each vertex, interleaved
    flat: object  # (u, v, w, theta_x) of each vertex, interleaved
    packed: FieldPackedRows | None  # the same, packed by field (a modal space's)
    q_ref: np.ndarray | None = None
    column_bound: np.ndarray | None = None
    reach: float = np.inf


class WallContact:
    """Impact and friction forces of the borehole wall on the vertices of the mesh."""

    name: ClassVar[str] = "wall"
    switch: ClassVar[str] = "contact"
    conservative: ClassVar[bool] = False
    recorded: ClassVar[dict] = {
        "vertices_in_contact": ("1", "vertices in contact with the wall at the end of the step"),
    }

    def __init__(self, disc: BeamDiscretization, space, contact, borehole_radius: float,
                 law_sign: tuple[float, float] = (1.0, 1.0), damper_law: str = "consistent", culling: bool = True):
        """``contact``: the scene's [contact] section (its ``friction_model`` chooses the friction law);
        ``law_sign``: +1 (consistent) or -1 (as printed) for the axial friction (18) and the friction torque (19)
        of the paper's model; ``damper_law``: the damper of (17); ``culling``: evaluate the law only at the
        vertices that can reach the wall (exact)."""
        self.x = disc.vertex_x
        contact_radius, hole_radius = disc.vertex_radii(borehole_radius)
        self.gap = hole_radius - contact_radius  # per vertex
        self.coulomb = contact.friction_model == "coulomb"
        # the friction torque's arm: the pipe's surface, where the Coulomb force acts; the borehole's radius in (19)
        self.arm = contact_radius if self.coulomb else hole_radius
        self.law_names = ("wall_damper", "wall_friction_axial", "wall_friction_tangential") if self.coulomb else \
            ("wall_damper", "wall_axial_friction", "wall_friction_torque")
        self.k1, self.k2 = contact.stiffness_linear, contact.stiffness_cubic
        self.c = contact.damping
        self.damper_law = damper_law
        # the friction coefficient of each law, negative for a law taken as printed (scene.LAW_SIGN)
        self.mu_axial = law_sign[0] * contact.friction
        self.mu_torque = law_sign[1] * contact.friction
        self.v_s = contact.sliding_velocity_scale
        self.stick_stiffness = contact.stick_stiffness
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
        lateral_rows = self.flat[lateral] if space.sparse else np.ascontiguousarray(self.flat[lateral])
        field_of_row = np.tile(np.arange(len(FIELDS)), n)  # the groups of the packed rows: FIELDS' order
        self.every = VertexSet(np.arange(n), lateral_rows, self.flat,
                               None if space.sparse else FieldPackedRows.of(self.flat, field_of_row))
        # |P_i[:, j]|_1 of each vertex's (v, w) rows P_i: |(v, w)_i(q) - (v, w)_i(q_ref)| <= sum_j of it |dq_j|
        self._column_sizes = abs(lateral_rows[0::2]) + abs(lateral_rows[1::2])
        self.culling = culling
        self._near = None  # the VertexSet of the last culled evaluation
        self._kept_tangent = None  # (matrix, blocks, updates) of the modal tangent (:meth:`_updated_tangent`)
        # the Coulomb force's memory at the last accepted state: each vertex's (u, v, w, theta_x) and friction
        # (F_a, F_t); None outside a run (a static state: no friction)
        self._history = None
        # a full-order string split over MPI ranks: (comm, whether each vertex is this rank's); None: one rank
        self._share = None
        self._mine = None  # (vertex set, this rank's vertices among them, their rows) of the last shared evaluation

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "WallContact":
        signs = (LAW_SIGN[scene.law(scene.contact.axial_friction_law)],
                 LAW_SIGN[scene.law(scene.contact.friction_torque_law)])
        return cls(disc, space, scene.contact, scene.borehole.radius, signs, scene.law(scene.contact.damper_law),
                   scene.contact.culling)

    def with_stiffness_scale(self, factor: float) -> "WallContact":
        """A copy whose wall springs k_FS1, k_FS2 are scaled by ``factor`` (the static continuation)."""
        scaled = copy.copy(self)
        scaled.k1, scaled.k2 = factor * self.k1, factor * self.k2
        scaled._kept_tangent = None
        return scaled

    def fresh(self) -> "WallContact":
        """A copy whose modal tangent is formed afresh and whose friction has no memory yet (a simulation's results
        never depend on another's)."""
        changed = copy.copy(self)
        changed._kept_tangent = None
        changed._history = None
        return changed

    def split_over(self, comm, owned: np.ndarray) -> "WallContact":
        """A copy for a full-order string split over the ranks of ``comm`` (:mod:`~fenics_drill.model.kernels.
        split_band`): the law runs at the vertices this rank ``owned`` only and the ranks' loads are summed, so
        every rank holds the whole evaluation; the tangent is this rank's vertices' own.  The friction's memory,
        updated at accepted steps only, stays every vertex's on every rank."""
        split = copy.copy(self)
        split._share, split._mine, split._near = (comm, owned), None, None
        return split

    def begin(self, t: float, q: np.ndarray) -> None:
        """Start the Coulomb force's memory at the initial state: anchored at q, no force yet."""
        if self.coulomb:
            self._history = ((self.flat @ q).reshape(-1, len(FIELDS)), np.zeros((len(self.x), 2)))

    def accept(self, t: float, q: np.ndarray, qd: np.ndarray) -> None:
        """Anchor the Coulomb force at an accepted state, holding the force each vertex feels there."""
        if not self.coulomb or self._history is None:
            return
        positions = (self.flat @ q).reshape(-1, len(FIELDS))
        rates = (self.flat @ qd).reshape(-1, len(FIELDS))
        _, nodal, _, _ = _vertex_loads(positions, rates, *self._law())
        self._history = (positions, np.column_stack([nodal[:, 0], nodal[:, 3] / self.arm]))

    def kept_on_wall(self, q_from: np.ndarray, q: np.ndarray) -> np.ndarray:
        """q with each vertex that touched the wall at ``q_from`` moved radially to the indentation it had there
        (full space: its (v, w) rows select dofs): a Newmark predictor extrapolates along a straight line, off the
        round wall."""
        lateral = self.every.lateral_rows
        before = (lateral @ q_from).reshape(-1, 2)
        now = (lateral @ q).reshape(-1, 2)
        r_before, r_now = np.hypot(*before.T), np.hypot(*now.T)
        touching = (r_before > self.gap) & (r_now > 0.0)
        scale = np.ones_like(r_now)
        scale[touching] = r_before[touching] / r_now[touching]
        columns, _ = _selection(lateral)
        columns = columns.reshape(-1, 2)
        out = q.copy()
        for k in range(2):
            free = columns[:, k] >= 0
            out[columns[free, k]] *= scale[free]
        return out

    def record(self, forces: "WallForces") -> dict[str, float]:
        return {"vertices_in_contact": int(np.count_nonzero(forces.delta > 0))}

    def _law(self, vertices: np.ndarray | None = None) -> tuple:
        """The law's constants at ``vertices`` (default: all), with the Coulomb force's memory there, in the order
        the compiled kernels take them."""
        at = slice(None) if vertices is None else vertices
        history = self._history
        count = len(self.x) if vertices is None else len(vertices)
        anchor, held = (np.zeros((count, len(FIELDS))), np.zeros((count, 2))) if history is None else \
            (np.ascontiguousarray(history[0][at]), np.ascontiguousarray(history[1][at]))
        return (np.ascontiguousarray(self.gap[at]), self.k1, self.k2, self.c, self.damper_law == "printed",
                self.mu_axial, self.mu_torque, np.ascontiguousarray(self.arm[at]), self.v_s, self.coulomb,
                self.stick_stiffness, anchor, held, history is not None)

    def memory(self):
        """What the law's constants depend on besides the vertices: the Coulomb force's memory (its identity
        changes at each accepted step)."""
        return self._history

    #: Vertices within this share of the gap from the wall are evaluated; the others are left out until
    #: q has moved enough, by the bound of :meth:`_near_vertices`, to possibly bring one of them to it.
    NEAR = 0.5

    def _near_vertices(self, q: np.ndarray) -> VertexSet:
        """The vertices that can touch the wall at q, exactly.  At a reference state q_ref the radius of
        every vertex is computed; those farther than NEAR gap from the wall are then left out while
        sum_j c_j |q_j - q_ref_j| < min of their distances to the wall, with c_j the largest
        |P_i[:, j]|_1 among them: by the triangle inequality none of them can have reached it."""
        near = self._near
        if near is not None and near.column_bound @ np.abs(q - near.q_ref) < near.reach:
            return near
        radius = np.hypot(*(self.every.lateral_rows @ q).reshape(-1, 2).T)
        slack = self.gap - radius  # each vertex's distance to the wall
        far = slack > self.NEAR * self.gap
        watched = far if far.any() else np.ones_like(far)  # without far vertices: every vertex, until q moves
        sizes = self._column_sizes[np.flatnonzero(watched)].max(axis=0)
        column_bound = sizes.toarray().ravel() if sp.issparse(sizes) else np.asarray(sizes).ravel()
        reach = float(np.min(slack[far])) if far.any() else self.NEAR * float(np.min(self.gap))
        vertices = np.flatnonzero(~far)
        rows = (len(FIELDS) * vertices[:, None] + np.arange(len(FIELDS))).ravel()
        lateral = (2 * vertices[:, None] + np.arange(2)).ravel()
        packed = None if self.every.packed is None else self.every.packed.at(rows)
        self._near = VertexSet(vertices, self.every.lateral_rows[lateral], self.flat[rows], packed, q.copy(),
                               column_bound, reach)
        return self._near

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> WallForces:
        """The wall force at (q, qd).  The rows of (v, w) find the vertices in contact, the law runs
        compiled over the vertices that can reach the wall, and the law-by-law split is projected only
        when read.  The indentation is -inf at the vertices left out."""
        vertex_set = self._near_vertices(q) if self.culling else self.every
        if self._share is not None:
            return self._shared_evaluation(vertex_set, q, qd, with_tangent)
        if sp.issparse(vertex_set.flat):  # the full space: the rows select dofs
            positions = (vertex_set.flat @ q).reshape(-1, len(FIELDS))
            rates = (vertex_set.flat @ qd).reshape(-1, len(FIELDS))
            delta, nodal, laws, potential = _vertex_loads(positions, rates, *self._law(vertex_set.vertices))
            generalised = np.asarray(vertex_set.flat.T @ nodal.ravel())
        else:
            delta, nodal, laws, potential, generalised, positions, rates = _modal_pass(
                vertex_set.packed.kernel_data(), q.size, q, qd, *self._law(vertex_set.vertices))
        return self.forces_of(vertex_set, (delta, nodal, laws, potential, generalised, positions, rates),
                              with_tangent)

    def _shared_evaluation(self, vertex_set: VertexSet, q: np.ndarray, qd: np.ndarray,
                           with_tangent: bool) -> WallForces:
        """:meth:`evaluate` on a string split over ranks (:meth:`split_over`): the law at this rank's vertices of
        ``vertex_set``; the generalised force, the indentations, the loads and the energy summed over the ranks in
        one collective (each vertex is one rank's, so each sum has one term but the energy's)."""
        comm, owned = self._share
        if self._mine is None or self._mine[0] is not vertex_set:
            mine = np.flatnonzero(owned[vertex_set.vertices])
            rows = (len(FIELDS) * mine[:, None] + np.arange(len(FIELDS))).ravel()
            self._mine = (vertex_set, mine, vertex_set.flat[rows])
        _, mine, flat = self._mine
        positions = (flat @ q).reshape(-1, len(FIELDS))
        rates = (flat @ qd).reshape(-1, len(FIELDS))
        delta_mine, nodal_mine, laws_mine, potential = _vertex_loads(positions, rates,
                                                                     *self._law(vertex_set.vertices[mine]))
        m, size, names = vertex_set.vertices.size, q.size, len(self.law_names)
        ends = np.cumsum([size, m, m * len(FIELDS), m * len(FIELDS) * names, 1])
        part = np.zeros(ends[-1])
        generalised, delta, nodal, laws, energy = np.split(part, ends[:-1])
        generalised[:] = flat.T @ nodal_mine.ravel()
        delta.reshape(m)[mine] = delta_mine
        nodal.reshape(m, len(FIELDS))[mine] = nodal_mine
        laws.reshape(m, len(FIELDS), names)[mine] = laws_mine
        energy[0] = potential
        total = np.empty_like(part)
        comm.Allreduce(part, total)
        generalised, delta, nodal, laws, energy = np.split(total, ends[:-1])
        out = self.forces_of(vertex_set, (delta, nodal.reshape(m, len(FIELDS)), laws.reshape(m, len(FIELDS), names),
                                          float(energy[0]), generalised, None, None), False)
        if with_tangent:
            out.tangent_data = (flat, positions, rates, vertex_set.vertices[mine], delta_mine)
        return out

    def forces_of(self, vertex_set: VertexSet, passed: tuple, with_tangent: bool) -> WallForces:
        """The evaluation of the vertices ``vertex_set`` from what :func:`_modal_pass` gives for them (also what a
        compiled Newton step hands back: solvers/compiled_step.py)."""
        delta, nodal, laws, potential, generalised, positions, rates = passed
        by_law = ProjectedLaws(vertex_set, delta, laws, self.law_names)
        out = WallForces(generalised, potential, by_law, len(self.x), vertex_set.vertices, delta, nodal,
                         tangential_arm=self.arm if self.coulomb else None)
        if with_tangent:  # what the tangent needs, differentiated only if Newton asks for it
            out.tangent_data = (vertex_set.flat, positions, rates, vertex_set.vertices, delta)
        return out

    def evaluated_vertices(self) -> VertexSet:
        """The vertices the next modal evaluation starts from: the culled set of the last one (None before any),
        or all of them without culling; each evaluation checks the culled set's bound itself."""
        return self._near if self.culling else self.every

    def kernel_data(self, vertex_set: VertexSet) -> tuple:
        """(the packed rows of ``vertex_set``, the law's constants, and the bound that keeps it: its columns'
        sizes, reference q and reach; none for every vertex) for
        :func:`~fenics_drill.solvers.compiled_residual.residual_at`."""
        size = vertex_set.flat.shape[1]
        law = tuple(value if isinstance(value, (bool, np.ndarray)) else float(value)
                    for value in self._law(vertex_set.vertices))
        rows = vertex_set.packed.kernel_data()
        if vertex_set.q_ref is None:
            return rows, law, np.zeros(size), np.zeros(size), np.inf
        return rows, law, vertex_set.column_bound, vertex_set.q_ref, float(vertex_set.reach)

    def tangent(self, forces: WallForces, c_u: float, c_v: float):
        """c_u d f/dq + c_v d f/dqd of the generalised wall force (None without contact):
        sum over the vertices in contact of R_i^T A_i R_i, with R_i the four rows of [Phi] of
        vertex i and A_i the 4 x 4 block of the pointwise derivatives.  In a modal space the product is
        formed in single precision (half the cost of the step's largest product): the tangent only steers
        Newton, and the residual, in double precision, decides when it has converged."""
        if forces.tangent_data is None:
            return None
        flat, positions, rates, vertices, delta = forces.tangent_data
        active = np.flatnonzero(delta > 0)
        if active.size == 0:
            return None
        blocks = _contact_blocks(active, positions, rates, *self._law(vertices), c_u, c_v)
        if sp.issparse(flat):  # the full space: each row of [Phi] selects one free dof (or none, at a support)
            columns, values = _selection(flat)
            at = len(FIELDS) * active[:, None] + np.arange(len(FIELDS))
            dofs, scale = columns[at], values[at]
            rows, columns = np.broadcast_arrays(dofs[:, :, None], dofs[:, None, :])
            data = scale[:, :, None] * blocks * scale[:, None, :]
            kept = (rows >= 0) & (columns >= 0) & (data != 0.0)
            return sp.coo_matrix((data[kept], (rows[kept], columns[kept])), shape=(flat.shape[1],) * 2)
        return self._updated_tangent(vertices[active], blocks)

    #: A vertex's block enters the modal tangent afresh when it changed by more than this share of the largest
    #: block since it last did; the tangent then differs from the exact one by less than that share of the
    #: largest block at each vertex (Newton's residual, exact, still decides convergence).
    BLOCK_TOLERANCE = 1e-4
    #: Updates of the kept tangent after which it is formed whole again: each adds the single-precision
    #: round-off of its own product, and this bounds their sum.
    UPDATES_BEFORE_REFORMING = 100

    def _updated_tangent(self, vertices: np.ndarray, blocks: np.ndarray) -> np.ndarray:
        """sum_i R_i^T A_i R_i in a modal space, with the blocks A_i of the vertices in contact, as an update
        of the last tangent formed: R_i^T (A_i - A_i_kept) R_i is added for the vertices whose block moved by
        more than BLOCK_TOLERANCE of the largest one, and the others keep theirs.  In steady contact a step's
        tangent changes at a fraction of the vertices, and so costs a fraction of the whole product; where
        most blocks moved it is formed whole."""
        kept = self._kept_tangent
        if kept is None or kept[2] >= self.UPDATES_BEFORE_REFORMING:
            size = self.flat.shape[1]
            kept = (np.zeros((size, size)), np.zeros((len(self.x), len(FIELDS), len(FIELDS))), 0)
            tolerance = 0.0  # every block in contact enters
        else:
            tolerance = self.BLOCK_TOLERANCE
        matrix, kept_blocks, updates = kept
        changed, increments, moved_blocks = _moved_blocks(vertices, blocks, kept_blocks, tolerance)
        if updates and 2 * changed.size > vertices.size:
            # most blocks moved (a change of step, contact lost): formed whole, as cheap, and without the
            # round-off of larger blocks that an update would leave in a smaller tangent
            self._kept_tangent = None
            return self._updated_tangent(vertices, blocks)
        kept_blocks = moved_blocks
        if changed.size:
            packed = self.every.packed
            rows, weighted, offsets = _weighted_rows(packed.kernel_data(), changed, increments)
            by_field = np.empty((offsets[-1], offsets[-1]), dtype=np.float32)
            for f in range(len(FIELDS)):  # block row f: R_f^T (A R)_f, one single-precision BLAS product
                by_field[offsets[f]:offsets[f + 1]] = rows[f, :, :packed.counts[f]].T @ weighted[f]
            matrix = _scattered_square(matrix.copy(), packed.columns, packed.counts, by_field.astype(float))
        self._kept_tangent = (matrix, kept_blocks, updates + 1)
        return matrix
