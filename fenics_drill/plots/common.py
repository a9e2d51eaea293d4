"""Helpers every figure module shares: unit conversions at the plotting edge, panels, saving."""

from __future__ import annotations

import json
from contextvars import ContextVar
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

M_PER_S_TO_M_PER_H = 3600.0
RAD_PER_S_TO_RPM = 60.0 / (2.0 * np.pi)


#: The state of the directory the figures being drawn come from (set by :mod:`fenics_drill.plots.directory` for
#: the time of one ``plot``): it goes into each PNG's metadata, and its ``banner`` across the top of the figure
#: when the data are partial (a run still running, interrupted or killed).
DRAWN_FROM: ContextVar[dict | None] = ContextVar("drawn_from", default=None)


def save_figure(fig, path: Path) -> Path:
    state = DRAWN_FROM.get()
    banner = state.get("banner") if state else None
    if banner:
        fig.text(0.5, 0.995, banner, ha="center", va="top", fontsize=9, color="white",
                 bbox={"boxstyle": "square,pad=0.3", "fc": "tab:red", "ec": "none"})
        fig.tight_layout(rect=(0, 0, 1, 0.95))
    else:
        fig.tight_layout()
    fig.savefig(path, dpi=120, metadata={"Description": json.dumps(state)} if state else None)
    plt.close(fig)
    return path


def panels(count: int, height: float = 3.0):
    fig, axes = plt.subplots(count, 1, figsize=(8, height * count), sharex=count > 1, squeeze=False)
    for ax in axes[:, 0]:
        ax.grid(alpha=0.3)
    return fig, axes[:, 0]
