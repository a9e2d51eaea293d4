"""What runs cost before and after a revision, measured side by side in one session.

    python benchmarks/speed_table.py [--before 50d35ac] [--runs out/speed] [--table benchmarks/results/speed_against_revision.md]

The revision ``--before`` is checked out with ``git worktree`` into RUNS/before-tree and run with the same
interpreter as the working tree (its packages come first on sys.path), one run at a time on one core.
Rows: the nominal 10 s scene, 2 s with the printed kinematics (wall impacts in the reduced models), a
Monte Carlo batch (4 realisations of 2 s) and the full-order reference (1000 elements, dt/4, 0.2 s).
Each gives wall time, steps, Newton iterations, the three costliest functions (cProfile, own time) and
rop and efficiency against the full order (500 elements, nominal step, same horizon; run once and kept in
RUNS/reference-*).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = "demos/scenes/paper.toml"
NOMINAL_DT = 0.0024659004490511254  # 1 / (2 f_max), f_max = 4 c_L / L of the paper scene (Section 6.2)
ROWS = {
    "nominal scene, 10 s": ("run", ["time.t_end=10.0"], "nominal-10s"),
    "printed kinematics, 2 s": ("run", ["time.t_end=2.0", "model.kinematics='printed'"], "printed-2s"),
    "Monte Carlo batch, 4 realisations of 2 s": ("mc", ["time.t_end=2.0"], "nominal-2s"),
    "full-order reference (1000 elements, dt/4), 0.2 s": (
        "run", ["time.t_end=0.2", "reduction.rule='none'", "beam.elements=1000", f"time.dt={NOMINAL_DT / 4}"], None),
}
REFERENCES = {"nominal-10s": ["time.t_end=10.0"], "printed-2s": ["time.t_end=2.0", "model.kinematics='printed'"],
              "nominal-2s": ["time.t_end=2.0"]}

WORKER = r"""
import cProfile, json, pstats, sys, time
import dolfinx_solver  # noqa: F401
from fenics_drill.scene import load_scene
kind, scene_path, overrides, out = sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), sys.argv[4]
scene = load_scene(scene_path, overrides + ["output.field_interval=0"])
profile = cProfile.Profile()
clock = time.perf_counter()
profile.enable()
if kind == "run":
    from fenics_drill.studies.run import run_scene
    s = run_scene(scene, out, progress=False, overwrite=True)
    result = {k: s.get(k) for k in ("status", "steps", "newton_iterations", "rop", "efficiency", "impacts_total")}
else:
    from fenics_drill.api import monte_carlo
    monte_carlo(scene, 4, out, overwrite=True)
profile.disable()
wall_time = time.perf_counter() - clock
if kind != "run":  # steps of the nominal realisation and the 4 sampled ones; rop and efficiency of the nominal one
    import pathlib
    import h5py
    attributes = []
    for path in [pathlib.Path(out) / "nominal.h5", *sorted((pathlib.Path(out) / "realisations").glob("*.h5"))]:
        with h5py.File(path, "r") as f:
            attributes.append(dict(f.attrs))
    result = {"status": "finished", "steps": int(sum(a["steps"] for a in attributes)), "newton_iterations": None,
              "rop": float(attributes[0]["rop"]), "efficiency": float(attributes[0]["efficiency"]),
              "impacts_total": None}
result["wall_time_s"] = wall_time
stats = pstats.Stats(profile)
top = sorted(stats.stats.items(), key=lambda kv: kv[1][2], reverse=True)[:3]
result["profile"] = [f"{func[2]} ({func[0].split('/')[-1]}:{func[1]}) {row[2]:.1f} s" for func, row in top]
print(json.dumps(result))
"""


def measure(tree: Path, kind: str, overrides: list[str], out: Path) -> dict:
    """One row in one tree, in its own process on one core."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "PYTHONPATH": str(tree)}
    done = subprocess.run([sys.executable, "-c", WORKER, kind, str(tree / SCENE), json.dumps(overrides), str(out)],
                          cwd=tree, env=env, capture_output=True, text=True)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if not lines:
        return {"status": f"failed: {done.stderr.strip().splitlines()[-1] if done.stderr.strip() else '?'}"}
    return json.loads(lines[-1])


def reference(name: str, runs: Path) -> dict:
    """The full order (500 elements, nominal step) of a row, run once with the working tree."""
    out = runs / f"reference-{name}"
    summary = out / "summary.json"
    if not (summary.exists() and json.loads(summary.read_text()).get("status") in ("finished", "suspect")):
        subprocess.run([sys.executable, "-m", "fenics_drill.cli", "run", SCENE, *[a for o in REFERENCES[name]
                        for a in ("--set", o)], "--set", "reduction.rule='none'", "--set", "output.field_interval=0",
                        "--quiet", "--overwrite", "--out", str(out)], cwd=ROOT, check=False,
                       env={**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"})
    return json.loads(summary.read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default="50d35ac")
    parser.add_argument("--runs", type=Path, default=ROOT / "out/speed")
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks/results/speed_against_revision.md")
    args = parser.parse_args()
    runs = args.runs.resolve()
    runs.mkdir(parents=True, exist_ok=True)
    before_tree = runs / "before-tree"
    if not before_tree.exists():
        subprocess.run(["git", "worktree", "add", "--detach", str(before_tree), args.before], cwd=ROOT, check=True)
    if not (before_tree / "fenics_drill/forms").exists():  # the weak forms ship as fenics_drill.forms (pyproject)
        shutil.copytree(before_tree / "forms", before_tree / "fenics_drill/forms")
    trees = {f"before ({args.before})": before_tree, "after": ROOT}
    lines = [f"# Speed before and after ({platform.processor() or platform.machine()}, "
             f"{os.cpu_count()} cores, one per run)", "",
             f"Command: `python benchmarks/speed_table.py --before {args.before}`. Accuracy: relative difference "
             "of rop / efficiency from the full order (500 elements, nominal step, same horizon). The Monte Carlo "
             "row's steps are those of its nominal and 4 sampled realisations, its accuracy the nominal "
             "realisation's (a realisation does not count its Newton iterations). Each tree runs its own defaults: "
             "the nominal step of the code before is the paper's 1/(2 f_max), today's is 1/(8 f_max) (time.band_steps, "
             "docs/verification.md), and the full order is run at today's.", "",
             "| row | code | wall [s] | steps | Newton iterations | rop / efficiency vs full order | "
             "costliest functions (own time) |", "|---|---|---|---|---|---|---|"]
    for row, (kind, overrides, ref_name) in ROWS.items():
        ref = reference(ref_name, runs) if ref_name else None
        for code, tree in trees.items():
            r = measure(tree, kind, overrides, runs / f"{code.split()[0]}-{len(lines)}")
            accuracy = "—"
            if ref is not None and r.get("rop") is not None:
                accuracy = (f"{abs(r['rop'] / ref['rop'] - 1):.1%} / "
                            f"{abs(r['efficiency'] / ref['efficiency'] - 1):.1%}")
            wall = r.get("wall_time_s")
            lines.append(f"| {row} | {code} | {'' if wall is None else f'{wall:.1f}'} | {r.get('steps') or '—'} | "
                         f"{r.get('newton_iterations') or '—'} | {accuracy} | "
                         f"{'; '.join(r.get('profile', [r.get('status', '')]))} |")
            print(lines[-1], flush=True)
    args.table.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
