"""The finite-element string at rest in the demo wells against the soft string: hook load and the wall's total force,
with the FE mesh refined, and the cost of the static state.

    python benchmarks/fe_wells.py [--table benchmarks/results/fe_wells.md]

For each well and element count: the FE static state's hook load and total wall force, the soft string's off bottom
(no axial slip: no axial friction; 1 m elements), their ratio, the Newton iterations and the wall time of the FE
model and static solve (the mesh, operators and the Newton solve, without reading the scene or writing files).
"""

from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

import numpy as np

import fenics_drill as fd
from fenics_drill.studies.prepare import prepare
from fenics_drill.studies.torque_drag import torque_drag_study

ROOT = Path(__file__).parents[1]
SCENES = ROOT / "demos" / "scenes"
WELLS = {"vertical-build-horizontal, 3000 m (well_vbh.toml)": "well_vbh.toml",
         "3D build-and-turn, 3500 m (well_3d.toml)": "well_3d.toml"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "fe_wells.md")
    parser.add_argument("--elements", type=int, nargs="+", default=[500, 1000, 2000])
    args = parser.parse_args()
    lines = ["# The FE string at rest in the demo wells against the soft string", "",
             f"Command: `python benchmarks/fe_wells.py`. Machine: {platform.machine()}, Python "
             f"{platform.python_version()}, {time.strftime('%Y-%m-%d')}. The soft string off bottom at 1 m elements; "
             "the FE static state (full order) with the scene's string and hole sections along its survey.", ""]
    for title, name in WELLS.items():
        scene = fd.load_scene(SCENES / name)
        soft = torque_drag_study(scene.with_changes(torque_drag={"element_length": 1.0}))
        hook = soft["report"]["operations"]["rotating_off_bottom"]["hook_load_N"]
        wall = float(np.sum(soft["profiles"]["wall_force_per_length_rotating_off_bottom"].values
                            * np.diff(soft["profiles"]["md"].values)))
        lines += [f"## {title}", "", f"Soft string: hook load {hook / 1e3:.2f} kN, wall force {wall / 1e3:.1f} kN.", "",
                  "| elements | FE hook load [kN] | / soft string | FE wall force [kN] | / soft string | Newton iterations "
                  "| wall time [s] |", "|---|---|---|---|---|---|---|"]
        lines += [static_row(scene, elements, hook, wall) for elements in args.elements] + [""]
    args.table.write_text("\n".join(lines))
    print("written:", args.table)


def static_row(scene, elements: int, hook: float, wall: float) -> str:
    """The FE static state of ``scene`` at ``elements`` against the soft string's hook load and wall force."""
    clock = time.perf_counter()
    prepared = prepare(scene.with_changes(beam={"elements": elements}), dynamics=False)
    seconds = time.perf_counter() - clock
    static = prepared.static
    row = (f"| {prepared.model.disc.elements} | {static['hook_load'] / 1e3:.2f} | {static['hook_load'] / hook:.5f} | "
           f"{static['contact_force_total'] / 1e3:.1f} | {static['contact_force_total'] / wall:.4f} | "
           f"{static['newton_iterations']} | {seconds:.1f} |")
    print(row, flush=True)
    return row


if __name__ == "__main__":
    main()
