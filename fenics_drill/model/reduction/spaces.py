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

import copy
import functools

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg.lapack import dgetrf as getrf
from scipy.linalg.lapack import dgetrs as getrs

from fenics_drill.model.kernels.banded_saddle import BandedSaddle, SparseSum, Triplets
from fenics_drill.model.kernels.split_band import SplitBandedSaddle, StringSplit
from fenics_drill.model.discretization import THETA_X, U, BeamDiscretization
from fenics_drill.model.reduction.enrichment import MODE_SPAN_TOLERANCE, augment, climbing_friction, enrich
from fenics_drill.model.reduction.modes import reduction_bands, select_modes, solve_modes, stuck_bit_modes
from fenics_drill.model.operators import LinearOperators


class SaddleFactorisation:
    """The factorised saddle matrix of (76) of the last (tangent, constraints) pair: a Newton iterate
    that keeps its tangent (modified Newton) solves without factorising again."""

    def __init__(self, factorise):
        self.factorise = factorise  # (tangent, constraints) -> solve(rhs_q, rhs_c) -> (dq, mu)
        self.key = self.value = None
        self.count = 0  # factorisations made

    def __call__(self, tangent, constraints):
        if self.key is None or self.key[0] is not tangent or self.key[1] is not constraints:
            self.key, self.value = (tangent, constraints), self.factorise(tangent, constraints)
            self.count += 1
        return self.value


class ModalPointRows:
    """The values of a few dofs in a modal space: the rows P = [Phi]_dofs (k x N_red), dense."""

    def __init__(self, rows: np.ndarray):
        self.matrix = np.ascontiguousarray(rows)

    def values(self, x: np.ndarray) -> np.ndarray:
        """P x: the dofs' values of a reduced vector."""
        return self.matrix @ x

    def spread(self, point_values: np.ndarray) -> np.ndarray:
        """P^T f: the generalised force of point forces f on the dofs."""
        return self.matrix.T @ point_values

    def unit_loads(self) -> tuple[np.ndarray, ...]:
        """P^T e_k of each dof k: the generalised force of a unit load on it (a point law's load is a
        multiple of it, cheaper than a product)."""
        return tuple(self.matrix.copy())

    def block(self, jacobian: np.ndarray) -> np.ndarray:
        """P^T A P: the tangent of a point law with Jacobian A (k x k) on the dofs."""
        return self.matrix.T @ jacobian @ self.matrix

    def subset(self, indices) -> "ModalPointRows":
        return ModalPointRows(self.matrix[indices])

    def dense(self) -> np.ndarray:
        return self.matrix


class SelectedPointRows:
    """The values of a few dofs in the full space: each row selects one free dof (or none, for a dof held
    by a support), so P q, P^T f and P^T A P are gathers and scatters, not sparse products."""

    def __init__(self, positions: np.ndarray, size: int):
        self.positions, self.size = np.asarray(positions, dtype=np.int64), size  # -1: a supported dof
        self.free = self.positions >= 0

    def values(self, x: np.ndarray) -> np.ndarray:
        out = np.zeros(self.positions.size)
        out[self._kept] = np.asarray(x)[self._kept_positions]
        return out

    def spread(self, point_values: np.ndarray) -> np.ndarray:
        return np.bincount(self._kept_positions, np.asarray(point_values, dtype=float)[self._kept],
                           minlength=self.size)

    def unit_loads(self) -> tuple[np.ndarray, ...]:
        return tuple(self.spread(unit) for unit in np.eye(self.positions.size))

    def block(self, jacobian: np.ndarray) -> Triplets:
        kept = self._kept
        rows, columns = self._block_entries
        return Triplets(np.asarray(jacobian, dtype=float)[np.ix_(kept, kept)].ravel(), rows, columns,
                        (self.size, self.size))

    @functools.cached_property
    def _kept(self) -> np.ndarray:
        return np.flatnonzero(self.free)

    @functools.cached_property
    def _kept_positions(self) -> np.ndarray:
        return self.positions[self._kept]

    @functools.cached_property
    def _block_entries(self) -> tuple[np.ndarray, np.ndarray]:
        """(row, column) of each entry of a block, row by row."""
        rows, columns = np.meshgrid(self.positions[self._kept], self.positions[self._kept], indexing="ij")
        return rows.ravel(), columns.ravel()

    def subset(self, indices) -> "SelectedPointRows":
        return SelectedPointRows(self.positions[indices], self.size)

    def dense(self) -> np.ndarray:
        out = np.zeros((self.positions.size, self.size))
        out[np.flatnonzero(self.free), self.positions[self.free]] = 1.0
        return out


def constraint_scale(tangent, constraints) -> float:
    """Factor k for the rows of [B] in the saddle system (76): with k [B] the constraint rows
    have the size of the tangent's, otherwise the system is singular to working precision."""
    diagonal = np.abs(tangent.diagonal()).max()
    largest = np.abs(np.asarray(constraints)).max(initial=0.0)  # no rows: a hook load with a top drive
    return diagonal / largest if diagonal > 0 and largest > 0 else 1.0


def stack_rows(rows) -> np.ndarray | sp.csr_matrix:
    """Rows of [Phi] (of either space) stacked into one map, so that one product gives them all: CSR for the
    full space, contiguous dense for a modal one."""
    if any(map(sp.issparse, rows)):
        return sp.vstack(rows, format="csr")
    return np.ascontiguousarray(np.vstack(rows))


def column_bound(rows) -> np.ndarray:
    """The largest |entry| of each column of ``rows``: max_i |(rows x)_i| <= sum_j of it |x_j| for any x."""
    bound = abs(rows).max(axis=0)
    return bound.toarray().ravel() if sp.issparse(bound) else np.asarray(bound).ravel()


class SaddleLU:
    """[[J, k B^T], [k B, 0]] of (76) factorised by LAPACK's getrf, solved by getrs, both called directly: SciPy's
    lu_factor/lu_solve check and look up LAPACK at every call, which costs ten times the solve of a small system
    (a Newton iterate makes several).  k = :func:`constraint_scale`; ``factors`` (Fortran order), ``pivots``
    (0-based, as SciPy gives them) and ``scale`` are what a compiled solve reads (solvers/compiled_step.py)."""

    def __init__(self, tangent: np.ndarray, constraints: np.ndarray):
        n, m = tangent.shape[0], constraints.shape[0]
        k = constraint_scale(tangent, constraints)
        system = np.empty((n + m, n + m), order="F")  # LAPACK's order: factorised in place, no copy
        system[:n, :n], system[:n, n:] = tangent, k * constraints.T
        system[n:, :n], system[n:, n:] = k * constraints, 0.0
        factors, pivots, info = getrf(system, overwrite_a=True)
        if info < 0:
            raise ValueError(f"getrf: argument {-info} is invalid")
        # info > 0: an exactly singular system; the solve gives non-finite values, which Newton reports
        self.factors, self.pivots, self.scale, self.size = factors, pivots, k, n
        self._rhs = np.empty(n + m)

    def __call__(self, rhs_q: np.ndarray, rhs_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n, rhs = self.size, self._rhs
        rhs[:n], rhs[n:] = rhs_q, self.scale * rhs_c
        x, _ = getrs(self.factors, self.pivots, rhs)
        return x[:n], self.scale * x[n:]


class ModalSpace:
    """Dense modal basis [Phi] (N_dofs x N_red)."""

    sparse = False

    def __init__(self, phi: np.ndarray):
        self.phi = np.ascontiguousarray(phi)
        self._saddle = SaddleFactorisation(SaddleLU)

    @property
    def size(self) -> int:
        return self.phi.shape[1]

    @property
    def factorisations(self) -> int:
        """The saddle matrices (76) factorised in this space so far."""
        return self._saddle.count

    def expand(self, q: np.ndarray) -> np.ndarray:
        return self.phi @ q

    def expand_rows(self, states: np.ndarray) -> np.ndarray:
        """The full-space dofs of many states (one per row): one product with [Phi] for all of them."""
        return states @ self.phi.T

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

    def point_rows(self, dofs) -> ModalPointRows:
        """P of a few dofs (the bit's, the top's): q -> their values, with its products."""
        return ModalPointRows(self.phi[np.asarray(dofs)])

    def zeros_matrix(self) -> np.ndarray:
        return np.zeros((self.size, self.size))

    def solve(self, matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        return sla.solve(matrix, rhs, check_finite=False)

    def combine(self, terms) -> np.ndarray:
        """sum of c A over the (c, A) of ``terms``: a tangent from its parts (a new matrix; the terms of
        c = +-1 are added in place, without a scaled copy)."""
        out = None
        for c, matrix in terms:
            if out is None:
                out = matrix.copy() if c == 1.0 else c * matrix
            elif c == 1.0:
                out += matrix
            elif c == -1.0:
                out -= matrix
            else:
                out += c * matrix
        return np.zeros((self.size, self.size)) if out is None else out

    def factorised(self, tangent: np.ndarray, constraints: np.ndarray) -> "SaddleLU":
        """The LU of the saddle matrix of (76) for (tangent, constraints), kept as :meth:`saddle_solve` keeps it."""
        return self._saddle(tangent, constraints)

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
        self.position = np.full(ndofs, -1, dtype=np.int64)  # of each dof among the free ones (-1: held)
        self.position[self.free] = np.arange(self.free.size)
        self._saddle = SaddleFactorisation(self._factorise)
        # the free dofs numbered along the string: an element couples only neighbours in this order
        self.band_order = np.argsort(disc.dof_coordinates[self.free], kind="stable")
        # the tangent's bandwidth in that order: the farthest two free dofs of one element (a point force
        # couples the dofs of one vertex, which share an element)
        band_position = np.full(ndofs, -1, dtype=np.int64)
        band_position[self.free[self.band_order]] = np.arange(self.free.size)
        cells = band_position[disc.V.dofmap.list]
        spread = np.where(cells >= 0, cells, -1).max(axis=1) - np.where(cells >= 0, cells, ndofs).min(axis=1)
        self.band_width = int(spread.max())
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

    def expand_rows(self, states: np.ndarray) -> np.ndarray:
        """The full-space dofs of many states (one per row)."""
        out = np.zeros((len(states), self.ndofs))
        out[:, self.free] = states
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

    def point_rows(self, dofs) -> SelectedPointRows:
        """P of a few dofs (the bit's, the top's): q -> their values, with its products."""
        return SelectedPointRows(self.position[np.asarray(dofs)], self.size)

    def zeros_matrix(self) -> sp.csr_matrix:
        return sp.csr_matrix((self.size, self.size))

    def solve(self, matrix, rhs: np.ndarray) -> np.ndarray:
        return spla.spsolve(sp.csc_matrix(matrix), rhs)

    def combine(self, terms) -> SparseSum:
        """sum of c A over the (c, A) of ``terms``, kept as its terms (:class:`~fenics_drill.model.kernels.
        banded_saddle.SparseSum`): no sparse sums, whose bookkeeping costs more than the banded LU, and a kept
        term's band is laid out once."""
        return SparseSum(terms, (self.size, self.size))

    @property
    def factorisations(self) -> int:
        """The saddle matrices (76) factorised in this space so far (this rank's part of them, split)."""
        return self._saddle.count

    def _factorise(self, tangent, constraints) -> BandedSaddle:
        return BandedSaddle(tangent, constraints, self.band_order, self.band_width)

    def split(self, string_split: StringSplit) -> "FullSpace":
        """This space with its saddle system solved across the two ranks of ``string_split``
        (:mod:`~fenics_drill.model.kernels.split_band`)."""
        space = copy.copy(self)
        space._saddle = SaddleFactorisation(
            lambda tangent, constraints: SplitBandedSaddle(tangent, constraints, string_split, self.band_width))
        return space

    def saddle_solve(self, tangent, constraints, rhs_q: np.ndarray, rhs_c: np.ndarray):
        """Solve [[J, B^T], [B, 0]] (dq, mu) = (rhs_q, rhs_c), Eq. (76), with a banded LU and the held dofs
        eliminated (:mod:`fenics_drill.model.kernels.banded_saddle`; kept for the same J and B)."""
        return self._saddle(tangent, constraints)(rhs_q, rhs_c)


class BasisError(ValueError):
    """A reduced basis that misses a load beyond the guard's tolerance, with enrichment off."""


def solution_space(scene, disc: BeamDiscretization, operators: LinearOperators, modal_stiffness=None):
    """(space, kept modes, all modes, guard report, stuck-bit modes): the modal basis of the scene's
    reduction rule (Section 6.3), with the 'auto' rule's torsional modes of a stuck bit (None otherwise),
    checked and enriched by the guard (:mod:`fenics_drill.model.reduction.enrichment`), or the full space for
    'none'; all modes of the band B (for spectra) either way, without their vectors for the full space.
    ``modal_stiffness(disc, operators)``, if given, is the K of (62) the basis's modes are solved with (a string
    prestressed by its static state in a well); it is called only for a modal basis."""
    if scene.reduction.rule == "none":
        return FullSpace(disc), None, solve_modes(disc, scene.modal.f_star_max, operators.mass, vectors=False), {}, \
            None
    if (why := climbing_friction(scene, disc, operators)) is not None:
        if scene.reduction.rule == "auto":
            return (FullSpace(disc), None, solve_modes(disc, scene.modal.f_star_max, operators.mass, vectors=False),
                    {"full_order": {"chosen": True, "why": why}}, None)
        raise BasisError(f"reduction.rule = '{scene.reduction.rule}' is not admissible here: {why}; use "
                         "reduction.rule = 'auto' or 'none' (the full order), or contact.friction_model = 'paper'")
    stiffness = None if modal_stiffness is None else modal_stiffness(disc, operators)
    modes = solve_modes(disc, scene.modal.f_star_max, operators.mass, stiffness=stiffness)
    basis = modes.select(select_modes(modes, scene))
    vectors, stuck = basis.vectors, None
    if scene.reduction.rule == "auto" and scene.model.bit_rock:
        stuck = stuck_bit_modes(disc, reduction_bands(scene)["torsional"], operators.mass, operators.stiffness)
        vectors = augment(vectors, stuck.vectors, operators.mass, MODE_SPAN_TOLERANCE)
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
