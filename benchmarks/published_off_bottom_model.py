"""Aarsnes & Shor's published off-bottom torsional model side by side with the axial-torsional string:
benchmarks/results/published_off_bottom_model.md and docs/figures/published_off_bottom_model.png.

    python benchmarks/published_off_bottom_model.py --published PATH [--t-end 300] [--after 60]

PATH: a checkout of github.com/Open-Source-Drilling-Community/Aarsnes-and-Shor-Torsional-Model (MIT licence; its
code is not copied into this repository): its python/torsionalWaveStep.py and python/parameters_WellB.py are
imported from there and stepped as their MAIN.m steps them: every 0.01 s the PI motor torque
38e3 (w_sp - w_td) + 100e3 z, held over the step, z the integral of w_sp - w_td, the set point raised towards 40 rpm
by w_sp += (40 rpm - w_sp) 0.01 s / 1 s, from rest.  Their model is the pipe over one collar section as torsional wave
guides (first-order upwind at 0.99 of the Courant limit), with the wall's Coulomb friction cell by cell: static
(mu_s) below 1.5 rad/s of spin, kinetic (0.65 mu_s) above, against the weight across the hole in air.

Cases, each over ``--t-end`` seconds, statistics over whole cycles after ``--after`` (tests/torsional_waves.py):

* **their well B as published** (MD 2500 m, built to 60 deg between 500 and 1600 m);
* **the same with the collars' polar moment of their sections' mean**: their parameters_WellB multiplies it by pi
  once more (Jc = pi sum(L pi (OD^4 - ID^4) / 32) / sum(L));
* **the side-by-side case**: that, in a straight hole at 60 deg from the surface (the wall force is then the weight
  across the hole in both models), one material (Gc = Gp, one wave speed as their grid assumes), the collars' contact
  radius that of one section of their area and polar moment; demos/scenes/off_bottom_side_by_side.toml states it for
  this string, which runs it on its compiled axial-torsional steps (10 m elements, the default step).  Two differences
  stay: their static threshold is 1.5 rad/s on the collars too, ours the pipe's surface speed (1.09 rad/s on the
  collars), and their motor torque is held over 0.01 s.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from off_bottom_well_b import spin_and_torque_figure  # noqa: E402
from speed import processor, write_result  # noqa: E402
from torsional_waves import limit_cycle_statistics, torsional_stick_slip  # noqa: E402

import fenics_drill as fd  # noqa: E402
from fenics_drill.studies.stick_slip import start  # noqa: E402

SCENE = ROOT / "demos" / "scenes" / "off_bottom_side_by_side.toml"
#: Their MAIN.m: the step [s], the set point [rad/s], the PI gains and the set point's time constant [s].
STEP, SET_POINT, K_P, K_I, RAMP = 0.01, 40.0 / 60.0 * 2.0 * math.pi, 38e3, 100e3, 1.0
#: The figure's window [s] from ``after``.
SHOWN = 40.0
#: The side-by-side string's meshes: 10, 5 and 2.5 m elements.
ELEMENTS = (250, 500, 1000)


def _substep(p) -> float:
    """Their scheme's substep [s]: STEP in equal parts within 0.99 of the Courant limit of the shorter cell."""
    return STEP / math.ceil(STEP / (min(p.Lp / p.Pp, p.Lc / p.Pc) / p.c_t * 0.99))


def published_model(module_path: Path, case: str, cells: int | None = None):
    """(their parameter object for ``case``, the damping rate [1/s] of their published scheme): their viscous source
    kt (omega) enters each substep with the substep in it, 2 kt dt on the spin.  ``cells``: the side-by-side case on
    that many cells instead of their 1000, kt scaled to keep the damping rate."""
    sys.path.insert(0, str(module_path))
    from parameters_WellB import parameters_WellB

    p = parameters_WellB(2500, 0.3, 0.65, 1.5)
    damping = 2.0 * p.kt * _substep(p)
    if case != "published":
        p.Jc = p.Jc / math.pi
    if case == "side by side":
        if cells is not None:
            p.Pp = round(cells * p.Lp / (p.Lp + p.Lc))
            p.Pc = cells - p.Pp
            p.kt = damping / (2.0 * _substep(p))
        p.Gc = p.Gp
        total, difference = 8.0 * p.Jc / p.Ac, 4.0 * p.Ac / math.pi  # D^2 + d^2 and D^2 - d^2 of one section
        p.Cro = 0.5 * math.sqrt(0.5 * (total + difference))
        p.PthetaVec, p.CthetaVec = np.full(p.Pp, math.radians(60.0)), np.full(p.Pc, math.radians(60.0))
        g = 9.81
        p.P_thresProfile = g * np.sin(p.PthetaVec) * p.rho * p.Ap * p.Pro * p.f_thres
        p.C_thresProfile = g * np.sin(p.CthetaVec) * p.rho * p.Ac * p.Cro * p.f_thres
    return p, damping


def published_run(module_path: Path, p, duration: float) -> dict:
    """Their model ``p`` stepped as MAIN.m steps it (module doc): {"time", "bit_angular_velocity", "top_torque"}, the
    bit's spin the last collar cell's and the top torque the motor's."""
    sys.path.insert(0, str(module_path))
    from torsionalWaveStep import torsionalWaveStep

    cells = p.Pp + p.Pc
    x = np.zeros(2 * cells + 1)
    steps = int(round(duration / STEP))
    rows = np.empty((steps + 1, 3))
    set_point = integral = 0.0
    for k in range(steps + 1):
        set_point += (SET_POINT - set_point) * STEP / RAMP
        top = x[2 * cells]
        torque = (set_point - top) * K_P + integral * K_I
        integral += STEP * (set_point - top)
        rows[k] = (k * STEP, x[2 * cells - 1], torque)
        if k < steps:
            x = torsionalWaveStep(p, x, STEP, torque)
    return {"time": rows[:, 0], "bit_angular_velocity": rows[:, 1], "top_torque": rows[:, 2]}


def characteristics(scene, duration: float, cell: float) -> dict:
    """The scene's string as torsional wave guides solved exactly along their characteristics, with the same wall
    law cell by cell (:func:`torsional_waves.torsional_stick_slip`): no scheme's dissipation at all."""
    beam, drive, contact = scene.beam, scene.drive, scene.contact
    sections, wall = [], []
    for section in reversed(scene.string.sections):  # the scene lists them from the bit up
        shear = section.get("young_modulus", beam.young_modulus) / (2.0 * (1.0 + beam.poisson_ratio))
        outer, inner = section["outer_radius"], section["inner_radius"]
        polar, area = math.pi / 2.0 * (outer**4 - inner**4), math.pi * (outer**2 - inner**2)
        density = section.get("density", beam.density)
        sections.append((section["length"], shear * polar, density * polar))
        wall.append((density * scene.environment.gravity * area * math.sin(math.radians(60.0)), outer))
    top_drive = (drive.top_drive_inertia, drive.proportional_gain, drive.integral_gain, drive.torque_limit)
    return torsional_stick_slip(sections, drive.rotation_speed, beam.damping, 0.0, duration, cell,
                                max(1, round(10 / cell)), top_drive,
                                (contact.static_factor, contact.friction, contact.static_slip_speed, wall))


def statistics_row(name: str, series: dict, after: float, wall: float) -> str:
    s = limit_cycle_statistics(series, SET_POINT, after)
    torque = series["top_torque"][series["time"] > after]
    return (f"| {name} | {s['period']:.3f} | {s['cycles']} | {s['max_spin']:.2f} ({s['max_spin'] * 30 / math.pi:.0f} "
            f"rpm) | {s['min_spin']:.2f} | {s['stuck_share']:.3f} | {s['surface_torque'] / 1e3:.3f} | "
            f"{torque.min() / 1e3:.2f} - {torque.max() / 1e3:.2f} | {wall:.1f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--published", type=Path, required=True,
                        help="a checkout of Open-Source-Drilling-Community/Aarsnes-and-Shor-Torsional-Model")
    parser.add_argument("--t-end", type=float, default=300.0)
    parser.add_argument("--after", type=float, default=60.0)
    args = parser.parse_args()
    module_path = args.published / "python"
    scene = fd.load_scene(SCENE)
    _, damping = published_model(module_path, "published")
    if not math.isclose(damping, scene.beam.damping, rel_tol=1e-12):
        raise SystemExit(f"their scheme damps at {damping!r} 1/s; {SCENE.name} says beam.damping = {scene.beam.damping!r}")
    commit = subprocess.run(["git", "-C", str(args.published), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip() or "its python/torsionalWaveStep.py of b73329e and " \
                                                         "python/parameters_WellB.py of 8539479"
    rows, shown = [], {}

    def measured(name, run):
        clock = time.perf_counter()
        series = run()
        rows.append(statistics_row(name, series, args.after, time.perf_counter() - clock))
        print(rows[-1], flush=True)
        return series

    for case in ("published", "collars' mean polar moment", "side by side"):
        series = measured(f"theirs: {case}, 2.5 m cells",
                          lambda: published_run(module_path, published_model(module_path, case)[0], args.t_end))
    shown["Aarsnes & Shor's code (2.5 m cells)"] = series
    for elements in ELEMENTS:
        series = measured(f"this string: side by side, {scene.string_length / elements:g} m elements",
                          lambda: start(scene.with_changes(beam={"elements": elements})).run(args.t_end))
        if elements == scene.beam.elements:
            shown["this string (10 m elements)"] = series
    measured("theirs: side by side, 1.25 m cells",
             lambda: published_run(module_path, published_model(module_path, "side by side", 2000)[0], args.t_end))
    for cell in (2.5, 1.0):
        measured(f"characteristics: side by side, {cell:g} m cells", lambda: characteristics(scene, args.t_end, cell))
    lines = ["# Aarsnes & Shor's published off-bottom model side by side with this string", "",
             f"Command: `python benchmarks/published_off_bottom_model.py --published PATH --t-end {args.t_end:g} "
             f"--after {args.after:g}`, PATH a checkout of github.com/Open-Source-Drilling-Community/"
             f"Aarsnes-and-Shor-Torsional-Model ({commit}). Machine: {platform.machine()}, {os.cpu_count()} cores "
             f"({processor()}), Python {platform.python_version()}; one process. Statistics over whole cycles in "
             f"[{args.after:g}, {args.t_end:g}] s; the side-by-side case is demos/scenes/off_bottom_side_by_side.toml "
             f"(its damping, {damping:.4g} 1/s, is their scheme's); the bit's spin below 1 % of the set 40 rpm is "
             "stuck.", "",
             "| model: case | cycle [s] | cycles | fastest spin [rad/s] | slowest spin [rad/s] | stuck share | "
             "mean motor torque [kN m] | motor torque [kN m] | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|", *rows]
    write_result("published_off_bottom_model.md", lines)
    draw(shown, args.after, ROOT / "docs" / "figures" / "published_off_bottom_model.png")


def draw(shown: dict, after: float, path: Path) -> None:
    spins, torques = {}, {}
    for label, series in shown.items():
        t = series["time"]
        window = (t > after) & (t < after + SHOWN)
        spins[label] = (t[window], series["bit_angular_velocity"][window])
        torques[label] = (t[window], series["top_torque"][window])
    spin_and_torque_figure(spins, torques, SET_POINT, "Off bottom at 40 rpm, 2500 m in a straight hole at 60 deg: the "
                           "published model and this one", path)


if __name__ == "__main__":
    main()
