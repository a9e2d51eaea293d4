"""The wall's normal force at a vertex, Eqs. (16)-(17): the Hunt-Crossley spring and damper of the indentation
delta = |(v, w)| - gap, clipped so that the wall never pulls."""

from __future__ import annotations

import numpy as np
from numba import njit


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
