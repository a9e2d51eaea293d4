"""Bit-rock force and torque at x = L, Eqs. (20)-(22), (41), (51), with their tangents.

The pointwise laws come first, in their physically consistent form (docs/errata.md):
the force and the torque never do positive work on the string.  :class:`BitRock`
projects them on the solution space and differentiates them for the Newton tangent.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from fenics_drill.model.kernels.compiled import kernel
from fenics_drill.model.discretization import THETA_X, U, BeamDiscretization
from fenics_drill.model.forces.protocol import ForceEvaluation
from fenics_drill.scene import LAW_SIGN


@njit(cache=True)
def _force(bit_velocity, limit_force, rate):
    """(20) at one instant."""
    return limit_force * math.expm1(-rate * bit_velocity) if bit_velocity > 0.0 else 0.0


@njit(cache=True)
def _regularisation(omega):
    """(22) at one instant."""
    return math.tanh(omega) + 2.0 * omega / (1.0 + omega * omega)


@njit(cache=True)
def _regularisation_slope(omega):
    """d xi_BR / d omega of (22) at one instant; 1 - tanh^2 without overflow at large omega."""
    tanh = math.tanh(omega)
    return 1.0 - tanh * tanh + 2.0 * (1.0 - omega * omega) / (1.0 + omega * omega) ** 2


@njit(cache=True)
def _torque(bit_force, bit_spin_rate, friction, borehole_radius):
    """(21) at one instant."""
    return -friction * abs(bit_force) * borehole_radius * _regularisation(bit_spin_rate)


@kernel
def _law(bit_velocity, bit_spin_rate, limit_force, rate, friction, borehole_radius):
    """(20)-(22) at the bit and their derivatives: F_BR, T_BR, dF_BR/du_dot, dT_BR/du_dot, dT_BR/d omega."""
    force = _force(bit_velocity, limit_force, rate)
    xi = _regularisation(bit_spin_rate)
    d_force = -limit_force * rate * math.exp(-rate * bit_velocity) if bit_velocity > 0.0 else 0.0
    # T = -mu |F| R xi = mu F R xi  (F <= 0)
    return (force, _torque(force, bit_spin_rate, friction, borehole_radius), d_force,
            friction * borehole_radius * xi * d_force,
            friction * force * borehole_radius * _regularisation_slope(bit_spin_rate))


#: :func:`_law` itself, for compiled code that evaluates the bit (solvers/compiled_residual.py).
LAW = _law.compiled


_FORCE, _TORQUE = np.vectorize(_force, otypes=(float,)), np.vectorize(_torque, otypes=(float,))
_REGULARISATION = np.vectorize(_regularisation, otypes=(float,))
_REGULARISATION_SLOPE = np.vectorize(_regularisation_slope, otypes=(float,))


def bit_rock_force(bit_velocity, limit_force, rate):
    """F_BR = Gamma_BR (exp(-alpha_BR u_dot_bit) - 1) for u_dot_bit > 0, else 0, Eq. (20)."""
    return _FORCE(bit_velocity, limit_force, rate)


def torque_regularisation(omega):
    """xi_BR(omega) = tanh(omega) + 2 omega / (1 + omega^2), Eq. (22); odd, sign of omega."""
    return _REGULARISATION(omega)


def bit_rock_torque(bit_force, bit_spin_rate, friction, borehole_radius):
    """T_BR = -mu_BR |F_BR| R_bh xi_BR(omega_bit), Eq. (21) with the magnitude of F_BR."""
    return _TORQUE(bit_force, bit_spin_rate, friction, borehole_radius)


def torque_regularisation_slope(omega):
    """d xi_BR / d omega of Eq. (22)."""
    return _REGULARISATION_SLOPE(omega)


#: A Newton update that crosses a kink is cut this share of the update past it, on the new branch.
KINK_PAST = 1e-6


@njit(cache=True)
def fraction_past_kink(value: float, change: float) -> float:
    """The step s in (0, 1] that lands KINK_PAST of the change past where value + s change crosses zero, or
    infinity if it does not.  Past by a share of the change, not of the distance: an iterate resting on the
    kink (value ~ 1e-19 after round-off) must still land on the new branch, beyond the round-off of the
    velocity it is computed from."""
    if change == 0.0 or value * change > 0.0 or abs(change) <= abs(value):
        return math.inf
    return min(-value / change + KINK_PAST, 1.0)


def step_past_kink(value: float, change: float) -> float | None:
    """:func:`fraction_past_kink`, None where it crosses no kink."""
    step = fraction_past_kink(float(value), float(change))
    return None if step == math.inf else step


@dataclass
class BitForces(ForceEvaluation):
    """The bit's state and reaction; ``generalised`` is [Phi]^T of (51), none of it conservative."""

    bit_velocity: float = 0.0
    bit_spin_rate: float = 0.0
    force: float = 0.0  # F_BR [N]
    torque: float = 0.0  # T_BR [N m]
    d_force: float = 0.0  # dF_BR / d u_dot_bit
    d_torque_velocity: float = 0.0  # dT_BR / d u_dot_bit
    d_torque_spin: float = 0.0  # dT_BR / d omega_bit


class BitRock:
    """Reaction of the rock on the bit (x = L): F_BR on u, T_BR on theta_x."""

    name: ClassVar[str] = "bit_rock"
    switch: ClassVar[str] = "bit_rock"
    conservative: ClassVar[bool] = False
    recorded: ClassVar[dict] = {
        "bit_force": ("N", "bit-rock force F_BR, Eq. (20)"),
        "bit_torque": ("N m", "bit-rock torque T_BR, Eq. (21)"),
    }

    def __init__(self, disc: BeamDiscretization, space, bit_rock, borehole_radius: float, torque_sign: float = 1.0):
        """``bit_rock``: the scene's [bit_rock] section (or a realisation of it); ``torque_sign``: +1 for the
        consistent torque (21), -1 for the torque as printed (mu_BR -> -mu_BR, since F_BR <= 0)."""
        self.torque_sign = torque_sign
        self.rows = space.point_rows([disc.end_dof(U, 1), disc.end_dof(THETA_X, 1)])  # q -> u(L), theta_x(L)
        # P^T of a unit force on u(L) and of a unit torque on theta_x(L): the laws' loads are multiples of them
        self._unit_loads = self.rows.unit_loads()
        self.limit_force, self.rate = bit_rock.limit_force, bit_rock.rate
        self.friction, self.borehole_radius = torque_sign * bit_rock.friction, borehole_radius

    @classmethod
    def chosen(cls, scene) -> bool:
        return scene.bit_rock.law == "paper"

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "BitRock":
        return cls(disc, space, scene.bit_rock, scene.hole_at_bit[0], LAW_SIGN[scene.law(scene.bit_rock.torque_law)])

    def with_parameters(self, bit_rock) -> "BitRock":
        """A copy with other law parameters (a Monte Carlo realisation of [bit_rock])."""
        changed = copy.copy(self)
        changed.limit_force, changed.rate = bit_rock.limit_force, bit_rock.rate
        changed.friction = self.torque_sign * bit_rock.friction
        return changed

    def record(self, forces: "BitForces") -> dict[str, float]:
        return {"bit_force": forces.force, "bit_torque": forces.torque}

    def kernel_data(self) -> tuple:
        """(the rows of u(L), theta_x(L), their unit loads, the law's constants) for
        :func:`~fenics_drill.solvers.compiled_residual.residual_at` (a modal space)."""
        return (self.rows.dense(), np.array(self._unit_loads),
                (self.limit_force, self.rate, self.friction, self.borehole_radius))

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> BitForces:
        u_dot, omega = self.rows.values(qd).tolist()
        force, torque, d_force, d_torque_velocity, d_torque_spin = _law(
            u_dot, omega, self.limit_force, self.rate, self.friction, self.borehole_radius)
        laws = {"bit_rock_force": force * self._unit_loads[0], "bit_rock_torque": torque * self._unit_loads[1]}
        generalised = laws["bit_rock_force"] + laws["bit_rock_torque"]
        return BitForces(generalised, 0.0, laws, u_dot, omega, force, torque, d_force, d_torque_velocity,
                         d_torque_spin)

    def kink_step(self, forces: BitForces, dq: np.ndarray, c_v: float) -> float | None:
        """The fraction of a Newton update dq (which moves qd by c_v dq) just past u_dot_bit = 0, where
        (20) switches between no force and its steepest slope; None if the update does not cross it."""
        return step_past_kink(forces.bit_velocity, c_v * float(self.rows.values(dq)[0]))

    def tangent(self, forces: BitForces, c_u: float, c_v: float):
        """c_v d f_BR / d qd (the law depends on velocities only, so c_u plays no part)."""
        return self.rows.block(c_v * np.array([[forces.d_force, 0.0],
                                               [forces.d_torque_velocity, forces.d_torque_spin]]))
