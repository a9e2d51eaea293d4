"""The discrete drillstring of a scene: Eq. (65) plus the constraints (72), ready for Newton.

    r(q, qd, qdd, mu) = f_int(q, qd, qdd) + f_td(qdd) - sum_k f_k(q, qd) - f_drive(q, qd) + [B]^T mu = 0
    [B] q = h(t) = h0 + (V0, Omega) t

f_int is the projected left-hand side of (43); the f_k are the point forces the
scene's ``model`` switches turn on (:mod:`fenics_drill.model.forces`: gravity (52),
wall impacts (50), bit-rock (51) or the cutting bit).  The drive (:mod:`fenics_drill.model.top_drive`)
holds u(0) and theta_x(0) by the multipliers mu, the lambda of the Lagrangian (74), whose
-lambda_1 and -lambda_4 are the force and torque it applies at x = 0; or it applies a weight
on bit f_drive and a motor torque to a top drive of inertia f_td instead, and [B] keeps only
the rows it still holds.

A model is not changed behind its users' backs: :meth:`DrillstringModel.with_drive`,
:meth:`~DrillstringModel.with_bit_rock` and :meth:`~DrillstringModel.with_force` return
new models that share the expensive parts (space, operators, internal force).
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from fenics_drill.model.discretization import THETA_X, U, V, W, BeamDiscretization
from fenics_drill.model.forces import ForceEvaluation, build_forces
from fenics_drill.model.reduction.hyper_reduction import RETRAIN_ABOVE, sampling_error, train_sample
from fenics_drill.model.internal_force import (AssembledInternalForce, ElementSample, LateralZoneInternalForce,
                                              SplitInternalForce, internal_force)
from fenics_drill.model.kernels.split_band import StringSplit
from fenics_drill.model.resolution import band_frequency
from fenics_drill.model.operators import LinearOperators, assemble_linear
from fenics_drill.model.reduction.out_of_band_damping import OutOfBandDamping
from fenics_drill.model.reduction.enrichment import augment
from fenics_drill.model.reduction.spaces import FullSpace, ModalSpace, solution_space, stack_rows
from fenics_drill.model.top_drive import DriveLoads, TopDrive


@dataclass
class Evaluation:
    """Residual of (65)+(72) at one state, its pieces and (optionally) its tangent, which is
    computed on first use: Newton never asks for the tangent of the state it converges to."""

    residual: np.ndarray
    internal: np.ndarray
    external: np.ndarray
    forces: dict[str, ForceEvaluation] = field(default_factory=dict)  # by force name
    drive: DriveLoads | None = None
    tangent_of: Callable | None = None
    internal_parts: tuple | None = None
    _tangent: object = None

    @property
    def tangent(self):
        if self._tangent is None and self.tangent_of is not None:
            self._tangent = self.tangent_of()
        return self._tangent


class DrillstringModel:
    """Operators, point forces and constraints of one scene in one solution space."""

    def __init__(self, scene, disc: BeamDiscretization, space, operators: LinearOperators, basis=None,
                 modes=None, guard=None):
        self.scene, self.disc, self.space, self.basis = scene, disc, space, basis
        self.modes = modes  # every mode of the band B, kept or not (to name spectral peaks)
        self.guard = guard or {}  # per load: share of its static response the modes / the basis miss
        self.vertex_gap = disc.vertex_gap(scene.borehole.radius)  # the radial clearance at each vertex [m]
        self.gap = float(self.vertex_gap.min())  # the smallest
        self.mass = space.project_matrix(operators.mass)
        self.internal = internal_force(disc, space, operators, scene.model)
        self.forces = build_forces(scene, disc, space, operators)
        if not space.sparse:  # a modal basis: its directions above the band damped (out_of_band_damping.py)
            damping = self._out_of_band_damping(space.project_matrix(operators.stiffness))
            if damping is not None:
                self.forces.append(damping)
        self.drive = TopDrive.from_scene(scene, disc, space)
        self.constraints = self.drive.constraints
        self.lateral_rows = (space.rows(disc.vertex_dofs(V)), space.rows(disc.vertex_dofs(W)))
        self.bit_rows = space.rows([disc.end_dof(U, 1), disc.end_dof(THETA_X, 1)])
        # where the step's local error is measured [m]: the lateral displacements (impacts) and, at the
        # bit, the axial displacement and the arc r theta_x of the surface (the bit-rock law's stiff laws)
        self.error_rows = (*self.lateral_rows, self.bit_rows[0:1], disc.properties.outer_radius * self.bit_rows[1:2])
        # every vertex's displacements (u, v, w) and surface arc r theta_x [m]: how far an increment of q moves
        # any point of the string's surface (Newton's stopping test, solvers/newmark.py)
        radius = disc.vertex_radii(scene.borehole.radius)[0]
        arcs = space.rows(disc.vertex_dofs(THETA_X))
        self.motion_rows = stack_rows([*(space.rows(disc.vertex_dofs(f)) for f in (U, V, W)),
                                       sp.diags(radius) @ arcs if sp.issparse(arcs) else radius[:, None] * arcs])
        self.operators = operators
        self.exact_internal, self.hyper_reduction, self.training_states = None, None, []  # set by with_sample
        self._kept_internal_tangent = None  # (coefficients, parts, their sum) of the last tangent

    @property
    def size(self) -> int:
        return self.space.size

    def _out_of_band_damping(self, stiffness: np.ndarray) -> OutOfBandDamping | None:
        """The damping of the Ritz directions of (``stiffness``, M_r) above the band (out_of_band_damping.py)."""
        return OutOfBandDamping.of_basis(self.mass, stiffness, band_frequency(self.scene),
                                         self.scene.reduction.out_of_band_damping)

    def resting_stiffness(self, q: np.ndarray) -> np.ndarray | None:
        """K_r plus the reduced wall's springs at q (the c_u = 1 tangent of the wall at rest); None without a modal
        basis or without a vertex on the wall at q."""
        wall = self.force("wall")
        if self.space.sparse or wall is None:
            return None
        wall = wall.fresh()  # its kept tangent is the run's, not this one's
        springs = wall.tangent(wall.evaluate(q, np.zeros_like(q), with_tangent=True), 1.0, 0.0)
        return None if springs is None else self.space.project_matrix(self.operators.stiffness) - springs

    def resting_at(self, q: np.ndarray) -> "DrillstringModel":
        """The modal model whose damped directions above the band are those of the string resting at q: the
        Ritz directions of :meth:`resting_stiffness`.  On the wall the springs stiffen the directions that press
        the resting vertices into it far above f_max, and these rang against the contact where the full order's
        local contact dynamics is damped by Newmark's alpha (a thin pipe between stabilisers lifted off and
        bounced; docs/verification.md, "The reduced model against its full order").  The model itself if :meth:`resting_stiffness` is None."""
        stiffness = self.resting_stiffness(q)
        if stiffness is None:
            return self
        model = copy.copy(self)
        damping = self._out_of_band_damping(stiffness)
        model.forces = [f for f in self.forces if f.name != OutOfBandDamping.name]
        if damping is not None:
            model.forces.append(damping)
        return model

    def force(self, name: str):
        """The point force called ``name`` (``gravity``, ``wall``, ``bit_rock``), or None if off."""
        return next((f for f in self.forces if f.name == name), None)

    def with_force(self, replacement) -> "DrillstringModel":
        """A model whose force of the same name is ``replacement`` (everything else shared)."""
        model = copy.copy(self)
        model.forces = [replacement if f.name == replacement.name else f for f in self.forces]
        return model

    def with_added_force(self, force) -> "DrillstringModel":
        """A model with one more point force (built in this model's space)."""
        model = copy.copy(self)
        model.forces = [*self.forces, force]
        return model

    @property
    def constraints(self):
        """[B] of (72), k x N_red: the rows the drive holds."""
        return self._constraints

    @constraints.setter
    def constraints(self, rows) -> None:
        self._constraints = rows
        #: [B]^T, formed once (a sparse [B] would form it at every product with the multipliers)
        self.constraints_transposed = rows.T.tocsr() if hasattr(rows, "tocsr") else np.ascontiguousarray(rows.T)

    @property
    def drive_rate(self) -> np.ndarray:
        """h_dot of (71) for the rows of [B]."""
        return self.drive.held_rate

    def at_rest(self) -> "DrillstringModel":
        """The model with both drive dofs held (the static equilibrium of Section 6.4)."""
        model = copy.copy(self)
        model.drive = self.drive.at_rest()
        model.constraints = model.drive.constraints
        return model

    def fresh(self) -> "DrillstringModel":
        """A model whose memories (the cutting bit's surface, the controller's integral) are its own:
        one per simulation, the shared model untouched."""
        model = copy.copy(self)
        model.forces = [f.fresh() if hasattr(f, "fresh") else f for f in self.forces]
        model.drive = self.drive.fresh()
        return model

    def begin(self, t: float, q: np.ndarray) -> None:
        """Start the memories at the initial state."""
        self.drive.begin(t, q)
        for force in self.forces:
            if hasattr(force, "begin"):
                force.begin(t, q)

    def start_step(self, t_next: float) -> None:
        """The time of the step about to be solved (the controller's reference)."""
        self.drive.start_step(t_next)

    def accept(self, t: float, q: np.ndarray, qd: np.ndarray) -> None:
        """Show the memories an accepted step."""
        self.drive.accept(t, q, qd)
        for force in self.forces:
            if hasattr(force, "accept"):
                force.accept(t, q, qd)

    def with_bit_rock(self, bit_rock) -> "DrillstringModel":
        """A model with other bit-rock parameters (a Monte Carlo realisation); nothing else depends on them."""
        bit = self.force("bit_rock")
        return self if bit is None else self.with_force(bit.with_parameters(bit_rock))

    def with_drive(self, axial_velocity: float, rotation_speed: float) -> "DrillstringModel":
        """A model with other drive speeds V0, Omega (a point of an operating window)."""
        model = copy.copy(self)
        model.drive = self.drive.with_speeds(axial_velocity, rotation_speed)
        model.forces = [f.with_drive(axial_velocity, rotation_speed) if hasattr(f, "with_drive") else f
                        for f in self.forces]
        return model

    def full_order(self) -> "DrillstringModel":
        """The same string in the full finite-element space (no modal reduction), sharing the operators."""
        return DrillstringModel(self.scene, self.disc, FullSpace(self.disc),
                                self.operators, None, self.modes, {})

    def split_over(self, comm) -> "DrillstringModel":
        """This full-order model with its elements shared between the two ranks of ``comm``: each assembles its own
        half's internal force and tangent, and the saddle system (76) is solved across both
        (:mod:`~fenics_drill.model.kernels.split_band`); the wall's law runs at each rank's own vertices
        (:meth:`~fenics_drill.model.forces.wall_contact.WallContact.split_over`).  Every rank steps the whole state
        alike.  ValueError where the string cannot be split (its dofs do not part at one vertex, or the drive's lie
        near the cut)."""
        if not self.space.sparse or not isinstance(self.internal, (AssembledInternalForce, LateralZoneInternalForce)):
            raise ValueError("a run splits its string over MPI ranks in the full order with its nonlinear internal "
                             "force only (reduction.rule = 'none', or 'auto' where it chooses the full order; "
                             "model.geometric_nonlinearity or model.inertial_nonlinearity on)")
        split = StringSplit(self.disc, self.space, comm)
        split.check_drive(self.constraints, self.space.band_width)
        model = copy.copy(self)
        model.space = self.space.split(split)
        share = (self.internal.over(split.cells, model.space) if isinstance(self.internal, LateralZoneInternalForce)
                 else AssembledInternalForce(self.disc, model.space, self.operators, *self.internal.switches,
                                             cells=split.cells))
        model.internal = SplitInternalForce(self.internal, share, comm)
        model.forces = [f.split_over(comm, split.owned_vertices) if hasattr(f, "split_over") else f
                        for f in self.forces]
        model._kept_internal_tangent = None
        return model

    def with_vectors(self, vectors: np.ndarray, guard: dict) -> "DrillstringModel":
        """A model whose modal basis also spans the full-space ``vectors`` (M-orthonormalised), with the
        guard's report ``guard``."""
        phi = augment(self.space.phi, vectors, self.operators.mass)
        return DrillstringModel(self.scene, self.disc, ModalSpace(phi), self.operators, self.basis, self.modes,
                                guard)

    def with_sample(self, sample: ElementSample, report: dict, training_states: list) -> "DrillstringModel":
        """A model whose nonlinear internal forces are evaluated on an element sample (ECSW,
        :mod:`fenics_drill.model.reduction.hyper_reduction`); the unsampled forces stay as ``exact_internal``, the
        reference of the error indicator, and ``report`` says how the sample was trained on
        ``training_states``."""
        model = copy.copy(self)
        model.exact_internal = self.internal
        model.internal = internal_force(self.disc, self.space, self.operators, self.scene.model, sample)
        model.hyper_reduction = {**report, "retrainings": 0}
        model.training_states = list(training_states)
        return model

    def check_sample(self, q, qd, qdd) -> tuple[float, bool] | None:
        """The error indicator of a sampled model at a state (None without a sample), and whether the
        sample was retrained there: beyond RETRAIN_ABOVE this model's sample is trained again with the
        state among its training states (the shared model that this one was copied from keeps its own)."""
        if self.exact_internal is None:
            return None
        error = sampling_error(self.exact_internal, self.internal, q, qd, qdd)
        if error <= RETRAIN_ABOVE:
            return error, False
        m = self.scene.model
        switches = (m.geometric_nonlinearity, m.inertial_nonlinearity, m.kinematics, m.angular_velocity)
        self.training_states = [*self.training_states, (q.copy(), qd.copy(), qdd.copy())]
        sample, report = train_sample(self.disc, self.space, self.operators, switches, self.training_states,
                                      self.scene.reduction.hyper_tolerance)
        self.internal = internal_force(self.disc, self.space, self.operators, m, sample)
        retrainings = self.hyper_reduction["retrainings"] + 1
        self.hyper_reduction = {**self.hyper_reduction, **report, "retrainings": retrainings}
        return error, True

    def drive_velocity_field(self) -> np.ndarray:
        """Initial velocity of Section 3.2 in reduced coordinates: u_dot = V0, theta_x_dot = Omega,
        projected with the mass as in (54) (exact: both are rigid-body motions)."""
        full = np.zeros(self.disc.ndofs)
        full[self.disc.field_dofs[U]] = self.drive.rate[0]
        full[self.disc.field_dofs[THETA_X]] = self.drive.rate[1]
        return self.space.solve(self.mass, self.space.project(self.operators.mass @ full))

    def evaluate(self, q, qd, qdd, mu, tangent_coefficients=None, internal_parts=None) -> Evaluation:
        """Residual at (q, qd, qdd, mu); with (c_u, c_v, c_a) also the tangent.

        ``internal_parts`` (df/dq, df/dqd, df/dqdd) of the internal force may come from an
        earlier state (modified Newton); without them, and for each part given as None, they are
        computed at this state, only those with a non-zero coefficient.
        The point forces' tangents are always fresh.
        """
        internal = self.internal.evaluate(q, qd, qdd)
        if self.drive.inertia:
            internal = internal + self.drive.inertia_force(qdd)
        drive = self.drive.evaluate(q, qd)
        external = drive.generalised.copy()
        want = tangent_coefficients is not None
        evaluations = {}
        for force in self.forces:
            evaluation = evaluations[force.name] = force.evaluate(q, qd, with_tangent=want)
            external += evaluation.generalised
        residual = internal - external
        if mu.size:
            residual += self.constraints_transposed @ mu
        out = Evaluation(residual, internal, external, evaluations, drive)
        if want:
            parts = internal_parts
            if parts is None or any(part is None for part in parts):
                parts = self._completed_parts(tangent_coefficients, parts)
            self._with_tangent(out, tangent_coefficients, parts)
        return out

    def _with_tangent(self, evaluation: Evaluation, coefficients, parts) -> None:
        """Give ``evaluation`` its tangent with ``coefficients`` (formed on first use) and the internal ``parts``."""
        evaluation.internal_parts = parts if all(p is not None for p in parts) else None  # reusable only if whole
        forces, drive = evaluation.forces, evaluation.drive
        evaluation.tangent_of = lambda: self._tangent(coefficients, parts, forces, drive)

    def evaluation_at(self, q, qd, residual, internal, external, evaluations: dict, coefficients,
                      internal_parts) -> Evaluation:
        """The :meth:`evaluate` of (q, qd) with its tangent, from a residual and force evaluations computed
        elsewhere (:mod:`fenics_drill.solvers.compiled_residual`); ``internal_parts`` whole."""
        out = Evaluation(residual, internal, external, evaluations, self.drive.evaluate(q, qd))
        self._with_tangent(out, coefficients, internal_parts)
        return out

    def _completed_parts(self, coefficients, kept) -> tuple:
        """The parts (df/dq, df/dqd, df/dqdd) of the internal tangent: those ``kept`` (None: none), and the
        missing ones that a non-zero coefficient asks for computed at the state evaluated last."""
        kept = kept if kept is not None else (None, None, None)
        needed = tuple(c != 0 and part is None for c, part in zip(coefficients, kept))
        fresh = self.internal.tangent_parts(needed) if any(needed) else kept
        return tuple(part if part is not None else new for part, new in zip(kept, fresh))

    def kink_step(self, evaluation: Evaluation, dq: np.ndarray, c_v: float) -> float | None:
        """The fraction of a Newton update dq (qd moves by c_v dq) just past the first kink of a point
        force's law along it (the bit-rock law (20) at u_dot_bit = 0), or None."""
        steps = [force.kink_step(evaluation.forces[force.name], dq, c_v) for force in self.forces
                 if hasattr(force, "kink_step")]
        steps = [s for s in steps if s is not None]
        return min(steps) if steps else None

    def _tangent(self, coefficients, internal_parts, evaluations, drive):
        """c_u dr/dq + c_v dr/dqd + c_a dr/dqdd of the residual of :meth:`evaluate`."""
        c_u, c_v, c_a = coefficients
        terms = [(1.0, self._internal_tangent(coefficients, internal_parts))]
        inertia = self.drive.inertia_tangent(c_a)
        if inertia is not None:
            terms.append((1.0, inertia))
        load_tangents = [force.tangent(evaluations[force.name], c_u, c_v) for force in self.forces]
        terms += [(-1.0, t) for t in [*load_tangents, self.drive.tangent(drive, c_u, c_v)] if t is not None]
        return self.space.combine(terms)

    def _internal_tangent(self, coefficients, parts):
        """c_u df/dq + c_v df/dqd + c_a df/dqdd of the internal force, kept for the next tangent with the same
        parts and coefficients (Newmark's steps of one size while the parts are kept): one sum of three
        matrices instead of one per tangent."""
        kept = self._kept_internal_tangent
        if kept is not None and kept[0] == coefficients and all(a is b for a, b in zip(kept[1], parts)):
            return kept[2]
        matrix = self.space.combine([(c, part) for c, part in zip(coefficients, parts) if c != 0])
        self._kept_internal_tangent = (coefficients, parts, matrix)
        return matrix

    def kinetic_energy(self, q, qd) -> float:
        """Kinetic energy (24) of the string plus that of the top drive."""
        return self.internal.kinetic_energy(q, qd) + self.drive.kinetic_energy(qd)

    def mechanical_energies(self, qs: np.ndarray, qds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic (24, with the top drive's) and strain (30) energies of many states (rows of qs and qds)."""
        kinetic, strain = self.internal.energies(qs, qds)
        if self.drive.inertia:
            kinetic = kinetic + np.array([self.drive.kinetic_energy(qd) for qd in qds])
        return kinetic, strain

    def potential_energy(self, evaluation: Evaluation) -> float:
        """Energy stored by the point forces at an evaluated state (gravity, wall springs)."""
        potential = 0.0
        for force in self.forces:
            potential += evaluation.forces[force.name].potential
        return potential

    def bit_state(self, q, qd) -> tuple[float, float, float, float]:
        """u(L), u_dot(L), theta_x(L), theta_x_dot(L)."""
        (u, tx), (du, dtx) = self.bit_rows @ q, self.bit_rows @ qd
        return float(u), float(du), float(tx), float(dtx)


def build_model(scene, modal_stiffness=None) -> DrillstringModel:
    """Discretize, solve the modal problem, choose the basis and build the model of a scene
    (``modal_stiffness``: :func:`~fenics_drill.model.reduction.spaces.solution_space`'s)."""
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    space, basis, modes, guard, _ = solution_space(scene, disc, operators, modal_stiffness)
    return DrillstringModel(scene, disc, space, operators, basis, modes, guard)
