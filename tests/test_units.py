"""Drilling units through pint (fenics_drill/units.py): values written with their unit are the SI numbers of
their definitions (NIST SP 811: 1 in = 0.0254 m, 1 lb = 0.45359237 kg, 1 US gal = 3.785411784e-3 m^3), SI numbers
keep working, and a unit that is unknown or of the wrong dimension is refused in one line naming the key."""

import math

import pytest

from fenics_drill.cli import main
from fenics_drill.scene import SceneError, load_scene


def test_drilling_units_are_their_si_definitions():
    scene = load_scene(None, ['drive.rotation_speed="120 rpm"', 'drive.axial_velocity="15 m/h"',
                              'fluid.density="10.4 ppg"', 'beam.outer_radius="2.5 in"', 'drive.weight_on_bit="20 kN"',
                              'torque_drag.rate_of_penetration="60 ft/h"'])
    # exact definitions: round-off only
    assert scene.drive.rotation_speed == pytest.approx(4 * math.pi, rel=1e-15)
    assert scene.drive.axial_velocity == pytest.approx(15 / 3600, rel=1e-15)
    assert scene.fluid.density == pytest.approx(10.4 * 0.45359237 / 3.785411784e-3, rel=1e-14)
    assert round(scene.fluid.density, 1) == 1246.2
    assert scene.beam.outer_radius == pytest.approx(0.0635, rel=1e-15)
    assert scene.drive.weight_on_bit == 20e3
    assert scene.torque_drag.rate_of_penetration == pytest.approx(60 * 0.3048 / 3600, rel=1e-15)
    assert load_scene(None, ["drive.rotation_speed=2.5"]).drive.rotation_speed == 2.5  # SI numbers as before
    from fenics_drill.units import read_quantity

    assert read_quantity("5 in", "m") == pytest.approx(0.127, rel=1e-15)
    assert read_quantity("10.4 ppg", "kg/m^3") == pytest.approx(1246.1948, rel=1e-7)


def test_sections_take_diameters_and_units():
    pipe = ('{name = "drill pipe", length = "1000 ft", outer_diameter = "5 in", inner_diameter = "4.276 in", '
            'tool_joint_outer_diameter = "6.625 in", tool_joint_length = "18 in", tool_joint_spacing = "31 ft"}')
    scene = load_scene(None, [f"string.sections=[{pipe}]"])
    section = scene.string.sections[0]
    assert section["outer_radius"] == pytest.approx(0.0635, rel=1e-15)
    assert section["inner_radius"] == pytest.approx(4.276 * 0.0254 / 2, rel=1e-15)
    assert section["tool_joint_outer_radius"] == pytest.approx(6.625 * 0.0254 / 2, rel=1e-15)
    assert section["length"] == pytest.approx(304.8, rel=1e-15)
    both = '{length = 10.0, outer_radius = 0.0635, outer_diameter = "5 in", inner_radius = 0.05}'
    with pytest.raises(SceneError, match="outer_diameter and outer_radius are not admissible together"):
        load_scene(None, [f"string.sections=[{both}]"])


@pytest.mark.parametrize("override, words", [
    ('drive.rotation_speed="120 m"', "is not a quantity in rad/s"),
    ('drive.rotation_speed="120 furlongz"', "unknown unit 'furlongz'"),
    ('fluid.density="10.4 psi"', "is not a quantity in kg/m^3"),
    ('beam.elements="5 in"', "expected an integer"),
    ('string.sections=[{length = 10.0, outer_diameter = "5 rpm", inner_radius = 0.05}]', "is not a quantity in m"),
])
def test_a_unit_unknown_or_of_another_dimension_is_refused_in_one_line(capsys, override, words):
    assert main(["scene", "--set", override]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err, err


def test_the_scene_command_prints_si_with_the_unit_written(capsys):
    assert main(["scene", "--set", 'drive.rotation_speed="60 rpm"']) == 0
    line = next(li for li in capsys.readouterr().out.splitlines() if li.startswith("rotation_speed = 6.28"))
    assert "(written '60 rpm')" in line


def test_an_eight_and_a_half_inch_bit_drills_the_wells_own_hole():
    """The VBH demo well's hole at the bit is 0.108 m: an 8 1/2 in bit (0.10795 m) is admissible there, whatever
    [borehole] says, and the keys of the one pipe and hole the well replaces are marked unused."""
    from fenics_drill.scene import unused_keys

    scene = load_scene("demos/scenes/well_vbh.toml", ['bit_rock.law="detournay"', 'bit_rock.bit_radius="4.25 in"'])
    assert scene.bit_rock.bit_radius == pytest.approx(0.10795, rel=1e-15)
    assert {"beam.length", "beam.outer_radius", "borehole.radius"} <= unused_keys(scene)
    with pytest.raises(SceneError, match=r"well.hole_radius\[2\] \(the hole at the bit\)"):
        load_scene("demos/scenes/well_vbh.toml", ['bit_rock.law="detournay"', 'bit_rock.bit_radius="5 in"'])
