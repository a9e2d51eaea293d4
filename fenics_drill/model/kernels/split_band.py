"""The saddle system (76) of a full-order string split between two MPI ranks at one vertex (a Schur complement).

Rank 0 holds the elements before the cut vertex, rank 1 those after it.  The dofs of the cut vertex (the
separator S) are the only ones both ranks' elements hold.  Each rank lays out its own elements' tangent and
the point forces at its own vertices (those at the cut on rank 0; the wall's law runs there only) with its dofs
numbered towards the cut (rank 1 from the far end), S last and taken out of the band like the drive's held dofs
(:mod:`~fenics_drill.model.kernels.banded_saddle`), and factorises its band A_r with LAPACK's dgbtrf.  With
B_r and C_r its columns and rows at S and D_r its own part of the S block,

    (sum_r D_r - C_r A_r^-1 B_r) x_S = r_S - sum_r C_r A_r^-1 r_r,        x_r = A_r^-1 (r_r - B_r x_S).

B_r is non-zero only in the last band's width of rows and C_r in the last columns, so only those rows of
A_r^-1 B_r are formed: a forward sweep from a band's width before them and a backward sweep that stops there,
O(w^3) for a band w wide.  A solve is one forward and one backward sweep of each rank's half and two collectives
of |S| numbers; the ranks' halves of the solution are gathered, so every rank holds the whole of it.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.linalg.lapack as lapack

from fenics_drill.model.kernels.banded_saddle import BandLayout, band_order_positions, held_dofs
from fenics_drill.model.kernels.compiled import kernel
from numba import njit


@njit(cache=True)
def _sweep_forward(lu, kl, ku, pivots, b, start):
    """b <- L^-1 P b with dgbtrf's factors ``lu`` (band storage, 0-based ``pivots``), b holding the rows from
    ``start`` on of a vector that is zero above ``start`` + kl (where the earlier columns change nothing)."""
    n, kd = lu.shape[1], kl + ku
    for j in range(start, n - 1):
        k, p = j - start, pivots[j] - start
        if p != k:
            b[k], b[p] = b[p], b[k]
        value = b[k]
        if value != 0.0:
            for i in range(1, min(kl, n - j - 1) + 1):
                b[k + i] -= lu[kd + i, j] * value


@njit(cache=True)
def _sweep_backward(lu, kl, ku, b, start, stop):
    """b <- U^-1 b in its rows from ``stop`` on, which depend on those rows of b only (b holding the rows from
    ``start`` <= ``stop`` on; the rows above ``stop`` are left changed but not solved)."""
    n, kd = lu.shape[1], kl + ku
    for j in range(n - 1, stop - 1, -1):
        b[j - start] /= lu[kd, j]
        value = b[j - start]
        for i in range(max(stop, j - kd), j):
            b[i - start] -= lu[kd + i - j, j] * value


@kernel
def _schur_part(lu, kl, ku, pivots, tail, couple_columns, couple_rows):
    """C_r A_r^-1 B_r from B_r's rows ``couple_columns`` and C_r's columns ``couple_rows`` from ``tail`` on (both
    zero elsewhere): each column forward from a band's width above ``tail``, backward down to it."""
    n, m, size = lu.shape[1], couple_columns.shape[0], couple_columns.shape[1]
    start = max(tail - kl, 0)
    out, work = np.empty((size, size)), np.empty(n - start)
    for k in range(size):
        work[:] = 0.0
        work[tail - start: tail - start + m] = couple_columns[:, k]
        _sweep_forward(lu, kl, ku, pivots, work, start)
        _sweep_backward(lu, kl, ku, work, start, tail)
        out[:, k] = np.dot(couple_rows, work[tail - start: tail - start + m])
    return out


@kernel
def _condensed(lu, kl, ku, pivots, rhs, tail, couple_rows):
    """rhs <- L^-1 P rhs (in place); returns C_r (A_r^-1 rhs) from its rows ``tail`` on."""
    _sweep_forward(lu, kl, ku, pivots, rhs, 0)
    part = rhs[tail:].copy()
    _sweep_backward(lu, kl, ku, part, tail, tail)
    return np.dot(couple_rows, part[: couple_rows.shape[1]])


@kernel
def _expanded(lu, kl, ku, pivots, rhs, tail, couple_columns, x_separator):
    """rhs <- A_r^-1 (r - B_r x_S) from rhs = L^-1 P r (:func:`_condensed`)."""
    n, m = lu.shape[1], couple_columns.shape[0]
    start = max(tail - kl, 0)
    work = np.zeros(n - start)
    work[tail - start: tail - start + m] = np.dot(couple_columns, x_separator)
    _sweep_forward(lu, kl, ku, pivots, work, start)
    rhs[start:] -= work
    _sweep_backward(lu, kl, ku, rhs, 0, 0)


class StringSplit:
    """The elements of a full-order string shared between the two ranks of ``comm`` at the vertex that halves them,
    and each rank's numbering of the dofs of its elements (module doc)."""

    def __init__(self, disc, space, comm):
        """``space``: the string's :class:`~fenics_drill.model.reduction.spaces.FullSpace`."""
        if comm.size != 2:
            raise ValueError(f"a run splits its string over 1 or 2 MPI ranks, not {comm.size}")
        self.comm, self.rank, n = comm, comm.rank, space.size
        band = np.full(disc.ndofs, -1, dtype=np.int64)  # each dof's index along the string (-1: held by a support)
        band[space.free] = band_order_positions(space.band_order)
        cells = band[disc.V.dofmap.list]
        first = np.where(cells >= 0, cells, n).min(axis=1)
        along = np.argsort(first, kind="stable")  # the elements from the top drive on
        halves = along[: along.size // 2], along[along.size // 2:]
        dofs = [np.unique(cells[h][cells[h] >= 0]) for h in halves]
        separator = np.intersect1d(*dofs)
        if (separator.size == 0 or np.any(np.diff(separator) != 1) or dofs[0].max() != separator[-1]
                or dofs[1].min() != separator[0]):
            raise ValueError("the string's dofs do not part at one vertex: it cannot be split over two ranks")
        self.cells = np.sort(halves[self.rank]).astype(np.int32)  # this rank's elements
        self.separator = separator  # along the string
        self.size = n
        # this rank's numbering: towards the cut, the separator last
        self.local = band if self.rank == 0 else np.where(band >= 0, n - 1 - band, -1)
        self.local = np.where((band >= 0) & ((band <= separator[-1]) if self.rank == 0 else (band >= separator[0])),
                              self.local, -1)[space.free]
        self.n = separator[-1] + 1 if self.rank == 0 else n - separator[0]
        self.separator_local = separator if self.rank == 0 else n - 1 - separator
        # the point forces every rank evaluates whole (the bit's, the drive's) are laid out by the rank that owns
        # their vertex, the cut's by rank 0; the wall's law runs at each rank's own vertices (owned_vertices)
        self.shared_local = self.local.copy()
        if self.rank == 1:
            self.shared_local[np.isin(self.local, self.separator_local)] = -1
        self.free_along = space.band_order  # the free dof at each index along the string
        # the point forces at vertices (the wall's) are evaluated by the rank that owns the vertex: the cut's by rank 0
        cut = float(disc.dof_coordinates[space.free[space.band_order[separator]]].mean())
        half_element = 0.5 * float(np.min(np.diff(np.sort(disc.vertex_x))))
        self.owned_vertices = (disc.vertex_x <= cut + half_element) if self.rank == 0 else \
            (disc.vertex_x > cut + half_element)
        self.free_of_local = np.empty(self.n, dtype=np.int64)
        mine = np.flatnonzero(self.local >= 0)
        self.free_of_local[self.local[mine]] = mine

    def check_drive(self, constraints, width: int) -> None:
        """The drive's held dofs (the rows of [B]) must lie in the first rank's half, farther than a band's width
        from the cut (ValueError otherwise: a string of a few elements)."""
        along = np.full(self.size, -1, dtype=np.int64)
        along[self.free_along] = np.arange(self.size)
        held = along[held_dofs(constraints)[0]]
        if held.max() >= self.separator[0] - width:
            raise ValueError("the drive's dofs lie within a band's width of the cut between the ranks: the string is "
                             "too short to split")


class SplitBandedSaddle:
    """The saddle matrix [[J, B^T], [B, 0]] of (76) factorised across the two ranks of a :class:`StringSplit`:
    this rank's band and the Schur complement on the separator (module doc).  Every rank calls it alike."""

    def __init__(self, tangent, constraints, split: StringSplit, width: int):
        self.split, comm = split, split.comm
        held, self.coefficients = held_dofs(constraints)
        local_held = split.local[held]  # in the first rank's half (StringSplit.check_drive)
        self.held, self.held_local = held, local_held[local_held >= 0]
        self.kl = self.ku = width
        taken = np.concatenate([self.held_local, split.separator_local]).astype(np.int64)
        layout = BandLayout(split.local, taken, split.n, width, width, ("split", split.rank, id(split)),
                            shared_position=split.shared_local)
        band, columns, rows = layout.laid_out(tangent)
        h, n, size = self.held_local.size, split.n, split.separator.size
        self.held_columns, self.held_rows = columns[:, :h], rows[:h]
        # B_r and C_r: the separator's columns and rows at this rank's dofs, which lie within the band's width of
        # it (the held dofs lie farther: checked above)
        self.tail = max(n - size - width, 0)
        self.couple_columns = np.ascontiguousarray(columns[self.tail:n - size, h:])
        self.couple_rows = np.ascontiguousarray(rows[h:, self.tail:n - size])
        own_block = rows[h:][:, split.separator_local]  # D_r
        self.lu, self.pivots, info = lapack.dgbtrf(band, width, width, overwrite_ab=1)
        if info != 0:
            raise np.linalg.LinAlgError(f"the saddle matrix (76) is singular (LAPACK dgbtrf info = {info})")
        solved = _schur_part(self.lu, width, width, self.pivots, self.tail, self.couple_columns, self.couple_rows)
        schur = np.empty((size, size))  # C order, as the contiguous sum is sent
        comm.Allreduce(np.ascontiguousarray(own_block - solved), schur)
        self.schur = sla.lu_factor(schur, check_finite=False)

    def __call__(self, rhs_q: np.ndarray, rhs_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dq, mu) of [[J, B^T], [B, 0]] (dq, mu) = (rhs_q, rhs_c), the same on every rank."""
        split, width = self.split, self.kl
        sep = split.separator_local
        rhs = rhs_q[split.free_of_local]
        if split.rank == 0:
            x_held = np.asarray(rhs_c, dtype=float) / self.coefficients
            rhs -= self.held_columns @ x_held
            rhs[self.held_local] = x_held
        own_rhs = rhs[sep].copy() if split.rank == 0 else np.zeros(sep.size)  # r_S, counted once
        rhs[sep] = 0.0
        condensed = np.empty(sep.size)
        split.comm.Allreduce(own_rhs - _condensed(self.lu, width, width, self.pivots, rhs, self.tail,
                                                  self.couple_rows), condensed)
        x_sep = sla.lu_solve(self.schur, condensed, check_finite=False)
        _expanded(self.lu, width, width, self.pivots, rhs, self.tail, self.couple_columns, x_sep)
        rhs[sep] = x_sep
        mine = rhs[: split.n - sep.size]  # this rank's dofs but the separator, in its numbering
        if split.rank == 0:
            mu = (rhs_q[self.held] - self.held_rows @ rhs) / self.coefficients
            mine = np.concatenate([mine, mu])
        held = self.coefficients.size
        sizes = np.array([split.separator[0] + held, split.size - 1 - split.separator[-1]])
        gathered = np.empty(sizes.sum())
        split.comm.Allgatherv(np.ascontiguousarray(mine), [gathered, sizes])
        mu = gathered[sizes[0] - held: sizes[0]]
        along = np.concatenate([gathered[: sizes[0] - held], x_sep, gathered[sizes[0]:][::-1]])  # along the string
        x = np.empty(split.size)
        x[split.free_along] = along
        return x, mu
