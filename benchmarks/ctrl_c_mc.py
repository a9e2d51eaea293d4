"""One Ctrl-C on an MPI Monte Carlo, at random moments: how long the job takes to end, its exit code, and the
status its summary ends with.

    python benchmarks/ctrl_c_mc.py [--trials 12] [--ranks 2] [--seed 1] [--table benchmarks/results/ctrl_c_mc.md]

Each trial starts ``mpiexec -n RANKS fenics-drill mc`` on a 20 m string (8 realisations of 0.3 s) and sends
SIGINT to mpiexec, as a terminal's Ctrl-C does, after a random delay between the start and the study's usual end.
"""

from __future__ import annotations

import argparse
import json
import platform
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).parents[1]
TOOL = [sys.executable, "-m", "fenics_drill.cli"]
MPIEXEC = str(Path(sys.executable).parent / "mpiexec")
STUDY = ["mc", str(ROOT / "demos" / "scenes" / "paper.toml"), "--set", "beam.length=20", "--set", "beam.elements=40",
         "--set", "output.field_interval=0", "--set", "time.t_end=0.3", "--samples", "8", "--quiet"]


def trial(delay: float, ranks: int, out: Path) -> dict:
    process = subprocess.Popen([MPIEXEC, "-n", str(ranks), *TOOL, *STUDY, "--out", str(out)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, cwd=ROOT, start_new_session=True)
    time.sleep(delay)
    sent = time.monotonic()
    process.send_signal(signal.SIGINT)
    try:
        _, err = process.communicate(timeout=120)
        ended = time.monotonic() - sent
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
        ended = float("inf")
    done = len(list((out / "realisations").glob("*.h5"))) if (out / "realisations").is_dir() else 0
    try:
        status = json.loads((out / "summary.json").read_text())["status"]
    except (OSError, ValueError, KeyError):
        status = "no summary"
    return {"delay": delay, "ended_s": ended, "code": process.returncode, "status": status, "done": done,
            "traceback": "Traceback" in err}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=12)
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "ctrl_c_mc.md")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        started = time.monotonic()
        subprocess.run([MPIEXEC, "-n", str(args.ranks), *TOOL, *STUDY, "--out", f"{tmp}/whole"], check=True,
                       capture_output=True, cwd=ROOT)
        whole = time.monotonic() - started
        delays = np.random.default_rng(args.seed).uniform(0.5, whole, args.trials)
        rows = [trial(float(d), args.ranks, Path(tmp) / f"t{k}") for k, d in enumerate(delays)]
    lines = [f"# One Ctrl-C on `mpiexec -n {args.ranks} fenics-drill mc`", "",
             f"Command: `python benchmarks/ctrl_c_mc.py --trials {args.trials} --ranks {args.ranks} --seed {args.seed}`. "
             f"Machine: {platform.machine()}, {platform.python_version()}, {time.strftime('%Y-%m-%d')}. The whole study "
             f"takes {whole:.1f} s; each trial sends SIGINT to mpiexec after a random delay.", "",
             "| delay [s] | ended after [s] | exit code | summary status | realisations written | traceback |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['delay']:.2f} | {r['ended_s']:.2f} | {r['code']} | {r['status']} | {r['done']} | "
                     f"{'yes' if r['traceback'] else 'no'} |")
    worst = max(r["ended_s"] for r in rows)
    lines += ["", f"Longest time to end: {worst:.2f} s; statuses: "
              + ", ".join(f"{s} {sum(r['status'] == s for r in rows)}" for s in sorted({r['status'] for r in rows}))]
    args.table.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
