"""Figures of a torque-and-drag study: the loads along the string for each operation (``well_loads.png``), the
well's path with the string's buckled lengths (``well_path.png``), and the string in 3D coloured by its wall contact
force (``well_3d.png``); and of the FE static state on a well (``static_loads.png``)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fenics_drill.io.files import read_json
from fenics_drill.plots.common import save_figure
from fenics_drill.plots.pictures import off_screen_plotter

LABELS = {"rotating_on_bottom": "rotating on bottom", "rotating_off_bottom": "rotating off bottom",
          "sliding": "sliding", "tripping_in": "tripping in", "tripping_out": "tripping out"}


def well_figures(directory: Path) -> list[Path]:
    import xarray

    report = read_json(directory / "torque_drag.json")
    profiles = xarray.load_dataset(directory / "torque_drag.h5", engine="h5netcdf")
    return [loads_figure(report, profiles, directory / "well_loads.png"),
            path_figure(report, profiles, directory / "well_path.png"),
            picture_3d(report, profiles, directory / "well_3d.png")]


def loads_figure(report: dict, profiles, path: Path) -> Path:
    """Effective tension (with the buckling loads as compression limits), torque and wall force along the string;
    the measured depth runs down the page."""
    fig, axes = plt.subplots(1, 3, figsize=(13, 7), sharey=True)
    md, md_e = profiles["md"].values, profiles["md_element"].values
    for name in report["operations"]:
        label = LABELS.get(name, name)
        line, = axes[0].plot(profiles[f"tension_{name}"].values / 1e3, md, label=label)
        axes[1].plot(profiles[f"torque_{name}"].values / 1e3, md, color=line.get_color())
        axes[2].step(profiles[f"wall_force_per_length_{name}"].values, md_e, where="mid", color=line.get_color(),
                     lw=1)
    _tension_axes(axes, profiles)
    lowest = min(float(profiles[f"tension_{n}"].min()) for n in report["operations"])
    axes[0].set_xlim(left=min(1.5 * lowest, -1.0) / 1e3)
    axes[1].set_xlabel("torque [kN m]")
    axes[2].set_xlabel("wall contact force [N/m]")
    fig.suptitle(f"Soft-string torque and drag: {report['well']['measured_depth_m']:.0f} m well, "
                 f"{report['string']['length_m']:.0f} m string")
    return save_figure(fig, path)


def _tension_axes(axes, profiles) -> None:
    """The buckling loads as compression limits on the tension axes (the first), measured depth down the page."""
    md_e = profiles["md_element"].values
    axes[0].plot(-profiles["sinusoidal_buckling_load"].values / 1e3, md_e, "k--", lw=1, label="sinusoidal buckling")
    axes[0].plot(-profiles["helical_buckling_load"].values / 1e3, md_e, "k:", lw=1, label="helical buckling")
    axes[0].set_xlabel("effective tension [kN]")
    axes[0].set_ylabel("measured depth [m]")
    axes[0].invert_yaxis()
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="lower left")


def static_loads_figure(directory: Path) -> Path:
    """The FE static state along its well (``static_profiles.h5``): its effective tension against the soft string's
    in the same operation and the buckling loads as compression limits, its torque, and the wall's force per
    length."""
    import xarray

    profiles = xarray.load_dataset(directory / "static_profiles.h5", engine="h5netcdf")
    md, md_e = profiles["md"].values, profiles["md_element"].values
    fig, axes = plt.subplots(1, 2, figsize=(10, 7), sharey=True)
    axes[0].plot(profiles["axial_force"].values / 1e3, md_e, label="FE static state")
    operation = profiles.attrs.get("soft_string_operation", "rotating_off_bottom")
    axes[0].plot(profiles["soft_string_tension"].values / 1e3, md, "--", label=f"soft string, {LABELS[operation]}")
    axes[1].plot(profiles["wall_force_per_length"].values, md, lw=0.5, color="0.7", label="at the vertices")
    if "wall_force_per_length_smoothed" in profiles:
        axes[1].plot(profiles["wall_force_per_length_smoothed"].values, md, lw=1.2, color="tab:blue",
                     label="over 10 m (about a joint of pipe)")
        axes[1].legend(fontsize=8, loc="lower right")
    _tension_axes(axes, profiles)
    lowest = float(min(profiles["axial_force"].min(), profiles["soft_string_tension"].min()))
    highest = float(max(profiles["axial_force"].max(), profiles["soft_string_tension"].max()))
    axes[0].set_xlim(min(1.5 * lowest, -0.2 * highest) / 1e3, 1.1 * max(highest, 1.0) / 1e3)
    axes[1].set_xlabel("wall contact force per length [N/m]")
    fig.suptitle("The FE string at rest in its well")
    return save_figure(fig, directory / "static_loads.png")


def path_figure(report: dict, profiles, path: Path) -> Path:
    """Vertical section (true vertical depth against the horizontal distance along the well's final azimuth), plan
    view, and inclination along the string; where the string buckles in the operation that compresses it most,
    in colour."""
    north, east, tvd = (profiles[k].values for k in ("north", "east", "tvd"))
    md_e = profiles["md_element"].values
    end = np.array([north[-1], east[-1]])
    direction = end / np.linalg.norm(end) if np.linalg.norm(end) > 0 else np.array([1.0, 0.0])
    along = north * direction[0] + east * direction[1]
    worst = max(report["operations"], key=lambda n: report["operations"][n]["max_compression_N"])
    state = profiles[f"buckling_{worst}"].values
    fig, axes = plt.subplots(1, 3, figsize=(14, 5))
    axes[0].plot(along, tvd, "0.5", lw=2)
    axes[0].invert_yaxis()
    axes[0].set_xlabel("horizontal distance [m]")
    axes[0].set_ylabel("true vertical depth [m]")
    axes[0].set_title("vertical section")
    axes[1].plot(east, north, "0.5", lw=2)
    axes[1].set_xlabel("east [m]")
    axes[1].set_ylabel("north [m]")
    axes[1].set_title("plan view")
    axes[1].set_aspect("equal", adjustable="datalim")
    axes[2].plot(md_e, profiles["inclination_deg"].values, "0.5")
    axes[2].set_xlabel("measured depth [m]")
    axes[2].set_ylabel("inclination [deg]")
    for level, colour, text in ((1, "tab:orange", "sinusoidally buckled"), (2, "tab:red", "helically buckled")):
        at = state == level
        if at.any():
            middle = lambda a: 0.5 * (a[1:] + a[:-1])  # noqa: E731
            axes[0].plot(middle(along)[at], middle(tvd)[at], ".", color=colour, ms=3,
                         label=f"{text} ({LABELS.get(worst, worst)})")
            axes[2].plot(md_e[at], profiles["inclination_deg"].values[at], ".", color=colour, ms=3)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    return save_figure(fig, path)


def picture_3d(report: dict, profiles, path: Path) -> Path:
    """The string along the well in 3D (PyVista, off screen), coloured by the wall contact force per length of the
    first operation; the tube's radius is exaggerated to be seen at the well's scale."""
    import pyvista as pv

    name = next(iter(report["operations"]))
    points = np.column_stack([profiles["north"].values, profiles["east"].values, -profiles["tvd"].values])
    force = profiles[f"wall_force_per_length_{name}"].values
    line = pv.lines_from_points(points)
    label = "wall force [N/m]"
    line[label] = np.concatenate([[force[0]], 0.5 * (force[1:] + force[:-1]), [force[-1]]])
    extent = float(np.ptp(points, axis=0).max())
    plotter = off_screen_plotter((1200, 900))
    plotter.add_mesh(line.tube(radius=0.006 * extent, n_sides=16), scalars=label, cmap="plasma",
                     scalar_bar_args={"title": label, "vertical": True, "position_x": 0.74, "position_y": 0.25, "fmt": "%.0f",
                                      "height": 0.5, "title_font_size": 14, "label_font_size": 12})
    plotter.add_mesh(pv.Plane(center=(points[:, 0].mean(), points[:, 1].mean(), 0.0), i_size=1.2 * extent,
                              j_size=1.2 * extent), color="tan", opacity=0.3)
    plotter.show_grid(xtitle="north [m]", ytitle="east [m]", ztitle="up [m]")
    plotter.view_vector((1.0, -1.2, 0.6), viewup=(0, 0, 1))
    plotter.add_text(f"{report['well']['measured_depth_m']:.0f} m well, wall force {LABELS.get(name, name)} "
                     "(tube radius exaggerated)", font_size=10)
    plotter.screenshot(str(path))
    plotter.close()
    return path
