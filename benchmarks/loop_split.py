"""Where a run's time goes, without a profiler: the time loop's parts timed around their calls.

    python benchmarks/loop_split.py T_END [SECTION.KEY=VALUE ...]

Runs the paper scene for T_END seconds (no field output) and prints the total, the time loop (the
ECSW training run included) and, inside it, the Newton steps, the per-step recording (time series,
von Mises), the energies and power terms of the budget, the step's error estimate and the sample
checks; then the model's parts inside the Newton steps (evaluations, tangents, saddle solves, the wall,
the sampled internal force, the bit), with their calls and time per call.  cProfile inflates small
calls; this does not (benchmarks/RESULTS.md, issue 17).
"""

from __future__ import annotations

import collections
import sys
import tempfile
import time

import fenics_drill  # noqa: F401  (dolfinx_solver and h5py first)
import fenics_drill.solvers.time_loop as time_loop
from fenics_drill.model.drillstring import DrillstringModel
from fenics_drill.model.forces.bit_rock import BitRock
from fenics_drill.model.forces.wall_contact import WallContact
from fenics_drill.model.internal_force import AssembledInternalForce
from fenics_drill.model.reduction.spaces import ModalSpace
from fenics_drill.scene import load_scene
from fenics_drill.studies.run import run_scene

SPENT: collections.Counter = collections.Counter()
CALLS: collections.Counter = collections.Counter()
LAST_RUN: dict = {}


def timed(owner, name: str, key: str) -> None:
    """Replace the method ``owner.name`` by one that adds its wall time to SPENT[key] (and counts it)."""
    method = getattr(owner, name)

    def wrapper(*args, **kwargs):
        clock = time.perf_counter()
        try:
            return method(*args, **kwargs)
        finally:
            SPENT[key] += time.perf_counter() - clock
            CALLS[key] += 1

    setattr(owner, name, wrapper)


#: The model's parts inside a Newton step: (owner, method, label).
PARTS = (
    (DrillstringModel, "evaluate", "model evaluation"),
    (DrillstringModel, "_tangent", "model tangent (on first use)"),
    (ModalSpace, "saddle_solve", "saddle solve"),
    (WallContact, "evaluate", "  wall evaluation"),
    (WallContact, "tangent", "  wall tangent"),
    (AssembledInternalForce, "evaluate", "  internal force"),
    (AssembledInternalForce, "tangent_parts", "  internal tangent parts"),
    (BitRock, "evaluate", "  bit-rock law"),
)


def main() -> None:
    timed(time_loop.NewmarkNewton, "step", "Newton steps")
    timed(time_loop.Simulation, "_power_terms", "power terms of the budget")
    timed(time_loop.EnergyBudget, "_settle", "energies of the budget (batched)")
    timed(time_loop.Simulation, "_check_sample", "sample checks")
    timed(time_loop.EnergyBudget, "advance", "budget advance")
    timed(time_loop.StepController, "error_ratio", "error estimate")
    for owner, name, label in PARTS:
        timed(owner, name, label)
    run = time_loop.Simulation.run

    def timed_run(self, state, t_end, on_step=None, progress=None, **options):
        def recorded(record):
            clock = time.perf_counter()
            try:
                return on_step(record) if on_step is not None else None
            finally:
                SPENT["recording (rows, von Mises)"] += time.perf_counter() - clock

        clock = time.perf_counter()
        before = SPENT.copy(), CALLS.copy()
        try:
            return run(self, state, t_end, recorded, progress, **options)
        finally:
            SPENT["time loop"] += time.perf_counter() - clock
            LAST_RUN.clear()  # this run alone (the main run comes after the ECSW training run)
            LAST_RUN.update({label: (SPENT[label] - before[0][label], CALLS[label] - before[1][label])
                             for label in ("Newton steps", *(label for _, _, label in PARTS))})

    time_loop.Simulation.run = timed_run
    scene = load_scene("demos/scenes/paper.toml", [f"time.t_end={sys.argv[1]}", "output.field_interval=0",
                                                   *sys.argv[2:]])
    with tempfile.TemporaryDirectory() as out:
        clock = time.perf_counter()
        summary = run_scene(scene, out, progress=False, overwrite=True)
        total = time.perf_counter() - clock
    print(f"total {total:.2f} s, {summary['steps']} steps, {summary['newton_iterations']} Newton iterations")
    parts = {label for _, _, label in PARTS}
    for key, seconds in SPENT.most_common():
        if key not in parts:
            print(f"  {key:30s} {seconds:7.2f} s")
    print("the main run's Newton steps and the model's parts in them:")
    for label, (seconds, calls) in LAST_RUN.items():
        if calls:
            print(f"  {label:30s} {seconds:7.2f} s {calls:7d} calls {1e6 * seconds / calls:7.0f} us")


if __name__ == "__main__":
    main()
