"""fenics-drill torque-drag: the files a user opens, the paper's straight horizontal hole as the default well, and a
lock-up said as such."""

import json
import math
from pathlib import Path

import meshio
import numpy as np
import pytest
import xarray as xr

from fenics_drill.cli import main
from fenics_drill.scene import load_scene

VBH = Path(__file__).parents[2] / "demos" / "scenes" / "well_vbh.toml"


def test_torque_drag_writes_the_study_its_profiles_the_path_and_figures(tmp_path, capsys):
    """The report, an xarray dataset with a profile per operation, a VTU polyline for ParaView, three figures; the
    operations order the hook load as friction does: pulling out > rotating off bottom > running in."""
    assert main(["torque-drag", str(VBH), "--out", str(tmp_path)]) == 0
    said = capsys.readouterr().out
    assert "3000 m well" in said and "tripping_out" in said
    report = json.loads((tmp_path / "torque_drag.json").read_text())
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "finished"
    ops = report["operations"]
    assert ops["tripping_out"]["hook_load_N"] > ops["rotating_off_bottom"]["hook_load_N"] > \
        ops["tripping_in"]["hook_load_N"]
    profiles = xr.load_dataset(tmp_path / "torque_drag.h5", engine="h5netcdf")
    assert profiles["md"].values[-1] == pytest.approx(3000.0)
    assert profiles["tension_tripping_out"].values[0] == pytest.approx(ops["tripping_out"]["hook_load_N"])
    assert profiles["wall_force_per_length_sliding"].dims == ("md_element",)
    path = meshio.read(tmp_path / "well.vtu")
    assert path.points.shape == (profiles.sizes["md"], 3)
    assert path.points[-1, 2] == pytest.approx(-report["well"]["true_vertical_depth_m"])
    for name in ("well_loads.png", "well_path.png", "well_3d.png"):
        assert (tmp_path / name).stat().st_size > 10_000


def test_the_default_well_is_the_paper_hole_and_running_in_it_locks_up(tmp_path, capsys):
    """Without [well] and [string]: the paper's pipe in its straight horizontal hole, the same study as a survey of
    that hole gives (to round-off).  Horizontal, every metre must be pushed in against mu w: the hook load of
    tripping in is -mu w L, which the hook cannot give: locked up."""
    default = tmp_path / "default"
    assert main(["torque-drag", "--out", str(default)]) == 0
    assert "LOCKED UP" in capsys.readouterr().out
    survey = ["--set", "well.md=[0.0, 100.0]", "--set", "well.inclination=[90.0, 90.0]",
              "--set", "well.azimuth=[0.0, 0.0]"]
    assert main(["torque-drag", *survey, "--out", str(tmp_path / "survey")]) == 0
    a = json.loads((default / "torque_drag.json").read_text())["operations"]
    b = json.loads((tmp_path / "survey" / "torque_drag.json").read_text())["operations"]
    for name in a:  # one hole described two ways: equal to round-off (abs: the torques that vanish)
        assert b[name]["hook_load_N"] == pytest.approx(a[name]["hook_load_N"], rel=1e-12, abs=1e-9)
        assert b[name]["surface_torque_Nm"] == pytest.approx(a[name]["surface_torque_Nm"], rel=1e-12, abs=1e-12)
    scene = load_scene(None)
    weight = scene.beam.density * math.pi * (scene.beam.outer_radius**2 - scene.beam.inner_radius**2) * 9.81
    assert a["tripping_in"]["hook_load_N"] == pytest.approx(-scene.torque_drag.friction_open * weight * 100.0,
                                                            rel=1e-12)
    assert a["tripping_in"]["locked_up"] and not a["tripping_out"]["locked_up"]


def test_a_bad_survey_is_a_one_line_scene_error(tmp_path, capsys):
    bad = tmp_path / "well.toml"
    bad.write_text("[well]\nmd = [0.0, 500.0, 400.0]\ninclination = [0.0, 0.0, 0.0]\nazimuth = [0.0, 0.0, 0.0]\n")
    assert main(["torque-drag", str(bad), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "station 3: md = 400 m does not exceed the station before" in err and "Traceback" not in err


def test_static_on_a_well_writes_its_loads_along_the_well_beside_the_soft_strings(tmp_path, capsys):
    """``fenics-drill static`` on the 3 km VBH demo well: the hook load, the profiles (the FE effective tension, the
    soft string's, the buckling loads) and their figure.  The hook load is the soft string's off bottom (1e-3,
    measured 2.0e-4), and so is the FE tension, in the vertical section and the lateral within 1e-3 of the hook load
    (measured 2.0e-4 and 9e-5: the two models carry the weight alike), in the build within 1 % (6.1e-3: the stiff
    pipe crosses the hole there, on 12 m elements)."""
    assert main(["static", str(VBH), "--set", "drive.start='off_bottom'", "--set", "beam.elements=250", "--out",
                 str(tmp_path)]) == 0
    assert "hook load" in capsys.readouterr().out
    report = json.loads((tmp_path / "static.json").read_text())
    profiles = xr.load_dataset(tmp_path / "static_profiles.h5", engine="h5netcdf")
    force, middle = profiles["axial_force"].values, profiles["md_element"].values
    soft = profiles["soft_string_tension"].values
    assert report["hook_load"] == pytest.approx(soft[0], rel=1e-3)
    error = abs(force - np.interp(middle, profiles["md"].values, soft)) / report["hook_load"]
    build = (middle > 1000.0) & (middle < 1675.0)
    assert error[(middle < 1000.0) | (middle > 1675.0) & (middle < 2900.0)].max() < 1e-3
    assert error[build].max() < 1e-2
    assert profiles["helical_buckling_load"].values.min() > profiles["sinusoidal_buckling_load"].values.min() > 0
    assert (tmp_path / "static_loads.png").stat().st_size > 10_000
    # the string where it lies, for ParaView: on the well's path, its bit (held on the axis) at the well's depth
    from fenics_drill.model.well import well_of

    path = meshio.read(tmp_path / "static_path.vtu")
    assert path.points.shape == (profiles.sizes["md"], 3)
    bottom = well_of(load_scene(VBH), 3000.0).trajectory.positions([3000.0])[0]
    assert path.points[-1] == pytest.approx(bottom, abs=1e-9)  # v = w = 0 at the bit: the axis, to round-off
    assert path.point_data["lateral_displacement"].max() < 0.03  # within the largest clearance
