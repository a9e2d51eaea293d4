"""Contact only where it can happen: the wall law is evaluated at the vertices that can reach the wall,
and the others are left out while a bound on the motion proves they cannot."""

import numpy as np
import pytest
from conftest import scene_with

from fenics_drill.solvers.static import solve_static
from fenics_drill.studies.prepare import prepare
from fenics_drill.solvers.time_loop import Simulation

#: The 20 m string of the reduced-model tests, on its wall near the bit and centred at the drive.
STRING = ("beam.length=20.0", "beam.elements=40", "output.field_interval=0")


@pytest.fixture(scope="module")
def resting():
    scene = scene_with(*STRING)
    model = prepare(scene, dynamics=False).model
    return model, solve_static(model).q


def test_a_vertex_left_out_cannot_reach_the_wall_while_the_bound_holds(resting):
    """From the static state, 300 random motions of q whose bound is 0.999 of the reach (the distance of
    the nearest vertex left out): every vertex left out stays off the wall.  Some are left out (else the
    test proves nothing), and the bound is tight to a factor sqrt(2) for a motion of one coordinate."""
    model, q0 = resting
    wall = model.force("wall")
    wall.evaluate(q0, np.zeros_like(q0))
    near = wall._near
    left_out = np.setdiff1d(np.arange(len(wall.x)), near.vertices)
    assert 0 < left_out.size < len(wall.x)
    rng = np.random.default_rng(3)

    def radii(q):
        return np.hypot(*(wall.every.lateral_rows @ q).reshape(-1, 2).T)[left_out]

    for _ in range(300):
        dq = rng.standard_normal(q0.size) * rng.uniform(0, 1, q0.size) ** 3
        dq *= 0.999 * near.reach / (near.column_bound @ np.abs(dq))
        assert np.all(radii(q0 + dq) < wall.gap[left_out])  # each left-out vertex off the wall at its clearance
        assert wall._near_vertices(q0 + dq) is near  # inside the reach the set is kept
    # the bound is not vacuous: moving one coordinate, the vertex that decides it moves by at least
    # 1/sqrt(2) of the bound (|(a, b)|_2 >= |(a, b)|_1 / sqrt(2))
    worst = int(np.argmax(near.column_bound))
    dq = np.zeros_like(q0)
    dq[worst] = near.reach / near.column_bound[worst]
    moved = np.hypot(*(wall.every.lateral_rows @ dq).reshape(-1, 2).T)[left_out]
    assert moved.max() >= near.reach / np.sqrt(2) * (1 - 1e-12)


def run(culling: str):
    """The simulation, its final state, and how many contacts began at each vertex (impacts or not)."""
    scene = scene_with(*STRING, "time.t_end=0.3", "model.kinematics='printed'", f"contact.culling={culling}")
    prepared = prepare(scene)
    simulation = Simulation(prepared.model, scene)
    onsets, contact = np.zeros(len(prepared.model.disc.vertex_x), dtype=int), {}

    def count(record):
        if contact:
            onsets[record.in_contact & ~contact["last"]] += 1
        contact["last"] = record.in_contact.copy()

    final = simulation.run(simulation.initial_state(prepared.equilibrium.q), scene.time.t_end, on_step=count)
    return simulation, final, onsets


def test_culled_runs_give_the_same_impacts_as_full_evaluation():
    """0.3 s of the 20 m string with the printed kinematics (its lateral vibration makes contacts begin and end):
    culled and full evaluation give the same contact onsets and impacts at the same vertices, the same steps,
    and the same state.
    The culled run sums the same non-zero vertex forces as the full one, in another order: 1e-9 of the
    state's size is round-off carried through 0.3 s of Newton solves."""
    culled, q_culled, onsets_culled = run("true")
    full, q_full, onsets_full = run("false")
    assert onsets_culled.sum() > 0
    np.testing.assert_array_equal(onsets_culled, onsets_full)
    np.testing.assert_array_equal(culled.impacts_per_vertex, full.impacts_per_vertex)
    assert culled.stats["steps"] == full.stats["steps"]
    np.testing.assert_allclose(q_culled.q, q_full.q, atol=1e-9 * np.abs(q_full.q).max())
