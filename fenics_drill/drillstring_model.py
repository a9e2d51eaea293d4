"""The discrete drillstring of a scene: Eq. (65) plus the constraints (72), ready for Newton.

    r(q, qd, qdd, mu) = f_int(q, qd, qdd) - f_G - f_FS(q, qd) - f_BR(qd) + [B]^T mu = 0
    [B] q = h(t) = h0 + (V0, Omega) t

f_int is the projected left-hand side of (43); f_G (52), f_FS (50) and f_BR (51) are
built only when the scene's ``model`` switches them on.  The multipliers mu are
the lambda of the Lagrangian (74): -lambda_1 and -lambda_4 are the force and
torque the drive applies at x = 0 (the rows of [B] the supports leave to enforce).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fenics_drill.bit_rock import BitForces, BitRock
from fenics_drill.discretization import BeamDiscretization
from fenics_drill.internal_force import internal_force
from fenics_drill.modal_report import scene_discretization
from fenics_drill.operators import LinearOperators, assemble_linear
from fenics_drill.reduced_space import FullSpace, ModalSpace
from fenics_drill.static_correction import augment, bit_load_responses
from fenics_drill.wall_contact import WallContact, WallForces

U_FIELD, V_FIELD, W_FIELD, TX_FIELD = 0, 1, 2, 3


@dataclass
class Evaluation:
    """Residual of (65)+(72) at one state, its pieces and (optionally) its tangent."""

    residual: np.ndarray
    internal: np.ndarray
    external: np.ndarray
    wall: WallForces | None
    bit: BitForces | None
    tangent: object = None
    internal_parts: tuple | None = None


class DrillstringModel:
    """Operators, force laws and constraints of one scene in one solution space."""

    def __init__(self, scene: dict, disc: BeamDiscretization, space, operators: LinearOperators, basis=None,
                 modes=None):
        self.scene, self.disc, self.space, self.basis = scene, disc, space, basis
        self.modes = modes  # every mode of the band B, kept or not (to name spectral peaks)
        model = scene["model"]
        borehole_radius = scene["borehole"]["radius"]
        self.gap = borehole_radius - disc.properties.outer_radius
        self.mass = space.project_matrix(operators.mass)
        self.internal = internal_force(disc, space, operators, model)
        self.gravity = space.project(operators.gravity) if model["gravity"] else None
        self.wall = WallContact(disc, space, scene["contact"], borehole_radius) if model["contact"] else None
        self.borehole_radius = borehole_radius
        self.bit = BitRock(disc, space, scene["bit_rock"], borehole_radius) if model["bit_rock"] else None
        drive_dofs = [disc.end_dof(U_FIELD, 0), disc.end_dof(TX_FIELD, 0)]
        rows = space.rows(drive_dofs)
        self.constraints = rows.toarray() if space.sparse else rows  # [B], 2 x N_red (72)
        self.drive_rate = np.array([scene["drive"]["axial_velocity"], scene["drive"]["rotation_speed"]])
        self.lateral_rows = (space.rows(disc.vertex_dofs(V_FIELD)), space.rows(disc.vertex_dofs(W_FIELD)))
        self.bit_rows = space.rows([disc.end_dof(U_FIELD, 1), disc.end_dof(TX_FIELD, 1)])
        self._operators = operators

    @property
    def size(self) -> int:
        return self.space.size

    def set_bit_rock(self, bit_rock: dict) -> None:
        """New bit-rock parameters (a Monte Carlo realisation); nothing else depends on them."""
        if self.bit is not None:
            self.bit = BitRock(self.disc, self.space, bit_rock, self.borehole_radius)

    def set_drive(self, axial_velocity: float, rotation_speed: float) -> None:
        """New drive speeds V0, Omega (a point of an operating window); nothing else depends on them."""
        self.drive_rate = np.array([axial_velocity, rotation_speed])

    def drive_velocity_field(self) -> np.ndarray:
        """Initial velocity of Section 3.2 in reduced coordinates: u_dot = V0, theta_x_dot = Omega,
        projected with the mass as in (54) (exact: both are rigid-body motions)."""
        full = np.zeros(self.disc.ndofs)
        full[self.disc.field_dofs[U_FIELD]] = self.drive_rate[0]
        full[self.disc.field_dofs[TX_FIELD]] = self.drive_rate[1]
        return self.space.solve(self.mass, self.space.project(self._operators.mass @ full))

    def evaluate(self, q, qd, qdd, mu, tangent_coefficients=None, internal_parts=None) -> Evaluation:
        """Residual at (q, qd, qdd, mu); with (c_u, c_v, c_a) also the tangent.

        ``internal_parts`` (df/dq, df/dqd, df/dqdd) of the internal force may come from an
        earlier state (modified Newton); without them they are computed at this state, only
        those with a non-zero coefficient.
        The force laws' tangents are always fresh.
        """
        internal = self.internal.evaluate(q, qd, qdd)
        external = np.zeros_like(q) if self.gravity is None else self.gravity.copy()
        wall = bit = None
        want = tangent_coefficients is not None
        if self.wall is not None:
            wall = self.wall.evaluate(q, qd, with_derivatives=want)
            external += wall.generalised
        if self.bit is not None:
            bit = self.bit.evaluate(qd)
            external += bit.generalised
        residual = internal - external + self.constraints.T @ mu
        out = Evaluation(residual, internal, external, wall, bit)
        if want:
            c_u, c_v, c_a = tangent_coefficients
            needed = tuple(c != 0 for c in tangent_coefficients)
            parts = internal_parts if internal_parts is not None else self.internal.tangent_parts(needed)
            out.internal_parts = parts if all(p is not None for p in parts) else None  # reusable only if whole
            J = sum(c * part for c, part in zip(tangent_coefficients, parts) if c != 0)
            if wall is not None:
                wall_tangent = self.wall.tangent(wall, c_u, c_v)
                if wall_tangent is not None:
                    J = J - wall_tangent
            if bit is not None:
                J = J - self.bit.tangent(bit, c_v)
            out.tangent = J
        return out

    def bit_state(self, q, qd) -> tuple[float, float, float, float]:
        """u(L), u_dot(L), theta_x(L), theta_x_dot(L)."""
        (u, tx), (du, dtx) = self.bit_rows @ q, self.bit_rows @ qd
        return float(u), float(du), float(tx), float(dtx)


def solution_space(scene: dict, disc: BeamDiscretization, operators: LinearOperators):
    """(space, kept modes, all modes): the modal basis of the scene's reduction rule (Section 6.3),
    with the static correction for the bit loads if asked, or the full space for 'none'; all
    modes of the band B (for spectra) either way."""
    from fenics_drill.modal import solve_modes
    from fenics_drill.reduction import select_modes

    p = disc.properties
    modes = solve_modes(disc, scene["modal"]["f_star_max"])
    if scene["reduction"]["rule"] == "none":
        return FullSpace(disc.ndofs, disc.support_dofs), None, modes
    basis = modes.select(select_modes(modes, scene["reduction"], p.length, p.longitudinal_wave_speed))
    phi = basis.vectors
    if scene["reduction"]["static_correction"]:
        phi = augment(phi, bit_load_responses(disc, operators), operators.mass)
    return ModalSpace(phi), basis, modes


def build_model(scene: dict) -> DrillstringModel:
    """Discretize, solve the modal problem, choose the basis and build the model of a scene."""
    disc = scene_discretization(scene)
    operators = assemble_linear(disc)
    space, basis, modes = solution_space(scene, disc, operators)
    return DrillstringModel(scene, disc, space, operators, basis, modes)
