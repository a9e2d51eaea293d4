"""The axial-torsional string's stick-slip against the wave guides solved along their characteristics:
benchmarks/results/stick_slip_waves.md.

    python benchmarks/stick_slip_waves.py [--t-end 100] [--after 40]

The 2000 m vertical string of demos/scenes/vertical_2000m.toml (1800 m of 5 in drill pipe over 200 m of 6 3/4 in
collars) drilling with the paper's bit law (20)-(22) at a held 20 m/h, so that its bit force settles at
Gamma (exp(-alpha V0) - 1) and the torsion sees a bit torque of the spin alone; the reference
(tests/torsional_waves.py) is the same string as a torsional wave guide with that bit torque, on a 1 m grid.  For
each element length and step of the compiled steps, and for the reference, the statistics of the limit cycle over
[after, t_end]: the mean cycle's duration, the bit's fastest and slowest spin, the share of time stuck (spin below
1 % of the drive's), the mean surface torque, and the wall time; Newmark's alpha (``time.newmark_alpha``, 0.015 by
default) at 0 and 0.1 shows what the scheme's own dissipation does to the cycle.  Then the same string in air with
the cutting law under its hook-load drive at two points, against the axial and torsional wave guides that meet in
the law at the bit; the reference on three grids shows how sharply this coupled cycle is defined.  Last, a grid of
weight on bit x rotation speed with the cutting law, as a stick-slip map would take it, the bit free and held, and the
points where the compiled steps stay calm while the wave guides bounce, at the default step and at twice it.  And the
same string rotating off bottom in a straight hole inclined 60 degrees, with the wall's static friction (static factor
0.3, kinetic 0.195): the off-bottom torsional oscillation of Aarsnes & Shor (2018), against the wave guides with the
same wall law cell by cell.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from speed import processor, write_result  # noqa: E402
from torsional_waves import (inclined_wall_friction_case, limit_cycle_statistics, vertical_cutting_law_case,  # noqa: E402
                             vertical_paper_law_case)

from fenics_drill.model.axial_torsional_string import axial_torsional_string  # noqa: E402
from fenics_drill.studies.stick_slip import default_step, start  # noqa: E402

#: (elements over 2000 m, the step as a share of the default, Newmark's alpha: time.newmark_alpha)
GRIDS = ((100, 1.0, 0.015), (200, 1.0, 0.015), (400, 1.0, 0.015), (200, 0.5, 0.015), (200, 0.25, 0.015),
         (400, 0.25, 0.015), (200, 1.0, 0.0), (200, 1.0, 0.1))
#: The cutting law's points (weight on bit [kN], rotation speed [rpm]) and the grids of the compiled steps there.
CUTTING_POINTS, CUTTING_GRIDS = ((60, 120), (45, 100)), ((100, 1.0, 0.015), (200, 1.0, 0.015), (200, 0.5, 0.015))
#: The reference's torsional cells [m] (the axial ones 1.6 times as long).
CELLS = (1.0, 0.5, 0.25)
HEADER = ["| model | elements or cell | step [ms] | alpha | cycle [s] | fastest spin [rad/s] | slowest spin [rad/s] | "
          "stuck share | surface torque [N m] | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|"]


def row(name: str, grid: str, step: float, alpha: str, series: dict, rotation_speed: float, after: float,
        wall: float) -> str:
    s = limit_cycle_statistics(series, rotation_speed, after)
    line = (f"| {name} | {grid} | {1e3 * step:.3f} | {alpha} | {s['period']:.4f} | {s['max_spin']:.3f} | "
            f"{s['min_spin']:.4f} | {s['stuck_share']:.4f} | {s['surface_torque']:.1f} | {wall:.1f} |")
    print(line, flush=True)
    return line


def compiled_rows(case, grids, t_end: float, after: float) -> list[str]:
    lines = []
    for elements, share, alpha in grids:
        scene, _ = case(elements)
        scene = scene.with_changes(time={"newmark_alpha": alpha})
        clock = time.perf_counter()
        string = axial_torsional_string(scene)
        simulation = start(scene, string, dt=share * default_step(string))
        series = simulation.run(t_end)
        lines.append(row("compiled steps", str(elements), simulation.dt, f"{alpha:g}", series,
                         scene.drive.rotation_speed, after, time.perf_counter() - clock))
    return lines


def reference_rows(case, t_end: float, after: float, cells=CELLS) -> list[str]:
    lines = []
    scene, reference = case(200)
    torsional_speed = math.sqrt(scene.beam.young_modulus / (2 * (1 + scene.beam.poisson_ratio)) / scene.beam.density)
    for cell in cells:
        clock = time.perf_counter()
        series = reference(t_end, cell)
        lines.append(row("wave guides", f"{cell:g} m", cell / torsional_speed, "-", series, scene.drive.rotation_speed,
                         after, time.perf_counter() - clock))
    return lines


#: The map's grid of the cutting law's points: weights on bit [kN], rotation speeds [rpm].
MAP_WEIGHTS, MAP_SPEEDS = (30, 45, 60, 75), (60, 100, 140)


def _map_cell(series: dict, rotation_speed: float, after: float) -> str:
    try:
        s = limit_cycle_statistics(series, rotation_speed, after)
    except IndexError:  # fewer than two rises through the drive's speed after ``after``
        spin = series["bit_angular_velocity"][series["time"] > after]
        return f"no cycle: {spin.max():.1f} / {spin.min():.1f} rad/s"
    bounce = " (bounce)" if s["min_spin"] < -0.1 * rotation_speed else ""
    return (f"{s['period']:.2f} s, {s['max_spin']:.1f} / {s['min_spin']:.1f} rad/s, stuck {s['stuck_share']:.3f}"
            f"{bounce}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=100.0)
    parser.add_argument("--after", type=float, default=40.0)
    args = parser.parse_args()
    lines = ["# The axial-torsional string against the wave guides solved along their characteristics", "",
             f"Command: `python benchmarks/stick_slip_waves.py --t-end {args.t_end:g} --after {args.after:g}`. Machine: "
             f"{platform.machine()}, {os.cpu_count()} cores ({processor()}), Python {platform.python_version()}; one "
             "process. Statistics over whole cycles in "
             f"[{args.after:g}, {args.t_end:g}] s (tests/torsional_waves.py).", "",
             "**Torsion alone**: the 2000 m vertical string (demos/scenes/vertical_2000m.toml) with the paper's bit law "
             "at a held 20 m/h and 60 rpm.", "", *HEADER,
             *compiled_rows(vertical_paper_law_case, GRIDS, args.t_end, args.after),
             *reference_rows(vertical_paper_law_case, args.t_end, args.after)]
    for controller in ("pi", "soft_torque"):
        def case(elements, controller=controller):
            return vertical_paper_law_case(elements, controller)

        lines += ["", f"**Torsion alone, a top drive**: the same, turned by `drive.controller = '{controller}'`.", "",
                  *HEADER, *compiled_rows(case, GRIDS[1:2], args.t_end, args.after),
                  *reference_rows(case, args.t_end, args.after, CELLS[:2])]
    for weight, speed in CUTTING_POINTS:
        def case(elements, weight=weight, speed=speed):
            return vertical_cutting_law_case(elements, weight * 1e3, speed * math.pi / 30.0)

        lines += ["", f"**The cutting law, axial and torsional**: the same string in air (Poisson ratio 0.28) under its "
                  f"hook-load drive, {weight} kN on the bit at {speed} rpm.", "", *HEADER,
                  *compiled_rows(case, CUTTING_GRIDS, args.t_end, args.after),
                  *reference_rows(case, args.t_end, args.after)]
    lines += ["", "**Over weight on bit x rotation speed**: the cutting law's points as a map takes them, the compiled steps "
              "at their defaults (10 m elements, 1 ms) against the wave guides (1 m): mean cycle [s], fastest and slowest "
              "spin [rad/s], stuck share; \"bounce\" where the bit turns backwards faster than a tenth of the drive's "
              "speed.", "", "| weight on bit [kN] | rotation speed [rpm] | compiled steps | wave guides |", "|---|---|---|---|"]
    calm_where_bouncing = []  # (step, weight, speed, cell) where the compiled steps are calm and the guides bounce
    for weight in MAP_WEIGHTS:
        for speed in MAP_SPEEDS:
            scene, reference = vertical_cutting_law_case(200, weight * 1e3, speed * math.pi / 30.0)
            string = axial_torsional_string(scene)
            cells = [_map_cell(series, scene.drive.rotation_speed, args.after)
                     for series in (start(scene, string).run(args.t_end), reference(args.t_end),
                                    start(scene, string, dt=2.0 * default_step(string)).run(args.t_end))]
            lines.append(f"| {weight} | {speed} | {cells[0]} | {cells[1]} |")
            print(lines[-1], flush=True)
            for step, cell in (("default", cells[0]), ("whole transit", cells[2])):
                if "bounce" in cells[1] and "bounce" not in cell:
                    calm_where_bouncing.append((step, weight, speed, cell))
    lines += ["", "The same grid with the bit held against turning backwards (`bit_rock.backward_spin = 'held'`, a damper of "
              "1e6 N m s in both; \"no cycle\": no two rises of the spin through the drive's speed, each after a fall a "
              "quarter of its range below it, or where that is below its slowest a quarter of the way from it):", "",
              "| weight on bit [kN] | rotation speed [rpm] | compiled steps | wave guides |", "|---|---|---|---|"]
    for weight in MAP_WEIGHTS:
        for speed in MAP_SPEEDS:
            scene, reference = vertical_cutting_law_case(200, weight * 1e3, speed * math.pi / 30.0, "held")
            cells = [_map_cell(series, scene.drive.rotation_speed, args.after)
                     for series in (start(scene).run(args.t_end), reference(args.t_end))]
            lines.append(f"| {weight} | {speed} | {cells[0]} | {cells[1]} |")
            print(lines[-1], flush=True)
    lines += ["", "The points of the first grid where the compiled steps settle on a calm cycle and the wave guides bounce, at "
              "the default step (half the mean element's axial transit, 1 ms) and at twice it (the whole transit, 2 ms):",
              "", "| step | weight on bit [kN] | rotation speed [rpm] | compiled steps |", "|---|---|---|---|"]
    if not any(step == "default" for step, *_ in calm_where_bouncing):
        lines.append("| default | none | | |")
    lines += [f"| {step} | {weight} | {speed} | {cell} |" for step, weight, speed, cell in calm_where_bouncing]
    for controller in ("stiff", "pi"):
        def case(elements, controller=controller):
            return inclined_wall_friction_case(elements, controller=controller)[:2]

        lines += ["", f"**The wall's static friction, off bottom**: the same string in air in a straight hole inclined 60 "
                  "degrees, rotating off bottom at 40 rpm with the wall's static factor 0.3, kinetic 0.195 and static slip "
                  f"speed 0.11 m/s, `drive.controller = '{controller}'` (J_td 2900 kg m^2, k_p 38 kN m s, k_i 100 kN m: "
                  "Aarsnes & Shor's well B); the wave guides carry the same wall law cell by cell.", "", *HEADER,
                  *compiled_rows(case, GRIDS[:3], args.t_end, args.after),
                  *reference_rows(case, args.t_end, args.after, CELLS[:2])]
    write_result("stick_slip_waves.md", lines)


if __name__ == "__main__":
    main()
