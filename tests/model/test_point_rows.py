"""The point rows P of a few dofs (space.point_rows) give P q, P^T f and P^T A P as the dense rows of
[Phi] do, in the full space (gathers and scatters) and in a modal one, a dof held by a support included."""

import numpy as np
import pytest

from conftest import scene_with
from fenics_drill.model.discretization import THETA_X, U, W
from fenics_drill.model.drillstring import build_model


@pytest.mark.parametrize("rule", ["none", "auto"])
def test_point_rows_are_the_rows_of_phi(rule):
    model = build_model(scene_with("beam.length=10.0", "beam.elements=20", f"reduction.rule='{rule}'"))
    disc, space = model.disc, model.space
    held = int(disc.support_dofs[0])  # a dof the supports hold: no column of [Phi] reaches it
    dofs = [disc.end_dof(U, 1), held, disc.end_dof(THETA_X, 1), int(disc.vertex_dofs(W)[7])]
    rows = space.point_rows(dofs)
    phi = space.phi.toarray() if rule == "none" else space.phi
    expected = phi[dofs]
    assert np.array_equal(rows.dense(), expected)
    rng = np.random.default_rng(3)
    x, f, jacobian = rng.standard_normal(space.size), rng.standard_normal(4), rng.standard_normal((4, 4))
    block = rows.block(jacobian)
    block = block.toarray() if hasattr(block, "toarray") else block
    # the same products computed two ways: in the full space a gather/scatter of entries that are 1 or 0
    # (exact), in a modal one the same BLAS products (at most 59 terms of O(1) each, so a few 1e-16 of
    # round-off); 1e-13 of the operands' size is far above that and far below any wrong row or sign
    assert np.allclose(rows.values(x), expected @ x, rtol=1e-13, atol=1e-13 * np.abs(x).max())
    assert np.allclose(rows.spread(f), expected.T @ f, rtol=1e-13, atol=1e-13)
    assert np.allclose(block, expected.T @ jacobian @ expected, rtol=1e-13, atol=1e-13 * np.abs(jacobian).max())
    assert np.array_equal(rows.subset([2]).dense(), expected[[2]])
    # P^T e_k: the generalised force of a unit load on dof k is column k of P^T (row k of P), exactly (a
    # copy of the row, or a scatter of one entry); zero for the held dof
    for k, load in enumerate(rows.unit_loads()):
        assert np.array_equal(load, expected[k])
    assert not rows.unit_loads()[1].any()
