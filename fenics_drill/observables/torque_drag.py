"""Torque and drag read off a run: the axial force and the torque along the string, and the wall's normal force
per length, from a state's vertex values; the force and torque the drive applies at the top, from the series.

Along each element between two vertices the axial force is E A eps with the Green-Lagrange stretch
eps = u' + (v'^2 + w'^2) / 2 and the torque the model's torsional stiffness kappa_s G (2 I4) times theta_x', from
the vertex values (the element's mean strain); the wall's normal force at a vertex is its spring force
k_FS1 delta + k_FS2 delta^3 (Eq. 17 without the damper) over the length the vertex stands for.
"""

from __future__ import annotations

import numpy as np


def string_profiles(x, u, v, w, theta_x, properties, gap: float, stiffness_linear: float,
                    stiffness_cubic: float) -> dict[str, np.ndarray]:
    """``axial_force`` [N] (tension positive) and ``torque`` [N m] on the elements between consecutive vertices
    (sorted along x), and ``wall_normal_force_per_length`` [N/m] at the vertices."""
    order = np.argsort(x)
    x, u, v, w, theta_x = (np.asarray(a, dtype=float)[order] for a in (x, u, v, w, theta_x))
    h = np.diff(x)
    du, dv, dw, dt = (np.diff(a) / h for a in (u, v, w, theta_x))
    s = properties.section
    axial = properties.young_modulus * s.area * (du + 0.5 * (dv**2 + dw**2))
    torque = properties.shear_factor * properties.shear_modulus * 2.0 * s.I4 * dt
    delta = np.hypot(v, w) - gap
    spring = np.where(delta > 0, stiffness_linear * delta + stiffness_cubic * delta**3, 0.0)
    tributary = np.concatenate([[h[0] / 2], 0.5 * (h[1:] + h[:-1]), [h[-1] / 2]])
    return {"axial_force": axial, "torque": torque, "wall_normal_force_per_length": spring / tributary}


def top_loads(time, lambda_1, lambda_4) -> dict:
    """The force and torque the drive applies at the top (-lambda_1, -lambda_4), at the end and averaged over the
    second half of the run."""
    time = np.asarray(time, dtype=float)
    half = int(np.searchsorted(time, 0.5 * (time[0] + time[-1])))
    weights = np.gradient(time[half:]) if time.size - half > 1 else np.ones(time.size - half)
    out = {}
    for name, series in (("top_axial_force", -np.asarray(lambda_1)), ("surface_torque", -np.asarray(lambda_4))):
        out[name] = {"last": float(series[-1]), "mean_second_half": float(np.average(series[half:], weights=weights))}
    return out
