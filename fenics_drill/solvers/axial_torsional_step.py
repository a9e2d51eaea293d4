"""Newmark steps of the axial-torsional string in one compiled call, with no Python per step.

The string is :class:`~fenics_drill.model.axial_torsional_string.AxialTorsionalString`: M, C, K in one band. Each
step solves M a + C v + K q = F_G + F_wall(q) + F_bit(q, v) + F_drive(q, v) at t + dt by Newton, with Newmark's
(gamma, beta) = (1/2 + alpha, (1 + alpha)^2 / 4) (alpha = ``time.newmark_alpha``); the tangent K + c_v C + c_a M
less the laws' derivatives is factorised in its band (LU without pivoting: c_a M dominates it) at every iterate.
An update that does not reduce the residual is cut first to just past the first kink of the bit's law along it
(the FE Newton's line search, :func:`~fenics_drill.solvers.newton.backtrack`), then by halves: a full update that
jumps the wear flats' contact ramp (v_c wide) otherwise cycles between its branches until the step is halved.

* **Wall**: at each vertex, pressed by its normal force (the soft string's, or its own axial force's at each
  accepted step: ``contact.normal_force``), the Coulomb force at the contact point by return mapping
  (:func:`~fenics_drill.model.forces.wall.coulomb._return_map`, the FE wall's law), its slip (du, R d theta_x)
  since the step's start and its stuck spring k_t; its factor kinetic where the vertex slid at the last step at
  least as fast as the static slip speed, static elsewhere
  (:mod:`~fenics_drill.model.forces.axial_torsional_wall`).
* **Bit**: the paper's law (20)-(22) (:data:`~fenics_drill.model.forces.bit_rock.LAW`) or the cutting law
  (:func:`~fenics_drill.model.forces.cutting_bit.cutting_law`) over the bottom surface one blade passage behind,
  kept here as the accepted steps' (angle, surface) where the bit turned further than ever before.
* **Drive**: u(0) held at V0 t or pushed with a constant force (hook load); theta_x(0) held at Omega t, or a top
  drive of inertia J on it turned by a PI motor torque k_p (Omega - theta_dot) + k_i z, limited to T_max, its
  integral z frozen while at the limit (:mod:`~fenics_drill.model.top_drive`).

The algorithmic damping ratio of Newmark's scheme at a mode of circular frequency omega is about alpha omega dt / 2
for omega dt << 1 (Hughes 2000, Sec. 9.3): at the first torsional modes of a long string (omega dt ~ 1e-3) it
is far below the physics' damping, so a weak stick-slip instability is not damped away.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fenics_drill.model.forces.axial_torsional_wall import _pressed_normals
from fenics_drill.model.forces.bit_rock import LAW as PAPER_LAW
from fenics_drill.model.forces.bit_rock import fraction_past_kink
from fenics_drill.model.forces.cutting_bit import cutting_law, cutting_law_kink, surface_at
from fenics_drill.model.forces.wall.coulomb import _return_map
from fenics_drill.model.kernels.compiled import kernel

#: The bit laws: none, the paper's (20)-(22), the cutting law.
NO_BIT, PAPER, CUTTING = 0, 1, 2
#: The columns of a record row.
RECORDED = ("time", "bit_velocity", "bit_angular_velocity", "bit_force", "bit_torque", "top_velocity",
            "top_angular_velocity", "top_force", "top_torque", "depth_of_cut", "vertices_stuck_on_the_wall")
#: What :func:`advance` returns on failure: the step whose Newton did not converge.
CONVERGED, NOT_CONVERGED = 0, 1


@njit(cache=True)
def band_product(band, w, x):
    """band x, ``band`` holding row i's entries of columns i - w .. i + w."""
    n = x.size
    out = np.empty(n)
    for i in range(n):
        if w <= i < n - w:  # a whole row: a loop of fixed length
            s = 0.0
            for k in range(2 * w + 1):
                s += band[i, k] * x[i - w + k]
        else:
            s = 0.0
            for j in range(max(0, i - w), min(n, i + w + 1)):
                s += band[i, j - i + w] * x[j]
        out[i] = s
    return out


@njit(cache=True)
def _largest(values):
    """max |values|."""
    out = 0.0
    for value in values:
        out = max(out, abs(value))
    return out


@njit(cache=True)
def band_solve(band, w, rhs):
    """x of band x = rhs by Gaussian elimination without pivoting; ``band`` is overwritten by its LU."""
    n = rhs.size
    x = rhs.copy()
    for k in range(n):
        inverse = 1.0 / band[k, w]
        band[k, w] = inverse  # kept as the reciprocal for the back substitution
        last = min(n, k + w + 1)
        for i in range(k + 1, last):
            factor = band[i, k - i + w] * inverse
            shift = k - i
            for j in range(k + 1, last):
                band[i, j - k + w + shift] -= factor * band[k, j - k + w]
            x[i] -= factor * x[k]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for j in range(i + 1, min(n, i + w + 1)):
            s -= band[i, j - i + w] * x[j]
        x[i] = s * band[i, w]
    return x


@njit(cache=True)
def _wall(q, wall_dofs, normal, arm, stick_stiffness, anchor, held, residual, tangent, w):
    """The wall's Coulomb forces at every vertex, at its factor ``held[k, 2]``: subtracted from ``residual``, their
    derivatives from ``tangent``; ``held[k, :2]`` becomes the forces and ``held[k, 3]`` 1 where it slides, else 0.
    Returns how many vertices stick."""
    stuck = 0
    for k in range(normal.size):
        iu, it = wall_dofs[k, 0], wall_dofs[k, 1]
        r = arm[k]
        friction = held[k, 2]
        cap = friction * abs(normal[k])
        if cap == 0.0:  # off the wall: no friction
            held[k, 0], held[k, 1], held[k, 3] = 0.0, 0.0, 0.0
            continue
        g_a, g_t = q[iu] - anchor[k, 0], r * (q[it] - anchor[k, 1])
        f_a, f_t, size = _return_map(normal[k], held[k, 0], held[k, 1], g_a, g_t, friction, stick_stiffness)
        residual[iu] -= f_a
        residual[it] -= r * f_t
        kt = stick_stiffness
        held[k, 3] = 1.0 if size > cap else 0.0
        if size <= cap:
            aa, at, tt = -kt, 0.0, -kt
            stuck += 1
        else:  # on the cone: F = cap e, e = F* / |F*|, dF/dg = -k_t cap (I - e e^T) / |F*|
            e_a, e_t = f_a / cap, f_t / cap
            shrink = cap / size
            aa, at, tt = -kt * shrink * (1.0 - e_a * e_a), kt * shrink * e_a * e_t, -kt * shrink * (1.0 - e_t * e_t)
        tangent[iu, w] -= aa
        tangent[iu, it - iu + w] -= at * r
        tangent[it, iu - it + w] -= at * r
        tangent[it, w] -= tt * r * r
        held[k, 0], held[k, 1] = f_a, f_t
    return stuck


@njit(cache=True)
def _previous_pass(surface, count, pruned, feed, passage, angle):
    return surface_at(surface[0, :count], surface[1, :count], pruned, feed, angle - passage)


@njit(cache=True)
def _residual(base, offset, w, top, bit, wall_dofs, normal, arm, wall_law, bit_kind, bit_law, drive, c_v, h, q,
              q_pred, v_pred, x, anchor, held, trial_held, surface, surface_state, tangent):
    """The residual of the step to x (the drive's held rows zero), with its tangent (from ``base`` = K + c_v C + c_a M)
    written into ``tangent`` and the wall's forces into ``trial_held``; and what is recorded of it: (residual, bit
    force, bit torque, depth of cut, stuck vertices, top force, top torque, z), then the bit's state for
    :func:`_kink`: (u_dot, omega, u - S, dS/dphi).

    M a + C v + K x - F_G = base (x - x_pred) + ``offset`` with ``offset`` = K x_pred + C v_pred - F_G, for
    a = c_a (x - x_pred) and v = v_pred + c_v (x - x_pred) (Newmark's (67)-(68)): one band product per iterate, of
    the step's increment over its predictor."""
    increment = x - q_pred
    residual = band_product(base, w, increment) + offset
    tangent[:, :] = base
    trial_held[:, :] = held
    stuck = _wall(x, wall_dofs, normal, arm, wall_law[1], anchor, trial_held, residual, tangent, w)
    tu, tt = top
    bu, bt = bit
    bit_velocity, bit_spin = v_pred[bu] + c_v * increment[bu], v_pred[bt] + c_v * increment[bt]
    bit_force = bit_torque = depth = clearance = slope = 0.0
    if bit_kind == PAPER:
        bit_force, bit_torque, d_force, d_torque_v, d_torque_w = PAPER_LAW(bit_velocity, bit_spin, bit_law[0],
                                                                           bit_law[1], bit_law[2], bit_law[3])
        tangent[bu, w] -= c_v * d_force
        tangent[bt, bu - bt + w] -= c_v * d_torque_v
        tangent[bt, w] -= c_v * d_torque_w
    elif bit_kind == CUTTING:
        cut, slope = _previous_pass(surface, int(surface_state[0]), surface_state[1] > 0.5, surface_state[2],
                                    bit_law[9], x[bt])
        clearance = x[bu] - cut
        law = cutting_law(x[bu], bit_velocity, bit_spin, cut, slope, bit_law[0], bit_law[1], bit_law[2], bit_law[3],
                          bit_law[4], bit_law[5], bit_law[6], bit_law[7], bit_law[8])
        depth, bit_force, bit_torque = law[0], law[1], law[2]
        tangent[bu, w] -= law[3] + c_v * law[7]
        tangent[bu, bt - bu + w] -= law[4]
        tangent[bt, bu - bt + w] -= law[5] + c_v * law[8]
        tangent[bt, w] -= law[6] + c_v * law[9]
    residual[bu] -= bit_force
    residual[bt] -= bit_torque
    top_force, top_torque, z = residual[tu], residual[tt], drive[8]  # what holding the top takes
    if drive[0] > 0.5:
        residual[tu] = 0.0
        tangent[tu, :] = 0.0
        tangent[tu, w] = 1.0
    else:
        top_force = drive[2]
        residual[tu] -= top_force
    if drive[3] > 0.5:
        residual[tt] = 0.0
        tangent[tt, :] = 0.0
        tangent[tt, w] = 1.0
    else:  # z = z_n + int (Omega - theta_dot) dt over the step, frozen at the motor's limit
        omega, k_p, k_i, t_max = drive[4], drive[5], drive[6], drive[7]
        z = drive[8] + omega * h - (x[tt] - q[tt])
        top_torque = k_p * (omega - v_pred[tt] - c_v * increment[tt]) + k_i * z
        if abs(top_torque) > t_max:
            top_torque, z = math.copysign(t_max, top_torque), drive[8]
        else:
            tangent[tt, w] += k_p * c_v + k_i
        residual[tt] -= top_torque
    return (residual, bit_force, bit_torque, depth, stuck, top_force, top_torque, z, bit_velocity, bit_spin, clearance,
            slope)


@njit(cache=True)
def _kink(bit_kind, bit_law, evaluated, du, dphi, c_v):
    """The fraction of a Newton update that moves the bit's (u, theta_x) by (du, dphi) just past the first kink of
    the bit's law along it (:meth:`~fenics_drill.model.forces.cutting_bit.CuttingBit.kink_step`,
    :meth:`~fenics_drill.model.forces.bit_rock.BitRock.kink_step`), from the iterate ``evaluated`` by
    :func:`_residual`; infinity if it crosses none."""
    bit_velocity, bit_spin, clearance, slope = evaluated[8], evaluated[9], evaluated[10], evaluated[11]
    if bit_kind == PAPER:
        return fraction_past_kink(bit_velocity, c_v * du)
    if bit_kind == CUTTING:
        return cutting_law_kink(bit_velocity, bit_spin, clearance, slope, du, dphi, c_v, bit_law[0], bit_law[5],
                                bit_law[6], bit_law[7], bit_law[8])
    return math.inf


@njit(cache=True)
def _attempt(base, damping, stiffness, w, gravity, top, bit, wall_dofs, normal, arm, wall_law, bit_kind, bit_law,
             drive, h, newmark, tolerance, max_iterations, q, v, a, t, anchor, held, trial_held, surface,
             surface_state, tangent):
    """One Newmark step of ``h`` from (q, v, a) at t by Newton, an update cut while it does not reduce the
    residual (at most :data:`BACKTRACKS` times: first to just past the bit law's first kink along it, then by
    halves); ``base`` = K + c_v C + c_a M at ``h``.  Returns (converged, x, recorded values of :func:`_residual`,
    iterations)."""
    gamma, beta = newmark
    c_v = gamma / (beta * h)
    q_pred = q + h * v + h * h * (0.5 - beta) * a
    v_pred = v + h * (1.0 - gamma) * a
    x = q + h * v + 0.5 * h * h * a
    if drive[0] > 0.5:
        x[top[0]] = drive[1] * (t + h)
    if drive[3] > 0.5:
        x[top[1]] = drive[4] * (t + h)
    scale = max(_largest(gravity) * q.size, abs(drive[2]), 1.0)
    offset = band_product(stiffness, w, q_pred) + band_product(damping, w, v_pred) - gravity
    ev = _residual(base, offset, w, top, bit, wall_dofs, normal, arm, wall_law, bit_kind, bit_law, drive, c_v, h, q,
                   q_pred, v_pred, x, anchor, held, trial_held, surface, surface_state, tangent)
    norm = _largest(ev[0])
    for iteration in range(max_iterations):
        dx = band_solve(tangent, w, -ev[0])
        cut, at_kink = 1.0, False
        for attempt in range(BACKTRACKS + 1):
            trial = x + cut * dx
            trial_ev = _residual(base, offset, w, top, bit, wall_dofs, normal, arm, wall_law, bit_kind, bit_law, drive,
                                 c_v, h, q, q_pred, v_pred, trial, anchor, held, trial_held, surface, surface_state,
                                 tangent)
            trial_norm = _largest(trial_ev[0])
            if trial_norm < norm or trial_norm <= tolerance * scale or (at_kink and trial_norm <= norm):
                break
            # the full update failed: next, the step just past the bit law's first kink along it (a branch the
            # tangent did not see), taken if it does not raise the residual (solvers/newton.py's backtrack)
            past = _kink(bit_kind, bit_law, ev, dx[bit[0]], dx[bit[1]], c_v) if attempt == 0 else math.inf
            at_kink = past < cut
            cut = past if at_kink else 0.5 * cut
        x, ev, norm = trial, trial_ev, trial_norm
        if norm <= tolerance * scale or cut * _largest(dx) <= ROUND_OFF * (_largest(x) + 1.0):
            return True, x, ev, iteration + 1
    return False, x, ev, max_iterations


#: Halvings of a Newton update that does not reduce the residual; halvings of a step that does not converge.
BACKTRACKS, SUBSTEP_HALVINGS = 4, 10
#: An update below this share of the state's largest entry is round-off: the iterate has converged (at small steps
#: the residual's inertia, (x - x_pred) / (beta dt^2), carries the state's round-off magnified by 1 / dt^2).
ROUND_OFF = 1e-14


@kernel
def advance(mass, damping, stiffness, w, gravity, top, bit, wall_dofs, normal, arm, press, wall_law, bit_kind,
            bit_law, drive, dt, newmark, tolerance, max_iterations, steps, stride, q, v, a, clock, anchor, held,
            surface, surface_state, records, counters):
    """Take ``steps`` steps of ``dt`` from the state (q, v, a) at ``clock[0]`` (all updated in place) and write a
    row of :data:`RECORDED` into ``records`` every ``stride`` steps.  A step whose Newton does not converge is
    taken in halves (down to dt / 2 ** :data:`SUBSTEP_HALVINGS`).  Returns (status, rows written).

    ``normal``: each vertex's normal force, pressed anew at each accepted step by ``press`` = (turn, weight, axis,
    rigidity, lengths) of :class:`~fenics_drill.model.forces.axial_torsional_wall.TensionPress` from the string's
    own axial force where its rigidity is not empty, held otherwise;
    ``wall_law``: (kinetic factor, stick stiffness, static factor, static slip speed); ``bit_law``: the law's constants (:data:`PAPER`: Gamma, alpha,
    mu, R; :data:`CUTTING`: :func:`~fenics_drill.model.forces.cutting_bit.cutting_law_constants` then the blade
    passage); ``drive``: (axial held, V0, top force, rotation held, Omega, k_p, k_i, T_max, z); ``anchor``,
    ``held``: each vertex's (u, theta_x), and (F_a, F_t, factor for the next step, 1 if sliding) at the last step; ``surface``: (2, capacity) angles and
    surfaces of the cut bottom with ``surface_state`` = (count, pruned, feed per radian); ``counters``: (steps,
    Newton iterations, steps halved), added to."""
    gamma = newmark[0]
    bu, bt = bit
    tangent, base = np.empty_like(mass), np.empty_like(mass)
    base_step = 0.0  # the step size of ``base``
    trial_held = held.copy()
    rows = 0
    for step in range(steps):
        remaining, h = dt, dt
        while remaining > 1e-9 * dt:
            h = min(h, remaining)
            if h != base_step:
                base[:, :] = stiffness + newmark[0] / (newmark[1] * h) * damping + 1.0 / (newmark[1] * h * h) * mass
                base_step = h
            ok, x, ev, iterations = _attempt(base, damping, stiffness, w, gravity, top, bit, wall_dofs, normal, arm,
                                             wall_law, bit_kind, bit_law, drive, h, newmark, tolerance, max_iterations,
                                             q, v, a, clock[0], anchor, held, trial_held, surface, surface_state,
                                             tangent)
            counters[1] += iterations
            if not ok:
                counters[2] += 1
                h *= 0.5
                if h < dt / 2.0**SUBSTEP_HALVINGS:
                    return NOT_CONVERGED, rows
                continue
            c_a = 1.0 / (newmark[1] * h * h)
            acc = (x - (q + h * v + h * h * (0.5 - newmark[1]) * a)) * c_a
            v[:] = v + h * (1.0 - gamma) * a + gamma * h * acc
            a[:] = acc
            if bit_kind == CUTTING:
                _advance_surface(surface, surface_state, bit_law[9], x[bu], x[bt])
            q[:] = x
            anchor[:, 0] = x[wall_dofs[:, 0]]
            anchor[:, 1] = x[wall_dofs[:, 1]]
            held[:, :] = trial_held
            _next_factors(held, v, wall_dofs, arm, wall_law)
            if press[3].size > 0:
                _pressed_normals(anchor[:, 0], press[0], press[1], press[2], press[3], press[4], normal)
            drive[8] = ev[7]
            clock[0] += h
            remaining -= h
            counters[0] += 1
        if (step + 1) % stride == 0 and rows < records.shape[0]:
            row = records[rows]
            row[0], row[1], row[2], row[3], row[4] = clock[0], v[bu], v[bt], ev[1], ev[2]
            row[5], row[6], row[7], row[8] = v[top[0]], v[top[1]], ev[5], ev[6]
            row[9], row[10] = ev[3], ev[4]
            rows += 1
    return CONVERGED, rows


@njit(cache=True)
def _next_factors(held, v, wall_dofs, arm, wall_law):
    """Each vertex's factor for the next step (:mod:`~fenics_drill.model.forces.axial_torsional_wall`): kinetic
    where it slid at least as fast as the static slip speed, static elsewhere."""
    kinetic, static, static_speed = wall_law[0], wall_law[2], wall_law[3]
    for k in range(held.shape[0]):
        speed = math.hypot(v[wall_dofs[k, 0]], arm[k] * v[wall_dofs[k, 1]])
        held[k, 2] = kinetic if held[k, 3] > 0.5 and speed >= static_speed else static


@njit(cache=True)
def _advance_surface(surface, surface_state, passage, position, angle):
    """Record an accepted bit state (:meth:`~fenics_drill.model.forces.cutting_bit.CutSurface.advance`): where the
    bit turned further than ever, the blade at ``angle`` leaves max(position, the surface it met); entries more
    than two revolutions behind are dropped when the storage is full."""
    count = int(surface_state[0])
    if angle <= surface[0, count - 1]:
        return
    if count == surface.shape[1]:
        keep = max(1, np.searchsorted(surface[0, :count], angle - 4.0 * math.pi) - 1)
        surface[:, :count - keep] = surface[:, keep:count].copy()
        count -= keep
        surface_state[1] = 1.0
    cut = _previous_pass(surface, count, surface_state[1] > 0.5, surface_state[2], passage, angle)[0]
    surface[0, count], surface[1, count] = angle, max(position, cut)
    surface_state[0] = count + 1
