"""Wall time of the paper-scene modal analysis (Eq. 62 + Section 6.3 basis selection).

    .venv/bin/python benchmarks/modal_timing.py

Runs the analysis once to compile the forms (FFCx JIT, cached on disk), then
times ``repeats`` runs and prints the median, split into assembly and eigensolve.
"""

from __future__ import annotations

import platform
import statistics
import time
from pathlib import Path

from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.reduction.modes import solve_modes
from fenics_drill.studies.modal_report import modal_report
from fenics_drill.scene import load_scene

SCENE = Path(__file__).parents[1] / "demos" / "scenes" / "paper.toml"


def main(repeats: int = 5) -> None:
    scene = load_scene(SCENE)
    modal_report(scene)  # JIT warm-up
    totals, setups, solves = [], [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        disc = BeamDiscretization.from_scene(scene)
        t1 = time.perf_counter()
        basis = solve_modes(disc, scene.modal.f_star_max)
        t2 = time.perf_counter()
        totals.append(t2 - t0)
        setups.append(t1 - t0)
        solves.append(t2 - t1)
    print(f"machine: {platform.processor() or platform.machine()}, {platform.python_version()}")
    print(f"paper scene: {disc.ndofs} dofs, {len(basis)} modes with f* <= 4")
    print(f"median over {repeats}: total {statistics.median(totals):.2f} s "
          f"(mesh+space {statistics.median(setups):.2f} s, assembly+SLEPc {statistics.median(solves):.2f} s)")


if __name__ == "__main__":
    main()
