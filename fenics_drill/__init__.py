"""fenics-drill: nonlinear dynamics of horizontal drillstrings on FEniCSx.

``dolfinx_solver`` must be imported before ``dolfinx`` and ``petsc4py`` so that
the real-scalar PETSc/SLEPc of the ``dolfinx-solver-real`` wheel is the one
loaded; importing this package does that once for every module below it.
"""

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py)

__version__ = "0.1.0"
