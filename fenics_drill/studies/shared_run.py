"""One run on two MPI ranks: ``mpiexec -n 2 fenics-drill run SCENE --out DIR``.

Both ranks read the scene, build the model and solve its static equilibrium alike; then a full-order string is
split between them at the vertex that halves its elements (:meth:`~fenics_drill.model.drillstring.DrillstringModel.
split_over`): each assembles its own half's internal force and tangent, and the saddle system (76) of every Newton
update is solved across both (:mod:`~fenics_drill.model.kernels.split_band`).  Every rank holds the whole state
and takes the same steps; the first writes the files and the summary, the other writes nothing.  A reduced
(modal) model, which runs near real time on one core, is not split: the first rank runs it alone.

A signal on any rank stops both after the same step (a ``collective`` :class:`~fenics_drill.studies.lifecycle.
StopOnSignal`: the ranks exchange it after the set-up and after every step); an error on one rank alone ends the job (the command line's MPI_Abort).
"""

from __future__ import annotations

import zlib

import numpy as np

from fenics_drill.model.internal_force import AssembledInternalForce, LateralZoneInternalForce
from fenics_drill.solvers.static import StaticFailure
from fenics_drill.solvers.step_control import RunFailure
from fenics_drill.solvers.time_loop import Simulation
from fenics_drill.studies.lifecycle import StopOnSignal, agree_to_stop, uninterrupted
from fenics_drill.studies.prepare import prepare


class RankCountError(ValueError):
    """A run started on more ranks than it can share."""


def check_ranks(comm) -> None:
    """A run shares its string over one or two ranks (RankCountError otherwise; every rank raises it alike)."""
    if comm.size > 2:
        raise RankCountError(f"a run shares its string over 1 or 2 MPI ranks, not {comm.size} (mpiexec -n 2); "
                             "mc and optimize spread their runs over any number of ranks")


def why_not_split(model) -> str | None:
    """Why ``model`` is run by the first rank alone, or None when its string is split between the ranks."""
    if not model.space.sparse:
        return "a reduced (modal) model runs on one rank"
    if not isinstance(model.internal, (AssembledInternalForce, LateralZoneInternalForce)):
        return "a linear model (both nonlinearities off) runs on one rank"
    return None


def shared_model(model, comm):
    """(the model the ranks step together, the summary's ``ranks`` entry): the string split between them, or the
    model the first rank runs alone, with why (every rank decides alike)."""
    why = why_not_split(model)
    if why is None:
        try:
            return model.split_over(comm), {"ranks": comm.size, "split": True}
        except ValueError as refused:
            why = str(refused)
    return model, {"ranks": comm.size, "split": False, "why": why}


def check_same_state(comm, q: np.ndarray) -> None:
    """Every rank starts from the same state, bit for bit (their steps must agree to meet in the same collectives)."""
    sums = comm.allgather(zlib.crc32(np.ascontiguousarray(q).tobytes()))
    if len(set(sums)) != 1:
        raise RuntimeError("the ranks' static states differ: their set-ups did not compute alike")


def second_rank_run(scene, comm, refused: str | None) -> dict:
    """A rank other than the first: the set-up, then its half of every step; it writes nothing.  ``refused``: why
    the first rank could not take the output directory (then nothing is done)."""
    if refused is not None:
        return {"status": "failed", "message": refused}
    summary = {"status": "failed", "message": ""}
    with StopOnSignal(collective=True):
        try:
            prepared = prepare(scene)
            agree_to_stop(comm)
            model, report = shared_model(prepared.model, comm)
            if not report["split"]:
                return {"status": "finished", "message": f"the first rank ran it alone: {report['why']}"}
            simulation = Simulation(model, scene)
            start = simulation.initial_state(prepared.equilibrium.q)
            check_same_state(comm, start.q)
            simulation.run(start, scene.time.t_end, atomic=lambda: uninterrupted(comm=comm))
            summary.update(status="finished", message="reached time.t_end")
        except RunFailure as failure:
            summary["message"] = str(failure)
        except StaticFailure as failure:
            summary["message"] = f"at t = 0 s: {failure}"
        except KeyboardInterrupt:
            summary.update(status="interrupted", message="stopped by Ctrl-C or SIGTERM")
    return summary
