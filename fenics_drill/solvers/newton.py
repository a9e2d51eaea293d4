"""Newton's method on the saddle-point system (76), shared by the static solver and the Newmark step.

Each iteration solves [[J, B^T], [B, 0]] (dq, dmu) = -(r, [B] q - h) in the
solution space and takes the largest step of a backtracking line search on the
residual norm (Armijo's sufficient decrease).  The wall law (17) has a kink at first
contact and the bit-rock law (20) one at u_dot_bit = 0; a full Newton update can jump
from one branch to the other and back forever, and halving the update until the
residual norm decreases stops that.  Once a full update of a solve fails that test, the
solve's line searches measure a trial by its Newton correction J^-1 r with the iterate's
factorisation against the update's instead (natural monotonicity, Deuflhard 2004,
Sec. 3.3): the residual's 2-norm weighs the stiff wall springs of resting vertices that
switch between stuck and sliding along the update, and halving on it crawled (measured:
docs/performance.md, "Newton's iterations").  What counts as converged is the caller's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

#: Halvings of a Newton update before the last one is taken anyway.
HALVINGS = 6
#: Sufficient decrease: accept when |r(step)| < (1 - ARMIJO step) |r(0)|.
ARMIJO = 1e-4


def backtrack(trial, norm0: float, step: float = 1.0, kink=None):
    """Largest step = step / 2^k (k < HALVINGS) whose ``trial(step) -> (norm, payload)`` decreases
    the norm enough; returns (step, norm, payload) of the accepted (or last) trial.

    ``kink()``: the step just past the first kink of a force law along the update (a branch the tangent
    did not see), or None; asked only when the first trial fails, it is tried next and the halving goes
    on from it.  The kink's trial is taken if it does not raise the norm: its purpose is the new branch's
    tangent, and from an iterate that sits on the kink itself it is a step of a few ulps, which cannot
    decrease the norm by Armijo's share."""
    at_kink = False
    for attempt in range(HALVINGS):
        norm, payload = trial(step)
        if norm < (1.0 - ARMIJO * step) * norm0 or (at_kink and norm <= norm0):
            break
        past = kink() if attempt == 0 and kink is not None else None
        at_kink = past is not None and past < step
        step = past if at_kink else 0.5 * step
    return step, norm, payload


@dataclass
class KeptTangent:
    """The tangent a Newton solve last used, offered to the next solve of the same system (a modified Newton
    across Newmark steps of one size: the same tangent and its factorisation, Deuflhard 2004, Sec. 2.1).
    Its owner empties it when the system changes (another step size, internal tangent parts assembled
    afresh)."""

    matrix: object = None


def saddle_newton(evaluate: Callable, space, constraints: np.ndarray, target: np.ndarray, q: np.ndarray,
                  mu: np.ndarray, evaluation, check: Callable, max_iterations: int,
                  first_step: Callable[[np.ndarray], float] | None = None, reuse_rate: float = 0.0,
                  kink_step: Callable | None = None, settled: Callable | None = None,
                  kept: KeptTangent | None = None):
    """Iterate from (q, mu), whose ``evaluation`` (with ``.residual`` and ``.tangent``) is given.

    ``evaluate(q, mu)`` evaluates a trial state.  Before each update
    ``check(iteration, q, mu, evaluation, norm, gap)`` returns the result to stop with,
    or None to go on (it may raise).  ``first_step(dq)`` limits the move of an update (default 1: none);
    a limited update is taken without the line search, as a trust region's step: far from the solution
    (a straight string falling onto the wall) the residual need not decrease along it.  With
    ``reuse_rate`` > 0 the tangent of an earlier iterate is kept while each full update shrinks the
    residual norm at least by that factor (a modified Newton with a convergence-rate test; Deuflhard
    2004, Sec. 2.1); a slower or damped update takes a fresh one.  The line search measures a trial by its
    residual norm until a full update fails, then by its natural level (module doc).
    ``kink_step(evaluation, dq)`` gives the fraction of an update just past the first kink of a force
    law along it (None if there is none before the full update): the line search's second trial.
    ``settled(iteration, q, mu, evaluation, dq, dmu, gap)`` may stop with a verdict once the next update
    (dq, dmu) is known to be negligible, before it is taken (an iterate need not be evaluated again to
    learn that it is converged).  ``kept``: the first update takes its tangent, if it holds one, and the
    rate test above judges it as any kept tangent; it holds this solve's last tangent on return.  Returns
    None when ``max_iterations`` updates did not satisfy ``check``.
    """
    norm = math.sqrt(evaluation.residual @ evaluation.residual)
    natural = False  # set once a full update fails: the solve's line searches are natural from then on
    kept = KeptTangent() if kept is None else kept
    tangent = kept.matrix
    for iteration in range(1, max_iterations + 1):
        gap = constraints @ q - target
        verdict = check(iteration, q, mu, evaluation, norm, gap)
        if verdict is not None:
            return verdict
        if tangent is None:
            tangent = kept.matrix = evaluation.tangent
        dq, dmu = space.saddle_solve(tangent, constraints, -evaluation.residual, -gap)
        if settled is not None:
            verdict = settled(iteration, q, mu, evaluation, dq, dmu, gap)
            if verdict is not None:
                return verdict

        def trial(step, level=norm, update=math.sqrt(dq @ dq), solved=tangent):
            """The trial's merit on the scale of ``level`` (the iterate's residual norm): its residual norm until
            a full update of this solve fails to decrease it enough, from then on its Newton correction with the
            iterate's factorisation against the update's (natural monotonicity)."""
            nonlocal natural
            point = (q + dq, mu + dmu) if step == 1.0 else (q + step * dq, mu + step * dmu)
            result = evaluate(*point)
            residual = math.sqrt(result.residual @ result.residual)
            natural = natural or (step == 1.0 and not residual < (1.0 - ARMIJO) * level)
            if not natural or update == 0.0:
                return residual, (point, result, residual)
            correction, _ = space.saddle_solve(solved, constraints, -result.residual,
                                               -(constraints @ point[0] - target))
            return level * math.sqrt(correction @ correction) / update, (point, result, residual)

        previous, at = norm, evaluation
        kink = (lambda: kink_step(at, dq)) if kink_step is not None else None
        limit = 1.0 if first_step is None else first_step(dq)
        if limit < 1.0:  # a move-limited step is taken as it is (see the docstring)
            step, (_, ((q, mu), evaluation, norm)) = limit, trial(limit)
        else:
            step, _, ((q, mu), evaluation, norm) = backtrack(trial, norm, 1.0, kink)
        if step < 1.0 or norm > reuse_rate * previous:
            tangent = kept.matrix = None
    return None
