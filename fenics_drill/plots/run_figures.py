"""Figures of a saved run (``fenics-drill plot DIR``): everything a person looks at after a run.

timeseries.h5 -> Fig. 14 bit displacement and velocity, Fig. 15 bit rotation and
angular velocity, Fig. 16 transverse displacement and velocity at the section,
Fig. 17 radial displacement at the section against the gap, Fig. 18 impacts against
time, Fig. 19 impacts per vertex, the hook load and surface torque (surface_loads.png), Figs. 21-23 power spectral densities and
spectra.json (Section 6.8 peaks with the nearest natural frequencies); fields.h5 ->
Figs. 13 and 20 and animation.gif (:mod:`fenics_drill.plots.pictures`).  Units are
converted here, at the plotting edge only (mm, m/h, rev, rpm as in the paper).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fenics_drill.io.files import write_json
from fenics_drill.io.timeseries import read_modes, read_series
from fenics_drill.observables.spectra import run_spectra
from fenics_drill.io.fields import FieldSnapshots
from fenics_drill.plots.common import M_PER_S_TO_M_PER_H, RAD_PER_S_TO_RPM, panels, plt, save_figure
from fenics_drill.plots.pictures import make_pictures


def _time_pair(path, t, top, bottom, labels, title) -> Path:
    fig, (a, b) = panels(2)
    a.plot(t, top, lw=0.8)
    b.plot(t, bottom, lw=0.6)
    a.set_ylabel(labels[0])
    b.set_ylabel(labels[1])
    b.set_xlabel("time [s]")
    a.set_title(title)
    return save_figure(fig, path)


def time_series_figures(data: dict, attrs: dict, out: Path) -> list[Path]:
    """Figs. 14-19 from the variables of timeseries.h5."""
    t, x_s, gap = data["time"], float(attrs["section_x"]), float(attrs.get("gap", np.nan))
    paths = [
        _time_pair(out / "fig14_bit_axial.png", t, data["bit_displacement"] * 1e3,
                   data["bit_velocity"] * M_PER_S_TO_M_PER_H, ("bit displacement [mm]", "bit velocity [m/h]"),
                   "Fig. 14: drill-bit axial motion"),
        _time_pair(out / "fig15_bit_rotation.png", t, data["bit_rotation"] / (2 * np.pi),
                   data["bit_angular_velocity"] * RAD_PER_S_TO_RPM, ("bit rotation [rev]", "bit angular velocity [rpm]"),
                   "Fig. 15: drill-bit rotation"),
        _time_pair(out / "fig16_section_lateral.png", t, data["section_w"] * 1e3, data["section_w_velocity"],
                   ("w [mm]", "w velocity [m/s]"), f"Fig. 16: transverse motion in z at x = {x_s:g} m"),
    ]
    fig, (ax,) = panels(1, 3.5)
    ax.plot(t, np.hypot(data["section_v"], data["section_w"]) * 1e3, lw=0.8, label="radial displacement")
    if np.isfinite(gap):
        ax.axhline(gap * 1e3, color="k", ls="--", lw=1, label="borehole gap")
    ax.set(xlabel="time [s]", ylabel="radial displacement [mm]", title=f"Fig. 17: radial displacement at x = {x_s:g} m")
    ax.legend(loc="lower right")
    paths.append(save_figure(fig, out / "fig17_section_radial.png"))
    path18 = _time_pair(out / "fig18_impacts_time.png", t, data["impacts"], data["vertices_in_contact"],
                        ("impacts per step [-]", "vertices in contact [-]"), "Fig. 18: wall impacts against time")
    fig, (ax,) = panels(1, 3.5)
    x, per_vertex = data["vertex_x"], data["impacts_per_vertex"]
    ax.bar(x, per_vertex, width=x[1] - x[0])
    ax.set(xlabel="x [m]", ylabel="impacts [-]", title="Fig. 19: wall impacts per vertex", xlim=(x[0], x[-1]),
           ylim=(0, max(1.0, 1.05 * float(np.max(per_vertex)))))
    if not np.any(per_vertex):
        ax.text(0.5, 0.5, "no impact in this run", transform=ax.transAxes, ha="center", va="center", color="0.4")
    paths += [path18, save_figure(fig, out / "fig19_impacts_position.png")]
    if "lambda_1" in data and "lambda_4" in data:  # the drive's multipliers: lambda_1 the hook load, -lambda_4 the torque
        paths.append(_time_pair(out / "surface_loads.png", t, data["lambda_1"] / 1e3, -data["lambda_4"] / 1e3,
                                ("hook load [kN]", "surface torque [kN m]"), "The drive's loads at the surface"))
    return paths


def orbit_figure(data: dict, attrs: dict, path: Path) -> Path:
    """The recorded section's centre in the hole, coloured by time, with the wall the centre reaches (the gap
    circle), as seen from the top looking towards the bit."""
    gap, x_s = float(attrs.get("gap", np.nan)), float(attrs["section_x"])
    fig, ax = plt.subplots(figsize=(6, 5.4))
    points = ax.scatter(data["section_v"] * 1e3, data["section_w"] * 1e3, c=data["time"], s=2, cmap="viridis",
                        linewidths=0)
    if np.isfinite(gap):
        angle = np.linspace(0, 2 * np.pi, 361)
        ax.plot(gap * 1e3 * np.cos(angle), gap * 1e3 * np.sin(angle), "k-", lw=1, label="wall (centre at the gap)")
        ax.legend(loc="upper right", fontsize=8)
        ax.set_xlim(-1.15 * gap * 1e3, 1.15 * gap * 1e3)
        ax.set_ylim(-1.15 * gap * 1e3, 1.15 * gap * 1e3)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set(xlabel="v, horizontal [mm]", ylabel="w, vertical [mm]", title=f"Orbit of the section at x = {x_s:g} m")
    fig.colorbar(points, ax=ax, label="time [s]")
    return save_figure(fig, path)


def torque_drag_figure(snapshots: FieldSnapshots, path: Path) -> Path | None:
    """Axial force, torque and the wall's normal force per length along the string, as torque-and-drag plots show
    them: the last snapshot, the mean over the second half of the snapshots and their range.  None if the field
    file holds no profiles (a run of an older version)."""
    cells, points = snapshots.cell_fields, snapshots.fields
    if "axial_force" not in cells or "torque" not in cells:
        return None
    x_mid = 0.5 * (snapshots.x[1:] + snapshots.x[:-1])
    late = snapshots.times >= 0.5 * snapshots.times[-1]
    panels_ = [(x_mid, cells["axial_force"] / 1e3, "axial force [kN] (tension +)"),
               (x_mid, cells["torque"] / 1e3, "torque [kN m] (the drive's sense +)")]
    if "wall_normal_force_per_length" in points:
        panels_.append((snapshots.x, points["wall_normal_force_per_length"] / 1e3, "wall normal force [kN/m]"))
    fig, axes = panels(len(panels_), 2.6)
    for ax, (x, values, label) in zip(axes, panels_):
        ax.fill_between(x, values[late].min(axis=0), values[late].max(axis=0), color="tab:blue", alpha=0.2,
                        lw=0, label="range, second half")
        ax.plot(x, values[late].mean(axis=0), color="tab:blue", lw=1.2, label="mean, second half")
        ax.plot(x, values[-1], color="k", lw=0.8, ls="--", label=f"t = {snapshots.times[-1]:.3g} s")
        ax.set_ylabel(label)
    axes[0].legend(fontsize=8, loc="best")
    axes[-1].set_xlabel("x along the string (0: the drive, L: the bit) [m]")
    axes[0].set_title("Torque and drag along the string")
    return save_figure(fig, path)


def _peak_label(peak: dict) -> str:
    """A peak and the nearest modes: of the free string and, if known, of the string held by the drive."""
    text = f"{peak['frequency_hz']:.2f} Hz (nearest mode: {peak['mode_kind']} {peak['mode_frequency_hz']:.2f} Hz"
    if "held_mode_kind" in peak:
        text += f"; held by the drive: {peak['held_mode_kind']} {peak['held_mode_frequency_hz']:.2f} Hz"
    return text + ")"


def spectra_figures(spectra: dict, out: Path) -> list[Path]:
    """Figs. 21-23: raw periodogram (magenta) and Savitzky-Golay smoothed PSD (blue), peaks marked."""
    paths = []
    for figure in sorted({s["figure"] for s in spectra.values()}):
        names = [n for n, s in spectra.items() if s["figure"] == figure]
        fig, axes = panels(len(names))
        for ax, name in zip(axes, names):
            s = spectra[name]
            ax.plot(s["frequency_hz"], s["psd_db"], color="m", lw=0.4, label="periodogram")
            ax.plot(s["frequency_hz"], s["smoothed_db"], color="b", lw=1.0, label="Savitzky-Golay")
            found = s["peaks"]
            if found:
                ax.plot([p["frequency_hz"] for p in found], [p["psd_db"] for p in found], "kv", ms=5)
                text = "\n".join(_peak_label(p) for p in found)
                ax.text(0.99, 0.96, text, transform=ax.transAxes, ha="right", va="top", fontsize=7,
                        bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
            visible = s["smoothed_db"][s["frequency_hz"] > 1.0]
            if visible.size and np.ptp(visible) > 0:
                ax.set_ylim(np.percentile(visible, 1) - 10, visible.max() + 15)
            ax.set(ylabel=f"PSD [dB/Hz]\nref. 1 {s['psd_unit']}", title=s["label"])
            ax.legend(loc="lower left", fontsize=7)
        axes[-1].set_xlabel("frequency [Hz]")
        fig.suptitle(f"Fig. {figure}: power spectral density")
        paths.append(save_figure(fig, out / f"fig{figure}_psd.png"))
    return paths


def spectra_json(spectra: dict) -> dict:
    """The peaks (and the grid) of each spectrum, for spectra.json."""
    return {name: {"label": s["label"], "psd_unit": s["psd_unit"], "figure": s["figure"],
                   "frequency_resolution_hz": float(s["frequency_hz"][1] - s["frequency_hz"][0]),
                   "nyquist_hz": float(s["frequency_hz"][-1]), "peaks": s["peaks"]}
            for name, s in spectra.items()}


def run_spectra_of(run_dir: Path) -> dict:
    """Spectra of a saved run, peaks named by the modes stored with it."""
    data, _ = read_series(run_dir / "timeseries.h5")
    path = run_dir / "timeseries.h5"
    return run_spectra(data, *read_modes(path), held_modes=read_modes(path, "modes_drive_held"))


def plot_run(run_dir: Path, gif: bool = True) -> list[Path]:
    """Every figure of a run directory; returns the files written."""
    data, attrs = read_series(run_dir / "timeseries.h5")
    paths = time_series_figures(data, attrs, run_dir)
    paths.append(orbit_figure(data, attrs, run_dir / "fig16b_orbit.png"))
    if (run_dir / "fields.h5").exists():
        profiles = torque_drag_figure(FieldSnapshots(run_dir / "fields.h5"), run_dir / "torque_drag.png")
        if profiles is not None:
            paths.append(profiles)
    spectra = run_spectra_of(run_dir)
    paths += spectra_figures(spectra, run_dir)
    write_json(run_dir / "spectra.json", spectra_json(spectra))
    paths.append(run_dir / "spectra.json")
    return paths + make_pictures(run_dir, gif)
