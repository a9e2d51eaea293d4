"""The cost of a run against the string's length: set-up, wall time per simulated second, steps, Newton iterations,
peak memory, on the paper's cross-section with the default model.

    python benchmarks/scale.py [--lengths 100 300 1000] [--t-end 0.5] [--table benchmarks/results/scale.md]

Each length L runs `fenics-drill run demos/scenes/paper.toml --set beam.length=L --set beam.elements=2L --set
time.t_end=T --set output.field_interval=0` in its own process (its peak resident memory is that process's, read
from the kernel's accounting when it ends); the ratios are to the first length's row of the same invocation.
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
from pathlib import Path

ROOT = Path(__file__).parents[1]
PAPER = ROOT / "demos" / "scenes" / "paper.toml"


def measure(length: float, t_end: float) -> dict:
    """One run of the paper's cross-section at ``length``: its summary's costs and the process's peak memory."""
    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "fenics_drill.cli", "run", str(PAPER), "--quiet", "--out", out,
                   "--set", f"beam.length={length}", "--set", f"beam.elements={int(round(2 * length))}",
                   "--set", f"time.t_end={t_end}", "--set", "output.field_interval=0"]
        clock = time.perf_counter()
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - clock
        summary = json.loads((Path(out) / "summary.json").read_text())
    return {"length": length, "status": summary["status"], "unknowns": summary["reduced_size"],
            "space": summary["discretisation"]["space"], "setup": summary["setup_time_s"],
            "per_second": summary["integration_time_s"] / t_end, "steps": summary["steps"],
            "newton": summary["newton_iterations"], "memory_gb": usage.ru_maxrss / 1e6, "wall": wall,
            "rop": summary.get("rop"), "efficiency": summary.get("efficiency")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lengths", type=float, nargs="+", default=[100.0, 300.0, 1000.0])
    parser.add_argument("--t-end", type=float, default=0.5)
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "scale.md")
    args = parser.parse_args()
    lines = ["# The cost of a run against the string's length", "",
             f"Command: `python benchmarks/scale.py --lengths {' '.join(f'{x:g}' for x in args.lengths)} --t-end "
             f"{args.t_end:g}`. Machine: {platform.machine()}, {os.cpu_count()} cores, Python "
             f"{platform.python_version()}, {time.strftime('%Y-%m-%d')}; one run at a time. The paper's cross-section, "
             "2 elements per metre, the default model and friction.", "",
             "| L [m] | space | unknowns | set-up [s] | integration per simulated s [s] | x first | steps | Newton "
             "iterations (per step) | peak memory [GB] | rop [m/h] | efficiency |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    first = None
    for length in args.lengths:
        row = measure(length, args.t_end)
        first = first or row
        rop = f"{row['rop'] * 3600:.3f}" if row["rop"] is not None else "-"
        efficiency = f"{row['efficiency']:.4f}" if row["efficiency"] is not None else "-"
        lines.append(f"| {length:g} | {row['space']} | {row['unknowns']} | {row['setup']:.1f} | {row['per_second']:.1f} | "
                     f"{row['per_second'] / first['per_second']:.1f} | {row['steps']} | {row['newton']} "
                     f"({row['newton'] / max(row['steps'], 1):.1f}) | {row['memory_gb']:.2f} | {rop} | {efficiency} |")
        print(lines[-1], flush=True)
    args.table.write_text("\n".join(lines) + "\n")
    print("written:", args.table)


if __name__ == "__main__":
    main()
