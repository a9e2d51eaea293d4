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
    """LAPACK's band storage of the renumbered matrix, identity at the held dofs, and the matrix's held
    columns and rows (dense), in one pass over its (row, column, value) entries (repeated ones add up).
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
    for dof in range(held_slot.size):
        if held_slot[dof] >= 0:
            band[kl + ku, position[dof]] = 1.0
    return outside


class BandedSaddle:
    """The factorised saddle matrix [[J, B^T], [B, 0]] of (76), J sparse, its dofs renumbered by ``order``."""

    def __init__(self, tangent: sp.spmatrix, constraints, order: np.ndarray, width: int | None = None):
        """``width``: the bandwidth the renumbered J has by construction (found from its entries if None);
        an entry outside it is an error."""
        tangent = tangent if isinstance(tangent, sp.coo_matrix) else sp.coo_matrix(tangent)
        n = tangent.shape[0]
        self.held, self.coefficients = held_dofs(constraints)
        held_slot = np.full(n, -1, dtype=np.int64)
        held_slot[self.held] = np.arange(self.held.size)
        position = np.empty(n, dtype=np.int64)
        position[order] = np.arange(n)
        self.order = order
        self.kl, self.ku = _band_widths(tangent.row, tangent.col, position, held_slot) if width is None \
            else (width, width)
        band = np.zeros((n, 2 * self.kl + self.ku + 1)).T  # Fortran order, as LAPACK stores it
        self.held_columns, self.held_rows = np.zeros((n, self.held.size)), np.zeros((self.held.size, n))
        outside = _band_fill(tangent.row, tangent.col, tangent.data, position, held_slot, self.kl, self.ku, band,
                             self.held_columns, self.held_rows)
        if outside:
            raise ValueError(f"{outside} entries of the tangent lie outside its bandwidth {self.kl}: a force couples "
                             "dofs of different elements")
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
