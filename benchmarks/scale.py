"""The cost of a run against the string's length: set-up, wall time per simulated second, steps, Newton iterations,
peak memory, on the paper's cross-section with the default model; rop and efficiency against the converged full
order; and a realistic well.

    python benchmarks/scale.py [--lengths 100 300 1000 3000 6000] [--t-end 1] [--converged-up-to 1000]
                               [--well demos/scenes/well_vbh.toml --well-elements 2000]
                               [--table benchmarks/results/scale.md]

Each length L runs `fenics-drill run demos/scenes/paper.toml --set beam.length=L --set beam.elements=2L --set
time.t_end=T --set output.field_interval=0` in its own process (its peak resident memory is that process's, read
from the kernel's accounting when it ends); the ratios are to the first length's row of the same invocation.  Up to
``--converged-up-to`` the same run at a tenth of time.error_tolerance (the step converged: the full order's own
reference) gives the rop and efficiency the row is compared with.  ``--well`` adds one row for a well scene at its
own length, on ``--well-elements`` elements.
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
sys.path.insert(0, str(ROOT))
from fenics_drill.scene import load_scene  # noqa: E402
PAPER = ROOT / "demos" / "scenes" / "paper.toml"


def measure(length: float | None, t_end: float, scene: Path = PAPER, extra: tuple = ()) -> dict:
    """One run of ``scene`` (at ``length`` with 2 elements per metre, or as the scene has it for None): its
    summary's costs and the process's peak memory."""
    sizes = [] if length is None else ["--set", f"beam.length={length}", "--set",
                                       f"beam.elements={int(round(2 * length))}"]
    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "fenics_drill.cli", "run", str(scene), "--quiet", "--out", out, *sizes,
                   "--set", f"time.t_end={t_end}", "--set", "output.field_interval=0",
                   *(a for setting in extra for a in ("--set", setting))]
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
    parser.add_argument("--lengths", type=float, nargs="+", default=[100.0, 300.0, 1000.0, 3000.0, 6000.0])
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--converged-up-to", type=float, default=1000.0)
    parser.add_argument("--well", type=Path, default=None)
    parser.add_argument("--well-elements", type=int, default=2000)
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "scale.md")
    args = parser.parse_args()
    lines = ["# The cost of a run against the string's length", "",
             f"Command: `python benchmarks/scale.py --lengths {' '.join(f'{x:g}' for x in args.lengths)} --t-end "
             f"{args.t_end:g} --converged-up-to {args.converged_up_to:g}"
             f"{f' --well {args.well} --well-elements {args.well_elements}' if args.well else ''}`. Machine: {platform.machine()}, {os.cpu_count()} cores, "
             f"Python {platform.python_version()}, {time.strftime('%Y-%m-%d')}; one run at a time. The paper's "
             "cross-section, 2 elements per metre, the default model and friction; the converged reference is the "
             "same run at time.error_tolerance = 1e-6 (a tenth of the default).", "",
             "| L [m] | space | unknowns | set-up [s] | integration per simulated s [s] | x first | steps | Newton "
             "iterations (per step) | peak memory [GB] | rop [m/h] | efficiency | rop, efficiency against the "
             "converged |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    first = None
    rows = [(length, None) for length in args.lengths] + ([(None, args.well)] if args.well else [])
    for length, well in rows:
        row = measure(length, args.t_end) if well is None else \
            measure(None, args.t_end, well, (f"beam.elements={args.well_elements}",))
        first = first or row
        rop = f"{row['rop'] * 3600:.3f}" if row["rop"] is not None else "-"
        efficiency = f"{row['efficiency']:.4f}" if row["efficiency"] is not None else "-"
        against = "-"
        if well is None and length <= args.converged_up_to and row["rop"] is not None:
            reference = measure(length, args.t_end, extra=("time.error_tolerance=1e-6",))
            against = (f"{row['rop'] / reference['rop'] - 1:+.2%}, "
                       f"{row['efficiency'] / reference['efficiency'] - 1:+.2%}")
        name = f"{length:g}" if well is None else f"{well.stem} ({load_scene(well).string_length:.0f})"
        lines.append(f"| {name} | {row['space']} | {row['unknowns']} | {row['setup']:.1f} | {row['per_second']:.1f} | "
                     f"{row['per_second'] / first['per_second']:.1f} | {row['steps']} | {row['newton']} "
                     f"({row['newton'] / max(row['steps'], 1):.1f}) | {row['memory_gb']:.2f} | {rop} | {efficiency} | "
                     f"{against} |")
        print(lines[-1], flush=True)
    args.table.write_text("\n".join(lines) + "\n")
    print("written:", args.table)


if __name__ == "__main__":
    main()
