"""Would a step controller on the quantities the accuracy is judged by admit larger steps?  The displacement error
tolerance (``time.error_tolerance``) loosened, each run against the step-converged one.

    python benchmarks/step_tolerance.py [--length 100] [--t-end 2] [--values 1e-5 3e-5 1e-4 3e-4]
                                        [--table benchmarks/results/step_tolerance.md]

The paper's cross-section at ``--length`` (2 elements per metre; 100 m: the paper's scene as it is, 500 elements),
its default model (the full order with the Coulomb wall), one run per tolerance, each against the run at a tenth of
the default tolerance.  If rop, efficiency and peak stress stay where the step-converged run has them while the
tolerance on the displacements is loosened, a controller on those quantities would take the larger steps; if the
step count does not fall, the step is bounded by something else (the band's nominal step, the wall's impacts).
Costs in seconds and in the machine unit of :mod:`speed`, measured in the same invocation.
"""

from __future__ import annotations

import argparse
import os
import platform
from pathlib import Path

from speed import DEFAULT_TOLERANCE, PAPER, ROOT, cost_cells, machine_unit, processor, run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=100.0)
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--values", type=float, nargs="+", default=[1e-5, 3e-5, 1e-4, 3e-4])
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "step_tolerance.md")
    args = parser.parse_args()
    sizes = () if args.length == 100 else (f"beam.length={args.length:g}", f"beam.elements={int(2 * args.length)}")
    unit = machine_unit()
    reference = run(PAPER, sizes, args.t_end, DEFAULT_TOLERANCE / 10)
    lines = ["# The step's error tolerance: speed against the quantities the accuracy is judged by", "",
             f"Command: `python benchmarks/step_tolerance.py --length {args.length:g} --t-end {args.t_end:g} --values "
             f"{' '.join(f'{v:g}' for v in args.values)}`. Machine: {platform.machine()}, {os.cpu_count()} cores "
             f"({processor()}), Python {platform.python_version()}; one run at a time. The paper's cross-section, "
             f"{args.length:g} m, {args.t_end:g} s, its default model; machine unit (one LAPACK banded LU and solve of "
             f"54 000 unknowns, kl = ku = 14): {unit * 1e3:.1f} ms.", "",
             f"Reference: time.error_tolerance = {DEFAULT_TOLERANCE / 10:g} m ({reference['steps']} steps).", "",
             "| time.error_tolerance [m] | steps | mean step [ms] | Newton iterations (per step) | "
             "integration per simulated s [s] | [units] | against the reference |", "|---|---|---|---|---|---|---|"]
    for value in args.values:
        row = run(PAPER, sizes, args.t_end, value)
        mean_step = row["t_end"] / max(row["steps"], 1)
        lines.append(f"| {value:g} | {row['steps']} | {mean_step * 1e3:.3f} | {cost_cells(row, reference, unit, 2)} |")
        print(lines[-1], flush=True)
    args.table.write_text("\n".join(lines) + "\n")
    print("written:", args.table)


if __name__ == "__main__":
    main()
