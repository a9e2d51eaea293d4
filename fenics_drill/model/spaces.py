"""The space the dynamics is solved in: Q = [Phi] q, Eqs. (63)-(64).

Two kinds share one interface so the integrator never asks which it has:

* :class:`ModalSpace` - the columns of [Phi] are M-orthonormal modes (dense,
  N_dofs x N_red); projected operators are small dense matrices.
* :class:`FullSpace` - ``reduction.rule = "none"``: [Phi] selects the dofs not
  held by the supports (sparse); projected operators stay sparse.  This is the
  full-order reference the reduced models are measured against.

Either way the transverse supports are satisfied by the space itself, and only
u(0, t) = V0 t and theta_x(0, t) = Omega t need Lagrange multipliers (70)-(76).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fenics_drill.model.banded_saddle import BandedSaddle
from fenics_drill.model.discretization import THETA_X, U, BeamDiscretization
from fenics_drill.model.enrichment import augment, enrich
from fenics_drill.model.modes import reduction_bands, select_modes, solve_modes, stuck_bit_modes
from fenics_drill.model.operators import LinearOperators


class SaddleFactorisation:
    """The factorised saddle matrix of (76) of the last (tangent, constraints) pair: a Newton iterate
    that keeps its tangent (modified Newton) solves without factorising again."""

    def __init__(self, factorise):
        self.factorise = factorise  # (tangent, constraints) -> solve(rhs_q, rhs_c) -> (dq, mu)
        self.key = self.value = None

    def __call__(self, tangent, constraints):
        if self.key is None or self.key[0] is not tangent or self.key[1] is not constraints:
            self.key, self.value = (tangent, constraints), self.factorise(tangent, constraints)
        return self.value


def constraint_scale(tangent, constraints) -> float:
    """Factor k for the rows of [B] in the saddle system (76): with k [B] the constraint rows
    have the size of the tangent's, otherwise the system is singular to working precision."""
    diagonal = np.abs(tangent.diagonal()).max()
    largest = np.abs(np.asarray(constraints)).max(initial=0.0)  # no rows: a hook load with a top drive
    return diagonal / largest if diagonal > 0 and largest > 0 else 1.0


class ModalSpace:
    """Dense modal basis [Phi] (N_dofs x N_red)."""

    sparse = False

    def __init__(self, phi: np.ndarray):
        self.phi = np.ascontiguousarray(phi)
        self._saddle = SaddleFactorisation(self._factorise)

    @property
    def size(self) -> int:
        return self.phi.shape[1]

    def expand(self, q: np.ndarray) -> np.ndarray:
        return self.phi @ q

    def project(self, vector: np.ndarray) -> np.ndarray:
        return self.phi.T @ vector

    def project_matrix(self, matrix: sp.spmatrix) -> np.ndarray:
        """[Phi]^T A [Phi], touching only the rows of A that hold entries."""
        A = sp.csr_matrix(matrix)
        rows = np.flatnonzero(np.diff(A.indptr))
        if rows.size == 0:
            return np.zeros((self.size, self.size))
        return self.phi[rows].T @ (A[rows] @ self.phi)

    def rows(self, dofs: np.ndarray) -> np.ndarray:
        """The rows of [Phi] of some dofs: maps q to the values of those dofs."""
        return self.phi[np.asarray(dofs)]

    def zeros_matrix(self) -> np.ndarray:
        return np.zeros((self.size, self.size))

    def solve(self, matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        return sla.solve(matrix, rhs, check_finite=False)

    def combine(self, terms) -> np.ndarray:
        """sum of c A over the (c, A) of ``terms``: a tangent from its parts."""
        out = np.zeros((self.size, self.size))
        for c, matrix in terms:
            out += c * matrix
        return out

    @staticmethod
    def _factorise(tangent: np.ndarray, constraints: np.ndarray):
        m = constraints.shape[0]
        k = constraint_scale(tangent, constraints)
        system = np.block([[tangent, k * constraints.T], [k * constraints, np.zeros((m, m))]])
        factors = sla.lu_factor(system, check_finite=False)
        n = tangent.shape[0]

        def solve(rhs_q, rhs_c):
            x = sla.lu_solve(factors, np.concatenate([rhs_q, k * rhs_c]), check_finite=False)
            return x[:n], k * x[n:]

        return solve

    def saddle_solve(self, tangent: np.ndarray, constraints: np.ndarray, rhs_q: np.ndarray, rhs_c: np.ndarray):
        """Solve [[J, B^T], [B, 0]] (dq, mu) = (rhs_q, rhs_c), Eq. (76) (LU kept for the same J and B)."""
        return self._saddle(tangent, constraints)(rhs_q, rhs_c)


class FullSpace:
    """Full-order model: [Phi] is the (sparse) selection of the dofs free of supports."""

    sparse = True

    def __init__(self, disc: BeamDiscretization, fixed: np.ndarray | None = None):
        """The dofs of ``disc`` but the ``fixed`` ones (default: the supports and stabilisers)."""
        ndofs = disc.ndofs
        self.free = np.setdiff1d(np.arange(ndofs), disc.support_dofs if fixed is None else fixed)
        self.ndofs = ndofs
        self._saddle = SaddleFactorisation(self._factorise)
        # the free dofs numbered along the string: an element couples only neighbours in this order
        self._band_order = np.argsort(disc.dof_coordinates[self.free], kind="stable")
        self.phi = sp.csr_matrix(
            (np.ones(self.free.size), (self.free, np.arange(self.free.size))), shape=(ndofs, self.free.size)
        )

    @property
    def size(self) -> int:
        return self.free.size

    def expand(self, q: np.ndarray) -> np.ndarray:
        out = np.zeros(self.ndofs)
        out[self.free] = q
        return out

    def project(self, vector: np.ndarray) -> np.ndarray:
        return np.asarray(vector)[self.free]

    def project_matrix(self, matrix: sp.spmatrix) -> sp.csr_matrix:
        """The free rows and columns of ``matrix``, without the zeros its sparsity pattern holds (an
        assembled form's pattern couples every field of an element, most of them with zeros)."""
        projected = sp.csr_matrix(matrix)[self.free][:, self.free]
        projected.eliminate_zeros()
        return projected

    def rows(self, dofs: np.ndarray) -> sp.csr_matrix:
        return self.phi[np.asarray(dofs)]

    def zeros_matrix(self) -> sp.csr_matrix:
        return sp.csr_matrix((self.size, self.size))

    def solve(self, matrix, rhs: np.ndarray) -> np.ndarray:
        return spla.spsolve(sp.csc_matrix(matrix), rhs)

    def combine(self, terms) -> sp.coo_matrix:
        """sum of c A over the (c, A) of ``terms``, as the entries of all terms side by side (a COO matrix
        whose repeated entries add up): no sparse sums, whose bookkeeping costs more than the banded LU."""
        parts = [sp.coo_matrix(matrix) for _, matrix in terms]
        if not parts:
            return sp.coo_matrix((self.size, self.size))
        data = np.concatenate([c * part.data for (c, _), part in zip(terms, parts)])
        rows = np.concatenate([part.row for part in parts])
        columns = np.concatenate([part.col for part in parts])
        return sp.coo_matrix((data, (rows, columns)), shape=(self.size, self.size))

    def _factorise(self, tangent, constraints) -> BandedSaddle:
        return BandedSaddle(tangent, constraints, self._band_order)

    def saddle_solve(self, tangent, constraints, rhs_q: np.ndarray, rhs_c: np.ndarray):
        """Solve [[J, B^T], [B, 0]] (dq, mu) = (rhs_q, rhs_c), Eq. (76), with a banded LU and the held dofs
        eliminated (:mod:`fenics_drill.model.banded_saddle`; kept for the same J and B)."""
        return self._saddle(tangent, constraints)(rhs_q, rhs_c)


def weighted_product(rows_a, weights: np.ndarray, rows_b):
    """rows_a^T diag(weights) rows_b for dense or sparse rows of [Phi]: the projection of a
    pointwise (diagonal) Jacobian d F_a / d y_b acting at a set of dofs."""
    if sp.issparse(rows_b):
        return rows_a.T @ (sp.diags(weights) @ rows_b)
    return rows_a.T @ (weights[:, None] * rows_b)


class BasisError(ValueError):
    """A reduced basis that misses a load beyond the guard's tolerance, with enrichment off."""


def solution_space(scene, disc: BeamDiscretization, operators: LinearOperators):
    """(space, kept modes, all modes, guard report, stuck-bit modes): the modal basis of the scene's
    reduction rule (Section 6.3), with the 'auto' rule's torsional modes of a stuck bit (None otherwise),
    checked and enriched by the guard (:mod:`fenics_drill.model.enrichment`), or the full space for
    'none'; all modes of the band B (for spectra) either way."""
    modes = solve_modes(disc, scene.modal.f_star_max, operators.mass)
    if scene.reduction.rule == "none":
        return FullSpace(disc), None, modes, {}, None
    basis = modes.select(select_modes(modes, scene))
    vectors, stuck = basis.vectors, None
    if scene.reduction.rule == "auto" and scene.model.bit_rock:
        stuck = stuck_bit_modes(disc, reduction_bands(scene)["torsional"], operators.mass, operators.stiffness)
        vectors = augment(vectors, stuck.vectors, operators.mass)
    drive = [disc.end_dof(U, 0), disc.end_dof(THETA_X, 0)]
    phi, guard = enrich(vectors, scene, disc, operators, lambda phi: phi[drive])
    tolerance = scene.reduction.guard_tolerance
    for load, verdict in guard.items():
        if verdict["error"] > tolerance:
            raise BasisError(
                f"the reduced basis (reduction.rule = '{scene.reduction.rule}') misses {verdict['error']:.3g} of the "
                f"static response to {load.replace('_', ' ')} (reduction.guard_tolerance = {tolerance:g}): set "
                "reduction.enrich = true to add it, widen the band (reduction.rule = 'band'), or use the full "
                "order (reduction.rule = 'none')")
    return ModalSpace(phi), basis, modes, guard, stuck
