"""The axial-torsional string's stick-slip against the torsional wave guide solved along its characteristics:
benchmarks/results/stick_slip_waves.md.

    python benchmarks/stick_slip_waves.py [--t-end 100] [--after 40]

The 2000 m vertical string of demos/scenes/vertical_2000m.toml (1800 m of 5 in drill pipe over 200 m of 6 3/4 in
collars) drilling with the paper's bit law (20)-(22) at a held 20 m/h, so that its bit force settles at
Gamma (exp(-alpha V0) - 1) and the torsion sees a bit torque of the spin alone; the reference
(tests/torsional_waves.py) is the same string as a torsional wave guide with that bit torque, on a 1 m grid.  For
each element length and step of the compiled steps, and for the reference, the statistics of the limit cycle over
[after, t_end]: the mean cycle's duration, the bit's fastest and slowest spin, the share of time stuck (spin below
1 % of the drive's), the mean surface torque, and the wall time; Newmark's alpha (``time.newmark_alpha``, 0.015 by
default) at 0 and 0.1 shows what the scheme's own dissipation does to the cycle.
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

from speed import processor  # noqa: E402
from torsional_waves import limit_cycle_statistics, vertical_paper_law_case  # noqa: E402

from fenics_drill.model.axial_torsional_string import axial_torsional_string  # noqa: E402
from fenics_drill.studies.stick_slip import default_step, start  # noqa: E402

#: (elements over 2000 m, the step as a share of the default, Newmark's alpha: time.newmark_alpha)
GRIDS = ((100, 1.0, 0.015), (200, 1.0, 0.015), (400, 1.0, 0.015), (200, 0.5, 0.015), (200, 0.25, 0.015),
         (400, 0.25, 0.015), (200, 1.0, 0.0), (200, 1.0, 0.1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=100.0)
    parser.add_argument("--after", type=float, default=40.0)
    args = parser.parse_args()
    lines = ["# The axial-torsional string against the torsional wave guide", "",
             f"Command: `python benchmarks/stick_slip_waves.py --t-end {args.t_end:g} --after {args.after:g}`. Machine: "
             f"{platform.machine()}, {os.cpu_count()} cores ({processor()}), Python {platform.python_version()}; one "
             "process.", "",
             "The 2000 m vertical string (demos/scenes/vertical_2000m.toml) with the paper's bit law at a held 20 m/h "
             "and 60 rpm; statistics over "
             f"[{args.after:g}, {args.t_end:g}] s (tests/torsional_waves.py).", "",
             "| model | elements | step [ms] | alpha | cycle [s] | fastest spin [rad/s] | slowest spin [rad/s] | stuck share "
             "| surface torque [N m] | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for elements, share, alpha in GRIDS:
        scene, reference = vertical_paper_law_case(elements)
        scene = scene.with_changes(time={"newmark_alpha": alpha})
        clock = time.perf_counter()
        string = axial_torsional_string(scene)
        simulation = start(scene, string, dt=share * default_step(string))
        series = simulation.run(args.t_end)
        wall = time.perf_counter() - clock
        s = limit_cycle_statistics(series, scene.drive.rotation_speed, args.after)
        lines.append(f"| compiled steps | {elements} | {1e3 * simulation.dt:.3f} | {alpha:g} | {s['period']:.4f} | "
                     f"{s['max_spin']:.3f} | {s['min_spin']:.4f} | {s['stuck_share']:.4f} | "
                     f"{s['surface_torque']:.1f} | {wall:.1f} |")
        print(lines[-1], flush=True)
    clock = time.perf_counter()
    series = reference(args.t_end)
    wall = time.perf_counter() - clock
    s = limit_cycle_statistics(series, scene.drive.rotation_speed, args.after)
    grid_step = 1e3 / math.sqrt(scene.beam.young_modulus / (2 * (1 + scene.beam.poisson_ratio)) / scene.beam.density)
    lines.append(f"| wave guide, 1 m grid | - | {grid_step:.3f} | - | {s['period']:.4f} | {s['max_spin']:.3f} | {s['min_spin']:.4f} | {s['stuck_share']:.4f} | "
                 f"{s['surface_torque']:.1f} | {wall:.1f} |")
    print(lines[-1])
    out = ROOT / "benchmarks" / "results" / "stick_slip_waves.md"
    out.write_text("\n".join(lines) + "\n")
    print(f"-> {out}")


if __name__ == "__main__":
    main()
