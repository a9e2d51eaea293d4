"""Rows of [Phi] packed by field (model/kernels/packed_rows.py) against the dense products they replace."""

import numpy as np
from numba import njit

from fenics_drill.model.kernels.packed_rows import FieldPackedRows, add_row, dot_row, dot_row_twice, gathered, scatter


@njit
def _products(packed, x, y, loads):
    """Each row's dots with x and y, and sum_r loads[r] row_r, through the packed helpers."""
    values, field, columns, counts = packed
    x_at, y_at = gathered(x, columns), gathered(y, columns)
    dots, twice = np.empty(values.shape[0]), np.empty((values.shape[0], 2))
    sums = np.zeros(columns.shape)
    for r in range(values.shape[0]):
        g = field[r]
        dots[r] = dot_row(values, r, x_at[g], counts[g])
        twice[r, 0], twice[r, 1] = dot_row_twice(values, r, x_at[g], y_at[g], counts[g])
        add_row(sums[g], values, r, loads[r], counts[g])
    out = np.zeros(x.size)
    scatter(out, columns, counts, sums)
    return dots, twice, out


def test_packed_rows_give_the_dense_products_on_a_basis_of_field_modes():
    """A basis whose columns each move one group of fields (as modes of the straight string do), plus two
    columns that move every field (as enrichment vectors do): the packed rows hold every nonzero and fewer
    columns than the dense ones, and their dot products and projection are the dense ones (sums of the same
    nonzero products, reassociated: within Higham's bound for sums in any order)."""
    rng = np.random.default_rng(4)
    fields = rng.integers(0, 6, size=300)
    group = np.array([0, 1, 2, 3, 2, 1])[fields]  # u; v with theta_z; w with theta_y; theta_x
    column_group = rng.integers(0, 4, size=40)
    dense = rng.standard_normal((300, 42)) * np.column_stack(
        [group[:, None] == column_group[None, :], np.ones((300, 2), dtype=bool)])
    packed = FieldPackedRows.of(dense, fields)
    assert np.array_equal(packed.dense(), dense)
    assert packed.counts.max() < dense.shape[1]
    assert np.all(packed.counts % 4 == 0)
    x, y, loads = rng.standard_normal(42), rng.standard_normal(42), rng.standard_normal(300)
    dots, twice, projected = _products(packed.kernel_data(), x, y, loads)
    # a sum of n products in any order is off by at most n eps sum|terms| (Higham, Accuracy and Stability, Sec.
    # 3.1): n = 42 columns for a row's dot, n = 300 rows for a column of the projection (measured: 2e-16 and 7e-17
    # of the sums of magnitudes)
    eps = np.finfo(float).eps
    x_sizes, y_sizes = np.abs(dense) @ np.abs(x), np.abs(dense) @ np.abs(y)
    assert np.all(np.abs(dots - dense @ x) <= 42 * eps * x_sizes)
    assert np.all(np.abs(twice[:, 0] - dense @ x) <= 42 * eps * x_sizes)
    assert np.all(np.abs(twice[:, 1] - dense @ y) <= 42 * eps * y_sizes)
    assert np.all(np.abs(projected - dense.T @ loads) <= 300 * eps * (np.abs(dense).T @ np.abs(loads)))
    some = rng.choice(300, size=50, replace=False)
    assert np.array_equal(packed.at(some).dense(), dense[some])
