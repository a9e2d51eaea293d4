"""fenics-drill: nonlinear dynamics of horizontal drillstrings on FEniCSx.

The public API (see :mod:`fenics_drill.api`)::

    import fenics_drill as fd
    scene = fd.load_scene("demos/scenes/paper.toml", ["time.t_end=1"])
    run = fd.run(scene)          # run.summary, run.series (xarray.Dataset)

``dolfinx_solver`` must be imported before ``dolfinx`` and ``petsc4py`` so that
the real-scalar PETSc/SLEPc of the ``dolfinx-solver-real`` wheel is the one
loaded; importing this package does that once for every module below it.

The dense algebra of a reduced model works on 44 x 44 matrices and 4006 x 44
bases: threaded BLAS only adds overhead there, and two runs (or MPI ranks) on a
2-core machine then oversubscribe it (measured: 113 s against 50 s for the
nominal 10 s run).  So one BLAS thread per process unless the user says otherwise.
"""

import os

for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

try:
    import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py)
    # h5py must be loaded before dolfinx.fem.petsc, whose HDF5 1.14 would otherwise be the one h5py finds
    # ("Not a datatype" at import): a notebook may import any module of the package first.
    import h5py  # noqa: F401
except KeyboardInterrupt:
    # A Ctrl-C while the libraries load (a second or two): the command-line tool ends with one line, as it does
    # once running; anywhere else (a notebook) the interrupt goes on as usual.
    import sys

    if os.path.basename(sys.argv[0]) in ("fenics-drill", "-m", "cli.py"):
        sys.stderr.write("fenics-drill: interrupted\n")
        sys.stderr.flush()
        os._exit(130)
    raise

from fenics_drill.scene import Scene, SceneError, load_scene  # noqa: E402
from fenics_drill.units import UnitError, read_quantity  # noqa: E402  (a drilling value in SI: "8 1/2 in" -> m)

__version__ = "0.2.0"

#: The API functions, imported on first use (``fenics-drill scene`` needs none of DOLFINx).
_API = ("RunResult", "modal_analysis", "static_state", "run", "monte_carlo", "operating_window", "campbell", "TorqueDragResult",
        "torque_drag", "plot")

__all__ = ["Scene", "SceneError", "load_scene", "UnitError", "read_quantity", *_API]


def __getattr__(name: str):
    if name in _API:
        from fenics_drill import api

        return getattr(api, name)
    raise AttributeError(f"module 'fenics_drill' has no attribute {name!r}")
