"""fenics-drill torque-drag: the files a user opens, the paper's straight horizontal hole as the default well, and a
lock-up said as such."""

import json
import math
from pathlib import Path

import meshio
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
    for name in a:
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
