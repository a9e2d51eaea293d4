"""A string whose bit is pressed on bottom in its static state: a velocity drive pushes where the string is light,
the static bit force is the set weight on bit, a weight the string cannot carry is refused with the reason, and a
string compressed beyond its buckling load says so."""

import json
import math

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


def test_an_axial_torsional_string_on_bottom_keeps_the_steady_cutting_load():
    """2000 m of drill pipe without weight in a vertical hole, axial-torsional (``model.lateral_length = 0``), on
    bottom under a velocity drive at V0 = 36 m/h and 60 rpm with the cutting law: set at the steady cutting load of
    that rate and speed, W = zeta eps a d + sigma a l with d = 2 pi V0 / Omega (the closed form of the law, 46.66 kN),
    the bit force keeps its mean over 1 s within 5 % of it (measured +4.0 %: the torsional wave reaches the bit after
    0.6 s, so the bit has barely started turning), and the lateral fields stay zero."""
    import numpy as np
    import xarray

    import fenics_drill as fd

    v0, omega, a = 0.01, 2 * math.pi, 0.108
    scene = fd.load_scene(None, [
        "beam.length=2000.0", "beam.elements=40", "beam.outer_radius=0.0635", "beam.inner_radius=0.0543",
        "well.md=[0.0, 2000.0]", "well.inclination=[0.0, 0.0]", "well.azimuth=[0.0, 0.0]", "borehole.radius=0.11",
        "model.gravity=false", "model.lateral_length=0.0", "bit_rock.law='detournay'", f"bit_rock.bit_radius={a}",
        "drive.mode='velocity'", "drive.start='on_bottom'", f"drive.axial_velocity={v0}", f"drive.rotation_speed={omega}",
        "time.t_end=1.0", "output.field_interval=0"])
    bit = scene.bit_rock
    steady = (bit.cutting_orientation * bit.specific_energy * a * 2 * math.pi * v0 / omega
              + bit.contact_strength * a * bit.wear_flat_length)
    scene = scene.with_changes(drive={"weight_on_bit": steady})
    run = fd.run(scene)
    series = run.series
    t, force = series["time"].values, series["bit_force"].values
    mean = -np.trapezoid(force, t) / (t[-1] - t[0])  # the rock's push on the bit, compression > 0
    assert run.summary["status"] == "finished", run.summary.get("suspect_reasons")
    assert abs(mean / steady - 1.0) < 0.05, mean / steady
    assert np.all(series["section_v"].values == 0.0) and np.all(series["section_w"].values == 0.0)
