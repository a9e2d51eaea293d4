"""The Campbell diagram of a ``campbell.json``: whirl frequencies against the spin, in rpm and Hz."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fenics_drill.plots.common import plt, save_figure

#: marker and colour of each whirl label, and its legend entry
WHIRL_STYLE = {"forward": ("^", "tab:blue", "forward whirl"), "backward": ("v", "tab:red", "backward whirl"),
               "mixed": ("d", "tab:purple", "mixed whirl"), "planar": ("o", "0.5", "planar (no whirl)"),
               "none": ("s", "0.3", "no lateral motion")}


def crossing_text(crossing: dict) -> str:
    """'1x line meets the forward whirl of a flexural branch' (or 'a torsional branch' without lateral motion)."""
    whirl, kind = crossing["whirl"], crossing["kind"]
    branch = f"a {kind} branch" if whirl == "none" else f"the {whirl} whirl of a {kind} branch"
    if whirl == "planar":
        branch = f"a {kind} branch (planar)"
    return f"{crossing['order']:g}x line meets {branch}"


def campbell_figure(report: dict, path: Path) -> Path:
    """Branches (markers by whirl; torsional and axial dashed), excitation lines n x Omega labelled inside the
    axes, critical speeds (circles), the operating window where it lies inside the sweep; the legend lists
    only what occurs and sits outside the data."""
    rpm = np.asarray(report["rotation_speed_rpm"])
    fig, ax = plt.subplots(figsize=(9, 5.5))
    ax.grid(alpha=0.3)
    top = 0.0
    seen = set()
    for branch in report["branches"]:
        f = np.asarray(branch["frequency_hz"])
        top = max(top, f.max())
        lateral = any(k == "flexural" for k in branch["kind"])
        ax.plot(rpm, f, "-" if lateral else "--", color="0.6", lw=1, zorder=1)
        for label, (marker, colour, _) in WHIRL_STYLE.items():
            at = np.array([w == label for w in branch["whirl"]])
            if at.any():
                seen.add(label)
                ax.plot(rpm[at], f[at], marker, color=colour, ms=4, ls="none", zorder=2)
    for label, (marker, colour, text) in WHIRL_STYLE.items():
        if label in seen:
            ax.plot([], [], marker, color=colour, ls="none", label=text)
    ymax = 1.05 * top if top > 0 else 1.0
    for order in report["excitation_orders"]:
        line = order * rpm / 60.0
        ax.plot(rpm, line, "k:", lw=1)
        # label where the line leaves the axes, just outside their frame (top or right edge): off the data
        if line[-1] > ymax:
            at, offset, align = (ymax * 60.0 / order, ymax), (0, 2), ("center", "bottom")
        else:
            at, offset, align = (rpm[-1], line[-1]), (3, 0), ("left", "center")
        ax.annotate(f"{order:g}x", at, xytext=offset, textcoords="offset points", fontsize=9, ha=align[0],
                    va=align[1], annotation_clip=False)
    for c in report["critical_speeds"]:
        ax.plot(c["speed_rpm"], c["frequency_hz"], "o", mfc="none", mec="k", ms=9, zorder=3)
    if report["critical_speeds"]:
        ax.plot([], [], "o", mfc="none", mec="k", label="critical speed")
    low, high = report.get("operating_window_rpm", (None, None))
    if low is not None and high > low and low < rpm[-1] and high > rpm[0]:
        ax.axvspan(max(low, rpm[0]), min(high, rpm[-1]), color="tab:green", alpha=0.12, label="operating window")
    ax.set_xlim(rpm[0], rpm[-1])
    ax.set_ylim(0, ymax)
    ax.set_xlabel("rotation speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    load = report["axial_force_N"]
    ax.set_title(f"Campbell diagram ({report['steady_state']['state']} string, axial compression {load / 1e3:.3g} kN)",
                 pad=16)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    return save_figure(fig, path)
