"""The guard and the enrichment of a truncated modal basis (Section 6.3 made safe).

A basis of the lowest modes reproduces a load's dynamic response but not always its
quasi-static deflection: the modes left out may hold most of it.  A 6 m string has no
flexural mode below the paper's 5 Hz band, so its sag under gravity is zero in the
paper's basis; a point force at the bit loses 5 % of the tip compliance of a bar to the
axial modes above f* = 4.  The guard measures, for every load the scene applies, how
much of its static response the basis misses, in the energy norm of the linear
stiffness K, with the drive end u(0), theta_x(0) held where the multipliers hold it:

    error^2 = 1 - f . u_basis / f . u,    u = K^-1 f,  u_basis its Galerkin projection,

which is the share of the static strain energy the basis cannot carry.  The loads are
gravity (52), a unit bit force and a unit bit torque at x = L (20)-(21), the wall
reaction of the string at rest (16)-(17), and the axial friction (18) and friction torque
(19) that this reaction drives when the string slides or turns on the wall.  The axial friction
is a load along the whole resting length, whose static response (an axial force growing from the
bit to the drive) the axial modes of the band carry poorly: on the paper scene they miss 28 % of
it and half of the axial strain at the held top, where the peak stress sits (docs/verification.md).

Enrichment adds to the basis the static response of every load beyond the tolerance
(modal truncation augmentation; Dickens, Nakagawa & Wittbrodt 1997) and, when the
geometric nonlinearity is on and ``reduction.axial_companions`` asks for it, the axial
companion of each load's response: the static modal derivative theta = -K^-1 D^2
f_el(0)[phi, phi] (Idelsohn & Cardona 1985), the axial shortening and twist that a large
transverse deflection phi drags along.  Linear bending shapes alone stretch the string's
axis and stiffen it (the sag of a 30 m string came out 40 % short); the companions recover
part of it (677 of 747 mm), and the static state added by
:func:`fenics_drill.studies.prepare.prepare` all of it.  In the dynamics of the paper scene
the companions make the bit velocity fluctuate 60 % more than the full order
(benchmarks/results/reduced_accuracy.md), so they are off by default.  Every added vector is
M-orthogonalised against the basis and M-normalised.
"""

from __future__ import annotations

import dolfinx.fem.petsc as fem_petsc
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import ufl
from dolfinx import fem

from fenics_drill.forms import energies
from fenics_drill.model.discretization import THETA_X, U, V, W, BeamDiscretization
from fenics_drill.model.kernels.compiled import form as compiled_form
from fenics_drill.model.operators import LinearOperators


class StaticSolver:
    """K^-1 with the supports and the drive end u(0), theta_x(0) held (one sparse LU, reused)."""

    def __init__(self, disc: BeamDiscretization, operators: LinearOperators):
        fixed = np.union1d(disc.support_dofs, [disc.end_dof(U, 0), disc.end_dof(THETA_X, 0)])
        self.free = np.setdiff1d(np.arange(disc.ndofs), fixed)
        self.ndofs = disc.ndofs
        self.lu = spla.splu(sp.csc_matrix(operators.stiffness[self.free][:, self.free]))

    def responses(self, loads: np.ndarray) -> np.ndarray:
        """Static responses (ndofs, k) to the columns of ``loads`` (ndofs, k)."""
        loads = np.asarray(loads).reshape(self.ndofs, -1)
        out = np.zeros_like(loads, dtype=float)
        out[self.free] = self.lu.solve(np.ascontiguousarray(loads[self.free]))
        return out


def bit_loads(disc: BeamDiscretization) -> dict[str, np.ndarray]:
    """A unit axial force and a unit torque at the bit, x = L."""
    force, torque = np.zeros(disc.ndofs), np.zeros(disc.ndofs)
    force[disc.end_dof(U, 1)] = 1.0
    torque[disc.end_dof(THETA_X, 1)] = 1.0
    return {"bit_force": force, "bit_torque": torque}


def wall_rest_load(disc: BeamDiscretization, gravity: np.ndarray, gravity_response: np.ndarray,
                   gap) -> np.ndarray | None:
    """The wall's reaction on a string at rest, estimated from the linear sag: the vertices the sag
    takes beyond the gap (one per vertex, or one for all) rest on the wall, which carries their lateral weight.
    None if none do."""
    w_dofs, v_dofs = disc.vertex_dofs(W), disc.vertex_dofs(V)
    radius = np.hypot(gravity_response[v_dofs], gravity_response[w_dofs])
    resting = radius > gap
    if not resting.any():
        return None
    load = np.zeros(disc.ndofs)
    for dofs in (v_dofs[resting], w_dofs[resting]):
        load[dofs] = -gravity[dofs]
    return load


def wall_friction_loads(disc: BeamDiscretization, reaction: np.ndarray, lateral: bool = False) -> dict[str, np.ndarray]:
    """The friction that the wall's ``reaction`` at rest (full-space loads on v and w) drives: at each resting vertex
    |F_n| on u (the axial friction) and on theta_x (the friction torque), and with ``lateral`` (the Coulomb force
    at the contact point) |F_n| along the wall's tangent t = (-n_w, n_v), which makes a spinning string climb.  A
    static response's shape depends neither on the friction coefficient, nor on the torque's arm, nor on the
    direction of sliding."""
    on_v, on_w = reaction[disc.vertex_dofs(V)], reaction[disc.vertex_dofs(W)]
    magnitude = np.hypot(on_v, on_w)
    axial, torque = np.zeros(disc.ndofs), np.zeros(disc.ndofs)
    axial[disc.vertex_dofs(U)] = magnitude
    torque[disc.vertex_dofs(THETA_X)] = magnitude
    loads = {"wall_axial_friction": axial, "wall_friction_torque": torque}
    if lateral:  # the reaction is -|F_n| n: so |F_n| t = (reaction_w, -reaction_v)
        along = np.zeros(disc.ndofs)
        along[disc.vertex_dofs(V)], along[disc.vertex_dofs(W)] = on_w, -on_v
        loads["wall_lateral_friction"] = along
    return loads


def climbing_friction(scene, disc: BeamDiscretization, operators: LinearOperators) -> str | None:
    """Why no modal basis can carry the scene, or None: a spinning string that rests on the wall with Coulomb
    friction at the contact point climbs it and swings along it, each resting vertex on the round wall, whose
    second-order shape (w = -sqrt(gap^2 - v^2)) a linear subspace misses by more than the wall's indentation
    (0.25 um on the paper's string) after a turn of half a degree: the reduced string lifted off and bounced
    (2505 impacts in 2 s of the paper scene) where the full order rests (0; docs/verification.md)."""
    contact = scene.contact
    if not (scene.model.contact and scene.model.gravity and contact.friction_model == "coulomb"
            and contact.friction > 0 and scene.drive.rotation_speed != 0 and np.any(operators.gravity)):
        return None
    statics = StaticSolver(disc, operators)
    gap = disc.vertex_gap(scene.borehole.radius)
    if wall_rest_load(disc, operators.gravity, statics.responses(operators.gravity)[:, 0], gap) is None:
        return None
    return ("the spinning string rests on the wall with Coulomb friction at the contact point: it climbs and swings "
            "along the round wall, which a modal basis cannot follow (contact.friction_model = 'coulomb')")


def scene_loads(scene, disc: BeamDiscretization, operators: LinearOperators, statics: StaticSolver):
    """name -> full-space load vector of every load the scene applies (see the module doc)."""
    loads: dict[str, np.ndarray] = {}
    if scene.model.gravity and np.any(operators.gravity):
        loads["gravity"] = operators.gravity
    if scene.model.bit_rock:
        loads.update(bit_loads(disc))
    if scene.model.contact and "gravity" in loads:
        gap = disc.vertex_gap(scene.borehole.radius)
        wall = wall_rest_load(disc, operators.gravity, statics.responses(operators.gravity)[:, 0], gap)
        if wall is not None:
            loads["wall_at_rest"] = wall
            if scene.contact.friction > 0:
                loads.update(wall_friction_loads(disc, wall, scene.contact.friction_model == "coulomb"))
    return loads


def tangent_responses(space, tangent, constraints: np.ndarray, loads: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """name -> full-space static response to each full-space load of ``loads`` of the string at a state whose
    tangent dr/dq in the full ``space`` is ``tangent``, with the rows ``constraints`` held: how the state moves
    when the load changes a little (the geometric stiffness and the wall's springs included)."""
    out = {}
    for name, load in loads.items():
        response, _ = space.saddle_solve(tangent, constraints, space.project(load), np.zeros(constraints.shape[0]))
        out[name] = space.expand(response)
    return out


def basis_error(phi: np.ndarray, stiffness, constraints: np.ndarray, load: np.ndarray, response: np.ndarray) -> float:
    """Share of the static strain energy of ``load`` the basis ``phi`` misses (square root; 0 = exact)."""
    exact = float(load @ response)
    if exact <= 0:
        return 0.0
    K = phi.T @ (stiffness @ phi)
    B = constraints
    m = B.shape[0]
    scale = np.abs(np.diag(K)).max()
    system = np.block([[K, scale * B.T], [scale * B, np.zeros((m, m))]])
    rhs = np.concatenate([phi.T @ load, np.zeros(m)])
    q = np.linalg.lstsq(system, rhs, rcond=None)[0][: phi.shape[1]]
    # the missed energy e^T K e of the error e = response - Phi q, which equals exact - load . Phi q (Galerkin,
    # both held) but has no cancellation: that difference left a floor of sqrt(round-off) ~ 1e-6
    error = response - phi @ q
    return float(np.sqrt(max(float(error @ (stiffness @ error)), 0.0) / exact))


def missed_share(phi: np.ndarray, stiffness, constraints: np.ndarray, vector: np.ndarray) -> float:
    """Share of a displacement ``vector`` (held at the drive end) the basis misses: :func:`basis_error` of
    the load K v whose static response it is."""
    return basis_error(phi, stiffness, constraints, stiffness @ vector, vector)


def axial_companions(disc: BeamDiscretization, statics: StaticSolver, vectors: np.ndarray,
                     kinematics: str) -> np.ndarray:
    """theta_i = -K^-1 D^2 f_el(0)[phi_i, phi_i] for each column phi_i (static modal derivatives)."""
    p = disc.form_properties
    dx = ufl.Measure("dx", domain=disc.mesh, metadata={"quadrature_degree": 2 * disc.element_degree})
    zero, direction = fem.Function(disc.V), fem.Function(disc.V)
    force = energies.elastic_force(p, ufl.TestFunction(disc.V), zero, dx, True, kinematics)
    second = compiled_form(ufl.derivative(ufl.derivative(force, zero, direction), zero, direction))
    loads = np.zeros((disc.ndofs, vectors.shape[1]))
    for i, phi in enumerate(vectors.T):
        direction.x.array[:] = phi
        loads[:, i] = -fem_petsc.assemble_vector(second).array
    return statics.responses(loads)


#: A vector whose part outside the basis is below this share of its M-norm is already in the span: the
#: round-off of Gram-Schmidt on vectors known to about machine precision (static responses, the static state).
SPAN_TOLERANCE = 1e-8
#: The same for eigenvectors of another eigensolve (the stuck-bit modes augmented onto the free string's):
#: they are known to about the eigensolver's 1e-10 residual over the gap of their frequencies, and below 1e-6
#: what is left can be mostly that error, a direction of noise that changes with round-off (a 10 m string's
#: stuck-bit modes left 3.8e-9 or 7.7e-8 of one, with and without SLEPc's purification, and the basis had 31
#: or 32 vectors).  The physical parts left are 3.7e-7 and more there, equal to 7 digits whatever the round-off;
#: on the paper string 1.2e-5 and more, so its basis is the same with either tolerance.
MODE_SPAN_TOLERANCE = 1e-6


def augment(phi: np.ndarray, vectors: np.ndarray, mass: sp.spmatrix, tolerance: float = SPAN_TOLERANCE) -> np.ndarray:
    """[Phi, V'] with V' the part of ``vectors`` M-orthogonal to [Phi], M-normalised (Gram-Schmidt twice);
    a vector already in the span (what is left is below ``tolerance`` of it) is dropped."""
    basis = phi
    for v in np.asarray(vectors).reshape(phi.shape[0], -1).T:
        size = np.sqrt(v @ (mass @ v))
        if size == 0:
            continue
        for _ in range(2):
            v = v - basis @ (basis.T @ (mass @ v))
        left = np.sqrt(v @ (mass @ v))
        if left > tolerance * size:
            basis = np.column_stack([basis, v / left])
    return basis


def enrich(phi: np.ndarray, scene, disc: BeamDiscretization, operators: LinearOperators,
           constraints_of) -> tuple[np.ndarray, dict]:
    """The guarded basis.  Checked: the static response of every load, and, with
    ``reduction.axial_companions`` and the geometric nonlinearity on, its axial companion; each one the
    modes miss beyond ``reduction.guard_tolerance`` is added when ``reduction.enrich`` is on.  ``constraints_of(phi)`` gives [B] of a basis.  Returns the
    basis and the guard's report: per vector, the share the modes alone miss, the share the final
    basis misses, and whether it was added."""
    red = scene.reduction
    statics = StaticSolver(disc, operators)
    loads = scene_loads(scene, disc, operators, statics)
    names = list(loads)
    vectors = statics.responses(np.column_stack([loads[n] for n in names])) if names else np.zeros((disc.ndofs, 0))
    if red.axial_companions and scene.model.geometric_nonlinearity and names:
        vectors = np.column_stack([vectors, axial_companions(disc, statics, vectors, scene.model.kinematics)])
        names += [f"{name}_axial_companion" for name in names]
    def missed(basis, i):
        return missed_share(basis, operators.stiffness, constraints_of(basis), vectors[:, i])

    report = {name: {"error_modes": missed(phi, i)} for i, name in enumerate(names)}
    added = [i for i, name in enumerate(names) if red.enrich and report[name]["error_modes"] > red.guard_tolerance]
    if added:
        phi = augment(phi, vectors[:, added], operators.mass)
    for i, name in enumerate(names):
        report[name]["added"] = i in added
        report[name]["error"] = missed(phi, i)
    return phi, report
