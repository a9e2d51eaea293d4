"""Every finite-element command on a well given by its survey, with a string of sections in mud through a cased and
an open hole: each ends "finished" (or "suspect" for a mesh the scene chose coarse) with the well's loads."""

import json

import pytest

from fenics_drill.cli import main

from tests.conftest import expected_status

WELL = """
[beam]
elements = 100

[well]
md = [0.0, 40.0, 100.0]
inclination = [0.0, 0.0, 45.0]
azimuth = [0.0, 0.0, 30.0]
hole_bottom = [50.0, 100.0]
hole_radius = [0.112, 0.108]
hole_cased = [true, false]

[fluid]
density = 1200.0

[drive]
start = "off_bottom"  # hanging: the hook holds the string's weight

[[string.sections]]
name = "collar"
length = 20.0
outer_radius = 0.0857
inner_radius = 0.0357

[[string.sections]]
name = "drill pipe"
length = 80.0
outer_radius = 0.0635
inner_radius = 0.0543
tool_joint_outer_radius = 0.084
tool_joint_length = 0.45
tool_joint_spacing = 9.4
"""


@pytest.fixture
def well_scene(tmp_path):
    path = tmp_path / "well.toml"
    path.write_text(WELL)
    return path


def summary(directory):
    return json.loads((directory / "summary.json").read_text())


def test_run_modal_and_campbell_work_on_a_well(well_scene, tmp_path):
    """A 0.05 s run holds the string up with about its static hook load (the drive's multiplier, within 5 %: the
    string is set spinning and fed from rest), and closes its energy budget (1e-3); the modal analysis and the
    Campbell sweep finish on the same string.  (Measured: 39.7 kN at rest, 38.3 kN at 0.05 s; budget 5.5e-4.)"""
    from fenics_drill.scene import load_scene

    scene = load_scene(well_scene, ["time.t_end=0.05"])
    out = tmp_path / "run"
    assert main(["run", str(well_scene), "--set", "time.t_end=0.05", "--quiet", "--out", str(out)]) == 0
    run = summary(out)
    assert run["status"] == expected_status(scene)
    hook = run["static"]["hook_load"]
    assert hook > 0.5 * run["static"]["weight"]  # a string hanging in a 45 deg well: most of its weight at the hook
    assert run["torque_and_drag"]["hook_load"]["last"] == pytest.approx(hook, rel=0.05)
    assert abs(run["energy"]["balance_error"]) < 1e-3
    assert main(["modal", str(well_scene), "--out", str(tmp_path / "modal")]) == 0
    assert summary(tmp_path / "modal")["status"] in ("finished", "suspect")
    # the modes about the static state in the well, the three spectra labelled, and their figure
    modes = json.loads((tmp_path / "modal" / "modes.json").read_text())
    assert modes["linearised_about"]["state"] == "static"
    assert set(modes["spectra"]) == {"free_free", "drive_held_bit_off_bottom", "drive_held_bit_stuck"}
    assert modes["spectra"]["drive_held_bit_stuck"]["held"] == ["u(0)", "theta_x(0)", "theta_x(L)"]
    torsional = [m["frequency_hz"] for m in modes["spectra"]["drive_held_bit_off_bottom"]["modes"]
                 if m["kind"] == "torsional"]
    # the period is 1 / f of the same float: round-off of one division
    assert modes["first_torsional_period_s"] == pytest.approx(1 / torsional[0], rel=1e-12)
    assert len(modes["lateral_critical_speeds_rpm"]) == 3
    assert (tmp_path / "modal" / "modes.png").stat().st_size > 0
    assert main(["campbell", str(well_scene), "--set", "campbell.rotation_speed=[0.0, 6.0, 3]",
                 "--out", str(tmp_path / "campbell")]) == 0
    assert summary(tmp_path / "campbell")["status"] in ("finished", "suspect")
