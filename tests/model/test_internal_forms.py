"""The models of one string share its compiled internal-force forms (and their functions U, V, A):
a model's force and tangent stay its own when another model of the string evaluates in between."""

import numpy as np

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
