"""Modes of the string: the modal problem (62) and the choice of the reduced basis (Section 6.3).

Solve: K phi = omega^2 M phi with SLEPc, Krylov-Schur with shift-and-invert about a
small negative target, so the two rigid-body modes (u and theta_x are free) and the
lowest elastic modes come first; support dofs are Dirichlet rows that never enter the
spectrum.  Every mode is classified from its kinetic-energy fractions per field.

Select: the modes a scene's ``reduction.rule`` keeps (the paper's Section 6.3 bands,
Table 4; bands or counts per family; or all).  Enrichment of the kept modes lives in
:mod:`fenics_drill.model.enrichment`, the space built on them in :mod:`fenics_drill.model.spaces`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc
from slepc4py import SLEPc

from fenics_drill.model.discretization import THETA_X, THETA_Y, THETA_Z, U, V, W, BeamDiscretization
from fenics_drill.model.operators import assemble_linear, assemble_modal_pair, field_mass_fractions

KINDS = ("rigid", "flexural", "torsional", "axial")
FAMILIES = ("flexural", "torsional", "axial")

#: Axial or torsional modes below this f* are rigid-body motions: the first elastic
#: axial mode of a free-free bar sits at f* = 1/2 and the first torsional one at
#: f* = c_T / (2 c_L) ~ 0.29 for steel, while round-off leaves rigid modes near 1e-5.
RIGID_F_STAR = 0.05


@dataclass
class ModalBasis:
    """Eigenpairs of (62) sorted by frequency, M-orthonormal eigenvectors as columns."""

    frequencies_hz: np.ndarray
    f_star: np.ndarray
    kinds: list[str]
    energy_fractions: np.ndarray  # (n_modes, 6): kinetic energy share of u, v, w, tx, ty, tz
    vectors: np.ndarray  # (ndofs, n_modes)

    def __len__(self) -> int:
        return len(self.frequencies_hz)

    def select(self, indices) -> "ModalBasis":
        idx = np.asarray(indices, dtype=int)
        return ModalBasis(
            self.frequencies_hz[idx], self.f_star[idx], [self.kinds[i] for i in idx],
            self.energy_fractions[idx], self.vectors[:, idx],
        )


def classify(f_star: float, fractions: np.ndarray) -> str:
    """Mode kind from the kinetic-energy fractions (u: axial, theta_x: torsional, rest: flexural)."""
    shares = {"axial": fractions[U], "torsional": fractions[THETA_X],
              "flexural": fractions[[V, W, THETA_Y, THETA_Z]].sum()}
    kind = max(shares, key=shares.get)
    if kind != "flexural" and abs(f_star) < RIGID_F_STAR:
        return "rigid"
    return kind


def estimated_mode_count(disc: BeamDiscretization, f_max_hz: float) -> int:
    """Number of modes below f_max from the closed forms (Euler-Bernoulli bending, wave equations)."""
    p = disc.properties
    L = p.length
    s = p.section
    bending_speed = math.sqrt(p.young_modulus * s.I4 / (p.density * s.area))
    omega = 2.0 * math.pi * f_max_hz
    flexural_per_plane = L / math.pi * math.sqrt(omega / bending_speed) + 1
    torsional = 2.0 * L * f_max_hz / p.torsional_wave_speed + 1
    axial = 2.0 * L * f_max_hz / p.longitudinal_wave_speed + 1
    return int(2 * flexural_per_plane + torsional + axial) + 2


def shift_and_invert(st: SLEPc.ST, factorisation: str) -> None:
    """Shift-and-invert spectral transformation with a direct MUMPS solve ('cholesky' or 'lu')."""
    st.setType(SLEPc.ST.Type.SINVERT)
    ksp = st.getKSP()
    ksp.setType(PETSc.KSP.Type.PREONLY)
    pc = ksp.getPC()
    pc.setType(factorisation)
    pc.setFactorSolverType("mumps")


def _solve_eps(K: PETSc.Mat, M: PETSc.Mat, nev: int, target: float) -> SLEPc.EPS:
    eps = SLEPc.EPS().create(K.getComm())
    eps.setOperators(K, M)
    eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    eps.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
    eps.setDimensions(nev=nev, ncv=max(2 * nev, nev + 32))
    eps.setTarget(target)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
    shift_and_invert(eps.getST(), PETSc.PC.Type.CHOLESKY)
    eps.setTolerances(tol=1e-10, max_it=500)
    eps.solve()
    return eps


def solve_modes(disc: BeamDiscretization, f_star_max: float, mass=None, held: tuple = (),
                safety: float = 1.15) -> ModalBasis:
    """All modes with f* = f L / c_L <= ``f_star_max`` (Eq. 95), sorted by frequency; ``mass`` is the
    assembled free-free M (SciPy) used to normalise and classify them (assembled here if not given).
    ``held`` adds (field, end) pairs to the supports: with :data:`~fenics_drill.model.discretization.DRIVE`,
    the modes of the string held by the drive as in a run (axial and torsional quarter waves).

    The number of requested eigenpairs starts from the closed-form estimate and
    grows until the highest converged mode lies above the band.
    """
    p = disc.properties
    c_L = p.longitudinal_wave_speed
    f_max = f_star_max * c_L / p.length
    K, M = assemble_modal_pair(disc, held)
    mass = assemble_linear(disc).mass if mass is None else mass
    # The target sits below zero so K - target*M is positive definite despite the rigid modes.
    target = -((2.0 * math.pi * 1e-3 * c_L / p.length) ** 2)
    nev = max(8, int(safety * estimated_mode_count(disc, f_max)) + 4)
    constrained = len(disc.support_dofs) + len(held)
    nev = min(nev, disc.ndofs - constrained - 1)
    while True:
        eps = _solve_eps(K, M, nev, target)
        nconv = eps.getConverged()
        eigenvalues = np.array([eps.getEigenvalue(i).real for i in range(nconv)])
        top_hz = math.sqrt(max(eigenvalues.max(), 0.0)) / (2 * math.pi) if nconv else 0.0
        free_dofs = disc.ndofs - constrained
        if (nconv >= nev and top_hz > f_max) or nev >= free_dofs - 1:
            break
        nev = min(2 * nev, free_dofs - 1)
    vr = K.createVecRight()
    vectors = np.empty((disc.ndofs, nconv))
    for i in range(nconv):
        eps.getEigenvector(i, vr)
        vectors[:, i] = vr.array
    order = np.argsort(eigenvalues)
    eigenvalues, vectors = eigenvalues[order], vectors[:, order]
    # M-normalise (SLEPc does for GHEP; doing it again makes the contract explicit).
    vectors /= np.sqrt(np.einsum("ij,ij->j", vectors, mass @ vectors))
    freqs = np.sqrt(np.clip(eigenvalues, 0.0, None)) / (2.0 * math.pi)
    f_star = freqs * p.length / c_L
    keep = f_star <= f_star_max
    fractions = field_mass_fractions(mass, disc.field_of_dof, vectors[:, keep])
    kinds = [classify(fs, fr) for fs, fr in zip(f_star[keep], fractions)]
    for obj in (eps, K, M):
        obj.destroy()
    return ModalBasis(freqs[keep], f_star[keep], kinds, fractions, vectors[:, keep])


def paper_bands(length: float, longitudinal_wave_speed: float) -> dict[str, float]:
    """Section 6.3 as printed: flexural f* <= 5 L / c_L, torsional and axial f* <= 4."""
    return {"flexural": 5.0 * length / longitudinal_wave_speed, "torsional": 4.0, "axial": 4.0}


def select_modes(basis: ModalBasis, reduction, length: float, longitudinal_wave_speed: float) -> np.ndarray:
    """Indices of the modes kept by ``reduction.rule`` (always including the rigid modes).

    'paper': the printed Section 6.3 bands; 'band': ``reduction.<family>`` is
    the f* upper bound per family; 'count': ``reduction.<family>`` is the number of
    lowest modes kept per family; 'none': every mode (the full model uses no basis).
    """
    rule = reduction.rule
    kinds = np.array(basis.kinds)
    keep = kinds == "rigid"
    if rule == "none":
        return np.arange(len(basis))
    if rule in ("paper", "band"):
        bands = paper_bands(length, longitudinal_wave_speed) if rule == "paper" else {
            f: getattr(reduction, f) for f in FAMILIES
        }
        for family in FAMILIES:
            keep |= (kinds == family) & (basis.f_star > 0) & (basis.f_star <= bands[family])
    elif rule == "count":
        for family in FAMILIES:
            members = np.flatnonzero(kinds == family)[: int(getattr(reduction, family))]
            keep[members] = True
    else:
        raise ValueError(f"unknown reduction rule {rule!r}")
    return np.flatnonzero(keep)


def family_counts(kinds) -> dict[str, int]:
    """Number of modes of each kind."""
    kinds = list(kinds)
    return {k: kinds.count(k) for k in ("rigid", *FAMILIES)}
