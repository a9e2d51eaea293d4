"""Assembly of the linear operators M, C, K and the gravity load F_G (Eqs. 44-46, 52), and of the initial-stress
stiffness of a prestressed state."""

from __future__ import annotations

from dataclasses import dataclass

import dolfinx.fem.petsc as fem_petsc
import numpy as np
import scipy.sparse as sp
import ufl
from dolfinx import fem
from petsc4py import PETSc

from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.kernels.compiled import form as compiled_form
from fenics_drill.forms import damping_form, geometric_stiffness_form, gravity_form, mass_form, stiffness_form


def petsc_to_scipy(A: PETSc.Mat) -> sp.csr_matrix:
    """Copy an assembled (serial) PETSc AIJ matrix into a SciPy CSR matrix."""
    indptr, indices, data = A.getValuesCSR()
    return sp.csr_matrix((data.copy(), indices.copy(), indptr.copy()), shape=A.getSize())


@dataclass
class LinearOperators:
    """Free-free M, C, K (SciPy CSR) and gravity load vector of one discretization."""

    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix
    gravity: np.ndarray


def _forms(disc: BeamDiscretization):
    U, psi = ufl.TrialFunction(disc.V), ufl.TestFunction(disc.V)
    dx = ufl.Measure("dx", domain=disc.mesh)
    p, numbers = disc.form_properties, disc.properties  # what the forms take; the switches read numbers
    return (
        compiled_form(mass_form(p, psi, U, dx)),
        compiled_form(damping_form(p, psi, U, dx)) if numbers.damping != 0 or numbers.lateral_fluid_damping != 0 else None,
        compiled_form(stiffness_form(p, psi, U, dx)),
        compiled_form(gravity_form(p, psi, dx)) if numbers.gravity != 0 else None,  # g = 0: UFL's zero form
    )


def assemble_linear(disc: BeamDiscretization) -> LinearOperators:
    """Assemble the free-free operators (no support conditions applied)."""
    m, c, k, g = _forms(disc)

    def mat(a):
        if a is None:
            return sp.csr_matrix((disc.ndofs, disc.ndofs))
        A = fem_petsc.assemble_matrix(a)
        A.assemble()
        return petsc_to_scipy(A)

    gravity = np.zeros(disc.ndofs)
    if g is not None:
        b = fem_petsc.assemble_vector(g)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        gravity = b.array.copy()
    return LinearOperators(mat(m), mat(c), mat(k), gravity)


def assemble_geometric_stiffness(disc: BeamDiscretization, displacement: np.ndarray) -> sp.csr_matrix:
    """The initial-stress stiffness of the axial force of the full-space ``displacement`` (free-free, SciPy CSR;
    :func:`~fenics_drill.forms.linear.geometric_stiffness_form`)."""
    state = fem.Function(disc.V)
    state.x.array[:] = displacement
    U, psi = ufl.TrialFunction(disc.V), ufl.TestFunction(disc.V)
    dx = ufl.Measure("dx", domain=disc.mesh)
    A = fem_petsc.assemble_matrix(compiled_form(geometric_stiffness_form(disc.form_properties, psi, U, state, dx)))
    A.assemble()
    return petsc_to_scipy(A)


def assemble_modal_pair(disc: BeamDiscretization, held: tuple = (),
                        stiffness: sp.spmatrix | None = None) -> tuple[PETSc.Mat, PETSc.Mat]:
    """K and M for the modal problem (62), support dofs (and the ``held`` (field, end) pairs) as
    Dirichlet rows; K is the stiffness (46), or ``stiffness`` (SciPy, on every dof: a tangent stiffness about a
    loaded state).

    K gets 1 and M gets 0 on the diagonal of each constrained row/column, so the
    constrained dofs carry infinite eigenvalues that shift-and-invert never finds.
    """
    m, _, k, _ = _forms(disc)
    bcs = disc.support_bcs(held)
    if stiffness is None:
        K = fem_petsc.assemble_matrix(k, bcs=bcs, diag=1.0)
        K.assemble()
    else:
        constrained = np.concatenate([disc.support_dofs, [disc.end_dof(f, end) for f, end in held]]).astype(int)
        free = np.ones(disc.ndofs)
        free[constrained] = 0.0
        keep = sp.diags(free)
        A = (keep @ sp.csr_matrix(stiffness) @ keep + sp.diags(1.0 - free)).tocsr()
        A.sort_indices()
        K = PETSc.Mat().createAIJ(A.shape, csr=(A.indptr, A.indices, A.data), comm=disc.comm)
    M = fem_petsc.assemble_matrix(m, bcs=bcs, diag=0.0)
    M.assemble()
    return K, M


def field_mass_fractions(mass: sp.csr_matrix, field_of_dof: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """Kinetic-energy fraction of each field in each column of ``vectors``.

    M couples no two fields (Eq. 44), so phi^T M phi splits exactly into the six
    per-field sums phi_i^T M_ii phi_i. Returns an array (n_vectors, 6).
    """
    weighted = vectors * (mass @ vectors)
    per_field = np.stack([weighted[field_of_dof == i].sum(axis=0) for i in range(6)], axis=1)
    total = per_field.sum(axis=1, keepdims=True)
    return per_field / np.where(total > 0, total, 1.0)
