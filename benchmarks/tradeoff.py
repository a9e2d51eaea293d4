"""Speed against accuracy of every fidelity knob, on a scene of the user's choice.

    .venv/bin/python benchmarks/tradeoff.py [SCENE] [--t-end 0.5] [--workers 2] [--out benchmarks/results/tradeoff]

Runs a converged reference (full order, fine mesh, small step) and a ladder of cheaper
settings, each in its own process (so that peak memory is that variant's), and reports
wall time, peak resident memory and the relative error against the reference of what
users read: rop, efficiency, mean and RMS bit velocity and angular velocity, impacts,
max von Mises stress.  Writes OUT/tradeoff.md (table) and OUT/pareto.png (error against
time), and OUT/runs/*.json (raw results, reused when present: delete them to rerun).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import platform
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

#: name -> overrides; "reference" is the converged run every other is compared with.  The default is the
#: 'auto' rule (the paper's bands with the stuck-bit torsional modes) with the guard's enrichment;
#: every knob below is changed alone from it.
LADDER = {
    "reference: full order, 1000 elements, dt/4": ["reduction.rule='none'", "beam.elements=1000", "DT/4"],
    "full order, 500 elements, dt/4": ["reduction.rule='none'", "DT/4"],
    "full order, 500 elements, dt": ["reduction.rule='none'"],
    "default: auto basis + guard, 500 elements, dt, alpha 0.015": [],
    "paper basis (44) + guard": ["reduction.rule='paper'"],
    "pure paper basis (enrich off)": ["reduction.rule='paper'", "reduction.enrich=false", "reduction.guard_tolerance=1"],
    "pure paper basis (enrich off), dt/4": ["reduction.rule='paper'", "reduction.enrich=false",
                                            "reduction.guard_tolerance=1", "DT/4"],
    "default, dt/2": ["DT/2"],
    "default, dt/4": ["DT/4"],
    "default, fixed step (not adaptive)": ["time.adaptive=false"],
    "default, tolerance 1e-6 m": ["time.error_tolerance=1e-6"],
    "default, alpha 0": ["time.newmark_alpha=0.0"],
    "default, Newton tolerance 1e-6": ["solver.newton_tolerance=1e-6"],
    "default, internal tangent fresh every step": ["solver.tangent_reuse=1"],
    "default, internal tangent reused 100 steps": ["solver.tangent_reuse=100"],
    "default, alpha 0.1": ["time.newmark_alpha=0.1"],
    "default, 250 elements": ["beam.elements=250"],
    "default, element degree 3": ["beam.element_degree=3"],
    "band basis: flexural f* <= 2 (124)": ["reduction.rule='band'", "reduction.flexural=2.0",
                                           "reduction.torsional=4.0", "reduction.axial=4.0"],
    "band basis: flexural f* <= 4 (all 168 modes of B)": ["reduction.rule='band'", "reduction.flexural=4.0",
                                                          "reduction.torsional=4.0", "reduction.axial=4.0"],
    "default, no von Mises probe": ["output.von_mises=false"],
    "linear model (no geometric/inertial nonlinearity)": ["model.geometric_nonlinearity=false",
                                                          "model.inertial_nonlinearity=false"],
    "no contact": ["model.contact=false"],
}
QUANTITIES = ("rop", "efficiency", "mean_bit_velocity", "rms_bit_velocity", "mean_omega", "rms_omega",
              "impacts_total", "max_von_mises")
#: The three error measures of the Pareto plot: what each use reads.
GROUPS = {
    "drilling quantities (rop, efficiency, means)": ("rop", "efficiency", "mean_bit_velocity", "mean_omega"),
    "fluctuations (RMS bit velocity and angular velocity)": ("rms_bit_velocity", "rms_omega"),
    "max von Mises stress": ("max_von_mises",),
}

WORKER = r"""
import json, resource, sys, tempfile, time
import h5py, numpy as np
from fenics_drill.studies.run import run_scene
from fenics_drill.scene import load_scene
scene = load_scene(sys.argv[1], json.loads(sys.argv[2]))
with tempfile.TemporaryDirectory() as tmp:
    clock = time.perf_counter()
    s = run_scene(scene, tmp, progress=False)
    wall = time.perf_counter() - clock
    with h5py.File(tmp + "/timeseries.h5") as f:
        t, v, w = f["time"][()], f["bit_velocity"][()], f["bit_angular_velocity"][()]
rms = lambda x: float(np.sqrt(np.trapezoid(x**2, t) / t[-1]))
print(json.dumps({"status": s["status"], "message": s["message"], "wall_time_s": wall,
    "peak_memory_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, "steps": s["steps"],
    "reduced_size": s.get("reduced_size"), "rop": s.get("rop"), "efficiency": s.get("efficiency"),
    "mean_bit_velocity": s.get("mean_bit_velocity"), "rms_bit_velocity": rms(v),
    "mean_omega": float(np.trapezoid(w, t) / t[-1]), "rms_omega": rms(w),
    "impacts_total": s.get("impacts_total"), "max_von_mises": s.get("max_von_mises", {}).get("value")}))
"""


#: Every variant runs the paper's wall friction (18)-(19): under the Coulomb force at the contact point a spinning
#: string on the wall climbs it, and the 'auto' rule takes the full order, so there are no reduced variants to weigh.
PAPER_FRICTION = ["contact.friction_model='paper'", "contact.sliding_velocity_scale=1e-3"]


def overrides(items: list[str], t_end: float, nominal_dt: float) -> list[str]:
    out = [f"time.t_end={t_end}", "output.field_interval=0", *PAPER_FRICTION]
    for item in items:
        out.append(f"time.dt={nominal_dt / int(item[3:])}" if item.startswith("DT/") else item)
    return out


def measure(scene: str, name: str, items: list[str], t_end: float, nominal_dt: float, runs: Path) -> dict:
    path = runs / f"{hashlib.sha1(name.encode()).hexdigest()[:12]}.json"
    if path.exists():
        return json.loads(path.read_text())
    done = subprocess.run([sys.executable, "-c", WORKER, scene, json.dumps(overrides(items, t_end, nominal_dt))],
                          capture_output=True, text=True, check=True)
    result = json.loads(done.stdout.strip().splitlines()[-1])
    result["name"] = name
    path.write_text(json.dumps(result, indent=1))
    print(f"{name}: {result['wall_time_s']:.1f} s", flush=True)
    return result


def relative_error(value, reference) -> float:
    if value is None or reference is None:
        return float("nan")
    if reference == 0:
        return abs(value)
    return abs(value / reference - 1.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="demos/scenes/paper.toml")
    parser.add_argument("--t-end", type=float, default=0.5)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("benchmarks/results/tradeoff"))
    args = parser.parse_args()
    from fenics_drill.scene import load_scene
    from fenics_drill.solvers.step_control import nominal_step

    nominal_dt = nominal_step(load_scene(args.scene, []))
    runs = args.out / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    with ThreadPoolExecutor(args.workers) as pool:
        results = list(pool.map(lambda kv: measure(args.scene, kv[0], kv[1], args.t_end, nominal_dt, runs),
                                LADDER.items()))
    ref = results[0]
    lines = [f"# Fidelity study: {args.scene}, t_end = {args.t_end} s", "",
             f"Command: `.venv/bin/python benchmarks/tradeoff.py {args.scene} --t-end {args.t_end} "
             f"--workers {args.workers}`  ",
             f"Machine: {platform.machine()}, {args.workers} variants at a time, one core and one BLAS thread each, "
             f"Python {platform.python_version()}. Errors are relative to the first row.", "",
             "| # | variant | N | steps | wall [s] | peak memory [MB] | " + " | ".join(f"err {q}" for q in QUANTITIES)
             + " | impacts |", "|---" * (7 + len(QUANTITIES)) + "|"]
    points = []
    for index, r in enumerate(results):
        errors = dict(zip(QUANTITIES, (relative_error(r.get(q), ref.get(q)) for q in QUANTITIES)))
        points.append((index, r["wall_time_s"], {g: max((errors[q] for q in qs), default=np.nan)
                                                  for g, qs in GROUPS.items()}))
        cells = " | ".join("—" if not np.isfinite(e) else f"{e:.1%}" for e in errors.values())
        status = "" if r["status"] == "finished" else f" ({r['status']}: {r['message']})"
        lines.append(f"| {index} | {r['name']}{status} | {r['reduced_size']} | {r['steps']} | {r['wall_time_s']:.1f} | "
                     f"{r['peak_memory_mb']:.0f} | {cells} | {r['impacts_total']} |")
    lines += ["", "Reference values: " + ", ".join(f"{q} = {ref.get(q):.6g}" for q in QUANTITIES
                                                      if ref.get(q) is not None), ""]
    (args.out / "tradeoff.md").write_text("\n".join(lines) + "\n")
    _pareto(points[1:], args.out / "pareto.png")
    print("\n".join(lines))


def _pareto(points, path: Path) -> None:
    """One panel per error measure (GROUPS): error against wall time, points numbered as in the
    table, the Pareto front in red."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(GROUPS), figsize=(16, 5.5))
    for ax, group in zip(axes, GROUPS):
        kept = [(i, t, e[group]) for i, t, e in points if np.isfinite(e[group])]
        times = np.array([t for _, t, _ in kept])
        errors = np.array([max(e, 1e-4) for _, _, e in kept])
        front = [k for k in range(len(kept)) if not any(times[j] <= times[k] and errors[j] < errors[k]
                                                         for j in range(len(kept)) if j != k)]
        ax.scatter(times, errors, c=["C3" if k in front else "C0" for k in range(len(kept))], s=18)
        for (index, _, _), t, e in zip(kept, times, errors):
            ax.annotate(str(index), (t, e), fontsize=7, xytext=(3, 2), textcoords="offset points")
        order = sorted(front, key=lambda k: times[k])
        ax.plot(times[order], errors[order], "C3--", lw=0.8, label="Pareto front")
        ax.set(xscale="log", yscale="log", xlabel="wall time [s]", ylabel="largest relative error",
               title=group)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.suptitle("Speed against accuracy: each point one setting, numbered as in tradeoff.md "
                 "(errors against row 0, floored at 1e-4)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
