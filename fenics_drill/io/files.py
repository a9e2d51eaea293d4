"""Files that are whole or absent: every file of a run or study is written to a temporary name beside
its place and renamed into it (atomic on POSIX), so a kill at any moment leaves the old version or the
new one, never half of one.  JSON goes through here, with one reader that names a broken file."""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
from pathlib import Path


class UnreadableFile(ValueError):
    """A file that exists but cannot be read (truncated, corrupt, not ours); the message names it."""


def temporary_path(path: Path) -> Path:
    """The temporary name beside ``path`` that :func:`write_atomic` writes first."""
    return path.with_name(f".{path.name}.tmp{os.getpid()}")


def write_atomic(path: Path, write) -> None:
    """``write(tmp)`` a temporary file beside ``path``, then rename it into place."""
    path = Path(path)
    tmp = temporary_path(path)
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_json(path: Path, data: dict) -> None:
    """Write ``data`` as indented JSON (NumPy scalars as floats), atomically."""
    text = json.dumps(data, indent=1, default=float)
    write_atomic(Path(path), lambda tmp: tmp.write_text(text))


def read_json(path: Path) -> dict:
    """The JSON object of ``path``; :class:`UnreadableFile` naming it if it is not valid JSON."""
    try:
        return json.loads(Path(path).read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise UnreadableFile(f"{path} is not a readable JSON file (truncated or corrupt?): {err}") from err


def usable_result(path: Path, read) -> bool:
    """Whether a study's result file is there and whole (``read(path)`` succeeds).  One that is there but
    unreadable (truncated by a crash of the disk or the machine) is renamed ``*.corrupt``, said on stderr
    with its name, and counted as not done, so the study computes it again."""
    if not path.exists():
        return False
    try:
        read(path)
        return True
    except UnreadableFile as err:
        aside = path.with_name(path.name + ".corrupt")
        os.replace(path, aside)
        print(f"fenics-drill: {err}; moved to {aside.name} and computed again", file=sys.stderr)
        return False


def update_hdf5(path: Path, update) -> None:
    """Apply ``update(h5py.File)`` to a copy of the HDF5 file ``path`` and rename the copy into place: a
    kill during the update leaves the previous whole file.  The copy costs one read of the file, which
    :class:`FlushClock` keeps to a small share of the run."""
    import h5py

    def write(tmp: Path) -> None:
        shutil.copyfile(path, tmp)
        with h5py.File(tmp, "a") as f:
            update(f)

    write_atomic(path, write)


class FlushClock:
    """When to write buffered output: every ``seconds`` of wall time, stretched so that writing takes at
    most ``share`` of the run (an update copies the whole file, which grows with the run)."""

    def __init__(self, seconds: float = 2.0, share: float = 0.05):
        self.seconds, self.share = seconds, share
        self.interval = seconds
        self.last = time.monotonic()

    def due(self) -> bool:
        return time.monotonic() - self.last >= self.interval

    def wrote(self, duration: float) -> None:
        """Record a write that took ``duration`` seconds; the next is due after the stretched interval."""
        self.interval = max(self.seconds, duration / self.share)
        self.last = time.monotonic()


#: errno of the ways a write finds no room: no space left, quota exceeded, file beyond the size limit.
_NO_ROOM = {28: "the disk is full (no space left on the device)", 122: "the disk quota is exceeded",
            27: "a file reached the size limit (ulimit -f)"}


def no_room_message(err: BaseException) -> str | None:
    """A one-line reason if ``err`` (or an error it was raised from) is a write that found no room on the disk;
    None otherwise.  HDF5's errors carry the errno only in their text."""
    seen = set()
    while err is not None and id(err) not in seen:
        seen.add(id(err))
        if isinstance(err, OSError) and err.errno in _NO_ROOM:
            return _NO_ROOM[err.errno]
        if isinstance(err, (OSError, RuntimeError)):  # h5py raises RuntimeError when HDF5 cannot close a file
            text = str(err)
            for code, reason in _NO_ROOM.items():
                if f"errno = {code}," in text or os.strerror(code) in text:
                    return reason
        err = err.__cause__ or err.__context__
    return None


def write_final_json(path: Path, data: dict, keep: tuple[str, ...] = ("command", "status", "message")) -> bool:
    """Write a command's final ``summary.json`` whatever the disk: atomically if there is room, else the ``keep``
    keys alone written over the old file in place (truncating it frees its blocks, so a few bytes fit where a
    second file does not).  False if even that failed."""
    try:
        write_json(path, data)
        return True
    except Exception as err:
        if no_room_message(err) is None:
            raise
    try:
        with open(path, "r+" if Path(path).exists() else "w") as f:
            f.truncate(0)
            f.write(json.dumps({key: data.get(key) for key in keep}, default=float))
        return True
    except OSError:
        return False
