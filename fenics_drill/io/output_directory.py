"""The policy for output directories (``--out``), one for every command.

* A directory belongs to the command that wrote it: ``summary.json`` names the command
  (``run``, ``static``, ``modal``, ``mc``, ``optimize``) from the moment it starts.  A
  command never writes into another command's directory.
* A directory that already holds the output of the same command is refused unless the
  user says ``--overwrite`` (then every file that command wrote is removed first, and
  nothing else) or, for a study, ``--resume`` (continue it).
* What a command wrote is known from a record, ``.fenics-drill-files.json``: the names of the entries it writes
  in the directory (its outputs, named before it starts, and the figures drawn from it), and their temporary
  files ``.NAME.tmpPID``.  Only what the command itself names is recorded: a file that appears in the directory
  while the command runs (a user's notes saved there) is not the command's, and ``--overwrite`` leaves it and says
  so.  A file is never removed because of its name either: a user's ``figure_from_colleague.png`` or
  ``.notes.tmp.txt`` is not in the record.  A directory written
  before the record existed is read by the exact names of its command's outputs.
* A directory with files that are not a command's output is never touched.
* One process at a time: an exclusive lock (``.fenics-drill.lock``, released by the
  kernel when the process dies, and removed when the command ends) refuses a second command on the same
  directory.
* While the command works, ``summary.json`` says ``"status": "running"`` with its pid and host; a
  "running" summary whose process is gone (killed, out of memory) reads as ``"killed"``
  (:func:`summary_of`).
* A refused command leaves nothing behind: no lock file, no directory it created.
* Figures drawn from a directory are listed in ``figures.json`` with the state they were drawn from;
  a command that writes the directory again removes them (:func:`remove_figures`), so no figure
  passes for current.

Every refusal is an :class:`OutputError` naming the directory and the remedy.
"""

from __future__ import annotations

import fcntl
import os
import re
import shutil
import socket
import time
from pathlib import Path

from fenics_drill.io.files import UnreadableFile, read_json, write_json

LOCK_NAME = ".fenics-drill.lock"
#: The record of what fenics-drill wrote in a directory (module doc).
WRITTEN_RECORD = ".fenics-drill-files.json"
#: The list of figures drawn from a directory, and the state they were drawn from.
FIGURE_RECORD = "figures.json"

#: The outputs each command writes in its directory under these exact names (the figures a plot draws are
#: recorded as it draws them).
OWNED = {
    "run": ("summary.json", "timeseries.h5", "fields.xdmf", "fields.h5", "spectra.json", "animation.gif",
            FIGURE_RECORD),
    "static": ("summary.json", "static.json", "static.xdmf", "static.h5", "static_profiles.h5", "static_path.vtu",
               "static_loads.png", FIGURE_RECORD),
    "modal": ("summary.json", "modes.json", "modes.png", FIGURE_RECORD),
    "campbell": ("summary.json", "campbell.json", "campbell.png", FIGURE_RECORD),
    "mc": ("summary.json", "scene.json", "nominal.h5", "nominal.h5.corrupt", "realisations", "statistics.h5",
           FIGURE_RECORD),
    "optimize": ("summary.json", "scene.json", "points", "optimize.json", FIGURE_RECORD),
    "torque-drag": ("summary.json", "torque_drag.json", "torque_drag.h5", "well.vtu", "well_loads.png",
                    "well_path.png", "well_3d.png", "risk.json", "risk.nc", "samples", "scene.json", "risk.png", FIGURE_RECORD),
    "broomstick": ("summary.json", "broomstick.json", "broomstick.nc", "broomstick.csv", "broomstick.png",
                   FIGURE_RECORD),
    "calibrate": ("summary.json", "calibration.json", "broomstick.nc", "calibrated.nc", "calibration.png",
                  "friction_track.png", FIGURE_RECORD),
    "stick-slip-map": ("summary.json", "scene.json", "points", "map.json", "map.nc", "map.csv", "stick_slip_map.png",
                       FIGURE_RECORD),
}
#: A temporary file of an atomic write (:func:`fenics_drill.io.files.temporary_path`): ``.NAME.tmpPID``.
TEMPORARY = re.compile(r"^\.(?P<name>.+)\.tmp\d+$")
SIGNATURE = {"run": "timeseries.h5", "static": "static.json", "modal": "modes.json", "campbell": "campbell.json",
             "mc": "realisations", "optimize": "points",
             "torque-drag": "torque_drag.json", "broomstick": "broomstick.json", "calibrate": "calibration.json",
             "stick-slip-map": "map.json"}
DESCRIPTION = {"run": "a drilling run", "static": "a static equilibrium", "modal": "a modal analysis",
               "campbell": "a Campbell diagram", "mc": "a Monte Carlo study", "optimize": "an operating-window study",
               "torque-drag": "a torque-and-drag study", "broomstick": "a broomstick chart",
               "calibrate": "a friction calibration", "stick-slip-map": "a stick-slip map"}


class OutputError(ValueError):
    """An output directory that cannot be used; the message names it and says what to do."""


def directory_kind(out: Path) -> str | None:
    """The command whose output ``out`` holds (None if it holds none)."""
    summary = out / "summary.json"
    if summary.is_file():
        try:
            command = read_json(summary).get("command")
        except UnreadableFile:
            command = None
        if command in OWNED:
            return command
    for command, marker in SIGNATURE.items():
        if (out / marker).exists():
            return command
    return None


def _process_alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, dead but not yet reaped by its parent, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return True


def summary_of(out: Path) -> dict | None:
    """``out/summary.json`` (None if absent), with a "running" status whose process is gone on this host read as
    "killed": the command was ended before it could say how (SIGKILL, the out-of-memory killer, a full disk)."""
    path = out / "summary.json"
    if not path.is_file():
        return None
    summary = read_json(path)
    pid = summary.get("pid")
    if (summary.get("status") == "running" and isinstance(pid, int) and summary.get("host") == socket.gethostname()
            and not _process_alive(pid)):
        summary = {**summary, "status": "killed",
                   "message": f"the process (pid {pid}) ended without a final summary: it was killed (SIGKILL, out "
                              "of memory, a full disk, a lost node); the files hold what it wrote before"}
    return summary


def remove_figures(out: Path) -> list[str]:
    """Remove the figures listed in ``figures.json`` and the list itself: they were drawn from a state of the
    directory that a command is about to change.  Returns their names."""
    record = out / FIGURE_RECORD
    if not record.is_file():
        return []
    try:
        names = read_json(record).get("figures", [])
    except UnreadableFile:
        names = []
    for name in names:
        path = out / Path(name).name
        if path.is_file():
            path.unlink()
    record.unlink()
    return names


def recorded_names(out: Path) -> set[str]:
    """The names of the entries fenics-drill recorded as written in ``out`` (empty without a record)."""
    try:
        names = read_json(out / WRITTEN_RECORD).get("files", []) if (out / WRITTEN_RECORD).is_file() else []
    except UnreadableFile:
        names = []
    return {str(name) for name in names if isinstance(name, str) and "/" not in name and name not in ("", ".", "..")}


def record_written(out: Path, names) -> None:
    """Add ``names`` (entries of ``out``) to the record of what fenics-drill wrote there."""
    names = {Path(name).name for name in names} - {LOCK_NAME, WRITTEN_RECORD}
    known = recorded_names(out)
    if not (out / WRITTEN_RECORD).is_file() and (kind := directory_kind(out)) is not None:
        known = {name for name in owned_names_without_record(out, kind)}  # a directory written before the record
    if names - known or not (out / WRITTEN_RECORD).is_file():
        write_json(out / WRITTEN_RECORD, {"files": sorted(known | names)})


def owned_names_without_record(out: Path, command: str) -> set[str]:
    """What ``command`` wrote in a directory written before the record existed: its outputs by their exact names,
    and the figures ``figures.json`` lists."""
    names = {name for name in OWNED[command] if (out / name).exists()}
    try:
        if (out / FIGURE_RECORD).is_file():
            names |= {Path(str(n)).name for n in read_json(out / FIGURE_RECORD).get("figures", [])}
    except UnreadableFile:
        pass
    return names


def owned_paths(out: Path, command: str) -> list[Path]:
    """The files and folders of ``out`` that ``command`` wrote: the record's (module doc), or, in a directory
    without one, the command's outputs by their exact names and the figures ``figures.json`` lists; and their
    temporary files."""
    names = recorded_names(out) if (out / WRITTEN_RECORD).is_file() else owned_names_without_record(out, command)
    paths = {out / name for name in names if (out / name).exists()}
    paths |= {p for p in out.iterdir() if (m := TEMPORARY.match(p.name)) and m["name"] in names}
    return sorted(paths)


def _foreign(out: Path, command: str | None) -> list[Path]:
    """Entries of ``out`` that no command owns (hidden files aside)."""
    mine = set(owned_paths(out, command)) if command else set()
    return [p for p in out.iterdir() if not p.name.startswith(".") and p not in mine]


class OutputClaim:
    """An output directory held by this process: the lock stays until :meth:`release` or exit."""

    def __init__(self, out: Path, command: str, lock_file):
        self.out, self.command, self._lock = out, command, lock_file

    def __enter__(self) -> "OutputClaim":
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def release(self) -> None:
        """Give the directory back, removing the lock file (idempotent; a claim without a lock, as on MPI ranks
        > 0, holds nothing)."""
        if self._lock is None:
            return
        (self.out / LOCK_NAME).unlink(missing_ok=True)  # before unlocking: see _lock for the race
        fcntl.flock(self._lock, fcntl.LOCK_UN)
        self._lock.close()
        self._lock = None


def _lock(out: Path):
    """The exclusive lock of ``out``: its lock file, opened and locked.  A holder removes the file before it
    unlocks, so a lock taken on a file that is no longer the one at the path is let go and taken again."""
    path = out / LOCK_NAME
    while True:
        try:
            handle = open(path, "a+")
        except OSError as err:
            raise OutputError(f"--out {out} is not writable: {err.strerror}") from err
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as err:
            handle.seek(0)
            holder = handle.read().strip() or "unknown"
            handle.close()
            raise OutputError(f"--out {out} is in use by another fenics-drill process (pid {holder}): wait for "
                              "it or choose another --out") from err
        try:
            current = os.stat(path).st_ino
        except FileNotFoundError:
            current = None
        if current == os.fstat(handle.fileno()).st_ino:
            break
        fcntl.flock(handle, fcntl.LOCK_UN)
        handle.close()
    handle.seek(0)
    handle.truncate()
    handle.write(str(os.getpid()))
    handle.flush()
    return handle


def claim_output(out: str | Path, command: str, overwrite: bool = False, resume: bool = False,
                 record: dict | None = None) -> OutputClaim:
    """Take ``out`` for ``command`` under the policy of this module; write the "running" summary
    (with ``record`` added).  ``resume`` (studies only) keeps what an earlier run of the study wrote."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out} is a file, not a directory: choose a directory")
    if resume and not (out.is_dir() and directory_kind(out) == command):
        raise OutputError(f"--resume: --out {out} holds no 'fenics-drill {command}' study to continue; drop "
                          "--resume to start one")
    created_dir = not out.exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(f"cannot create --out {out}: {err.strerror}") from err
    created_lock = not (out / LOCK_NAME).exists()
    try:
        lock = _lock(out)
    except OutputError:  # in use (the lock is the other process's) or not writable (no lock was made)
        _leave_nothing(out, created_dir, created_lock=False)
        raise
    try:
        kind = directory_kind(out)
        if kind is not None and kind != command:
            raise OutputError(f"--out {out} holds {DESCRIPTION[kind]} ('fenics-drill {kind}'); 'fenics-drill "
                              f"{command}' never writes into another command's directory: choose another --out")
        foreign = _foreign(out, kind)
        if foreign:
            names = ", ".join(p.name for p in foreign[:5])
            raise OutputError(f"--out {out} holds files that are not fenics-drill output ({names}): choose an "
                              "empty or new directory")
        if kind == command and not resume:
            if not overwrite:
                remedy = " or --resume to continue it" if command in ("mc", "optimize") else ""
                raise OutputError(f"--out {out} already holds {DESCRIPTION[kind]}: add --overwrite to replace "
                                  f"it{remedy}, or choose another --out")
            for path in owned_paths(out, command):
                shutil.rmtree(path) if path.is_dir() else path.unlink()
        remove_figures(out)
        record_written(out, [name for name in OWNED[command] if not (out / name).exists()])  # named before they exist
        write_json(out / "summary.json", {"command": command, "status": "running", "pid": os.getpid(),
                                          "host": socket.gethostname(),
                                          "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), **(record or {})})
    except BaseException:
        fcntl.flock(lock, fcntl.LOCK_UN)
        lock.close()
        _leave_nothing(out, created_dir, created_lock)
        raise
    return OutputClaim(out, command, lock)


def _leave_nothing(out: Path, created_dir: bool, created_lock: bool) -> None:
    """After a refusal: remove the lock file this command created, and the directory if it created it and it is
    empty, so that a refused command leaves the user's directory as it was."""
    if created_lock:
        (out / LOCK_NAME).unlink(missing_ok=True)
        if created_dir:
            (out / WRITTEN_RECORD).unlink(missing_ok=True)
    if created_dir:
        try:
            out.rmdir()
        except OSError:
            pass
