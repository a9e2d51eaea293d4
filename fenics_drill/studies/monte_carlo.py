"""``fenics-drill mc``: Monte Carlo over the random bit-rock laws (Sections 5 and 6.11).

Every process prepares the scene once (model and static equilibrium:
:func:`fenics_drill.studies.prepare.prepare`; neither depends on the bit-rock
parameters), then runs its share of the realisations: realisation k on rank k mod P,
with parameters drawn from ``default_rng([seed, k])``.  Each finished realisation is
written at once (:mod:`fenics_drill.io.realisations`); ``--resume`` skips those
present.  When all are done, rank 0 reads them in index order and writes the
statistics (:mod:`fenics_drill.studies.statistics`), so the result does not depend
on the number of processes.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from fenics_drill.io.files import UnreadableFile, usable_result
from fenics_drill.io.realisations import NOMINAL, read_realisation, realisation_path, write_realisation
from fenics_drill.io.study_directory import all_done, claim, polled_barrier, stopped_rank
from fenics_drill.model.resources import check_memory
from fenics_drill.scene import MAX_SAMPLES, SceneError, check_history_grid
from fenics_drill.studies.lifecycle import stop_if_requested, study_run
from fenics_drill.studies.prepare import prepare, run_realisation
from fenics_drill.studies.statistics import write_statistics
from fenics_drill.studies.uncertainty import BitRockLaws


def _progress(out: Path, samples: int, started: float, done_at_start: int) -> None:
    files = sorted((out / "realisations").glob("*.h5"))
    done = len(files)
    q_norms = []
    for path in files:
        try:
            q_norms.append(read_realisation(path, histories=False)["q_norm_integral"])
        except UnreadableFile:
            pass  # being replaced by --resume, or named when the statistics are assembled
    metric = np.sqrt(sum(q_norms) / len(q_norms)) if q_norms else float("nan")
    rate = (done - done_at_start) / (time.perf_counter() - started)
    eta = (samples - done) / rate if rate > 0 else float("nan")
    sys.stderr.write(f"\r  realisations {done:5d} / {samples}  conv_MC {metric:.6e}  eta {eta:8.0f} s ")
    sys.stderr.flush()


def monte_carlo(scene, samples: int, out: str | Path, resume: bool = False, progress: bool = True,
                comm=MPI.COMM_WORLD, overwrite: bool = False) -> dict | None:
    """Run (or finish) the study; rank 0 returns the summary, the other ranks None."""
    if isinstance(samples, bool) or not isinstance(samples, int) or not 1 <= samples <= MAX_SAMPLES:
        raise SceneError(f"the number of realisations (--samples) {samples!r} is not admissible: must be an integer in "
                         f"[1, {MAX_SAMPLES}]")
    out = Path(out)
    laws = BitRockLaws(scene.bit_rock, scene.uncertainty)  # refuses inadmissible laws
    check_history_grid(scene)
    check_memory(scene.beam.elements, scene.beam.element_degree)
    def counts() -> dict:
        return {"samples": samples, "realisations_done": len(list((out / "realisations").glob("*.h5")))}

    with claim(out, scene.to_dict(), "mc", resume, overwrite, comm, counts), study_run(out, "mc", comm, counts):
        if comm.rank == 0:
            (out / "realisations").mkdir(exist_ok=True)
        polled_barrier(comm)
        prepared = prepare(scene)
        if comm.rank == 0 and not usable_result(out / NOMINAL, read_realisation):
            write_realisation(out / NOMINAL, run_realisation(prepared, scene))
        done_at_start = len(list((out / "realisations").glob("*.h5")))
        started = time.perf_counter()
        for k in range(comm.rank, samples, comm.size):
            stop_if_requested()
            if (stop := stopped_rank(out, comm.rank)) is not None:
                raise stop
            path = realisation_path(out, k)
            if usable_result(path, read_realisation):
                continue
            write_realisation(path, run_realisation(prepared, scene.with_changes(bit_rock=laws.sample(k))))
            if progress and comm.rank == 0:
                _progress(out, samples, started, done_at_start)
        if not all_done(out, comm, progress):
            return None
        return write_statistics(out, samples)
