"""Helpers every figure module shares: unit conversions at the plotting edge, panels, saving."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

M_PER_S_TO_M_PER_H = 3600.0
RAD_PER_S_TO_RPM = 60.0 / (2.0 * np.pi)


def save_figure(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def panels(count: int, height: float = 3.0):
    fig, axes = plt.subplots(count, 1, figsize=(8, height * count), sharex=count > 1, squeeze=False)
    for ax in axes[:, 0]:
        ax.grid(alpha=0.3)
    return fig, axes[:, 0]
