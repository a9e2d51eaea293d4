"""Speed against accuracy of the drilling dynamics: basis size, time step, reduced vs full order.

    .venv/bin/python benchmarks/dynamics_convergence.py [--t-end 1.0] [--out benchmarks/dynamics_convergence.md]

Runs the paper's scene for --t-end seconds with each variant and tabulates the bit
velocity statistics (mean, standard deviation, rop), the energy balance error, the
steps and the wall time, with the errors against the finest variant of each study.
"""

from __future__ import annotations

import argparse
import platform
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from fenics_drill.studies.run import run_scene
from fenics_drill.scene import load_scene

STUDIES = {
    "basis": [
        ("paper rule (Section 6.3)", []),
        ("flexural f* <= 0.5", ["reduction.rule='band'", "reduction.flexural=0.5", "reduction.torsional=4.0",
                                "reduction.axial=4.0"]),
        ("flexural f* <= 2", ["reduction.rule='band'", "reduction.flexural=2.0", "reduction.torsional=4.0",
                              "reduction.axial=4.0"]),
        ("full order (rule none)", ["reduction.rule='none'"]),
    ],
    "time step": [
        ("dt nominal, adaptive", []),
        ("dt nominal / 2, adaptive", ["time.dt=0.0012329502245255627"]),
        ("dt nominal / 4, adaptive", ["time.dt=0.0006164751122627813"]),
        ("tolerance 1e-6 m", ["time.error_tolerance=1e-6"]),
    ],
}


def measure(overrides: list[str], t_end: float) -> dict:
    scene = load_scene("demos/scenes/paper.toml", [f"time.t_end={t_end}", "output.field_interval=0", *overrides])
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        summary = run_scene(scene, tmp, progress=False)
        wall = time.perf_counter() - start
        with h5py.File(Path(tmp) / "timeseries.h5", "r") as f:
            t, v = f["time"][()], f["bit_velocity"][()]
    dt = np.diff(t, prepend=0.0)
    mean_v = summary["mean_bit_velocity"]
    std_v = float(np.sqrt(np.sum(dt * (v - np.sum(dt * v) / t[-1]) ** 2) / t[-1]))
    return {"mean": mean_v, "std": std_v, "rop": summary["rop"], "steps": summary["steps"],
            "balance": summary["energy"]["balance_error"], "wall": wall, "size": summary["reduced_size"],
            "integration": summary["integration_time_s"]}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--out", type=Path, default=Path("benchmarks/dynamics_convergence.md"))
    args = parser.parse_args()
    lines = [f"# Drilling dynamics: speed against accuracy (paper scene, t_end = {args.t_end} s)", "",
             f"Command: `.venv/bin/python benchmarks/dynamics_convergence.py --t-end {args.t_end}`  ",
             f"Machine: {platform.processor() or platform.machine()}, Python {platform.python_version()}, one core.", ""]
    for study, variants in STUDIES.items():
        rows = [(label, measure(ov, args.t_end)) for label, ov in variants]
        ref = rows[-1][1] if study == "basis" else rows[2][1]
        lines += [f"## {study}", "",
                  "| variant | N_red | steps | mean u_dot_bit [m/h] | std [m/h] | rop [m/h] | err(mean) | err(std) "
                  "| balance error | integration [s] | speed-up |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for label, r in rows:
            lines.append(
                f"| {label} | {r['size']} | {r['steps']} | {r['mean'] * 3600:.3f} | {r['std'] * 3600:.3f} | "
                f"{r['rop'] * 3600:.3f} | {abs(r['mean'] / ref['mean'] - 1):.2%} | {abs(r['std'] / ref['std'] - 1):.2%} | "
                f"{r['balance']:.2e} | {r['integration']:.1f} | {ref['integration'] / r['integration']:.1f}x |"
            )
            print(lines[-1], flush=True)
        lines.append("")
    args.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
