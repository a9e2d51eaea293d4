"""What the default runs cost, in seconds and in machine units, and how accurate they are against the step-converged
full order.

    python benchmarks/speed.py [--rows nominal 3km 6km vbh] [--reference-rows nominal 3km vbh] [--workers 1]
                               [--table benchmarks/results/speed.md]

Rows (each `fenics-drill run` in its own process, default model and friction, no field output):

- ``nominal``: `demos/scenes/paper.toml`, 10 s (its 500 elements);
- ``3km``, ``6km``: the paper's cross-section at 3000 and 6000 m, 2 elements per metre, 1 s;
- ``vbh``: `demos/scenes/well_vbh.toml` on 2000 elements, 1 s.

Beside each run's cost: its Newton iterations (those of the accepted and rejected steps), the Newton solves that
failed and cut the step (their iterations are not counted there), and the saddle matrices (76) factorised per
simulated second (the failed solves' included; each about one machine unit on the 3 km band).

The machine unit is one LAPACK banded LU and solve (dgbtrf + dgbtrs) of a 54 000-unknown band with kl = ku = 14,
the full order's band at 3 km, timed in this process before and after the runs (median of 7): a row's cost in units
can be compared across machines.  The reference of a row (``--reference-rows``) is the same run at a tenth of
time.error_tolerance (the step converged); the table gives the row's relative difference in rop, efficiency, peak
von Mises stress, stick-slip severity, mean hook load and mean surface torque (second half of the run).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import scipy.linalg.lapack as lapack

ROOT = Path(__file__).resolve().parents[1]
PAPER, VBH = ROOT / "demos" / "scenes" / "paper.toml", ROOT / "demos" / "scenes" / "well_vbh.toml"
#: row name -> (scene, settings, simulated time [s])
ROWS = {
    "nominal": (PAPER, (), 10.0),
    "3km": (PAPER, ("beam.length=3000", "beam.elements=6000"), 1.0),
    "6km": (PAPER, ("beam.length=6000", "beam.elements=12000"), 1.0),
    "vbh": (VBH, ("beam.elements=2000",), 1.0),
}
#: The machine unit's band: the full order's at 3 km (6000 elements, 9 unknowns each), its bandwidths.
UNIT_SIZE, UNIT_BANDWIDTH = 54_000, 14
DEFAULT_TOLERANCE = 1e-5  # time.error_tolerance's default [m]


def machine_unit(repeats: int = 7) -> float:
    """Median wall time [s] of one dgbtrf + dgbtrs of a diagonally dominant random band of UNIT_SIZE unknowns."""
    rng = np.random.default_rng(0)
    kl = ku = UNIT_BANDWIDTH
    band = np.zeros((2 * kl + ku + 1, UNIT_SIZE), order="F")
    band[kl:] = rng.standard_normal((kl + ku + 1, UNIT_SIZE))
    band[kl + ku] += 4.0 * (kl + ku + 1)
    rhs = rng.standard_normal(UNIT_SIZE)
    times = []
    for _ in range(repeats):
        work = band.copy(order="F")
        clock = time.perf_counter()
        lu, pivots, info = lapack.dgbtrf(work, kl, ku, overwrite_ab=1)
        _, info_solve = lapack.dgbtrs(lu, kl, ku, rhs, pivots)
        times.append(time.perf_counter() - clock)
        assert info == 0 and info_solve == 0
    return float(np.median(times))


def processor() -> str:
    """The CPU's model name, as the kernel reports it."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "CPU not reported"


def write_result(name: str, lines: list[str]) -> Path:
    """benchmarks/results/``name`` holding ``lines``, one per line; its path, printed."""
    out = Path(__file__).resolve().parent / "results" / name
    out.write_text("\n".join(lines) + "\n")
    print(f"-> {out}")
    return out


def machine() -> str:
    """This machine as a results file states it: architecture, cores, CPU and Python."""
    return (f"{platform.machine()}, {os.cpu_count()} cores ({processor()}), Python {platform.python_version()}")


def run(scene: Path, settings: tuple, t_end: float, tolerance: float | None = None) -> dict:
    """One `fenics-drill run` in its own process: its summary, the whole run's wall time and its peak memory."""
    with tempfile.TemporaryDirectory() as out:
        extra = [] if tolerance is None else [f"time.error_tolerance={tolerance}"]
        command = [sys.executable, "-m", "fenics_drill.cli", "run", str(scene), "--quiet", "--out", out,
                   "--set", f"time.t_end={t_end}", "--set", "output.field_interval=0",
                   *(a for setting in (*settings, *extra) for a in ("--set", setting))]
        clock = time.perf_counter()
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, cwd=ROOT)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - clock
        summary = json.loads((Path(out) / "summary.json").read_text())
    summary["whole_run_s"], summary["peak_memory_gb"] = wall, usage.ru_maxrss / 1e6
    return summary


QUANTITIES = {  # name -> how to read it from a summary
    "rop": lambda s: s.get("rop"),
    "efficiency": lambda s: s.get("efficiency"),
    "peak stress": lambda s: s.get("max_von_mises", {}).get("value"),
    "stick-slip severity": lambda s: s.get("stick_slip", {}).get("stick_slip_severity"),
    "hook load": lambda s: s.get("torque_and_drag", {}).get("hook_load", {}).get("mean_second_half"),
    "surface torque": lambda s: s.get("torque_and_drag", {}).get("surface_torque", {}).get("mean_second_half"),
}


def differences(row: dict, reference: dict | None) -> str:
    if reference is None:
        return "-"
    parts = []
    for name, read in QUANTITIES.items():
        mine, theirs = read(row), read(reference)
        if mine is None or theirs is None or theirs == 0:
            continue
        parts.append(f"{name} {mine / theirs - 1:+.2%}")
    return ", ".join(parts)


def cost_cells(row: dict, reference: dict | None, unit: float, digits: int = 1) -> str:
    """A run's table cells: Newton iterations (per step), integration per simulated second [s] and in machine units,
    and its differences from ``reference``."""
    per_second = row["integration_time_s"] / row["t_end"]
    return (f"{row['newton_iterations']} ({row['newton_iterations'] / max(row['steps'], 1):.1f}) | "
            f"{per_second:.{digits}f} | {per_second / unit:.0f} | {differences(row, reference)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", nargs="+", default=list(ROWS), choices=list(ROWS))
    parser.add_argument("--reference-rows", nargs="*", default=["nominal", "3km", "vbh"], choices=list(ROWS))
    parser.add_argument("--workers", type=int, default=1, help="runs at a time (one core each)")
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "speed.md")
    args = parser.parse_args()
    unit_before = machine_unit()
    print(f"machine unit: {unit_before * 1e3:.1f} ms", flush=True)
    jobs = [(name, None) for name in args.rows] + [(name, DEFAULT_TOLERANCE / 10) for name in args.rows
                                                     if name in args.reference_rows]

    def measure(job):
        name, tolerance = job
        scene, settings, t_end = ROWS[name]
        result = run(scene, settings, t_end, tolerance)
        print(f"{name} {'reference' if tolerance else ''}: {result['whole_run_s']:.1f} s", flush=True)
        return job, result

    with ThreadPoolExecutor(args.workers) as pool:
        results = dict(pool.map(measure, jobs))
    unit_after = machine_unit()
    unit = 0.5 * (unit_before + unit_after)
    lines = [
        "# What the default runs cost", "",
        f"Command: `python benchmarks/speed.py --rows {' '.join(args.rows)} --reference-rows "
        f"{' '.join(args.reference_rows)} --workers {args.workers}`. Machine: {platform.machine()}, "
        f"{os.cpu_count()} cores ({processor()}), Python {platform.python_version()}; "
        f"{args.workers} run(s) at a time, one core each.", "",
        f"Machine unit: one LAPACK dgbtrf + dgbtrs of {UNIT_SIZE} unknowns, kl = ku = {UNIT_BANDWIDTH}: "
        f"{unit_before * 1e3:.1f} ms before the runs, {unit_after * 1e3:.1f} ms after; the mean is the unit.", "",
        "| run | space (integrator) | unknowns | steps | Newton iterations (per step) | failed Newton solves "
        "| factorisations per simulated s | set-up [s] | whole run [s] | integration per simulated s [s] | [units] "
        "| peak memory [GB] | against the step-converged run |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name in args.rows:
        row = results[(name, None)]
        reference = results.get((name, DEFAULT_TOLERANCE / 10))
        per_second = row["integration_time_s"] / row["t_end"]
        space = row["discretisation"]["space"]
        lines.append(
            f"| {name} ({row['t_end']:g} s) | {space} (Newmark, Newton) | {row['reduced_size']} | {row['steps']} | "
            f"{row['newton_iterations']} ({row['newton_iterations'] / max(row['steps'], 1):.1f}) | "
            f"{row['newton_failures']} | {row['factorisations'] / row['t_end']:.0f} | {row['setup_time_s']:.1f} | {row['whole_run_s']:.1f} | {per_second:.1f} | {per_second / unit:.0f} | "
            f"{row['peak_memory_gb']:.2f} | {differences(row, reference)} |")
    if "3km" in args.rows and "6km" in args.rows:
        ratio = (results[("6km", None)]["integration_time_s"] / results[("3km", None)]["integration_time_s"])
        lines += ["", f"6 km costs {ratio:.2f} times 3 km per simulated second."]
    args.table.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print("written:", args.table)


if __name__ == "__main__":
    main()
