"""The Newmark predictor kept on the round wall: a vertex resting on the wall at the last accepted state starts
Newton at the indentation it had there, in the direction the straight-line predictor moved it (full space)."""

import numpy as np
import pytest
from conftest import scene_with

from fenics_drill.solvers.static import solve_static
from fenics_drill.studies.prepare import prepare


@pytest.fixture(scope="module")
def resting_full_order():
    scene = scene_with("beam.length=20.0", "beam.elements=40", "output.field_interval=0", "reduction.rule='none'")
    model = prepare(scene, dynamics=False).model
    return model, solve_static(model).q


def test_resting_vertices_keep_their_indentation_along_the_predicted_direction(resting_full_order):
    """A move of 2 mm along the wall's tangent at every vertex (a straight line, which leaves the wall by
    (2 mm)^2 / 2 R): the vertices on the wall at q0 come back to their indentation there, to round-off of
    the radius (1e-15 m on 15 mm); their angle is the move's; the vertices off the wall are not touched."""
    model, q0 = resting_full_order
    wall = model.force("wall")
    lateral = wall.every.lateral_rows
    before = (lateral @ q0).reshape(-1, 2)
    r0 = np.hypot(*before.T)
    touching = r0 > wall.gap
    assert 0 < touching.sum() < touching.size  # some on the wall, some off it: both branches are checked
    tangent = np.column_stack([-before[:, 1], before[:, 0]]) / np.maximum(r0, 1e-30)[:, None]
    move = np.zeros(q0.size)
    columns = lateral.indices  # each (v, w) row selects one free dof; rows held by a support have none
    rows_with_dof = np.flatnonzero(np.diff(lateral.indptr))
    move[columns] = (2e-3 * tangent).ravel()[rows_with_dof]
    q = q0 + move
    kept = wall.kept_on_wall(q0, q)
    after, moved = (lateral @ kept).reshape(-1, 2), (lateral @ q).reshape(-1, 2)
    # a scaling and a hypot of a 15 mm radius: a few ulps (3e-18 m each); 1e-15 m leaves room and is still 1e-8 of
    # the 0.1 um indentations the vertices rest at
    assert np.allclose(np.hypot(*after[touching].T), r0[touching], rtol=0, atol=1e-15)
    angle = np.arctan2(after[:, 1], after[:, 0]) - np.arctan2(moved[:, 1], moved[:, 0])
    assert np.abs(angle[touching]).max() < 1e-12
    assert np.array_equal(after[~touching], moved[~touching])
    others = np.setdiff1d(np.arange(q0.size), columns)
    assert np.array_equal(kept[others], q[others])
