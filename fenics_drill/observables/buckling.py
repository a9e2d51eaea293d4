"""Buckling loads of a pipe lying in a hole: the axial compression (effective, Lubinski) beyond which it buckles
sinusoidally, and beyond which helically.

- straight inclined hole (Dawson & Paslay 1984): F_sin = 2 sqrt(E I w sin I / r);
- vertical hole (Lubinski 1950; Wu & Juvkam-Wold 1993): F_sin = 2.55 (E I w^2)^(1/3), F_hel = 5.55 (E I w^2)^(1/3),
  which govern where the inclination leaves the formula above below them;
- curved hole (He & Kyllingstad 1995): F_sin = (4 E I kappa / r) (1 + sqrt(1 + r w sin I / (4 E I kappa^2))), which
  tends to Dawson-Paslay as the curvature kappa goes to 0 (the curve holds the pipe against its outer side);
- helical: sqrt(2) times the sinusoidal load of the same hole (Chen, Lin & Cheatham 1990, 2 sqrt(2) against 2 in
  a straight hole).

w is the pipe's buoyed weight per length, r the radial clearance between pipe and hole, E I the body's.
"""

from __future__ import annotations

import numpy as np


def sinusoidal_load(stiffness, weight, inclination, clearance, curvature=0.0):
    """F_sin [N]: Dawson-Paslay in a straight hole, He-Kyllingstad in a curved one, Lubinski's where it is higher."""
    stiffness, weight, inclination, clearance, curvature = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (stiffness, weight, inclination, clearance, curvature)))
    lateral = np.abs(weight) * np.sin(inclination)
    straight = 2.0 * np.sqrt(stiffness * lateral / clearance)
    with np.errstate(divide="ignore", invalid="ignore"):
        curved = 4.0 * stiffness * curvature / clearance * (
            1.0 + np.sqrt(1.0 + clearance * lateral / (4.0 * stiffness * curvature**2)))
    inclined = np.where(curvature > 0, curved, straight)
    vertical = 2.55 * np.cbrt(stiffness * weight**2)
    return np.maximum(inclined, vertical)


def helical_load(stiffness, weight, inclination, clearance, curvature=0.0):
    """F_hel [N]: sqrt(2) F_sin of an inclined or curved hole, Wu & Juvkam-Wold's 5.55 (E I w^2)^(1/3) in a vertical
    one, where that is higher."""
    sinusoidal = sinusoidal_load(stiffness, weight, inclination, clearance, curvature)
    vertical = 5.55 * np.cbrt(np.asarray(stiffness, dtype=float) * np.asarray(weight, dtype=float)**2)
    inclined = np.sqrt(2.0) * sinusoidal
    return np.maximum(inclined, vertical)


def buckled_spans(md_element: np.ndarray, lengths: np.ndarray, compression: np.ndarray, sinusoidal: np.ndarray,
                  helical: np.ndarray) -> dict:
    """Where elements (mid-depths ``md_element``, ``lengths``) under ``compression`` [N] exceed their sinusoidal or
    helical buckling loads: the lengths buckled each way [m], the first and last buckled mid-depth (None: none), the
    largest compression and, at that element, the two loads [N]."""
    sin = (compression > sinusoidal) & (compression <= helical)
    hel = compression > helical
    either = sin | hel
    worst = int(np.argmax(compression))
    return {"sinusoidally_buckled_length_m": float(lengths[sin].sum()),
            "helically_buckled_length_m": float(lengths[hel].sum()),
            "first_buckled_md_m": float(md_element[either][0]) if either.any() else None,
            "last_buckled_md_m": float(md_element[either][-1]) if either.any() else None,
            "max_compression_N": float(max(compression.max(), 0.0)),
            "buckling_loads_at_max_compression_N": [float(sinusoidal[worst]), float(helical[worst])]}
