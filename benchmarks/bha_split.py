"""The BHA split against the whole string: 2 s of the 900 m build-and-hold demo well drilling on bottom (cutting
law, the drawworks holding 40 kN on the bit, 60 rpm) with the lateral fields over the whole string
(``model.lateral_length = -1``), over the bottom 150 m (the collars and the heavy-weight pipe) and nowhere (0), each
by ``fenics-drill run``; the means over the second second of what a drilling engineer reads, and each run's wall time.

    python benchmarks/bha_split.py [--t-end 2] [--lengths=-1,150,0] [--set KEY=VALUE ...] [--name bha_split]

writes benchmarks/results/NAME.md.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import fenics_drill as fd  # noqa: E402
from fenics_drill.io.timeseries import read_series  # noqa: E402
from speed import machine_unit, processor  # noqa: E402

SCENE = "demos/scenes/well_build_hold.toml"


def measured(length: float, t_end: float, settings: list[str]) -> dict:
    scene = fd.load_scene(SCENE, [*settings, f"model.lateral_length={length}", f"time.t_end={t_end}",
                                  "output.field_interval=0"])
    with tempfile.TemporaryDirectory() as out:
        clock = time.perf_counter()
        run = fd.run(scene, out=Path(out) / "run")
        wall = time.perf_counter() - clock
        data, _ = read_series(Path(out) / "run" / "timeseries.h5")
    late = data["time"] >= t_end / 2
    weights = np.gradient(data["time"][late])

    def mean(name, sign=1.0):
        return float(np.average(sign * data[name][late], weights=weights))

    spin = data["bit_angular_velocity"][late]
    loads = run.summary["torque_and_drag"]
    return {"status": run.summary["status"], "wall_s": wall, "steps": run.summary.get("steps"),
            "hook_load_kN": loads["hook_load"]["mean_second_half"] / 1e3,
            "surface_torque_kN_m": loads["surface_torque"]["mean_second_half"] / 1e3,
            "weight_on_bit_kN": mean("bit_force", -1.0) / 1e3, "bit_spin_mean": float(np.average(spin, weights=weights)),
            "bit_spin_min": float(spin.min()), "bit_spin_max": float(spin.max()),
            "rop_m_h": mean("bit_velocity") * 3600.0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--lengths", default="-1,150,0")
    parser.add_argument("--set", action="append", default=[], dest="settings", help="a scene setting, KEY=VALUE")
    parser.add_argument("--name", default="bha_split", help="the results file's name")
    args = parser.parse_args()
    unit = machine_unit()
    rows = [(float(length), measured(float(length), args.t_end, args.settings)) for length in args.lengths.split(",")]
    written = "".join(f" --set \"{setting}\"" for setting in args.settings)
    lines = ["# The BHA split against the whole string", "",
             f"`python benchmarks/bha_split.py --t-end {args.t_end:g} --lengths={args.lengths}{written} --name "
             f"{args.name}`. Machine: "
             f"{platform.machine()}, {os.cpu_count()} cores ({processor()}), Python {platform.python_version()}; one "
             f"process; machine unit (benchmarks/speed.py) {unit * 1e3:.1f} ms.", "",
             f"{SCENE} on bottom, means over the second half of {args.t_end:g} s:", "",
             "| lateral_length [m] | status | wall [s] | steps | hook load [kN] | surface torque [kN m] | WOB [kN] "
             "| bit spin mean [rad/s] | bit spin range [rad/s] | rop [m/h] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for length, r in rows:
        lines.append(f"| {length:g} | {r['status']} | {r['wall_s']:.1f} | {r['steps']} | {r['hook_load_kN']:.2f} | "
                     f"{r['surface_torque_kN_m']:.3f} | {r['weight_on_bit_kN']:.2f} | {r['bit_spin_mean']:.3f} | "
                     f"{r['bit_spin_min']:.2f} to {r['bit_spin_max']:.2f} | {r['rop_m_h']:.2f} |")
    text = "\n".join(lines) + "\n"
    Path(f"benchmarks/results/{args.name}.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
