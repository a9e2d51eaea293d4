"""The residual norm of every Newton iterate of the last steps of a run, and the evaluations per step.

    python benchmarks/newton_history.py T_END [STEPS] [SECTION.KEY=VALUE ...]

Runs the paper scene to T_END (no field output) and prints, for each of the last STEPS steps (default 15),
the evaluations it made (line-search trials included) and the residual norm Newton checked at each
iterate; then the run's steps and iterations.  Linear convergence, halving line searches and branch
jumps of a force law show here (benchmarks/RESULTS.md, issue 17).
"""

from __future__ import annotations

import sys
import tempfile

import fenics_drill  # noqa: F401  (dolfinx_solver and h5py first)
import fenics_drill.solvers.newmark as newmark
from fenics_drill.scene import load_scene
from fenics_drill.studies.run import run_scene

HISTORY: list[tuple[int, list[float]]] = []


def recording(saddle_newton):
    """``saddle_newton`` that appends (evaluations, norms) of each call to HISTORY."""

    def wrapper(evaluate, space, constraints, target, q, mu, evaluation, check, max_iterations, **options):
        norms, evaluations = [], [0]

        def counted(q, mu, *args, **kwargs):
            evaluations[0] += 1
            return evaluate(q, mu, *args, **kwargs)

        def watched(iteration, q, mu, ev, norm, gap):
            norms.append(norm)
            return check(iteration, q, mu, ev, norm, gap)

        try:
            return saddle_newton(counted, space, constraints, target, q, mu, evaluation, watched, max_iterations,
                                 **options)
        finally:
            HISTORY.append((evaluations[0] + 1, norms))  # + the predictor's evaluation

    return wrapper


def main() -> None:
    t_end, rest = sys.argv[1], sys.argv[2:]
    shown = int(rest.pop(0)) if rest and "=" not in rest[0] else 15
    newmark.saddle_newton = recording(newmark.saddle_newton)
    scene = load_scene("demos/scenes/paper.toml", [f"time.t_end={t_end}", "output.field_interval=0", *rest])
    with tempfile.TemporaryDirectory() as out:
        summary = run_scene(scene, out, progress=False, overwrite=True)
    for evaluations, norms in HISTORY[-shown:]:
        print(f"{evaluations:3d} evaluations: " + " ".join(f"{n:.1e}" for n in norms))
    print(f"{summary['steps']} steps, {summary['newton_iterations']} Newton iterations")


if __name__ == "__main__":
    main()
