"""Figures 14-19 of the paper from a run's timeseries.h5 (what ``fenics-drill run`` writes).

    python demos/drilling_figures.py out/nominal-objective [--docs docs/figures --tag objective]

Fig. 14 bit displacement and velocity, Fig. 15 bit rotation and angular velocity,
Fig. 16 lateral displacement and velocity at the section, Fig. 17 radial
displacement at the section, Fig. 18 impacts and vertices in contact against time,
Fig. 19 impacts per vertex.  Units are converted at this plotting edge only
(mm, m/h, rev, rpm as in the paper).
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _pair(path, t, top, bottom, top_label, bottom_label, title):
    fig, (a, b) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    a.plot(t, top, lw=0.8)
    a.set_ylabel(top_label)
    b.plot(t, bottom, lw=0.6)
    b.set_ylabel(bottom_label)
    b.set_xlabel("time [s]")
    a.set_title(title)
    for ax in (a, b):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _single(path, draw, xlabel, ylabel, title):
    fig, ax = plt.subplots(figsize=(8, 3.5))
    draw(ax)
    ax.set(xlabel=xlabel, ylabel=ylabel, title=title)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def make_figures(run_dir: Path) -> list[Path]:
    with h5py.File(run_dir / "timeseries.h5", "r") as f:
        d = {k: f[k][()] for k in f.keys()}
        section_x = float(f.attrs["section_x"])
    t = d["time"]
    out = []
    p = run_dir / "fig14_bit_axial.png"
    _pair(p, t, d["bit_displacement"] * 1e3, d["bit_velocity"] * 3600, "bit displacement [mm]",
          "bit velocity [m/h]", "Fig. 14: drill-bit axial motion")
    out.append(p)
    p = run_dir / "fig15_bit_rotation.png"
    _pair(p, t, d["bit_rotation"] / (2 * np.pi), d["bit_angular_velocity"] * 60 / (2 * np.pi),
          "bit rotation [rev]", "bit angular velocity [rpm]", "Fig. 15: drill-bit rotation")
    out.append(p)
    p = run_dir / "fig16_section_lateral.png"
    _pair(p, t, d["section_w"] * 1e3, d["section_w_velocity"], "w [mm]", "w velocity [m/s]",
          f"Fig. 16: transverse motion at x = {section_x:g} m")
    out.append(p)
    p = run_dir / "fig17_section_radial.png"
    _single(p, lambda ax: ax.plot(t, np.hypot(d["section_v"], d["section_w"]) * 1e3, lw=0.8),
            "time [s]", "radial displacement [mm]", f"Fig. 17: radial displacement at x = {section_x:g} m")
    out.append(p)
    p = run_dir / "fig18_impacts_time.png"
    _pair(p, t, d["impacts"], d["vertices_in_contact"], "impacts per step", "vertices in contact",
          "Fig. 18: wall impacts against time")
    out.append(p)
    p = run_dir / "fig19_impacts_position.png"
    _single(p, lambda ax: ax.bar(d["vertex_x"], d["impacts_per_vertex"], width=d["vertex_x"][1] - d["vertex_x"][0]),
            "x [m]", "impacts", "Fig. 19: wall impacts per vertex")
    out.append(p)
    return out


def shock_packages(run_dir: Path, quiet_gap_s: float = 0.2) -> int:
    """Number of groups of impacts separated by more than ``quiet_gap_s`` without any (Section 6.7)."""
    with h5py.File(run_dir / "timeseries.h5", "r") as f:
        t, impacts = f["time"][()], f["impacts"][()]
    times = t[impacts > 0]
    if times.size == 0:
        return 0
    return int(1 + np.sum(np.diff(times) > quiet_gap_s))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--docs", type=Path, help="also copy the figures here")
    parser.add_argument("--tag", default="", help="suffix for the copied file names")
    args = parser.parse_args()
    figures = make_figures(args.run_dir)
    print(f"{len(figures)} figures in {args.run_dir}; shock packages: {shock_packages(args.run_dir)}")
    if args.docs:
        args.docs.mkdir(parents=True, exist_ok=True)
        for fig in figures:
            shutil.copy(fig, args.docs / (fig.stem + (f"_{args.tag}" if args.tag else "") + fig.suffix))


if __name__ == "__main__":
    main()
