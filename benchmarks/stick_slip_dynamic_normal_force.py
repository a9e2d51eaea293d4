"""The wall's normal force held at the soft string's against pressed by the string's own tension
(``contact.normal_force``), on stick-slip map points of the two demo wells: benchmarks/results/
stick_slip_dynamic_normal_force.md.

    python benchmarks/stick_slip_dynamic_normal_force.py

Each point is a map's point (the settings of ``make well-maps``: hook-load drive, the cutting law, an 8 1/2 in bit,
the stiff drive, 10 m elements), run to its limit cycle or to the map's time limit by the compiled steps, once with
each wall.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

from speed import machine, write_result  # noqa: E402

import fenics_drill as fd  # noqa: E402
from fenics_drill.studies.stick_slip import limit_cycle  # noqa: E402
from fenics_drill.studies.stick_slip_map import map_scene, point_scene  # noqa: E402

WELLS = {"build-and-hold": "demos/scenes/well_build_hold.toml", "VBH": "demos/scenes/well_vbh.toml"}
SETTINGS = ["drive.mode='hook_load'", "bit_rock.law='detournay'", "bit_rock.bit_radius='4.25 in'",
            "model.lateral_length=0"]
POINTS = ((20e3, 60.0), (60e3, 60.0), (90e3, 60.0), (60e3, 120.0), (90e3, 180.0))
RPM = 3.141592653589793 / 30.0


def cell(value, digits=3):
    return "-" if value is None else f"{value:.{digits}g}"


def main() -> None:
    rows = []
    for well, path in WELLS.items():
        for weight, rpm in POINTS:
            for mode in ("static", "dynamic"):
                scene = map_scene(fd.load_scene(path, [*SETTINGS, f"contact.normal_force='{mode}'"]))
                point = point_scene(scene, "stiff", weight, rpm * RPM)
                clock = time.perf_counter()
                m = limit_cycle(point, scene.stick_slip_map.time_limit)
                wall = time.perf_counter() - clock
                line = (f"| {well} | {weight / 1e3:g} | {rpm:g} | {mode} | {'yes' if m['settled'] else 'no'} | "
                        f"{cell(m['period_s'])} | {cell(m['severity'])} | {m['stuck_share']:.3f} | "
                        f"{m['max_bit_spin_rad_s']:.2f} | {m['surface_torque_N_m'] / 1e3:.3f} | "
                        f"{m['hook_load_N'] / 1e3:.1f} | {m['rop_m_s'] * 3600:.2f} | {wall:.1f} |")
                print(line, flush=True)
                rows.append(line)
    lines = ["# The wall's normal force: the soft string's, or the string's own tension", "",
             f"Command: `python benchmarks/stick_slip_dynamic_normal_force.py`. Machine: {machine()}; one process. "
             "Map points of the demo wells with the settings of `make well-maps` (hook-load drive, the cutting law, "
             "an 8 1/2 in bit, the stiff drive, 10 m elements), each run to its limit cycle or to the map's time "
             "limit (200 s) with `contact.normal_force` 'static' (the soft string's normal force for the point's "
             "weight on bit) and 'dynamic' (pressed by the string's own tension at each step). Statistics over the "
             "settled block, or the last two windows.", "",
             "| well | WOB [kN] | rpm | wall | settled | period [s] | severity | stuck share | fastest spin [rad/s] | "
             "surface torque [kN m] | hook load [kN] | rop [m/h] | wall time [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|", *rows]
    write_result("stick_slip_dynamic_normal_force.md", lines)


if __name__ == "__main__":
    main()
