"""Aarsnes & van de Wouw's published distributed axial-torsional model on bottom, side by side with the
axial-torsional string: benchmarks/results/published_axial_torsional_model.md.

    python benchmarks/published_axial_torsional_model.py --published-series DIR [--elements 200]

Their model (github.com/ulfjakob/AxialTorsionalDrillString, "Coupled - nondim": parameters.m, runSim.m,
waveStepUpwind.m; MATLAB, not run here) is a uniform string as axial and torsional wave guides in nondimensional form,
solved by first-order upwinding: length 1, torsional wave speed 1, axial c_a / c_t = 1.6, viscous damping
k = -ln(eta) on both, the top held at (v0, omega0), the cutting law at the bit with its delay (the depth of cut per
blade, d = u(t) - u(t - t_N), t_N one blade passage, as a transport in the bit's angle), d K_a and d the cutting
weight and torque, a wear-flat contact of weight Wf and torque beta Wf that sticks, and a torsional stick below a spin
of 0.02.  Their MAIN.m runs K_a = 20, eta = 0.7, beta = 0.1, Wf = 200, v0 = 2 and omega0 = 1 for 120 time units.

DIR holds their runs as CSV files ``omega0_<omega0>.csv`` (columns: t, the bit's velocity, its spin, from runSim's
y(4,:) and y(5,:)), and optionally runs of their scheme refined, ``omega0_<omega0>_cells<P>[_delay].csv``: P cells, the
step of the waves' CFL condition alone, and with ``_delay`` the depth of cut read from the bit's recorded path
instead of their transport in the bit's angle.  Without DIR this string's runs alone are reported.

Besides the fastest spin over all the cycles, each cycle's own fastest spin is reported (its median and its 10th and
90th percentiles over the cycles): an irregular cycle's fastest spin is the extreme of that spread.

The string here (tests/torsional_waves.py, :func:`moving_top_cutting_law_case`): 2000 m of 5 in drill pipe (E = 210 GPa, nu = 0.28: c_a / c_t = 1.6), vertical,
without gravity (their model has none), a 4-blade bit of 0.108 m radius, zeta = 1, l = 1.2 mm, mu = 0.5; the
scales of their groups are t* = L / c_t, the angle of one blade passage 2 pi / n, the depth U* that makes their
cutting torque d, U* = 2 G J (2 pi / n) / (L eps a^2 n), the weight E A U* / L and the torque G J (2 pi / n) / L,
from which eps, sigma and gamma follow.  Its bit turned backwards is held (``bit_rock.backward_spin = 'held'``), as
theirs sticks.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from speed import processor, write_result  # noqa: E402
from torsional_waves import (BETA, ETA, K_A, LENGTH, V0, WEAR_FLAT, limit_cycle_statistics,  # noqa: E402
                            moving_top_cutting_law_case, published_scales)

from fenics_drill.observables.spectra import dominant_period  # noqa: E402
from fenics_drill.studies.stick_slip import cycles, start  # noqa: E402

#: The set spins compared (their first, and their second at the same v0), and the time units run and skipped.
SPINS, DURATION, AFTER = (1.0, 1.8), 120.0, 60.0
#: The exact characteristics' torsional cell [m] (the axial one 1.6 times it: 1 m).
CELL = 0.625


def statistics(t: np.ndarray, velocity: np.ndarray, spin: np.ndarray, omega0: float) -> dict:
    """The limit cycle's statistics over the whole cycles after AFTER, in their units, with each cycle's fastest
    spin's median and 10th and 90th percentiles over the cycles."""
    series = {"time": t, "bit_angular_velocity": spin, "top_torque": 0.0 * t}
    s = limit_cycle_statistics(series, omega0, AFTER)
    late = t > AFTER
    peaks = [spin[late][rows].max() for rows in cycles({k: v[late] for k, v in series.items()}, omega0)]
    return {**s, "max_velocity": float(velocity[late].max()), "mean_velocity": float(velocity[late].mean()),
            "cycle_peaks": np.percentile(peaks, (50, 10, 90)), "dominant_period": dominant_period(t[late], spin[late])}


def scaled_statistics(series: dict, omega0: float) -> dict:
    """:func:`statistics` of a run of this string (SI units), in their units."""
    s = published_scales()
    return statistics(series["time"] / s["time"], series["bit_velocity"] / s["velocity"],
                      series["bit_angular_velocity"] / s["spin"], omega0)


def peaks_cell(s: dict) -> str:
    """Each cycle's fastest spin as a table cell: the median (10th-90th percentile)."""
    median, low, high = s["cycle_peaks"]
    return f"{median:.3f} ({low:.2f}-{high:.2f})"


def row(name: str, s: dict, wall: float | None) -> str:
    return (f"| {name} | {s['period']:.3f} | {s['cycles']} | {s['max_spin']:.3f} | {peaks_cell(s)} "
            f"| {s['stuck_share']:.3f} | {s['max_velocity']:.2f} | {s['mean_velocity']:.3f} | "
            f"{'' if wall is None else f'{wall:.1f}'} |")


def published_label(path: Path, omega0: float) -> str:
    """Their run's row name from its file name (module doc)."""
    words = [f"omega0 = {omega0:g}"]
    for token in path.stem.split("_")[2:]:
        words.append(f"{token[5:]} cells, CFL step" if token.startswith("cells") else "recorded depth of cut")
    return "theirs, " + ", ".join(words)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--published-series", type=Path, default=None)
    parser.add_argument("--elements", type=int, default=200)
    args = parser.parse_args()
    s = published_scales()
    rows = []
    for omega0 in SPINS:
        if args.published_series is not None:
            found = sorted(args.published_series.glob(f"omega0_{omega0:g}.csv"))
            refined = args.published_series.glob(f"omega0_{omega0:g}_cells*.csv")
            for path in found + sorted(refined, key=lambda p: int(p.stem.split("_")[2][5:])):
                theirs = np.loadtxt(path, delimiter=",")
                rows.append(row(published_label(path, omega0), statistics(*theirs.T, omega0), None))
                print(rows[-1], flush=True)
        scene, exact_run = moving_top_cutting_law_case(omega0, args.elements)
        for zeta in (0.0, 1.0):
            clock = time.perf_counter()
            series = start(scene.with_changes(stick_slip_map={"mesh_viscosity": zeta})).run(DURATION * s["time"])
            wall = time.perf_counter() - clock
            mine = scaled_statistics(series, omega0)
            rows.append(row(f"this string, omega0 = {omega0:g}, {LENGTH / args.elements:g} m elements"
                            + (f", mesh viscosity {zeta:g}" if zeta else ""), mine, wall))
            print(rows[-1], flush=True)
        clock = time.perf_counter()
        exact = exact_run(DURATION * s["time"], CELL)
        wall = time.perf_counter() - clock
        rows.append(row(f"this string's law, exact characteristics, omega0 = {omega0:g}, {CELL:g} m cells",
                        scaled_statistics(exact, omega0), wall))
        print(rows[-1], flush=True)
    lines = ["# Aarsnes & van de Wouw's published axial-torsional model on bottom, side by side with this string", "",
             f"Command: `python benchmarks/published_axial_torsional_model.py --published-series DIR --elements "
             f"{args.elements}`. Machine: {platform.machine()}, {os.cpu_count()} cores ({processor()}), Python "
             f"{platform.python_version()}; one process. Their case (K_a = {K_A:g}, eta = {ETA:g}, beta = {BETA:g}, "
             f"Wf = {WEAR_FLAT:g}, v0 = {V0:g}) in their units: time L / c_t = {s['time']:.4f} s, velocity "
             f"{s['velocity']:.4g} m/s, spin {s['spin']:.4f} rad/s; statistics over the whole cycles in "
             f"[{AFTER:g}, {DURATION:g}]; stuck: a spin below 1 % of omega0; per cycle: each cycle's fastest spin, "
             "the median (10th-90th percentile) over the cycles. DIR: their runs (1000 cells, as published; refined "
             "as the row says) from a Python translation of their waveStepUpwind.m and runSim.m (MATLAB is not on "
             "this machine; the translation is not in this repository).", "",
             "| model, case | cycle | cycles | fastest spin | per cycle | stuck share | fastest bit velocity | "
             "mean bit velocity | wall [s] |", "|---|---|---|---|---|---|---|---|---|", *rows]
    write_result("published_axial_torsional_model.md", lines)


if __name__ == "__main__":
    main()
