"""Pointwise force laws of wall impacts (16)-(19) and bit-rock interaction (20)-(22), in NumPy.

Written in their physically consistent form (docs/errata.md): the normal force
never pulls the string towards the wall, and friction forces and the bit-rock
force and torque never do positive work on the string.
"""

from __future__ import annotations

import numpy as np


def indentation(v, w, gap):
    """delta_FS = r - gap, r = sqrt(v^2 + w^2), Eq. (16); positive in contact."""
    return np.hypot(v, w) - gap


def hunt_crossley_normal_force(delta, delta_rate, stiffness_linear, stiffness_cubic, damping):
    """Radial force on the string (<= 0: towards the axis), Eq. (17) with the damper c |delta|^3 delta_dot.

    Zero out of contact, and clipped at zero so the damper never makes the wall pull.
    """
    delta = np.asarray(delta, dtype=float)
    in_contact = delta > 0
    d = np.where(in_contact, delta, 0.0)
    force = -stiffness_linear * d - stiffness_cubic * d**3 - damping * np.abs(d) ** 3 * delta_rate
    return np.where(in_contact, np.minimum(force, 0.0), 0.0)


def regularised_sign(x, velocity_scale):
    """tanh(x / velocity_scale): Coulomb's sgn, smoothed so Newton can converge."""
    return np.tanh(np.asarray(x, dtype=float) / velocity_scale)


def wall_friction(normal_force, axial_velocity, spin_rate, friction, borehole_radius, velocity_scale):
    """Axial friction force (18) and friction torque (19) with the magnitude |F_n|:
    F_a = -mu |F_n| sgn(u_dot), T = -mu |F_n| R_bh sgn(theta_x_dot).

    Both signs are regularised on a sliding speed: u_dot and R_bh theta_x_dot."""
    magnitude = friction * np.abs(normal_force)
    force = -magnitude * regularised_sign(axial_velocity, velocity_scale)
    torque = -magnitude * borehole_radius * regularised_sign(borehole_radius * np.asarray(spin_rate), velocity_scale)
    return force, torque


def bit_rock_force(bit_velocity, limit_force, rate):
    """F_BR = Gamma_BR (exp(-alpha_BR u_dot_bit) - 1) for u_dot_bit > 0, else 0, Eq. (20)."""
    u = np.asarray(bit_velocity, dtype=float)
    return np.where(u > 0, limit_force * np.expm1(-rate * np.maximum(u, 0.0)), 0.0)


def torque_regularisation(omega):
    """xi_BR(omega) = tanh(omega) + 2 omega / (1 + omega^2), Eq. (22); odd, sign of omega."""
    omega = np.asarray(omega, dtype=float)
    return np.tanh(omega) + 2.0 * omega / (1.0 + omega**2)


def bit_rock_torque(bit_force, bit_spin_rate, friction, borehole_radius):
    """T_BR = -mu_BR |F_BR| R_bh xi_BR(omega_bit), Eq. (21) with the magnitude of F_BR."""
    return -friction * np.abs(bit_force) * borehole_radius * torque_regularisation(bit_spin_rate)
