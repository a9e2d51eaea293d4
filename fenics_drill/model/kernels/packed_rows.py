"""Rows of a modal basis [Phi] packed on the columns of each row's field.

The modes of the straight string move one group of coupled fields each (model/reduction/modes.py): u, theta_x,
(v, theta_z), (w, theta_y).  A row of [Phi] at a dof of one field is therefore zero outside the columns of
the modes that move that field, and of the basis vectors added to them (model/reduction/enrichment.py): on the paper
scene's 62 columns u, v, w, theta_x, theta_y and theta_z have 13, 11, 14, 27, 14 and 11.  Products with
the rows (positions of a state at the dofs, loads projected back) need only those columns.

:class:`FieldPackedRows` keeps each row's entries on its field's columns, contiguous, and the compiled helpers
below run the products over them: :func:`gathered` takes a reduced vector at every field's columns once,
:func:`dot_row` and :func:`add_row` then read a row in its packed form, and :func:`scatter` adds packed
sums back onto the columns.  Each field's columns are padded with zero entries to a multiple of PADDING,
which spares the vectorised loops their remainders.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

#: Each field's column count is rounded up to a multiple of this (zero entries on column 0).
PADDING = 4


@dataclass(frozen=True)
class FieldPackedRows:
    """Rows of [Phi] (dense: rows x columns), each packed on its field's columns.

    Row r holds its entries on ``columns[field[r], :counts[field[r]]]`` in ``values[r, :counts[field[r]]]``."""

    values: np.ndarray  # (rows, width)
    field: np.ndarray  # (rows,) the group of columns of each row (int64)
    columns: np.ndarray  # (groups, width) each group's columns (int64; padding: column 0)
    counts: np.ndarray  # (groups,) each group's columns, padded (int64)
    size: int  # the dense rows' columns

    @classmethod
    def of(cls, rows: np.ndarray, fields: np.ndarray) -> "FieldPackedRows":
        """The dense ``rows`` packed by the field of each (``fields``: any integer labels); a field's columns
        are those where any of its rows is nonzero."""
        labels, field = np.unique(np.asarray(fields), return_inverse=True)
        nonzero = [np.flatnonzero(np.any(rows[field == g] != 0.0, axis=0)) for g in range(len(labels))]
        counts = np.array([-(-c.size // PADDING) * PADDING for c in nonzero], dtype=np.int64)
        width = int(counts.max(initial=0))
        columns = np.zeros((len(labels), width), dtype=np.int64)
        values = np.zeros((rows.shape[0], width))
        for g, c in enumerate(nonzero):
            columns[g, :c.size] = c
            values[field == g, :c.size] = rows[field == g][:, c]
        return cls(values, field.astype(np.int64), columns, counts, rows.shape[1])

    def at(self, indices: np.ndarray) -> "FieldPackedRows":
        """Some of the rows, in the order of ``indices``."""
        return FieldPackedRows(np.ascontiguousarray(self.values[indices]), self.field[indices], self.columns,
                               self.counts, self.size)

    def dense(self) -> np.ndarray:
        """The dense rows again (rows x size)."""
        out = np.zeros((len(self.field), self.size))
        for r, g in enumerate(self.field):
            np.add.at(out[r], self.columns[g, :self.counts[g]], self.values[r, :self.counts[g]])
        return out

    def kernel_data(self) -> tuple:
        """(values, field, columns, counts): what the compiled helpers take."""
        return self.values, self.field, self.columns, self.counts


#: :meth:`FieldPackedRows.kernel_data` of no rows (for kernels that take rows they do not use).
NO_ROWS = (np.empty((0, 0)), np.empty(0, dtype=np.int64), np.empty((0, 0), dtype=np.int64), np.empty(0, dtype=np.int64))


@njit(cache=True)
def gathered(x, columns):
    """``x`` at each group's columns: (groups, width)."""
    out = np.empty(columns.shape)
    for g in range(columns.shape[0]):
        for k in range(columns.shape[1]):
            out[g, k] = x[columns[g, k]]
    return out


@njit(cache=True, inline="always")
def dot_row(values, r, x, count):
    """values[r, :count] . x[:count] (x: a row of :func:`gathered`), without views."""
    s = 0.0
    for k in range(count):
        s += values[r, k] * x[k]
    return s


@njit(cache=True, inline="always")
def dot_row_twice(values, r, x, y, count):
    """(values[r, :count] . x[:count], values[r, :count] . y[:count]), reading the row once."""
    s = t = 0.0
    for k in range(count):
        s += values[r, k] * x[k]
        t += values[r, k] * y[k]
    return s, t


@njit(cache=True, inline="always")
def add_row(out, values, r, factor, count):
    """out[:count] += factor values[r, :count] (out: a group's packed sums), without views."""
    for k in range(count):
        out[k] += factor * values[r, k]


@njit(cache=True)
def scatter(out, columns, counts, packed):
    """out[columns[g, k]] += packed[g, k] for every group's columns."""
    for g in range(columns.shape[0]):
        for k in range(counts[g]):
            out[columns[g, k]] += packed[g, k]
