"""``fenics-drill plot DIR``: the figures of whatever DIR holds - a run, a Monte Carlo study, an
operating window, a Campbell diagram, a modal analysis or a torque-and-drag study.

Every plot records what it was drawn from (``figures.json``: the command's status, rows or realisations, and
the figures), and marks the figures of a run or study that is running, interrupted, failed or killed with a
banner saying so; a command that writes the directory again removes them
(:func:`fenics_drill.io.output_directory.remove_figures`), so a figure never passes for current."""

from __future__ import annotations

from pathlib import Path

from fenics_drill.io.files import UnreadableFile, read_json, write_json
from fenics_drill.io.output_directory import FIGURE_RECORD, record_written, summary_of
from fenics_drill.io.timeseries import read_series
from fenics_drill.plots.common import DRAWN_FROM


class NothingToPlot(ValueError):
    """The directory holds none of the files the figures are drawn from."""


#: Statuses whose figures show everything the command was asked for.
COMPLETE = ("finished", "suspect")


def plot_directory(directory: Path, gif: bool = True) -> list[Path]:
    """Figs. 24-27/36 (optimize.json), 28-35 (statistics.h5) or 13-23 (timeseries.h5); the files written.
    ``drawn_from(directory)`` says what they show."""
    state = drawn_from(directory)
    token = DRAWN_FROM.set(state)
    try:
        paths = _draw(directory, state["kind"], gif)
    finally:
        DRAWN_FROM.reset(token)
    write_json(directory / FIGURE_RECORD, {"drawn_from": state, "figures": [p.name for p in paths]})
    record_written(directory, [*(p.name for p in paths), FIGURE_RECORD])
    return paths


def drawn_from(directory: Path) -> dict:
    """What a plot of ``directory`` would show: its kind, the command's status (a "running" command whose
    process is gone reads "killed"), how much it holds, and a ``banner`` when that is not the whole answer."""
    if not directory.is_dir():
        raise NothingToPlot(f"{directory} does not exist" if not directory.exists() else f"{directory} is a file, "
                            "not an output directory")
    try:
        summary = summary_of(directory) or {}
    except (UnreadableFile, OSError):
        summary = {}
    status = summary.get("status", "unknown")
    for kind, name in (("stick-slip-map", "map.json"), ("calibrate", "calibration.json"),
                       ("broomstick", "broomstick.json"), ("risk", "risk.json"),
                       ("torque-drag", "torque_drag.json"), ("campbell", "campbell.json"), ("modal", "modes.json"),
                       ("optimize", "optimize.json"), ("mc", "statistics.h5"),
                       ("run", "timeseries.h5"), ("static", "static_profiles.h5")):
        if (directory / name).exists():
            break
    else:
        said = f" (its command is {status}: {summary.get('message')})" if summary.get("message") else ""
        raise NothingToPlot(f"{directory} holds no timeseries.h5 ('fenics-drill run'), statistics.h5 "
                            "('fenics-drill mc'), optimize.json ('fenics-drill optimize'), modes.json ('fenics-drill "
                            "modal'), campbell.json "
                            "('fenics-drill campbell'), torque_drag.json or risk.json ('fenics-drill torque-drag'), "
                            "broomstick.json "
                            "('fenics-drill broomstick'), map.json ('fenics-drill stick-slip-map'), "
                            "calibration.json ('fenics-drill calibrate') or "
                            f"static_profiles.h5 ('fenics-drill static' on a well){said}")
    state = {"kind": kind, "status": status}
    if kind == "run":
        data, attrs = read_series(directory / "timeseries.h5")  # UnreadableFile names a broken file
        rows = len(data["time"])
        if rows < 2:
            said = f" ({status}: {summary.get('message')})" if summary else ""
            raise NothingToPlot(f"{directory}: the run{said} recorded fewer than two instants; there is nothing "
                                "to draw")
        t_last, t_end = float(data["time"][-1]), float(attrs["scene"].time.t_end)
        state.update(rows=rows, t=t_last, t_end=t_end)
        if status not in COMPLETE:
            state["banner"] = f"PARTIAL: the run is {status}; these figures show t = 0 to {t_last:.4g} s of {t_end:g} s"
    elif status not in COMPLETE:
        done = summary.get("realisations_done", summary.get("runs_done"))
        state["banner"] = f"PARTIAL: the study is {status}" + (f" ({done} results written)" if done is not None
                                                                 else "") + "; these figures show an earlier state"
    if kind == "mc":
        state["samples"] = summary.get("realisations")
    return state


def _draw(directory: Path, kind: str, gif: bool) -> list[Path]:
    if kind == "stick-slip-map":
        from fenics_drill.plots.stick_slip_map import stick_slip_map_figures

        return stick_slip_map_figures(directory)
    if kind == "risk":
        from fenics_drill.plots.risk import risk_figures

        return risk_figures(directory)
    if kind in ("broomstick", "calibrate"):
        from fenics_drill.plots.broomstick import broomstick_figures

        return broomstick_figures(directory)
    if kind == "torque-drag":
        from fenics_drill.plots.well import well_figures

        return well_figures(directory)
    if kind == "static":
        from fenics_drill.plots.well import static_loads_figure

        return [static_loads_figure(directory)]
    if kind == "campbell":
        from fenics_drill.plots.campbell import campbell_figure

        return [campbell_figure(read_json(directory / "campbell.json"), directory / "campbell.png")]
    if kind == "modal":
        from fenics_drill.plots.modal import spectra_figure

        return [spectra_figure(read_json(directory / "modes.json"), directory / "modes.png")]
    if kind == "optimize":
        from fenics_drill.plots.window import optimize_figures

        return optimize_figures(directory)
    if kind == "mc":
        from fenics_drill.plots.monte_carlo import mc_figures

        return mc_figures(directory)
    from fenics_drill.plots.run_figures import plot_run

    return plot_run(directory, gif=gif)
