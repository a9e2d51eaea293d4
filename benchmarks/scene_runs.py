"""What the paper-scene studies of benchmarks/ share: their command line, and runs that are made once and
reused (a run directory whose summary says it finished is not run again)."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

SCENE = "demos/scenes/paper.toml"


def study_arguments(doc: str, t_end: float, runs: str, table: str) -> argparse.Namespace:
    """--t-end, --runs (where the runs go) and --table (the Markdown file written)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=t_end)
    parser.add_argument("--runs", type=Path, default=Path(runs))
    parser.add_argument("--table", type=Path, default=Path(table))
    return parser.parse_args()


def run_once(out: Path, t_end: float, overrides: list[str]) -> dict:
    """``fenics-drill run SCENE --set time.t_end=T --set OVERRIDE...`` into ``out`` unless it already
    finished there; returns its summary ({"status": "refused", "message": ...} for a scene the tool refuses)."""
    summary = out / "summary.json"
    if not (summary.exists() and json.loads(summary.read_text()).get("status") in ("finished", "suspect")):
        sets = [a for o in overrides for a in ("--set", o)]
        result = subprocess.run([sys.executable, "-m", "fenics_drill.cli", "run", SCENE, "--set", f"time.t_end={t_end}",
                                 *sets, "--quiet", "--overwrite", "--out", str(out)], check=False,
                                stderr=subprocess.PIPE, text=True)
        sys.stderr.write(result.stderr)
        if not summary.exists():
            return {"status": "refused", "message": result.stderr.strip()}
    return json.loads(summary.read_text())


def write_table(path: Path, lines: list[str]) -> None:
    path.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
