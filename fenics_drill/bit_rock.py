"""Bit-rock force and torque at x = L, Eqs. (20)-(22), (41), (51), with their tangents."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fenics_drill.discretization import BeamDiscretization
from fenics_drill.force_laws import bit_rock_force, bit_rock_torque, torque_regularisation
from fenics_drill.reduced_space import weighted_product

U_FIELD, TX_FIELD = 0, 3


@dataclass
class BitForces:
    bit_velocity: float
    bit_spin_rate: float
    force: float  # F_BR [N]
    torque: float  # T_BR [N m]
    generalised: np.ndarray  # [Phi]^T of (51)
    d_force: float  # dF_BR / d u_dot_bit
    d_torque_velocity: float  # dT_BR / d u_dot_bit
    d_torque_spin: float  # dT_BR / d omega_bit


def torque_regularisation_slope(omega):
    """d xi_BR / d omega of Eq. (22)."""
    omega = np.asarray(omega, dtype=float)
    return 1.0 / np.cosh(omega) ** 2 + 2.0 * (1.0 - omega**2) / (1.0 + omega**2) ** 2


class BitRock:
    """Reaction of the rock on the bit (x = L): F_BR on u, T_BR on theta_x."""

    def __init__(self, disc: BeamDiscretization, space, bit_rock: dict, borehole_radius: float):
        self.row_u = space.rows([disc.end_dof(U_FIELD, 1)])  # 1 x N_red: q -> u(L)
        self.row_tx = space.rows([disc.end_dof(TX_FIELD, 1)])  # 1 x N_red: q -> theta_x(L)
        self.limit_force, self.rate = bit_rock["limit_force"], bit_rock["rate"]
        self.friction, self.borehole_radius = bit_rock["friction"], borehole_radius

    def evaluate(self, qd: np.ndarray) -> BitForces:
        u_dot, omega = float((self.row_u @ qd)[0]), float((self.row_tx @ qd)[0])
        force = float(bit_rock_force(u_dot, self.limit_force, self.rate))
        torque = float(bit_rock_torque(force, omega, self.friction, self.borehole_radius))
        d_force = -self.limit_force * self.rate * np.exp(-self.rate * u_dot) if u_dot > 0 else 0.0
        xi = float(torque_regularisation(omega))
        # T = -mu |F| R xi = mu F R xi  (F <= 0)
        d_torque_velocity = self.friction * self.borehole_radius * xi * d_force
        d_torque_spin = self.friction * force * self.borehole_radius * float(torque_regularisation_slope(omega))
        generalised = self.row_u.T @ np.array([force]) + self.row_tx.T @ np.array([torque])
        return BitForces(u_dot, omega, force, torque, generalised, d_force, d_torque_velocity, d_torque_spin)

    def tangent(self, forces: BitForces, c_v: float):
        """c_v d f_BR / d qd (the law depends on velocities only)."""
        gu, gt = self.row_u, self.row_tx
        return (
            weighted_product(gu, np.array([c_v * forces.d_force]), gu)
            + weighted_product(gt, np.array([c_v * forces.d_torque_velocity]), gu)
            + weighted_product(gt, np.array([c_v * forces.d_torque_spin]), gt)
        )
