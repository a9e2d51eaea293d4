"""Torque and drag read off a run: the axial force and the torque along the string, and the wall's normal force
per length, from a state's vertex values; the force and torque the drive applies at the top, from the series.

Along each element between two vertices the axial force is E A eps (1 + u') with the Green-Lagrange stretch
eps = u' + (u'^2 + v'^2 + w'^2) / 2 (on a well's curved axis, u' - k2 v - k3 w in the axis' frame) and the torque
minus the model's torsional stiffness G J times theta_x'
(:attr:`~fenics_drill.forms.properties.BeamProperties.torsional_rigidity`: positive in the drive's sense), from
the vertex values (the element's mean strain); the wall's normal force at a vertex is its spring force
k_FS1 delta + k_FS2 delta^3 (Eq. 17 without the damper) over the length the vertex stands for.
"""

from __future__ import annotations

import numpy as np


def string_profiles(x, u, v, w, theta_x, properties, gap: float, stiffness_linear: float,
                    stiffness_cubic: float, theta_y=None, theta_z=None,
                    curvature: tuple | None = None) -> dict[str, np.ndarray]:
    """``axial_force`` [N] (tension positive) and ``torque`` [N m] on the elements between consecutive vertices
    (sorted along x), and ``wall_normal_force_per_length`` [N/m] at the vertices.  ``properties``' numbers may be
    one per element (a string of sections), ``gap`` one per vertex.  On a curved axis,
    ``curvature`` (k2, k3) on each element: the derivatives are the frame's, u' - k2 v - k3 w and
    theta_x' - k2 theta_y - k3 theta_z with the element's mean v, w, theta_y, theta_z."""
    order = np.argsort(x)
    x, u, v, w, theta_x = (np.asarray(a, dtype=float)[order] for a in (x, u, v, w, theta_x))
    h = np.diff(x)
    du, dv, dw, dt = (np.diff(a) / h for a in (u, v, w, theta_x))
    if curvature is not None:
        k2, k3 = curvature
        mean = lambda a: 0.5 * (a[1:] + a[:-1])  # noqa: E731
        du = du - k2 * mean(v) - k3 * mean(w)
        dt = dt - k2 * mean(np.asarray(theta_y)[order]) - k3 * mean(np.asarray(theta_z)[order])
    s = properties.stiffness_section
    # the force along the axis, dW/du' = E A eps (1 + u'), eps the Green-Lagrange stretch (what the top holds)
    axial = properties.young_modulus * s.area * (du + 0.5 * (du**2 + dv**2 + dw**2)) * (1.0 + du)
    # the torque the string carries down-hole, positive in the drive's sense (the soft string's and the surface
    # torque's sign): minus G J theta_x', the twist falling from the driven top to the resisting bit
    torque = -properties.torsional_rigidity * dt
    delta = np.hypot(v, w) - (np.asarray(gap)[order] if np.ndim(gap) else gap)
    spring = np.where(delta > 0, stiffness_linear * delta + stiffness_cubic * delta**3, 0.0)
    tributary = np.concatenate([[h[0] / 2], 0.5 * (h[1:] + h[:-1]), [h[-1] / 2]])
    return {"axial_force": axial, "torque": torque, "wall_normal_force_per_length": spring / tributary}


def top_loads(time, lambda_1, lambda_4) -> dict:
    """The force and torque the drive applies at the top (-lambda_1, -lambda_4; the force along x, down-hole) and
    the hook load (lambda_1: what the top holds up, the force's opposite), at the end and averaged over the second
    half of the run."""
    time = np.asarray(time, dtype=float)
    half = int(np.searchsorted(time, 0.5 * (time[0] + time[-1])))
    weights = np.gradient(time[half:]) if time.size - half > 1 else np.ones(time.size - half)
    out = {}
    for name, series in (("top_axial_force", -np.asarray(lambda_1)), ("hook_load", np.asarray(lambda_1)),
                         ("surface_torque", -np.asarray(lambda_4))):
        out[name] = {"last": float(series[-1]), "mean_second_half": float(np.average(series[half:], weights=weights))}
    return out
