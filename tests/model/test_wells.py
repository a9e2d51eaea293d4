"""The well's axis by minimum curvature, the string's sections in the mud, and the soft-string torque-and-drag
model against closed forms: a string hanging in a vertical hole, one lying in a straight inclined hole, the capstan
law in a circular build, the free rotating weight of any well; the buckling loads against their formulas."""

import math

import numpy as np
import pytest

from fenics_drill.model.soft_string import Operation, soft_string, string_mesh
from fenics_drill.model.string_sections import string_sections
from fenics_drill.model.well import Survey, SurveyError, Trajectory, read_survey_csv, well_of
from fenics_drill.observables.buckling import helical_load, sinusoidal_load
from fenics_drill.scene import SceneError, load_scene

G = 9.81
PIPE = {"name": "pipe", "length": 1000.0, "outer_radius": 0.0635, "inner_radius": 0.0543}


def scene(*overrides, sections=(PIPE,), **tables):
    """A scene with these string sections; ``tables`` add whole sections (``well={...}``)."""
    from fenics_drill.scene import validate

    raw = {"string": {"sections": list(sections)}, **tables}
    base = load_scene(None, overrides)
    merged = base.to_dict()
    for name, table in raw.items():
        merged[name].update(table)
    return validate(merged)


def mesh_of(s, element_length=10.0, mu=0.3):
    sections = string_sections(s)
    well = well_of(s, sections[-1].bottom)
    fluid = s.fluid.density
    weights = [x.buoyed_weight(s.environment.gravity, fluid, fluid) for x in sections]
    return string_mesh(well, sections, element_length, weights, mu, mu), sections, weights


def test_minimum_curvature_follows_a_quarter_circle():
    """A build from vertical to horizontal at constant rate is a quarter circle of radius R = L / (pi/2): the
    positions, tangents and curvature of the arc, between the stations too, are those of the circle (exact
    geometry; 1e-9 m is round-off)."""
    radius = 600.0
    length = radius * math.pi / 2
    trajectory = Trajectory(Survey.of([0.0, length], [0.0, 90.0], [45.0, 45.0]))
    s = np.linspace(0.0, length, 17)
    angle = s / radius
    horizontal = radius * (1 - np.cos(angle))
    expected = np.column_stack([horizontal * math.cos(math.pi / 4), horizontal * math.sin(math.pi / 4),
                                -radius * np.sin(angle)])
    assert np.allclose(trajectory.positions(s), expected, atol=1e-9)
    assert np.allclose(trajectory.inclination(s), angle, atol=1e-12)
    assert np.allclose(trajectory.curvature(s), 1.0 / radius)


def minimum_curvature_reference(md, inclination_deg, azimuth_deg, s):
    """Positions (north, east, up) at measured depths ``s`` by the industry's minimum-curvature formula applied to
    an interpolated station: between stations k and k + 1 the tangent at s is t_k turned about their binormal by the
    share of the dogleg, and the step from station k is (s - md_k) / 2 RF(beta_s) (t_k + t_s), RF(b) =
    tan(b/2)/(b/2), beta_s the angle from t_k to t_s.  Written here from the formula, with the dogleg from
    atan2(|t_k x t_k+1|, t_k . t_k+1) and a series for RF at small angles: no code of the product."""
    inc, azi = np.radians(inclination_deg), np.radians(azimuth_deg)
    t = np.column_stack([np.sin(inc) * np.cos(azi), np.sin(inc) * np.sin(azi), -np.cos(inc)])

    def step(t1, t2, length):
        beta = math.atan2(np.linalg.norm(np.cross(t1, t2)), float(t1 @ t2))
        rf = 1 + beta**2 / 12 + beta**4 / 120 if beta < 1e-3 else math.tan(beta / 2) / (beta / 2)
        return 0.5 * length * rf * (t1 + t2)

    stations = [np.zeros(3)]
    for k in range(len(md) - 1):
        stations.append(stations[-1] + step(t[k], t[k + 1], md[k + 1] - md[k]))
    out = []
    for x in s:
        k = min(int(np.searchsorted(md, x, side="right")) - 1, len(md) - 2)
        cross = np.cross(t[k], t[k + 1])
        beta = math.atan2(np.linalg.norm(cross), float(t[k] @ t[k + 1]))
        share = (x - md[k]) / (md[k + 1] - md[k])
        if beta == 0:
            t_s = t[k]
        else:
            axis, angle = cross / np.linalg.norm(cross), share * beta  # Rodrigues: t_k turned in the arc's plane
            t_s = t[k] * math.cos(angle) + np.cross(axis, t[k]) * math.sin(angle)
        out.append(stations[k] + step(t[k], t_s, x - md[k]))
    return np.array(out)


def test_positions_between_stations_are_the_minimum_curvature_interpolation():
    """A build-hold-drop well with a turn, sampled every metre: positions within 1 mm of the minimum-curvature
    interpolation (:func:`minimum_curvature_reference`; measured 1e-9 m: round-off over 3 km), on the holds too,
    where two stations' tangents are equal and a difference of cosines by a round-off angle once put points 8 m
    off; distinct depths on a hold are distinct points 1 m apart; the dogleg severity of a hold is exactly 0."""
    from fenics_drill.model.well import dogleg_severity_deg_per_30m

    md = [0.0, 500.0, 1000.0, 1100.0, 1500.0, 2000.0, 2500.0, 3000.0]
    # angles whose tangent's dot product with itself rounds below 1 (arccos then gave a 1.5e-8 rad "dogleg")
    inc = [0.0, 0.0, 13.69, 13.69, 13.69, 45.0, 10.0, 10.0]
    azi = [341.51, 341.51, 341.51, 341.51, 341.51, 60.0, 60.0, 60.0]
    survey = Survey.of(md, inc, azi)
    trajectory = Trajectory(survey)
    s = np.arange(0.0, 3000.0, 1.0)
    reference = minimum_curvature_reference(np.array(md), np.array(inc), np.array(azi), s)
    assert np.abs(trajectory.positions(s) - reference).max() < 1e-3
    hold = trajectory.positions([1090.0, 1100.0])
    assert np.linalg.norm(hold[1] - hold[0]) == pytest.approx(10.0, rel=1e-9)
    severity = dogleg_severity_deg_per_30m(survey)
    assert severity[2] == 0.0 and severity[6] == 0.0 and severity[3] == 0.0


def test_a_survey_that_cannot_describe_a_well_is_refused_with_its_station(tmp_path):
    with pytest.raises(SurveyError, match="station 3: md = 100 m does not exceed"):
        Survey.of([0, 100, 100], [0, 0, 1], [0, 0, 0])
    with pytest.raises(SurveyError, match="inclination = 181"):
        Survey.of([0, 100], [0, 181], [0, 0])
    with pytest.raises(SurveyError, match="more than any pipe can pass"):
        Survey.of([0, 10], [0, 90], [0, 0])  # 270 deg/30 m: a typing error
    bad = tmp_path / "survey.csv"
    bad.write_text("md,dip,azimuth\n0,0,0\n")
    with pytest.raises(SurveyError, match="no column inclination"):
        read_survey_csv(bad)
    bad.write_text("md,inclination,azimuth\n0,0,0\n100,x,0\n")
    with pytest.raises(SurveyError, match="line 3: inclination = 'x' is not a number"):
        read_survey_csv(bad)


def test_a_scene_relates_its_string_and_its_well_or_says_why_not(tmp_path):
    """A survey file is found beside the scene file; a string longer than the well, a section wider than the hole
    and file-plus-inline stations are refused with the key, by torque-drag and by the FE model alike."""
    from fenics_drill.model.discretization import BeamDiscretization
    from fenics_drill.studies.torque_drag import torque_drag_study

    (tmp_path / "s.csv").write_text("md,inclination,azimuth\n0,0,0\n500,0,0\n")
    (tmp_path / "w.toml").write_text('[well]\nsurvey = "s.csv"\n[[string.sections]]\nlength = 400.0\n'
                                     'outer_radius = 0.0635\ninner_radius = 0.0543\n')
    s = load_scene(tmp_path / "w.toml")
    assert s.well.survey == str(tmp_path / "s.csv")
    assert torque_drag_study(s)["report"]["well"]["measured_depth_m"] == 500.0
    with pytest.raises(SceneError, match="longer than the well"):
        torque_drag_study(s.with_changes(string={"sections": [dict(PIPE, length=600.0)]}))
    with pytest.raises(SceneError, match="does not fit the hole"):
        torque_drag_study(scene(sections=[dict(PIPE, tool_joint_outer_radius=0.2, tool_joint_length=0.5,
                                         tool_joint_spacing=9.0)]))
    with pytest.raises(SceneError, match="not admissible together"):
        torque_drag_study(scene(well={"survey": str(tmp_path / "s.csv"), "md": [0.0, 10.0], "inclination": [0.0, 0.0],
                                "azimuth": [0.0, 0.0]}))
    with pytest.raises(SceneError, match="inner_radius"):
        scene(sections=[dict(PIPE, inner_radius=0.07)])
    with pytest.raises(SceneError, match="unknown key string.sections\\[1\\].od"):
        scene(sections=[dict(PIPE, od=0.1)])
    with pytest.raises(SceneError, match="longer than the well"):  # the FE string checks its well alike
        BeamDiscretization.from_scene(s.with_changes(string={"sections": [dict(PIPE, length=600.0)]}))
    assert BeamDiscretization.from_scene(s).properties.length == 400.0


def test_a_hanging_string_carries_its_buoyed_weight_and_touches_nothing():
    """Vertical hole, mud inside and out: the hook load is the weight less the displaced mud,
    g L (rho_s - rho_m) A_steel, whatever the operation (no wall force, so no friction); and rotating costs no torque.
    Tool joints add steel and displacement (Archimedes); the model sums them element by element (round-off)."""
    joint = dict(PIPE, tool_joint_outer_radius=0.084, tool_joint_length=0.45, tool_joint_spacing=9.4)
    s = scene("fluid.density=1200.0", sections=[joint], well={"md": [0.0, 1000.0], "inclination": [0.0, 0.0],
                                                             "azimuth": [0.0, 0.0]})
    mesh, sections, _ = mesh_of(s)
    extra = math.pi * (0.084**2 - 0.0635**2) * 0.45 / 9.4
    steel = math.pi * (0.0635**2 - 0.0543**2) + extra
    expected = G * 1000.0 * (s.beam.density - 1200.0) * steel  # mud inside and out: the net displaced area is the steel's
    for op in (Operation("trip out", -0.3, 0.0, 0.0, 0.0), Operation("rotate", 0.0, 10.0, 0.0, 0.0)):
        loads = soft_string(mesh, op)
        assert loads["tension"][0] == pytest.approx(expected, rel=1e-12)
        assert np.all(loads["wall_force_per_length"] < 1e-9)
        assert loads["torque"][0] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("elements", [100, 263, 700])
def test_the_hook_load_of_a_hanging_string_of_sections_is_their_buoyed_weights_on_any_mesh(elements):
    """Collars of 2.2 kN/m under 4 1/2 in pipe in a vertical hole: the effective tension at the top with W on the bit
    is sum w_i L_i - W (Lubinski), which a hook-load drive sets.  The joint at 2416 m falls between the points of a
    uniform grid of the string's 2592 m; sampled across it, the weight's step put the hook load 659 N off, 3.3 % of
    a 20 kN weight on bit.  Integrated section by section it is exact (1e-12: round-off)."""
    from fenics_drill.model.well import hanging_tension

    collars = {"name": "collars", "length": 176.0, "outer_radius": 0.1016, "inner_radius": 0.0357}
    pipe = {"name": "pipe", "length": 2416.0, "outer_radius": 0.05715, "inner_radius": 0.04859}
    s = scene(f"beam.elements={elements}", "fluid.density=1200.0", sections=[collars, pipe],
              well={"md": [0.0, 2592.0], "inclination": [0.0, 0.0], "azimuth": [0.0, 0.0]})
    weights = [x.buoyed_weight(s.environment.gravity, 1200.0, 1200.0) * (x.bottom - x.top) for x in string_sections(s)]
    expected = sum(weights)
    # 1e-12: a piecewise-constant weight summed interval by interval is exact but for round-off; the sampled grid
    # missed by 586-659 N, 8e-4 of the 780 kN, eight orders above it
    assert hanging_tension(s, [0.0], 20e3)[0] == pytest.approx(expected - 20e3, rel=1e-12)
    assert hanging_tension(s, [2416.0], 0.0)[0] == pytest.approx(weights[-1], rel=1e-12)  # the collars' alone


@pytest.mark.parametrize("inclination", [30.0, 60.0, 90.0])
def test_a_string_in_a_straight_inclined_hole_drags_mu_w_sin_i(inclination):
    """Straight hole at inclination I: the wall carries w sin I per length, and pulling out needs
    w L (cos I + mu sin I), running in w L (cos I - mu sin I); rotating off bottom turns with mu w L sin I r_c and
    lifts w L cos I; rotating while feeding splits mu N by the slip's direction (Johancsik's closed forms; exact
    for a straight hole, 1e-10 is round-off)."""
    s = scene(well={"md": [0.0, 1000.0], "inclination": [inclination] * 2, "azimuth": [10.0] * 2})
    mu = 0.3
    mesh, sections, weights = mesh_of(s, mu=mu)
    w, length, i = weights[0], 1000.0, math.radians(inclination)
    r = sections[0].contact_radius
    out = soft_string(mesh, Operation("out", -0.3, 0.0, 0.0, 0.0))
    inn = soft_string(mesh, Operation("in", 0.3, 0.0, 0.0, 0.0))
    rot = soft_string(mesh, Operation("rot", 0.0, 6.0, 0.0, 0.0))
    assert out["tension"][0] == pytest.approx(w * length * (math.cos(i) + mu * math.sin(i)), rel=1e-10)
    assert inn["tension"][0] == pytest.approx(w * length * (math.cos(i) - mu * math.sin(i)), rel=1e-10, abs=1e-6)
    assert rot["tension"][0] == pytest.approx(w * length * math.cos(i), rel=1e-10, abs=1e-6)
    assert rot["torque"][0] == pytest.approx(mu * w * length * math.sin(i) * r, rel=1e-10)
    assert np.allclose(rot["wall_force_per_length"], w * math.sin(i), rtol=1e-10)
    feed, spin = 0.01, 6.0
    both = soft_string(mesh, Operation("drill", feed, spin, 0.0, 0.0))
    slip = math.hypot(feed, r * spin)
    assert both["tension"][0] == pytest.approx(w * length * (math.cos(i) - mu * math.sin(i) * feed / slip),
                                               rel=1e-10, abs=1e-6)
    assert both["torque"][0] == pytest.approx(mu * w * length * math.sin(i) * r * r * spin / slip, rel=1e-10)


def test_a_weightless_string_pulled_round_a_bend_follows_the_capstan_law():
    """Around a circular arc of angle beta, a weightless string pulled out needs F_top = F_bit exp(mu beta)
    (Euler's capstan).  Each element is exact to O(beta_e^3), so the error falls as the element length squared:
    halving the elements divides it by 4 (within 5 %)."""
    s = scene("environment.gravity=0.0", well={"md": [0.0, 200.0, 671.24, 1000.0], "inclination": [0, 0, 90, 90],
                                               "azimuth": [0, 0, 0, 0]},
              sections=[dict(PIPE, length=1000.0)])
    mu, pull, beta = 0.3, 10e3, math.pi / 2
    errors = []
    for h in (40.0, 20.0, 10.0):
        mesh, _, _ = mesh_of(s, element_length=h, mu=mu)
        top = soft_string(mesh, Operation("out", -0.3, 0.0, pull, 0.0))["tension"][0]
        errors.append(top / (pull * math.exp(mu * beta)) - 1.0)
    assert abs(errors[-1]) < 1e-3
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.05)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.05)


def test_the_free_rotating_weight_is_the_buoyed_weight_times_the_vertical_depth():
    """Rotating off bottom in any well, the wall's friction turns the string and does not lift it: the hook load
    is the integral of w dz, the buoyed weight over the true vertical depth of each section.  The demo's 3D well;
    the chord's cos(beta_e/2) factors leave O(beta_e^2) = 1e-5 relative."""
    from pathlib import Path

    from fenics_drill.studies.torque_drag import torque_drag_study

    s = load_scene(Path(__file__).parents[2] / "demos" / "scenes" / "well_3d.toml",
                   ["torque_drag.operations=['rotating_off_bottom']"])
    study = torque_drag_study(s)
    sections = string_sections(s)
    well = well_of(s, sections[-1].bottom)
    weights = [x.buoyed_weight(G, 1200.0, 1200.0) for x in sections]
    z = lambda md: well.trajectory.positions([md])[0, 2]  # noqa: E731
    expected = sum(w * (z(x.top) - z(x.bottom)) for x, w in zip(sections, weights))
    assert study["report"]["operations"]["rotating_off_bottom"]["hook_load_N"] == pytest.approx(expected, rel=1e-4)


def test_buckling_loads_take_their_published_forms():
    """Dawson-Paslay in a straight inclined hole, Lubinski / Wu-Juvkam-Wold in a vertical one, He-Kyllingstad in
    a build tending to Dawson-Paslay as the curvature vanishes, helical sqrt(2) times sinusoidal."""
    ei, w, r = 1.2e6, 250.0, 0.025
    for inc in (0.3, 1.0, math.pi / 2):
        straight = 2 * math.sqrt(ei * w * math.sin(inc) / r)
        assert sinusoidal_load(ei, w, inc, r) == pytest.approx(max(straight, 2.55 * (ei * w**2) ** (1 / 3)))
        assert sinusoidal_load(ei, w, inc, r, 1e-9) == pytest.approx(sinusoidal_load(ei, w, inc, r), rel=1e-3)
        assert helical_load(ei, w, inc, r) == pytest.approx(max(math.sqrt(2) * sinusoidal_load(ei, w, inc, r),
                                                                 5.55 * (ei * w**2) ** (1 / 3)))
    assert sinusoidal_load(ei, w, 0.0, r) == pytest.approx(2.55 * (ei * w**2) ** (1 / 3))
    kappa = math.radians(3.0) / 30.0
    curved = 4 * ei * kappa / r * (1 + math.sqrt(1 + r * w * math.sin(1.0) / (4 * ei * kappa**2)))
    assert sinusoidal_load(ei, w, 1.0, r, kappa) == pytest.approx(curved)


@pytest.mark.parametrize("inner", [-1.0, 0.0])
def test_the_fe_model_weighs_the_pipe_in_the_mud_as_archimedes_does(inner):
    """The FE gravity load (52) scaled by the buoyancy factor sums to the pipe's weight in the mud that the soft
    string uses: g L (rho_s A - rho_m pi R^2 + rho_i pi r^2); with mud inside and out, the textbook
    (1 - rho_m / rho_s) of the weight in air (round-off)."""
    from fenics_drill.model.discretization import BeamDiscretization
    from fenics_drill.model.operators import assemble_linear

    s = load_scene(None, ["fluid.density=1300.0", f"fluid.inner_density={inner}", "beam.elements=8"])
    disc = BeamDiscretization.from_scene(s)
    vertical = assemble_linear(disc).gravity[disc.field_dofs[2]].sum()  # the w field
    section = string_sections(s)[0]
    inside = 1300.0 if inner == -1.0 else inner
    assert -vertical == pytest.approx(section.buoyed_weight(s.environment.gravity, 1300.0, inside) * s.beam.length,
                                      rel=1e-12)
    if inner == -1.0:
        assert s.buoyancy_factor == pytest.approx(1.0 - 1300.0 / s.beam.density, rel=1e-14)


def test_the_mud_moves_with_the_lateral_motion_only():
    """M carries (rho A + m_f) on v and w and rho A on u, C adds c_f on v and w: by the partition of unity,
    1^T M 1 over one field's dofs is that field's mass per length times L (round-off).  m_f = rho_i pi r^2 +
    C_a rho_m pi R^2 with the confined-annulus C_a = (R_h^2 + R^2)/(R_h^2 - R^2), which tends to the unconfined
    cylinder's 1 in a wide hole."""
    from fenics_drill.model.discretization import BeamDiscretization
    from fenics_drill.model.operators import assemble_linear

    s = load_scene(None, ["fluid.density=1200.0", "fluid.lateral_damping=40.0", "beam.elements=8"])
    b, hole = s.beam, s.borehole.radius
    c_a = (hole**2 + b.outer_radius**2) / (hole**2 - b.outer_radius**2)
    m_f = math.pi * 1200.0 * (b.inner_radius**2 + c_a * b.outer_radius**2)
    assert s.lateral_added_mass == pytest.approx(m_f, rel=1e-14)
    disc = BeamDiscretization.from_scene(s)
    ops = assemble_linear(disc)
    steel = b.density * math.pi * (b.outer_radius**2 - b.inner_radius**2)
    total = lambda matrix, field: matrix[disc.field_dofs[field]][:, disc.field_dofs[field]].sum()  # noqa: E731
    assert total(ops.mass, 0) == pytest.approx(steel * b.length, rel=1e-12)
    for field in (1, 2):
        assert total(ops.mass, field) == pytest.approx((steel + m_f) * b.length, rel=1e-12)
        assert total(ops.damping, field) == pytest.approx((b.damping * steel + 40.0) * b.length, rel=1e-12)
    wide = load_scene(None, ["fluid.density=1000.0", "borehole.radius=80.0"])
    unconfined = math.pi * 1000.0 * (b.inner_radius**2 + b.outer_radius**2)
    assert wide.lateral_added_mass == pytest.approx(unconfined, rel=1e-5)


def test_a_hanging_string_stretches_under_its_weight_in_the_mud():
    """A plain pipe hanging in a vertical hole with mud inside and out stretches g L^2 (rho_s - 2 rho_m (1 - nu)) /
    (2 E): the true tension rho_s g A (L - z) - rho_m g L A and the Poisson shortening of the hydrostatic radial and
    hoop stresses (Lubinski).  The strain is linear along the string and the midpoint rule integrates it exactly
    (round-off)."""
    from fenics_drill.studies.torque_drag import torque_drag_study

    s = scene("fluid.density=1200.0", "torque_drag.operations=['tripping_out', 'rotating_off_bottom']",
              well={"md": [0.0, 1000.0], "inclination": [0.0, 0.0], "azimuth": [0.0, 0.0]})
    b = s.beam
    expected = G * 1000.0**2 * (b.density - 2 * 1200.0 * (1 - b.poisson_ratio)) / (2 * b.young_modulus)
    for op in torque_drag_study(s)["report"]["operations"].values():
        assert op["stretch_m"] == pytest.approx(expected, rel=1e-10)
