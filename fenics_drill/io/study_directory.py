"""The output directory of a study spread over MPI ranks (``fenics-drill mc`` and ``optimize``).

Rank 0 takes the directory under the common policy (:mod:`fenics_drill.io.output_directory`)
and checks, on ``--resume``, that ``scene.json`` is the scene being run, so that a study
continues itself and nothing else; every rank then sees the same verdict, so a refusal ends
all of them alike.  One result file per task, each written whole (:mod:`fenics_drill.io.files`),
so a killed study leaves only whole results.

No rank ever waits inside a blocking MPI call for another: a rank that stopped (Ctrl-C, SIGTERM, an error)
would leave the others there for ever, deaf to signals.  At the start the ranks wait for rank 0's verdict on
the directory in a non-blocking barrier tested with pauses (:func:`polled_barrier`); at the end each rank
leaves a marker in ``.ranks/`` saying how it ended, and waits for the others' markers: a rank that stopped
stops them all (:class:`RankStopped`).
"""

from __future__ import annotations

import json
import shutil
import sys
import time
from pathlib import Path

from fenics_drill.io.files import UnreadableFile, read_json, write_json
from fenics_drill.io.output_directory import OutputClaim, OutputError, claim_output

#: Hidden folder of the rank markers: ``<rank>.json`` with the rank's status and message.
RANKS = ".ranks"
#: Seconds between two tests of a pending barrier (and reads of the markers).
POLL_SECONDS = 0.05


class RankStopped(Exception):
    """Another rank of the study stopped (interrupted or failed); the message names it and says why."""

    def __init__(self, rank: int, status: str, message: str):
        super().__init__(f"rank {rank} {status}: {message}" if message else f"rank {rank} {status}")
        self.rank, self.status, self.reason = rank, status, message


def mark_rank(out: Path, rank: int, status: str, message: str = "") -> None:
    """Leave this rank's marker: ``finished``, ``interrupted`` or ``failed`` with its message."""
    (out / RANKS).mkdir(exist_ok=True)
    write_json(out / RANKS / f"{rank}.json", {"rank": rank, "status": status, "message": message})


def stopped_rank(out: Path, rank: int) -> RankStopped | None:
    """The first other rank whose marker says it stopped (interrupted or failed), if any."""
    for path in sorted((out / RANKS).glob("*.json")):
        try:
            marker = read_json(path)
        except (UnreadableFile, OSError):
            continue  # being written
        if marker.get("rank") != rank and marker.get("status") in ("interrupted", "failed"):
            return RankStopped(marker["rank"], marker["status"], marker.get("message", ""))
    return None


def polled_barrier(comm, out: Path | None = None) -> None:
    """Wait for every rank, seeing signals while waiting; with ``out``, raise :class:`RankStopped` as soon as
    another rank's marker says it stopped."""
    if comm.size == 1:
        return
    request = comm.Ibarrier()
    while not request.Test():
        time.sleep(POLL_SECONDS)
        if out is not None and (stop := stopped_rank(out, comm.rank)) is not None:
            raise stop


def claim(out: Path, scene: dict, command: str, resume: bool, overwrite: bool, comm, counts=None) -> OutputClaim:
    """On rank 0: take ``out`` for ``command``, refuse another scene's study, record the scene, clear the rank
    markers of an earlier run.  Every rank raises the same OutputError on refusal; each returns its claim
    (rank 0's holds the directory's lock, the others' nothing), to hold to the end of the study.  A study stopped
    while the ranks meet here has its summary say so, with what ``counts()`` says is asked and done."""
    error, held = None, OutputClaim(out, command, None)
    if comm.rank == 0:
        try:
            held = claim_output(out, command, overwrite=overwrite, resume=resume)
            meta = out / "scene.json"
            if meta.exists() and read_json(meta) != json.loads(json.dumps(scene)):
                held.release()
                error = f"--out {out} holds a study of another scene; choose another --out"
            else:
                write_json(meta, scene)
                shutil.rmtree(out / RANKS, ignore_errors=True)
        except (OutputError, UnreadableFile) as err:
            error = str(err)
    try:
        polled_barrier(comm)  # the verdict is ready on rank 0: the broadcast below does not wait
        error = comm.bcast(error, root=0)
    except KeyboardInterrupt:  # stopped before the study began: what rank 0 took says so
        if comm.rank == 0 and error is None:
            write_json(out / "summary.json", {"command": command, "status": "interrupted",
                                              "message": "stopped by Ctrl-C or SIGTERM before the study began",
                                              **(counts() if counts is not None else {})})
        raise
    if error:
        raise OutputError(error)
    return held


def all_done(out: Path, comm, progress: bool) -> bool:
    """This rank has done its share: wait until every rank's marker says so (RankStopped as soon as one says it
    stopped; no MPI call, so no request is left pending if this wait is interrupted); True on rank 0, which then
    assembles the results."""
    mark_rank(out, comm.rank, "finished")
    while len(list((out / RANKS).glob("*.json"))) < comm.size or stopped_rank(out, comm.rank) is not None:
        if (stop := stopped_rank(out, comm.rank)) is not None:
            raise stop
        time.sleep(POLL_SECONDS)
    if comm.rank != 0:
        return False
    if progress:
        sys.stderr.write("\n")
    return True
