"""The default reduced model against its full order on random scenes: geometries, drives and bit laws that no
test or table was tuned on (what a held-back check would do).

    python benchmarks/random_scenes.py [--scenes 8] [--seed 2026] [--t-end 1] [--runs out/random_scenes]
                                       [--table benchmarks/results/random_scenes/random_scenes.md] [--jobs 2] [--lengths 30 250]
                                       [--set SECTION.KEY=VALUE ...]

Draws each scene from the paper scene by changing its length, mesh, pipe radii, gap, drive speeds and bit-rock
law within the ranges of :data:`RANGES`, with the paper's wall friction (18)-(19) (under the Coulomb force at the
contact point a spinning string on the wall climbs it, and the 'auto' rule takes the full order: there is no reduced
model to compare), runs it with the default reduced model and with the full order
(``reduction.rule = 'none'``) at the same settings, ``--jobs`` runs at a time, and tabulates rop, efficiency,
peak von Mises stress and impacts with the reduced model's relative difference.  Runs that finished are reused.
"""

from __future__ import annotations

import argparse
import math
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from scene_runs import run_once, write_table

#: (low, high) of each drawn quantity; lengths and radii in m, speeds in m/h and rpm, forces in N.
RANGES = {
    "length": (30.0, 250.0),
    "outer_radius": (0.05, 0.09),
    "inner_share": (0.6, 0.85),  # R_int / R_ext
    "gap": (0.005, 0.04),  # R_bh - R_ext
    "rop_mh": (10.0, 40.0),
    "rpm": (40.0, 120.0),
    "limit_force": (15e3, 45e3),
    "rate": (200.0, 600.0),
    "friction": (0.25, 0.5),
}
#: Elements per metre of string (the paper: 500 on 100 m), within ELEMENT_BOUNDS.
ELEMENTS_PER_M, ELEMENT_BOUNDS = 2.5, (60, 600)


def draw(rng: np.random.Generator, ranges: dict = RANGES) -> dict:
    """One scene's drawn quantities."""
    d = {key: float(rng.uniform(*bounds)) for key, bounds in ranges.items()}
    d["elements"] = int(np.clip(round(ELEMENTS_PER_M * d["length"]), *ELEMENT_BOUNDS))
    return d


def overrides(d: dict) -> list[str]:
    """The ``--set`` overrides of the paper scene that make scene ``d``."""
    return [f"beam.length={d['length']:.6g}", f"beam.elements={d['elements']}",
            f"beam.outer_radius={d['outer_radius']:.6g}", f"beam.inner_radius={d['outer_radius'] * d['inner_share']:.6g}",
            f"borehole.radius={d['outer_radius'] + d['gap']:.6g}",
            f"drive.axial_velocity={d['rop_mh'] / 3600:.9g}", f"drive.rotation_speed={d['rpm'] * math.pi / 30:.9g}",
            f"bit_rock.limit_force={d['limit_force']:.6g}", f"bit_rock.rate={d['rate']:.6g}",
            f"bit_rock.friction={d['friction']:.4g}", "output.field_interval=0", "contact.friction_model='paper'",
            "contact.sliding_velocity_scale=1e-3"]


def relative(reduced: float, full: float) -> str:
    return f"{reduced / full - 1:+.2%}" if full else "—"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=8)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--runs", type=Path, default=Path("out/random_scenes"))
    parser.add_argument("--table", type=Path, default=Path("benchmarks/results/random_scenes/random_scenes.md"))
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--lengths", type=float, nargs=2, default=RANGES["length"], metavar=("LOW", "HIGH"),
                        help="the range of the string's length [m]")
    parser.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                        help="an override of every scene (both models), after the drawn ones")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    ranges = {**RANGES, "length": tuple(args.lengths)}
    scenes = [draw(rng, ranges) for _ in range(args.scenes)]
    jobs = [(args.runs / f"{i}-{model}", [*overrides(d), *args.set, *extra])
            for i, d in enumerate(scenes) for model, extra in (("full", ["reduction.rule='none'"]), ("reduced", []))]
    with ThreadPoolExecutor(args.jobs) as pool:
        summaries = list(pool.map(lambda job: run_once(job[0], args.t_end, job[1]), jobs))
    lines = [f"# The default reduced model against its full order on {args.scenes} random scenes, "
             f"t_end = {args.t_end:g} s", "",
             f"Command: `python benchmarks/random_scenes.py --scenes {args.scenes} --seed {args.seed} "
             f"--t-end {args.t_end:g} --lengths {args.lengths[0]:g} {args.lengths[1]:g}"
             f"{''.join(f' --set {o}' for o in args.set)}`. Each scene is the paper scene with the quantities below drawn uniformly "
             "(ranges in `RANGES`); reduced: its defaults; full: `reduction.rule='none'`. Differences are the "
             "reduced model's, relative to the full order.", "",
             "| # | L [m] | elements | R_ext / R_int / gap [mm] | V0 [m/h] | rpm | Gamma [kN] / alpha / mu | "
             "unknowns | status | rop full [m/h] | rop | efficiency full | efficiency | peak VM full [MPa] | peak VM "
             "| impacts full / reduced | balance error full / reduced | wall full / reduced [s] |",
             "|" + "---|" * 18]
    for i, d in enumerate(scenes):
        full, red = summaries[2 * i], summaries[2 * i + 1]
        status = f"{full['status']} / {red['status']}"
        if full.get("efficiency") is None or red.get("efficiency") is None:
            rows = "| — | — | — | — | — | — |"
        else:
            vm_full, vm_red = full["max_von_mises"]["value"], red["max_von_mises"]["value"]
            rows = (f"| {full['rop'] * 3600:.3f} | {relative(red['rop'], full['rop'])} | {full['efficiency']:.4f} | "
                    f"{relative(red['efficiency'], full['efficiency'])} | {vm_full / 1e6:.1f} | "
                    f"{relative(vm_red, vm_full)} |")
        lines.append(
            f"| {i} | {d['length']:.0f} | {d['elements']} | {d['outer_radius'] * 1e3:.1f} / "
            f"{d['outer_radius'] * d['inner_share'] * 1e3:.1f} / {d['gap'] * 1e3:.1f} | {d['rop_mh']:.1f} | "
            f"{d['rpm']:.0f} | {d['limit_force'] / 1e3:.1f} / {d['rate']:.0f} / {d['friction']:.2f} | "
            f"{red.get('reduced_size', '—')} | {status} {rows} {full.get('impacts_total', '—')} / "
            f"{red.get('impacts_total', '—')} | {full.get('energy', {}).get('balance_error', math.nan):.1e} / "
            f"{red.get('energy', {}).get('balance_error', math.nan):.1e} | {full.get('wall_time_s', math.nan):.0f} / "
            f"{red.get('wall_time_s', math.nan):.0f} |")
    write_table(args.table, lines)


if __name__ == "__main__":
    main()
