"""A string whose bit is pressed on bottom in its static state: a velocity drive pushes where the string is light,
the static bit force is the set weight on bit, a weight the string cannot carry is refused with the reason, and a
string compressed beyond its buckling load says so."""

import json

import pytest

from fenics_drill.cli import main


def weightless_vertical(length: float, elements: int, weight_on_bit: float) -> list[str]:
    """A pipe of [beam] in a vertical hole with gravity off (as distributed axial-torsional models pose it), on bottom
    under a velocity drive at ``weight_on_bit`` [N], in the full order."""
    return ["--set", f"beam.length={length}", "--set", f"beam.elements={elements}", "--set", f"well.md=[0.0, {length}]",
            "--set", "well.inclination=[0.0, 0.0]", "--set", "well.azimuth=[0.0, 0.0]", "--set", "model.gravity=false",
            "--set", "drive.mode='velocity'", "--set", "drive.start='on_bottom'",
            "--set", f"drive.weight_on_bit={weight_on_bit}", "--set", "reduction.rule='none'"]


def static_of(tmp_path, capsys, *args) -> tuple[dict, str]:
    assert main(["static", *args, "--out", str(tmp_path / "static")]) == 0
    return json.loads((tmp_path / "static" / "static.json").read_text()), capsys.readouterr().out


def test_a_weightless_string_on_bottom_is_pressed_at_the_set_weight_and_the_top_pushes(tmp_path, capsys):
    """50 m without weight, 20 kN on the bit (below the column's Euler load, 44.7 kN fixed-pinned): the velocity drive
    pushes with the 20 kN the bit takes (nothing else loads the string axially), every element carries 20 kN of
    compression (equilibrium of a weightless rod: round-off only), and the state stands straight off the wall."""
    report, out = static_of(tmp_path, capsys, *weightless_vertical(50.0, 40, 20e3))
    assert report["weight_on_bit"] == 20e3
    assert report["hook_load"] == pytest.approx(-20e3, rel=1e-9)
    assert "the top pushes with 20.00 kN" in out
    import xarray

    profiles = xarray.load_dataset(tmp_path / "static" / "static_profiles.h5", engine="h5netcdf")
    assert profiles["axial_force"].values == pytest.approx(-20e3, rel=1e-9)
    assert report["buckling"]["unstable"] is False and "stands straight" in report["buckling"]["message"]


def test_a_long_weightless_string_pressed_on_bottom_is_said_buckled(tmp_path, capsys):
    """2000 m without weight pressed at 168.48 kN: compressed along its whole length far beyond any buckling load
    (the fixed-pinned column's own is 28 N), the straight state the static solve finds does not stand; the static report says
    where the string is buckled, with its load, and the command ends suspect with that reason."""
    report, out = static_of(tmp_path, capsys, *weightless_vertical(2000.0, 100, 168.48e3))
    buckling = report["buckling"]
    assert buckling["unstable"] and buckling["unstable_mode_count"] > 0
    assert buckling["helically_buckled_length_m"] + buckling["sinusoidally_buckled_length_m"] == pytest.approx(2000.0)
    assert buckling["max_compression_N"] == pytest.approx(168.48e3, rel=1e-9)
    summary = json.loads((tmp_path / "static" / "summary.json").read_text())
    assert summary["status"] == "suspect" and any("does not stand" in r for r in summary["suspect_reasons"])
    assert "suspect: the string is compressed beyond its buckling load in the hole" in out
