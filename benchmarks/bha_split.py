"""The BHA split against the whole string: a demo well drilling on bottom (by default the 900 m build-and-hold well,
cutting law, the drawworks holding 40 kN on the bit, 60 rpm) with the lateral fields over the whole string
(``model.lateral_length = -1``), over the bottom 150 m (the collars and the heavy-weight pipe) and nowhere (0), each
by ``fenics-drill run``: over the second half of the run, what a drilling engineer reads (the bit's stick-slip, the
surface loads, the rop), the whirl of the watched section 30 m above the bit and the peak von Mises stress, and each
run's wall time per simulated second.

    python benchmarks/bha_split.py [--scene demos/scenes/well_build_hold.toml] [--t-end 2] [--lengths=-1,150,0]
        [--set KEY=VALUE ...] [--name bha_split]

writes benchmarks/results/NAME.md.
"""

from __future__ import annotations

import argparse
import os
import platform
import shlex
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import fenics_drill as fd  # noqa: E402
from fenics_drill.io.timeseries import read_series  # noqa: E402
from speed import machine_unit, processor  # noqa: E402
from fenics_drill.studies.stick_slip import STUCK_SHARE, mean_period  # noqa: E402


def whirl(data: dict, late: np.ndarray) -> tuple[float, float]:
    """The watched section's largest distance from the hole's axis [m] and its mean orbit speed [rpm] (positive
    with the string's rotation: forward whirl) over the rows ``late``."""
    radius = np.hypot(data["section_v"][late], data["section_w"][late])
    angle = np.unwrap(data["section_orbit_angle"][late])
    t = data["time"][late]
    return float(radius.max()), float((angle[-1] - angle[0]) / (t[-1] - t[0]) * 30.0 / np.pi)


def measured(scene_path: str, length: float, t_end: float, settings: list[str]) -> dict:
    scene = fd.load_scene(scene_path, [*settings, f"model.lateral_length={length}", f"time.t_end={t_end}",
                                  "output.field_interval=0"])
    with tempfile.TemporaryDirectory() as out:
        clock = time.perf_counter()
        run = fd.run(scene, out=Path(out) / "run")
        wall = time.perf_counter() - clock
        data, _ = read_series(Path(out) / "run" / "timeseries.h5")
    late = data["time"] >= data["time"][-1] / 2  # the second half of what was run
    weights = np.gradient(data["time"][late])

    def mean(name, sign=1.0):
        return float(np.average(sign * data[name][late], weights=weights))

    spin = data["bit_angular_velocity"][late]
    loads = run.summary.get("torque_and_drag")  # not in the summary of a run that failed
    if loads is None:
        loads = {key: {"mean_second_half": float("nan")} for key in ("hook_load", "surface_torque")}
    speed = scene.drive.rotation_speed
    late_series = {"time": data["time"][late], "bit_angular_velocity": spin}
    period = mean_period(late_series, speed)
    stress = data["max_von_mises"][late]
    radius, orbit = whirl(data, late) if length != 0 else (float("nan"), float("nan"))
    return {"status": f"{run.summary['status']} at {data['time'][-1]:.2f} s", "wall_s": wall, "steps": run.summary.get("steps"),
            "per_second": wall / float(data["time"][-1]),
            "severity": float(np.ptp(spin) / (2.0 * np.average(spin, weights=weights))), "period_s": period,
            "stuck_share": float(np.average(spin < STUCK_SHARE * speed, weights=weights)), "whirl_radius_mm": radius * 1e3,
            "whirl_rpm": orbit, "peak_von_mises_MPa": float(stress.max()) / 1e6,
            "peak_von_mises_x": float(data["max_von_mises_x"][late][int(np.argmax(stress))]),
            "hook_load_kN": loads["hook_load"]["mean_second_half"] / 1e3,
            "surface_torque_kN_m": loads["surface_torque"]["mean_second_half"] / 1e3,
            "weight_on_bit_kN": mean("bit_force", -1.0) / 1e3, "bit_spin_mean": float(np.average(spin, weights=weights)),
            "bit_spin_min": float(spin.min()), "bit_spin_max": float(spin.max()),
            "rop_m_h": mean("bit_velocity") * 3600.0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="demos/scenes/well_build_hold.toml")
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--lengths", default="-1,150,0")
    parser.add_argument("--set", action="append", default=[], dest="settings", help="a scene setting, KEY=VALUE")
    parser.add_argument("--name", default="bha_split", help="the results file's name")
    args = parser.parse_args()
    unit = machine_unit()
    rows = []
    for length in args.lengths.split(","):
        rows.append((float(length), measured(args.scene, float(length), args.t_end, args.settings)))
        print(length, rows[-1], flush=True)
    written = "".join(f" --set {shlex.quote(setting)}" for setting in args.settings)
    lines = ["# The BHA split against the whole string", "",
             f"`python benchmarks/bha_split.py --scene {args.scene} --t-end {args.t_end:g} --lengths={args.lengths}"
             f"{written} --name {args.name}`. Machine: {platform.machine()}, {os.cpu_count()} cores ({processor()}), "
             f"Python {platform.python_version()}; one process; machine unit (benchmarks/speed.py) "
             f"{unit * 1e3:.1f} ms.", "",
             f"{args.scene} on bottom, over the second half of {args.t_end:g} s (means, or extremes where a range is "
             "given):", "",
             "| lateral_length [m] | status | wall [s] | per simulated s [s] | [units] | steps | hook load [kN] "
             "| surface torque [kN m] | WOB [kN] | rop [m/h] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for length, r in rows:
        lines.append(f"| {length:g} | {r['status']} | {r['wall_s']:.1f} | {r['per_second']:.2f} | "
                     f"{r['per_second'] / unit:.0f} | {r['steps']} | {r['hook_load_kN']:.2f} | "
                     f"{r['surface_torque_kN_m']:.3f} | {r['weight_on_bit_kN']:.2f} | {r['rop_m_h']:.2f} |")
    lines += ["", "| lateral_length [m] | bit spin mean [rad/s] | bit spin range [rad/s] | severity | period [s] "
              "| stuck share | whirl radius [mm] | whirl [rpm] | peak von Mises [MPa] | at x [m] |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for length, r in rows:
        period = "-" if r["period_s"] is None else f"{r['period_s']:.3f}"
        radius = "-" if np.isnan(r["whirl_radius_mm"]) else f"{r['whirl_radius_mm']:.1f}"
        orbit = "-" if np.isnan(r["whirl_rpm"]) else f"{r['whirl_rpm']:.1f}"
        lines.append(f"| {length:g} | {r['bit_spin_mean']:.3f} | {r['bit_spin_min']:.2f} to {r['bit_spin_max']:.2f} | "
                     f"{r['severity']:.3f} | {period} | {r['stuck_share']:.3f} | {radius} | {orbit} | "
                     f"{r['peak_von_mises_MPa']:.1f} | {r['peak_von_mises_x']:.0f} |")
    text = "\n".join(lines) + "\n"
    Path(f"benchmarks/results/{args.name}.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
