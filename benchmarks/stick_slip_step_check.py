"""Points of the build-and-hold well's stick-slip map at the default step and at half of it, with and without the
mesh viscosity: benchmarks/results/stick_slip_step_check.md.

    python benchmarks/stick_slip_step_check.py

The map's settings of ``make well-maps`` (the cutting law, the drawworks holding the weight on bit, the stiff drive,
10 m elements); each point run to its limit cycle or 200 s by :func:`~fenics_drill.studies.stick_slip.limit_cycle`.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

from speed import machine, write_result  # noqa: E402

import fenics_drill as fd  # noqa: E402
from fenics_drill.model.axial_torsional_string import axial_torsional_string, pressed_for  # noqa: E402
from fenics_drill.studies.stick_slip import limit_cycle, start  # noqa: E402
from fenics_drill.studies.stick_slip_map import map_scene, point_scene  # noqa: E402

SCENE = "demos/scenes/well_build_hold.toml"
SETTINGS = ["drive.mode='hook_load'", "bit_rock.law='detournay'", "bit_rock.bit_radius='4.25 in'"]
#: (weight on bit [N], rotation speed [rpm]) of each point.
POINTS = ((40e3, 60.0), (60e3, 120.0), (90e3, 80.0), (20e3, 180.0))


def main() -> None:
    rows = []
    for zeta in (0.0, 1.0):
        scene = map_scene(fd.load_scene(ROOT / SCENE, [*SETTINGS, f"stick_slip_map.mesh_viscosity={zeta}"]))
        string = axial_torsional_string(scene)
        for weight, rpm in POINTS:
            point = point_scene(scene, "stiff", weight, rpm * math.pi / 30.0)
            for share in (1.0, 0.5):
                simulation = start(point, string=pressed_for(string, point))
                if share != 1.0:
                    simulation = start(point, string=pressed_for(string, point), dt=share * simulation.dt)
                clock = time.perf_counter()
                c = limit_cycle(point, 200.0, simulation=simulation)
                period = "-" if c["period_s"] is None else f"{c['period_s']:.3f}"
                rows.append(f"| {zeta:g} | {weight / 1e3:g} | {rpm:g} | {share:g} | {c['settled']} | {period} | "
                            f"{c['max_bit_spin_rad_s']:.2f} | {c['stuck_share']:.3f} | {c['severity']:.3f} | "
                            f"{c['surface_torque_N_m'] / 1e3:.3f} | {time.perf_counter() - clock:.1f} |")
                print(rows[-1], flush=True)
    lines = ["# Points of the build-and-hold well's map at the default step and at half of it", "",
             f"Command: `python benchmarks/stick_slip_step_check.py`. Machine: {machine()}; one process. {SCENE} "
             "with the settings of "
             "`make well-maps`, the stiff drive, 10 m elements; each point to its limit cycle or 200 s. zeta: "
             "`stick_slip_map.mesh_viscosity`; step: the share of the default step.", "",
             "| zeta | weight on bit [kN] | rotation speed [rpm] | step | settled | cycle [s] | fastest spin [rad/s] | "
             "stuck share | severity | surface torque [kN m] | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|", *rows]
    write_result("stick_slip_step_check.md", lines)


if __name__ == "__main__":
    main()
