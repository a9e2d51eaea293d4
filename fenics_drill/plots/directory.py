"""``fenics-drill plot DIR``: the figures of whatever DIR holds - a run, a Monte Carlo study, an
operating window or a Campbell diagram."""

from __future__ import annotations

from pathlib import Path

from fenics_drill.io.files import UnreadableFile, read_json
from fenics_drill.io.timeseries import read_series


class NothingToPlot(ValueError):
    """The directory holds none of the files the figures are drawn from."""


def plot_directory(directory: Path, gif: bool = True) -> list[Path]:
    """Figs. 24-27/36 (optimize.json), 28-35 (statistics.h5) or 13-23 (timeseries.h5); the files written."""
    if (directory / "campbell.json").exists():
        from fenics_drill.plots.campbell import campbell_figure

        return [campbell_figure(read_json(directory / "campbell.json"), directory / "campbell.png")]
    if (directory / "optimize.json").exists():
        from fenics_drill.plots.window import optimize_figures

        return optimize_figures(directory)
    if (directory / "statistics.h5").exists():
        from fenics_drill.plots.monte_carlo import mc_figures

        return mc_figures(directory)
    if (directory / "timeseries.h5").exists():
        from fenics_drill.plots.run_figures import plot_run

        _check_run(directory)
        return plot_run(directory, gif=gif)
    raise NothingToPlot(f"{directory} holds no timeseries.h5 ('fenics-drill run'), statistics.h5 "
                        "('fenics-drill mc'), optimize.json ('fenics-drill optimize') or campbell.json "
                        "('fenics-drill campbell')")


def _check_run(directory: Path) -> None:
    """Refuse a run directory whose run recorded nothing to draw (it failed or was stopped at t = 0)."""
    data, _ = read_series(directory / "timeseries.h5")  # UnreadableFile names a broken file
    if len(data["time"]) < 2:
        try:
            summary = read_json(directory / "summary.json")
            said = f" ({summary.get('status')}: {summary.get('message')})"
        except (UnreadableFile, OSError):
            said = ""
        raise NothingToPlot(f"{directory}: the run{said} recorded fewer than two instants; there is nothing to draw")
