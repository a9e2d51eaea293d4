"""The output directory of a study spread over MPI ranks (``fenics-drill mc`` and ``optimize``).

One result file per task, each written through a temporary file renamed into place, so a
killed study leaves only whole results; a ``scene.json`` beside them says which scene they
belong to, so that ``--resume`` continues that study and nothing else.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path


def claim(out: Path, scene: dict, results: str, pattern: str, resume: bool, comm) -> None:
    """On rank 0: create ``out/results``, refuse another scene's study or an existing one without
    ``resume``, record the scene.  Every rank raises ValueError with the same message on refusal."""
    error = None
    if comm.rank == 0:
        (out / results).mkdir(parents=True, exist_ok=True)
        meta = out / "scene.json"
        done = len(list((out / results).glob(pattern)))
        if meta.exists() and json.loads(meta.read_text()) != json.loads(json.dumps(scene)):
            error = f"{out} holds a study of another scene; choose another --out"
        elif done and not resume:
            error = f"{out} already holds {done} results: add --resume to continue that study, or choose another --out"
        else:
            meta.write_text(json.dumps(scene, indent=1))
    error = comm.bcast(error, root=0)
    if error:
        raise ValueError(error)


def write_atomic(path: Path, write) -> None:
    """``write(tmp)`` a temporary file beside ``path``, then rename it into place."""
    tmp = path.with_suffix(f".tmp{os.getpid()}")
    write(tmp)
    os.replace(tmp, path)


def all_done(comm, progress: bool) -> bool:
    """Wait for every rank; True on rank 0, which then assembles the results."""
    comm.Barrier()
    if comm.rank != 0:
        return False
    if progress:
        sys.stderr.write("\n")
    return True
