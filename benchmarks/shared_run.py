"""Strong scaling of one run over two MPI ranks: the same full-order string on 1 and 2 ranks, its costs and how far
the two summaries lie apart.

    python benchmarks/shared_run.py [--lengths 1000 3000] [--t-end 0.3] [--repeats 3]
                                    [--well demos/scenes/well_vbh.toml --well-elements 2000]
                                    [--table benchmarks/results/shared_run.md]

Each length L runs `mpiexec -n P fenics-drill run demos/scenes/paper.toml --set beam.length=L --set
beam.elements=2L --set time.t_end=T --set output.field_interval=0` for P = 1 and 2, one run at a time,
``--repeats`` times each (1 and 2 ranks in turn); ``--well`` adds a well scene at its own length on
``--well-elements`` elements.  Peak memory is the largest rank's resident
set (the kernel's accounting of mpiexec's children).  The times are the fastest of the repeats (a shared machine's
pauses only lengthen a run), with the slowest over the fastest in brackets; the speed-up is the one rank's
integration time over the two ranks' (the set-up, the same on both ranks, is not split); "largest difference" is
the largest relative difference between the two summaries' results (rop, efficiency, mean bit velocity, peak
stress, stick-slip severity, hook load and surface torque, input and dissipated
work, impacts).
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


def run(scene: Path, sizes: list[str], t_end: float, ranks: int) -> dict:
    """The summary of one run of ``scene`` with the ``sizes`` settings on ``ranks`` ranks, and its peak memory."""
    with tempfile.TemporaryDirectory() as out:
        command = [str(MPIEXEC), "-n", str(ranks), sys.executable, "-m", "fenics_drill.cli", "run", str(scene),
                   "--quiet", "--out", out, *sizes, "--set", f"time.t_end={t_end}", "--set", "output.field_interval=0"]
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(process.pid, 0)
        if status != 0:
            raise RuntimeError(f"{' '.join(command)} ended with status {status}")
        return {**json.loads((Path(out) / "summary.json").read_text()), "memory_gb": usage.ru_maxrss / 1e6}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lengths", type=float, nargs="+", default=[1000.0, 3000.0])
    parser.add_argument("--t-end", type=float, default=0.3)
    parser.add_argument("--well", type=Path, default=None)
    parser.add_argument("--well-elements", type=int, default=2000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "shared_run.md")
    args = parser.parse_args()
    cases = [(f"{length:g}", PAPER, ["--set", f"beam.length={length}", "--set",
                                     f"beam.elements={int(round(2 * length))}"]) for length in args.lengths]
    if args.well is not None:
        cases.append((f"{args.well.stem} ({args.well_elements} elements)", args.well,
                      ["--set", f"beam.elements={args.well_elements}"]))
    rows = []
    for name, scene, sizes in cases:
        runs = {1: [], 2: []}
        for _ in range(args.repeats):
            for ranks in (1, 2):
                runs[ranks].append(run(scene, sizes, args.t_end, ranks))
        one, two = runs[1][0], runs[2][0]
        a, b = numbers(one), numbers(two)
        differences = {k: abs(b[k] - a[k]) / max(abs(a[k]), 1e-300) for k in a if k in b and a[k] != 0.0}
        worst = max(differences, key=differences.get) if differences else ""
        setup = {r: [s["setup_time_s"] for s in runs[r]] for r in runs}
        loop = {r: [s["integration_time_s"] for s in runs[r]] for r in runs}

        def cell(values: dict) -> str:
            return " / ".join(f"{min(values[r]):.1f} ({max(values[r]) / min(values[r]):.2f})" for r in (1, 2))

        row = (f"| {name} | {one['reduced_size']} | {one['steps']} / {two['steps']} | "
               f"{one['newton_iterations']} / {two['newton_iterations']} | {cell(setup)} | {cell(loop)} | "
               f"{min(loop[1]) / min(loop[2]):.2f} | {max(s['memory_gb'] for s in runs[1]):.2f} / "
               f"{max(s['memory_gb'] for s in runs[2]):.2f} | {differences.get(worst, 0.0):.1e} ({worst}) |")
        rows.append(row)
        print(row, flush=True)
    lines = [
        "# One run on two MPI ranks",
        "",
        f"`python benchmarks/shared_run.py --lengths {' '.join(f'{x:g}' for x in args.lengths)} --t-end {args.t_end:g} "
        f"--repeats {args.repeats}"
        + (f" --well {args.well.relative_to(ROOT) if args.well.is_absolute() else args.well} --well-elements "
           f"{args.well_elements}" if args.well is not None else "") + "`"
        f" on {platform.node()} ({platform.processor() or platform.machine()}, 2 cores), "
        f"{time.strftime('%Y-%m-%d')}: the paper's cross-section in the full order, 2 elements per metre, "
        f"{args.t_end:g} s simulated, one run at a time, {args.repeats} times each; each cell is 1 rank / 2 ranks, the "
        "fastest of the repeats with the slowest over it in brackets.",
        "",
        "| L [m] | unknowns | steps | Newton iterations | set-up [s] | integration [s] | speed-up | peak memory "
        "[GB] | largest difference of the summaries |",
        "|---|---|---|---|---|---|---|---|---|",
        *rows,
        "",
    ]
    args.table.write_text("\n".join(lines))


if __name__ == "__main__":
    main()
