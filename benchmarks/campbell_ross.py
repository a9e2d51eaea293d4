"""Campbell diagram of a pinned-pinned hollow shaft: fenics-drill against ROSS, frequencies and time.

    make bench-ross            # creates .venv-ross with ross-rotordynamics, then runs this script
    python benchmarks/campbell_ross.py --ross-python .venv-ross/bin/python --rounds 2

Both codes model the same Timoshenko shaft (the paper's pipe section, steel, 10 m, pinned at both ends:
v = w = 0, rotations free; ROSS with translational bearings of 1e15 N/m), with the same shear factor
(Cowper's for a hollow circle, which ROSS uses; fenics-drill takes it as ``beam.shear_factor``),
over the same speeds.  Each round runs the whole process of each code - interpreter, imports, model,
sweep - as a subprocess, the two alternating, so the machine's state is shared.  Writes
benchmarks/results/campbell_ross.md.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fenics_drill.scene import load_scene  # noqa: E402

LENGTH = 10.0
SPEEDS = (0.0, 500.0, 20)  # rad/s: 0 to 4775 rpm
LATERAL = 8  # lateral frequencies compared at each speed


def cowper_shear_factor(outer_radius: float, inner_radius: float, poisson: float) -> float:
    """Cowper (J. Appl. Mech. 33 (1966) 335) for a hollow circle, m = R_int / R_ext."""
    m2 = (inner_radius / outer_radius) ** 2
    return 6 * (1 + poisson) * (1 + m2) ** 2 / ((7 + 6 * poisson) * (1 + m2) ** 2 + (20 + 12 * poisson) * m2)


def spec(elements: int) -> dict:
    beam = load_scene(ROOT / "demos/scenes/paper.toml").beam
    return {"elements": elements, "length": LENGTH, "inner_radius": beam.inner_radius,
            "outer_radius": beam.outer_radius, "density": beam.density, "young_modulus": beam.young_modulus,
            "poisson_ratio": beam.poisson_ratio, "support_stiffness": 1e15, "speeds_rad_s": list(SPEEDS),
            "modes": 12}


def run_ross(python: str, shaft: dict) -> tuple[dict, float]:
    start = time.perf_counter()
    done = subprocess.run([python, str(ROOT / "benchmarks/campbell_ross_side.py"), json.dumps(shaft)],
                          capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    return json.loads(done.stdout.strip().splitlines()[-1]), wall


def run_ours(shaft: dict) -> tuple[dict, float]:
    kappa = cowper_shear_factor(shaft["outer_radius"], shaft["inner_radius"], shaft["poisson_ratio"])
    low, high, n = shaft["speeds_rad_s"]
    with tempfile.TemporaryDirectory() as out:
        command = [str(ROOT / ".venv/bin/fenics-drill"), "campbell", str(ROOT / "demos/scenes/paper.toml"),
                   "--out", out, "--set", f"beam.length={shaft['length']}", "--set",
                   f"beam.elements={shaft['elements']}", "--set", f"beam.shear_factor={kappa}",
                   "--set", "model.supports=pinned", "--set", "model.gravity=false", "--set", "model.contact=false",
                   "--set", "model.bit_rock=false", "--set", f"campbell.rotation_speed=[{low}, {high}, {n}]",
                   "--set", "campbell.modes=12", "--set", "campbell.excitation_orders=[1]"]
        start = time.perf_counter()
        subprocess.run(command, capture_output=True, text=True, check=True)
        wall = time.perf_counter() - start
        report = json.loads((Path(out) / "campbell.json").read_text())
    return report, wall


def lateral_ours(report: dict) -> np.ndarray:
    """(speeds, LATERAL) flexural frequencies, sorted at each speed."""
    rows = []
    for i in range(len(report["rotation_speed_rad_s"])):
        f = sorted(b["frequency_hz"][i] for b in report["branches"] if b["kind"][i] == "flexural")
        rows.append(f[:LATERAL])
    return np.array(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ross-python", required=True, help="a Python with ross-rotordynamics")
    parser.add_argument("--elements", type=int, default=500)
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    shaft = spec(args.elements)
    times = {"ross": [], "fenics-drill": []}
    for _ in range(args.rounds):
        ross, wall = run_ross(args.ross_python, shaft)
        times["ross"].append(wall)
        ours, wall = run_ours(shaft)
        times["fenics-drill"].append(wall)
    f_ross = np.sort(np.asarray(ross["frequency_hz"]), axis=1)[:, :LATERAL]
    f_ours = lateral_ours(ours)
    difference = np.abs(f_ours / f_ross - 1.0)
    kappa = cowper_shear_factor(shaft["outer_radius"], shaft["inner_radius"], shaft["poisson_ratio"])
    rpm = np.asarray(ours["rotation_speed_rpm"])
    lines = [
        "# Campbell diagram: fenics-drill against ROSS (pinned-pinned hollow shaft)",
        "",
        f"Command: `make bench-ross` (= `python benchmarks/campbell_ross.py --ross-python .venv-ross/bin/python "
        f"--elements {args.elements} --rounds {args.rounds}`), ross-rotordynamics 3.1.0. Machine: "
        f"{platform.machine()}, {platform.processor() or 'cpu'}, 2 cores, Python {platform.python_version()}; "
        f"run on {time.strftime('%Y-%m-%d')}.",
        "",
        f"Shaft: L = {LENGTH} m, R_ext = {shaft['outer_radius']} m, R_int = {shaft['inner_radius']} m, "
        f"E = {shaft['young_modulus']:.3g} Pa, rho = {shaft['density']} kg/m^3, nu = {shaft['poisson_ratio']}, "
        f"Cowper's shear factor {kappa:.4f} in both; {args.elements} elements in each code; "
        f"{SPEEDS[2]} speeds from {rpm[0]:.0f} to {rpm[-1]:.0f} rpm; the {LATERAL} lowest lateral frequencies.",
        "",
        "## Frequencies",
        "",
        f"Largest relative difference over all speeds and the {LATERAL} frequencies: **{difference.max():.2e}** "
        f"(mean {difference.mean():.2e}).",
        "",
        "| rpm | " + " | ".join(f"f{k + 1} ours / ROSS [Hz]" for k in range(4)) + " |",
        "|---|" + "---|" * 4,
    ]
    for i in (0, len(rpm) // 2, len(rpm) - 1):
        cells = " | ".join(f"{f_ours[i, k]:.4f} / {f_ross[i, k]:.4f}" for k in range(4))
        lines.append(f"| {rpm[i]:.0f} | {cells} |")
    ross_best, ours_best = min(times["ross"]), min(times["fenics-drill"])
    lines += [
        "",
        "## Time (whole process: interpreter, imports, model, sweep; alternating rounds)",
        "",
        "| round | ROSS run_campbell [s] | fenics-drill campbell [s] |",
        "|---|---|---|",
        *[f"| {k + 1} | {r:.1f} | {o:.1f} |" for k, (r, o) in enumerate(zip(times["ross"], times["fenics-drill"]))],
        "",
        f"Speed-up (best of each): **{ross_best / ours_best:.0f}x**.",
    ]
    out = ROOT / "benchmarks/results/campbell_ross.md"
    out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
