"""The soft-string study of the demo wells: surface loads and their convergence with the element length, and the
cost, up to a 6 km well.

    python benchmarks/torque_drag_wells.py [--table benchmarks/results/torque_drag_wells.md]

For each well and element length: hook load and surface torque of each operation, and the study's wall time (the
computation, without reading the scene or writing files).  The 6 km well is the vertical-build-horizontal demo with
its horizontal section and the lateral's drill pipe extended by 3 km.
"""

from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

import fenics_drill as fd
from fenics_drill.studies.torque_drag import torque_drag_study

ROOT = Path(__file__).parents[1]
SCENES = ROOT / "demos" / "scenes"
LONG = ["well.md=[0.0, 1000.0, 1675.0, 6000.0]", "well.hole_bottom=[1700.0, 6000.0]"]


def long_well():
    scene = fd.load_scene(SCENES / "well_vbh.toml", LONG)
    sections = [dict(s) for s in scene.string.sections]
    lateral = next(k for k, s in enumerate(sections) if "lateral" in s.get("name", ""))
    sections[lateral]["length"] += 3000.0
    return scene.with_changes(string={"sections": sections})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "torque_drag_wells.md")
    args = parser.parse_args()
    wells = {"vertical-build-horizontal, 3000 m (well_vbh.toml)": fd.load_scene(SCENES / "well_vbh.toml"),
             "3D build-and-turn, 3500 m (well_3d.toml)": fd.load_scene(SCENES / "well_3d.toml"),
             "vertical-build-horizontal, 6000 m": long_well()}
    lines = ["# Soft-string torque and drag of the demo wells", "",
             f"Command: `python benchmarks/torque_drag_wells.py`. Machine: {platform.machine()}, Python "
             f"{platform.python_version()}, {time.strftime('%Y-%m-%d')}. Hook load [kN] / surface torque [kN m] per "
             "operation; wall time of the computation (five operations, buckling loads).", ""]
    for title, scene in wells.items():
        lines += [f"## {title}", "", "| element length [m] | elements | " + " | ".join(
            o.replace("_", " ") for o in scene.torque_drag.operations) + " | wall time [s] |",
                  "|---|---|" + "---|" * len(scene.torque_drag.operations) + "---|"]
        for h in (30.0, 10.0, 3.0, 1.0):
            study = torque_drag_study(scene.with_changes(torque_drag={"element_length": h}))
            report = study["report"]
            cells = [f"{op['hook_load_N'] / 1e3:.2f} / {op['surface_torque_Nm'] / 1e3:.3f}"
                     for op in report["operations"].values()]
            lines.append(f"| {h:g} | {report['elements']} | " + " | ".join(cells) + f" | {report['wall_time_s']:.2f} |")
            print(lines[-1], flush=True)
        lines.append("")
    args.table.write_text("\n".join(lines))
    print(f"-> {args.table}")


if __name__ == "__main__":
    main()
