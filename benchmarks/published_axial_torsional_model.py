"""Aarsnes & van de Wouw's published distributed axial-torsional model on bottom, side by side with the
axial-torsional string: benchmarks/results/published_axial_torsional_model.md.

    python benchmarks/published_axial_torsional_model.py --published-series DIR [--elements 200]

Their model (github.com/ulfjakob/AxialTorsionalDrillString, "Coupled - nondim": parameters.m, runSim.m,
waveStepUpwind.m; MATLAB, not run here) is a uniform string as axial and torsional wave guides in nondimensional form,
solved by first-order upwinding: length 1, torsional wave speed 1, axial c_a / c_t = 1.6, viscous damping
k = -ln(eta) on both, the top held at (v0, omega0), the cutting law at the bit with its delay (the depth of cut per
blade, d = u(t) - u(t - t_N), t_N one blade passage, as a transport in the bit's angle), d K_a and d the cutting
weight and torque, a wear-flat contact of weight Wf and torque beta Wf that sticks, and a torsional stick below a spin
of 0.02.  Their MAIN.m runs K_a = 20, eta = 0.7, beta = 0.1, Wf = 200, v0 = 2 and omega0 = 1 for 120 time units.

DIR holds their runs as CSV files ``omega0_<omega0>.csv`` (columns: t, the bit's velocity, its spin, from runSim's
y(4,:) and y(5,:)).  Without DIR this string's runs alone are reported.

The string here (:func:`scene_of`): 2000 m of 5 in drill pipe (E = 210 GPa, nu = 0.28: c_a / c_t = 1.6), vertical,
without gravity (their model has none), a 4-blade bit of 0.108 m radius, zeta = 1, l = 1.2 mm, mu = 0.5; the
scales of their groups are t* = L / c_t, the angle of one blade passage 2 pi / n, the depth U* that makes their
cutting torque d, U* = 2 G J (2 pi / n) / (L eps a^2 n), the weight E A U* / L and the torque G J (2 pi / n) / L,
from which eps, sigma and gamma follow.  Its bit turned backwards is held (``bit_rock.backward_spin = 'held'``), as
theirs sticks.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from speed import processor  # noqa: E402
from torsional_waves import axial_torsional_stick_slip, limit_cycle_statistics  # noqa: E402

import fenics_drill as fd  # noqa: E402
from fenics_drill.model.forces.cutting_bit import HELD_BACKWARD_DAMPING  # noqa: E402
from fenics_drill.studies.stick_slip import start  # noqa: E402

#: Their MAIN.m's case: the cutting weight per depth, damping per time unit, contact torque arm, contact weight, v0.
K_A, ETA, BETA, WEAR_FLAT, V0 = 20.0, 0.7, 0.1, 200.0, 2.0
#: The set spins compared (their first, and their second at the same v0), and the time units run and skipped.
SPINS, DURATION, AFTER = (1.0, 1.8), 120.0, 60.0
#: The exact characteristics' torsional cell [m] (the axial one 1.6 times it: 1 m).
CELL = 0.625
#: The dimensional string (module doc).
LENGTH, OUTER, INNER, YOUNG, POISSON, DENSITY = 2000.0, 0.127, 0.1086, 210e9, 0.28, 7850.0
BLADES, RADIUS, ZETA, FLAT_LENGTH, MU = 4, 0.108, 1.0, 1.2e-3, 0.5


def scales() -> dict:
    """The dimensional scales of their groups for this string (module doc): time, velocity, spin, depth, weight."""
    shear = YOUNG / (2.0 * (1.0 + POISSON))
    speed = math.sqrt(shear / DENSITY)
    polar = math.pi / 32.0 * (OUTER**4 - INNER**4)
    area = math.pi / 4.0 * (OUTER**2 - INNER**2)
    passage = 2.0 * math.pi / BLADES
    energy = K_A * YOUNG * area / (ZETA * RADIUS * BLADES * LENGTH)  # eps from K_a = zeta eps a n L / (E A)
    depth = 2.0 * shear * polar * passage / (LENGTH * energy * RADIUS**2 * BLADES)
    weight, torque = YOUNG * area * depth / LENGTH, shear * polar * passage / LENGTH
    t_star = LENGTH / speed
    return {"time": t_star, "velocity": depth / t_star, "spin": passage / t_star, "depth": depth, "weight": weight,
            "torque": torque, "specific_energy": energy}


def scene_of(omega0: float, elements: int):
    """Their case at ``omega0`` as a scene of this string (module doc)."""
    s = scales()
    contact = WEAR_FLAT * s["weight"]  # sigma a l
    text = f"""
[well]
md = [0.0, {LENGTH}]
inclination = [0.0, 0.0]
azimuth = [0.0, 0.0]
hole_bottom = [{LENGTH}]
hole_radius = [{RADIUS}]
hole_cased = [false]
[[string.sections]]
name = "drill pipe 5 in"
length = {LENGTH}
outer_diameter = {OUTER}
inner_diameter = {INNER}
[beam]
elements = {elements}
young_modulus = {YOUNG}
poisson_ratio = {POISSON}
density = {DENSITY}
damping = {-math.log(ETA) / s["time"]!r}
[model]
gravity = false
lateral_length = 0.0
[contact]
friction = 0.0
[drive]
mode = "velocity"
axial_velocity = {V0 * s["velocity"]!r}
rotation_speed = {omega0 * s["spin"]!r}
weight_on_bit = {(K_A * V0 / omega0 + WEAR_FLAT) * s["weight"]!r}
start = "on_bottom"
[bit_rock]
law = "detournay"
bit_radius = {RADIUS}
blades = {BLADES}
specific_energy = {s["specific_energy"]!r}
cutting_orientation = {ZETA}
contact_strength = {contact / (RADIUS * FLAT_LENGTH)!r}
wear_flat_length = {FLAT_LENGTH}
friction = {MU}
geometry_factor = {2.0 * BETA * s["torque"] / (RADIUS * s["weight"]) / MU!r}
contact_velocity = {0.01 * s["velocity"]!r}
backward_spin = "held"
"""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "scene.toml"
        path.write_text(text)
        return fd.load_scene(path)


def characteristics(scene, duration: float, cell: float) -> dict:
    """The scene's string and bit law solved exactly along the characteristics of its axial and torsional wave guides
    (:func:`torsional_waves.axial_torsional_stick_slip`, torsional cells of ``cell`` [m]), its top held moving."""
    beam, bit, drive = scene.beam, scene.bit_rock, scene.drive
    shear = beam.young_modulus / (2.0 * (1.0 + beam.poisson_ratio))
    polar, area = math.pi / 32.0 * (OUTER**4 - INNER**4), math.pi / 4.0 * (OUTER**2 - INNER**2)
    sections = [(LENGTH, beam.young_modulus * area, beam.density * area, shear * polar, beam.density * polar)]
    energy, radius = bit.specific_energy, bit.bit_radius
    law = (bit.blades, bit.cutting_orientation * energy * radius, energy * radius**2 / 2.0,
           bit.contact_strength * radius * bit.wear_flat_length, bit.friction * bit.geometry_factor * radius / 2.0,
           bit.contact_velocity, bit.contact_depth, bit.contact_velocity / radius, HELD_BACKWARD_DAMPING)
    return axial_torsional_stick_slip(sections, drive.rotation_speed, drive.axial_velocity, None, drive.weight_on_bit,
                                      beam.damping, 0.0, law, duration, cell, max(1, round(10 / cell)))


def statistics(t: np.ndarray, velocity: np.ndarray, spin: np.ndarray, omega0: float) -> dict:
    """The limit cycle's statistics over the whole cycles after AFTER, in their units."""
    s = limit_cycle_statistics({"time": t, "bit_angular_velocity": spin, "top_torque": 0.0 * t}, omega0, AFTER)
    late = t > AFTER
    return {**s, "max_velocity": float(velocity[late].max()), "mean_velocity": float(velocity[late].mean())}


def row(name: str, s: dict, wall: float | None) -> str:
    return (f"| {name} | {s['period']:.3f} | {s['cycles']} | {s['max_spin']:.3f} | {s['stuck_share']:.3f} | "
            f"{s['max_velocity']:.2f} | {s['mean_velocity']:.3f} | {'' if wall is None else f'{wall:.1f}'} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--published-series", type=Path, default=None)
    parser.add_argument("--elements", type=int, default=200)
    args = parser.parse_args()
    s = scales()
    rows = []
    for omega0 in SPINS:
        if args.published_series is not None:
            theirs = np.loadtxt(args.published_series / f"omega0_{omega0:g}.csv", delimiter=",")
            rows.append(row(f"theirs, omega0 = {omega0:g}", statistics(*theirs.T, omega0), None))
            print(rows[-1], flush=True)
        clock = time.perf_counter()
        series = start(scene_of(omega0, args.elements)).run(DURATION * s["time"])
        wall = time.perf_counter() - clock
        mine = statistics(series["time"] / s["time"], series["bit_velocity"] / s["velocity"],
                          series["bit_angular_velocity"] / s["spin"], omega0)
        rows.append(row(f"this string, omega0 = {omega0:g}, {LENGTH / args.elements:g} m elements", mine, wall))
        print(rows[-1], flush=True)
        clock = time.perf_counter()
        exact = characteristics(scene_of(omega0, args.elements), DURATION * s["time"], CELL)
        wall = time.perf_counter() - clock
        rows.append(row(f"this string's law, exact characteristics, omega0 = {omega0:g}, {CELL:g} m cells",
                        statistics(exact["time"] / s["time"], exact["bit_velocity"] / s["velocity"],
                                   exact["bit_angular_velocity"] / s["spin"], omega0), wall))
        print(rows[-1], flush=True)
    lines = ["# Aarsnes & van de Wouw's published axial-torsional model on bottom, side by side with this string", "",
             f"Command: `python benchmarks/published_axial_torsional_model.py --published-series DIR --elements "
             f"{args.elements}`. Machine: {platform.machine()}, {os.cpu_count()} cores ({processor()}), Python "
             f"{platform.python_version()}; one process. Their case (K_a = {K_A:g}, eta = {ETA:g}, beta = {BETA:g}, "
             f"Wf = {WEAR_FLAT:g}, v0 = {V0:g}) in their units: time L / c_t = {s['time']:.4f} s, velocity "
             f"{s['velocity']:.4g} m/s, spin {s['spin']:.4f} rad/s; statistics over the whole cycles in "
             f"[{AFTER:g}, {DURATION:g}]; stuck: a spin below 1 % of omega0. DIR: their runs of 1000 cells, from a "
             "Python translation of their waveStepUpwind.m and runSim.m (MATLAB is not on this machine; the "
             "translation is not in this repository).", "",
             "| model, case | cycle | cycles | fastest spin | stuck share | fastest bit velocity | mean bit velocity | "
             "wall [s] |", "|---|---|---|---|---|---|---|---|", *rows]
    out = ROOT / "benchmarks" / "results" / "published_axial_torsional_model.md"
    out.write_text("\n".join(lines) + "\n")
    print(f"-> {out}")


if __name__ == "__main__":
    main()
