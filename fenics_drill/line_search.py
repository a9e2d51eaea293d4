"""Backtracking on the residual norm for Newton updates (Armijo's sufficient decrease).

The wall law (17) has a kink at first contact and the bit-rock law (20) one at
u_dot_bit = 0; a full Newton update can jump from one branch to the other and
back forever.  Halving the update until the residual norm decreases stops that.
"""

from __future__ import annotations

#: Halvings of a Newton update before the last one is taken anyway.
HALVINGS = 6
#: Sufficient decrease: accept when |r(step)| < (1 - ARMIJO step) |r(0)|.
ARMIJO = 1e-4


def backtrack(trial, norm0: float, step: float = 1.0):
    """Largest step = step / 2^k (k < HALVINGS) whose ``trial(step) -> (norm, payload)`` decreases
    the norm enough; returns (step, norm, payload) of the accepted (or last) trial."""
    for _ in range(HALVINGS):
        norm, payload = trial(step)
        if norm < (1.0 - ARMIJO * step) * norm0:
            break
        step *= 0.5
    return step, norm, payload
