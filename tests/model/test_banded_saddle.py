"""The banded saddle solve of the full order (fenics_drill/model/kernels/banded_saddle.py) against a dense solve
of the bordered system (76), and on a full-order string against SciPy's sparse LU."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fenics_drill.model.kernels.banded_saddle import BandedSaddle, SparseSum, Triplets
from fenics_drill.model.drillstring import build_model
from conftest import scene_with


def scrambled_band(n: int, width: int, seed: int):
    """A random non-symmetric matrix that is banded in some numbering of its dofs, stored in another
    (COO, with every entry split into two repeated ones), and that numbering (position -> dof)."""
    rng = np.random.default_rng(seed)
    banded = np.zeros((n, n))
    for d in range(-width, width + 1):
        banded += np.diag(rng.standard_normal(n - abs(d)), d)
    banded += np.diag(np.full(n, 4.0 * width))  # diagonally dominant: regular, also without the held dofs
    order = rng.permutation(n)  # position -> dof
    dense = np.zeros((n, n))
    dense[np.ix_(order, order)] = banded
    rows, cols = np.nonzero(dense)
    half = 0.5 * dense[rows, cols]
    coo = sp.coo_matrix((np.concatenate([half, half]), (np.concatenate([rows, rows]), np.concatenate([cols, cols]))),
                        shape=(n, n))
    return dense, coo, order


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_banded_saddle_matches_a_dense_solve_of_the_bordered_system(seed):
    n, width = 60, 3
    dense, coo, order = scrambled_band(n, width, seed)
    rng = np.random.default_rng(10 + seed)
    held = rng.choice(n, size=2, replace=False)
    B = np.zeros((2, n))
    B[0, held[0]], B[1, held[1]] = 1.0, -3.5  # scaled selection rows, as a full space's [B] may be
    saddle = np.block([[dense, B.T], [B, np.zeros((2, 2))]])
    rhs_q, rhs_c = rng.standard_normal(n), rng.standard_normal(2)
    expected = np.linalg.solve(saddle, np.concatenate([rhs_q, rhs_c]))
    solve = BandedSaddle(coo, B, order)
    x, mu = solve(rhs_q, rhs_c)
    assert (solve.kl, solve.ku) == (width, width)  # the numbering is the band's
    # both are direct solves of one system; J's condition number is about 2 and the bordered matrix's about
    # 200 (measured for these seeds), so their difference is round-off, far below 1e-12 of the solution
    assert np.allclose(x, expected[:n], rtol=0, atol=1e-12 * np.abs(expected).max())
    assert np.allclose(mu, expected[n:], rtol=0, atol=1e-12 * np.abs(expected).max())


def test_a_sum_kept_as_its_terms_solves_as_its_matrix_and_its_kept_layout_follows_no_stale_terms():
    """A tangent as the model forms it, SparseSum([(1, kept sum of three parts), (-1, fresh part)]): the solve equals
    the dense one of the summed matrix; a second tangent over the same kept sum with another fresh part (the kept
    band copied, not laid out again) equals its own dense solve, and so does one under other held dofs; the fresh
    part as a SciPy COO matrix or as :class:`Triplets` (how the point forces give theirs) alike."""
    n, width = 60, 3
    order = scrambled_band(n, width, 3)[2]
    dense_parts = []  # five banded matrices in that one numbering; the first diagonally dominant
    for k in range(5):
        rng = np.random.default_rng(20 + k)
        banded = sum(np.diag(rng.standard_normal(n - abs(d)), d) for d in range(-width, width + 1))
        dense = np.zeros((n, n))
        dense[np.ix_(order, order)] = banded + (np.diag(np.full(n, 12.0 * width)) if k == 0 else 0.0)
        dense_parts.append(dense)
    kept = SparseSum([(1.0, dense_parts[0]), (2.5, dense_parts[1]), (-0.5, dense_parts[2])], (n, n))
    rng = np.random.default_rng(30)
    for fresh, as_entries in ((dense_parts[3], False), (dense_parts[4], False), (dense_parts[4], True)):
        entries = sp.coo_matrix(fresh)
        if as_entries:
            entries = Triplets(entries.data, entries.row, entries.col, entries.shape)
        for held in (rng.choice(n, size=2, replace=False), rng.choice(n, size=1, replace=False)):
            tangent = SparseSum([(1.0, kept), (-1.0, entries)], (n, n))
            matrix = dense_parts[0] + 2.5 * dense_parts[1] - 0.5 * dense_parts[2] - fresh
            # the same sums in another order: entries of size ~40 (the dominant diagonal) agree to a few ulps, and a
            # product's rows (7 such terms each) to ten
            assert np.allclose(tangent.toarray(), matrix, rtol=0, atol=1e-13)
            assert np.allclose(tangent @ np.ones(n), matrix @ np.ones(n), rtol=0, atol=1e-12)
            B = np.zeros((held.size, n))
            B[np.arange(held.size), held] = 2.0
            saddle = np.block([[matrix, B.T], [B, np.zeros((held.size, held.size))]])
            rhs_q, rhs_c = rng.standard_normal(n), rng.standard_normal(held.size)
            expected = np.linalg.solve(saddle, np.concatenate([rhs_q, rhs_c]))
            x, mu = BandedSaddle(tangent, B, order, width)(rhs_q, rhs_c)
            # direct solves of one well-conditioned system (diagonally dominant J): round-off apart
            assert np.allclose(x, expected[:n], rtol=0, atol=1e-11 * np.abs(expected).max())
            assert np.allclose(mu, expected[n:], rtol=0, atol=1e-11 * np.abs(expected).max())


def test_a_constraint_on_two_dofs_is_refused():
    dense, coo, order = scrambled_band(20, 2, 0)
    B = np.zeros((1, 20))
    B[0, [3, 4]] = 1.0
    with pytest.raises(ValueError, match="holds 2 dofs"):
        BandedSaddle(coo, B, order)


def test_an_entry_outside_the_given_bandwidth_is_refused():
    """The full space gives the bandwidth of one element; an entry beyond it would be left out of the
    factorisation, so it must stop the solve instead."""
    dense, coo, order = scrambled_band(20, 2, 0)
    B = np.zeros((1, 20))
    B[0, order[0]] = 1.0
    BandedSaddle(coo, B, order, width=2)  # the band's own width holds every entry
    with pytest.raises(ValueError, match="outside its bandwidth 1"):
        BandedSaddle(coo, B, order, width=1)


def test_a_singular_tangent_is_reported():
    n = 12
    J = sp.coo_matrix(np.diag(np.r_[np.ones(n - 1), 0.0]))
    B = np.zeros((1, n))
    B[0, 0] = 1.0
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        BandedSaddle(J, B, np.arange(n))


def test_full_order_string_solves_as_scipy_sparse_lu():
    """The full order of a 60-element string: the Newmark tangent of a deflected state, renumbered along
    the string, solves (76) as SuperLU does on the bordered system."""
    model = build_model(scene_with("beam.elements=60", "beam.length=20.0", "reduction.rule='none'"))
    rng = np.random.default_rng(3)
    n = model.size
    q = 1e-3 * rng.standard_normal(n)
    dt = 2.5e-3
    evaluation = model.evaluate(q, q, q, np.zeros(2), (1.0, 0.5 / (0.25 * dt), 1.0 / (0.25 * dt * dt)))
    J, B = evaluation.tangent.tocsr(), np.asarray(model.constraints)
    k = abs(J.diagonal()).max()  # rows of [B] scaled to the tangent's: the bordered system is well posed
    bordered = sp.bmat([[J, sp.csr_matrix(k * B).T], [sp.csr_matrix(k * B), None]], format="csc")
    rhs_q, rhs_c = rng.standard_normal(n), 1e-3 * rng.standard_normal(2)
    reference = spla.splu(bordered).solve(np.concatenate([rhs_q, k * rhs_c]))
    x, mu = model.space.saddle_solve(evaluation.tangent, model.constraints, rhs_q, rhs_c)
    # two direct solves of one system with condition ~1e8 (c_a M against the wall's 1e10 N/m): 1e-8
    assert np.abs(x - reference[:n]).max() <= 1e-8 * np.abs(reference[:n]).max()
    assert np.abs(mu - k * reference[n:]).max() <= 1e-8 * np.abs(k * reference[n:]).max()
    assert np.abs(B @ x - rhs_c).max() <= 1e-14
