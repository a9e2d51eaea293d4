"""Monte Carlo throughput on 1 and 2 MPI ranks: realisations per hour and parallel efficiency.

    .venv/bin/python benchmarks/mc_scaling.py [--samples 8] [--t-end 1.0]

Runs the same study of the paper scene (fresh output directories) with ``mpiexec -n 1`` and
``-n 2`` and times each end to end (setup included: every rank builds its own model).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=8)
    parser.add_argument("--t-end", type=float, default=1.0)
    args = parser.parse_args()
    mpiexec = Path(sys.executable).parent / "mpiexec"
    rates = {}
    for ranks in (1, 2):
        with tempfile.TemporaryDirectory() as out:
            clock = time.perf_counter()
            subprocess.run([str(mpiexec), "-n", str(ranks), sys.executable, "-m", "fenics_drill.cli", "mc",
                            "demos/scenes/paper.toml", "--set", f"time.t_end={args.t_end}", "--quiet",
                            "--samples", str(args.samples), "--out", out], check=True, capture_output=True)
            wall = time.perf_counter() - clock
        rates[ranks] = args.samples / wall * 3600
        print(f"{ranks} rank(s): {args.samples} realisations of {args.t_end:g} s in {wall:.1f} s "
              f"-> {rates[ranks]:.0f} per hour", flush=True)
    print(f"parallel efficiency on 2 ranks: {rates[2] / (2 * rates[1]):.0%}")


if __name__ == "__main__":
    main()
