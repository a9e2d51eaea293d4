"""The command-line tool's guard for commands that must stop when told to (``run``, ``static``, ``modal``).

Python sees a signal only between two bytecodes: inside a long C call (the mesh of a huge scene,
a PETSc factorisation) SIGINT and SIGTERM wait until the call returns, which can be many minutes.
So ``fenics-drill`` runs such a command in a worker process and stays light itself: it passes
every SIGINT/SIGTERM on to the worker, gives it :data:`GRACE_SECONDS` to stop cleanly (the worker
then writes its summary itself, :mod:`fenics_drill.studies.lifecycle`), and otherwise ends it with
SIGKILL and marks the summary "interrupted".  Nothing is lost that was written: the files of a run
are whole at every moment (:mod:`fenics_drill.io.files`).  Under ``mpiexec`` (the studies) the
process manager delivers the signals to every rank and no worker is used.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from fenics_drill.io.files import UnreadableFile, read_json, write_json

#: Seconds a worker gets to stop cleanly after a signal before it is killed.
GRACE_SECONDS = 5.0
#: Set in the worker's environment: it runs the command itself.
WORKER_VARIABLE = "FENICS_DRILL_WORKER"


def is_worker() -> bool:
    return os.environ.get(WORKER_VARIABLE) == "1"


def _die_with_parent() -> None:
    """In the worker, before it starts: the kernel sends it SIGKILL if the supervisor dies (Linux), so a
    SIGKILL of ``fenics-drill`` (the out-of-memory killer, a scheduler's hard limit) ends both."""
    try:
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        pass  # not Linux: the worker outlives a killed supervisor, and still writes whole files


def supervise(argv: list[str], command: str, out: Path | None) -> int:
    """Run ``fenics-drill ARGV`` in a worker process; return its exit code (130 if it had to be killed)."""
    worker = subprocess.Popen([sys.executable, "-m", "fenics_drill.cli", *argv],
                              env={**os.environ, WORKER_VARIABLE: "1"}, preexec_fn=_die_with_parent)
    received: list[int] = []

    def forward(signum, frame):
        received.append(signum)
        if worker.poll() is None:
            worker.send_signal(signum)

    previous = {s: signal.signal(s, forward) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        deadline = None
        while True:
            try:
                code = worker.wait(timeout=0.2)
                break
            except subprocess.TimeoutExpired:
                if received and deadline is None:
                    deadline = time.monotonic() + GRACE_SECONDS
                if deadline is not None and time.monotonic() > deadline:
                    worker.kill()
                    worker.wait()
                    _mark_killed(out, command, received[0], f"the command did not stop within {GRACE_SECONDS:g} s "
                                 "(it was inside a long computation) and was killed", "interrupted")
                    return 130
    finally:
        for s, handler in previous.items():  # after a signal, the later ones of the same Ctrl-C or kill are ignored
            signal.signal(s, signal.SIG_IGN if received else handler)
    if code < 0:  # the worker died of a signal: one it could not handle (SIGKILL from outside, a crash), or a late
        # second Ctrl-C or SIGTERM after it had written its summary and given the handlers back
        if received:
            _mark_killed(out, command, -code, "the command died of it before it wrote its summary", "interrupted")
            return 130
        _mark_killed(out, command, -code, "nothing here sent it: the out-of-memory killer, a hard limit of a batch "
                     "system, or a crash", "killed")
        return 128 - code
    return code


def _mark_killed(out: Path | None, command: str, signum: int, how: str, status: str) -> None:
    """Say in ``out/summary.json`` that the command was ended from outside (``status``: interrupted when the user
    asked it to stop, killed otherwise), keeping what it recorded."""
    if out is None or not out.is_dir():
        return
    path = out / "summary.json"
    try:
        summary = read_json(path) if path.exists() else {"command": command}
    except UnreadableFile:
        summary = {"command": command}
    if summary.get("command") != command or summary.get("status") not in (None, "running"):
        return  # not this command's directory, or the worker wrote its own final summary
    name = signal.Signals(signum).name
    summary.update(status=status, message=f"ended by {name}: {how}; the files hold everything up to their last write")
    summary.pop("pid", None)
    write_json(path, summary)
