"""Displacement and rotation fields for ParaView: XDMF with u, v, w, theta_x, theta_y, theta_z on P1.

XDMFFile writes functions of the mesh's degree only, so each sub-field of the
mixed space is collapsed and interpolated to P1 (vertex values) before writing.
"""

from __future__ import annotations

from pathlib import Path

import basix.ufl
import numpy as np
from dolfinx import fem, io

from fenics_drill.discretization import BeamDiscretization
from fenics_drill.forms import FIELD_NAMES


class FieldWriter:
    """Writes the six fields of full-space dof vectors at chosen times."""

    def __init__(self, disc: BeamDiscretization, path: str | Path):
        self.disc = disc
        self.file = io.XDMFFile(disc.comm, str(path), "w")
        self.file.write_mesh(disc.mesh)
        p1 = fem.functionspace(disc.mesh, basix.ufl.element("Lagrange", "interval", 1))
        self.mixed = fem.Function(disc.V)
        self.outputs = []
        for i, name in enumerate(FIELD_NAMES):
            f = fem.Function(p1, name=name)
            self.outputs.append((self.mixed.sub(i), f))

    def write(self, dofs: np.ndarray, t: float) -> None:
        self.mixed.x.array[:] = dofs
        for sub, out in self.outputs:
            out.interpolate(sub)
            self.file.write_function(out, t)

    def close(self) -> None:
        self.file.close()
