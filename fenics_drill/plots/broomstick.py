"""The broomstick chart (``broomstick.png``): the indicated hook load against bit depth for each operation and
friction pair, with the minimum weight to helical buckling, the maximum weight for yield and the rig's hook-load
limit, and the surface torque beside it with the rig's torque limit; depth runs down the page, as the industry draws
it.  Measured points (a calibration's) are drawn on top, and calibrated curves as heavier lines."""

from __future__ import annotations

from pathlib import Path

import warnings

import matplotlib.pyplot as plt
import numpy as np

from fenics_drill.plots.common import save_figure
from fenics_drill.plots.well import LABELS

#: The colour of each operation on both panels.
COLOURS = {"tripping_in": "tab:blue", "tripping_out": "tab:red", "rotating_off_bottom": "tab:green",
           "rotating_on_bottom": "tab:purple", "sliding": "tab:orange"}
#: The measured columns and the operation whose curve each lies on: (panel, operation).
MEASURED = {"pick_up": (0, "tripping_out"), "slack_off": (0, "tripping_in"),
            "rotating_off_bottom": (0, "rotating_off_bottom"), "torque_off_bottom": (1, "rotating_off_bottom"),
            "torque_on_bottom": (1, "rotating_on_bottom")}


def broomstick_figure(chart, path: Path, measured: dict | None = None, calibrated=None, title: str = "") -> Path:
    """``chart``: a broomstick dataset (:func:`~fenics_drill.studies.broomstick.broomstick_study`); ``measured``:
    ``bit_depth`` [m] and any of :data:`MEASURED` [N, N m] as arrays (NaN: not measured); ``calibrated``: a chart of
    the calibrated friction pair, drawn heavier."""
    fig, (load_ax, torque_ax) = plt.subplots(1, 2, figsize=(13, 8), sharey=True)
    depth = chart["depth"].values
    pairs = chart["pair"].values
    for j, name in enumerate(chart["operation"].values):
        colour = COLOURS.get(str(name), "k")
        for p in pairs:
            alpha = 0.25 + 0.6 * (p + 1) / len(pairs)
            label = LABELS.get(str(name), str(name)) if p == pairs[-1] else None
            load_ax.plot(chart["hook_load"].values[:, j, p] / 1e3, depth, color=colour, lw=0.8, alpha=alpha,
                         label=label)
            if str(name) in ("rotating_off_bottom", "rotating_on_bottom", "sliding"):
                torque_ax.plot(chart["surface_torque"].values[:, j, p] / 1e3, depth, color=colour, lw=0.8,
                               alpha=alpha, label=label)
    with warnings.catch_warnings():  # a depth where no pair buckles: NaN, no line there
        warnings.simplefilter("ignore", RuntimeWarning)
        helical = np.nanmax(chart["helical_buckling_hook_load"].values, axis=1)
    load_ax.plot(helical / 1e3, depth, "k--", lw=1.2, label="minimum weight to helical buckling")
    load_ax.plot(np.nanmin(chart["yield_hook_load"].values, axis=1) / 1e3, depth, "k:", lw=1.2,
                 label="maximum weight for yield")
    limits = chart.attrs
    if limits.get("hook_load_limit_N", -1.0) > 0:
        load_ax.axvline(limits["hook_load_limit_N"] / 1e3, color="crimson", lw=2, label="rig hook-load limit")
    if limits.get("torque_limit_Nm", -1.0) > 0:
        torque_ax.axvline(limits["torque_limit_Nm"] / 1e3, color="crimson", lw=2, label="rig torque limit")
    if calibrated is not None:
        for j, name in enumerate(calibrated["operation"].values):
            colour = COLOURS.get(str(name), "k")
            load_ax.plot(calibrated["hook_load"].values[:, j, 0] / 1e3, calibrated["depth"].values, color=colour,
                         lw=2.5)
            if str(name) in ("rotating_off_bottom", "rotating_on_bottom"):
                torque_ax.plot(calibrated["surface_torque"].values[:, j, 0] / 1e3, calibrated["depth"].values,
                               color=colour, lw=2.5)
    for column, (panel, operation) in MEASURED.items():
        if measured is not None and column in measured:
            ax = (load_ax, torque_ax)[panel]
            values = np.asarray(measured[column], dtype=float)
            ax.plot(values / 1e3, measured["bit_depth"], "o", ms=5, mfc="white", mec=COLOURS[operation], mew=1.5,
                    label=f"measured {column.replace('_', ' ')}")
    friction = chart["friction_cased"].values, chart["friction_open"].values
    load_ax.set_title(f"friction factors: cased {friction[0].min():g}-{friction[0].max():g}, open "
                      f"{friction[1].min():g}-{friction[1].max():g} (lighter lines: lower factors)", fontsize=9)
    block = limits.get("block_weight_N", 0.0)
    load_ax.set_xlabel(f"indicated hook load [kN]{f' (block {block / 1e3:.4g} kN included)' if block else ''}")
    torque_ax.set_xlabel("surface torque [kN m]")
    load_ax.set_ylabel("bit depth (measured) [m]")
    load_ax.invert_yaxis()
    # the operations' loads and the rig's limits fill the axes; the yield line shows where it comes near them
    loads = np.nanmax(chart["hook_load"].values) / 1e3
    load_ax.set_xlim(0.0, 1.15 * max(loads, limits.get("hook_load_limit_N", -1.0) / 1e3))
    torques = np.nanmax(chart["surface_torque"].values) / 1e3
    torque_ax.set_xlim(0.0, 1.15 * max(torques, limits.get("torque_limit_Nm", -1.0) / 1e3))
    for ax in (load_ax, torque_ax):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")  # a fixed place: "best" weighs every line of the chart
    fig.suptitle(title or "Broomstick chart")
    return save_figure(fig, path)


def broomstick_figures(directory: Path) -> list[Path]:
    """The chart of a ``broomstick`` directory (``broomstick.png``), or of a ``calibrate`` one with its measured
    points and calibrated curves and the friction factors back-calculated at each point (``calibration.png``,
    ``friction_track.png``)."""
    import xarray

    chart = xarray.load_dataset(directory / "broomstick.nc", engine="h5netcdf")
    if not (directory / "calibration.json").exists():
        return [broomstick_figure(chart, directory / "broomstick.png")]
    from fenics_drill.io.files import read_json

    report = read_json(directory / "calibration.json")
    calibrated = xarray.load_dataset(directory / "calibrated.nc", engine="h5netcdf")
    measured = {name: np.array([np.nan if v is None else v for v in values], dtype=float)
                for name, values in report["measured"].items()}
    fit = "calibrated: " + ", ".join(f"{name} {report[f'friction_{name}']['value']:.3f}" for name in ("cased", "open")
                                     if report[f"friction_{name}"]["value"] is not None)
    return [broomstick_figure(chart, directory / "calibration.png", measured, calibrated, title=fit),
            track_figure(report, directory / "friction_track.png")]


def track_figure(report: dict, path: Path) -> Path:
    """The friction factor back-calculated at each measured point, per column, against bit depth (down the page),
    with the calibrated factors as lines."""
    fig, ax = plt.subplots(figsize=(6, 8))
    depth = np.array(report["measured"]["bit_depth"], dtype=float)
    for column, values in report["back_calculated"].items():
        operation = MEASURED[column][1]
        ax.plot(np.array([np.nan if v is None else v for v in values], dtype=float), depth, "o-", ms=4, lw=0.8,
                color=COLOURS[operation], label=column.replace("_", " "))
    for name, style in (("friction_cased", "--"), ("friction_open", "-")):
        value = report[name]["value"]
        if value is not None:
            ax.axvline(value, color="k", ls=style, lw=1, label=f"{name.replace('_', ' ')} {value:.3f}")
    shoe = report.get("casing_shoe_m")
    if shoe:
        ax.axhline(shoe, color="0.5", lw=1, label=f"casing shoe {shoe:.0f} m")
    ax.set_xlabel("friction factor back-calculated [-]")
    ax.set_ylabel("bit depth (measured) [m]")
    ax.invert_yaxis()
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path)
