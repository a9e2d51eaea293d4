"""Speed against accuracy of the Coulomb wall's stick stiffness k_t (``contact.stick_stiffness``).

    python benchmarks/stick_stiffness.py [--length 1000] [--t-end 3] [--values 1e8 1e7 1e6]
                                         [--table benchmarks/results/stick_stiffness.md]

The paper's cross-section at ``--length`` (2 elements per metre; 100 m: the paper's scene as it is), one run per
value of k_t, each against the run at the default k_t = 1e8 N/m and a tenth of time.error_tolerance (the step
converged).  A stuck contact gives mu |F_n| / k_t before it slips: the larger the give, the fewer stick-slip switches
Newton meets, and the more the contact creeps while stuck.  Costs in seconds and in the machine unit of
:mod:`speed` (one banded LU of the 3 km band), measured in the same invocation.
"""

from __future__ import annotations

import argparse
import os
import platform
from pathlib import Path

from speed import DEFAULT_TOLERANCE, PAPER, ROOT, cost_cells, machine_unit, processor, run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=1000.0)
    parser.add_argument("--t-end", type=float, default=3.0)
    parser.add_argument("--values", type=float, nargs="+", default=[1e8, 1e7, 1e6])
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "stick_stiffness.md")
    args = parser.parse_args()
    sizes = () if args.length == 100 else (f"beam.length={args.length:g}", f"beam.elements={int(2 * args.length)}")
    unit = machine_unit()
    reference = run(PAPER, (*sizes, "contact.stick_stiffness=1e8"), args.t_end, DEFAULT_TOLERANCE / 10)
    lines = ["# The stick stiffness of the Coulomb wall: speed against accuracy", "",
             f"Command: `python benchmarks/stick_stiffness.py --length {args.length:g} --t-end {args.t_end:g} --values "
             f"{' '.join(f'{v:g}' for v in args.values)}`. Machine: {platform.machine()}, {os.cpu_count()} cores "
             f"({processor()}), Python {platform.python_version()}; one run at a time. The paper's cross-section, "
             f"{args.length:g} m, {args.t_end:g} s; machine unit (one LAPACK banded LU and solve of 54 000 unknowns, "
             f"kl = ku = 14): {unit * 1e3:.1f} ms.", "",
             "Reference: k_t = 1e8 N/m (the default) at a tenth of time.error_tolerance.", "",
             "| k_t [N/m] | steps | Newton iterations (per step) | integration per simulated s [s] | [units] | "
             "against the reference |", "|---|---|---|---|---|---|"]
    for value in args.values:
        row = run(PAPER, (*sizes, f"contact.stick_stiffness={value:g}"), args.t_end)
        lines.append(f"| {value:g} | {row['steps']} | {cost_cells(row, reference, unit)} |")
        print(lines[-1], flush=True)
    args.table.write_text("\n".join(lines) + "\n")
    print("written:", args.table)


if __name__ == "__main__":
    main()
