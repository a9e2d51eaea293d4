"""The finite-element string on a well's curved axis: the Bishop frame, the curved beam's statics against the rod
equations solved exactly, rigid motions of a curved string, the straight horizontal survey against the default
geometry, and the FE static state against the soft-string model on a build-and-hold well."""

from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg

from fenics_drill.model.discretization import THETA_X, THETA_Y, THETA_Z, U, V, W, BeamDiscretization
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.well import Survey, Trajectory
from fenics_drill.observables.torque_drag import string_profiles
from fenics_drill.scene import SceneError
from fenics_drill.studies.prepare import prepare
from fenics_drill.studies.modal_report import modal_report
from fenics_drill.studies.torque_drag import torque_drag_study

from tests.conftest import scene_with


def well(md, inclination, azimuth):
    """Overrides that give the scene these survey stations, the string hanging off bottom in them."""
    return (f"well.md={list(map(float, md))}", f"well.inclination={list(map(float, inclination))}",
            f"well.azimuth={list(map(float, azimuth))}", "drive.start='off_bottom'")


def test_bishop_frame_is_carried_without_twist_and_holds_the_curvature():
    """t' = k2 d2 + k3 d3, d2' = -k2 t, d3' = -k3 t (central differences, whose error is 1e-9 here) along a
    build-and-turn well, with (t, d2, d3) orthonormal and right-handed and d3 the high side at the top."""
    trajectory = Trajectory(Survey.of([0, 200, 500, 900, 1500], [0, 0, 40, 70, 90], [0, 30, 30, 80, 120]))
    s = np.linspace(1.0, 1499.0, 997)
    h = 1e-4
    f, plus, minus = (trajectory.bishop_frames(s + d) for d in (0.0, h, -h))
    derivative = {name: (getattr(plus, name) - getattr(minus, name)) / (2 * h) for name in ("t", "d2", "d3")}
    k2, k3 = f.k2[:, None], f.k3[:, None]
    assert np.abs(derivative["t"] - k2 * f.d2 - k3 * f.d3).max() < 1e-9
    assert np.abs(derivative["d2"] + k2 * f.t).max() < 1e-9
    assert np.abs(derivative["d3"] + k3 * f.t).max() < 1e-9
    assert np.abs(np.einsum("ij,ij->i", f.t, np.cross(f.d2, f.d3)) - 1.0).max() < 1e-12
    assert np.allclose(np.hypot(f.k2, f.k3), trajectory.curvature(s), rtol=1e-12, atol=1e-15)
    top = trajectory.bishop_frames([0.0])  # vertical: the high side the hole builds toward (azimuth 0: north)
    assert np.allclose(top.d3[0], [1.0, 0.0, 0.0]) and np.allclose(top.down()[0], [1.0, 0.0, 0.0])


def rigid_motion_residual(elements: int, curved: bool = True) -> float:
    """max |K r| / (max |K| max |r|) of a rigid motion r of a string on a 3D well, its components in the frame
    interpolated at the dofs (straight derivatives with ``curved`` False)."""
    scene = scene_with(*well([0, 40, 100, 160], [0, 20, 55, 80], [0, 10, 60, 100]), "beam.length=160.0",
                       f"beam.elements={elements}")
    disc = BeamDiscretization.from_scene(scene)
    frames = disc.trajectory.bishop_frames(disc.dof_coordinates)
    positions = disc.trajectory.positions(disc.dof_coordinates)
    rng = np.random.default_rng(1)
    translation, rotation = rng.standard_normal(3), 1e-3 * rng.standard_normal(3)
    vectors = {U: translation + np.cross(rotation, positions), THETA_X: np.broadcast_to(rotation, positions.shape)}
    rigid = np.zeros(disc.ndofs)
    for first, value in vectors.items():
        for f, axis in zip(range(first, first + 3), (frames.t, frames.d2, frames.d3)):
            at = disc.field_of_dof == f
            rigid[at] = np.einsum("ij,ij->i", value[at], axis[at])
    if not curved:
        disc = BeamDiscretization(replace(disc.properties, axis=None), disc.elements, disc.element_degree)
    stiffness = assemble_linear(disc).stiffness
    return np.abs(stiffness @ rigid).max() / (abs(stiffness).max() * np.abs(rigid).max())


def test_rigid_motions_of_a_curved_string_store_no_strain_energy():
    """K r -> 0 for a translation and a small rotation of the whole string in space, written in the frame of a
    3D well: the frame's turning in the derivatives (docs/wells.md) is what makes them strain-free.  What is left is
    the interpolation of the frame's trigonometric components by the elements' polynomials, which falls by 16 per
    halving (measured 2.4e-8, 1.5e-9, 1.5e-10 at 80, 160, 320 elements): at least 8 asked.  The straight axis'
    derivatives strain the same motion at O(curvature), above 1e-4."""
    coarse, fine = rigid_motion_residual(80), rigid_motion_residual(160)
    assert fine < 1e-8 and coarse / fine > 8.0
    assert rigid_motion_residual(80, curved=False) > 1e-4


def rod_solution(trajectory, s_out, properties, weight_per_length):
    """Displacements (u, v, w) at ``s_out`` and the top's axial reaction of a linear Timoshenko rod on one
    circular arc of the well (constant curvature (k2, k3) in the Bishop frame) under its weight, held at the top
    (u, v, w and the three rotations) and at the bottom laterally (v = w = 0, no axial force or moment).

    The rod equations in the frame, independent of the energy the FE model derives its forces from:
    n' + f = 0, m' + t x n = 0 with n = N t + Q2 d2 + Q3 d3, m = Mt t + M2 d2 + M3 d3, and the strains
    N/EA = u' - k2 v - k3 w, Q2/kGA = v' + k2 u - theta_z, Q3/kGA = w' + k3 u + theta_y,
    Mt/GJ = theta_x' - k2 theta_y - k3 theta_z, M2/EI = theta_y' + k2 theta_x, M3/EI = theta_z' + k3 theta_x;
    the weight f = w (down_t, down_2, down_3) turns with the frame.  Constant coefficients: y(s) = exp(A s) y(0),
    the six forces and moments at the top found from the six conditions at the bottom."""
    p = properties
    ea, ei = p.young_modulus * p.section.area, p.young_modulus * p.section.I4
    kga, gj = p.shear_factor * p.shear_modulus * p.section.area, 2 * p.shear_modulus * p.section.I4  # St-Venant
    top = trajectory.bishop_frames([0.0])
    k2, k3 = float(top.k2[0]), float(top.k3[0])
    u, v, w, tx, ty, tz, n, q2, q3, mt, m2, m3, gt, g2, g3 = range(15)
    a = np.zeros((15, 15))
    rows = {
        u: {n: 1 / ea, v: k2, w: k3}, v: {q2: 1 / kga, u: -k2, tz: 1.0}, w: {q3: 1 / kga, u: -k3, ty: -1.0},
        tx: {mt: 1 / gj, ty: k2, tz: k3}, ty: {m2: 1 / ei, tx: -k2}, tz: {m3: 1 / ei, tx: -k3},
        n: {q2: k2, q3: k3, gt: -1.0}, q2: {n: -k2, g2: -1.0}, q3: {n: -k3, g3: -1.0},
        mt: {m2: k2, m3: k3}, m2: {mt: -k2, q3: 1.0}, m3: {mt: -k3, q2: -1.0},
        gt: {g2: k2, g3: k3}, g2: {gt: -k2}, g3: {gt: -k3},
    }
    for row, entries in rows.items():
        for column, value in entries.items():
            a[row, column] = value
    start = np.zeros(15)
    start[gt:] = weight_per_length * top.down()[0]
    unknown = [n, q2, q3, mt, m2, m3]
    bottom = [v, w, n, mt, m2, m3]
    end = scipy.linalg.expm(a * s_out[-1])
    forces = np.linalg.solve(end[np.ix_(bottom, unknown)], -end[bottom] @ start)
    start[unknown] = forces
    states = np.array([scipy.linalg.expm(a * s) @ start for s in s_out])
    return states[:, [u, v, w]], forces[0]


def fe_displacements(stations, elements):
    """(u, v, w) at the vertices of the FE static state of a 30 m pipe on the survey ``stations`` (no wall, linear
    strains), its vertices, properties, trajectory and hook load."""
    scene = scene_with(*well(*stations), "beam.length=30.0", f"beam.elements={elements}", "model.contact=false",
                       "model.geometric_nonlinearity=false", "reduction.rule='none'")
    prepared = prepare(scene, dynamics=False)
    full, disc = prepared.model.space.expand(prepared.equilibrium.q), prepared.model.disc
    return (np.stack([full[disc.vertex_dofs(f)] for f in (U, V, W)], axis=1), disc, prepared.static["hook_load"])


@pytest.mark.parametrize("stations", [
    ([0.0, 30.0], [90.0, 90.0], [0.0, 6.0]),  # a horizontal turn: the weight bends and twists it out of its plane
    ([0.0, 30.0], [30.0, 60.0], [0.0, 0.0]),  # a build: the weight pulls along it and bends it in its plane
], ids=["turn", "build"])
def test_static_sag_of_a_stiff_pipe_in_a_curved_hole_converges_to_the_curved_rod_solution(stations):
    """The FE static state of a 30 m pipe on one arc of constant curvature against the rod equations solved exactly
    (:func:`rod_solution`): the displacements converge at second order (the rotations are linear: the error falls
    by 4 from 60 to 120 elements, within 10 %), within 2e-4 of the largest at 120 elements; so does the top's
    axial reaction, within 1e-6 of the weight at 120."""
    errors, hook_errors = [], []
    for elements in (60, 120):
        fe, disc, hook_load = fe_displacements(stations, elements)
        p = disc.properties
        weight = p.density * p.section.area * p.gravity * p.length
        reference, top_reaction = rod_solution(disc.trajectory, disc.vertex_x, p, weight / p.length)
        largest = np.abs(reference).max()
        errors.append(np.abs(fe - reference).max() / largest)
        hook_errors.append(abs(hook_load - top_reaction) / weight)
    assert largest > 0.1  # a sag to measure: the turn 0.76 m, the build 0.45 m
    assert errors[1] < 2e-4
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.1)
    # the weight's direction is interpolated linearly between vertices: its error falls at second order too
    assert hook_errors[1] < 1e-6 and hook_errors[1] <= max(hook_errors[0] / 3.5, 1e-12)


@pytest.mark.parametrize("state", ["unloaded", "static"])
def test_a_straight_horizontal_survey_is_the_default_geometry_to_round_off(state):
    """The paper's hole given as a survey (inclination 90 deg, azimuth 0): the same static state on the wall and
    the same modes as the default straight hole, to round-off (the frame's 6e-17 of cos 90 deg is the only
    difference in the operators), whether the modes are the unloaded string's or linearised about the static state
    on the wall (with its wall springs, in every spectrum)."""
    base = ("beam.length=40.0", "beam.elements=80", "reduction.rule='none'", f"modal.state='{state}'")
    states, frequencies = [], []
    for extra in ((), well([0, 40], [90, 90], [0, 0])):
        scene = scene_with(*base, *extra)
        prepared = prepare(scene, dynamics=False)
        states.append(prepared.model.space.expand(prepared.equilibrium.q))
        report = modal_report(scene)
        assert report["linearised_about"]["state"] == state
        frequencies.append([m["frequency_hz"] for spectrum in report["spectra"].values() for m in spectrum["modes"]])
    assert np.abs(states[1] - states[0]).max() <= 1e-9 * np.abs(states[0]).max()
    assert np.allclose(frequencies[1], frequencies[0], rtol=1e-9, atol=0)


@pytest.mark.parametrize("mud", [0.0, 1200.0])
def test_fe_string_hanging_in_a_vertical_hole_carries_its_buoyed_weight_and_stretches(mud):
    """A 100 m string hanging in a vertical hole: hook load w L with w the buoyed weight per length (1e-9: axial
    equilibrium), no wall force, and in air the stretch w L^2 / (2 E A) (1e-4: the Green-Lagrange strain's
    u'^2 / 2 at u' <= 4e-5).  (In mud the FE stretch is that of the effective tension; the true tension's
    Poisson term is in the soft string's stretch, docs/wells.md.)"""
    scene = scene_with(*well([0, 100], [0, 0], [0, 0]), "beam.length=100.0", "beam.elements=100",
                       f"fluid.density={mud}")
    prepared = prepare(scene, dynamics=False)
    model, disc = prepared.model, prepared.model.disc
    p = disc.properties
    weight = p.density * p.section.area * scene.environment.gravity * scene.buoyancy_factor
    assert prepared.static["hook_load"] == pytest.approx(weight * p.length, rel=1e-9)
    assert prepared.static.get("contact_force_total", 0.0) == 0.0
    if mud == 0.0:
        stretch = model.space.expand(prepared.equilibrium.q)[disc.end_dof(U, 1)]
        assert stretch == pytest.approx(weight * p.length**2 / (2 * p.young_modulus * p.section.area), rel=1e-4)


@pytest.mark.parametrize("inclination", [30.0, 60.0])
def test_fe_string_in_a_straight_inclined_hole_lies_on_the_low_side(inclination):
    """A 100 m string in a straight hole at inclination I: it lies on the low side with the wall's force per length
    w sin I (away from the end supports, where the pipe's bending spreads the supports' reactions: within 1e-6,
    measured 8e-8), and the top holds w L cos I (no friction at rest, the wall's force normal to the axis: 1e-9,
    measured 2e-15)."""
    scene = scene_with(*well([0, 100], [inclination] * 2, [0, 0]), "beam.length=100.0", "beam.elements=200")
    prepared = prepare(scene, dynamics=False)
    model, disc = prepared.model, prepared.model.disc
    p = disc.properties
    w = p.density * p.section.area * p.gravity
    wall = model.force("wall").evaluate(prepared.equilibrium.q, np.zeros_like(prepared.equilibrium.q))
    x = disc.vertex_x[wall.in_contact]
    per_length = -np.asarray(wall.normal) / np.diff(disc.vertex_x)[0]
    inside = (x > 20.0) & (x < 80.0)
    assert inside.sum() > 100
    assert np.allclose(per_length[inside], w * np.sin(np.radians(inclination)), rtol=1e-6)
    _, w_low = (rows @ prepared.equilibrium.q for rows in model.lateral_rows)
    assert np.all(w_low[(disc.vertex_x > 20.0) & (disc.vertex_x < 80.0)] < -model.gap)  # the low side: -d3
    assert prepared.static["hook_load"] == pytest.approx(w * p.length * np.cos(np.radians(inclination)),
                                                         abs=1e-9 * w * p.length)


def test_fe_static_state_on_a_build_and_hold_well_matches_the_soft_string():
    """A 250 m string (vertical to 50 m, built to 60 deg at 18 deg/30 m, held) resting on the wall: the FE static
    state against the soft string off bottom (no axial slip, so no axial friction).  The stiff string carries its
    weight as the cable does but for its bending: the hook load within 1e-4 (measured 2.1e-5).  Where it lies along
    one side of the hole the wall's force per length is the cable's: on the build, pressed to the high side by its
    tension (T kappa - w sin I), within 1e-3 (measured 3.0e-4, the cable's 0.5 m elements); on the hold, on the low
    side (w sin I), within 1e-3 (measured 1.3e-7).  Where it crosses the hole (at 120 m, where T kappa = w sin I)
    and near the bit's support the stiffness matters and the two differ, as they should."""
    survey = well([0, 50, 150, 250], [0, 0, 60, 60], [0, 0, 0, 0])
    scene = scene_with(*survey, "beam.length=250.0", "beam.elements=500", "torque_drag.element_length=0.5")
    prepared = prepare(scene, dynamics=False)
    model = prepared.model
    wall = model.force("wall").evaluate(prepared.equilibrium.q, np.zeros_like(prepared.equilibrium.q))
    x = model.disc.vertex_x[wall.in_contact]
    fe = -np.asarray(wall.normal) / np.diff(model.disc.vertex_x)[0]  # the vertices' share of the wall: 0.5 m
    soft = torque_drag_study(scene)
    hook = soft["report"]["operations"]["rotating_off_bottom"]["hook_load_N"]
    assert abs(prepared.static["hook_load"] - hook) < 1e-4 * hook
    profiles = soft["profiles"]
    cable = np.interp(x, profiles["md_element"].values,
                      profiles["wall_force_per_length_rotating_off_bottom"].values)
    for a, b in ((60.0, 105.0), (160.0, 230.0)):
        on = (x > a) & (x < b)
        assert on.sum() > 80  # the string lies along the wall there, vertex after vertex
        assert np.abs(fe[on] / cable[on] - 1.0).max() < 1e-3, (a, b)
    # the axial force along the string, read off the state as a run writes it, is the cable's tension: within 1e-3
    # down to the build's middle (measured 2.7e-4), 1e-6 on the hold (6e-9); without the frame's turning in u'
    # (straight derivatives) it would be off by 500 %
    disc, dofs = model.disc, model.space.expand(prepared.equilibrium.q)
    fields = [dofs[disc.vertex_dofs(f)] for f in (U, V, W, THETA_X, THETA_Y, THETA_Z)]
    force = string_profiles(disc.vertex_x, *fields[:4], disc.properties, model.gap, 1.0, 0.0, *fields[4:],
                            disc.element_curvature)["axial_force"]
    middle = 0.5 * (disc.vertex_x[1:] + disc.vertex_x[:-1])
    tension = np.interp(middle, profiles["md"].values, profiles["tension_rotating_off_bottom"].values)
    for (a, b), tolerance in (((5.0, 105.0), 1e-3), ((160.0, 240.0), 1e-6)):
        on = (middle > a) & (middle < b)
        assert np.abs(force[on] / tension[on] - 1.0).max() < tolerance, (a, b)


def test_a_section_wider_than_its_hole_is_refused_by_the_fe_model():
    scene = scene_with(*well([0, 100], [90, 90], [0, 0]), "well.hole_bottom=[50.0, 100.0]",
                       "well.hole_radius=[0.1, 0.07]", "beam.length=100.0")
    with pytest.raises(SceneError, match="does not fit the hole of radius 0.07 m at md = 5"):
        BeamDiscretization.from_scene(scene)


def test_a_string_spinning_in_a_curved_hole_stores_a_bounded_bending_energy():
    """The section spun by theta_x about the axis' tangent sees the axis' curvature k turned by theta_x: a uniform
    spin of the stress-free curved string bends it by 2 k sin(theta_x / 2), bounded and periodic, so the strain
    energy is EI k^2 L (1 - cos theta_x) = 2 EI k^2 L sin^2(theta_x / 2) (exact for a uniform field).  The
    linearised coupling k theta_x grew as theta_x^2: a string spun for 5 s (31 rad) in a 4.5 deg/30 m build wound
    up a spurious 30 kN m there."""
    import ufl
    from dolfinx import fem

    from fenics_drill.forms.energies import strain_energy_density, strain_slots

    scene = scene_with(*well([0, 30], [30, 34.5], [0, 0]), "beam.length=30.0", "beam.elements=30")
    disc = BeamDiscretization.from_scene(scene)
    p = disc.form_properties
    state = fem.Function(disc.V)
    dx = ufl.Measure("dx", domain=disc.mesh)
    energy = fem.form(strain_energy_density(p, strain_slots(state, p.axis, True), True) * dx)
    k = float(disc.trajectory.curvature([15.0])[0])
    bending = disc.properties.young_modulus * disc.properties.section.I4
    for spin in (np.pi / 3, np.pi, 2 * np.pi, 10 * np.pi + 1.0):
        state.x.array[:] = 0.0
        state.x.array[disc.field_dofs[THETA_X]] = spin
        stored = fem.assemble_scalar(energy)
        # the Green-Lagrange strains add terms of order (k r)^2 ~ 1e-8 relative to the bending: 1e-6; at a whole
        # number of turns the energy is round-off of EI k^2 L times sin(2 pi n)^2, hence the absolute 1e-9
        assert stored == pytest.approx(bending * k**2 * 30.0 * (1 - np.cos(spin)), rel=1e-6, abs=1e-9 * bending * k**2)
