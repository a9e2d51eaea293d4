"""Torque and drag as the rig uses it: broomstick charts against the torque-and-drag study, friction factors
calibrated from measured points, and the probability of reaching the rig's limits against closed forms."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

import fenics_drill as fd
from fenics_drill.cli import main
from fenics_drill.io.measured import read_measured
from fenics_drill.scene import SceneError
from fenics_drill.studies.broomstick import broomstick_study, indicator_factor
from fenics_drill.studies.calibration import Calibration, calibrate
from fenics_drill.studies.torque_drag import torque_drag_study

ROOT = Path(__file__).parents[2]
VBH = ROOT / "demos" / "scenes" / "well_vbh.toml"
KLBF = 4448.2216152605

#: A 1200 m build-and-hold well cased to 500 m, a collar and drill pipe, in mud: small enough for every test here.
WELL = """
[well]
md = [0.0, 300.0, 600.0, 1200.0]
inclination = [0.0, 0.0, 45.0, 45.0]
azimuth = [0.0, 0.0, 30.0, 30.0]
hole_bottom = [500.0, 1200.0]
hole_radius = ["4.34 in", "4 1/4 in"]
hole_cased = [true, false]

[fluid]
density = "10 ppg"

[torque_drag]
element_length = 5.0

[broomstick]
depth_step = 100.0
friction_cased = [0.2, 0.3]
friction_open = [0.25, 0.35]
block_weight = "30 t"

[[string.sections]]
name = "collars"
length = 100.0
outer_diameter = "6 1/2 in"
inner_diameter = "2 13/16 in"

[[string.sections]]
name = "drill pipe"
length = 1100.0
outer_diameter = "5 in"
inner_diameter = "4.276 in"
tool_joint_outer_diameter = "6 5/8 in"
tool_joint_length = 0.45
tool_joint_spacing = 9.4
"""


@pytest.fixture
def well(tmp_path) -> Path:
    path = tmp_path / "well.toml"
    path.write_text(WELL)
    return path


def test_each_broomstick_curve_at_a_depth_is_the_torque_and_drag_study_at_that_depth(well):
    """With the bit at 700 m the chart's string is the scene's cut at the top; the torque-and-drag study of the scene
    whose drill pipe is 600 m long gives, for every operation and friction pair, the same hook load and torque (the
    same compiled soft string: equal to round-off of the block weight's addition)."""
    scene = fd.load_scene(well)
    chart = broomstick_study(scene)["chart"]
    depth = list(chart["depth"].values).index(700.0)
    sections = list(scene.string.sections)
    sections[1] = {**sections[1], "length": 600.0}
    cut = scene.with_changes(string={"sections": sections})
    block = scene.broomstick.block_weight
    for p in chart["pair"].values:
        cased, open_hole = float(chart["friction_cased"][p]), float(chart["friction_open"][p])
        study = torque_drag_study(cut.with_changes(torque_drag={"friction_cased": cased, "friction_open": open_hole,
                                                                "operations": list(chart["operation"].values)}))
        for j, name in enumerate(chart["operation"].values):
            op = study["report"]["operations"][str(name)]
            assert float(chart["hook_load"][depth, j, p]) - block == pytest.approx(op["hook_load_N"], rel=1e-12)
            assert float(chart["surface_torque"][depth, j, p]) == pytest.approx(op["surface_torque_Nm"], rel=1e-12,
                                                                                abs=1e-9)


def test_the_weight_indicator_reads_the_deadline():
    """The line tensions sheave by sheave: from the fast line over the n + 1 sheaves to the deadline each line
    carries e times the one before while hoisting (1/e while lowering); the strung lines carry the hook load and the
    indicator reads n times the deadline's tension.  Without losses it reads the hook load."""
    for lines, e in ((10, 0.96), (8, 0.98), (12, 0.9)):
        for motion, ratio in ((1, e), (-1, 1.0 / e)):
            tensions = ratio ** np.arange(1, lines + 2)  # lines 1..n, then the deadline, for a fast line of 1
            hook_load, deadline = tensions[:lines].sum(), tensions[lines]
            assert indicator_factor(lines, e, motion) == pytest.approx(lines * deadline / hook_load, rel=1e-12)
    assert indicator_factor(10, 1.0, 1) == indicator_factor(0, 0.9, 1) == indicator_factor(10, 0.9, 0) == 1.0


def test_the_broomstick_command_writes_its_chart(well, tmp_path, capsys):
    out = tmp_path / "chart"
    assert main(["broomstick", str(well), "--out", str(out)]) == 0
    header = (out / "broomstick.csv").read_text().splitlines()[0]
    assert header == "bit_depth (m),operation,friction_cased (-),friction_open (-),hook_load (N),surface_torque (N*m)"
    import xarray

    chart = xarray.load_dataset(out / "broomstick.nc", engine="h5netcdf")
    assert chart["hook_load"].shape == (12, 5, 4) and (out / "broomstick.png").stat().st_size > 10_000
    # the minimum weight to helical buckling lies below the weight of the string at rest, the yield above it
    rest = chart["hook_load"].sel(operation="rotating_off_bottom").values
    assert np.all(np.nan_to_num(chart["helical_buckling_hook_load"].values, nan=0.0) < rest)
    assert np.all(chart["yield_hook_load"].values > chart["hook_load"].sel(operation="tripping_out").values)


def synthetic(scene, cased: float, open_hole: float, noise: float = 0.0, seed: int = 1) -> dict:
    """Measured points from the model with known friction factors at every 100 m from 100 m (hook loads and
    torques), with relative Gaussian noise."""
    depths = np.arange(100.0, 1201.0, 100.0)
    columns = ("pick_up", "slack_off", "rotating_off_bottom", "torque_off_bottom", "torque_on_bottom")
    empty = {"bit_depth": depths, **{c: np.zeros_like(depths) for c in columns}}
    model = Calibration(scene, empty).loads(np.array([[cased, open_hole]]), scene.broomstick.block_weight)
    rng = np.random.default_rng(seed)
    return {"bit_depth": depths, **{c: model[c][:, 0] * (1 + noise * rng.standard_normal(depths.size))
                                    for c in columns}}


def test_a_calibration_recovers_the_friction_factors_the_points_were_made_from(well):
    """Without noise: the factors within 1e-3 (the model that fits is the one that made the points, on the same
    elements).  With 1.5 % noise: each factor inside its 95 % interval, an interval narrower than 0.1 (it says
    something)."""
    scene = fd.load_scene(well)
    exact = calibrate(scene, synthetic(scene, 0.22, 0.31))
    assert exact["friction_cased"]["value"] == pytest.approx(0.22, abs=1e-3)
    assert exact["friction_open"]["value"] == pytest.approx(0.31, abs=1e-3)
    noisy = calibrate(scene, synthetic(scene, 0.22, 0.31, noise=0.015))
    for name, true in (("friction_cased", 0.22), ("friction_open", 0.31)):
        low, high = noisy[name]["interval"]
        assert low <= true <= high and high - low < 0.1, (name, noisy[name])
    # at each point alone, the factor that meets it: the true one, without noise (the grid's interpolation: 1e-3)
    for column in ("pick_up", "slack_off", "torque_on_bottom"):
        track = [v for v in exact["back_calculated"][column][1:] if v is not None]
        depths = exact["measured"]["bit_depth"][1:]
        truth = [0.22 if d <= 500.0 else 0.31 for d, v in zip(depths, exact["back_calculated"][column][1:])
                 if v is not None]
        assert track and np.allclose(track, truth, atol=2e-3), (column, track)


def test_a_well_with_the_bit_in_casing_only_fits_the_cased_factor(well):
    scene = fd.load_scene(well)
    points = synthetic(scene, 0.22, 0.31)
    inside = {k: v[:5] for k, v in points.items()}  # 100-500 m: the shoe is at 500 m
    report = calibrate(scene, inside)
    assert report["friction_cased"]["value"] == pytest.approx(0.22, abs=1e-3)
    assert report["friction_open"]["value"] is None and "undetermined" in report["friction_open"]["message"]


def test_pick_up_below_slack_off_is_flagged_as_more_than_friction_explains(well):
    scene = fd.load_scene(well)
    points = synthetic(scene, 0.22, 0.31)
    points["pick_up"][6], points["slack_off"][6] = points["slack_off"][6] * 0.97, points["pick_up"][6]
    warnings = calibrate(scene, points)["warnings"]
    assert any("at bit depth 700.0 m pick-up" in w for w in warnings) and len(warnings) == 1, warnings


def test_the_calibrate_command_reads_a_measured_file_in_oilfield_units(well, tmp_path, capsys):
    scene = fd.load_scene(well)
    points = synthetic(scene, 0.22, 0.31)
    lines = ["# made from the model: friction 0.22 cased, 0.31 open", "bit_depth (ft);pick_up (klbf);slack_off (klbf)"]
    lines += [f"{d / 0.3048:.2f};{u / KLBF:.4f};{s / KLBF:.4f}".replace(".", ",")
              for d, u, s in zip(points["bit_depth"], points["pick_up"], points["slack_off"])]
    (tmp_path / "measured.csv").write_text("\n".join(lines) + "\n")
    assert main(["calibrate", str(well), str(tmp_path / "measured.csv"), "--out", str(tmp_path / "cal")]) == 0
    report = json.loads((tmp_path / "cal" / "calibration.json").read_text())
    # the file's rounding (1e-4 klbf, 1 cm) moves the fit by far less than 1e-3
    assert report["friction_cased"]["value"] == pytest.approx(0.22, abs=1e-3)
    assert report["friction_open"]["value"] == pytest.approx(0.31, abs=1e-3)
    assert (tmp_path / "cal" / "calibration.png").exists() and (tmp_path / "cal" / "friction_track.png").exists()


@pytest.mark.parametrize("content, words", [
    ("bit_depth (ft),pick_up (klbf)\n3937.1,100\n", "beyond the well"),  # 1200.03 m in a 1200 m well
    ("bit_depth (m),pick_up (kN)\n600,-5\n", "is negative"),
    ("bit_depth (m),hook_speed (m/s)\n600,1\n", "unknown column 'hook_speed (m/s)'"),
    ("bit_depth (m),pick_up (furlongz)\n600,1\n", "unknown unit 'furlongz'"),
    ("bit_depth (m),pick_up (kN)\n600,abc\n", "line 2: pick_up = 'abc' is not a number"),
])
def test_a_bad_measured_file_is_refused_naming_the_line_or_column(well, tmp_path, capsys, content, words):
    (tmp_path / "m.csv").write_text(content)
    assert main(["calibrate", str(well), str(tmp_path / "m.csv"), "--out", str(tmp_path / "cal")]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "cal").exists()


def test_depths_in_feet_meet_the_well_within_their_round_off(tmp_path):
    """3937.01 ft is the 1200 m well's bottom (1200.0006 m)."""
    (tmp_path / "m.csv").write_text("bit_depth (ft),pick_up (klbf)\n3937.01,100\n")
    assert read_measured(tmp_path / "m.csv", 1200.0)["bit_depth"][0] == 1200.0


def test_a_friction_grid_outside_zero_one_is_refused(well, capsys):
    assert main(["broomstick", str(well), "--set", "broomstick.friction_open=[0.2, 1.3]", "--out", "x"]) == 2
    assert "broomstick.friction_open = [0.2, 1.3] is not admissible" in capsys.readouterr().err


# --- under uncertainty ---------------------------------------------------------------------------------------------

STRAIGHT = """
[well]
md = [0.0, 1000.0]
inclination = [{inclination}, {inclination}]
azimuth = [0.0, 0.0]

[broomstick]
depth_step = 1000.0
operations = ["tripping_out"]
hook_load_limit = {limit}

[risk]
friction_open = [0.1, 0.5]

[[string.sections]]
name = "drill pipe"
length = 1000.0
outer_radius = 0.0635
inner_radius = 0.0543
"""


def test_the_probability_of_exceeding_the_hook_load_limit_is_the_closed_form(tmp_path, capsys):
    """A straight hole at 60 deg, open hole, friction uniform on [0.1, 0.5]: pulling out, H = w L (cos I + mu sin I),
    so P(H > limit) = (0.5 - mu*) / 0.4 with mu* = (limit / (w L) - cos I) / sin I.  4000 realisations: the estimate
    within 4 standard errors of a binomial (0.031 at p = 0.5)."""
    path = tmp_path / "straight.toml"
    path.write_text(STRAIGHT.format(inclination=60.0, limit=1.0))
    scene = fd.load_scene(path)
    from fenics_drill.model.string_sections import string_sections

    w = string_sections(scene)[0].buoyed_weight(scene.environment.gravity, 0.0, 0.0)
    inclination = math.radians(60.0)
    mu_star = 0.3
    limit = w * 1000.0 * (math.cos(inclination) + mu_star * math.sin(inclination))
    path.write_text(STRAIGHT.format(inclination=60.0, limit=limit))
    samples = 4000
    assert main(["torque-drag", str(path), "--samples", str(samples), "--quiet", "--out", str(tmp_path / "r")]) == 0
    risk = json.loads((tmp_path / "r" / "risk.json").read_text())
    expected = (0.5 - mu_star) / 0.4
    assert abs(risk["max_probability_over_hook_load_limit"] - expected) < 4 * math.sqrt(0.25 / samples)


def test_in_a_vertical_well_the_probability_does_not_depend_on_friction(tmp_path):
    """Vertical: pulling out lifts the string's weight whatever the friction, so a limit just below it is exceeded by
    every realisation, and one just above by none."""
    from fenics_drill.model.string_sections import string_sections

    path = tmp_path / "vertical.toml"
    path.write_text(STRAIGHT.format(inclination=0.0, limit=1.0))
    scene = fd.load_scene(path)
    weight = string_sections(scene)[0].buoyed_weight(scene.environment.gravity, 0.0, 0.0) * 1000.0
    for limit, expected in ((0.999 * weight, 1.0), (1.001 * weight, 0.0)):
        path.write_text(STRAIGHT.format(inclination=0.0, limit=limit))
        out = tmp_path / f"r{expected}"
        assert main(["torque-drag", str(path), "--samples", "100", "--quiet", "--out", str(out)]) == 0
        assert json.loads((out / "risk.json").read_text())["max_probability_over_hook_load_limit"] == expected


def test_friction_laws_have_the_stated_moments():
    """Bounds only: uniform; a mean: the truncated exponential of that mean; a mean and a dispersion: the beta law of
    that mean and standard deviation.  20 000 draws: the sample moments within 4 standard errors."""
    from fenics_drill.studies.risk import FrictionLaw

    rng = np.random.default_rng(7)
    n = 20_000
    for law, mean, std in ((FrictionLaw("f", 0.1, 0.5), 0.3, 0.4 / math.sqrt(12.0)),
                           (FrictionLaw("f", 0.1, 0.5, 0.2), 0.2, None),
                           (FrictionLaw("f", 0.1, 0.5, 0.25, 0.2), 0.25, 0.05)):
        draws = np.array([law.draw(rng) for _ in range(n)])
        assert draws.min() >= 0.1 and draws.max() <= 0.5
        assert abs(draws.mean() - mean) < 4 * draws.std() / math.sqrt(n)
        if std is not None:
            assert draws.std() == pytest.approx(std, rel=0.03)
    with pytest.raises(SceneError, match="a dispersion below"):
        FrictionLaw("friction_open", 0.1, 0.5, 0.3, 1.0)


def test_an_unknown_error_model_or_one_without_welleng_is_refused(well, tmp_path, capsys, monkeypatch):
    args = ["torque-drag", str(well), "--samples", "10", "--quiet", "--out", str(tmp_path / "r")]
    pytest.importorskip("welleng")
    assert main([*args, "--set", "risk.survey_error='ISCWSA Wishful Rev9'"]) == 2
    assert "is not an error model welleng knows" in capsys.readouterr().err
    import fenics_drill.model.survey_errors as errors

    monkeypatch.setattr(errors, "welleng_installed", lambda: False)
    assert main([*args, "--set", "risk.survey_error='ISCWSA MWD Rev5.11'"]) == 2
    assert "needs welleng, the optional dependency" in capsys.readouterr().err


def test_survey_uncertainty_and_tortuosity_spread_the_loads(well, tmp_path):
    """The ISCWSA MWD model's systematic terms and a 1 deg tortuosity of 30 m period widen the envelopes of a fixed
    friction pair (which alone would give none) and the tortuosity raises the median pick-up (its doglegs add drag)."""
    pytest.importorskip("welleng")
    fixed = ["risk.friction_cased=[0.25, 0.25]", "risk.friction_open=[0.3, 0.3]", "broomstick.depth_step=400.0"]
    from fenics_drill.studies.risk import write_risk

    plain = write_risk(fd.load_scene(well, fixed), 20, tmp_path / "a", progress=False)["risk"]
    moved = write_risk(fd.load_scene(well, [*fixed, "risk.survey_error='ISCWSA MWD Rev5.11'",
                                            "risk.tortuosity_amplitude=1.0"]), 20, tmp_path / "b",
                       progress=False)["risk"]
    pick = list(plain["operation"].values).index("tripping_out")
    spread = lambda r: float(r["hook_load"][2, -1, pick] - r["hook_load"][0, -1, pick])  # noqa: E731
    assert spread(plain) == pytest.approx(0.0, abs=1e-6) and spread(moved) > 100.0
    assert float(moved["hook_load"][1, -1, pick]) > float(plain["hook_load"][1, -1, pick])


def test_the_iscwsa_covariance_at_td_of_example_well_1_is_the_published_one():
    """ISCWSA's example well 1 (8000 m: vertical to 1200 m, built at 2 deg/30 m to 60 deg, held to 5100 m, built at 3
    deg/30 m to horizontal, azimuth 75 deg; B = 50 000 nT, dip 72 deg, declination -4 deg) under the MWD Rev 5.11
    model: the position covariance at TD against the example workbook's totals (NN 8477.9141, EE 708.2741,
    VV 513.2943, NE -2233.4057, NV -58.6686, EV -146.0403 m^2).  The vertical terms agree to 1e-6; the horizontal
    ones within 0.5 %: the declination term DEC-OH as welleng computes it for these inputs is 10 % above the
    workbook's (438.4 against 397.6 m^2 of NN), every other term within 1e-4 (measured)."""
    pytest.importorskip("welleng")
    from fenics_drill.model.survey_errors import iscwsa_covariance
    from fenics_drill.model.well import Survey

    md = np.append(np.arange(0.0, 7981.0, 30.0), 8000.0)
    inc = np.interp(md, [0.0, 1200.0, 2100.0, 5100.0, 5400.0, 8000.0], [0.0, 0.0, 60.0, 60.0, 90.0, 90.0])
    azi = np.where(md > 1200.0, 75.0, 0.0)
    cov = iscwsa_covariance(Survey(md, np.radians(inc), np.radians(azi)), "ISCWSA MWD Rev5.11", (50e-6, 72.0, -4.0))
    published = np.array([[8477.9141, -2233.4057, -58.6686], [-2233.4057, 708.2741, -146.0403],
                          [-58.6686, -146.0403, 513.2943]])
    assert cov[-1][2, 2] == pytest.approx(published[2, 2], rel=1e-6)
    assert cov[-1][0, 2] == pytest.approx(published[0, 2], rel=1e-6)
    assert np.all(np.abs(cov[-1] - published) <= 5e-3 * np.abs(published))
