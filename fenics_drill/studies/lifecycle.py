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
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

from fenics_drill.io.files import UnreadableFile, no_room_message, read_json, write_final_json, write_json
from fenics_drill.io.output_directory import claim_output
from fenics_drill.io.study_directory import RankStopped, mark_rank
from fenics_drill.model.resources import check_memory

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopOnSignal:
    """Context manager: the first SIGINT/SIGTERM raises KeyboardInterrupt (at the end of an
    :func:`uninterrupted` block if it arrives inside one), later ones are ignored; the previous handlers
    come back on exit (a no-op outside the main thread, where Python has no handlers).

    ``collective`` (the ranks of one shared run): the signal is only noted, and the ranks stop together where they
    exchange it (:func:`agree_to_stop`, :func:`uninterrupted` with ``comm``).  A rank that raised at once, between
    two exchanges, would stop a step before the others and leave them waiting in a collective it never joins."""

    #: The innermost StopOnSignal of this process, which :func:`uninterrupted` defers.
    active: "StopOnSignal | None" = None

    def __init__(self, collective: bool = False) -> None:
        self.collective = collective

    def __enter__(self) -> "StopOnSignal":
        self.previous = None
        self.deferring = 0  # depth of the uninterrupted blocks open
        self.requested = False  # the first signal has arrived
        if threading.current_thread() is threading.main_thread():
            self.previous = {s: signal.getsignal(s) for s in SIGNALS}
            for s in SIGNALS:
                signal.signal(s, self._first)
            self.outer, StopOnSignal.active = StopOnSignal.active, self
            self.previous_hook, sys.unraisablehook = sys.unraisablehook, self._unraisable
        return self

    def _unraisable(self, unraisable) -> None:
        """The interrupt raised where Python can only print it (a weakref callback, a destructor, a C library's
        callback) is not printed: ``requested`` stays set, and the next :func:`uninterrupted` block or study
        step raises it again."""
        if not issubclass(unraisable.exc_type, KeyboardInterrupt):
            self.previous_hook(unraisable)

    def _first(self, signum, frame):
        for s in SIGNALS:
            signal.signal(s, signal.SIG_IGN)
        self.requested = True
        if not self.deferring and not self.collective:
            raise KeyboardInterrupt

    def __exit__(self, *exc) -> None:
        if self.previous is not None:
            StopOnSignal.active = self.outer
            sys.unraisablehook = self.previous_hook
            for s, handler in self.previous.items():
                signal.signal(s, handler)


def stop_if_requested() -> None:
    """Raise KeyboardInterrupt if a signal arrived and its interrupt was lost (a study checks between tasks)."""
    stop = StopOnSignal.active
    if stop is not None and stop.requested and not stop.deferring and not stop.collective:
        raise KeyboardInterrupt


def _asked_on_any_rank(comm) -> bool:
    """Whether a signal arrived on any rank of ``comm`` (a collective call)."""
    from mpi4py import MPI

    stop = StopOnSignal.active
    return comm.allreduce(stop is not None and stop.requested, op=MPI.LOR)


def agree_to_stop(comm) -> None:
    """Raise KeyboardInterrupt on every rank of ``comm`` if a signal arrived on any of them (a collective call:
    every rank makes it at the same point of a shared run)."""
    if _asked_on_any_rank(comm):
        raise KeyboardInterrupt


@contextmanager
def uninterrupted(stop_after: bool = True, comm=None):
    """A block that the active :class:`StopOnSignal` does not cut (a no-op outside one).  ``stop_after``
    (the recording of a step): KeyboardInterrupt comes as the block ends if a signal has arrived, inside it
    or before it (an interrupt raised where Python only prints exceptions, a destructor or a callback of a
    C library, would otherwise be lost, and the run would go on until the supervisor kills it); without it
    (the writing of a summary), the signal is ignored.  ``comm``: the ranks that take the steps of one run together
    (:mod:`~fenics_drill.studies.shared_run`) tell each other at the end of the block whether a signal arrived, and
    if one did on any of them, every rank raises KeyboardInterrupt after the same step (a rank that stopped alone
    would leave the others waiting in the step's collectives); under a ``collective`` :class:`StopOnSignal` a block
    without ``comm`` does not stop the rank."""
    stop = StopOnSignal.active
    if stop is None:
        yield
        return
    stop.deferring += 1
    try:
        yield
        agreed = stop.requested and not stop.collective
        if stop_after and comm is not None:
            # told while the signal is still deferred: a rank waiting here for a slower one, where a signal most
            # often lands, must not leave the exchange alone (the other would stop a step later, in a collective
            # this rank never joins); a signal after its share was sent waits for the next step's exchange
            agreed = _asked_on_any_rank(comm)
    finally:
        stop.deferring -= 1
    if stop_after and agreed and not stop.deferring:
        raise KeyboardInterrupt


def scene_record(scene) -> dict:
    """What every command's summary.json says of its scene's well: where the bit is against the well's bottom
    (``bit_above_well_bottom_m``) and the notes of :func:`~fenics_drill.model.well.well_notes`."""
    from fenics_drill.model.well import bit_above_bottom, well_notes

    return {"bit_above_well_bottom_m": bit_above_bottom(scene), "notes": well_notes(scene)}


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
    summary = {"command": command, "status": "finished", "message": "", **scene_record(scene)}
    try:
        with StopOnSignal():
            try:
                yield summary
            except KeyboardInterrupt:
                summary.update(status="interrupted", message="stopped by Ctrl-C or SIGTERM")
                raise
            except Exception as err:
                room = no_room_message(err)
                summary.update(status="failed", message=f"cannot write the files: {room}" if room else str(err))
                raise
            finally:
                with uninterrupted(stop_after=False):  # the summary is written whatever comes
                    summary["wall_time_s"] = time.perf_counter() - start
                    write_final_json(out / "summary.json", summary)
    finally:
        claim.release()


@contextmanager
def study_run(out: Path, command: str, comm, counts):
    """One rank's part of a study (``mc``, ``optimize``) spread over MPI ranks: signals stop it
    (:class:`StopOnSignal`), its marker in ``.ranks/`` says how it ended, and ``summary.json`` is final however
    the study ends: interrupted, or failed with the failing rank's message (rank 0, or the failing rank itself,
    writes it; ``counts()`` adds what is done).  A rank leaving the block ignores further signals, so that
    waiting in MPI_Finalize for the others it is not killed by the Ctrl-C they are still handling."""
    status = message = None
    try:
        with StopOnSignal():
            try:
                yield
            except RankStopped as stop:
                status, message = ("interrupted" if stop.status == "interrupted" else "failed"), str(stop)
                raise
            except KeyboardInterrupt:
                status, message = "interrupted", "stopped by Ctrl-C or SIGTERM"
                mark_rank(out, comm.rank, status, message)
                raise
            except Exception as err:
                where = f"rank {comm.rank}: " if comm.size > 1 else ""
                reason = no_room_message(err) or f"{type(err).__name__}: {err}"
                status, message = "failed", f"{where}{reason}"
                try:
                    mark_rank(out, comm.rank, status, reason)
                except OSError:
                    pass  # a full disk: the summary below may still fit
                raise
            finally:
                if status is not None:
                    with uninterrupted(stop_after=False):
                        _final_study_summary(out, command, status, message, comm.rank == 0 or status == "failed",
                                             counts)
    finally:
        if comm.size > 1:
            for s in SIGNALS:
                signal.signal(s, signal.SIG_IGN)


def _final_study_summary(out: Path, command: str, status: str, message: str, always: bool, counts) -> None:
    """The study's summary with its final status, if it is still "running" (or ``always``)."""
    try:
        summary = read_json(out / "summary.json")
    except (UnreadableFile, OSError):
        summary = {"command": command}
    if summary.get("status") != "running" and not always:
        return
    try:
        done = counts()
    except Exception:  # the directory may be unreadable (a full disk): the status still goes in
        done = {}
    summary.update(status=status, message=message, **done)
    summary.pop("pid", None)
    write_final_json(out / "summary.json", summary)
