"""FFCx's element kernels called from Numba on an element sample (fenics_drill/model/kernels/cell_kernels.py), and
the wall law in one pass over a modal space's rows (fenics_drill/model/forces/wall_contact.py)."""

import numpy as np
import pytest
import ufl
from conftest import scene_with
from dolfinx import fem

from fenics_drill.model.kernels.cell_kernels import CellAssembly
from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.drillstring import build_model
from fenics_drill.model.forces.wall.vertex_passes import _contact_blocks, _modal_pass, _projected_laws, _vertex_loads
from fenics_drill.model.internal_force import ElementSample, InternalForms, SampledCoefficients
from fenics_drill.solvers.static import solve_static
from fenics_drill.studies.prepare import prepare

STRING = ("beam.length=20.0", "beam.elements=40", "output.field_interval=0")


class Sampled:
    """A string's sampled forms with the weights of one element sample set (zero on the other cells), its
    cells and their dofs, and DOLFINx's packed coefficients of a form read at those cells."""

    def __init__(self, disc, forms, sample):
        self.disc, self.forms, self.cells = disc, forms, sample.cells
        forms.weight.x.array[:] = 0.0
        forms.weight.x.array[sample.cells] = sample.weights
        self.dofs = np.unique(disc.V.dofmap.list[sample.cells])

    def packed(self, form):
        (key, packed), = fem.pack_coefficients(form).items()
        return packed[self.cells]  # a form on all cells packs them in the mesh's order


@pytest.fixture(scope="module")
def sampled_forms():
    scene = scene_with(*STRING)
    disc = BeamDiscretization.from_scene(scene)
    m = scene.model
    # unsorted cells with unequal weights: the assembly must follow the given order of the cells
    sample = ElementSample(np.array([31, 2, 17, 9]), np.array([0.7, 1.9, 1.1, 2.5]))
    forms = InternalForms(disc, (m.geometric_nonlinearity, m.inertial_nonlinearity, m.kinematics,
                                 m.angular_velocity), sampled=True)
    return Sampled(disc, forms, sample)


def test_the_cells_kernels_give_dolfinx_assembly_of_the_sampled_force(sampled_forms):
    """At three random states of the fields (displacements, rates and rotations of 0.3 in SI units, so every
    polynomial and sine of the energies is active), the vector of the sampled cells' kernels equals DOLFINx's
    assemble_vector at the sampled dofs.  Both add the same element vectors of the same kernel, only in
    another order: they agree to round-off (1e-13 of the largest entry)."""
    forms, dofs = sampled_forms.forms, sampled_forms.dofs
    rng = np.random.default_rng(7)
    assembly = CellAssembly(forms.residual, dofs, sampled_forms.cells)
    for _ in range(3):
        for function in forms.functions:
            function.x.array[:] = 0.3 * rng.standard_normal(function.x.array.size)
        reference = fem.assemble_vector(forms.residual).array
        ours = assembly(sampled_forms.packed(forms.residual))
        assert np.abs(reference).max() > 0
        # the same element vectors added in another order (an entry sums at most two cells' values; the cells
        # of zero weight add exact zeros): a few ulps of the largest entry; 1e-13 is about 500 eps
        np.testing.assert_allclose(ours, reference[dofs], rtol=0, atol=1e-13 * np.abs(reference).max())
        # the cells of zero weight add nothing: the sampled cells touch no other dof
        assert np.abs(np.delete(reference, dofs)).max() == 0.0


def test_the_cells_kernels_give_dolfinx_assembly_of_the_sampled_tangents_and_energies(sampled_forms):
    """The same for the sampled tangents df/dq, df/dqd, df/dqdd (dense at the sampled dofs, against DOLFINx's
    assemble_matrix) and the kinetic and strain energies (against assemble_scalar): the same element tensors
    added in another order, so round-off of the largest entry (1e-13)."""
    forms, dofs, cells = sampled_forms.forms, sampled_forms.dofs, sampled_forms.cells
    rng = np.random.default_rng(8)
    for _ in range(2):
        for function in forms.functions:
            function.x.array[:] = 0.3 * rng.standard_normal(function.x.array.size)
        for jacobian in forms.jacobians:
            if jacobian is None:
                continue
            reference = fem.assemble_matrix(jacobian).to_dense()
            ours = CellAssembly(jacobian, dofs, cells)(sampled_forms.packed(jacobian))
            assert np.abs(reference).max() > 0
            # the same element matrices added in another order: an entry sums at most two cells' values,
            # so a few ulps of the largest entry; 1e-13 is about 500 eps
            np.testing.assert_allclose(ours, reference[np.ix_(dofs, dofs)], rtol=0,
                                       atol=1e-13 * np.abs(reference).max())
            untouched = np.ones(reference.shape, dtype=bool)
            untouched[np.ix_(dofs, dofs)] = False
            assert np.abs(reference[untouched]).max() == 0.0
        for energy in (forms.kinetic, forms.strain):
            reference = fem.assemble_scalar(energy)
            assert reference != 0.0
            # the same four weighted cell integrals summed in another order (DOLFINx adds the other cells'
            # exact zeros): a few ulps of the sum
            assert CellAssembly(energy, cells=cells)(sampled_forms.packed(energy)) == pytest.approx(
                reference, rel=1e-13, abs=0.0)


def test_the_sampled_forms_projected_cell_by_cell_are_the_projections_of_their_assembly(sampled_forms):
    """The sampled forms as a run evaluates them: coefficients from the reduced state (q, qd, qdd) and each
    cell's tensor projected on its rows of [Phi] (P_c^T f_c, P_c^T K_c P_c), against Phi_s^T of the vector
    and Phi_s^T A Phi_s of the matrix assembled at the sampled dofs from the same state.  Sums of the same
    products in another order: round-off of the largest entry (1e-12, the projections adding 59-term sums
    to the element tensors' 1e-13)."""
    forms, dofs, cells = sampled_forms.forms, sampled_forms.dofs, sampled_forms.cells
    rng = np.random.default_rng(9)
    # a basis whose rows at each field's dofs are zero on some columns, as a modal basis's are (packed by field)
    fields = sampled_forms.disc.field_of_dof[dofs]
    basis = rng.standard_normal((len(dofs), 7)) * (np.arange(7)[None, :] % 3 != fields[:, None] % 3)
    sampled = [SampledCoefficients(form, forms.functions, dofs, basis, cells, fields)
               for form in (forms.residual, *forms.jacobians) if form is not None]
    state = 0.3 * rng.standard_normal(3 * basis.shape[1])
    for function, values in zip(forms.functions, state.reshape(3, -1)):
        function.x.array[:] = 0.0
        function.x.array[dofs] = basis @ values
    for form, coefficients in zip((forms.residual, *(j for j in forms.jacobians if j is not None)), sampled):
        at_dofs = CellAssembly(form, dofs, cells)(sampled_forms.packed(form))
        reference = basis.T @ at_dofs if at_dofs.ndim == 1 else basis.T @ at_dofs @ basis
        ours = coefficients.assemble(state)
        assert np.abs(reference).max() > 0
        # projected cell by cell instead of after assembly: sums of up to 15 x 15 x 4 products per entry in
        # another order (Higham: n eps ~ 2e-13 of the sum of magnitudes), so 1e-12 of the largest entry
        np.testing.assert_allclose(ours, reference, rtol=0, atol=1e-12 * np.abs(reference).max())


def test_the_full_orders_force_and_tangent_parts_are_dolfinx_assembly_of_its_forms():
    """The full order's internal force and its tangent parts df/dq, df/dqd, df/dqdd, assembled by the forms' FFCx
    kernels in one compiled loop over the cells (coefficients read off the state where DOLFINx packs them, the
    tangents read at the entries that matter, fenics_drill/model/internal_force.py), against DOLFINx's
    assemble_vector and assemble_matrix of the same forms, their functions set to the state, at the free dofs, at
    three random states (displacements, rates and rotations of 0.3 in SI units:
    every polynomial and sine of the energies active).  The same element tensors summed in another order: an entry
    sums at most two cells' values, so a few ulps of the largest entry (1e-13 is about 500 eps)."""
    import dolfinx.fem.petsc as fem_petsc

    model = build_model(scene_with(*STRING, "reduction.rule=none"))
    force, space = model.internal, model.space
    rng = np.random.default_rng(12)
    for _ in range(3):
        state = [0.3 * rng.standard_normal(model.size) for _ in range(3)]
        ours = force.evaluate(*state)
        for function, values in zip((force.U, force.V, force.A), state):
            function.x.array[:] = space.expand(values)
        reference = space.project(fem_petsc.assemble_vector(force._residual).array)
        assert np.abs(reference).max() > 0
        # the same element vectors added in another order: an entry sums at most two cells' values, a few ulps of
        # the largest entry; 1e-13 is about 500 eps
        np.testing.assert_allclose(ours, reference, rtol=0, atol=1e-13 * np.abs(reference).max())
        for part, jacobian in zip(force.tangent_parts(), force._jacobians):
            reference = space.project_matrix(fem.assemble_matrix(jacobian).to_scipy()).toarray()
            assert np.abs(reference).max() > 0
            # the same element matrices: the COO's repeated entries (a dof pair of two cells) summed by SciPy, DOLFINx's
            # in its CSR, in another order; a few ulps of the largest entry, 1e-13 is about 500 eps
            np.testing.assert_allclose(part.toarray(), reference, rtol=0, atol=1e-13 * np.abs(reference).max())


def test_cell_assembly_refuses_a_bilinear_form_of_two_spaces(sampled_forms):
    disc = sampled_forms.disc
    weights = fem.functionspace(disc.mesh, ("DG", 0))
    mixed = fem.form(ufl.TrialFunction(weights) * ufl.TestFunction(disc.V)[0] * ufl.dx(domain=disc.mesh))
    with pytest.raises(ValueError, match="one space"):
        CellAssembly(mixed, sampled_forms.dofs)


def test_the_wall_pass_of_a_modal_space_is_the_law_at_its_positions_projected():
    """In the default (modal) space, at 20 random states around the string's rest on the wall, the one-pass
    kernel gives (1) the positions and rates [Phi] q, [Phi] qd, (2) the pointwise law (16)-(19) at them and
    (3) [Phi]^T of its loads, and (:func:`_projected_laws`) of each law's loads.  They read the rows packed by
    field and sum in another order than BLAS (reassociated, vectorised) and may fuse multiply-adds, so each part
    is held to the round-off that allows, nothing looser:

    * a sum of n products in any order differs by at most n eps sum|terms| (Higham, Accuracy and Stability,
      Sec. 3.1): the bound for (1), with n = 64 >= the 59 terms of a row, and for (3), with n = 4 rows per
      vertex times the vertices (the terms of a column of [Phi]^T);
    * the law at the kernel's own positions, against the same law called from NumPy: fused multiply-adds
      change results by an ulp, and the indentation delta = |(v, w)| - gap cancels about 1e4 of its digits
      (delta ~ 1e-6 m against gap ~ 1e-2 m), so 1e-11 of the largest value."""
    scene = scene_with(*STRING)
    model = prepare(scene, dynamics=False).model
    resting = solve_static(model).q  # on the wall near the bit
    wall = model.force("wall")
    flat, packed = wall.every.flat, wall.every.packed
    # the rows packed by field, scattered back, are the dense ones, on fewer columns (the kernel reads only those)
    assert np.array_equal(packed.dense(), flat)
    assert packed.counts.max() < flat.shape[1]
    rng = np.random.default_rng(11)
    eps, terms = np.finfo(float).eps, 64
    touched = 0
    for _ in range(20):
        q = resting * (1 + 0.05 * rng.standard_normal(model.size))
        qd = rng.standard_normal(model.size) * 0.5
        delta, nodal, laws, potential, generalised, positions, rates = _modal_pass(packed.kernel_data(), model.size,
                                                                                   q, qd, *wall._law())
        projected = _projected_laws(packed.kernel_data(), model.size, delta, laws)
        # (1) positions and rates
        position_bound = terms * eps * (np.abs(flat) @ np.abs(q)).reshape(-1, 4)
        rate_bound = terms * eps * (np.abs(flat) @ np.abs(qd)).reshape(-1, 4)
        assert np.all(np.abs(positions - (flat @ q).reshape(-1, 4)) <= position_bound)
        assert np.all(np.abs(rates - (flat @ qd).reshape(-1, 4)) <= rate_bound)
        # (2) the law at those positions and rates
        ref_delta, ref_nodal, ref_laws, ref_potential = _vertex_loads(positions, rates, *wall._law())
        np.testing.assert_allclose(delta, ref_delta, rtol=0, atol=1e-11 * np.abs(ref_delta).max())
        np.testing.assert_allclose(nodal, ref_nodal, rtol=0, atol=1e-11 * np.abs(ref_nodal).max())
        np.testing.assert_allclose(laws, ref_laws, rtol=0, atol=1e-11 * np.abs(ref_laws).max())
        assert potential == pytest.approx(ref_potential, rel=1e-11, abs=0.0)
        # (3) the projection of the kernel's own loads, and of each law's (damper, axial friction, torque)
        column_terms = flat.shape[0]
        projection_bound = column_terms * eps * (np.abs(flat).T @ np.abs(nodal.ravel()))
        assert np.all(np.abs(generalised - flat.T @ nodal.ravel()) <= projection_bound)
        by_law = laws.reshape(-1, 3)
        law_bound = column_terms * eps * (np.abs(flat).T @ np.abs(by_law))
        assert np.all(np.abs(projected.T - flat.T @ by_law) <= law_bound)
        touched += int((ref_delta > 0).sum())
    assert touched > 20  # the states reach the wall, so the loads are tested


def test_the_cells_kernels_give_dolfinx_evaluation_of_the_strain_expression():
    """The von Mises probe's strain expression at every cell, from random dof values of the size of a drilling
    state's (0.3 in SI units, every term of the Green-Lagrange strains active): the same kernel as DOLFINx's
    Expression.eval, fed with the same coefficients, so equal to round-off (1e-13 of the largest value)."""
    from fenics_drill.observables.von_mises import VonMisesProbe

    disc = BeamDiscretization.from_scene(scene_with(*STRING))
    probe = VonMisesProbe(disc)
    rng = np.random.default_rng(5)
    for _ in range(3):
        dofs = 0.3 * rng.standard_normal(disc.ndofs)
        probe.field.x.array[:] = dofs
        reference = probe.expression.eval(disc.mesh, probe.cells)
        ours = probe._at_cells(dofs)
        assert np.abs(reference).max() > 0
        # the same kernel on the same coefficients: equal but for round-off of the largest value's size
        np.testing.assert_allclose(ours, reference.reshape(ours.shape), rtol=0,
                                   atol=1e-13 * np.abs(reference).max())


def test_the_wall_tangent_of_a_modal_space_is_its_double_precision_product_to_single_round_off():
    """In a modal space the wall's tangent R^T (A R) is formed in single precision (it steers Newton only;
    the residual, in double precision, decides convergence).  Against R^T (A R) in double precision at 10
    states pressed into the wall, each entry is within the bound of a single-precision product: both
    factors rounded once (2 u) and a sum of k products in any order (k u, Higham Sec. 3.1), times
    sum |R| |A R|, with u the unit round-off of float32.  A tangent off by 1e-4 of its largest entry
    breaks that bound, so the test can fail."""
    scene = scene_with(*STRING)
    model = prepare(scene, dynamics=False).model
    resting = solve_static(model).q
    wall = model.force("wall")
    rng = np.random.default_rng(5)
    u = np.finfo(np.float32).eps / 2
    for _ in range(10):
        q = resting * (1 + 0.05 * rng.standard_normal(model.size))
        radius = np.sort(np.hypot(*(rows @ q for rows in model.lateral_rows)))
        q *= 1.03 * model.gap / radius[-3]  # at least three vertices pressed into the wall
        qd = rng.standard_normal(model.size) * 0.5
        forces = wall.evaluate(q, qd, with_tangent=True)
        c_u, c_v = 1.0, 1e3
        tangent = wall.fresh().tangent(forces, c_u, c_v)  # formed whole (no kept tangent to update)
        rows_of, positions, rates, vertices, _ = forces.tangent_data
        flat = rows_of.flat
        active = np.flatnonzero(forces.delta > 0)
        blocks = _contact_blocks(active, positions, rates, *wall._law(vertices), c_u, c_v)
        rows = flat.reshape(-1, 4, model.size)[active]  # (vertex, field, column)
        weighted = np.einsum("vof,vfj->voj", blocks, rows)
        reference = np.einsum("voi,voj->ij", rows, weighted)
        k = 4 * active.size
        bound = (k + 2) * u * np.einsum("voi,voj->ij", np.abs(rows), np.abs(weighted))
        assert np.all(np.abs(tangent - reference) <= bound)
        assert np.any(np.abs(tangent + 1e-4 * np.abs(reference).max() - reference) > bound)
        assert np.abs(reference).max() > 0


def test_the_updated_wall_tangent_is_the_exact_one_within_its_block_tolerance():
    """A simulation's wall keeps its modal tangent and adds R_i^T (A_i - A_i_kept) R_i only at the vertices
    whose block A_i moved by more than tau = BLOCK_TOLERANCE of the largest block s.  Along 30 states that
    drift as a step's Newton iterates and steps do (with one change of c_v, as after a change of step), each
    tangent is within the bound that rule gives against R^T A R in double precision:

        tau s sum_i |R_i|^T 1 |R_i|     (each kept entry off by at most tau s; 1: the 4 x 4 ones)
      + U (k + 2) u sum_i |R_i|^T 2 M_i |R_i|   (the single-precision round-off of the U updates so far,
                                                 each increment bounded by 2 M_i, M_i the largest |A_i| seen)

    A tangent kept from five states earlier breaks that bound at most states, so the test can fail."""
    scene = scene_with(*STRING)
    model = prepare(scene, dynamics=False).model
    resting = solve_static(model).q
    wall = model.force("wall").fresh()
    tau = wall.BLOCK_TOLERANCE
    rng = np.random.default_rng(7)
    u = np.finfo(np.float32).eps / 2
    radius = np.sort(np.hypot(*(rows @ resting for rows in model.lateral_rows)))
    q = resting * 1.03 * model.gap / radius[-3]  # three or more vertices pressed into the wall
    qd = rng.standard_normal(model.size) * 0.05
    rows = wall.flat.reshape(-1, 4, model.size)  # (vertex, field, column) of every vertex
    largest = np.zeros((rows.shape[0], 4, 4))  # M_i
    history, stale_breaks = [], 0
    for state in range(30):
        q = q + 2e-4 * np.abs(q).max() * rng.standard_normal(model.size)
        qd = qd + 0.01 * rng.standard_normal(model.size)
        c_u, c_v = 1.0, (1e3 if state < 15 else 2e3)
        forces = wall.evaluate(q, qd, with_tangent=True)
        tangent = wall.tangent(forces, c_u, c_v)
        _, lateral, rates, vertices, _ = forces.tangent_data
        active = np.flatnonzero(forces.delta > 0)
        blocks = np.zeros_like(largest)
        blocks[forces.vertices[active]] = _contact_blocks(active, lateral, rates, *wall._law(vertices), c_u, c_v)
        largest = np.maximum(largest, np.abs(blocks))
        reference = np.einsum("voi,vof,vfj->ij", rows, blocks, rows)
        kept_off = tau * largest.max() * np.einsum("voi,vfj->ij", np.abs(rows), np.abs(rows))
        updates = state + 1
        round_off = updates * (4 * rows.shape[0] + 2) * u * np.einsum("voi,vof,vfj->ij", np.abs(rows), 2 * largest,
                                                                        np.abs(rows))
        assert np.all(np.abs(tangent - reference) <= kept_off + round_off)
        history.append(tangent)
        if state >= 5:
            stale_breaks += np.any(np.abs(history[-6] - reference) > kept_off + round_off)
    assert stale_breaks >= 20
