"""The Campbell diagram of a ``campbell.json``: whirl frequencies against the spin, in rpm and Hz."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fenics_drill.plots.common import plt, save_figure

#: marker and colour of each whirl label
WHIRL_STYLE = {"forward": ("^", "tab:blue"), "backward": ("v", "tab:red"), "mixed": ("d", "tab:purple"),
               "planar": ("o", "0.5"), "none": ("s", "0.3")}


def campbell_figure(report: dict, path: Path) -> Path:
    """Branches (lines, markers by whirl; torsional and axial dashed), excitation lines n x Omega,
    critical speeds (circles) and the operating window of ``optimize.rotation_speed`` (shaded)."""
    rpm = np.asarray(report["rotation_speed_rpm"])
    fig, ax = plt.subplots(figsize=(8, 6))
    ax.grid(alpha=0.3)
    top = 0.0
    for branch in report["branches"]:
        f = np.asarray(branch["frequency_hz"])
        top = max(top, f.max())
        lateral = any(k == "flexural" for k in branch["kind"])
        ax.plot(rpm, f, "-" if lateral else "--", color="0.6", lw=1, zorder=1)
        for label, (marker, colour) in WHIRL_STYLE.items():
            at = np.array([w == label for w in branch["whirl"]])
            if at.any():
                ax.plot(rpm[at], f[at], marker, color=colour, ms=4, ls="none", zorder=2)
    for label, (marker, colour) in WHIRL_STYLE.items():
        ax.plot([], [], marker, color=colour, ls="none", label=f"{label} whirl" if label != "none" else
                "no lateral motion")
    for order in report["excitation_orders"]:
        ax.plot(rpm, order * rpm / 60.0, "k:", lw=1)
        ax.annotate(f"{order:g}x", (rpm[-1], order * rpm[-1] / 60.0), fontsize=8, ha="right", va="bottom")
    for c in report["critical_speeds"]:
        ax.plot(c["speed_rpm"], c["frequency_hz"], "o", mfc="none", mec="k", ms=9, zorder=3)
    if report["critical_speeds"]:
        ax.plot([], [], "o", mfc="none", mec="k", label="critical speed")
    low, high = report.get("operating_window_rpm", (None, None))
    if low is not None and high > low:
        ax.axvspan(low, high, color="tab:green", alpha=0.12, label="operating window")
    ax.set_xlim(rpm[0], rpm[-1])
    ax.set_ylim(0, 1.05 * top)
    ax.set_xlabel("rotation speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    load = report["axial_force_N"]
    ax.set_title(f"Campbell diagram ({report['steady_state']['state']} string, axial compression {load / 1e3:.3g} kN)")
    ax.legend(fontsize=8, loc="upper left")
    return save_figure(fig, path)
