"""The top's axial force and torque of three runs of the paper's string against the soft-string model (Johancsik,
Friesen & Dawson 1984), with the wall's friction as one Coulomb force at the contact point (the default) and as the
paper's two laws (18)-(19) side by side.

    python benchmarks/torque_drag_check.py [--t-end 2] [--runs out/torque-drag] [--table benchmarks/results/torque_drag_check.md]

The runs: rotating on bottom (20 m/h, 60 rpm), sliding (20 m/h, no rotation), rotating with a low feed (1 m/h,
60 rpm).  Each is averaged over the second half of the run.  In a straight horizontal hole the soft-string model
loads each length of pipe on the wall with its weight, and its combined-velocity friction splits mu N along the
contact point's slip: the top pushes with F_bit + mu N V0 / |s| and turns with T_bit + mu N R_ext (R_ext Omega) / |s|,
|s| = sqrt(V0^2 + (R_ext Omega)^2).  N is the weight the wall carries in the FE static state (the end supports
carry the rest, which a soft string has none of), F_bit and T_bit the run's own mean bit force and torque.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
from pathlib import Path

import numpy as np
import xarray as xr

import fenics_drill as fd
from fenics_drill.studies.run import run_scene

ROOT = Path(__file__).parents[1]
CASES = {
    "rotating on bottom": ["drive.axial_velocity=0.005555555555555556", "drive.rotation_speed=6.283185307179586"],
    "sliding": ["drive.axial_velocity=0.005555555555555556", "drive.rotation_speed=0.0"],
    "rotating, low feed": ["drive.axial_velocity=0.0002777777777777778", "drive.rotation_speed=6.283185307179586"],
}
LAWS = {"Coulomb force at the contact point": [], "paper's (18)-(19)": ["contact.friction_model='paper'",
                                                                       "contact.sliding_velocity_scale=1e-3"]}


def second_half_means(directory: Path) -> dict:
    series = xr.open_dataset(directory / "timeseries.h5", engine="h5netcdf", phony_dims="sort")
    t = series["time"].values
    late = t > 0.5 * t[-1]
    weights = np.gradient(t)[late]
    mean = lambda name, sign=1.0: float(np.average(sign * series[name].values[late], weights=weights))  # noqa: E731
    return {"top_force": mean("lambda_1", -1.0), "top_torque": mean("lambda_4", -1.0),
            "bit_force": mean("bit_force", -1.0), "bit_torque": mean("bit_torque", -1.0)}


def soft_string(scene, wall_load: float, bit_force: float, bit_torque: float) -> tuple[float, float]:
    """Top force and torque of the combined-velocity soft-string model in a straight horizontal hole."""
    mu, radius = scene.contact.friction, scene.beam.outer_radius
    feed, surface = scene.drive.axial_velocity, radius * scene.drive.rotation_speed
    slip = math.hypot(feed, surface)
    return bit_force + mu * wall_load * feed / slip, bit_torque + mu * wall_load * radius * surface / slip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--runs", type=Path, default=Path("out/torque-drag"))
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "torque_drag_check.md")
    args = parser.parse_args()
    lines = ["# Torque and drag at the top: the FE runs against the soft-string model", "",
             f"Command: `python benchmarks/torque_drag_check.py --t-end {args.t_end}`. Machine: {platform.machine()}, "
             f"Python {platform.python_version()}, {time.strftime('%Y-%m-%d')}. The paper's 100 m string; means over "
             "the second half of each run; the soft string loads the wall with the weight it carries in the FE static "
             "state and takes the run's own bit force and torque.", "",
             "| run | friction law | top force FE [kN] | soft string [kN] | difference | top torque FE [kN m] | "
             "soft string [kN m] | difference |", "|---|---|---|---|---|---|---|---|"]
    for case, drive in CASES.items():
        for law, friction in LAWS.items():
            scene = fd.load_scene(ROOT / "demos" / "scenes" / "paper.toml",
                                  [f"time.t_end={args.t_end}", "output.field_interval=0", *drive, *friction])
            directory = args.runs / f"{case}-{law}".replace(" ", "_").replace("'", "").replace("(", "").replace(")", "")
            summary_path = directory / "summary.json"
            if not (summary_path.exists() and json.loads(summary_path.read_text()).get("status") in ("finished", "suspect")):
                run_scene(scene, directory, progress=False, overwrite=True)
            summary = json.loads(summary_path.read_text())
            got = second_half_means(directory)
            wall = summary["static"]["contact_force_total"]
            expected_force, expected_torque = soft_string(scene, wall, got["bit_force"], got["bit_torque"])
            law_name = law
            relative = lambda a, b: f"{(a - b) / abs(b):+.2%}" if abs(b) > 1e-9 else "—"  # noqa: E731
            lines.append(f"| {case} | {law_name} | {got['top_force'] / 1e3:.3f} | {expected_force / 1e3:.3f} | "
                         f"{relative(got['top_force'], expected_force)} | {got['top_torque'] / 1e3:.3f} | "
                         f"{expected_torque / 1e3:.3f} | {relative(got['top_torque'], expected_torque)} |")
            print(lines[-1], flush=True)
    args.table.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
