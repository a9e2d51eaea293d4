"""Where the full order's Newton iterations go: the solves that fail, their line search, what the wall law switches
along their updates, and where the residual's largest entry sits (docs/performance.md, "Newton's iterations").

    python benchmarks/newton_crawl.py [--length 1000] [--t-end 0.6] [--out benchmarks/results/newton_crawl.md]

The paper's cross-section at --length m (2 elements per metre) is run for --t-end s (`fenics-drill run
demos/scenes/paper.toml`, its defaults) with Newton's pieces wrapped, not changed:

- every Newton solve: whether it converged, its iterations (the summary's ``newton_iterations`` counts those of the
  solves that converged only), and in the solves that failed each update's line search: the residual norm before
  it, after the full update and after the update taken;
- after each of the first PROBED failed solves past the first step (where the string settles on the wall), at its
  iterate PROBE_ITERATION: the wall vertices that change state
  between the iterate and points along its Newton update (shares 1e-4 to 1 of it): entering or leaving the wall,
  and switching between stuck and sliding (the friction force below or on the cone mu |F_n|).  The probe's
  factorisation is the only trace it leaves in the run (the failed solve's tangents are dropped by the step's cut);
- after the first update of every solve: the field and vertex of the residual's largest entry.
"""

from __future__ import annotations

import argparse
import collections
import platform
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from speed import processor  # noqa: E402

#: Failed solves probed along an update, and the iterate probed in each.
PROBED, PROBE_ITERATION = 3, 12
#: Shares of the Newton update at which the wall's states are compared with the iterate's.
SHARES = (1e-4, 1e-3, 1e-2, 0.5, 1.0)
FIELDS = ("U", "V", "W", "THETA_X", "THETA_Y", "THETA_Z")


def wall_states(evaluation) -> dict[int, bool]:
    """Each vertex in contact at an evaluation: whether its friction force is on the cone mu |F_n| (sliding)."""
    wall = evaluation.forces["wall"]
    touching = wall.delta > 0
    vertices = wall.vertices[touching]
    normal = np.abs(wall.normal)
    friction = np.hypot(wall.axial, wall.torque / wall.tangential_arm[vertices])
    ratio = np.divide(friction, normal, out=np.zeros_like(friction), where=normal > 0)
    cone = ratio.max(initial=0.0)
    return dict(zip(vertices.tolist(), (ratio >= cone * (1.0 - 1e-9)).tolist()))


def instrumented_run(length: float, t_end: float) -> dict:
    import fenics_drill.solvers.newmark as newmark
    import fenics_drill.solvers.newton as newton_module
    import fenics_drill.solvers.time_loop as time_loop
    from fenics_drill.cli import main
    from fenics_drill.model import discretization

    solves, probes, largest, model = [], [], collections.Counter(), {}
    start_simulation, newton, line_search = time_loop.Simulation.__init__, newmark.saddle_newton, newton_module.backtrack
    searches: list = []  # the line searches of the solve under way

    def simulation(self, built, *args, **kwargs):
        model["model"] = built
        return start_simulation(self, built, *args, **kwargs)

    def names() -> dict[int, tuple[str, int]]:
        if "names" not in model:
            built, table = model["model"], {}
            for field in FIELDS:
                rows = built.space.rows(built.disc.vertex_dofs(getattr(discretization, field))).tocsr()
                for vertex in range(rows.shape[0]):
                    for column in rows.indices[rows.indptr[vertex]:rows.indptr[vertex + 1]]:
                        table[int(column)] = (field, vertex)
            model["names"], model["bit"] = table, len(built.disc.vertex_x) - 1
        return model["names"]

    def search(trial, norm0, step=1.0, kink=None):
        trials = []

        def recorded(share):
            result = trial(share)
            trials.append(result[0])
            return result

        out = line_search(recorded, norm0, step, kink)
        searches.append((norm0, trials[0], out[1]))
        return out

    def wrapped(evaluate, space, constraints, target, q, mu, evaluation, check, max_iterations, **kwargs):
        norms, kept = [], {}
        searches.clear()

        def checked(iteration, q, mu, ev, norm, gap):
            norms.append(norm)
            if iteration == 2:
                at = int(np.argmax(np.abs(ev.residual)))
                field, vertex = names().get(at, ("interior", -1))
                largest[(field, "at the bit" if vertex == model["bit"] else "elsewhere")] += 1
            if iteration == PROBE_ITERATION:
                kept.update(q=q, mu=mu, ev=ev, gap=gap)
            return check(iteration, q, mu, ev, norm, gap)

        result = newton(evaluate, space, constraints, target, q, mu, evaluation, checked, max_iterations, **kwargs)
        solves.append({"converged": result is not None, "iterations": len(norms), "searches": list(searches)})
        started = any(solve["converged"] for solve in solves[:-1])  # not the first step's, where the string settles
        if result is None and kept and started and len(probes) < PROBED:
            base = wall_states(kept["ev"])
            dq, _ = space.saddle_solve(kept["ev"].tangent, constraints, -kept["ev"].residual, -kept["gap"])
            row = {}
            for share in SHARES:
                moved = wall_states(evaluate(kept["q"] + share * dq, kept["mu"]))
                row[share] = (len(set(moved) ^ set(base)),
                              sum(1 for v in set(moved) & set(base) if moved[v] != base[v]))
            probes.append({"vertices": len(base), "sliding": sum(base.values()), "shares": row})
        return result

    time_loop.Simulation.__init__, newmark.saddle_newton, newton_module.backtrack = simulation, wrapped, search
    try:
        with tempfile.TemporaryDirectory() as out:
            main(["run", "demos/scenes/paper.toml", "--set", f"beam.length={length:g}", "--set",
                  f"beam.elements={int(round(2 * length))}", "--set", f"time.t_end={t_end:g}", "--set",
                  "output.field_interval=0", "--quiet", "--overwrite", "--out", out])
    finally:
        time_loop.Simulation.__init__, newmark.saddle_newton = start_simulation, newton
        newton_module.backtrack = line_search
    return {"solves": solves, "probes": probes, "largest": largest}


def report(measured: dict, args) -> str:
    solves = measured["solves"]
    failed = [s for s in solves if not s["converged"]]
    converged = [s for s in solves if s["converged"]]
    total = sum(s["iterations"] for s in solves)
    in_failed = sum(s["iterations"] for s in failed)
    raised, shares = [], []
    for solve in failed:
        for norm0, full, taken in solve["searches"][2:]:  # past the first two updates, where the crawl sits
            raised.append(full / norm0)
            shares.append(taken / norm0)
    lines = [f"# Where the full order's Newton iterations go ({args.length:g} m, {args.t_end:g} s)", "",
             f"Command: `python benchmarks/newton_crawl.py --length {args.length:g} --t-end {args.t_end:g}`. "
             f"Machine: {platform.machine()}, {processor()}, Python {platform.python_version()}; one process.", "",
             f"Newton solves: {len(solves)}, {len(failed)} failed. Iterations: {total}, of which {in_failed} "
             f"({in_failed / max(total, 1):.0%}) in the failed solves; the converged ones took "
             f"{(total - in_failed) / max(len(converged), 1):.1f} each on average.", ""]
    if raised:
        lines += [f"In the failed solves, past their first two updates: the full update changed the residual norm "
                  f"by a factor {np.median(raised):.2f} (median; 10th-90th percentile {np.percentile(raised, 10):.2f}"
                  f"-{np.percentile(raised, 90):.2f}), the update taken by {np.median(shares):.3f} "
                  f"({np.percentile(shares, 10):.3f}-{np.percentile(shares, 90):.3f}).", ""]
    if measured["probes"]:
        lines += ["Wall vertices that change state between a failed solve's iterate "
                  f"{PROBE_ITERATION} and points along its Newton update (entering or leaving the wall / "
                  "switching between stuck and sliding):", "",
                  "| probe | vertices on the wall (sliding) | " + " | ".join(f"{s:g} of the update" for s in SHARES)
                  + " |", "|---|---|" + "---|" * len(SHARES)]
        for k, probe in enumerate(measured["probes"], 1):
            cells = " | ".join(f"{a} / {b}" for a, b in probe["shares"].values())
            lines.append(f"| {k} | {probe['vertices']} ({probe['sliding']}) | {cells} |")
        lines.append("")
    lines += ["Where the residual's largest entry sits after a solve's first update:", "",
              "| field | vertex | solves |", "|---|---|---|"]
    for (field, where), count in measured["largest"].most_common():
        lines.append(f"| {field} | {where} | {count} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=1000.0, help="the string's length [m]")
    parser.add_argument("--t-end", type=float, default=0.6, help="the run's length [s]")
    parser.add_argument("--out", type=Path, default=Path("benchmarks/results/newton_crawl.md"))
    args = parser.parse_args()
    text = report(instrumented_run(args.length, args.t_end), args)
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
