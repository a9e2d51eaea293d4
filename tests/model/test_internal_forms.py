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
def test_each_tangent_part_of_the_nonlinear_remainder_is_its_derivative(geometric, inertial):
    """The sampled forms hold only the nonlinear remainder of each force that has one, and a tangent part
    exists only for the fields the remainder holds (read off the form, not by expanding its derivatives).
    Against the remainder itself ([Phi]^T of its element vectors, without the linear part, whose K q would
    drown the velocity's share in round-off): along a random direction of q, qd or qdd, a part's nonlinear
    share (the part less the projected linear matrix) is the central difference of the remainder, and where
    it is zero the remainder does not change at all.  The state: rotations of 0.03 rad (the elastic remainder
    stays small enough that its round-off does not drown the inertial one), rates of 10 and 100 per second.
    Steps: 1e-5 of q; 0.3 of qd and qdd, where the kinetic energy's forces are quadratic and linear, so
    central differences are exact and a large step lifts the change above the remainder's round-off.
    Measured errors: at most 4e-7 of the change (the inertial remainder's q-dependence, 4e-8 N, summed over
    elements that cancel); 1e-5 keeps a margin, while a missing or wrong part errs at order one."""
    from fenics_drill.model.internal_force import AssembledInternalForce, ElementSample

    scene = scene_with("beam.length=10.0", "beam.elements=20", f"model.geometric_nonlinearity={str(geometric).lower()}",
                       f"model.inertial_nonlinearity={str(inertial).lower()}")
    model = build_model(scene)
    cells = np.arange(model.disc.elements, dtype=np.int32)
    m = scene.model
    force = AssembledInternalForce(model.disc, model.space, model.operators, geometric, inertial, m.kinematics,
                                   m.angular_velocity, sample=ElementSample(cells, np.ones(cells.size)))
    phi_cells = model.space.phi[model.disc.V.dofmap.list[cells]]

    def remainder(x):
        return np.einsum("edn,ed->n", phi_cells, force.element_vectors(*x))

    rng = np.random.default_rng(11)
    state = [size * rng.standard_normal(model.size) for size in (0.03, 10.0, 100.0)]
    force.evaluate(*state)
    parts = force.tangent_parts()
    for k, (part, linear) in enumerate(zip(parts, force.linear)):
        nonlinear = np.asarray(part) - linear
        direction = rng.standard_normal(model.size) * (1e-5, 0.3, 0.3)[k] * np.linalg.norm(state[k]) / model.size**0.5
        plus, minus = ([x + sign * direction if i == k else x for i, x in enumerate(state)] for sign in (1, -1))
        change = (remainder(plus) - remainder(minus)) / 2
        if not nonlinear.any():
            assert not change.any()
        else:
            assert np.linalg.norm(change - nonlinear @ direction) <= 1e-5 * np.linalg.norm(change)
