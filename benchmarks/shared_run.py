"""Strong scaling of one run over two MPI ranks: the same full-order string on 1 and 2 ranks, its costs and how far
the two summaries lie apart.

    python benchmarks/shared_run.py [--lengths 1000 3000] [--t-end 0.3] [--table benchmarks/results/shared_run.md]

Each length L runs `mpiexec -n P fenics-drill run demos/scenes/paper.toml --set beam.length=L --set
beam.elements=2L --set time.t_end=T --set output.field_interval=0` for P = 1 and 2, one run at a time.  The
speed-up is the one rank's integration time over the two ranks' (the set-up, the same on both ranks, is not
split); "largest difference" is the largest relative difference between the two summaries' results (rop,
efficiency, mean bit velocity, peak stress, stick-slip severity, hook load and surface torque, input and dissipated
work, impacts).
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).parents[1]
PAPER = ROOT / "demos" / "scenes" / "paper.toml"
MPIEXEC = Path(sys.executable).parent / "mpiexec"
#: the results compared, by their dotted keys in summary.json
RESULTS = ("rop", "efficiency", "mean_bit_velocity", "max_von_mises.value", "stick_slip.stick_slip_severity",
           "torque_and_drag.hook_load.mean_second_half", "torque_and_drag.surface_torque.mean_second_half",
           "energy.input_work", "energy.dissipated", "impacts_total")


def numbers(summary: dict) -> dict:
    """The summary's :data:`RESULTS` that it holds."""
    out = {}
    for key in RESULTS:
        value = summary
        for part in key.split("."):
            value = value.get(part) if isinstance(value, dict) else None
        if isinstance(value, (int, float)):
            out[key] = float(value)
    return out


def run(length: float, t_end: float, ranks: int) -> dict:
    with tempfile.TemporaryDirectory() as out:
        command = [str(MPIEXEC), "-n", str(ranks), sys.executable, "-m", "fenics_drill.cli", "run", str(PAPER),
                   "--quiet", "--out", out, "--set", f"beam.length={length}", "--set",
                   f"beam.elements={int(round(2 * length))}", "--set", f"time.t_end={t_end}", "--set",
                   "output.field_interval=0"]
        clock = time.perf_counter()
        subprocess.run(command, stdout=subprocess.DEVNULL, check=True)
        wall = time.perf_counter() - clock
        return {**json.loads((Path(out) / "summary.json").read_text()), "command_wall_s": wall}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lengths", type=float, nargs="+", default=[1000.0, 3000.0])
    parser.add_argument("--t-end", type=float, default=0.3)
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "shared_run.md")
    args = parser.parse_args()
    rows = []
    for length in args.lengths:
        one, two = (run(length, args.t_end, ranks) for ranks in (1, 2))
        a, b = numbers(one), numbers(two)
        differences = {k: abs(b[k] - a[k]) / max(abs(a[k]), 1e-300) for k in a if k in b and a[k] != 0.0}
        worst = max(differences, key=differences.get) if differences else ""
        row = (f"| {length:g} | {one['reduced_size']} | {one['steps']} / {two['steps']} | "
               f"{one['newton_iterations']} / {two['newton_iterations']} | {one['setup_time_s']:.1f} / "
               f"{two['setup_time_s']:.1f} | {one['integration_time_s']:.1f} / {two['integration_time_s']:.1f} | "
               f"{one['integration_time_s'] / two['integration_time_s']:.2f} | "
               f"{differences.get(worst, 0.0):.1e} ({worst}) |")
        rows.append(row)
        print(row, flush=True)
    lines = [
        "# One run on two MPI ranks",
        "",
        f"`python benchmarks/shared_run.py --lengths {' '.join(f'{x:g}' for x in args.lengths)} --t-end {args.t_end:g}`"
        f" on {platform.node()} ({platform.processor() or platform.machine()}, 2 cores), "
        f"{time.strftime('%Y-%m-%d')}: the paper's cross-section in the full order, 2 elements per metre, "
        f"{args.t_end:g} s simulated, one run at a time; each cell is 1 rank / 2 ranks.",
        "",
        "| L [m] | unknowns | steps | Newton iterations | set-up [s] | integration [s] | speed-up | largest "
        "difference of the summaries |",
        "|---|---|---|---|---|---|---|---|",
        *rows,
        "",
    ]
    args.table.write_text("\n".join(lines))


if __name__ == "__main__":
    main()
