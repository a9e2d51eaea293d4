"""Pictures of the string in the borehole from a run's ``fields.h5`` (Figs. 13 and 20, and an animation).

* Fig. 13 / 3D views (PyVista, off-screen): the string as a tube of radius R_ext inside
  the translucent borehole, cut by the plane y = 0 as in Fig. 20, coloured by the
  von Mises stress (or the lateral displacement when the run recorded no stress).
  The lateral scale is true; the axial axis is compressed (AXIAL_DIAMETERS borehole
  diameters for the whole length, said in the title) or nothing could be seen.
* Fig. 20 (Matplotlib): for several instants, the string in the plane y = 0 between
  the borehole walls, and its cross-sections at x = 0, L/2 and L inside the borehole.
* ``animation.gif``: the 3D view at every field snapshot.

The XDMF (``fields.xdmf``) opens in ParaView with the same fields.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fenics_drill.io.fields import FieldSnapshots
from fenics_drill.io.timeseries import read_series
from fenics_drill.plots.common import plt, save_figure

#: The whole string is drawn this many borehole diameters long.
AXIAL_DIAMETERS = 20.0


def _geometry(run_dir: Path) -> dict:
    scene = read_series(run_dir / "timeseries.h5")[1]["scene"]
    return {"L": scene.beam.length, "R": scene.beam.outer_radius, "R_bh": scene.borehole.radius}


def _tube_scene(plotter, snap: FieldSnapshots, k: int, geo: dict, clim=None):
    """Add the borehole (cut at y = 0) and the string at snapshot k to a PyVista plotter."""
    import pyvista as pv

    scale = AXIAL_DIAMETERS * 2 * geo["R_bh"] / geo["L"]
    x = snap.x * scale
    points = np.column_stack([x + snap.fields["u"][k] * scale, snap.fields["v"][k], snap.fields["w"][k]])
    line = pv.lines_from_points(points)
    stress = snap.vertex_stress(k)
    if stress is not None:
        line["von Mises [MPa]"] = stress / 1e6
        label = "von Mises [MPa]"
    else:
        line["lateral displacement [mm]"] = 1e3 * np.hypot(snap.fields["v"][k], snap.fields["w"][k])
        label = "lateral displacement [mm]"
    tube = line.tube(radius=geo["R"], n_sides=24)
    plotter.add_mesh(tube, scalars=label, cmap="viridis", clim=clim,
                     scalar_bar_args={"title": label, "position_x": 0.3, "position_y": 0.03, "width": 0.4})
    bore = pv.Cylinder(center=(x[-1] / 2, 0, 0), direction=(1, 0, 0), radius=geo["R_bh"], height=x[-1],
                       resolution=64, capping=False).clip(normal="y", origin=(0, 0, 0))
    plotter.add_mesh(bore, color="sienna", opacity=0.35)
    plotter.view_vector((-0.35, -1.0, 0.6), viewup=(0, 0, 1))
    plotter.reset_camera()
    plotter.camera.zoom(1.6)


def off_screen_plotter(window_size):
    """An off-screen PyVista plotter; VTK's complaint about the missing X display is silenced."""
    import pyvista as pv

    pv.vtk_verbosity("off")
    return pv.Plotter(off_screen=True, window_size=window_size)


def picture_3d(snap: FieldSnapshots, k: int, geo: dict, path: Path, title: str) -> Path:
    plotter = off_screen_plotter((1400, 600))
    _tube_scene(plotter, snap, k, geo)
    plotter.add_text(f"{title}\n(axial axis compressed to {AXIAL_DIAMETERS:g} borehole diameters)", font_size=10)
    plotter.screenshot(str(path))
    plotter.close()
    return path


def animation(snap: FieldSnapshots, geo: dict, path: Path) -> Path:
    """The 3D view at every snapshot, as a GIF (colour scale fixed over the run)."""
    clim = None
    if "von_mises" in snap.cell_fields:
        clim = (0.0, float(snap.cell_fields["von_mises"].max()) / 1e6)
    plotter = off_screen_plotter((1000, 450))
    plotter.open_gif(str(path), fps=10)
    for k, t in enumerate(snap.times):
        plotter.clear()
        _tube_scene(plotter, snap, k, geo, clim)
        plotter.add_text(f"t = {t:.2f} s", font_size=12)
        plotter.write_frame()
    plotter.close()
    return path


def sections_figure(snap: FieldSnapshots, geo: dict, path: Path, instants: int = 4) -> Path:
    """Fig. 20: the string in the plane y = 0 and its sections at x = 0, L/2, L, for a few instants."""
    picks = np.unique(np.linspace(0, len(snap.times) - 1, instants).round().astype(int))
    fig, axes = plt.subplots(len(picks), 4, figsize=(12, 2.4 * len(picks)),
                             gridspec_kw={"width_ratios": [3, 1, 1, 1]}, squeeze=False)
    gap_mm = (geo["R_bh"] - geo["R"]) * 1e3
    theta = np.linspace(0, 2 * np.pi, 100)
    for row, k in zip(axes, picks):
        side = row[0]
        side.plot(snap.x, snap.fields["w"][k] * 1e3, lw=1)
        for s in (-1, 1):
            side.axhline(s * gap_mm, color="k", lw=0.8)
        side.set(xlim=(0, geo["L"]), ylabel="w at y = 0 [mm]", title=f"t = {snap.times[k]:.2f} s")
        side.grid(alpha=0.3)
        for ax, x_cut in zip(row[1:], (0.0, 0.5 * geo["L"], geo["L"])):
            i = int(np.argmin(np.abs(snap.x - x_cut)))
            v, w = snap.fields["v"][k][i] * 1e3, snap.fields["w"][k][i] * 1e3
            ax.fill(geo["R_bh"] * 1e3 * np.cos(theta), geo["R_bh"] * 1e3 * np.sin(theta), color="tan", alpha=0.3)
            ax.fill(v + geo["R"] * 1e3 * np.cos(theta), w + geo["R"] * 1e3 * np.sin(theta), color="C0")
            ax.set(aspect="equal", title=f"x = {snap.x[i]:g} m", xlabel="y [mm]", ylabel="z [mm]")
    axes[-1][0].set_xlabel("x [m]")
    fig.suptitle("Fig. 20: the string in the borehole (plane y = 0, and sections x = 0, L/2, L)")
    return save_figure(fig, path)


def make_pictures(run_dir: Path, gif: bool = True) -> list[Path]:
    """Fig. 13 (static state, t = 0), 3D views at the instants of Fig. 20, Fig. 20, and the GIF."""
    if not (run_dir / "fields.h5").exists():
        return []
    snap = FieldSnapshots(run_dir / "fields.h5")
    geo = _geometry(run_dir)
    paths = [picture_3d(snap, 0, geo, run_dir / "fig13_static_3d.png", "Fig. 13: static equilibrium (t = 0)")]
    k = int(np.argmax(snap.cell_fields["von_mises"].max(axis=1))) if "von_mises" in snap.cell_fields \
        else len(snap.times) - 1
    paths.append(picture_3d(snap, k, geo, run_dir / "fig20_3d.png",
                            f"t = {snap.times[k]:.2f} s (largest von Mises stress of the snapshots)"))
    paths.append(sections_figure(snap, geo, run_dir / "fig20_sections.png"))
    if gif and len(snap.times) > 1:
        paths.append(animation(snap, geo, run_dir / "animation.gif"))
    return paths
