"""Energy-derived nonlinear forms: linearisation, printed operators, invariances,
positivity, Taylor test of the tangents, and dissipativity of the force laws."""

import basix.ufl
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import pytest
import ufl
from conftest import scene_with
from dolfinx import fem

from fenics_drill.model import discretization as field
from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.studies.form_check import compare_printed_forms, random_state
from fenics_drill.forms import damping_form, mass_form, stiffness_form
from fenics_drill.forms.energies import damping_force, elastic_force, inertial_force, strain_energy_density, strain_slots
from fenics_drill.forms.printed import PRINTED_ERRATA
from fenics_drill.forms.section_polynomial import annulus_moment


@pytest.fixture(scope="module", params=["air", "mud"])
def disc(request):
    """The paper's pipe, in air and in mud (the mud's lateral added mass and damping enter M, C and the energies)."""
    mud = ("fluid.density=1200.0", "fluid.lateral_damping=40.0") if request.param == "mud" else ()
    return BeamDiscretization.from_scene(scene_with("beam.length=3", "beam.elements=6", *mud))


def dx_of(disc):
    return ufl.Measure("dx", domain=disc.mesh, metadata={"quadrature_degree": 10})


def vector(form):
    return fem_petsc.assemble_vector(fem.form(form)).array.copy()


def matrix(form):
    A = fem_petsc.assemble_matrix(fem.form(form))
    A.assemble()
    return A


def test_section_moments_are_those_of_eqs_3_to_10(paper_properties):
    # Both sides are closed forms of the same integrals in double precision: round-off tolerance.
    p = paper_properties
    s = p.section
    ro, ri = p.outer_radius, p.inner_radius
    assert annulus_moment(0, 0, ro, ri) == pytest.approx(s.area, rel=1e-14)
    assert annulus_moment(2, 0, ro, ri) == pytest.approx(s.I4, rel=1e-14)
    assert annulus_moment(0, 2, ro, ri) == pytest.approx(s.I4, rel=1e-14)
    assert annulus_moment(4, 0, ro, ri) == pytest.approx(3 * s.I6, rel=1e-14)
    assert annulus_moment(2, 2, ro, ri) == pytest.approx(s.I6, rel=1e-14)
    assert annulus_moment(1, 2, ro, ri) == 0.0


def test_linearisation_about_rest_is_M_C_K(disc):
    """Tangents of the energy-derived forces at U = V = A = 0 equal (44), (45), (46), to round-off."""
    p, dx = disc.properties, dx_of(disc)
    U, V, A = (fem.Function(disc.V) for _ in range(3))
    psi, dU = ufl.TestFunction(disc.V), ufl.TrialFunction(disc.V)
    pairs = [
        (ufl.derivative(inertial_force(p, psi, U, V, A, dx), A, dU), mass_form(p, psi, dU, dx)),
        (ufl.derivative(damping_force(p, psi, V, dx), V, dU), damping_form(p, psi, dU, dx)),
        (ufl.derivative(elastic_force(p, psi, U, dx), U, dU), stiffness_form(p, psi, dU, dx)),
    ]
    rng = np.random.default_rng(0)
    for derived, printed in pairs:
        Ad, Ap = matrix(derived), matrix(printed)
        x = Ad.createVecRight()
        for _ in range(3):
            x.array[:] = rng.standard_normal(disc.ndofs)
            yd, yp = Ad.createVecLeft(), Ap.createVecLeft()
            Ad.mult(x, yd)
            Ap.mult(x, yp)
            assert np.linalg.norm(yd.array - yp.array) <= 1e-12 * np.linalg.norm(yp.array)
    # no velocity-dependent (gyroscopic) stiffness at rest
    gyro = matrix(ufl.derivative(inertial_force(p, psi, U, V, A, dx), V, dU))
    assert gyro.norm() == 0.0


@pytest.mark.parametrize("variant", ["printed torsion", "tool joints"])
def test_stiffness_46_is_the_energys_tangent_in_each_torsion_and_with_homogenised_tool_joints(variant):
    """The strain energy's tangent at rest equals the stiffness (46) with the paper's torsion kappa_s G J
    (``model.torsion = 'printed'``) and on a string whose cells carry homogenised tool joints (the stiffness
    moments A, I4, I6 scaled per cell), to round-off; and (46)'s torsion is G J (St-Venant) or kappa_s G J."""
    if variant == "printed torsion":
        scene = scene_with("beam.length=3", "beam.elements=6", "model.torsion='printed'")
    else:
        joint = ('{length = 3.0, outer_radius = 0.0635, inner_radius = 0.0543, tool_joint_outer_radius = 0.0841, '
                 'tool_joint_inner_radius = 0.0413, tool_joint_length = 0.5, tool_joint_spacing = 9.4}')
        scene = scene_with("beam.elements=6", f"string.sections=[{joint}]", "well.md=[0.0, 3.0]",
                           "well.inclination=[90.0, 90.0]", "well.azimuth=[0.0, 0.0]")
    disc = BeamDiscretization.from_scene(scene)
    p, dx = disc.form_properties, dx_of(disc)
    U = fem.Function(disc.V)
    psi, dU = ufl.TestFunction(disc.V), ufl.TrialFunction(disc.V)
    Ad = matrix(ufl.derivative(elastic_force(p, psi, U, dx), U, dU))
    Ap = matrix(stiffness_form(p, psi, dU, dx))
    x = Ad.createVecRight()
    x.array[:] = np.random.default_rng(1).standard_normal(disc.ndofs)
    yd, yp = Ad.createVecLeft(), Ap.createVecLeft()
    Ad.mult(x, yd)
    Ap.mult(x, yp)
    assert np.linalg.norm(yd.array - yp.array) <= 1e-12 * np.linalg.norm(yp.array)
    numbers = disc.properties
    expected = (numbers.shear_factor if variant == "printed torsion" else numbers.inertia_stiffness_factor) * \
        numbers.shear_modulus * 2 * numbers.section.I4
    # the same product of floats in another order: round-off
    assert numbers.torsional_rigidity == pytest.approx(expected, rel=1e-14)
    if variant == "tool joints":
        assert numbers.inertia_stiffness_factor > 1.04  # the joints stiffen the pipe (4.7 %): the case tests something


@pytest.mark.parametrize("seed", [3, 11])
def test_printed_operators_match_energy_or_are_recorded_errata(disc, seed):
    """F_KE (48) equals the energy derivation term by term; every Gamma that does not is in
    docs/errata.md (PRINTED_ERRATA); no recorded erratum is stale."""
    rows = {row.term: row for row in compare_printed_forms(disc, seed=seed)}
    for name, row in rows.items():
        assert row.status in ("match", "recorded erratum"), (name, row.relative_difference)
    assert all(rows[t].matches for t in rows if t.startswith("F_KE"))
    assert rows["Gamma_1[theta_x]"].matches
    assert rows["F_SE[sign]"].relative_difference == pytest.approx(2.0, rel=1e-9)  # opposite sign exactly
    assert set(PRINTED_ERRATA) <= set(rows)


def test_rigid_motions_produce_no_elastic_force(disc):
    """theta_x = const (large) and u = const: zero strains, so zero elastic force."""
    p, dx = disc.properties, dx_of(disc)
    psi = ufl.TestFunction(disc.V)
    U = fem.Function(disc.V)
    K_scale = np.abs(vector(elastic_force(p, psi, random_state(disc, 1), dx))).max()
    for tx, u in ((1.3, 0.0), (0.0, 0.7), (-2.9, 0.2)):
        U.x.array[:] = 0.0
        U.x.array[disc.field_dofs[field.THETA_X]] = tx
        U.x.array[disc.field_dofs[field.U]] = u
        assert np.abs(vector(elastic_force(p, psi, U, dx))).max() <= 1e-12 * K_scale


def test_strain_energy_is_non_negative_element_by_element(disc):
    p, dx = disc.properties, dx_of(disc)
    dg0 = fem.functionspace(disc.mesh, basix.ufl.element("DG", "interval", 0))
    q = ufl.TestFunction(dg0)
    for seed in range(10):
        U = random_state(disc, 100 + seed, scale=0.2, rotation_scale=3.0)
        energies = vector(strain_energy_density(p, strain_slots(U)) * q * dx)
        assert energies.min() >= -1e-12 * np.abs(energies).max()
        assert energies.max() > 0


def test_taylor_second_order_for_the_full_residual(disc):
    """R(X + h dX) - R(X) - h J dX = O(h^2), J assembled from ufl.derivative w.r.t. U, V, A."""
    p, dx = disc.properties, dx_of(disc)
    psi, trial = ufl.TestFunction(disc.V), ufl.TrialFunction(disc.V)
    U, V, A = (random_state(disc, s, scale=0.05, rotation_scale=1.0) for s in (21, 22, 23))

    def residual():
        return inertial_force(p, psi, U, V, A, dx) + damping_force(p, psi, V, dx) + elastic_force(p, psi, U, dx)

    R = residual()
    jacobians = [matrix(ufl.derivative(R, X, trial)) for X in (U, V, A)]
    base = [X.x.array.copy() for X in (U, V, A)]
    rng = np.random.default_rng(5)
    directions = [0.05 * rng.standard_normal(disc.ndofs) for _ in range(3)]
    R0 = vector(R)
    JdX = np.zeros(disc.ndofs)
    for J, d in zip(jacobians, directions):
        x, y = J.createVecRight(), J.createVecLeft()
        x.array[:] = d
        J.mult(x, y)
        JdX += y.array
    steps = [2.0**-k for k in range(2, 7)]
    remainders = []
    for h in steps:
        for X, b, d in zip((U, V, A), base, directions):
            X.x.array[:] = b + h * d
        remainders.append(np.linalg.norm(vector(R) - R0 - h * JdX))
    for X, b in zip((U, V, A), base):
        X.x.array[:] = b
    rates = np.log2(np.array(remainders[:-1]) / np.array(remainders[1:]))
    assert rates == pytest.approx(2.0, abs=0.1)  # observed rate within 0.1 of 2


def test_cli_forms_check_passes_and_show_prints(capsys):
    from fenics_drill.cli import main

    assert main(["forms", "check", "--set", "beam.length=3"]) == 0
    out = capsys.readouterr().out
    assert "Gamma_7[dtheta_x]" in out and "UNRECORDED" not in out
    assert main(["forms", "show", "gravity"]) == 0
    assert "dx" in capsys.readouterr().out
    assert main(["forms", "show", "no_such_form"]) == 2


@pytest.mark.parametrize("kinematics", ["objective", "printed"])
def test_a_rigid_spin_leaves_the_strain_energy_of_a_bent_string_unchanged_only_when_objective(disc, kinematics):
    """Spinning a sagging string rigidly about its axis (theta_x += phi) cannot load it.  The
    objective kinematics keeps its strain energy to round-off; the printed (14) does not:
    its shear strains (35)-(36) turn v', w' with theta_x but not theta_y, theta_z."""
    p = disc.properties
    dx = dx_of(disc)
    bent = fem.Function(disc.V)
    x = disc.dof_coordinates
    L = p.length
    w = 1e-3 * np.sin(np.pi * x / L)  # a sag shape in z with its Euler-Bernoulli rotation
    bent.x.array[disc.field_dofs[field.W]] = w[disc.field_dofs[field.W]]
    bent.x.array[disc.field_dofs[field.THETA_Y]] = -(1e-3 * np.pi / L * np.cos(np.pi * x / L))[disc.field_dofs[field.THETA_Y]]
    energies = []
    for phi in (0.0, 0.7, np.pi / 2):
        spun = bent.copy()
        spun.x.array[disc.field_dofs[field.THETA_X]] += phi
        energies.append(fem.assemble_scalar(fem.form(
            strain_energy_density(p, strain_slots(spun), kinematics=kinematics) * dx)))
    spread = (max(energies) - min(energies)) / energies[0]
    if kinematics == "objective":
        assert spread < 1e-10
    else:
        assert spread > 1e2  # the spun string stores orders of magnitude more energy
