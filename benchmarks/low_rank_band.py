"""What a low-rank (Woodbury) update of a kept banded LU would save on the 3 km band, against the set changes of the
wall that the full order's Newton makes (docs/performance.md, "A kept factorisation and the wall's set").

    python benchmarks/low_rank_band.py [--length 1000] [--t-end 0.3] [--out benchmarks/results/low_rank_band.md]

Part 1, the algebra, on the band of benchmarks/speed.py's machine unit (54 000 unknowns, kl = ku = 14: the full
order's at 3 km): a fresh factorisation and solve (dgbtrf + dgbtrs, the unit), a solve with the LU kept (dgbtrs),
and a change of the matrix at m vertices (four dofs each, a dense 4 x 4 block per vertex: rank r = 4 m) solved by
Woodbury's identity with the LU of the old matrix kept,

    (A + U C U^T)^-1 b = x - Z (I + C U^T Z)^-1 C U^T x,   x = A^-1 b,   Z = A^-1 U (one dgbtrs with r columns),

each against the fresh factorisation of the changed matrix (relative difference of the solutions).  A set that
changes by m vertices at an iterate whose earlier changes are kept costs the r new columns of Z.

Part 2, the set changes, counted: the paper's cross-section at --length m (2 elements per metre) run for --t-end s
(`fenics-drill run demos/scenes/paper.toml`), each wall vertex's state (off the wall, stuck, sliding: its friction
force below or on the cone mu |F_n|) at every evaluation of a Newton solve, compared with the evaluation before it
in the same step.
"""

from __future__ import annotations

import argparse
import collections
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.linalg as la
import scipy.linalg.lapack as lapack

sys.path.insert(0, str(Path(__file__).parent))
from speed import UNIT_BANDWIDTH, UNIT_SIZE, machine_unit, processor  # noqa: E402

VERTEX_DOFS = 4  # (u, v, w, theta_x) of a wall vertex
VERTEX_COUNTS = (1, 4, 16, 64, 256)
REPEATS = 5


def _band(rng) -> np.ndarray:
    """LAPACK's band storage (with the LU's kl extra rows) of a diagonally dominant random band: the machine
    unit's."""
    kl = ku = UNIT_BANDWIDTH
    band = np.zeros((2 * kl + ku + 1, UNIT_SIZE), order="F")
    band[kl:] = rng.standard_normal((kl + ku + 1, UNIT_SIZE))
    band[kl + ku] += 4.0 * (kl + ku + 1)
    return band


def _changed(band: np.ndarray, dofs: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    """The band with each vertex's 4 x 4 block added at its dofs (consecutive, within the bandwidth)."""
    kl = ku = UNIT_BANDWIDTH
    out = band.copy(order="F")
    for first, block in zip(dofs[::VERTEX_DOFS], blocks):
        for i in range(VERTEX_DOFS):
            for j in range(VERTEX_DOFS):
                out[kl + ku + i - j, first + j] += block[i, j]
    return out


def _median_time(action, repeats: int = REPEATS, prepare=lambda: ()) -> tuple[float, object]:
    """Median wall time [s] of ``action(*prepare())`` (``prepare`` untimed), and its last result."""
    times, result = [], None
    for _ in range(repeats):
        arguments = prepare()
        clock = time.perf_counter()
        result = action(*arguments)
        times.append(time.perf_counter() - clock)
    return float(np.median(times)), result


def algebra() -> list[dict]:
    """Part 1: the costs [s] and the Woodbury solutions' differences from a fresh factorisation."""
    rng = np.random.default_rng(1)
    kl = ku = UNIT_BANDWIDTH
    band = _band(rng)
    rhs = rng.standard_normal(UNIT_SIZE)
    lu, pivots, info = lapack.dgbtrf(band.copy(order="F"), kl, ku)
    assert info == 0
    kept, _ = _median_time(lambda: lapack.dgbtrs(lu, kl, ku, rhs, pivots))
    rows = []
    for count in VERTEX_COUNTS:
        firsts = np.sort(rng.choice(UNIT_SIZE // VERTEX_DOFS - 1, count, replace=False)) * VERTEX_DOFS
        dofs = (firsts[:, None] + np.arange(VERTEX_DOFS)).ravel()
        blocks = rng.standard_normal((count, VERTEX_DOFS, VERTEX_DOFS)) * 10.0  # of the diagonal's size
        changed = _changed(band, dofs, blocks)
        rank = dofs.size
        selection = np.zeros((UNIT_SIZE, rank), order="F")
        selection[dofs, np.arange(rank)] = 1.0
        coupling = la.block_diag(*blocks)

        def fresh(work):  # as the machine unit: the band laid out already, factorised in place
            factors, pivots_new, _ = lapack.dgbtrf(work, kl, ku, overwrite_ab=1)
            return lapack.dgbtrs(factors, kl, ku, rhs, pivots_new)[0]

        def columns():
            return lapack.dgbtrs(lu, kl, ku, selection, pivots)[0]

        def woodbury(z):
            x = lapack.dgbtrs(lu, kl, ku, rhs, pivots)[0]
            small = np.eye(rank) + coupling @ z[dofs]
            return x - z @ la.solve(small, coupling @ x[dofs])

        fresh_time, reference = _median_time(fresh, prepare=lambda: (changed.copy(order="F"),))
        columns_time, z = _median_time(columns)
        update_time, solution = _median_time(lambda: woodbury(z))
        rows.append({"vertices": count, "rank": rank, "fresh": fresh_time, "kept": kept, "columns": columns_time,
                     "update": update_time,
                     "difference": float(np.linalg.norm(solution - reference) / np.linalg.norm(reference))})
    return rows


def set_changes(length: float, t_end: float) -> dict:
    """Part 2: each wall vertex's state at each evaluation of the run, compared within each step."""
    import fenics_drill.model.forces.wall_contact as wall_contact
    import fenics_drill.solvers.newmark as newmark
    from fenics_drill.cli import main

    states, step = [], [0]
    evaluate, take_step = wall_contact.WallContact.evaluate, newmark.NewmarkNewton.step

    def recorded(self, q, qd, with_tangent=False):
        out = evaluate(self, q, qd, with_tangent)
        state = np.zeros(len(self.x), dtype=np.int8)  # 0 off the wall, 1 stuck, 2 sliding
        touching = out.delta > 0
        if touching.any():
            vertices, loads = out.vertices[touching], out.nodal[touching]
            lateral = (self.every.lateral_rows @ q).reshape(-1, 2)[vertices]
            normal = lateral / np.hypot(*lateral.T)[:, None]
            pressed = np.abs(loads[:, 1] * normal[:, 0] + loads[:, 2] * normal[:, 1])
            friction = np.hypot(loads[:, 0], loads[:, 3] / self.arm[vertices])
            state[vertices] = np.where(friction >= abs(self.mu_axial) * pressed * (1.0 - 1e-9), 2, 1)
        states.append((step[0], state))
        return out

    def counted(self, *args, **kwargs):
        step[0] += 1
        return take_step(self, *args, **kwargs)

    wall_contact.WallContact.evaluate, newmark.NewmarkNewton.step = recorded, counted
    with tempfile.TemporaryDirectory() as out:
        try:
            main(["run", "demos/scenes/paper.toml", "--set", f"beam.length={length:g}", "--set",
                  f"beam.elements={int(round(2 * length))}", "--set", f"time.t_end={t_end:g}", "--set",
                  "output.field_interval=0", "--quiet", "--overwrite", "--out", out])
        except SystemExit:
            pass
    by_step = collections.defaultdict(list)
    for number, state in states:
        if number > 0:
            by_step[number].append(state)
    changes, kinds, repeated = [], collections.Counter(), 0
    for sequence in by_step.values():
        seq = np.array(sequence)
        moved = seq[1:] != seq[:-1]
        changes += moved.sum(axis=1).tolist()
        for before, after in zip(seq[:-1][moved], seq[1:][moved]):
            kinds[(int(before), int(after))] += 1
        repeated += int(np.count_nonzero(moved.sum(axis=0) >= 2))
    changes = np.array(changes)
    last = states[-1][1]
    return {"evaluations": len(states), "steps": len(by_step), "mean": changes.mean(), "median": np.median(changes),
            "p90": np.percentile(changes, 90), "max": changes.max(), "none": np.mean(changes == 0), "kinds": kinds,
            "repeated": repeated, "vertices": last.size, "stuck": int(np.count_nonzero(last == 1)),
            "sliding": int(np.count_nonzero(last == 2))}


def report(rows: list[dict], counts: dict, unit: float, args) -> str:
    names = {0: "off", 1: "stuck", 2: "sliding"}
    lines = ["# A kept factorisation and the wall's set: what a low-rank update would save", "",
             f"Command: `python benchmarks/low_rank_band.py --length {args.length:g} --t-end {args.t_end:g}`. "
             f"Machine: {platform.machine()}, {processor()}, Python {platform.python_version()}; one process.", "",
             f"Machine unit (one dgbtrf + dgbtrs of {UNIT_SIZE} unknowns, kl = ku = {UNIT_BANDWIDTH}): "
             f"{unit * 1e3:.1f} ms.", "",
             "## The algebra on the 3 km band", "",
             "| vertices changed | rank | fresh LU and solve [units] | solve, LU kept [units] | Z = A^-1 U [units] "
             "| Woodbury solve, Z kept [units] | fresh over Woodbury (Z and its solve) "
             "| relative difference from fresh |",
             "|---|---|---|---|---|---|---|---|"]
    for row in rows:
        woodbury = row["columns"] + row["update"]
        lines.append(f"| {row['vertices']} | {row['rank']} | {row['fresh'] / unit:.2f} | {row['kept'] / unit:.3f} | "
                     f"{row['columns'] / unit:.2f} | {row['update'] / unit:.3f} | {row['fresh'] / woodbury:.2f} | "
                     f"{row['difference']:.1e} |")
    kinds = ", ".join(f"{names[a]} -> {names[b]} {n}" for (a, b), n in sorted(counts["kinds"].items()))
    lines += ["", f"## The wall's set in the full order's Newton ({args.length:g} m, {args.t_end:g} s)", "",
              f"{counts['steps']} steps, {counts['evaluations']} evaluations; at the end {counts['stuck']} of the "
              f"{counts['vertices']} vertices stuck on the wall and {counts['sliding']} sliding.", "",
              "| vertices whose state changed from one evaluation to the next in a step | |", "|---|---|",
              f"| mean | {counts['mean']:.1f} |", f"| median | {counts['median']:.0f} |",
              f"| 90th percentile | {counts['p90']:.0f} |", f"| largest | {counts['max']:.0f} |",
              f"| share of evaluations with none | {counts['none']:.2f} |", "",
              f"Changes by kind: {kinds}. Vertex-steps in which a vertex changed state twice or more: "
              f"{counts['repeated']} ({counts['repeated'] / counts['steps']:.0f} per step)."]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=1000.0, help="the string's length for part 2 [m]")
    parser.add_argument("--t-end", type=float, default=0.3, help="the run's length for part 2 [s]")
    parser.add_argument("--out", type=Path, default=Path("benchmarks/results/low_rank_band.md"))
    args = parser.parse_args()
    unit = machine_unit()
    rows = algebra()
    counts = set_changes(args.length, args.t_end)
    text = report(rows, counts, 0.5 * (unit + machine_unit()), args)
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
