"""Independent references for the modes of a string: exact transfer-matrix roots of a piecewise-uniform rod (axial
or torsional waves), and a Chebyshev collocation solve of the tensioned Euler-Bernoulli beam.  Neither uses the
finite-element model or its forms: only the section's stiffness and inertia per length.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
import scipy.optimize


def rod_transfer(segments, omega):
    """The transfer matrix of the state (displacement, force) from the top of a rod to its bottom, at the circular
    frequency ``omega`` (a number, or an array: one matrix per frequency): the product of each uniform segment's
    [[cos kl, sin kl / (S k)], [-S k sin kl, cos kl]], k = omega sqrt(m / S).  ``segments``: (length [m],
    stiffness S [N or N m^2], inertia m [kg/m or kg m]) from the top down; the wave equation S y'' = m y_tt in
    each, y and S y' continuous between them."""
    omegas = np.atleast_1d(np.asarray(omega, dtype=float))
    matrix = np.broadcast_to(np.eye(2), (omegas.size, 2, 2)).copy()
    segment = np.empty_like(matrix)
    for length, stiffness, inertia in segments:
        k = omegas * math.sqrt(inertia / stiffness)
        c, s = np.cos(k * length), np.sin(k * length)
        segment[:, 0, 0], segment[:, 0, 1], segment[:, 1, 0], segment[:, 1, 1] = c, s / (stiffness * k), \
            -stiffness * k * s, c
        matrix = segment @ matrix
    return matrix if np.ndim(omega) else matrix[0]


#: The entry of the transfer matrix that vanishes at a natural frequency, for each (top, bottom) condition:
#: a free end has no force, a held one no displacement.
_FREQUENCY_ENTRY = {("free", "free"): (1, 0), ("held", "free"): (1, 1), ("held", "held"): (0, 1),
                    ("free", "held"): (0, 0)}


def rod_frequencies(segments, top: str, bottom: str, count: int, highest_hz: float) -> np.ndarray:
    """The ``count`` lowest nonzero natural frequencies [Hz] of the rod (:func:`rod_transfer`) with its top and
    bottom 'free' or 'held': the roots of the transfer matrix's entry that the end conditions leave, bracketed on
    a grid up to ``highest_hz`` and refined by Brent's method to round-off."""
    row, column = _FREQUENCY_ENTRY[(top, bottom)]

    def entry(f):
        return rod_transfer(segments, 2.0 * math.pi * f)[row, column]

    grid = np.linspace(1e-6 * highest_hz, highest_hz, 40000)
    values = rod_transfer(segments, 2.0 * math.pi * grid)[:, row, column]
    # Brent's method to the last bits of the root (frequencies of order 1-100 Hz): the reference must be exact far
    # below the 1e-4 the FE is held to
    roots = [scipy.optimize.brentq(entry, a, b, xtol=1e-14, rtol=1e-15)
             for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:]) if fa * fb < 0]
    if len(roots) < count:
        raise ValueError(f"found {len(roots)} roots below {highest_hz} Hz, {count} asked for")
    return np.array(roots[:count])


def chebyshev(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Trefethen's Chebyshev differentiation matrix D on the n + 1 points x_j = cos(pi j / n) of [-1, 1]."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.hstack([2.0, np.ones(n - 1), 2.0]) * (-1.0) ** np.arange(n + 1)
    dx = x[:, None] - x[None, :]
    d = np.outer(c, 1.0 / c) / (dx + np.eye(n + 1))
    return d - np.diag(d.sum(axis=1)), x


#: Collocation sizes tried in turn by :func:`tensioned_beam_frequencies`: the fourth-derivative matrix's round-off
#: grows as points^8, so a stiff short beam converges at 40-80 points and is spoilt beyond 100, while a long string's
#: tension boundary layer (sqrt(EI / T) ~ 3 m in 500 m) needs 120-160.
POINTS = (40, 60, 80, 100, 120, 140, 160, 200)
#: Two sizes agreeing to this relative difference give the converged frequencies: a thousand times below the 1e-3
#: the FE's lateral modes are held to, and above the collocation's round-off at the sizes that converge.
CONVERGED = 1e-6


def tensioned_beam_frequencies(length: float, bending_stiffness: float, mass_per_length: float,
                               weight_per_length: float, bottom_compression: float, count: int) -> np.ndarray:
    """The ``count`` lowest natural frequencies [Hz] of lateral vibration of a uniform string hanging in a vertical
    hole: (EI y'')'' - (T y')' + m y_tt = 0 on 0 <= s <= L (s down from the top), T(s) = w (L - s) - P (the
    buoyed weight below s, less the compression P at the bit), clamped at the top (y = y' = 0), pinned at the bit
    (y = y'' = 0): the first of :data:`POINTS` whose frequencies agree with the previous size's within
    :data:`CONVERGED` (:func:`_collocated_frequencies`)."""
    last = None
    for points in POINTS:
        values = _collocated_frequencies(length, bending_stiffness, mass_per_length, weight_per_length,
                                         bottom_compression, count, points)
        if last is not None and len(values) == count and np.allclose(values, last, rtol=CONVERGED, atol=0):
            return values
        last = values
    raise ValueError(f"the collocation did not converge to {CONVERGED:g} over {POINTS} points")


def _collocated_frequencies(length, bending_stiffness, mass_per_length, weight_per_length, bottom_compression,
                            count, points):
    """Chebyshev collocation on ``points`` + 1 points; the boundary conditions replace the equation at the two
    points next to each end; the generalized eigenproblem's finite eigenvalues are m omega^2 / EI."""
    d, x = chebyshev(points)
    half = length / 2.0
    s = half * (1.0 - x)  # x = 1 at the top (s = 0), x = -1 at the bit
    d1 = -d / half  # d/ds
    d2, d4 = d1 @ d1, d1 @ d1 @ d1 @ d1
    tension = weight_per_length * (length - s) - bottom_compression
    # EI y'''' - T y'' - T' y' with T' = -w
    a = bending_stiffness * d4 - np.diag(tension) @ d2 + weight_per_length * d1
    b = np.eye(points + 1) * mass_per_length
    top, bit = 0, points
    rows = {top: np.eye(points + 1)[top], top + 1: d1[top], bit: np.eye(points + 1)[bit], bit - 1: d2[bit]}
    for row, condition in rows.items():
        a[row], b[row] = condition, 0.0
    values = scipy.linalg.eigvals(a, b)
    finite = values[np.isfinite(values)]
    real = np.sort(finite[(np.abs(finite.imag) < 1e-6 * np.abs(finite)) & (finite.real > 0)].real)
    return np.sqrt(real[:count]) / (2.0 * math.pi)
