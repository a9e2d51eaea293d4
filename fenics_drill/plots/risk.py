"""The figure of torque and drag under uncertainty (``risk.png``): the P10-P90 envelopes and the P50 of the indicated
hook load and of the surface torque of each operation against bit depth, the rig's limits, the probabilities of
exceeding them and of helical buckling while slacking off, and the distribution of the lock-up depth while sliding."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fenics_drill.plots.broomstick import COLOURS
from fenics_drill.plots.common import save_figure
from fenics_drill.plots.well import LABELS


def risk_figures(directory: Path) -> list[Path]:
    import xarray

    risk = xarray.load_dataset(directory / "risk.nc", engine="h5netcdf")
    return [risk_figure(risk, directory / "risk.png")]


def risk_figure(risk, path: Path) -> Path:
    fig, axes = plt.subplots(1, 4, figsize=(17, 8), gridspec_kw={"width_ratios": [3, 3, 2, 2]})
    load_ax, torque_ax, chance_ax, lock_ax = axes
    depth = risk["depth"].values
    for j, name in enumerate(risk["operation"].values):
        colour, label = COLOURS.get(str(name), "k"), LABELS.get(str(name), str(name))
        for ax, variable in ((load_ax, "hook_load"), (torque_ax, "surface_torque")):
            if variable == "surface_torque" and str(name) not in ("rotating_off_bottom", "rotating_on_bottom",
                                                                  "sliding"):
                continue
            low, median, high = (risk[variable].values[q, :, j] / 1e3 for q in range(3))
            ax.fill_betweenx(depth, low, high, color=colour, alpha=0.25, lw=0)
            ax.plot(median, depth, color=colour, lw=1.5, label=f"{label} (P50, P10-P90)")
    for ax, key, unit in ((load_ax, "hook_load_limit_N", "rig hook-load limit"),
                          (torque_ax, "torque_limit_Nm", "rig torque limit")):
        if risk.attrs.get(key, -1.0) > 0:
            ax.axvline(risk.attrs[key] / 1e3, color="crimson", lw=2, label=unit)
    for variable, style, label in (("probability_over_hook_load_limit", "-", "hook load over the limit"),
                                   ("probability_over_torque_limit", "--", "torque over the limit")):
        values = risk[variable].values
        if np.isfinite(values).any():  # NaN: the rig states no such limit
            chance_ax.plot(np.max(values, axis=1), depth, color="crimson", ls=style, label=label)
    chance_ax.plot(risk["probability_helical_slack_off"].values, depth, color="k", label="helical buckling, slack-off")
    lock = risk["lock_up_depth_sliding"].values
    found = lock[np.isfinite(lock)]
    if found.size:
        lock_ax.hist(found, bins=min(30, max(5, found.size // 10)), orientation="horizontal", color="tab:orange")
    lock_ax.set_title(f"sliding lock-up depth\n{np.mean(~np.isfinite(lock)):.0%} reach the bottom", fontsize=9)
    load_ax.set_xlabel("indicated hook load [kN]")
    torque_ax.set_xlabel("surface torque [kN m]")
    chance_ax.set_xlabel("probability [-]")
    chance_ax.set_xlim(-0.02, 1.02)
    lock_ax.set_xlabel("realisations")
    load_ax.set_ylabel("bit depth (measured) [m]")
    for ax in axes:
        ax.set_ylim(depth.max() * 1.02, 0.0)
        ax.grid(alpha=0.3)
    for ax in axes[:3]:
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="lower left")
    fig.suptitle(f"Torque and drag under uncertainty: {risk.attrs.get('samples', lock.size)} realisations")
    return save_figure(fig, path)
