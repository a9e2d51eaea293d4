"""Static correction of a truncated modal basis for the loads at the bit (modal truncation
augmentation).

A basis of the lowest modes reproduces a load's dynamic response but not the
quasi-static deflection owed to the modes left out: for a point force at the tip of a
bar, the axial modes with f* <= 4 carry only 95 % of the static tip displacement
(benchmarks/dynamics_convergence.md).  The bit-rock force (20) and torque (21) are
such point loads, so the basis is augmented with the static responses to a unit
axial force and a unit torque at x = L, the drive end u(0), theta_x(0) held (where
the multipliers hold it), M-orthogonalised against the modes and M-normalised.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fenics_drill.model.discretization import THETA_X, U, BeamDiscretization
from fenics_drill.model.operators import LinearOperators


def bit_load_responses(disc: BeamDiscretization, operators: LinearOperators) -> np.ndarray:
    """K^-1 of a unit axial force and a unit torque at x = L, supports and drive end fixed: (ndofs, 2)."""
    fixed = np.union1d(disc.support_dofs, [disc.end_dof(U, 0), disc.end_dof(THETA_X, 0)])
    free = np.setdiff1d(np.arange(disc.ndofs), fixed)
    K = sp.csc_matrix(operators.stiffness[free][:, free])
    loads = np.zeros((disc.ndofs, 2))
    loads[disc.end_dof(U, 1), 0] = 1.0
    loads[disc.end_dof(THETA_X, 1), 1] = 1.0
    responses = np.zeros_like(loads)
    responses[free] = spla.splu(K).solve(loads[free])
    return responses


def augment(phi: np.ndarray, vectors: np.ndarray, mass: sp.spmatrix) -> np.ndarray:
    """[Phi, V'] with V' the part of ``vectors`` M-orthogonal to [Phi], M-normalised (Gram-Schmidt twice)."""
    basis = phi
    for v in vectors.T:
        for _ in range(2):
            v = v - basis @ (basis.T @ (mass @ v))
        basis = np.column_stack([basis, v / np.sqrt(v @ (mass @ v))])
    return basis
