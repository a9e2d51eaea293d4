"""The life of a command: its output directory taken and its summary written however it ends, and
stopping it with SIGINT (Ctrl-C) or SIGTERM (a batch system's time limit, ``kill``).

Within :class:`StopOnSignal`, the first of either signal raises KeyboardInterrupt in the main
thread, and every later one is ignored, so that the shutdown it starts (writing the summary,
closing the files) cannot be cut short by a second Ctrl-C.  Inside :func:`uninterrupted` (the
recording of a step: its rows, its files, the state the summary reports) the interrupt waits until
the block ends, so that what the files hold and what the summary says stay the same step.  A signal that arrives while the
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
    """Context manager: the first SIGINT/SIGTERM raises KeyboardInterrupt (at the end of an
    :func:`uninterrupted` block if it arrives inside one), later ones are ignored; the previous handlers
    come back on exit (a no-op outside the main thread, where Python has no handlers)."""

    #: The innermost StopOnSignal of this process, which :func:`uninterrupted` defers.
    active: "StopOnSignal | None" = None

    def __enter__(self) -> "StopOnSignal":
        self.previous = None
        self.deferring = 0  # depth of the uninterrupted blocks open
        self.requested = False  # the first signal has arrived
        if threading.current_thread() is threading.main_thread():
            self.previous = {s: signal.getsignal(s) for s in SIGNALS}
            for s in SIGNALS:
                signal.signal(s, self._first)
            self.outer, StopOnSignal.active = StopOnSignal.active, self
        return self

    def _first(self, signum, frame):
        for s in SIGNALS:
            signal.signal(s, signal.SIG_IGN)
        self.requested = True
        if not self.deferring:
            raise KeyboardInterrupt

    def __exit__(self, *exc) -> None:
        if self.previous is not None:
            StopOnSignal.active = self.outer
            for s, handler in self.previous.items():
                signal.signal(s, handler)


@contextmanager
def uninterrupted(stop_after: bool = True):
    """A block that the active :class:`StopOnSignal` does not cut (a no-op outside one).  ``stop_after``
    (the recording of a step): KeyboardInterrupt comes as the block ends if a signal has arrived, inside it
    or before it (an interrupt raised where Python only prints exceptions, a destructor or a callback of a
    C library, would otherwise be lost, and the run would go on until the supervisor kills it); without it
    (the writing of a summary), the signal is ignored."""
    stop = StopOnSignal.active
    if stop is None:
        yield
        return
    stop.deferring += 1
    try:
        yield
    finally:
        stop.deferring -= 1
    if stop_after and stop.requested and not stop.deferring:
        raise KeyboardInterrupt


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
                with uninterrupted(stop_after=False):  # the summary is written whatever comes
                    summary["wall_time_s"] = time.perf_counter() - start
                    write_json(out / "summary.json", summary)
    finally:
        claim.release()
