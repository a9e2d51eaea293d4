"""Modes of the string: the modal problem (62) and the choice of the reduced basis (Section 6.3).

Solve: K phi = omega^2 M phi with SLEPc, Krylov-Schur with shift-and-invert about a
small negative target, so the two rigid-body modes (u and theta_x are free) and the
lowest elastic modes come first; support dofs are Dirichlet rows that never enter the
spectrum.  The problem is solved for each group of fields that K and M couple (four for the straight
string).  Every mode is classified from its kinetic-energy fractions per field.

Select: the modes a scene's ``reduction.rule`` keeps (the paper's Section 6.3 bands,
Table 4; the 'auto' bands of what the scene excites and its step resolves, with the
torsional modes of a stuck bit; bands or counts per family; or all).  Enrichment of the kept modes lives in
:mod:`fenics_drill.model.reduction.enrichment`, the space built on them in :mod:`fenics_drill.model.reduction.spaces`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from petsc4py import PETSc
from slepc4py import SLEPc

from fenics_drill.model.resolution import band_frequency
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
    vectors: np.ndarray | None  # (ndofs, n_modes); None: not kept (frequencies and kinds only)
    #: omega^2 of each mode, signed [1/s^2] (the frequencies clip a negative one to 0: a buckled mode); None: not known
    eigenvalues: np.ndarray | None = None
    #: x of each mode's largest lateral displacement [m] (None: not known)
    lateral_peak_x: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.frequencies_hz)

    def select(self, indices) -> "ModalBasis":
        idx = np.asarray(indices, dtype=int)
        pick = lambda a: None if a is None else a[idx]  # noqa: E731
        return ModalBasis(
            self.frequencies_hz[idx], self.f_star[idx], [self.kinds[i] for i in idx],
            self.energy_fractions[idx], None if self.vectors is None else self.vectors[:, idx],
            pick(self.eigenvalues), pick(self.lateral_peak_x),
        )


def classify(f_star: float, fractions: np.ndarray) -> str:
    """Mode kind from the kinetic-energy fractions (u: axial, theta_x: torsional, rest: flexural)."""
    shares = {"axial": fractions[U], "torsional": fractions[THETA_X],
              "flexural": fractions[[V, W, THETA_Y, THETA_Z]].sum()}
    kind = max(shares, key=shares.get)
    if kind != "flexural" and abs(f_star) < RIGID_F_STAR:
        return "rigid"
    return kind


def estimated_mode_counts(disc: BeamDiscretization, f_max_hz: float) -> dict[int, float]:
    """Modes below f_max by the field that carries them, from the closed forms (wave equations for u and
    theta_x, Euler-Bernoulli bending for each plane, counted under its displacement v or w)."""
    p = disc.properties
    L = p.length
    s = p.section
    bending_speed = math.sqrt(p.young_modulus * s.I4 / (p.density * s.area))
    omega = 2.0 * math.pi * f_max_hz
    flexural_per_plane = L / math.pi * math.sqrt(omega / bending_speed) + 1
    return {U: 2.0 * L * f_max_hz / p.longitudinal_wave_speed + 1,
            THETA_X: 2.0 * L * f_max_hz / p.torsional_wave_speed + 1,
            V: flexural_per_plane, W: flexural_per_plane}


def estimated_mode_count(disc: BeamDiscretization, f_max_hz: float) -> int:
    """Number of modes below f_max from the closed forms (:func:`estimated_mode_counts`)."""
    return int(sum(estimated_mode_counts(disc, f_max_hz).values())) + 2


def coupled_field_groups(matrices, field_of_dof: np.ndarray) -> list[np.ndarray]:
    """The fields that the (PETSc, serial) ``matrices`` couple, in groups: two fields share a group when an entry
    between their dofs is nonzero in any of them.  The straight string's K and M of (62) couple none of u,
    theta_x, (v, theta_z) and (w, theta_y) (Eq. 44), so the modal problem splits into four.  Groups are ordered
    by their first field."""
    group = list(range(6))

    def root(f):
        while group[f] != f:
            f = group[f]
        return f

    for matrix in matrices:
        indptr, columns, values = matrix.getValuesCSR()
        rows = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
        nonzero = values != 0.0
        for a, b in set(zip(field_of_dof[rows[nonzero]].tolist(), field_of_dof[columns[nonzero]].tolist())):
            group[root(a)] = root(b)
    roots = np.array([root(f) for f in range(6)])
    groups = [np.flatnonzero(roots == r) for r in set(roots.tolist())]
    return sorted(groups, key=lambda fields: fields[0])


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
    # nev + 32 Krylov vectors: twice nev (SLEPc's default) costs more in orthogonalisation than it saves in
    # restarts (the paper scene's 204 requested pairs: 0.40 s against 0.69 s)
    eps.setDimensions(nev=nev, ncv=nev + 32)
    eps.setTarget(target)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
    shift_and_invert(eps.getST(), PETSc.PC.Type.CHOLESKY)
    # no purification (SLEPc's default: one more solve per eigenvector, 0.09 s of 0.45 s for the paper's 204):
    # (K - target M)^-1 M maps every vector to one that vanishes at the Dirichlet rows (K's row there is the
    # identity's, M's is zero), so the eigenvectors hold no part of M's null space to purify
    eps.setPurify(False)
    eps.setTolerances(tol=1e-10, max_it=500)
    eps.solve()
    return eps


def _modes_of_block(K: PETSc.Mat, M: PETSc.Mat, dofs: np.ndarray, free_dofs: int, nev: int, target: float,
                    f_max: float) -> tuple[np.ndarray, np.ndarray]:
    """(eigenvalues, eigenvectors on ``dofs``) of the block of (K, M) on ``dofs``, ``free_dofs`` of them
    unconstrained: the number of requested pairs starts at ``nev`` and grows until the highest converged
    mode lies above f_max [Hz] (or the block has no more)."""
    rows = PETSc.IS().createGeneral(dofs, comm=K.getComm())
    K_block, M_block = K.createSubMatrix(rows, rows), M.createSubMatrix(rows, rows)
    nev = max(1, min(nev, free_dofs - 1))
    while True:
        eps = _solve_eps(K_block, M_block, nev, target)
        nconv = eps.getConverged()
        eigenvalues = np.array([eps.getEigenvalue(i).real for i in range(nconv)])
        top_hz = math.sqrt(max(eigenvalues.max(), 0.0)) / (2 * math.pi) if nconv else 0.0
        if (nconv >= nev and top_hz > f_max) or nev >= free_dofs - 1:
            break
        eps.destroy()
        nev = min(2 * nev, free_dofs - 1)
    vr = K_block.createVecRight()
    vectors = np.empty((len(dofs), nconv))
    for i in range(nconv):
        eps.getEigenvector(i, vr)
        vectors[:, i] = vr.array
    for obj in (eps, vr, K_block, M_block, rows):
        obj.destroy()
    return eigenvalues, vectors


def solve_modes(disc: BeamDiscretization, f_star_max: float, mass=None, held: tuple = (),
                safety: float = 1.15, vectors: bool = True, stiffness=None) -> ModalBasis:
    """All modes with f* = f L / c_L <= ``f_star_max`` (Eq. 95), sorted by frequency; ``mass`` is the
    assembled free-free M (SciPy) used to normalise and classify them (assembled here if not given).
    ``held`` adds (field, end) pairs to the supports: with :data:`~fenics_drill.model.discretization.DRIVE`,
    the modes of the string held by the drive as in a run (axial and torsional quarter waves).
    ``vectors``: keep the eigenvectors (False: frequencies and kinds only, for the full order's spectra; the
    modes of a band that grows with the length cost length^2 in memory, 0.7 GB at 3 km).
    ``stiffness``: K of (62) on every dof instead of the stiffness (46): the tangent stiffness about a loaded
    static state (:mod:`fenics_drill.studies.operating_state`), with its geometric stiffness and wall springs.

    The problem is solved for each group of fields that K and M couple (:func:`coupled_field_groups`: four
    for the straight string, a third of the cost of one solve of the whole); in each, the number of requested
    eigenpairs starts from the closed-form estimate and grows until the highest converged mode lies above
    the band.
    """
    p = disc.properties
    c_L = p.longitudinal_wave_speed
    f_max = f_star_max * c_L / p.length
    K, M = assemble_modal_pair(disc, held, stiffness)
    mass = sp.csr_matrix(assemble_linear(disc).mass if mass is None else mass)
    # The target sits below zero so K - target*M is positive definite despite the rigid modes.
    target = -((2.0 * math.pi * 1e-3 * c_L / p.length) ** 2)
    estimates = estimated_mode_counts(disc, f_max)
    constrained = np.zeros(disc.ndofs, dtype=bool)
    constrained[np.asarray(disc.support_dofs, dtype=int)] = True
    constrained[[disc.end_dof(field, end) for field, end in held]] = True
    eigenvalues, fractions, groups, peaks = [], [], [], []
    lateral = np.isin(disc.field_of_dof, (V, W))
    for fields in coupled_field_groups((K, M), disc.field_of_dof):  # (62) one coupled group at a time
        dofs = np.flatnonzero(np.isin(disc.field_of_dof, fields)).astype(np.int32)
        free = int(np.count_nonzero(~constrained[dofs]))
        if free == 0:
            continue
        estimate = sum(estimates.get(f, 0.0) for f in fields)
        values, block = _modes_of_block(K, M, dofs, free, max(8, int(safety * estimate) + 4), target, f_max)
        within = np.sqrt(np.clip(values, 0.0, None)) / (2.0 * math.pi) * p.length / c_L <= f_star_max
        values, block = values[within], block[:, within]
        # M-normalise (SLEPc does for GHEP; doing it again makes the contract explicit); M couples no two groups
        group_mass = mass[dofs][:, dofs]
        block /= np.sqrt(np.einsum("ij,ij->j", block, group_mass @ block))
        eigenvalues.append(values)
        fractions.append(field_mass_fractions(group_mass, disc.field_of_dof[dofs], block))
        sideways = lateral[dofs]
        peaks.append(disc.dof_coordinates[dofs[sideways]][np.argmax(np.abs(block[sideways]), axis=0)]
                     if sideways.any() else np.full(block.shape[1], np.nan))
        groups.append((dofs, block if vectors else None))
    for obj in (K, M):
        obj.destroy()
    order = np.argsort(np.concatenate(eigenvalues))
    eigenvalues = np.concatenate(eigenvalues)[order]
    fractions = np.concatenate(fractions)[order]
    freqs = np.sqrt(np.clip(eigenvalues, 0.0, None)) / (2.0 * math.pi)
    f_star = freqs * p.length / c_L
    kinds = [classify(fs, fr) for fs, fr in zip(f_star, fractions)]
    stacked = None
    if vectors:
        stacked = np.zeros((disc.ndofs, len(order)))
        column = 0
        for dofs, block in groups:
            stacked[dofs[:, None], np.arange(column, column + block.shape[1])] = block
            column += block.shape[1]
        stacked = stacked[:, order]
    return ModalBasis(freqs, f_star, kinds, fractions, stacked, eigenvalues, np.concatenate(peaks)[order])


def paper_bands(length: float, longitudinal_wave_speed: float) -> dict[str, float]:
    """Section 6.3 as printed: flexural f* <= 5 L / c_L, torsional and axial f* <= 4."""
    return {"flexural": 5.0 * length / longitudinal_wave_speed, "torsional": 4.0, "axial": 4.0}


#: Harmonics of the spin the 'auto' rule keeps flexural modes for (the paper keeps 5 Hz at Omega = 1 Hz).
SPIN_HARMONICS = 5.0


def step_band(scene) -> float:
    """The f* up to which the scene's time step resolves the motion: f*_max of the band B with the
    nominal step (time.band_steps steps per period of f_max, at least 2), or the Nyquist band L / (2 dt c_L)
    of a step of the scene's own."""
    p = scene.beam_properties
    f_star_max = scene.modal.f_star_max
    if scene.time.dt > 0:
        return min(f_star_max, p.length / (2.0 * scene.time.dt * p.longitudinal_wave_speed))
    return f_star_max


def auto_bands(scene) -> dict[str, float]:
    """The 'auto' rule's f* bound per family, from what the scene excites and resolves: flexural modes
    up to SPIN_HARMONICS times the spin frequency Omega / 2 pi (the paper's 5 Hz at Omega = 2 pi rad/s),
    torsional and axial modes up to what the time step resolves (the paper's f* = 4 at its step)."""
    p = scene.beam_properties
    step = step_band(scene)
    spin_hz = abs(scene.drive.rotation_speed) / (2.0 * math.pi)
    flexural = SPIN_HARMONICS * spin_hz * p.length / p.longitudinal_wave_speed
    return {"flexural": min(flexural, step), "torsional": step, "axial": step}


def reduction_bands(scene) -> dict[str, float] | None:
    """The f* bound per family of ``reduction.rule`` ('paper', 'band', 'auto'); None for 'count', 'none'."""
    red, p = scene.reduction, scene.beam_properties
    if red.rule == "paper":
        return paper_bands(p.length, p.longitudinal_wave_speed)
    if red.rule == "band":
        return {f: getattr(red, f) for f in FAMILIES}
    if red.rule == "auto":
        return auto_bands(scene)
    return None


def select_modes(basis: ModalBasis, scene) -> np.ndarray:
    """Indices of the modes kept by ``reduction.rule`` (always including the rigid modes).

    'paper': the printed Section 6.3 bands; 'auto': :func:`auto_bands`; 'band': ``reduction.<family>``
    is the f* upper bound per family; 'count': ``reduction.<family>`` is the number of lowest modes kept
    per family; 'none': every mode (the full model uses no basis).
    """
    reduction = scene.reduction
    kinds = np.array(basis.kinds)
    keep = kinds == "rigid"
    if reduction.rule == "none":
        return np.arange(len(basis))
    if reduction.rule == "count":
        for family in FAMILIES:
            members = np.flatnonzero(kinds == family)[: int(getattr(reduction, family))]
            keep[members] = True
        return np.flatnonzero(keep)
    bands = reduction_bands(scene)
    if bands is None:
        raise ValueError(f"unknown reduction rule {reduction.rule!r}")
    for family in FAMILIES:
        keep |= (kinds == family) & (basis.f_star > 0) & (basis.f_star <= bands[family])
    return np.flatnonzero(keep)


def _field_modes(disc: BeamDiscretization, field: int, held_ends: tuple, f_star_max: float, mass, stiffness,
                 kind: str) -> ModalBasis:
    """The modes of one field's block of (62) up to ``f_star_max``, with the field held at ``held_ends``
    (0: x = 0, 1: x = L) and at the supports.  The linear operators (46) couple neither u nor theta_x with
    any other field, so their blocks alone give their modes (:func:`_lowest_pairs`)."""
    p = disc.properties
    held = [disc.end_dof(field, end) for end in held_ends]
    inner = np.setdiff1d(disc.field_dofs[field], np.concatenate([held, disc.support_dofs]).astype(int))
    K = sp.csc_matrix(sp.csr_matrix(stiffness)[inner][:, inner])
    M = sp.csc_matrix(sp.csr_matrix(mass)[inner][:, inner])
    omega_max = 2.0 * math.pi * f_star_max * p.longitudinal_wave_speed / p.length
    eigenvalues, block = _lowest_pairs(K, M, omega_max**2)
    vectors = np.zeros((disc.ndofs, eigenvalues.size))
    vectors[inner] = block  # M-orthonormal: both solvers normalise block^T M block = I
    freqs = np.sqrt(eigenvalues) / (2.0 * math.pi)
    fractions = field_mass_fractions(mass, disc.field_of_dof, vectors)
    return ModalBasis(freqs, freqs * p.length / p.longitudinal_wave_speed, [kind] * eigenvalues.size,
                      fractions, vectors)


#: Systems up to this size are solved dense (LAPACK's eigh); larger ones by shift-and-invert Lanczos.
DENSE_BLOCK = 200


def _lowest_pairs(K: sp.spmatrix, M: sp.spmatrix, largest: float) -> tuple[np.ndarray, np.ndarray]:
    """The eigenpairs K x = lambda M x with lambda <= ``largest`` of a positive definite K (a held bar's
    block: tridiagonal for P1), ascending, M-orthonormal.  Shift-and-invert Lanczos about 0 (ARPACK, one
    sparse LU) for as many pairs as the band may hold, doubled until one lies above it: a dense eigensolve
    of the block costs O(n^3) for the handful of modes wanted."""
    n = K.shape[0]
    if n <= DENSE_BLOCK:
        return sla.eigh(K.toarray(), M.toarray(), subset_by_value=(0.0, largest))
    wanted = 8
    start = np.random.default_rng(0).standard_normal(n)  # ARPACK's own start is random: a run is reproducible
    while True:
        values, vectors = spla.eigsh(K, min(wanted, n - 2), M, sigma=0.0, which="LM", v0=start)
        order = np.argsort(values)
        values, vectors = values[order], vectors[:, order]
        if values[-1] > largest or wanted >= n - 2:
            keep = values <= largest
            return values[keep], vectors[:, keep]
        wanted *= 2


def stuck_bit_modes(disc: BeamDiscretization, f_star_max: float, mass, stiffness) -> ModalBasis:
    """Torsional modes of the string held by the drive and stuck at the bit (theta_x held at both ends):
    the fixed-fixed waves n c_T / 2L that ring while the bit sticks (stick-slip, Section 6.9).  The modes of
    the free bit alone reach the bit's stuck state only through many of them; with these, the basis
    spans both phases, as the fixed-interface modes of Craig & Bampton (1968) with the static bit
    responses of the guard as constraint modes."""
    return _field_modes(disc, THETA_X, (0, 1), f_star_max, mass, stiffness, "torsional")


def drive_held_modes(disc: BeamDiscretization, free: ModalBasis, f_star_max: float, mass, stiffness) -> ModalBasis:
    """The modes of the band B with u and theta_x held at x = 0, as the drive holds them in a run (what
    ``solve_modes(..., held=DRIVE)`` gives, without a second eigensolve of the whole string): holding them
    leaves the flexural modes of the ``free`` string as they are, and the axial and torsional modes come
    from their own blocks (:func:`_field_modes`)."""
    flexural = free.select(np.flatnonzero(np.array(free.kinds) == "flexural"))
    parts = [flexural, *(_field_modes(disc, field, (0,), f_star_max, mass, stiffness, kind)
                         for field, kind in ((U, "axial"), (THETA_X, "torsional")))]
    combined = ModalBasis(np.concatenate([part.frequencies_hz for part in parts]),
                          np.concatenate([part.f_star for part in parts]),
                          [kind for part in parts for kind in part.kinds],
                          np.concatenate([part.energy_fractions for part in parts]),
                          None if free.vectors is None else np.hstack([part.vectors for part in parts]))
    return combined.select(np.argsort(combined.frequencies_hz, kind="stable"))


def family_counts(kinds) -> dict[str, int]:
    """Number of modes of each kind."""
    kinds = list(kinds)
    return {k: kinds.count(k) for k in ("rigid", *FAMILIES)}
