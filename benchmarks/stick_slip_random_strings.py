"""The compiled axial-torsional steps against the distributed model solved exactly, on strings no test was tuned on:
benchmarks/results/stick_slip_random_strings.md.

    python benchmarks/stick_slip_random_strings.py [--strings 16] [--seed 2026] [--t-end 100] [--after 40]

Each string is drawn as a held-back check would pose one: a vertical hole, drill pipe of 800-3600 m over collars of
80-320 m (each a multiple of 8 m, so that both wave guides' cells fit it), the pipe and collar sizes from common API
sizes, in air, drilling with the cutting law of Richard, Germay & Detournay (2007) (the scene's defaults) under a
hook-load drive at a weight on bit of 20-80 kN and a held rotation speed of 50-160 rpm.  Each is run on the map's
default mesh and step (``stick_slip_map.element_length``, half the element's axial transit) and, as the reference, as
the axial and torsional wave guides that meet in that law at the bit, solved along their characteristics on 1 m
cells (tests/torsional_waves.py, :func:`hook_load_reference`).  Statistics over [after, t_end]: the mean
cycle, the bit's fastest and slowest spin, the share of time stuck (below 1 % of the drive's speed), the mean surface
torque; "bounces" where the reference's bit turns backwards (the irregular regime whose extremes move with the grid,
docs/guide/stick_slip_maps.md).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from speed import machine, write_result  # noqa: E402
from torsional_waves import hook_load_reference, limit_cycle_statistics  # noqa: E402

import fenics_drill as fd  # noqa: E402
from fenics_drill.model.axial_torsional_string import axial_torsional_string  # noqa: E402
from fenics_drill.studies.stick_slip import default_step, start  # noqa: E402
from fenics_drill.studies.stick_slip_map import map_scene  # noqa: E402

#: (outer, inner) diameters [in] of the drill pipe and of the collars drawn from.
PIPES = ((4.5, 3.826), (5.0, 4.276), (5.5, 4.778))
COLLARS = ((6.25, 2.25), (6.75, 2.8125), (8.0, 2.8125))
#: (low, high) of the drawn pipe and collar lengths [m], weight on bit [kN] and rotation speed [rpm].
PIPE_LENGTH, COLLAR_LENGTH, WEIGHT, SPEED = (800.0, 3600.0), (80.0, 320.0), (20.0, 80.0), (50.0, 160.0)
#: Both guides' cells fit a length that is a multiple of this [m] (c_A / c_T = 1.6 at a Poisson ratio of 0.28).
CELL_MULTIPLE = 8.0
#: The reference's torsional cells [m]: the second only where the first's bit bounces.
CELLS = (1.0, 0.5)

SCENE = """[well]
md = [0.0, {length}]
inclination = [0.0, 0.0]
azimuth = [0.0, 0.0]
hole_bottom = [{length}]
hole_radius = ["4.25 in"]
hole_cased = [false]

[[string.sections]]
name = "collars"
length = {collar_length}
outer_diameter = "{collar_od} in"
inner_diameter = "{collar_id} in"

[[string.sections]]
name = "drill pipe"
length = {pipe_length}
outer_diameter = "{pipe_od} in"
inner_diameter = "{pipe_id} in"

[fluid]
density = 0.0

[beam]
poisson_ratio = 0.28

[drive]
mode = "hook_load"
weight_on_bit = "{weight} kN"
rotation_speed = "{speed} rpm"
axial_velocity = "10 m/h"

[bit_rock]
law = "detournay"
bit_radius = "4.25 in"
"""


def _multiple(rng, low: float, high: float) -> float:
    return CELL_MULTIPLE * round(rng.uniform(low, high) / CELL_MULTIPLE)


def draw(rng) -> dict:
    """One string and its drive (module doc)."""
    pipe, collar = PIPES[rng.integers(len(PIPES))], COLLARS[rng.integers(len(COLLARS))]
    return {"pipe_length": _multiple(rng, *PIPE_LENGTH), "collar_length": _multiple(rng, *COLLAR_LENGTH),
            "pipe_od": pipe[0], "pipe_id": pipe[1], "collar_od": collar[0], "collar_id": collar[1],
            "weight": round(rng.uniform(*WEIGHT)), "speed": round(rng.uniform(*SPEED))}


def scene_of(case: dict, folder: Path):
    """The drawn case as a scene, on the map's mesh (:func:`~fenics_drill.studies.stick_slip_map.map_scene`)."""
    path = folder / "case.toml"
    path.write_text(SCENE.format(length=case["pipe_length"] + case["collar_length"], **case))
    return map_scene(fd.load_scene(path))


def cells(m: dict, series: dict, after: float) -> str:
    rop = np.mean(series["bit_velocity"][series["time"] > after]) * 3600.0
    return (f"{m['period']:.3f} | {m['max_spin']:.2f} | {m['min_spin']:.2f} | {m['stuck_share']:.3f} | "
            f"{m['surface_torque'] / 1e3:.3f} | {rop:.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strings", type=int, default=16)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--t-end", type=float, default=100.0)
    parser.add_argument("--after", type=float, default=40.0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for k in range(args.strings):
            case = draw(rng)
            scene = scene_of(case, Path(folder))
            omega = scene.drive.rotation_speed
            string = axial_torsional_string(scene)
            runs = []
            clock = time.perf_counter()
            series = start(scene, string, dt=default_step(string)).run(args.t_end)
            runs.append((f"compiled steps, {string.length / scene.beam.elements:.1f} m", series,
                         time.perf_counter() - clock))
            for cell in CELLS:
                clock = time.perf_counter()
                runs.append((f"exact, {cell:g} m cells", hook_load_reference(scene, args.t_end, cell),
                             time.perf_counter() - clock))
                exact = limit_cycle_statistics(runs[-1][1], omega, args.after)
                regime = "bounces" if exact["min_spin"] < -0.01 * omega else (
                    "sticks" if exact["stuck_share"] > 0 else "slips")
                if regime != "bounces":  # a calm cycle: one grid of the reference is enough
                    break
            label = (f"| {k + 1} | {case['pipe_length']:g} m of {case['pipe_od']:g} in over "
                     f"{case['collar_length']:g} m of {case['collar_od']:g} in | {case['weight']} | {case['speed']} | "
                     f"{regime}")
            for model, series, wall in runs:
                m = limit_cycle_statistics(series, omega, args.after)
                rows.append(f"{label} | {model} | {cells(m, series, args.after)} | {wall:.1f} |")
                print(rows[-1], flush=True)
    lines = ["# The compiled axial-torsional steps against the distributed model solved exactly, on drawn strings", "",
             f"Command: `python benchmarks/stick_slip_random_strings.py --strings {args.strings} --seed {args.seed} "
             f"--t-end {args.t_end:g} --after {args.after:g}`. Machine: {machine()}; one process. Each string: the "
             "compiled steps on the map's default mesh and step, then the wave guides solved exactly on 1 m cells "
             "(and on 0.5 m where its bit bounces); statistics over "
             f"[{args.after:g}, {args.t_end:g}] s: the mean cycle [s], the fastest and slowest spin [rad/s], the "
             "stuck share, the mean surface torque [kN m] and rop [m/h]. Regime: the reference's bit bounces (turns "
             "backwards), sticks, or only slips.", "",
             "| # | string | WOB [kN] | rpm | regime | model | cycle | fastest | slowest | stuck | torque | rop | "
             "wall [s] |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|", *rows]
    write_result("stick_slip_random_strings.md", lines)


if __name__ == "__main__":
    main()
