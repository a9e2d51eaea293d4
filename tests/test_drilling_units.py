"""Drilling quantities as drilling engineers write them (fenics_drill/units.py): mixed numbers, marks, thousands,
revolutions, oilfield spellings, each read to the SI number of its definition (NIST SP 811: 1 in = 0.0254 m,
1 ft = 0.3048 m, 1 lb = 0.45359237 kg, 1 lbf = 4.4482216152605 N, 1 US gal = 3.785411784e-3 m^3); what is ambiguous
refused in one line naming the key; and the checks of a scene that need no solve run by ``fenics-drill scene``."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

import fenics_drill as fd
from fenics_drill.cli import main
from fenics_drill.scene import SceneError, load_scene
from fenics_drill.units import UnitError, read_number, read_quantity

ROOT = Path(__file__).parents[1]
INCH, FOOT, LBF, LB, GALLON = 0.0254, 0.3048, 4.4482216152605, 0.45359237, 3.785411784e-3

#: (written, SI unit of the key, the SI value by the definitions above); exact definitions: round-off only.
SPELLINGS = [
    ("8 1/2 in", "m", 8.5 * INCH),
    ("9 5/8 in", "m", 9.625 * INCH),
    ("13 3/8 in", "m", 13.375 * INCH),
    ("8-1/2 in", "m", 8.5 * INCH),
    ("8\u00bd in", "m", 8.5 * INCH),
    ("3/4 in", "m", 0.75 * INCH),
    ('4 1/4"', "m", 4.25 * INCH),
    ('4.25"', "m", 4.25 * INCH),
    ("4.25''", "m", 4.25 * INCH),
    ("8.5 IN", "m", 8.5 * INCH),
    ("12'", "m", 12 * FOOT),
    ("12' 6\"", "m", 12 * FOOT + 6 * INCH),
    ("\u22125 m", "m", -5.0),
    ("5 000 N m", "N m", 5000.0),
    ("5\u202f000 N m", "N m", 5000.0),
    ("1 200 kg/m^3", "kg/m^3", 1200.0),
    ("40 000 N", "N", 40000.0),
    ("1,234,567 N", "N", 1234567.0),
    ("1,200.5 N", "N", 1200.5),
    ("0,3", "dimensionless", 0.3),
    ("12,25 in", "m", 12.25 * INCH),
    ("120 1/min", "rad/s", 4 * math.pi),
    ("120 min^-1", "rad/s", 4 * math.pi),
    ("120 min\u207b\u00b9", "rad/s", 4 * math.pi),
    ("2 Hz", "rad/s", 4 * math.pi),
    ("120 RPM", "rad/s", 4 * math.pi),
    ("120 rev/min", "rad/s", 4 * math.pi),
    ("120 r/min", "rad/s", 4 * math.pi),
    ("12.566370614359172 rad/s", "rad/s", 4 * math.pi),
    ("5 kN.m", "N m", 5000.0),
    ("5 kN\u00b7m", "N m", 5000.0),
    ("5000 Nm", "N m", 5000.0),
    ("5 kft-lbf", "N m", 5000 * FOOT * LBF),
    ("3700 ft-lbf", "N m", 3700 * FOOT * LBF),
    ("3700 ft-lb", "N m", 3700 * FOOT * LBF),  # a mass where a torque is asked: its weight
    ("40 klb", "N", 40e3 * LBF),
    ("40 klbf", "N", 40e3 * LBF),
    ("40 kips", "N", 40e3 * LBF),
    ("4 tf", "N", 4000 * 9.80665),
    ("10 t", "N", 10000 * 9.80665),
    ("5 tonf_us", "N", 10000 * LBF),
    ("50 fph", "m/s", 50 * FOOT / 3600),
    ("15 m/h", "m/s", 15 / 3600),
    ("78 pcf", "kg/m^3", 78 * LB / FOOT**3),
    ("10.4 ppg", "kg/m^3", 10.4 * LB / GALLON),
    ("1.25 g/cm3", "kg/m^3", 1250.0),
    ("1.2 sg", "kg/m^3", 1200.0),
]


@pytest.mark.parametrize("written, unit, si", SPELLINGS)
def test_each_spelling_is_its_si_value(written, unit, si):
    assert read_quantity(written, unit) == pytest.approx(si, rel=1e-13, abs=1e-15)


def test_the_issues_own_numbers():
    assert read_quantity("8 1/2 in", "m") == pytest.approx(0.2159, rel=1e-14)
    assert read_quantity("9 5/8 in", "m") == pytest.approx(0.244475, rel=1e-14)
    assert read_quantity("120 1/min", "rad/s") == pytest.approx(4 * math.pi, rel=1e-14)
    assert read_quantity("5 000 N m", "N m") == 5000.0
    assert read_quantity("40 klb", "N") == pytest.approx(177.93e3, rel=3e-5)  # 177.93 kN to its 5 digits


@pytest.mark.parametrize("written, unit, words", [
    ("1,200", "dimensionless", "ambiguous"),            # a thousand two hundred, or one point two
    ("1,200 kg/m^3", "kg/m^3", "ambiguous"),
    ("4 tonf", "N", "tonf_us, tonf_uk or tf"),          # short, long or metric
    ("2 ton", "N", "differ by 12 %"),
    ("17 deg", "dimensionless", "plain number"),        # an angle for a friction coefficient
    ("30 %", "dimensionless", "plain number"),
    ("5 00 N", "N", "groups of three digits"),
    ("8 3/2 in", "m", "not a mixed number"),
    ("1/0 in", "m", "denominator 0"),
    ("120 m", "rad/s", "is not a quantity in rad/s"),
    ("5 furlongz", "m", "unknown unit 'furlongz'"),
    ("inf m", "m", "expected a number"),
    ("1,234,5 N", "N", "commas both"),
])
def test_ambiguous_or_wrong_values_are_refused_with_the_reason(written, unit, words):
    with pytest.raises(UnitError, match=words):
        read_quantity(written, unit)


def test_plain_numbers_as_files_write_them():
    assert read_number("5 000") == 5000.0 and read_number("-12.5") == -12.5 and read_number("1/2") == 0.5
    assert read_number("45,5", decimal_comma=True) == 45.5 and read_number("1,200", decimal_comma=True) == 1.2
    with pytest.raises(UnitError, match="plain number"):
        read_number("5 m")


@pytest.mark.parametrize("override, words", [
    ('contact.friction="1,200"', "contact.friction = '1,200' is not admissible: '1,200' is ambiguous"),
    ('contact.friction="17 deg"', "contact.friction = '17 deg' is not admissible"),
    ('drive.weight_on_bit="4 tonf"', "drive.weight_on_bit = '4 tonf' is not admissible"),
    ('bit_rock.bit_radius="4 3/2 in"', "bit_rock.bit_radius = '4 3/2 in' is not admissible"),
])
def test_an_ambiguous_scene_value_is_refused_in_one_line_naming_the_key(capsys, override, words):
    assert main(["scene", "--set", override]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err, err


def test_a_decimal_comma_and_thousands_reach_the_scene():
    scene = load_scene(None, ["contact.friction=0,3", 'drive.weight_on_bit="40 000 N"',
                              'drive.rotation_speed="120 1/min"', 'torque_drag.torque_on_bit="5 000 N m"'])
    assert scene.contact.friction == 0.3 and scene.drive.weight_on_bit == 40e3
    assert scene.drive.rotation_speed == pytest.approx(4 * math.pi, rel=1e-15)
    assert scene.torque_drag.torque_on_bit == 5000.0


MIXED = """
[well]
md = [0.0, 300.0, 600.0]
inclination = [0.0, 0.0, 30.0]
azimuth = [0.0, 0.0, 45.0]
hole_bottom = [{casing_shoe}, 600.0]
hole_radius = [{casing}, {hole}]
hole_cased = [true, false]

[fluid]
density = {mud}

[bit_rock]
law = "detournay"
bit_radius = {bit}

[drive]
weight_on_bit = {wob}
rotation_speed = {speed}

[[string.sections]]
name = "collars"
length = {collar_length}
{collar}

[[string.sections]]
name = "drill pipe"
length = 510.0
{pipe}
tool_joint_length = 0.45
tool_joint_spacing = 9.4
"""


def test_a_scene_written_as_the_rig_writes_it_is_the_scene_written_in_si(tmp_path):
    """The same well and string written in drilling units (mixed numbers, feet, ppg, klbf, 1/min) and in SI: every
    field of the two validated scenes is the same number (to round-off: the conversions are exact definitions)."""
    drilling = MIXED.format(casing_shoe=f'"{300 / FOOT!r} ft"', casing='"4.3405 in"',
                            hole='"4 1/4 in"', mud='"10.4 ppg"', bit='"4 1/4 in"', wob='"9 klbf"',
                            speed='"120 1/min"', collar_length='"295 1/4 ft"',
                            collar='outer_diameter = "6 3/4 in"\ninner_diameter = "2 13/16 in"',
                            pipe='outer_diameter = "5 in"\ninner_diameter = "4.276 in"\n'
                                 'tool_joint_outer_diameter = "6 5/8 in"')
    si = MIXED.format(casing_shoe=300.0, casing=4.3405 * INCH, hole=4.25 * INCH, mud=10.4 * LB / GALLON,
                      bit=4.25 * INCH, wob=9000 * LBF, speed=4 * math.pi, collar_length=295.25 * FOOT,
                      collar=f"outer_radius = {3.375 * INCH!r}\ninner_radius = {1.40625 * INCH!r}",
                      pipe=f"outer_radius = {2.5 * INCH!r}\ninner_radius = {2.138 * INCH!r}\n"
                           f"tool_joint_outer_radius = {3.3125 * INCH!r}")
    (tmp_path / "drilling.toml").write_text(drilling)
    (tmp_path / "si.toml").write_text(si)
    a, b = (load_scene(tmp_path / name).to_dict() for name in ("drilling.toml", "si.toml"))

    def same(x, y, where):
        if isinstance(x, dict):
            assert set(x) == set(y), where
            for k in x:
                same(x[k], y[k], f"{where}.{k}")
        elif isinstance(x, (list, tuple)):
            assert len(x) == len(y), where
            for k, (u, v) in enumerate(zip(x, y)):
                same(u, v, f"{where}[{k}]")
        elif isinstance(x, float):
            assert x == pytest.approx(y, rel=1e-14, abs=1e-15), where
        else:
            assert x == y, where

    same(a, b, "scene")


def test_a_bound_broken_by_a_value_written_with_a_unit_quotes_what_was_written(capsys):
    """A collar's tool joint smaller than its body: the refusal names both diameters as they were written."""
    collar = ('{length = 10.0, outer_diameter = "6 3/4 in", inner_radius = 0.03, tool_joint_outer_diameter = '
              '"6 1/2 in", tool_joint_length = 0.4, tool_joint_spacing = 9.0}')
    assert main(["scene", "--set", f"string.sections=[{collar}]"]) == 2
    err = capsys.readouterr().err.strip()
    assert "outer_diameter was written '6 3/4 in'" in err and "tool_joint_outer_diameter was written '6 1/2 in'" \
        in err and len(err.splitlines()) == 1, err
    assert main(["scene", "--set", 'beam.outer_radius="1 1/2 in"']) == 2
    assert "beam.outer_radius was written '1 1/2 in'" in capsys.readouterr().err


# --- the well's files and geometry ---------------------------------------------------------------------------------

WELL = """
[well]
survey = "survey.csv"
{hole}

[fluid]
density = 1200.0

[[string.sections]]
name = "collars"
length = 60.0
outer_diameter = "6 3/4 in"
inner_diameter = "2 13/16 in"

[[string.sections]]
name = "drill pipe"
length = {pipe}
outer_diameter = "5 in"
inner_diameter = "4.276 in"
"""
VERTICAL_900 = "md,inclination,azimuth\n0,0,0\n900,0,0\n"
DEVIATED_900 = "md,inclination,azimuth\n0,0,0\n300,0,0\n900,60,0\n"


def well_files(folder: Path, survey: str = VERTICAL_900, pipe: float = 840.0, hole: str = "", extra: str = "") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "survey.csv").write_text(survey)
    (folder / "well.toml").write_text(WELL.format(hole=hole, pipe=pipe) + extra)
    return folder / "well.toml"


def test_a_survey_is_read_beside_its_scene_file_from_any_working_directory(tmp_path, monkeypatch):
    """A vertical 900 m survey beside the scene, a deviated one of the same name in the working directory: the scene
    reads its own (TVD 900 m), through the API and the command line; a survey given with --set is the working
    directory's."""
    scene_file = well_files(tmp_path / "well")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "survey.csv").write_text(DEVIATED_900)
    monkeypatch.chdir(elsewhere)
    scene = fd.load_scene(Path("..") / "well" / "well.toml")
    assert Path(scene.well.survey) == tmp_path / "well" / "survey.csv"
    result = subprocess.run([sys.executable, "-m", "fenics_drill.cli", "torque-drag", "../well/well.toml", "--out",
                             "td"], capture_output=True, text=True, timeout=120, cwd=elsewhere)
    assert result.returncode == 0, result.stderr
    tvd = json.loads((elsewhere / "td" / "torque_drag.json").read_text())["well"]["true_vertical_depth_m"]
    assert tvd == pytest.approx(900.0, rel=1e-12)
    overridden = fd.load_scene(Path("..") / "well" / "well.toml", ["well.survey='survey.csv'"])
    assert Path(overridden.well.survey) == elsewhere / "survey.csv"


def test_depths_written_in_feet_meet_metres_within_their_round_off(tmp_path, capsys):
    """A survey in feet to two decimals ends at 2952.76 ft = 900.0012 m: a 900 m string and hole_bottom = [900]
    are the same depth (the feet's round-off is 1.5 mm)."""
    survey = "MD (ft),Inc (deg),Azi (deg)\n0,0,0\n984.25,0,0\n2952.76,60,0\n"
    scene = well_files(tmp_path, survey, hole='hole_bottom = [900.0]\nhole_radius = ["4 1/4 in"]')
    assert main(["scene", str(scene)]) == 0
    assert "above the well's bottom" not in capsys.readouterr().out


def test_survey_columns_as_vendors_name_them(tmp_path, capsys):
    """A grid azimuth beside the true one is left out with a note; a grid azimuth alone is refused (it needs the grid
    convergence); ``Azim True (deg)`` is the azimuth, and a semicolon file's decimal commas are read."""
    both = "MD (m);Inc (deg);Azi (grid);Azim True (deg)\n0;0;0;0\n300;0;12,5;10,0\n900;60,0;12,5;10,0\n"
    scene = well_files(tmp_path / "both", both)
    assert main(["scene", str(scene)]) == 0
    out = capsys.readouterr().out
    assert "column 'Azi (grid)' left out, 'Azim True (deg)' read as the azimuth" in out
    survey = fd.load_scene(scene)
    from fenics_drill.model.well import well_of

    well = well_of(survey, 900.0)
    assert math.degrees(well.trajectory.survey.azimuth[-1]) == pytest.approx(10.0, rel=1e-12)
    grid_only = "MD (m),Inc (deg),Azi (grid)\n0,0,0\n300,0,12\n900,60,12\n"
    assert main(["scene", str(well_files(tmp_path / "grid", grid_only))]) == 2
    err = capsys.readouterr().err
    assert "referred to grid north" in err and len(err.strip().splitlines()) == 1


def test_a_bit_smaller_than_its_bha_is_refused_with_the_numbers(tmp_path, capsys):
    scene = well_files(tmp_path, extra='\n[bit_rock]\nlaw = "detournay"\nbit_radius = "1 1/2 in"\n')
    assert main(["scene", str(scene)]) == 2
    err = capsys.readouterr().err
    assert "the bit must pass its BHA" in err and "(collars) is 0.085725 m in radius (6.75 in across)" in err


def test_a_string_shorter_than_its_well_says_where_the_bit_is(tmp_path, capsys):
    scene = well_files(tmp_path, pipe=740.0)  # an 800 m string in a 900 m well
    assert main(["torque-drag", str(scene), "--out", str(tmp_path / "td")]) == 0
    out = capsys.readouterr().out
    assert "note: the bit is 100 m above the well's bottom" in out
    summary = json.loads((tmp_path / "td" / "summary.json").read_text())
    assert summary["bit_above_well_bottom_m"] == pytest.approx(100.0, rel=1e-12)
    assert main(["scene", str(scene)]) == 0 and "the bit is 100 m above" in capsys.readouterr().out


def test_the_scene_command_refuses_what_the_commands_refuse(tmp_path, capsys):
    """A hook-load drive's weight on bit beyond the string's buoyed weight: refused by ``scene`` as by ``static``
    (the same check, before any solve); ``modal.weight_on_bit`` is checked alike."""
    scene = well_files(tmp_path, hole='hole_bottom = [900.0]\nhole_radius = ["4 1/4 in"]',
                       extra='\n[drive]\nmode = "hook_load"\n[bit_rock]\nlaw = "detournay"\nbit_radius = "4 1/4 in"\n')
    for key in ("drive.weight_on_bit", "modal.weight_on_bit"):
        assert main(["scene", str(scene), "--set", f'{key}="1e6 kN"']) == 2
        err = capsys.readouterr().err
        assert f"{key} = 1e+09 N is not admissible with drive.mode = 'hook_load'" in err, err


def test_a_drive_in_a_well_starts_on_bottom_and_the_paper_scene_off(tmp_path):
    scene = fd.load_scene(well_files(tmp_path))
    assert scene.drive.mode == "velocity" and scene.starts_on_bottom
    assert not fd.load_scene(None).starts_on_bottom


# --- the output directory: only what the command writes is the command's -------------------------------------------


def test_a_users_file_written_while_a_command_runs_survives_overwrite(tmp_path, capsys, monkeypatch):
    """A user saves notes into the output folder while ``static`` runs: the command does not take them for its own,
    and the next ``--overwrite`` leaves them and says so."""
    import fenics_drill.studies.run as run

    out = tmp_path / "static"
    prepare = run.prepare

    def users_notes_meanwhile(*args, **kwargs):
        (out / "field_notes.txt").write_text("the user's notes")
        return prepare(*args, **kwargs)

    monkeypatch.setattr(run, "prepare", users_notes_meanwhile)
    small = ["--set", "beam.length=20", "--set", "beam.elements=40"]
    assert main(["static", str(ROOT / "demos" / "scenes" / "paper.toml"), *small, "--out", str(out)]) == 0
    monkeypatch.setattr(run, "prepare", prepare)
    record = json.loads((out / ".fenics-drill-files.json").read_text())["files"]
    assert "field_notes.txt" not in record
    capsys.readouterr()
    code = main(["static", str(ROOT / "demos" / "scenes" / "paper.toml"), *small, "--overwrite", "--out", str(out)])
    assert code == 2 and "field_notes.txt" in capsys.readouterr().err
    assert (out / "field_notes.txt").read_text() == "the user's notes"
