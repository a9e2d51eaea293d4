"""The public Python API (re-exported by ``fenics_drill``): what a notebook needs, one call each::

    import fenics_drill as fd
    scene = fd.load_scene("demos/scenes/paper.toml", ["time.t_end=1"])
    modes = fd.modal_analysis(scene)            # modes.json as a dict
    rest = fd.static_state(scene)               # static.json as a dict
    run = fd.run(scene)                         # run.summary (dict), run.series (xarray.Dataset)
    mc = fd.monte_carlo(scene, samples=8, out="out/mc")
    window = fd.operating_window(scene, out="out/window")
    diagram = fd.campbell(scene)                # campbell.json as a dict (critical speeds, whirl)
    td = fd.torque_drag(fd.load_scene("demos/scenes/well_vbh.toml"))  # td.report (dict), td.profiles (xarray)

Every call takes a :class:`~fenics_drill.scene.Scene`; change one with
``scene.with_changes(drive={"rotation_speed": 5.0})``.  Each call checks its scene again as the command line checks
a scene file (one changed with ``dataclasses.replace`` included) and refuses it with the same one-line
:class:`~fenics_drill.scene.SceneError`; an output directory's refusal names the Python arguments
(``overwrite=True``, ``resume=True``).  The command line does the same through :mod:`fenics_drill.cli`.
"""

from __future__ import annotations

import functools
import inspect
import tempfile
from dataclasses import dataclass
from pathlib import Path

from fenics_drill.io.output_directory import OutputError
from fenics_drill.io.timeseries import open_dataset
from fenics_drill.plots.directory import plot_directory
from fenics_drill.scene import Scene, checked
from fenics_drill.studies.campbell import campbell_report, write_campbell
from fenics_drill.studies.modal_report import modal_report
from fenics_drill.studies.monte_carlo import monte_carlo as _monte_carlo
from fenics_drill.studies.operating_window import run_optimize
from fenics_drill.studies.prepare import prepare
from fenics_drill.studies.run import run_scene, run_static
from fenics_drill.studies.torque_drag import torque_drag_study, write_torque_drag


@dataclass(frozen=True)
class RunResult:
    """A finished (or stopped) drilling run: its directory, its summary and its time series."""

    directory: Path
    summary: dict

    @property
    def series(self):
        """The time series as an ``xarray.Dataset`` (variables carry ``units`` and ``long_name``)."""
        return open_dataset(self.directory / "timeseries.h5")


#: The command line's words in an output directory's message, and the Python arguments they stand for.
PYTHON_WORDS = (("add --overwrite", "pass overwrite=True"), ("with --overwrite", "with overwrite=True"),
                ("--resume", "resume=True"), ("--out ", "out="))


def python_phrasing(message: str) -> str:
    """An output directory's message with the Python arguments in place of the command line's options."""
    for words, argument in PYTHON_WORDS:
        message = message.replace(words, argument)
    return message


def _entry(function):
    """An API call: its scene checked again (:func:`~fenics_drill.scene.checked`), an output directory's refusal in
    the Python arguments' words."""
    signature = inspect.signature(function)

    @functools.wraps(function)
    def call(scene, *args, **kwargs):
        scene = checked(scene)
        out = signature.bind(scene, *args, **kwargs).arguments.get("out")
        if out is not None and not str(out).strip():
            raise OutputError("out='' names no directory (it would write into the current one): give one, e.g. "
                              "out='out/run1', or None")
        try:
            return function(scene, *args, **kwargs)
        except OutputError as err:
            raise OutputError(python_phrasing(str(err))) from None
    return call


@_entry
def modal_analysis(scene: Scene) -> dict:
    """Modes of the band B (Eq. 62) about the state ``modal.state`` chooses (in a well: the static state, its tension
    and wall springs), their kinds, the spectra of the run's end conditions and the reduced basis (Section 6.3):
    modes.json."""
    return modal_report(scene)


@_entry
def static_state(scene: Scene, out: str | Path | None = None, overwrite: bool = False) -> dict:
    """Static equilibrium under gravity with wall contact (Section 6.4): static.json; with ``out`` also
    static.xdmf there."""
    if out is not None:
        return run_static(scene, out, overwrite=overwrite)
    return prepare(scene, dynamics=False).static


@_entry
def run(scene: Scene, out: str | Path | None = None, progress: bool = False, overwrite: bool = False) -> RunResult:
    """Static equilibrium, then the drilling dynamics to ``time.t_end`` into ``out`` (a new temporary
    directory if None; an earlier run there is replaced only with ``overwrite``)."""
    directory = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="fenics-drill-run-"))
    return RunResult(directory, run_scene(scene, directory, progress=progress, overwrite=overwrite))


@_entry
def monte_carlo(scene: Scene, samples: int, out: str | Path, resume: bool = False, progress: bool = False,
                overwrite: bool = False) -> dict:
    """Monte Carlo over the random bit-rock laws (Section 6.11): the summary of ``out``/summary.json."""
    return _monte_carlo(scene, samples, out, resume=resume, progress=progress, overwrite=overwrite)


@_entry
def operating_window(scene: Scene, out: str | Path, resume: bool = False, progress: bool = False,
                     overwrite: bool = False) -> dict:
    """The operating window of the scene's [optimize] section (Sections 6.9-6.12): optimize.json."""
    return run_optimize(scene, out, resume=resume, progress=progress, overwrite=overwrite)


@_entry
def campbell(scene: Scene, out: str | Path | None = None, overwrite: bool = False) -> dict:
    """Critical speeds: the modes of the string spinning over ``campbell.rotation_speed`` (campbell.json);
    with ``out`` also written there (draw it with :func:`plot`)."""
    if out is not None:
        return write_campbell(scene, out, overwrite=overwrite)
    return campbell_report(scene)


@dataclass(frozen=True)
class TorqueDragResult:
    """A soft-string study: ``report`` (torque_drag.json as a dict) and ``profiles`` (an ``xarray.Dataset`` over
    measured depth: tension, torque and wall force per operation, the buckling loads, the path)."""

    report: dict
    profiles: object


@_entry
def torque_drag(scene: Scene, out: str | Path | None = None, overwrite: bool = False) -> TorqueDragResult:
    """Soft-string torque and drag along the scene's well for each of ``torque_drag.operations``; with ``out``
    also written there (torque_drag.json, torque_drag.h5, well.vtu; draw it with :func:`plot`)."""
    study = write_torque_drag(scene, out, overwrite=overwrite) if out is not None else torque_drag_study(scene)
    return TorqueDragResult(study["report"], study["profiles"])


def plot(directory: str | Path, gif: bool = False) -> list[Path]:
    """The figures of a run, Monte Carlo study, operating window, Campbell or torque-and-drag directory; returns
    the files."""
    return plot_directory(Path(directory), gif=gif)
