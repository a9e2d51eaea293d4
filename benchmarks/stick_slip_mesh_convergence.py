"""The compiled axial-torsional steps' limit cycle against the mesh and the step, with and without the map's mesh
viscosity, on two cases: benchmarks/results/stick_slip_mesh_convergence.md.

    python benchmarks/stick_slip_mesh_convergence.py

The case is Aarsnes & van de Wouw's bit on bottom at omega0 = 1 (benchmarks/published_axial_torsional_model.py;
tests/torsional_waves.py, :func:`moving_top_cutting_law_case`), whose axial velocity spikes to 11 times its mean each
time it breaks free (its depth of cut stays above 0).  Each row is one run of :func:`~fenics_drill.studies.stick_slip.start` over
120 of their time units, with ``stick_slip_map.mesh_viscosity`` = zeta (on the torsional wave; "both": on the axial
wave too, this benchmark's variant), 2000 m / elements long elements and the step
a share of the default (half the element's axial wave transit); the last row is this string's law solved exactly
along its characteristics.  Statistics over the whole cycles in [60, 120], their units.

The second case is a calm stick-slip cycle: the 2000 m vertical string drilling with the cutting law at 45 kN and
100 rpm (tests/torsional_waves.py, :func:`vertical_cutting_law_case`; the test
``test_the_cutting_laws_limit_cycle_is_the_axial_and_torsional_wave_guides``), over [40, 100] s.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from published_axial_torsional_model import DURATION, peaks_cell, scaled_statistics  # noqa: E402
from speed import machine, write_result  # noqa: E402
from torsional_waves import (LENGTH, limit_cycle_statistics, moving_top_cutting_law_case, published_scales,  # noqa: E402
                             vertical_cutting_law_case)

from fenics_drill.model.axial_torsional_string import axial_torsional_string, mesh_viscosity  # noqa: E402
from fenics_drill.studies.stick_slip import default_step, start  # noqa: E402

#: (zeta, elements, share of the default step, on the axial wave too) of each run.
RUNS = [*[(zeta, elements, share, False) for zeta in (1.0, 0.25, 0.0)
          for elements, share in ((200, 2.0), (200, 1.0), (200, 0.5), (200, 0.25), (400, 1.0), (1000, 1.0))],
        *[(1.0, elements, share, True) for elements, share in ((200, 1.0), (200, 0.25), (400, 1.0))]]
#: The exact characteristics' torsional cells [m].
CELLS = (1.25, 0.3125)
#: (zeta, elements, share of the default step, on the axial wave too) of each run of the calm case, and the exact
#: characteristics' cells.
CALM_RUNS = [*[(zeta, elements, share, False) for zeta in (1.0, 0.25, 0.0)
               for elements, share in ((200, 1.0), (200, 0.25), (400, 1.0))],
             *[(1.0, elements, 1.0, True) for elements in (200, 400)]]
CALM_CELLS = (1.0, 0.5)


def simulation(scene, zeta: float, share: float, axial: bool):
    """The compiled steps of ``scene`` with the mesh viscosity zeta, on the torsional wave (the map's) or on both
    waves, at a share of the default step."""
    string = axial_torsional_string(scene)
    dt = share * default_step(string)
    if axial:
        return start(scene, replace(string, damping=string.damping + mesh_viscosity(string, zeta, axial=True)), dt=dt)
    return start(scene.with_changes(stick_slip_map={"mesh_viscosity": zeta}), string, dt=dt)


def waves(zeta: float, axial: bool) -> str:
    return "-" if zeta == 0 else ("both" if axial else "torsional")


def calm_rows() -> list[str]:
    """The calm case's rows: the compiled steps, then the exact characteristics."""
    rows = []
    for zeta, elements, share, axial in CALM_RUNS:
        scene, _ = vertical_cutting_law_case(elements, 45e3, 100.0 * math.pi / 30.0)
        clock = time.perf_counter()
        run = simulation(scene, zeta, share, axial)
        m = limit_cycle_statistics(run.run(100.0), scene.drive.rotation_speed, 40.0)
        rows.append(f"| {zeta:g} | {waves(zeta, axial)} | {run.string.length / elements:g} | {share:g} | {m['period']:.3f} | "
                    f"{m['max_spin']:.2f} | {m['min_spin']:.3f} | {m['stuck_share']:.3f} | "
                    f"{m['surface_torque'] / 1e3:.3f} | {time.perf_counter() - clock:.1f} |")
        print(rows[-1], flush=True)
    scene, exact_run = vertical_cutting_law_case(200, 45e3, 100.0 * math.pi / 30.0)
    for cell in CALM_CELLS:
        clock = time.perf_counter()
        m = limit_cycle_statistics(exact_run(100.0, cell), scene.drive.rotation_speed, 40.0)
        rows.append(f"| exact characteristics | | {cell:g} | - | {m['period']:.3f} | {m['max_spin']:.2f} | "
                    f"{m['min_spin']:.3f} | {m['stuck_share']:.3f} | {m['surface_torque'] / 1e3:.3f} | "
                    f"{time.perf_counter() - clock:.1f} |")
        print(rows[-1], flush=True)
    return rows


def violent_row(label: str, series: dict, wall: float) -> str:
    """A row of the violent case's table (their units), printed as it is made."""
    m = scaled_statistics(series, 1.0)
    row = (f"| {label} | {m['period']:.3f} | {m['max_spin']:.3f} | {peaks_cell(m)} | {m['stuck_share']:.3f} | "
           f"{m['max_velocity']:.2f} | {m['mean_velocity']:.3f} | {wall:.1f} |")
    print(row, flush=True)
    return row


def main() -> None:
    s = published_scales()
    rows = []
    for zeta, elements, share, axial in RUNS:
        scene, _ = moving_top_cutting_law_case(1.0, elements)
        clock = time.perf_counter()
        series = simulation(scene, zeta, share, axial).run(DURATION * s["time"])
        wall = time.perf_counter() - clock
        rows.append(violent_row(f"{zeta:g} | {waves(zeta, axial)} | {LENGTH / elements:g} | {share:g}", series, wall))
    _, exact_run = moving_top_cutting_law_case(1.0, 200)
    for cell in CELLS:
        clock = time.perf_counter()
        exact = exact_run(DURATION * s["time"], cell)
        rows.append(violent_row(f"exact characteristics | | {cell:g} | -", exact, time.perf_counter() - clock))
    lines = ["# The violent bit's limit cycle against the mesh, the step and the mesh viscosity", "",
             f"Command: `python benchmarks/stick_slip_mesh_convergence.py`. Machine: {machine()}; one process. "
             "Aarsnes & van "
             "de Wouw's case at omega0 = 1 (benchmarks/published_axial_torsional_model.py), 120 time units, "
             "statistics over the whole cycles in [60, 120] in their units. zeta: `stick_slip_map.mesh_viscosity`, "
             "on the torsional wave as the map adds it, or on both waves (this benchmark's variant, to show what "
             "the axial wave's share costs); step: the share of the default step (half the element's axial wave "
             "transit); per cycle: each cycle's fastest spin, the median (10th-90th percentile) over the cycles.", "",
             "| zeta | waves | element [m] | step | cycle | fastest spin | per cycle | stuck share | fastest bit "
             "velocity | mean bit velocity | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|---|", *rows, "",
             "The calm stick-slip cycle: the 2000 m vertical string with the cutting law at 45 kN and 100 rpm, "
             "statistics over the whole cycles in [40, 100] s, SI units.", "",
             "| zeta | waves | element [m] | step | cycle [s] | fastest spin [rad/s] | slowest spin [rad/s] | "
             "stuck share | mean surface torque [kN m] | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|",
             *calm_rows()]
    write_result("stick_slip_mesh_convergence.md", lines)


if __name__ == "__main__":
    main()
