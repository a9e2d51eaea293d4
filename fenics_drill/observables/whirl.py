"""Whirl of a cross-section in the hole: the orbit of its centre, its direction against the spin, its
frequency, and the share of time it rolls on the wall.

A section in contact rolls when the slip velocity of the pipe's surface at the contact point,
s_t = t . (v_dot, w_dot) + R_ext theta_x_dot with t = (-w, v) / r the wall's tangent, is small against the surface
speed R_ext |theta_x_dot|: the contact point is then at rest on the wall, and the centre orbits at
-R_ext theta_x_dot / r, backward against the spin (rolling whirl).  The analysis takes the second half of the
series, past the start-up.
"""

from __future__ import annotations

import numpy as np

#: A section in contact rolls while its slip is below this share of its surface speed R_ext |theta_x_dot|.
ROLLING_SLIP = 0.05


def slip_velocity(v, w, v_rate, w_rate, spin, radius):
    """s_t = t . (v_dot, w_dot) + R theta_x_dot, the tangential slip of the surface point facing the wall
    (t = (-w, v) / r); the centre's own orbit rate when it sits at the axis (r = 0) is not defined: there R theta_x_dot."""
    v, w = np.asarray(v, dtype=float), np.asarray(w, dtype=float)
    r = np.hypot(v, w)
    along = np.divide(-w * v_rate + v * w_rate, r, out=np.zeros_like(r), where=r > 0)
    return along + radius * np.asarray(spin)


def whirl(time, v, w, v_rate, w_rate, spin, gap: float, radius: float) -> dict:
    """The whirl of a section from its series over the second half: ``direction`` (forward, backward, or none
    when the centre makes less than one turn), ``frequency_hz`` (turns per second), ``revolutions`` (signed like
    the spin: negative is backward), ``contact_share`` and ``rolling_share`` of the time, and the largest orbit
    radius [m]."""
    time = np.asarray(time, dtype=float)
    half = int(np.searchsorted(time, 0.5 * (time[0] + time[-1])))
    t = time[half:]
    if t.size < 3:
        return {"direction": "none", "frequency_hz": 0.0, "revolutions": 0.0, "contact_share": 0.0,
                "rolling_share": 0.0, "orbit_radius_max": 0.0}
    sl = slice(half, None)
    v, w, v_rate, w_rate, spin = (np.asarray(a, dtype=float)[sl] for a in (v, w, v_rate, w_rate, spin))
    angle = np.unwrap(np.arctan2(w, v))
    turns = (angle[-1] - angle[0]) / (2.0 * np.pi)
    spin_sign = np.sign(np.mean(spin)) or 1.0
    revolutions = turns * spin_sign  # positive: with the spin
    duration = t[-1] - t[0]
    r = np.hypot(v, w)
    weights = np.gradient(t)
    contact = r > gap
    slip = slip_velocity(v, w, v_rate, w_rate, spin, radius)
    rolling = contact & (np.abs(slip) < ROLLING_SLIP * radius * np.abs(spin))
    direction = "none" if abs(turns) < 1.0 else ("forward" if revolutions > 0 else "backward")
    return {"direction": direction, "frequency_hz": abs(turns) / duration if direction != "none" else 0.0,
            "revolutions": float(revolutions), "contact_share": float(np.sum(weights[contact]) / np.sum(weights)),
            "rolling_share": float(np.sum(weights[rolling]) / np.sum(weights)), "orbit_radius_max": float(r.max())}
