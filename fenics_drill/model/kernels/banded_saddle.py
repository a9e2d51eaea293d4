"""The saddle-point system (76) of a full-order model, solved as a banded matrix.

A beam on an interval mesh couples each dof only with those of its own elements, so once the dofs are
numbered along the string (by their x) the tangent J is a band about as wide as one element's dofs.
In the full space every row of [B] holds one dof (u(0) or theta_x(0)), so the constraints are
eliminated exactly instead of bordering the matrix (taken out of the band into dense columns and rows):

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
def _band_widths(rows, columns, position, taken_slot):
    """(kl, ku): the lower and upper bandwidths of the renumbered matrix without the taken-out rows and columns."""
    kl, ku = 0, 0
    for k in range(rows.size):
        row, col = position[rows[k]], position[columns[k]]
        if row >= 0 and col >= 0 and taken_slot[row] < 0 and taken_slot[col] < 0:
            kl, ku = max(kl, row - col), max(ku, col - row)
    return kl, ku


@kernel
def _band_fill(rows, columns, data, position, taken_slot, kl, ku, band, taken_columns, taken_rows):
    """LAPACK's band storage of the renumbered matrix (the taken-out dofs' rows and columns left out) and the
    matrix's taken-out columns and rows (dense, by band index), added in one pass over its (row, column, value)
    entries (repeated ones add up).  ``position``: each dof's band index, -1 for a dof not in this band (another
    rank's: :mod:`~fenics_drill.model.kernels.split_band`), whose entries are left out.  Returns the number of
    entries outside the bandwidths (kl, ku), which are left out."""
    outside = 0
    for k in range(rows.size):
        row, col, value = position[rows[k]], position[columns[k]], data[k]
        if row < 0 or col < 0:
            continue
        if taken_slot[col] >= 0:
            taken_columns[row, taken_slot[col]] += value
        if taken_slot[row] >= 0:
            taken_rows[taken_slot[row], col] += value
        elif taken_slot[col] < 0:
            d = row - col
            if d > kl or -d > ku:
                outside += 1
            else:
                band[kl + ku + d, col] += value
    return outside


class Triplets:
    """A sparse matrix held as its (value, row, column) entries, repeated ones adding up: a point force's tangent in the
    full space, laid into the band entry by entry as it is.  Forming it costs nothing: a SciPy COO matrix checks its
    indices when made, which cost more than the band fill of a wall's tangent (measured in the split string's
    Newton: 13 % of its profiled time went to forming and checking COO matrices)."""

    def __init__(self, data: np.ndarray, row: np.ndarray, col: np.ndarray, shape: tuple[int, int]):
        self.data, self.row, self.col, self.shape = data, row, col, shape

    def tocoo(self) -> sp.coo_matrix:
        return sp.coo_matrix((self.data, (self.row, self.col)), shape=self.shape)

    def tocsr(self) -> sp.csr_matrix:
        return self.tocoo().tocsr()

    def toarray(self) -> np.ndarray:
        return self.tocoo().toarray()

    def __matmul__(self, x):
        return self.tocoo() @ x


def as_csr(matrix) -> sp.csr_matrix | np.ndarray:
    """A tangent as a CSR matrix (a full space's: SciPy's or :class:`Triplets`), or as it is (a modal space's
    dense one)."""
    return matrix.tocsr() if hasattr(matrix, "tocsr") else matrix


class SparseSum:
    """sum of c A over the (c, A) of ``terms`` (sparse matrices, or sums themselves), kept as its terms: the banded
    solve lays each term into the band itself, and a term kept across many tangents (the internal tangent, kept
    over Newton iterations and steps) keeps its band, so that each new tangent copies it and adds the few entries
    of the point forces (a tenth of the entries of the whole) instead of laying all of them out again.

    ``own``: in a string split over MPI ranks (:mod:`~fenics_drill.model.kernels.split_band`), the entries are this
    rank's own (assembled over its elements); otherwise every rank holds all of them (the point forces)."""

    def __init__(self, terms, shape: tuple[int, int], own: bool = False):
        self.terms = [(float(c), matrix if isinstance(matrix, (SparseSum, sp.coo_matrix, Triplets))
                       else sp.coo_matrix(matrix)) for c, matrix in terms]
        self.shape, self.own = shape, own
        self._bands = {}  # layout key -> (band, taken-out columns, taken-out rows) of this sum

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

    def laid_out(self, layout: "BandLayout") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(band, taken-out columns, taken-out rows) of this sum in ``layout``, kept for the next tangent that
        holds it."""
        if layout.key not in self._bands:
            arrays = layout.empty()
            _add_terms(self.terms, layout, arrays, self.own)
            layout.set_identity(arrays[0])
            if len(self._bands) > 2:  # a sum is laid out for one or two saddle systems (a run's and its statics')
                self._bands.clear()
            self._bands[layout.key] = arrays
        return self._bands[layout.key]


def _add_terms(terms, layout: "BandLayout", arrays, own: bool) -> None:
    """Add sum c A of ``terms`` into (band, taken-out columns, taken-out rows): a sum of several terms from its
    kept layout, any other term entry by entry (``own``: the terms are this rank's own, :class:`SparseSum`)."""
    for c, matrix in terms:
        if isinstance(matrix, SparseSum) and len(matrix.terms) > 1:
            for mine, theirs in zip(arrays, matrix.laid_out(layout)):
                mine += theirs if c == 1.0 else c * theirs
        elif isinstance(matrix, SparseSum):
            _add_terms([(c * inner, leaf) for inner, leaf in matrix.terms], layout, arrays, own or matrix.own)
        else:
            layout.fill(matrix, c, own, *arrays)


class BandLayout:
    """Where the entries of a tangent go in LAPACK's band storage: each dof's band index ``position`` (-1: not in
    this band), and for the entries every rank holds ``shared_position`` (the same, or -1 where another rank adds
    them); the dofs at the band indices ``taken`` are taken out into dense columns and rows, an identity left on
    their diagonal (module doc)."""

    def __init__(self, position: np.ndarray, taken: np.ndarray, n: int, kl: int, ku: int, key,
                 shared_position: np.ndarray | None = None):
        self.n, self.kl, self.ku, self.taken = n, kl, ku, taken
        self.position = position
        self.shared_position = position if shared_position is None else shared_position
        self.taken_slot = np.full(n, -1, dtype=np.int64)
        self.taken_slot[taken] = np.arange(taken.size)
        self.key = (key, tuple(taken.tolist()), kl, ku)

    def empty(self):
        return (np.zeros((self.n, 2 * self.kl + self.ku + 1)).T,  # Fortran order, as LAPACK stores it
                np.zeros((self.n, self.taken.size)), np.zeros((self.taken.size, self.n)))

    def fill(self, matrix: sp.coo_matrix, c: float, own: bool, band, taken_columns, taken_rows) -> None:
        data = matrix.data if c == 1.0 else c * matrix.data
        outside = _band_fill(matrix.row, matrix.col, data, self.position if own else self.shared_position,
                             self.taken_slot, self.kl, self.ku, band, taken_columns, taken_rows)
        if outside:
            raise ValueError(f"{outside} entries of the tangent lie outside its bandwidth {self.kl}: a force couples "
                             "dofs of different elements")

    def set_identity(self, band) -> None:
        band[self.kl + self.ku, self.taken] = 1.0

    def laid_out(self, tangent) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(band, taken-out columns, taken-out rows) of ``tangent`` (a sparse matrix or a :class:`SparseSum`)."""
        terms = tangent.terms if isinstance(tangent, SparseSum) else [(1.0, sp.coo_matrix(tangent))]
        own = isinstance(tangent, SparseSum) and tangent.own
        first = terms[0][1] if terms else None
        if terms[:1] and terms[0][0] == 1.0 and isinstance(first, SparseSum) and len(first.terms) > 1:
            # a sum led by a kept one (the internal tangent): a copy of its layout, the fresh terms (the point
            # forces) added
            arrays, terms = tuple(a.copy(order="K") for a in first.laid_out(self)), terms[1:]
        else:
            arrays = self.empty()
        _add_terms(terms, self, arrays, own)
        self.set_identity(arrays[0])
        return arrays


def band_order_positions(order: np.ndarray) -> np.ndarray:
    """Each dof's index in the numbering ``order`` (index -> dof)."""
    position = np.empty(order.size, dtype=np.int64)
    position[order] = np.arange(order.size)
    return position


#: The frames of the saddle systems factorised lately (:func:`_frame`), by the identities of their constraints and
#: numbering, which they hold (so that those identities are not reused while kept).
_FRAMES: dict = {}


def _frame(constraints, order: np.ndarray, n: int, width: int | None):
    """(held dofs, their coefficients, each dof's band index, the band layout or None if ``width`` is None) of a saddle
    system with these constraints and numbering: found once for the many tangents a run factorises with them."""
    key = (id(constraints), id(order), n, width)
    kept = _FRAMES.get(key)
    if kept is None or kept[0] is not constraints or kept[1] is not order:
        held, coefficients = held_dofs(constraints)
        position = band_order_positions(order)
        layout = None if width is None else BandLayout(position, position[held], n, width, width, id(order))
        if len(_FRAMES) >= 8:
            _FRAMES.clear()
        kept = _FRAMES[key] = (constraints, order, held, coefficients, position, layout)
    return kept[2:]


class BandedSaddle:
    """The factorised saddle matrix [[J, B^T], [B, 0]] of (76), J sparse, its dofs renumbered by ``order``."""

    def __init__(self, tangent, constraints, order: np.ndarray, width: int | None = None):
        """``tangent``: a sparse matrix or a :class:`SparseSum`; ``width``: the bandwidth the renumbered J has by
        construction (found from its entries if None); an entry outside it is an error."""
        n = tangent.shape[0]
        self.held, self.coefficients, position, layout = _frame(constraints, order, n, width)
        self.order = order
        self.held_band = position[self.held]
        if layout is None:
            coo = tangent.tocoo() if isinstance(tangent, SparseSum) else sp.coo_matrix(tangent)
            probe = BandLayout(position, self.held_band, n, 0, 0, id(order))
            kl, ku = _band_widths(coo.row, coo.col, position, probe.taken_slot)
            layout = BandLayout(position, self.held_band, n, kl, ku, id(order))
        self.kl, self.ku = layout.kl, layout.ku
        band, self.held_columns, self.held_rows = layout.laid_out(tangent)
        self.lu, self.pivots, info = lapack.dgbtrf(band, self.kl, self.ku, overwrite_ab=1)
        if info != 0:
            raise np.linalg.LinAlgError(f"the saddle matrix (76) is singular (LAPACK dgbtrf info = {info})")

    def __call__(self, rhs_q: np.ndarray, rhs_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dq, mu) of [[J, B^T], [B, 0]] (dq, mu) = (rhs_q, rhs_c)."""
        x_held = np.asarray(rhs_c, dtype=float) / self.coefficients
        rhs = rhs_q[self.order] - self.held_columns @ x_held
        rhs[self.held_band] = x_held
        permuted, info = lapack.dgbtrs(self.lu, self.kl, self.ku, rhs, self.pivots, overwrite_b=1)
        if info != 0:
            raise np.linalg.LinAlgError(f"LAPACK dgbtrs info = {info}")
        x = np.empty_like(permuted)
        x[self.order] = permuted
        mu = (rhs_q[self.held] - self.held_rows @ permuted) / self.coefficients
        return x, mu
