"""What the axial-torsional string costs and how its limit cycle converges: benchmarks/results/stick_slip.md.

    python benchmarks/stick_slip_speed.py

* Cost per simulated second of the compiled steps (after a first second that compiles and starts), in seconds and in
  machine units (one LAPACK banded LU and solve of benchmarks/speed.py, timed in this process before and after),
  with Newton iterations per step and the steps halved.
* The 2000 m vertical string of demos/scenes/vertical_2000m.toml to its limit cycle (or 200 s) at four points.
* The limit cycle of the build-and-hold demo well at 20 kN and 60 rpm against the element length and the step.
"""

from __future__ import annotations

import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import fenics_drill as fd  # noqa: E402
from fenics_drill.studies.stick_slip import limit_cycle, start  # noqa: E402
from speed import machine_unit, processor  # noqa: E402

VBH, BUILD_HOLD, VERTICAL = ("demos/scenes/well_vbh.toml", "demos/scenes/well_build_hold.toml",
                             "demos/scenes/vertical_2000m.toml")
MAP_POINT = ("drive.mode='hook_load'", "bit_rock.law='detournay'", "bit_rock.bit_radius='4.25 in'")
#: (name, scene, settings, simulated seconds timed)
COSTS = (
    ("VBH as the demo scene (paper's law, velocity drive), 10 m elements", VBH, ("beam.elements=300",), 20.0),
    ("VBH as the demo scene, its 900 elements", VBH, (), 10.0),
    ("VBH in stick-slip (cutting law, hook load 60 kN, 120 rpm), 10 m elements", VBH,
     ("beam.elements=300", *MAP_POINT, "drive.weight_on_bit='60 kN'", "drive.rotation_speed='120 rpm'"), 20.0),
    ("build-and-hold demo (cutting law, hook load 40 kN, 60 rpm), 10 m elements", BUILD_HOLD, ("beam.elements=90",),
     20.0),
    ("2000 m vertical (cutting law, hook load 60 kN, 60 rpm), 10 m elements", VERTICAL, ("beam.elements=200",), 20.0),
)

#: (weight on bit [kN], rotation speed [rpm]) of the 2000 m string: its scene's point, below and above 60 rpm.
VERTICAL_POINTS = ((60, 60), (45, 60), (45, 100), (60, 120))


def cost(path, settings, seconds):
    simulation = start(fd.load_scene(path, list(settings)))
    simulation.run(1.0)
    before = simulation.counters.copy()
    clock = time.perf_counter()
    simulation.run(seconds)
    wall = time.perf_counter() - clock
    steps, iterations, halved = simulation.counters - before
    return wall / seconds, iterations / steps, int(halved), simulation.string.size, simulation.dt


def main() -> None:
    unit_before = machine_unit()
    lines = ["# The axial-torsional string: cost and convergence", "",
             f"`python benchmarks/stick_slip_speed.py`. Machine: {platform.machine()}, {os.cpu_count()} cores "
             f"({processor()}), Python {platform.python_version()}; one process.", ""]
    rows = [cost(path, settings, seconds) for _, path, settings, seconds in COSTS]
    verticals = []
    for wob, rpm in VERTICAL_POINTS:
        clock = time.perf_counter()
        cycle = limit_cycle(fd.load_scene(VERTICAL, ["beam.elements=200", f"drive.weight_on_bit='{wob} kN'",
                                                     f"drive.rotation_speed='{rpm} rpm'"]), 200.0)
        verticals.append((wob, rpm, cycle, time.perf_counter() - clock))
    convergence = []
    for label, settings, dt_share in (("20 m elements", ("beam.elements=45",), 1.0),
                                      ("10 m elements", ("beam.elements=90",), 1.0),
                                      ("5 m elements", ("beam.elements=180",), 1.0),
                                      ("10 m elements, step / 2", ("beam.elements=90",), 0.5),
                                      ("10 m elements, step / 4", ("beam.elements=90",), 0.25)):
        scene = fd.load_scene(BUILD_HOLD, [*settings, "drive.weight_on_bit='20 kN'"])
        first = start(scene)
        convergence.append((label, limit_cycle(scene, 200.0, dt=first.dt * dt_share)))
    unit = 0.5 * (unit_before + machine_unit())
    lines += [f"Machine unit (one dgbtrf + dgbtrs of 54 000 unknowns, kl = ku = 14): {unit * 1e3:.1f} ms.", "",
              "| string | dofs | step [ms] | per simulated s [s] | [units] | Newton iterations per step "
              "| steps halved |", "|---|---|---|---|---|---|---|"]
    for (name, *_), (per_second, iterations, halved, size, dt) in zip(COSTS, rows):
        lines.append(f"| {name} | {size} | {dt * 1e3:.2f} | {per_second:.3f} | {per_second / unit:.1f} | "
                     f"{iterations:.2f} | {halved} |")
    lines += ["", "The 2000 m vertical string (10 m elements, cutting law, hook load) to its limit cycle or 200 s:", "",
              "| weight on bit [kN] | rotation speed [rpm] | settled | drilled [s] | wall [s] | severity | period [s] "
              "| stuck share | bit spin [rad/s] |", "|---|---|---|---|---|---|---|---|---|"]
    for wob, rpm, v, wall in verticals:
        lines.append(f"| {wob} | {rpm} | {'yes' if v['settled'] else 'no'} | {v['time_s']:.1f} | {wall:.1f} | "
                     f"{v['severity']:.3f} | {v['period_s'] or 0:.3f} | {v['stuck_share']:.3f} | "
                     f"{v['min_bit_spin_rad_s']:.2f} to {v['max_bit_spin_rad_s']:.2f} |")
    lines += ["", "The build-and-hold well's limit cycle at 20 kN and 60 rpm (cutting law, hook load):", "",
              "| mesh and step | step [ms] | settled after [s] | severity | period [s] | stuck share "
              "| surface torque [N m] | rop [m/h] |", "|---|---|---|---|---|---|---|---|"]
    for label, c in convergence:
        lines.append(f"| {label} | {c['dt_s'] * 1e3:.3f} | {c['time_s']:.1f} | {c['severity']:.4f} | "
                     f"{c['period_s'] or 0:.4f} | {c['stuck_share']:.4f} | {c['surface_torque_N_m']:.1f} | "
                     f"{c['rop_m_s'] * 3600:.3f} |")
    text = "\n".join(lines) + "\n"
    Path("benchmarks/results/stick_slip.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
