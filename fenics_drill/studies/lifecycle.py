"""The life of a command: its output directory taken and its summary written however it ends, and
stopping it with SIGINT (Ctrl-C) or SIGTERM (a batch system's time limit, ``kill``).

Within :class:`StopOnSignal`, the first of either signal raises KeyboardInterrupt in the main
thread, and every later one is ignored, so that the shutdown it starts (writing the summary,
closing the files) cannot be cut short by a second Ctrl-C.  A signal that arrives while the
process is inside a long C call (a PETSc solve, the mesh of a huge scene) is only seen when the
call returns; :mod:`fenics_drill.supervisor` bounds that wait for the command-line tool.
"""

from __future__ import annotations

import signal
import threading
import time
from contextlib import contextmanager
from pathlib import Path

from fenics_drill.io.files import write_json
from fenics_drill.io.output_directory import claim_output
from fenics_drill.model.resources import check_memory

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopOnSignal:
    """Context manager: the first SIGINT/SIGTERM raises KeyboardInterrupt, later ones are ignored; the
    previous handlers come back on exit (a no-op outside the main thread, where Python has no handlers)."""

    def __enter__(self) -> "StopOnSignal":
        self.previous = None
        if threading.current_thread() is threading.main_thread():
            self.previous = {s: signal.getsignal(s) for s in SIGNALS}
            for s in SIGNALS:
                signal.signal(s, self._first)
        return self

    @staticmethod
    def _first(signum, frame):
        for s in SIGNALS:
            signal.signal(s, signal.SIG_IGN)
        raise KeyboardInterrupt

    def __exit__(self, *exc) -> None:
        if self.previous is not None:
            for s, handler in self.previous.items():
                signal.signal(s, handler)


@contextmanager
def command_output(out: str | Path, command: str, scene, overwrite: bool = False):
    """Check that the scene fits in memory (ResourceError), take ``out`` for ``command`` (OutputError),
    both before any computation, and yield the summary dict the command fills; on the way out
    ``summary.json`` is written with the status: finished, interrupted (SIGINT, SIGTERM) or failed
    (with the exception's message)."""
    out = Path(out)
    check_memory(scene.beam.elements, scene.beam.element_degree)
    claim = claim_output(out, command, overwrite)
    start = time.perf_counter()
    summary = {"command": command, "status": "finished", "message": ""}
    try:
        with StopOnSignal():
            try:
                yield summary
            except KeyboardInterrupt:
                summary.update(status="interrupted", message="stopped by Ctrl-C or SIGTERM")
                raise
            except Exception as err:
                summary.update(status="failed", message=str(err))
                raise
            finally:
                summary["wall_time_s"] = time.perf_counter() - start
                write_json(out / "summary.json", summary)
    finally:
        claim.release()
