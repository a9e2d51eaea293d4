"""The lateral fields solved only where the scene needs them (``model.lateral_length``): above that length the string
lies on the well's axis and the wall acts through its friction on the axial and torsional motion alone."""

import math

import numpy as np
import pytest
from dolfinx import fem

from axial_torsional_references import steady_rotation_references
from string_references import rod_frequencies
from test_modes_in_the_well import COLLAR, HEAVY_WEIGHT, PIPE, G, RHO, segments, vertical_string

import fenics_drill as fd
from fenics_drill.cli import main
from fenics_drill.model.discretization import DRIVE, THETA_X, THETA_Y, THETA_Z, V, W, BeamDiscretization
from fenics_drill.model.internal_force import AssembledInternalForce, LateralZoneInternalForce, internal_force
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.reduction.spaces import FullSpace
from fenics_drill.model.reduction.modes import solve_modes
from fenics_drill.studies.prepare import prepare


def test_the_lateral_fields_are_held_above_the_lateral_length():
    """On the 900 m build-and-hold demo well with 60 m of lateral length: every v, w, theta_y, theta_z above 840 m
    and v, w at 840 m are held (the lateral part pinned on the axis at its top, its tilt free there); none below.
    0 holds them all; -1 none but the supports."""
    scene = fd.load_scene("demos/scenes/well_build_hold.toml", ["beam.elements=100", "model.lateral_length=60.0"])
    disc = BeamDiscretization.from_scene(scene)
    assert disc.lateral_top == pytest.approx(840.0)
    held = set(disc.support_dofs.tolist())
    for field in (V, W, THETA_Y, THETA_Z):
        dofs = disc.field_dofs[field]
        x = disc.dof_coordinates[dofs]
        above = x < 840.0 - 1e-6
        assert all(int(d) in held for d in dofs[above])
        below = (x > 840.0 + 1e-6) & (x < 900.0 - 1e-6)
        assert not any(int(d) in held for d in dofs[below])
        at_top = dofs[np.abs(x - 840.0) < 1e-6]
        assert all((int(d) in held) == (field in (V, W)) for d in at_top)
    none = BeamDiscretization.from_scene(scene.with_changes(model={"lateral_length": 0.0}))
    lateral = np.concatenate([none.field_dofs[f] for f in (V, W, THETA_Y, THETA_Z)])
    assert set(lateral.tolist()) <= set(none.support_dofs.tolist())
    whole = BeamDiscretization.from_scene(scene.with_changes(model={"lateral_length": -1.0}))
    assert whole.support_dofs.size == 6  # the supports of model.supports = 'paper'


@pytest.mark.parametrize("lateral_length, kinematics", [(60.0, "objective"), (60.0, "printed"), (0.0, "objective")])
def test_the_split_strings_internal_force_is_the_whole_forms_to_round_off(lateral_length, kinematics):
    """Above the lateral length the full order assembles the energies of u and theta_x alone (the forms with the
    lateral fields and tests set to zero) and the whole forms below: at random states of the build-and-hold well's
    full space (lateral dofs held where the length says) the force, its three tangent parts and both energies are
    those of the whole forms over every element, to 1e-12 of their size (round-off: the same terms, summed per
    element in another order; measured 0 on the force and the parts).  Both kinematics, whose strains differ in
    their nonlinear terms."""
    scene = fd.load_scene("demos/scenes/well_build_hold.toml", [
        "beam.elements=100", f"model.lateral_length={lateral_length}", f"model.kinematics='{kinematics}'"])
    disc = BeamDiscretization.from_scene(scene)
    operators, space = assemble_linear(disc), FullSpace(disc)
    split = internal_force(disc, space, operators, scene.model)
    zone, above = LateralZoneInternalForce.cells_of(disc, space)
    assert above.size > 0 and (zone.size > 0) == (lateral_length > 0)
    assert isinstance(split, LateralZoneInternalForce if lateral_length > 0 else AssembledInternalForce)
    m = scene.model
    whole = AssembledInternalForce(disc, space, operators, m.geometric_nonlinearity, m.inertial_nonlinearity,
                                   m.kinematics, m.angular_velocity)
    rng = np.random.default_rng(3)
    for size in (1e-3, 0.3):  # a drilling state's size and one where every nonlinear term counts
        q, qd, qdd = (size * rng.standard_normal(space.size) for _ in range(3))
        expected, got = whole.evaluate(q, qd, qdd), split.evaluate(q, qd, qdd)
        assert np.abs(got - expected).max() <= 1e-12 * np.abs(expected).max()
        for a, b in zip(whole.tangent_parts(), split.tangent_parts()):
            a, b = a.tocsr(), b.tocsr()
            assert abs(b - a).max() <= 1e-12 * abs(a).max()
        for a, b in zip(whole.energies(q[None], qd[None]), split.energies(q[None], qd[None])):
            assert b[0] == pytest.approx(a[0], rel=1e-12)  # the same cells' sums in two parts: round-off
        # and the energies, read from the cells' kernels with the coefficients taken off the state, are DOLFINx's
        # assembly of the forms with the functions set to it.  Round-off only: the same FFCx kernels, their 100 cells
        # summed in another order (reassociated); measured 0-7e-16, and 1e-12 is 100 cells x 1e-14 of margin, far
        # below any error a wrong coefficient or cell would make (order one)
        whole.U.x.array[:], whole.V.x.array[:] = space.expand(q), space.expand(qd)
        kinetic, strain = (fem.assemble_scalar(form) for form in (whole._kinetic, whole._strain))
        assert whole.kinetic_energy(q, qd) == pytest.approx(kinetic, rel=1e-12)
        assert whole.strain_energy(q) == pytest.approx(strain, rel=1e-12)


@pytest.mark.parametrize("value, words", [("2000.0", "must be <= the string's length"),
                                          ("-5.0", "model.lateral_length = -5.0 is not admissible")])
def test_a_lateral_length_beyond_the_string_or_negative_is_refused(capsys, value, words):
    assert main(["scene", "demos/scenes/well_build_hold.toml", "--set", f"model.lateral_length={value}"]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1, err


def test_the_wall_friction_of_an_axial_torsional_pipe_turning_on_the_wall_is_mu_w_l_r():
    """The paper's 100 m horizontal pipe, axial-torsional, turned at 60 rpm off bottom: once steady, the drive's
    torque is the wall's Coulomb torque, mu w L R_ext (the normal force per length is the weight w in a straight
    horizontal hole), plus the viscous damping (38) of the turning pipe, c rho I_p Omega L (with c = 2 /s, 22 % of
    it, and the torsional oscillation damped within the run).  Mean over the last 0.5 s of 1.5 s within 1e-3
    (measured 2.3e-4: the oscillation's residue)."""
    scene = fd.load_scene(None, ["model.lateral_length=0.0", "model.bit_rock=false", "time.t_end=1.5",
                                 "output.field_interval=0", "beam.elements=100", "contact.friction=0.25",
                                 "beam.damping=2.0"])
    run = fd.run(scene)
    t, torque = run.series["time"].values, -run.series["lambda_4"].values
    late = t > 1.0
    p = scene.beam_properties
    weight = p.density * p.section.area * p.gravity
    polar = math.pi / 2 * (p.outer_radius**4 - p.inner_radius**4)
    expected = (scene.contact.friction * weight * p.length * p.outer_radius
                + p.damping * p.density * polar * scene.drive.rotation_speed * p.length)
    assert np.trapezoid(torque[late], t[late]) / (t[late][-1] - t[late][0]) == pytest.approx(expected, rel=1e-3)
    assert np.all(run.series["section_v"].values == 0.0)


@pytest.mark.parametrize("space", ["full", "modal"])
def test_the_axial_torsional_walls_tangent_is_the_derivative_of_its_force(space):
    """The 900 m build-and-hold well's axial-torsional wall (its 60 m split, in the full space; the axial-torsional
    string, modal) anchored at a state, then moved by slips of 1e-9 to 1e-4 m per vertex, so that some contacts stay
    stuck (F = F* = -k_t g) and others slide on the cone (F = mu N F*/|F*|).  Its tangent c_u dF/dq, in the full
    space (entries laid into the band) and in the modal one (dense), against central differences of its generalised
    force: within 1e-6 of the largest entry (measured 4e-9 and 7e-8; h = 1e-12 m moves a trial force by 1e-4 N, far
    from the cone at the contacts checked, and its round-off in a force of 1e2-1e3 N is 1e-13 / 1e-12 of it)."""
    lateral_length = 60.0 if space == "full" else 0.0  # a split runs in the full space; the string at 0 is modal
    scene = fd.load_scene("demos/scenes/well_build_hold.toml", ["beam.elements=100",
                                                                 f"model.lateral_length={lateral_length}"])
    model = prepare(scene, dynamics=False).model
    assert model.space.sparse == (space == "full")
    wall = model.force("axial_torsional_wall").fresh()
    rng = np.random.default_rng(11)
    q0 = 1e-3 * rng.standard_normal(model.size)
    wall.begin(0.0, q0)
    n = wall.vertices.size
    slips = rng.standard_normal(2 * n) * 10.0 ** rng.uniform(-9, -4, 2 * n)
    rows = wall.rows.dense()  # a modal space reaches the slips it can: both branches still occur (asserted below)
    q = q0 + (wall.rows.spread(slips) if space == "full" else np.linalg.lstsq(rows, slips, rcond=None)[0])
    forces = wall.evaluate(q, np.zeros_like(q))
    cap = wall.friction * np.abs(wall.normal)
    sliding = forces.trial > cap
    assert 0 < np.count_nonzero(sliding) < n  # both branches are checked
    c_u = 1.7
    tangent = wall.tangent(forces, c_u, 0.0)
    tangent = tangent.toarray() if hasattr(tangent, "toarray") else tangent
    h = 1e-12
    numeric = np.empty((model.size, model.size))
    for j in range(model.size):
        up, down = q.copy(), q.copy()
        up[j] += h
        down[j] -= h
        change = wall.evaluate(up, 0 * up).generalised - wall.evaluate(down, 0 * down).generalised
        numeric[:, j] = c_u * change / (2 * h)
    assert np.abs(numeric).max() > 0
    assert np.abs(tangent - numeric).max() <= 1e-6 * np.abs(numeric).max()


@pytest.mark.parametrize("held", ["free-free", "drive-held", "bit stuck"])
def test_the_axial_torsional_strings_modes_are_the_transfer_matrix_roots(held):
    """``model.lateral_length = 0`` leaves the string its axial and torsional waves alone: collar, heavy-weight and
    drill pipe (500 m) hanging in a vertical well, their first three axial and torsional frequencies against the
    exact roots of the composite rod's transfer matrix (:mod:`string_references`), free at both ends, held by the
    drive at the top, or held there with the bit stuck (theta_x held at the bit).  Within 1e-4, the discretisation
    error of 1000 elements (test_modes_in_the_well: theta_x linear, (kh)^2 / 24 <= 1.1e-5 for the third mode)."""
    sections = [COLLAR, HEAVY_WEIGHT, PIPE]
    disc = BeamDiscretization.from_scene(vertical_string(sections, 1000, "model.lateral_length=0.0"))
    ends = {"free-free": (), "drive-held": DRIVE, "bit stuck": (*DRIVE, (THETA_X, 1))}[held]
    basis = solve_modes(disc, 2.0, assemble_linear(disc).mass, held=ends, vectors=False)
    assert set(basis.kinds) <= {"axial", "torsional", "rigid"}, set(basis.kinds)  # no lateral mode is left
    top = "free" if held == "free-free" else "held"
    for kind in ("axial", "torsional"):
        fe = basis.frequencies_hz[np.array(basis.kinds) == kind][:3]
        bottom = "held" if (held == "bit stuck" and kind == "torsional") else "free"
        exact = rod_frequencies(segments(sections, kind), top, bottom, 3, 1.2 * fe[-1])
        np.testing.assert_allclose(fe, exact, rtol=1e-4, err_msg=kind)


@pytest.mark.parametrize("normal_force, pressed_for", [("static", None), ("dynamic", 150e3)])
def test_a_steadily_rotating_axial_torsional_string_on_bottom_carries_the_soft_strings_hook_load_and_torque(
        normal_force, pressed_for):
    """:func:`~axial_torsional_references.steady_rotation_references` on ``fenics-drill run``: the hook load and the
    surface torque each within 2 % of the soft string's (measured 0.14 % and 0.4 %: the FE wall acts at the vertices
    of 10 m elements, the soft string's at 2 m, and the torsional oscillation's residue).  With the wall pressed by
    the string's own tension, started from the static state at 150 kN on the bit, carrying about 17 kN: the same
    (measured 0.10 % and 0.06 %; the wall held at the soft string's normal force for 150 kN gives 9 % less torque)."""
    def means_of(scene):
        run = fd.run(scene)
        assert run.summary["status"] == "finished"
        scope = run.summary["discretisation"]["lateral"]  # what the run solves and leaves out, stated
        assert scope["lateral_length_m"] == 0.0 and scope["wall_normal_force"] == normal_force
        s = run.series
        t = s["time"].values
        late = t > 4.0

        def mean(name):
            return float(np.trapezoid(s[name].values[late], t[late]) / (t[late][-1] - t[late][0]))

        return {"hook_load": mean("lambda_1"), "surface_torque": -mean("lambda_4"),
                "weight_on_bit": -mean("bit_force"), "bit_torque": -mean("bit_torque"), "rop": mean("bit_velocity"),
                "spin": s["bit_angular_velocity"].values[late]}

    _, means, (hook, torque) = steady_rotation_references(means_of, normal_force, pressed_for)
    assert means["hook_load"] == pytest.approx(hook, rel=0.02)
    assert means["surface_torque"] == pytest.approx(torque, rel=0.02)


def test_the_bha_split_drills_the_build_and_hold_well_as_the_whole_string_does_over_2_s(tmp_path):
    """2 s of the 900 m build-and-hold demo well drilled on bottom at 240 rpm (200 elements, the ten times softer wall
    of the guide's "What the split costs" in both), the lateral fields over the whole string and over the bottom
    150 m (collars and heavy-weight pipe): the means over the second second, the spin-up from rest to the drive's speed
    and its overshoot.

    The split changes only how the drill pipe above the BHA meets the wall: its normal force is the soft string's
    static one, where the whole string's pipe moves on the wall (it climbs, rolls and strikes it), which moves its mean
    normal force and so the friction torque mu R N; over a steady second (1.5-3 s at 500 elements,
    benchmarks/results/bha_split_steady.md) the surface torques differ by 0.3 %, over this spin-up by 2.1 %:
    3 %. The weight on bit is the drawworks' hook load less the axial friction, which rotation takes away (axial share
    rop / (R omega) ~ 1e-5): 1 % (measured 0.7 %). The bit's mean spin differs by the twist that torque difference
    winds into the pipe: 2 % (measured 1.3 %). The cutting law's rop follows the spin and the depth of cut: 3 %
    (measured 0.2 %)."""
    scene = fd.load_scene("demos/scenes/well_build_hold.toml",
                          ["beam.elements=200", "drive.rotation_speed='240 rpm'", "time.t_end=2.0",
                           "output.field_interval=0", "output.von_mises=false", "contact.stiffness_linear=1e9",
                           "contact.stiffness_cubic=1e13", "contact.damping=1e3"])

    def means_of(length):
        run = fd.run(scene.with_changes(model={"lateral_length": length}), out=tmp_path / f"split-{length:g}")
        assert run.summary["status"] in ("finished", "suspect"), run.summary["message"]
        s = run.series
        t = s["time"].values
        late = t >= 1.0

        def mean(name):
            return float(np.trapezoid(s[name].values[late], t[late]) / (t[late][-1] - t[late][0]))

        return {"surface_torque": -mean("lambda_4"), "weight_on_bit": -mean("bit_force"),
                "spin": mean("bit_angular_velocity"), "rop": mean("bit_velocity")}

    whole, split = means_of(-1.0), means_of(150.0)
    assert split["surface_torque"] == pytest.approx(whole["surface_torque"], rel=0.03)
    assert split["weight_on_bit"] == pytest.approx(whole["weight_on_bit"], rel=0.01)
    assert split["spin"] == pytest.approx(whole["spin"], rel=0.02)
    assert split["rop"] == pytest.approx(whole["rop"], rel=0.03)


def test_the_elements_above_the_lateral_length_take_their_own_length():
    """``model.axial_torsional_element_length``: on the build-and-hold well with 150 m of lateral length and 900
    elements (1 m), the vertices below the lateral length's top stay 1 m apart, those above are at most 10 m apart and
    still fall on every section end and survey station; -1 leaves the mesh as it was; with the whole string's
    lateral fields it is refused.  'auto' (0, the default) is 10 m, or the lateral part's elements where those are
    longer (60 elements: 15 m); over a whole axial-torsional string (``model.lateral_length = 0``) it keeps
    ``beam.elements``."""
    scene = fd.load_scene("demos/scenes/well_build_hold.toml", ["beam.elements=900", "model.lateral_length=150.0"])
    fine = BeamDiscretization.from_scene(scene.with_changes(model={"axial_torsional_element_length": -1.0})).vertex_x
    graded = BeamDiscretization.from_scene(scene.with_changes(model={"axial_torsional_element_length": 10.0})).vertex_x
    np.testing.assert_array_equal(BeamDiscretization.from_scene(scene).vertex_x, graded)
    assert np.diff(fine).max() <= 1.0 + 1e-9
    np.testing.assert_array_equal(graded[graded >= 750.0], fine[fine >= 750.0])
    above = graded[graded <= 750.0]
    assert np.diff(above).max() <= 10.0 + 1e-9 and above.size < 80
    stations = np.loadtxt("demos/scenes/well_build_hold_survey.csv", delimiter=",", skiprows=3)[:, 0]
    for x in [*stations[stations <= 750.0], 0.0, 750.0]:  # the stations above, the top of the drill pipe and the string
        assert np.min(np.abs(above - x)) < 1e-9
    assert main(["scene", "demos/scenes/well_build_hold.toml", "--set", "model.axial_torsional_element_length=10"]) == 2
    for kept in (scene.with_changes(beam={"elements": 60}), scene.with_changes(model={"lateral_length": 0.0})):
        np.testing.assert_array_equal(
            BeamDiscretization.from_scene(kept).vertex_x,
            BeamDiscretization.from_scene(kept.with_changes(model={"axial_torsional_element_length": -1.0})).vertex_x)


def test_coarse_axial_torsional_elements_keep_the_strings_modes_within_their_discretisation_error():
    """The axial-torsional string of the modes test (500 m: collar, heavy-weight and drill pipe hanging in a vertical
    well, drive-held) meshed with 10 m elements: its first three axial and torsional frequencies against the exact
    roots of the composite rod, within the discretisation error of the linear theta_x at h = 10 m: the dispersion of
    linear elements with a consistent mass on a uniform rod, omega_h = (c / h) sqrt(6 (1 - cos kh) / (2 + cos kh))
    (about (kh)^2 / 24), at the third torsional mode, with 1 % for the sections' joins (u is quadratic: far smaller);
    and no closer than half of it, so that the test sees the coarse mesh at all."""
    sections = [COLLAR, HEAVY_WEIGHT, PIPE]
    scene = vertical_string(sections, 1000, "model.lateral_length=0.0", "model.axial_torsional_element_length=10.0")
    disc = BeamDiscretization.from_scene(scene)
    assert np.diff(disc.vertex_x).max() <= 10.0 + 1e-9
    basis = solve_modes(disc, 2.0, assemble_linear(disc).mass, held=DRIVE, vectors=False)
    errors = {}
    for kind in ("axial", "torsional"):
        fe = basis.frequencies_hz[np.array(basis.kinds) == kind][:3]
        exact = rod_frequencies(segments(sections, kind), "held", "free", 3, 1.2 * fe[-1])
        errors[kind] = np.abs(fe / exact - 1.0)
        if kind == "torsional":
            wave_speed = math.sqrt(G / RHO)
            kh = 2 * math.pi * exact[-1] / wave_speed * 10.0
            bound = 1.01 * (math.sqrt(6 * (1 - math.cos(kh)) / (2 + math.cos(kh))) / kh - 1.0)
    assert errors["torsional"].max() <= bound
    assert errors["torsional"].max() >= 0.5 * bound
    assert errors["axial"].max() <= bound


def test_the_wall_pressed_by_the_strings_tension_is_the_soft_strings_at_its_static_state():
    """``contact.normal_force = 'dynamic'`` (:class:`~fenics_drill.model.forces.axial_torsional_wall.TensionPress`):
    in the straight hole at 60 deg of demos/scenes/off_bottom_side_by_side.toml each vertex is pressed by its half
    elements' weight across the axis, whatever the tension (the soft string's w h sin 60 deg; to round-off, 1e-12).
    On the build-and-hold demo well, at the static state on bottom, the normal forces of the string's own tension sum
    to the soft string's within 0.5 % (measured 0.17 % on 90 elements, 0.002 % on 200): this form turns the tension
    where two elements meet, the soft string within its 2 m elements, so that the two spread the change of curvature
    at the build's end differently over a vertex (7 % of the largest force there) but carry the same total.  So too
    on the VBH demo well at 20 kN on the bit, whose [torque_drag] section gives its own 60 kN and 120 rpm: each wall
    is pressed for the run's drive (measured 0.16 % on 10 m elements); and on the 3D demo well, whose axis turns in
    azimuth too (200 elements: measured 0.11 %)."""
    from fenics_drill.model.axial_torsional_string import axial_torsional_string
    from fenics_drill.model.forces.axial_torsional_wall import tension_press
    from fenics_drill.studies.stick_slip import start

    # where the whole string carries its lateral fields there is no such wall: refused in one line
    assert main(["scene", "demos/scenes/well_build_hold.toml", "--set", "contact.normal_force='dynamic'"]) == 2
    straight = fd.load_scene("demos/scenes/off_bottom_side_by_side.toml", ["model.lateral_length=0"])
    string = axial_torsional_string(straight)
    wall = string.wall_dofs[:, 0]
    press = tension_press(straight, string.x[wall])
    for u in (np.zeros(wall.size), np.random.default_rng(1).normal(scale=1e-2, size=wall.size)):
        # 1e-12: both are w h sin 60 deg, summed in a different order (measured 4e-14); the tension's share is
        # exactly zero where the axis does not turn, so any leak of it would show far above round-off
        np.testing.assert_allclose(press.normal_forces(u), string.wall_normal, rtol=1e-12)
    for path, settings in (("demos/scenes/well_build_hold.toml", ["beam.elements=90"]),
                           ("demos/scenes/well_vbh.toml", ["beam.elements=300", "drive.weight_on_bit='20 kN'",
                                                           "drive.rotation_speed='60 rpm'"]),
                           ("demos/scenes/well_3d.toml", ["beam.elements=200"])):
        scene = fd.load_scene(path, [*settings, "model.lateral_length=0"])
        string = axial_torsional_string(scene)
        wall = string.wall_dofs[:, 0]
        pressed = tension_press(scene, string.x[wall]).normal_forces(start(scene, string).state[0][wall])
        # 0.5 %: two discretisations of one equilibrium, the turn at the vertices here and within the soft string's
        # 2 m elements there, the FE static state's tension against the soft string's (measured 0.11-0.17 %); a wall
        # pressed for another operation misses by more (6.6 % on the VBH well pressed for 60 kN instead of 20)
        assert pressed.sum() == pytest.approx(string.wall_normal.sum(), rel=0.005)
