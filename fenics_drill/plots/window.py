"""Contour maps of an operating window (Figs. 24-27 and 36) from ``optimize.json``, in m/h and rpm,
with the admissible region's optimum marked by a blue cross and inadmissible points hatched; and the
stick-slip map (``stick_slip_map.png``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from fenics_drill.plots.common import M_PER_S_TO_M_PER_H, RAD_PER_S_TO_RPM, panels, save_figure
from fenics_drill.plots.common import plt  # the Agg backend set there

#: map -> (figure in the paper, label, scale)
MAPS = {
    "efficiency": ("24", "efficiency [%]", 100.0),
    "efficiency_torque_magnitude": ("24", "efficiency, bit torque counted by its magnitude [%]", 100.0),
    "max_von_mises": ("25", "max von Mises stress [MPa]", 1e-6),
    "rop": ("26", "rate of penetration (99) [m/h]", M_PER_S_TO_M_PER_H),
    "signed_rop": ("27", "mean of u_dot_bit (Fig. 27 variant) [m/h]", M_PER_S_TO_M_PER_H),
}

#: The stick-slip map (not in the paper): indicator -> (label, scale), over the second half of each run.
OSCILLATION_MAPS = {
    "stick_slip_severity": ("stick-slip severity (max - min) omega_bit / 2 Omega [-]", 1.0),
    "stick_fraction": ("time stuck (omega_bit < 0.1 Omega) [%]", 100.0),
    "off_bottom_fraction": ("time off bottom (u_dot_bit <= 0) [%]", 100.0),
}


def optimize_figures(directory: Path) -> list[Path]:
    report = json.loads((directory / "optimize.json").read_text())
    v0 = np.array(report["axial_velocity"]) * M_PER_S_TO_M_PER_H
    rpm = np.array(report["rotation_speed"]) * RAD_PER_S_TO_RPM
    admissible = np.array(report["admissible"])
    robust = report["mode"].startswith("robust")
    paths = []
    for name, (figure, label, scale) in MAPS.items():
        if name not in report:  # a map that studies of earlier versions did not make
            continue
        values = np.array(report[name], dtype=float) * scale
        fig, (ax,) = panels(1, 5.0)
        if len(v0) > 1 and len(rpm) > 1:
            levels = ax.contourf(v0, rpm, values.T, levels=15, cmap="viridis")
            fig.colorbar(levels, ax=ax, label=("E[" + label + "]") if robust and name != "max_von_mises" else label)
        else:
            ax.scatter(np.repeat(v0, len(rpm)), np.tile(rpm, len(v0)), c=values.ravel(), cmap="viridis")
        V, W = np.meshgrid(v0, rpm, indexing="ij")
        ax.plot(V[admissible], W[admissible], "k.", ms=3, label="grid point (admissible)")
        if (~admissible).any():
            ax.plot(V[~admissible], W[~admissible], "rx", ms=6, label="violates the von Mises constraint")
        if report["optimum"] is not None and name == report["objective"]:
            o = report["optimum"]
            ax.plot(o["axial_velocity"] * M_PER_S_TO_M_PER_H, o["rotation_speed"] * RAD_PER_S_TO_RPM, "b+", ms=16,
                    mew=3, label=f"optimum: {o['objective'] * scale:.3g}")
        shown = "36" if robust and name == "rop" else figure
        ax.set(xlabel="V0 [m/h]", ylabel="Omega [rpm]",
               title=f"Fig. {shown}: {label}\n{report['mode']}, t_end = {report['t_end']:g} s")
        ax.legend(loc="lower left", fontsize=7)
        paths.append(save_figure(fig, directory / f"fig{shown}_{name}_map.png"))
    if "smooth_drilling" in report and len(v0) > 1 and len(rpm) > 1:
        paths.append(stick_slip_map(report, v0, rpm, directory))
    return paths


def stick_slip_map(report: dict, v0: np.ndarray, rpm: np.ndarray, directory: Path) -> Path:
    """The three oscillation indicators side by side, the smooth-drilling region outlined (white)."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    smooth = np.array(report["smooth_drilling"], dtype=float)
    failed = ~np.isfinite(np.array(report["stick_slip_severity"], dtype=float))
    for ax, (name, (label, scale)) in zip(axes, OSCILLATION_MAPS.items()):
        values = np.array(report[name], dtype=float) * scale
        levels = ax.contourf(v0, rpm, values.T, levels=15, cmap="magma")
        fig.colorbar(levels, ax=ax, label=label)
        if 0 < smooth.sum() < smooth.size:
            ax.contour(v0, rpm, smooth.T, levels=[0.5], colors="w", linewidths=2)
        V, W = np.meshgrid(v0, rpm, indexing="ij")
        ax.plot(V[smooth > 0], W[smooth > 0], "wo", ms=4, label="smooth drilling")
        ax.plot(V[(smooth == 0) & ~failed], W[(smooth == 0) & ~failed], "cx", ms=5, label="stick-slip or bit-bounce")
        if failed.any():
            ax.plot(V[failed], W[failed], "ks", ms=6, label="run failed (blank)")
        ax.set(xlabel="V0 [m/h]", ylabel="Omega [rpm]", title=label.split(" [")[0])
        ax.legend(loc="lower left", fontsize=7)
    fig.suptitle(f"stick-slip map, second half of t_end = {report['t_end']:g} s")
    return save_figure(fig, directory / "stick_slip_map.png")
