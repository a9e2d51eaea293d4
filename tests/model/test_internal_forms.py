"""The models of one string share its compiled internal-force forms (and their functions U, V, A):
a model's force and tangent stay its own when another model of the string evaluates in between."""

import numpy as np
import pytest

from conftest import scene_with
from fenics_drill.model.drillstring import build_model


def test_models_of_one_string_share_forms_without_sharing_states():
    reduced = build_model(scene_with("beam.length=10.0", "beam.elements=20"))
    full = reduced.full_order()
    assert full.internal.U is reduced.internal.U  # compiled once for the string
    rng = np.random.default_rng(5)

    def state(model, size):
        return tuple(size * rng.standard_normal(model.size) for _ in range(3))

    x = state(reduced, 1e-2)
    force = reduced.internal.evaluate(*x)
    alone = reduced.internal.tangent_parts()
    full.internal.evaluate(*state(full, 1e-1))  # sets the shared functions to another state
    again = reduced.internal.tangent_parts()
    # the same kernels at the same state: equal up to round-off (~1e-16 of the entries; the functions are
    # set again from q by a product with [Phi], so not bit for bit). The other model's state is 10x larger
    # and random: had it leaked in, the parts would differ at order one
    for a, b in zip(alone, again):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * np.abs(a).max())
    assert np.allclose(reduced.internal.evaluate(*x), force, rtol=1e-12, atol=1e-12 * np.abs(force).max())


@pytest.mark.parametrize("geometric, inertial", [(True, True), (True, False), (False, True)])
def test_a_tangent_part_exists_exactly_where_the_nonlinear_remainder_depends_on_its_field(geometric, inertial):
    """The sampled forms hold only the nonlinear remainder of each force that has one, and a tangent part
    (df/dq, df/dqd, df/dqdd) exists only for the fields the remainder holds, read off the form instead of
    expanding its derivatives.  Where a part is absent, changing that field must leave the remainder (its
    element vectors) exactly as it was; where it is present, its nonlinear share (the part less the projected
    linear matrix) must not vanish at a random state.  The parts' values are DOLFINx's tangents: see
    test_hyper_reduction.py (every element at unit weight against the unsampled model)."""
    from fenics_drill.model.internal_force import AssembledInternalForce, ElementSample

    # 60 m: the basis holds flexural modes of both planes, which the inertial remainder needs (omega_1 of (13)
    # couples theta_x and theta_z through theta_y); a 10 m string's holds only the w plane's sag at 120 rpm
    scene = scene_with("beam.length=60.0", "beam.elements=20", f"model.geometric_nonlinearity={str(geometric).lower()}",
                       f"model.inertial_nonlinearity={str(inertial).lower()}")
    model = build_model(scene)
    m = scene.model
    cells = np.arange(model.disc.elements, dtype=np.int32)
    force = AssembledInternalForce(model.disc, model.space, model.operators, geometric, inertial, m.kinematics,
                                   m.angular_velocity, sample=ElementSample(cells, np.ones(cells.size)))
    rng = np.random.default_rng(11)
    state = [size * rng.standard_normal(model.size) for size in (0.3, 10.0, 100.0)]
    before = force.element_vectors(*state)
    force.evaluate(*state)
    parts = force.tangent_parts()
    expected = (True, inertial, inertial)  # q: either nonlinearity; qd, qdd: the kinetic energy's only
    for k, (part, linear) in enumerate(zip(parts, force.linear)):
        nonlinear = np.asarray(part) - linear
        if expected[k]:
            # not identically zero (a form kept for a field that cancels assembles exact zeros); the share is
            # small (2e-5 of the mass for df/dqdd: a modal state of order one is a small physical rotation)
            assert nonlinear.any()
        else:
            assert not nonlinear.any()
            moved = [x + rng.standard_normal(model.size) if i == k else x for i, x in enumerate(state)]
            assert np.array_equal(force.element_vectors(*moved), before)



def test_an_evaluation_assembles_only_the_internal_tangent_parts_it_is_not_given():
    """Newton's slow-contraction refresh assembles df/dq afresh and keeps df/dqd, df/dqdd of earlier steps
    (solvers/newmark.py): the tangent must then be c_u df/dq at this state plus c_v, c_a times the parts
    given, i.e. the fresh tangent less c_v (C_fresh - C_given) and c_a (M_fresh - M_given).  The parts given
    here are random matrices of the parts' size, so that using a fresh part where one is given (or the
    reverse) changes the tangent at order one.  Reference: the evaluation with every part fresh; the same
    matrices summed in another order (1e-12 of the largest entry)."""
    model = build_model(scene_with("beam.length=10.0", "beam.elements=20", "model.contact=false"))
    rng = np.random.default_rng(3)
    state = [size * rng.standard_normal(model.size) for size in (0.3, 10.0, 100.0)]
    mu = np.zeros(model.constraints.shape[0])
    coefficients = (1.0, 2e3, 4e6)
    fresh = model.evaluate(*state, mu, coefficients)
    stiffness, damping, mass = fresh.internal_parts
    given = tuple(np.abs(part).max() * rng.standard_normal(part.shape) for part in (damping, mass))
    partial = model.evaluate(*state, mu, coefficients, internal_parts=(None, *given))
    assert partial.internal_parts[1] is given[0] and partial.internal_parts[2] is given[1]
    # the same kernels at the same state: df/dq agrees to the round-off of its assembly (entries ~1e14 summed
    # from 20 cells: ~1e-15 relative), so 1e-12 of the largest entry; a stale or wrong part errs at order one
    assert np.allclose(partial.internal_parts[0], stiffness, rtol=0, atol=1e-12 * np.abs(stiffness).max())
    expected = fresh.tangent - coefficients[1] * (damping - given[0]) - coefficients[2] * (mass - given[1])
    # the same six matrices combined in another order (a few roundings of the largest term, ~1e-15 of it), so
    # 1e-12; using a fresh part where one is given changes entries at the size of the random given ones
    assert np.allclose(partial.tangent, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
