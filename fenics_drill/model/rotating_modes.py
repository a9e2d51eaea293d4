"""Modes of the string in steady spin: the energies linearised about it and their quadratic eigenproblem.

Linearised about a state U0 spinning at theta_x_dot = Omega (velocity Omega e_theta_x, no acceleration),
the left-hand side of (43) with the wall of (16)-(17) gives

    M x'' + (C + Omega G) x' + K x = 0,

M = df/dqdd, C + Omega G = df/dqd (C symmetric, the dissipation (38); Omega G its skew part, the
gyroscopic coupling 2 rho I4 Omega of theta_y' and theta_z' that the kinetic energy (24) with the
angular velocity (13) holds), and K = df/dq minus the wall's df/dq at U0: the material stiffness, the
geometric stiffness of any preload in U0 (weight on bit, sag) and the linearised wall springs with the
pendulum term F_n / r of a preloaded radial spring.  The energies hold no spin softening: with the
string's displacements in the inertial frame, (24) depends on theta_x only through theta_x_dot, so K does
not depend on Omega and G is the same at every speed (tests/model/test_rotating_modes.py checks both);
one linearisation serves a whole sweep.

Each speed is one quadratic eigenproblem (lambda^2 M + lambda (C + Omega G) + K) x = 0, solved by SLEPc's
PEP (TOAR, shift-and-invert about 0, so the lowest |lambda| come first).  Each mode is classified by the
orbit of (v, w) at the vertices (forward or backward whirl) and by its kinetic energy per field
(flexural, torsional, axial, as :func:`fenics_drill.model.reduction.modes.classify`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from petsc4py import PETSc
from slepc4py import SLEPc

from fenics_drill.model.kernels.banded_saddle import as_csr
from fenics_drill.model.kernels.compiled import interrupt_in
from fenics_drill.model.discretization import DRIVE, THETA_X, THETA_Y, THETA_Z, V, W, BeamDiscretization
from fenics_drill.model.internal_force import internal_force
from fenics_drill.model.reduction.modes import classify, shift_and_invert
from fenics_drill.model.operators import LinearOperators
from fenics_drill.model.reduction.spaces import FullSpace

#: Below this amplitude-weighted |orbit ratio| a lateral mode whirls along a line, not round (a
#: degenerate pair at Omega = 0, or a string on the wall that moves sideways only).
PLANAR_RATIO = 0.1
#: Share of the orbits (amplitude-weighted) turning one way for a mode to be called forward or backward.
WHIRL_SHARE = 0.9
#: A mode with less lateral kinetic energy than this share does not whirl (torsional, axial).
LATERAL_SHARE = 0.05


class Divergence(ValueError):
    """A linearised string with negative stiffness: buckled under its axial load (a real eigenvalue > 0)."""


class TooFewModes(ValueError):
    """The eigensolver found fewer whirl modes than asked for: too few dofs, or modes it could not converge."""


def held_space(disc: BeamDiscretization, held: tuple = DRIVE) -> FullSpace:
    """The full space without the support and stabiliser dofs and the ``held`` (field, end) pairs."""
    held_dofs = [disc.end_dof(field, end) for field, end in held]
    return FullSpace(disc, np.union1d(disc.support_dofs, held_dofs))


@dataclass
class SpinLinearisation:
    """M, C, G (per rad/s of spin) and K on the free dofs of ``space`` (SciPy CSR)."""

    space: FullSpace
    mass: sp.csr_matrix
    damping: sp.csr_matrix
    gyroscopic: sp.csr_matrix
    stiffness: sp.csr_matrix


def spin_velocity(disc: BeamDiscretization, spin: float) -> np.ndarray:
    """The full-space velocity of a rigid spin: theta_x_dot = ``spin`` everywhere."""
    velocity = np.zeros(disc.ndofs)
    velocity[disc.field_dofs[THETA_X]] = spin
    return velocity


def linearise_about_spin(disc: BeamDiscretization, operators: LinearOperators, model_switches, state: np.ndarray,
                         space: FullSpace, point_forces=()) -> SpinLinearisation:
    """The operators of the string linearised about the full-space displacement ``state`` in spin.

    ``model_switches`` is the scene's [model] section (which nonlinear energies are assembled, the
    kinematics); ``point_forces`` are forces built in ``space`` whose stiffness at ``state`` (at rest:
    no friction, no bit-rock) joins K, like the wall springs."""
    # Evaluated where the drive's dofs are free, so that the spin is uniform up to x = 0, then
    # restricted to ``space``: the rigid spin must not ramp down over the first element.
    supported = FullSpace(disc)
    internal = internal_force(disc, supported, operators, model_switches)
    q_supported = supported.project(state)
    internal.evaluate(q_supported, supported.project(spin_velocity(disc, 1.0)), np.zeros_like(q_supported))
    keep = np.searchsorted(supported.free, space.free)
    stiffness, first_order, mass = (sp.csr_matrix(part)[keep][:, keep] for part in internal.tangent_parts())
    q0 = space.project(state)
    for force in point_forces:
        tangent = force.tangent(force.evaluate(q0, np.zeros_like(q0), with_tangent=True), 1.0, 0.0)
        if tangent is not None:
            stiffness = stiffness - sp.csr_matrix(as_csr(tangent))
    damping = 0.5 * (first_order + first_order.T)
    gyroscopic = 0.5 * (first_order - first_order.T)
    return SpinLinearisation(space, mass, damping.tocsr(), gyroscopic.tocsr(), stiffness.tocsr())


@dataclass
class WhirlModes:
    """The lowest modes at one spin, sorted by frequency."""

    spin: float  # rad/s
    frequencies_hz: np.ndarray  # damped natural frequencies Im(lambda) / 2 pi
    damping_ratios: np.ndarray  # -Re(lambda) / |lambda|
    whirl: list[str]  # 'forward', 'backward', 'mixed', 'planar' or 'none' (no lateral motion)
    whirl_ratios: np.ndarray  # amplitude-weighted 2 Im(v w*) / (|v|^2 + |w|^2): +1 circular forward, -1 backward
    kinds: list[str]  # 'flexural', 'torsional', 'axial'
    vectors: np.ndarray  # complex full-space mode shapes (ndofs, n)
    relative_residual: float  # largest backward error |P(lambda) x| / ((|lambda|^2 |M| + |lambda| |D| + |K|) |x|)


def _petsc(matrix: sp.csr_matrix) -> PETSc.Mat:
    A = sp.csr_matrix(matrix)
    A.sort_indices()
    return PETSc.Mat().createAIJ(A.shape, csr=(A.indptr, A.indices, A.data), comm=PETSc.COMM_SELF)


#: Extra Krylov vectors tried, in turn, when SLEPc's TOAR fails to reorder its Schur form.
SUBSPACE_RETRIES = (0, 8, 16)


def _solve_pep(K: PETSc.Mat, D: PETSc.Mat, M: PETSc.Mat, nev: int) -> SLEPc.PEP:
    """TOAR with shift-and-invert about 0.  The v and w modes of a string come in exactly degenerate pairs;
    LAPACK's reordering of the projected Schur form (trexc, in SLEPc's DSSort) can fail to swap such a pair
    for one round-off (it did for one sparsity pattern of K).  Another subspace size builds another
    projected problem, so the solve is tried again with more Krylov vectors before giving up."""
    for extra in SUBSPACE_RETRIES:
        pep = SLEPc.PEP().create(PETSc.COMM_SELF)
        pep.setOperators([K, D, M])
        pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
        pep.setType(SLEPc.PEP.Type.TOAR)
        pep.setDimensions(nev=nev, ncv=min(max(2 * nev, nev + 24) + extra, K.getSize()[0]))
        pep.setScale(SLEPc.PEP.Scale.SCALAR)
        pep.setTarget(0.0)
        pep.setWhichEigenpairs(SLEPc.PEP.Which.TARGET_MAGNITUDE)
        shift_and_invert(pep.getST(), PETSc.PC.Type.LU)
        pep.setTolerances(tol=1e-10, max_it=500)
        try:
            pep.solve()
            return pep
        except (PETSc.Error, SystemError) as error:  # petsc4py may report PETSc's error as a SystemError
            pep.destroy()
            if interrupt_in(error) is not None:
                raise KeyboardInterrupt from error
            failure = error
    raise RuntimeError(f"SLEPc's PEP failed with {len(SUBSPACE_RETRIES)} subspace sizes") from failure


def kinetic_energy_fractions(mass: sp.csr_matrix, field_of_dof: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """Share of each field in Re(x^H M x) for complex columns x (M couples no two fields, Eq. 44): (n, 6)."""
    weighted = (np.conj(vectors) * (mass @ vectors)).real
    per_field = np.stack([weighted[field_of_dof == i].sum(axis=0) for i in range(6)], axis=1)
    return per_field / per_field.sum(axis=1, keepdims=True)


def orbit_whirl(v: np.ndarray, w: np.ndarray) -> tuple[float, float, float]:
    """Orbit measures of complex amplitudes v, w at the vertices: (amplitude-weighted ratio in [-1, 1],
    share of the orbits turning forward, amplitude-weighted |ratio|).  The orbit (Re v e^{i omega t},
    Re w e^{i omega t}) turns about +x, the sense of a positive spin, where Im(v conj(w)) > 0; a circle
    has |ratio| = 1, a line 0."""
    weight = np.abs(v) ** 2 + np.abs(w) ** 2
    turning = 2.0 * np.imag(v * np.conj(w))  # = weight * local ratio
    total, circular = weight.sum(), np.abs(turning).sum()
    if total == 0:
        return 0.0, 0.5, 0.0
    forward_share = turning.clip(min=0).sum() / circular if circular > 0 else 0.5
    return float(turning.sum() / total), float(forward_share), float(circular / total)


def whirl_label(forward_share: float, circularity: float, lateral_share: float) -> str:
    """forward / backward / mixed / planar / none from the orbit measures of one mode."""
    if lateral_share < LATERAL_SHARE:
        return "none"
    if circularity < PLANAR_RATIO:
        return "planar"
    if forward_share >= WHIRL_SHARE:
        return "forward"
    if forward_share <= 1.0 - WHIRL_SHARE:
        return "backward"
    return "mixed"


def solve_whirl_modes(disc: BeamDiscretization, linearisation: SpinLinearisation, spin: float, n_modes: int,
                      with_damping: bool = False) -> WhirlModes:
    """The ``n_modes`` lowest modes of the string spinning at ``spin`` rad/s (Im lambda > 0)."""
    lin = linearisation
    first_order = spin * lin.gyroscopic + (lin.damping if with_damping else 0.0 * lin.damping)
    K, D, M = _petsc(lin.stiffness), _petsc(first_order), _petsc(lin.mass)
    size = lin.space.size
    nev = min(2 * n_modes + 4, size - 2)
    pep = _solve_pep(K, D, M, nev)
    xr, xi = K.createVecRight(), K.createVecRight()
    values, vectors, errors, growth = [], [], [], []
    for i in range(pep.getConverged()):
        lam = complex(pep.getEigenpair(i, xr, xi))
        if lam.real > 0 and abs(lam.imag) < 1e-6 * abs(lam):
            growth.append(lam.real)
        if lam.imag > 0:
            values.append(lam)
            vectors.append(xr.array + 1j * xi.array)
            errors.append(pep.computeError(i, SLEPc.PEP.ErrorType.BACKWARD))
    for obj in (pep, K, D, M):
        obj.destroy()
    if growth:
        raise Divergence(f"the linearised string diverges (a real eigenvalue {max(growth):.3g} 1/s at {spin:g} rad/s): "
                         "its stiffness is not positive, it is buckled under the axial load")
    if len(values) < n_modes:
        raise TooFewModes(f"the spinning string gave {len(values)} of the {n_modes} whirl modes asked for "
                          f"(campbell.modes) at {spin:g} rad/s: a mesh of {disc.elements} elements may hold too "
                          "few of them; lower campbell.modes or raise beam.elements")
    order = np.argsort([lam.imag for lam in values])[:n_modes]
    lams = np.array([values[i] for i in order])
    X = np.stack([vectors[i] for i in order], axis=1)
    residual = max(errors[i] for i in order)
    full = np.zeros((disc.ndofs, n_modes), dtype=complex)
    full[lin.space.free] = X
    energy = kinetic_energy_fractions(lin.mass, disc.field_of_dof[lin.space.free], X)
    v_rows, w_rows = disc.vertex_dofs(V), disc.vertex_dofs(W)
    L, c_L = disc.properties.length, disc.properties.longitudinal_wave_speed
    whirl, ratios, kinds = [], [], []
    for k in range(n_modes):
        v, w = full[v_rows, k], full[w_rows, k]
        ratio, share, circularity = orbit_whirl(v, w)
        kinds.append(classify(lams[k].imag / (2 * math.pi) * L / c_L, energy[k]))
        whirl.append(whirl_label(share, circularity, energy[k][[V, W, THETA_Y, THETA_Z]].sum()))
        ratios.append(ratio)
    return WhirlModes(spin, lams.imag / (2 * math.pi), -lams.real / np.abs(lams), whirl, np.array(ratios), kinds,
                      full, residual)
