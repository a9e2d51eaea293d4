"""The saddle-point system (76) of a full-order model, solved as a banded matrix.

A beam on an interval mesh couples each dof only with those of its own elements, so once the dofs are
numbered along the string (by their x) the tangent J is a band about as wide as one element's dofs.
In the full space every row of [B] holds one dof (u(0) or theta_x(0)), so the constraints are
eliminated exactly instead of bordering the matrix:

    x_c = g / b,   A x = r - J[:, c] x_c  with row and column c of J replaced by the identity,
    mu = (r_c - (J x)_c) / b

and A is factorised by LAPACK's banded LU (dgbtrf): O(n w^2) for a band of width w, against a general
sparse LU's fill and bookkeeping (docs/performance.md).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg.lapack as lapack
import scipy.sparse as sp

from fenics_drill.model.kernels.compiled import kernel


def held_dofs(constraints) -> tuple[np.ndarray, np.ndarray]:
    """(dof c_i, coefficient b_i) of each row b_i e_{c_i}^T of [B]; a row holding more than one dof is an
    error (a full space's constraint rows are rows of its selection matrix)."""
    rows = np.asarray(constraints.toarray() if sp.issparse(constraints) else constraints, dtype=float)
    dofs = np.empty(rows.shape[0], dtype=np.int64)
    for i, row in enumerate(rows):
        held = np.flatnonzero(row)
        if held.size != 1:
            raise ValueError(f"constraint row {i} holds {held.size} dofs; the banded saddle solve needs one")
        dofs[i] = held[0]
    return dofs, rows[np.arange(rows.shape[0]), dofs]


@kernel
def _band_widths(rows, columns, position, held_slot):
    """(kl, ku): the lower and upper bandwidths of the renumbered matrix without the held rows and columns."""
    kl, ku = 0, 0
    for k in range(rows.size):
        if held_slot[rows[k]] < 0 and held_slot[columns[k]] < 0:
            d = position[rows[k]] - position[columns[k]]
            kl, ku = max(kl, d), max(ku, -d)
    return kl, ku


@kernel
def _band_fill(rows, columns, data, position, held_slot, kl, ku, band, held_columns, held_rows):
    """LAPACK's band storage of the renumbered matrix (the held dofs' rows and columns left out) and the matrix's
    held columns and rows (dense), added in one pass over its (row, column, value) entries (repeated ones add up).
    Returns the number of entries outside the bandwidths (kl, ku), which are left out."""
    outside = 0
    for k in range(rows.size):
        row, col, value = rows[k], columns[k], data[k]
        if held_slot[col] >= 0:
            held_columns[row, held_slot[col]] += value
        if held_slot[row] >= 0:
            held_rows[held_slot[row], col] += value
        elif held_slot[col] < 0:
            d = position[row] - position[col]
            if d > kl or -d > ku:
                outside += 1
            else:
                band[kl + ku + d, position[col]] += value
    return outside


class SparseSum:
    """sum of c A over the (c, A) of ``terms`` (sparse matrices, or sums themselves), kept as its terms: the banded
    solve lays each term into the band itself, and a term kept across many tangents (the internal tangent, kept
    over Newton iterations and steps) keeps its band, so that each new tangent copies it and adds the few entries
    of the point forces (a tenth of the entries of the whole) instead of laying all of them out again."""

    def __init__(self, terms, shape: tuple[int, int]):
        self.terms = [(float(c), matrix if isinstance(matrix, (SparseSum, sp.coo_matrix)) else sp.coo_matrix(matrix))
                      for c, matrix in terms]
        self.shape = shape
        self._bands = {}  # (order, held dofs, widths) -> (band, held columns, held rows) of this sum

    def tocoo(self) -> sp.coo_matrix:
        """The sum as one COO matrix (repeated entries add up)."""
        parts = [(c, m.tocoo()) for c, m in self.terms]
        if not parts:
            return sp.coo_matrix(self.shape)
        return sp.coo_matrix((np.concatenate([c * m.data for c, m in parts]),
                              (np.concatenate([m.row for _, m in parts]), np.concatenate([m.col for _, m in parts]))),
                             shape=self.shape)

    def tocsr(self) -> sp.csr_matrix:
        return self.tocoo().tocsr()

    def toarray(self) -> np.ndarray:
        return self.tocoo().toarray()

    def __matmul__(self, x):
        out = None
        for c, matrix in self.terms:
            term = c * (matrix @ x)
            out = term if out is None else out + term
        return np.zeros(self.shape[0]) if out is None else out

    def laid_out(self, layout: "_BandLayout") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(band, held columns, held rows) of this sum in ``layout``, kept for the next tangent that holds it."""
        if layout.key not in self._bands:
            arrays = layout.empty()
            _add_terms(self.terms, layout, arrays)
            layout.set_identity(arrays[0])
            if len(self._bands) > 2:  # a sum is laid out for one or two saddle systems (a run's and its statics')
                self._bands.clear()
            self._bands[layout.key] = arrays
        return self._bands[layout.key]


def _add_terms(terms, layout: "_BandLayout", arrays) -> None:
    """Add sum c A of ``terms`` into (band, held columns, held rows): a sum of several terms from its kept layout,
    any other term entry by entry."""
    for c, matrix in terms:
        if isinstance(matrix, SparseSum) and len(matrix.terms) > 1:
            for mine, theirs in zip(arrays, matrix.laid_out(layout)):
                mine += theirs if c == 1.0 else c * theirs
        elif isinstance(matrix, SparseSum):
            _add_terms([(c * inner, leaf) for inner, leaf in matrix.terms], layout, arrays)
        else:
            layout.fill(matrix, c, *arrays)


class _BandLayout:
    """Where the entries of a tangent go in LAPACK's band storage: its dofs renumbered by ``order``, the held
    ones taken out into dense columns and rows (module doc)."""

    def __init__(self, n: int, order: np.ndarray, held: np.ndarray, kl: int, ku: int):
        self.n, self.kl, self.ku = n, kl, ku
        self.held_slot = np.full(n, -1, dtype=np.int64)
        self.held_slot[held] = np.arange(held.size)
        self.position = np.empty(n, dtype=np.int64)
        self.position[order] = np.arange(n)
        self.key = (id(order), tuple(held.tolist()), kl, ku)

    def empty(self):
        return (np.zeros((self.n, 2 * self.kl + self.ku + 1)).T,  # Fortran order, as LAPACK stores it
                np.zeros((self.n, self.held_slot.max() + 1)), np.zeros((self.held_slot.max() + 1, self.n)))

    def fill(self, matrix: sp.coo_matrix, c: float, band, held_columns, held_rows) -> None:
        data = matrix.data if c == 1.0 else c * matrix.data
        outside = _band_fill(matrix.row, matrix.col, data, self.position, self.held_slot, self.kl, self.ku, band,
                             held_columns, held_rows)
        if outside:
            raise ValueError(f"{outside} entries of the tangent lie outside its bandwidth {self.kl}: a force couples "
                             "dofs of different elements")

    def set_identity(self, band) -> None:
        held = np.flatnonzero(self.held_slot >= 0)
        band[self.kl + self.ku, self.position[held]] = 1.0


class BandedSaddle:
    """The factorised saddle matrix [[J, B^T], [B, 0]] of (76), J sparse, its dofs renumbered by ``order``."""

    def __init__(self, tangent, constraints, order: np.ndarray, width: int | None = None):
        """``tangent``: a sparse matrix or a :class:`SparseSum`; ``width``: the bandwidth the renumbered J has by
        construction (found from its entries if None); an entry outside it is an error."""
        n = tangent.shape[0]
        self.held, self.coefficients = held_dofs(constraints)
        self.order = order
        if width is None:
            coo = tangent.tocoo() if isinstance(tangent, SparseSum) else sp.coo_matrix(tangent)
            probe = _BandLayout(n, order, self.held, 0, 0)
            self.kl, self.ku = _band_widths(coo.row, coo.col, probe.position, probe.held_slot)
        else:
            self.kl = self.ku = width
        layout = _BandLayout(n, order, self.held, self.kl, self.ku)
        terms = tangent.terms if isinstance(tangent, SparseSum) else [(1.0, sp.coo_matrix(tangent))]
        first = terms[0][1] if terms else None
        if terms[:1] and terms[0][0] == 1.0 and isinstance(first, SparseSum) and len(first.terms) > 1:
            # a sum led by a kept one (the internal tangent): a copy of its layout, the fresh terms (the point
            # forces) added
            arrays, terms = tuple(a.copy(order="K") for a in first.laid_out(layout)), terms[1:]
        else:
            arrays = layout.empty()
        _add_terms(terms, layout, arrays)
        band, self.held_columns, self.held_rows = arrays
        layout.set_identity(band)
        self.lu, self.pivots, info = lapack.dgbtrf(band, self.kl, self.ku, overwrite_ab=1)
        if info != 0:
            raise np.linalg.LinAlgError(f"the saddle matrix (76) is singular (LAPACK dgbtrf info = {info})")

    def __call__(self, rhs_q: np.ndarray, rhs_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dq, mu) of [[J, B^T], [B, 0]] (dq, mu) = (rhs_q, rhs_c)."""
        x_held = np.asarray(rhs_c, dtype=float) / self.coefficients
        rhs = rhs_q - self.held_columns @ x_held
        rhs[self.held] = x_held
        permuted, info = lapack.dgbtrs(self.lu, self.kl, self.ku, rhs[self.order], self.pivots, overwrite_b=1)
        if info != 0:
            raise np.linalg.LinAlgError(f"LAPACK dgbtrs info = {info}")
        x = np.empty_like(permuted)
        x[self.order] = permuted
        mu = (rhs_q[self.held] - self.held_rows @ x) / self.coefficients
        return x, mu
