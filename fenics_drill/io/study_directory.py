"""The output directory of a study spread over MPI ranks (``fenics-drill mc`` and ``optimize``).

Rank 0 takes the directory under the common policy (:mod:`fenics_drill.io.output_directory`)
and checks, on ``--resume``, that ``scene.json`` is the scene being run, so that a study
continues itself and nothing else; every rank then sees the same verdict, so a refusal ends
all of them alike.  One result file per task, each written whole (:mod:`fenics_drill.io.files`),
so a killed study leaves only whole results.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from fenics_drill.io.files import UnreadableFile, read_json, write_json
from fenics_drill.io.output_directory import OutputClaim, OutputError, claim_output


def claim(out: Path, scene: dict, command: str, resume: bool, overwrite: bool, comm) -> OutputClaim:
    """On rank 0: take ``out`` for ``command``, refuse another scene's study, record the scene.  Every rank
    raises the same OutputError on refusal; each returns its claim (rank 0's holds the directory's lock,
    the others' nothing), to hold to the end of the study."""
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
        except (OutputError, UnreadableFile) as err:
            error = str(err)
    error = comm.bcast(error, root=0)
    if error:
        raise OutputError(error)
    return held


def all_done(comm, progress: bool) -> bool:
    """Wait for every rank; True on rank 0, which then assembles the results."""
    comm.Barrier()
    if comm.rank != 0:
        return False
    if progress:
        sys.stderr.write("\n")
    return True
