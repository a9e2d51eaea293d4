"""Scene files: defaults, overrides and refusal of bad input with a precise message."""

import math
from pathlib import Path

import pytest

from fenics_drill.cli import main
from fenics_drill.scene import SceneError, load_scene, parse_override

PAPER = Path(__file__).parents[1] / "demos" / "scenes" / "paper.toml"


def test_paper_scene_holds_tables_1_to_3():
    s = load_scene(PAPER)
    assert s.beam.length == 100.0 and s.beam.elements == 500
    assert s.beam.young_modulus == 203e9 and s.beam.density == 7900.0
    assert s.borehole.radius == 95e-3
    assert s.contact.stiffness_cubic == 1e16 and s.bit_rock.rate == 400.0
    assert math.isclose(s.drive.axial_velocity * 3600, 20.0)
    assert math.isclose(s.drive.rotation_speed, 2 * math.pi)


def test_overrides_are_toml_values():
    s = load_scene(PAPER, ["beam.length=50", "model.supports=pinned", "model.contact=false",
                           "reduction.rule='count'", "reduction.flexural=4", "reduction.torsional=2",
                           "reduction.axial=1"])
    assert s.beam.length == 50.0 and isinstance(s.beam.length, float)
    assert s.model.supports == "pinned" and s.model.contact is False
    assert parse_override("optimize.rotation_speed=[4.7,7.3,5]") == ("optimize", "rotation_speed", [4.7, 7.3, 5])


@pytest.mark.parametrize(
    "override, words",
    [
        ("beam.length=-1", ["beam.length", "-1", "(0, 20000]"]),
        ("beam.length=abc", ["beam.length", "abc", "number"]),
        ("beam.inner_radius=0.09", ["beam.inner_radius", "0.09", "beam.outer_radius"]),
        ("borehole.radius=0.07", ["borehole.radius", "0.07", "beam.outer_radius"]),
        ("beam.poisson_ratio=0.5", ["beam.poisson_ratio", "0.5", "(-1, 0.5)"]),
        ("beam.elements=0", ["beam.elements", "0", ">= 2"]),
        ("beam.elements=2.5", ["beam.elements", "2.5", "integer"]),
        ("beam.colour=3", ["beam.colour", "unknown key"]),
        ("cheese.length=3", ["cheese", "unknown section"]),
        ("model.supports=glued", ["model.supports", "glued", "paper, pinned"]),
        ("model.contact=1", ["model.contact", "true or false"]),
        ("reduction.rule=band", ["reduction.flexural", "-1.0", "band"]),
    ],
)
def test_bad_input_is_refused_naming_key_value_and_range(override, words):
    with pytest.raises(SceneError) as err:
        load_scene(PAPER, [override])
    for word in words:
        assert word in str(err.value)


def test_cli_reports_scene_errors_before_computing(tmp_path, capsys):
    code = main(["modal", str(PAPER), "--set", "beam.inner_radius=0.1", "--out", str(tmp_path)])
    assert code == 2
    assert "beam.inner_radius" in capsys.readouterr().err
    assert not (tmp_path / "modes.json").exists()


@pytest.mark.parametrize(
    "overrides, words",
    [
        (["drive.mode=hook_load", "drive.weight_on_bit=30e3"], ["drive.weight_on_bit", "30000.0", "limit_force"]),
        (["drive.mode=hook_load", "model.bit_rock=false"], ["hook_load", "model.bit_rock"]),
        (["bit_rock.law=detournay", "bit_rock.bit_radius=0.2"], ["bit_rock.bit_radius", "0.2", "borehole.radius"]),
        (["drive.controller=fast"], ["drive.controller", "fast", "stiff, pi, soft_torque"]),
        (["model.lateral_length=0", "contact.static_friction=0.1"], ["contact.static_friction", "0.1", ">= "
                                                                     "contact.friction"]),
        (["contact.static_friction=0.4"], ["contact.static_friction", "model.lateral_length", "lateral wall"]),
    ],
)
def test_drives_and_bit_laws_that_cannot_work_are_refused(overrides, words):
    """A hook load the paper's law (20) cannot hold (W >= Gamma_BR: the bit would accelerate without bound),
    a pushed string with nothing at the bit, a bit wider than its hole, a static wall friction below the kinetic
    one, or one asked of the lateral wall (which has one factor)."""
    with pytest.raises(SceneError) as err:
        load_scene(PAPER, overrides)
    for word in words:
        assert word in str(err.value)
