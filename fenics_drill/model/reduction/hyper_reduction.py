"""Hyper-reduction of the nonlinear internal forces: energy-conserving sampling and weighting (ECSW).

A reduced model still assembles F_KE and F_SE (48)-(49) on every element to project them on
[Phi]: its cost scales with the mesh.  ECSW (Farhat, Avery, Chapman & Cortial 2014, "Dimensional
reduction of nonlinear finite element dynamic models with finite rotations and energy-based mesh
sampling and weighting for computational efficiency", IJNME 98) replaces the sum over the
elements by a sum over a sample E with weights xi_e >= 0,

    [Phi]^T f_nl(Phi q)  ~  sum_{e in E} xi_e [Phi_e]^T f_nl,e(Phi_e q),

chosen so that the projected element forces of training states are reproduced to a relative
``tolerance`` (a sparse non-negative least-squares problem, solved greedily by Lawson & Hanson's
active set, stopped at the tolerance).  With positive weights the forces remain the gradients of
the weighted element energies, so the sampled model conserves energy as the full one does.

The training states are the states of a short run of the unsampled reduced model, each also
turned through a revolution of the spin (theta_x shifted by 2 pi k / n_spin): a drilling string
turns, and the nonlinear forces depend on the spin angle through its sine and cosine.  During a
run the sample is checked against all elements every CHECK_INTERVAL (the error indicator); a state
it misses by more than RETRAIN_ABOVE joins the training states and the sample is trained again.
"""

from __future__ import annotations

import numpy as np

from fenics_drill.model.discretization import THETA_X, BeamDiscretization
from fenics_drill.model.internal_force import AssembledInternalForce, ElementSample

#: Spin angles per training state: the forces are trigonometric polynomials of low degree in theta_x.
SPIN_SHIFTS = 6
#: Simulated time between two checks of a sample against all elements during a run [s].
CHECK_INTERVAL = 0.1
#: A check finding the sampled nonlinear force further than this from all elements' retrains the sample
#: with that state added [-].
RETRAIN_ABOVE = 0.01


#: A weight below this share of the largest is round-off (a column the active set took, then found no use
#: for): it is dropped, and its element is not sampled.
NEGLIGIBLE_WEIGHT = 1e-12


def sparse_nnls(G: np.ndarray, b: np.ndarray, tolerance: float, max_columns: int | None = None) -> np.ndarray:
    """x >= 0 with few non-zeros and ||G x - b|| <= tolerance ||b||: Lawson & Hanson's active-set NNLS
    (1974, ch. 23), stopped as soon as the residual is within the tolerance (Farhat et al. 2014)."""
    n = G.shape[1]
    max_columns = n if max_columns is None else max_columns
    x = np.zeros(n)
    passive = np.zeros(n, dtype=bool)
    target = tolerance * np.linalg.norm(b)
    residual = b.copy()
    while np.linalg.norm(residual) > target and passive.sum() < max_columns:
        gradient = G.T @ residual
        gradient[passive] = -np.inf
        j = int(np.argmax(gradient))
        if gradient[j] <= 0:
            break
        passive[j] = True
        while True:
            columns = np.flatnonzero(passive)
            z = np.zeros(n)
            z[columns] = np.linalg.lstsq(G[:, columns], b, rcond=None)[0]
            if np.all(z[columns] > 0):
                x = z
                break
            negative = columns[z[columns] <= 0]
            step = np.min(x[negative] / (x[negative] - z[negative]))
            x = x + step * (z - x)
            passive &= x > NEGLIGIBLE_WEIGHT * max(x.max(), 1e-300)
            x[~passive] = 0.0
        residual = b - G @ x
    x[x <= NEGLIGIBLE_WEIGHT * max(x.max(), 1e-300)] = 0.0  # a column taken at round-off weight samples nothing
    return x


def spin_shift(disc: BeamDiscretization, space) -> np.ndarray:
    """Reduced coordinates of a unit rigid spin (theta_x = 1 everywhere): the basis holds the rigid modes."""
    rigid = np.zeros(disc.ndofs)
    rigid[disc.field_dofs[THETA_X]] = 1.0
    return np.linalg.lstsq(space.phi, rigid, rcond=None)[0]


def element_forces(disc: BeamDiscretization, space, operators, model_switches, states) -> np.ndarray:
    """[Phi_e]^T f_nl,e for every element e and training state: (n_states * N_red, n_elements), each element's
    vector as its kernel gives it (every element at unit weight), projected on its rows of [Phi]."""
    cells = np.arange(disc.elements, dtype=np.int32)
    trainer = AssembledInternalForce(disc, space, operators, *model_switches,
                                     sample=ElementSample(cells, np.ones(cells.size)))
    phi_cells = space.phi[disc.V.dofmap.list[cells]]  # (n_elements, dofs per cell, N_red)
    out = np.zeros((len(states) * space.size, disc.elements))
    for k, (q, qd, qdd) in enumerate(states):
        vectors = trainer.element_vectors(q, qd, qdd)  # (n_elements, dofs per cell)
        out[k * space.size:(k + 1) * space.size] = np.einsum("edn,ed->ne", phi_cells, vectors)
    return out


def train_sample(disc: BeamDiscretization, space, operators, model_switches, states, tolerance: float
                 ) -> tuple[ElementSample, dict]:
    """The ECSW sample of the given states (each also turned through SPIN_SHIFTS spin angles) and its
    training report: the relative error it leaves on them, and its size."""
    spin = spin_shift(disc, space)
    turned = [(q + angle * spin, qd, qdd) for q, qd, qdd in states
              for angle in 2.0 * np.pi * np.arange(SPIN_SHIFTS) / SPIN_SHIFTS]
    G = element_forces(disc, space, operators, model_switches, turned)
    # each state's projected force weighs the same: scale its rows by the size of its exact sum
    size = space.size
    for k in range(len(turned)):
        rows = slice(k * size, (k + 1) * size)
        G[rows] /= max(np.linalg.norm(G[rows].sum(axis=1)), 1e-300)
    b = G.sum(axis=1)
    weights = sparse_nnls(G, b, tolerance)
    cells = np.flatnonzero(weights > 0)
    error = float(np.linalg.norm(G @ weights - b) / np.linalg.norm(b))
    report = {"elements": int(cells.size), "of": int(disc.elements), "training_states": len(turned),
              "training_error": error, "tolerance": tolerance}
    return ElementSample(cells.astype(np.int32), weights[cells]), report


def sampling_error(exact: AssembledInternalForce, sampled: AssembledInternalForce, q, qd, qdd) -> float:
    """Error of the sampled internal force at a state, relative to the size of its nonlinear part
    (the part that is sampled): the error indicator of a hyper-reduced run."""
    K, C, M = sampled.linear
    reference = exact.evaluate(q, qd, qdd)
    nonlinear = reference - (K @ q + C @ qd + M @ qdd)
    return float(np.linalg.norm(sampled.evaluate(q, qd, qdd) - reference) / max(np.linalg.norm(nonlinear), 1e-300))
