"""The figure of a stick-slip map (``stick_slip_map.png``): for each rotary drive, the severity of the bit's
stick-slip, the share of time it is stuck, the rate of penetration and the mechanical specific energy over weight on
bit x rotation speed, the points whose cycle did not settle within the time limit hatched."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from fenics_drill.plots.common import save_figure

#: (variable, title, scale to the unit shown, colour map) of each column.
PANELS = (("severity", "stick-slip severity (max - min) / (2 mean) of the bit's spin", 1.0, "magma_r"),
          ("stuck_share", "share of time the bit is stuck", 1.0, "magma_r"),
          ("rop_m_s", "rate of penetration [m/h]", 3600.0, "viridis"),
          ("mechanical_specific_energy_Pa", "mechanical specific energy [MPa]", 1e-6, "viridis_r"))


def stick_slip_map_figures(directory: Path) -> list[Path]:
    import xarray

    grid = xarray.load_dataset(directory / "map.nc", engine="h5netcdf")
    return [stick_slip_map_figure(grid, directory / "stick_slip_map.png")]


def _edges(values: np.ndarray) -> np.ndarray:
    if values.size == 1:
        return np.array([values[0] * 0.95, values[0] * 1.05]) if values[0] else np.array([-0.5, 0.5])
    middle = 0.5 * (values[1:] + values[:-1])
    return np.concatenate([[2 * values[0] - middle[0]], middle, [2 * values[-1] - middle[-1]]])


def stick_slip_map_figure(grid, path: Path) -> Path:
    controllers = [str(c) for c in grid["controller"].values]
    fig, axes = plt.subplots(len(controllers), len(PANELS), figsize=(4.6 * len(PANELS), 3.9 * len(controllers)),
                             squeeze=False)
    rpm = grid["rotation_speed"].values * 30.0 / np.pi
    weight = grid["weight_on_bit"].values / 1e3
    # one colour scale per quantity, shared by the drives
    finite = {name: grid[name].values[np.isfinite(grid[name].values)] * scale for name, _, scale, _ in PANELS}
    limits = {name: (v.min(), v.max()) if v.size else (0.0, 1.0) for name, v in finite.items()}
    for row, controller in enumerate(controllers):
        at = grid.sel(controller=controller)
        unsettled = ~at["settled"].values
        for col, (name, title, scale, cmap) in enumerate(PANELS):
            ax = axes[row, col]
            values = at[name].values * scale
            mesh = ax.pcolormesh(_edges(rpm), _edges(weight), np.ma.masked_invalid(values), cmap=cmap,
                                 shading="flat", vmin=limits[name][0], vmax=limits[name][1])
            fig.colorbar(mesh, ax=ax)
            failed = at["failed"].values if "failed" in at else np.zeros_like(unsettled)
            moved = at["step_moved"].values if "step_moved" in at else np.zeros_like(unsettled)
            for i, j in zip(*np.nonzero(unsettled | moved)):
                mark = "!" if failed[i, j] else "x" if unsettled[i, j] else "~"
                ax.text(rpm[j], weight[i], mark, ha="center", va="center", color="grey")
            ax.set_xlabel("rotation speed [rpm]")
            ax.set_ylabel("weight on bit [kN]")
            ax.set_title(f"{controller}: {title}" if col == 0 else title, fontsize=9)
    fig.suptitle(f"stick-slip map ({grid.attrs.get('bit_rock_law', '')} bit law, {grid.attrs.get('drive_mode', '')} "
                 f"drive; x: not settled within {grid.attrs.get('time_limit_s', 0):g} s; !: a step failed, the "
                 "windows before it shown" + ("; ~: moved at half the step" if "step_moved" in grid else "") + ")",
                 fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)
