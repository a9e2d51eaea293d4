"""A Newmark step of a modal model in one compiled call, while it keeps its tangent.

Most of the paper scene's steps (86 % over 3 s; 66 % with the printed kinematics) take the tangent that the
step before them ended with and converge in two evaluations (solvers/newmark.py, CARRY_WITHIN); most of the
others form one at their predictor and keep it.  In Python their evaluations, tests and updates cost about as
much as their kernels (docs/performance.md).  :func:`kept_tangent_step` takes such a step as
:meth:`NewmarkNewton.step` does, with its tangent's LU kept: the predictor, the residual
(:func:`~fenics_drill.solvers.compiled_residual.residual_at`), the convergence test, the settle test, the full update
and its sufficient decrease, and the contraction test that keeps the tangent.  Where that Newton would do
anything else (a fresh tangent, a fresh stiffness, a halved or kinked update, a vertex the wall's culled set may
miss, no convergence) it returns without a result, and the step is taken in Python from its start: every step is
the one :meth:`NewmarkNewton.step` takes, to round-off (98 % of the paper scene's step attempts are taken here).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fenics_drill.model.kernels.compiled import kernel
from fenics_drill.solvers.compiled_residual import NO_BIT as _NO_BIT
from fenics_drill.solvers.compiled_residual import NO_WALL as _NO_WALL
from fenics_drill.solvers.compiled_residual import residual_at


@njit(cache=True)
def _saddle_solve(factors, pivots, scale, rhs_q, rhs_c):
    """getrs of :class:`~fenics_drill.model.reduction.spaces.SaddleLU`: (dq, mu) of [[J, k B^T], [k B, 0]] from its LU
    (row interchanges ``pivots``, 0-based), the constraint rows scaled by k = ``scale``."""
    n, size = rhs_q.size, factors.shape[0]
    x = np.empty(size)
    x[:n] = rhs_q
    x[n:] = scale * rhs_c
    for i in range(size):
        p = pivots[i]
        if p != i:
            x[i], x[p] = x[p], x[i]
    for i in range(size):  # L, unit diagonal
        s = x[i]
        for j in range(i):
            s -= factors[i, j] * x[j]
        x[i] = s
    for i in range(size - 1, -1, -1):  # U
        s = x[i]
        for j in range(i + 1, size):
            s -= factors[i, j] * x[j]
        x[i] = s / factors[i, i]
    return x[:n].copy(), scale * x[n:]


@njit(cache=True)
def _constraints_met(gap, target, tolerance):
    for k in range(gap.size):
        if not abs(gap[k]) <= tolerance * max(abs(target[k]), 1.0):
            return False
    return True


@njit(cache=True)
def _moves_less_than(motion_bound, motion_rows, dq, length):
    """:meth:`NewmarkNewton._moves_less_than`."""
    if np.dot(motion_bound, np.abs(dq)) <= length:
        return True
    return np.max(np.abs(np.dot(motion_rows, dq))) <= length


@kernel
def kept_tangent_step(internal, forces, order, constraints, drive_loads, lu, mass, motion_rows, motion_bound, q0,
                      qd0, qdd0, mu0, dt, newmark, target, levels, settling, max_iterations, drifted, rates, start):
    """One step of :meth:`NewmarkNewton.step` whose Newton keeps the LU ``lu`` = (factors, pivots, k) throughout;
    the model is :func:`residual_at`'s (``internal`` to ``drive_loads``).  ``start``: the (residual, internal,
    external) forces at the predictor, evaluated already (empty arrays: evaluated here).

    ``newmark``: (gamma, beta); ``levels``: (force level, multiplier levels) of the accepted steps; ``settling``:
    (settle length, < 0 for none; SETTLED_SHARE); ``drifted``: whether a slow update would assemble df/dq afresh;
    ``rates``: (the tangent reuse rate, SLOW_CONTRACTION, SETTLED_CONTRACTION, SETTLED_FORCE_SHARE, ROUND_OFF, ARMIJO,
    tolerance).  Returns (taken, q, qd, qdd, mu, iterations, the evaluation of :func:`residual_at` at q, force
    level, multiplier levels, whether the tangent may be carried on); not taken: the step is Python's."""
    reuse_rate, slow_contraction, settled_contraction, force_share, round_off, armijo, tolerance = rates
    settle_length, settled_share = settling
    force_level, multiplier_level = levels[0], levels[1].copy()
    factors, pivots, scale = lu
    g, b = newmark
    q_pred = q0 + dt * qd0 + dt * dt * (0.5 - b) * qdd0
    qd_pred = qd0 + dt * (1.0 - g) * qdd0
    c_a = 1.0 / (b * dt * dt)
    q = q0 + dt * qd0 + 0.5 * dt * dt * qdd0
    mu = mu0.copy()
    qdd = (q - q_pred) * c_a
    qd = qd_pred + g * dt * qdd
    if start[0].size:  # the caller's evaluation at the predictor, whose culled vertices hold it
        ev = (start[0], start[1], start[2], _NO_WALL, _NO_BIT, True)
    else:
        ev = residual_at(internal, forces, order, constraints, drive_loads, q, qd, qdd, mu)
    norms, scales = np.empty(max_iterations), np.empty(max_iterations)
    kept, taken, iterations = True, False, 0
    norm = math.sqrt(np.dot(ev[0], ev[0]))
    for iteration in range(1, max_iterations + 1):
        if not ev[5] or not math.isfinite(norm):  # a vertex the culled set may miss; non-finite: Python's to report
            break
        gap = np.dot(constraints, q) - target
        muf, inertia = np.dot(constraints.T, mu), np.dot(mass, (q - q_pred) * c_a)
        scale_f = math.sqrt(max(np.dot(ev[1], ev[1]), np.dot(ev[2], ev[2]), np.dot(muf, muf),
                                np.dot(inertia, inertia), 1e-60))
        norms[iteration - 1], scales[iteration - 1] = norm, scale_f
        converged = True
        if norm > tolerance * max(force_level, scale_f):
            mass_q = np.dot(mass, q)
            converged = not norm > round_off * c_a * math.sqrt(np.dot(mass_q, mass_q))
        if converged and _constraints_met(gap, target, tolerance):
            taken, iterations = True, iteration
            break
        if not kept:  # Python would form a fresh tangent here
            break
        dq, dmu = _saddle_solve(factors, pivots, scale, -ev[0], -gap)
        contracted = iteration >= 2 and not norms[iteration - 1] > settled_contraction * norms[iteration - 2]
        if (settle_length >= 0.0 and contracted
                and _moves_less_than(motion_bound, motion_rows, dq, settled_share * settle_length)
                and not np.any(np.abs(dmu) > force_share * multiplier_level)
                and _constraints_met(gap, target, tolerance)):
            taken, iterations = True, iteration
            break
        if drifted and iteration >= 2 and norms[iteration - 1] > slow_contraction * norms[iteration - 2]:
            break  # Python would assemble df/dq afresh at the next iterate
        trial_q, trial_mu = q + dq, mu + dmu
        trial_qdd = (trial_q - q_pred) * c_a
        trial_qd = qd_pred + g * dt * trial_qdd
        trial = residual_at(internal, forces, order, constraints, drive_loads, trial_q, trial_qd, trial_qdd,
                            trial_mu)
        trial_norm = math.sqrt(np.dot(trial[0], trial[0]))
        if not trial_norm < (1.0 - armijo) * norm:
            break  # Python would halve the update or step past a kink
        previous = norm
        q, qd, qdd, mu, ev, norm = trial_q, trial_qd, trial_qdd, trial_mu, trial, trial_norm
        if norm > reuse_rate * previous:
            kept = False
    if taken:
        force_level = max(force_level, scales[iterations - 1])
        multiplier_level = np.maximum(multiplier_level, np.abs(mu))
    return taken, q, qd, qdd, mu, iterations, ev, force_level, multiplier_level, kept
