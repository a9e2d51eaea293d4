"""What a driller reads off a run: efficiency (96)-(98), rate of penetration (99), and
stick-slip and bit-bounce indicators, as functions of time series.

Every function takes arrays sampled at the (possibly non-uniform) instants ``t``
and integrates with the trapezoidal rule: pure functions, no files.
(:func:`fenics_drill.studies.run.quantities_of_run` applies them to a saved run, which
is how ``summary.json`` gets its values.)

Indicators (documented for users in README.md, "Drilling quantities"):

* stick-slip: ``stick_fraction`` is the fraction of time the bit turns slower than
  STICK_THRESHOLD * Omega; ``stick_slip_severity`` = (max omega_bit - min omega_bit) /
  (2 Omega), the industry's usual measure (> 1: the bit stops and then spins at
  more than twice the surface speed); ``omega_max_ratio``, ``omega_min_ratio`` =
  max, min omega_bit / Omega.
* shock packages: groups of wall impacts separated by more than SHOCK_PACKAGE_GAP
  seconds without any (the paper counts 11 in Fig. 18).
* bit-bounce: ``off_bottom_fraction`` is the fraction of time u_dot_bit <= 0 (the
  bit-rock force (20) vanishes: the bit is not cutting); ``velocity_max_ratio``,
  ``velocity_min_ratio`` = max, min u_dot_bit / V0.
* ringing of the bit: :func:`spin_variation_ratio`, the total variation of omega_bit over the
  second half of a run against what a stick-slip at the string's first torsional frequency can give.
"""

from __future__ import annotations

import numpy as np

#: omega_bit below this fraction of Omega counts as "stuck" for ``stick_fraction``.
STICK_THRESHOLD = 0.1


def positive(x):
    """The positive part x^+ = max(x, 0)."""
    return np.maximum(x, 0.0)


def time_integral(t: np.ndarray, f: np.ndarray) -> float:
    """int f dt over the samples (trapezoidal rule)."""
    return float(np.trapezoid(f, t))


def time_fraction(t: np.ndarray, condition: np.ndarray) -> float:
    """Fraction of [t0, tf] during which ``condition`` holds (each interval counted by its end)."""
    dt = np.diff(t)
    return float(np.sum(dt * condition[1:]) / (t[-1] - t[0]))


def input_power(drive_velocity, drive_spin, lambda_1, lambda_4):
    """P_in of (98): u_dot(0)^+ (-lambda_1)^+ + theta_x_dot(0)^+ (-lambda_4)^+ [W]."""
    return positive(drive_velocity) * positive(-lambda_1) + positive(drive_spin) * positive(-lambda_4)


def output_power(bit_velocity, bit_force, bit_angular_velocity, bit_torque, torque_magnitude: bool = False):
    """P_out of (97): u_dot_bit^+ (-F_BR)^+ + omega_bit^+ (-T_BR)^+ [W].

    ``torque_magnitude``: omega_bit^+ |T_BR| in place of omega_bit^+ (-T_BR)^+.  With the bit torque (21)
    as printed, T_BR drives the bit (T_BR omega_bit >= 0) and (-T_BR)^+ vanishes while it turns forward;
    counting |T_BR| is how the paper's efficiency of about 16 % comes out (docs/reproduction.md)."""
    rotational = np.abs(bit_torque) if torque_magnitude else positive(-bit_torque)
    return positive(bit_velocity) * positive(-bit_force) + positive(bit_angular_velocity) * rotational


def efficiency(t, p_in, p_out) -> float:
    """E of (96): int P_out dt / int P_in dt (0 when no power went in)."""
    work_in = time_integral(t, p_in)
    return time_integral(t, p_out) / work_in if work_in > 0 else 0.0


def rop(t, bit_velocity) -> float:
    """Rate of penetration (99): the time mean of u_dot_bit^+ [m/s]."""
    return time_integral(t, positive(bit_velocity)) / (t[-1] - t[0])


def signed_rop(t, bit_velocity) -> float:
    """The alternative of Fig. 27: the time mean of u_dot_bit itself [m/s]."""
    return time_integral(t, bit_velocity) / (t[-1] - t[0])


def stick_slip(t, bit_angular_velocity, rotation_speed: float) -> dict:
    """Stick-slip indicators of omega_bit against the surface speed Omega (see module doc)."""
    w = np.asarray(bit_angular_velocity)
    if rotation_speed <= 0:
        return {"stick_fraction": time_fraction(t, np.abs(w) <= 0.0)}
    return {
        "stick_fraction": time_fraction(t, w < STICK_THRESHOLD * rotation_speed),
        "stick_slip_severity": float((w.max() - w.min()) / (2.0 * rotation_speed)),
        "omega_max_ratio": float(w.max() / rotation_speed),
        "omega_min_ratio": float(w.min() / rotation_speed),
    }


def bit_bounce(t, bit_velocity, axial_velocity: float) -> dict:
    """Bit-bounce indicators of u_dot_bit against the surface feed V0 (see module doc)."""
    v = np.asarray(bit_velocity)
    out = {"off_bottom_fraction": time_fraction(t, v <= 0.0)}
    if axial_velocity > 0:
        out["velocity_max_ratio"] = float(v.max() / axial_velocity)
        out["velocity_min_ratio"] = float(v.min() / axial_velocity)
    return out


def spin_variation_ratio(t, bit_angular_velocity, rotation_speed: float, torsional_frequency: float) -> float:
    """sum |omega_bit(t_{n+1}) - omega_bit(t_n)| over the second half of the run, divided by 4 Omega f_T T: the
    most that a stick-slip cycle at f_T (the string's first torsional frequency c_T / 4L), swinging omega_bit
    between 0 and 2 Omega, adds over that half's duration T.  A bit that rings at the basis's top
    frequencies, zig-zagging from step to step, gives tens to hundreds (docs/verification.md); NaN without
    spin or without a second half."""
    t, w = np.asarray(t), np.asarray(bit_angular_velocity)
    late = t >= 0.5 * t[-1]
    duration = t[-1] - t[late][0] if late.any() else 0.0
    if rotation_speed == 0 or duration <= 0 or torsional_frequency <= 0:
        return float("nan")
    return float(np.abs(np.diff(w[late])).sum() / (4.0 * abs(rotation_speed) * torsional_frequency * duration))


#: Impacts further apart than this belong to different shock packages (Section 6.7) [s].
SHOCK_PACKAGE_GAP = 0.2


def shock_packages(t, impacts, quiet_gap: float = SHOCK_PACKAGE_GAP) -> int:
    """Number of groups of impacts separated by more than ``quiet_gap`` seconds without any (Fig. 18)."""
    times = np.asarray(t)[np.asarray(impacts) > 0]
    return 0 if times.size == 0 else int(1 + np.sum(np.diff(times) > quiet_gap))


def drilling_quantities(series: dict, axial_velocity: float, rotation_speed: float) -> dict:
    """All of the above from a dict of time-series arrays (the variables of timeseries.h5)."""
    t = series["time"]
    if len(t) < 2 or t[-1] <= t[0]:
        raise ValueError("drilling quantities need at least two instants of a run")
    # the top's own velocities where recorded (a hook-load drive or a controller does not move it at V0, Omega)
    top_velocity = series.get("top_velocity", axial_velocity)
    top_spin = series.get("top_angular_velocity", rotation_speed)
    p_in = input_power(top_velocity, top_spin, series["lambda_1"], series["lambda_4"])
    bit = (series["bit_velocity"], series["bit_force"], series["bit_angular_velocity"], series["bit_torque"])
    p_out = output_power(*bit)
    return {
        "efficiency": efficiency(t, p_in, p_out),
        "efficiency_torque_magnitude": efficiency(t, p_in, output_power(*bit, torque_magnitude=True)),
        "rop": rop(t, series["bit_velocity"]),
        "signed_rop": signed_rop(t, series["bit_velocity"]),
        "mean_input_power": time_integral(t, p_in) / (t[-1] - t[0]),
        "mean_output_power": time_integral(t, p_out) / (t[-1] - t[0]),
        "stick_slip": stick_slip(t, series["bit_angular_velocity"], rotation_speed),
        "bit_bounce": bit_bounce(t, series["bit_velocity"], axial_velocity),
        "shock_packages": shock_packages(t, series["impacts"]),
    }
