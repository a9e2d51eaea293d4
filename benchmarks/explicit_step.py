"""The stable step an explicit central-difference integration of the full order would have.

    python benchmarks/explicit_step.py [--lengths 100 3000]

For the paper's cross-section at each length (100 m: the paper's scene, 500 elements; longer: 2 elements per metre),
the largest frequency omega_max of (K, M_lumped), M lumped by rows (positive for these elements), with and without the
wall's linear spring k_FS1 at every vertex (v and w), by Lanczos; the stable step of central differences is
2 / omega_max.  Printed, quoted in docs/performance.md.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import dolfinx_solver  # noqa: E402,F401  (before dolfinx: real PETSc/SLEPc)

from fenics_drill.model.discretization import V, W  # noqa: E402
from fenics_drill.scene import load_scene  # noqa: E402
from fenics_drill.studies.prepare import prepare  # noqa: E402


def largest_frequency(stiffness: sp.spmatrix, lumped_mass: np.ndarray) -> float:
    """omega_max of (K, diag(m)) [rad/s]."""
    scale = sp.diags(1.0 / np.sqrt(lumped_mass))
    return float(np.sqrt(spla.eigsh(scale @ stiffness @ scale, k=1, which="LA", return_eigenvectors=False)[0]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lengths", type=float, nargs="+", default=[100.0, 3000.0])
    args = parser.parse_args()
    for length in args.lengths:
        elements = 500 if length == 100 else int(round(2 * length))
        scene = load_scene(Path(__file__).resolve().parents[1] / "demos" / "scenes" / "paper.toml",
                           [f"beam.length={length:g}", f"beam.elements={elements}", "reduction.rule='none'"])
        model = prepare(scene, dynamics=False).model
        space, disc = model.space, model.disc
        stiffness = space.project_matrix(model.operators.stiffness).tocsr()
        lumped = np.asarray(space.project_matrix(model.operators.mass).sum(axis=1)).ravel()
        if not np.all(lumped > 0):
            raise SystemExit("a row of the mass matrix sums to <= 0: row lumping does not apply")
        springs = np.zeros(space.size)
        for field in (V, W):
            rows = space.position[disc.vertex_dofs(field)]
            springs[rows[rows >= 0]] += scene.contact.stiffness_linear
        for name, matrix in (("beam", stiffness), ("beam and the wall's springs", stiffness + sp.diags(springs))):
            omega = largest_frequency(matrix, lumped)
            print(f"{length:g} m, {elements} elements, {name}: omega_max = {omega:.3e} rad/s, "
                  f"stable step 2 / omega_max = {2 / omega:.3e} s")


if __name__ == "__main__":
    main()
