"""Figures 28-35 of the paper from a Monte Carlo study's ``statistics.h5``.

Fig. 28 convergence metric (101); Figs. 29, 31, 33 nominal (red), mean (blue) and 95 %
envelope (grey) of the bit axial motion, bit rotation and the section's transverse
motion; Figs. 30, 32 normalised PDFs of the bit velocity and angular velocity at t_end;
Figs. 34, 35 PDFs of the efficiency and of the rate of penetration.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from fenics_drill.plots.common import M_PER_S_TO_M_PER_H, RAD_PER_S_TO_RPM, panels, save_figure

#: (figure, file stem, [(history, scale, label), (history, scale, label)], title)
ENVELOPES = (
    ("29", "bit_axial", [("bit_displacement", 1e3, "bit displacement [mm]"),
                         ("bit_velocity", M_PER_S_TO_M_PER_H, "bit velocity [m/h]")], "drill-bit axial motion"),
    ("31", "bit_rotation", [("bit_rotation", 1 / (2 * np.pi), "bit rotation [rev]"),
                            ("bit_angular_velocity", RAD_PER_S_TO_RPM, "bit angular velocity [rpm]")],
     "drill-bit rotation"),
    ("33", "section_lateral", [("section_w", 1e3, "w at the section [mm]"),
                               ("section_w_velocity", 1.0, "w velocity at the section [m/s]")],
     "transverse motion at the section"),
)
#: (figure, pdf name, x label, x scale)
PDFS = (
    ("30", "bit_velocity_at_t_end", "normalised bit velocity at t_end [-]", 1.0),
    ("32", "bit_angular_velocity_at_t_end", "normalised bit angular velocity at t_end [-]", 1.0),
    ("34", "efficiency", "drilling efficiency [%]", 100.0),
    ("35", "rop", "rate of penetration [m/h]", M_PER_S_TO_M_PER_H),
)


def mc_figures(study: Path) -> list[Path]:
    paths = []
    with h5py.File(study / "statistics.h5", "r") as f:
        n = int(f.attrs["realisations"])
        fig, (ax,) = panels(1, 3.5)
        ax.plot(np.arange(1, n + 1), f["convergence_metric"][()], "b-", lw=1)
        ax.ticklabel_format(axis="y", useOffset=False)
        ax.set(xlabel="number of realisations", ylabel="conv_MC [kg^1/2 m s^1/2]",
               title="Fig. 28: convergence metric (101) of the M-normalised modal coordinates")
        paths.append(save_figure(fig, study / "fig28_convergence.png"))
        t = f["time"][()]
        for figure, stem, rows, title in ENVELOPES:
            fig, axes = panels(2)
            for ax, (name, scale, label) in zip(axes, rows):
                g = f[name]
                ax.fill_between(t, g["p2.5"][()] * scale, g["p97.5"][()] * scale, color="0.75", label="95 % envelope")
                ax.plot(t, g["nominal"][()] * scale, "r-", lw=0.7, label="nominal")
                ax.plot(t, g["mean"][()] * scale, "b-", lw=0.7, label="mean")
                ax.set_ylabel(label)
            axes[0].legend(loc="best", fontsize=8)
            axes[0].set_title(f"Fig. {figure}: {title} ({n} realisations)")
            axes[-1].set_xlabel("time [s]")
            paths.append(save_figure(fig, study / f"fig{figure}_{stem}_envelope.png"))
        for figure, name, xlabel, scale in PDFS:
            if name not in f["pdf"]:
                continue  # no spread (all realisations equal)
            g = f["pdf"][name]
            fig, (ax,) = panels(1, 3.5)
            ax.plot(g["points"][()] * scale, g["density"][()] / scale, "b-")
            unit = xlabel[xlabel.rindex("[") + 1:-1]
            ax.set(xlabel=xlabel, ylabel=f"probability density [1/{unit}]" if unit != "-" else "probability density [-]",
                   title=f"Fig. {figure}: PDF ({n} realisations, Gaussian KDE)")
            paths.append(save_figure(fig, study / f"fig{figure}_pdf_{name}.png"))
    return paths
