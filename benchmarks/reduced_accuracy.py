"""How far the reduced models are from the full order on the paper's scenes.

    python benchmarks/reduced_accuracy.py [--t-end 2] [--runs out/accuracy] [--table benchmarks/results/reduced_accuracy.md]

For the nominal scene with the objective kinematics and with the printed kinematics (wall impacts), it
runs (or reuses, when ``RUNS/<name>/summary.json`` says the run finished) the full order
(``reduction.rule = 'none'``), the default reduced model (the 'auto' rule: the paper's bands with the
torsional modes of a stuck bit, and the guard's enrichment), the paper rule with the guard, and the
paper's pure modal basis, and tabulates rop, efficiency, mean bit velocity, peak von Mises stress, RMS
of the bit velocity and wall time, with the relative difference from the full order.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
from scene_runs import SCENE, run_once, study_arguments, write_table

MODELS = {
    "full": ["reduction.rule='none'"],
    "reduced (default: auto rule + guard)": [],
    "paper rule + guard": ["reduction.rule='paper'"],
    "paper modal basis (enrich off)": ["reduction.rule='paper'", "reduction.enrich=false", "reduction.guard_tolerance=1"],
}
KINEMATICS = ("objective", "printed")
TARGETS = {"rop": 0.01, "efficiency": 0.01, "mean_bit_velocity": 0.01, "max_von_mises": 0.05, "bit_velocity_rms": 0.10}


def run(name: str, overrides: list[str], t_end: float, runs: Path) -> dict:
    out = runs / name
    s = run_once(out, t_end, overrides)
    with h5py.File(out / "timeseries.h5") as f:
        t, v = f["time"][()], f["bit_velocity"][()]
    mean = np.trapezoid(v, t) / (t[-1] - t[0])
    rms = np.sqrt(np.trapezoid((v - mean) ** 2, t) / (t[-1] - t[0]))
    return {"rop": s["rop"], "efficiency": s["efficiency"], "mean_bit_velocity": s["mean_bit_velocity"],
            "max_von_mises": s["max_von_mises"]["value"], "bit_velocity_rms": rms, "wall_time_s": s["wall_time_s"],
            "integration_time_s": s["integration_time_s"], "unknowns": s["reduced_size"], "steps": s["steps"],
            "impacts": s["impacts_total"], "status": s["status"]}


def main() -> None:
    args = study_arguments(__doc__, 2.0, "out/accuracy", "benchmarks/results/reduced_accuracy.md")
    lines = [f"# Reduced models against the full order: `{SCENE}`, t_end = {args.t_end} s", "",
             f"Command: `python benchmarks/reduced_accuracy.py --t-end {args.t_end}`. Relative differences from "
             "the full order (500 elements, the same adaptive steps).", ""]
    header = ("| kinematics | model | unknowns | steps | impacts | rop [m/h] | efficiency | mean bit velocity [m/h] "
              "| peak von Mises [MPa] | RMS bit velocity [m/h] | wall [s] | speed-up | time loop [s] | its speed-up |")
    lines += [header, "|" + "---|" * (header.count("|") - 1)]
    for kinematics in KINEMATICS:
        results = {model: run(f"{kinematics}-{i}", [*extra, f"model.kinematics={kinematics}"], args.t_end,
                              args.runs) for i, (model, extra) in enumerate(MODELS.items())}
        full = results["full"]
        for model, r in results.items():
            def cell(key, scale, fmt):
                text = format(r[key] * scale, fmt)
                if model != "full":
                    error = abs(r[key] / full[key] - 1)
                    mark = "" if error <= TARGETS[key] else " ✗"
                    text += f" ({error:.1%}{mark})"
                return text
            lines.append(f"| {kinematics} | {model} | {r['unknowns']} | {r['steps']} | {r['impacts']} | "
                         f"{cell('rop', 3600, '.3f')} | {cell('efficiency', 100, '.2f')} % | "
                         f"{cell('mean_bit_velocity', 3600, '.3f')} | {cell('max_von_mises', 1e-6, '.1f')} | "
                         f"{cell('bit_velocity_rms', 3600, '.2f')} | {r['wall_time_s']:.1f} | "
                         f"{full['wall_time_s'] / r['wall_time_s']:.1f}× | {r['integration_time_s']:.1f} | "
                         f"{full['integration_time_s'] / r['integration_time_s']:.1f}× |")
    lines += ["", "Targets: rop, efficiency, mean bit velocity within 1 %; peak von Mises within 5 %; RMS of the bit "
              "velocity within 10 %; at least 20× faster than the full order. ✗ marks a miss. Wall time includes the "
              "setup (modal analysis, guard, static state); the time loop is the integration alone."]
    write_table(args.table, lines)


if __name__ == "__main__":
    main()
