"""Displacement and rotation fields for ParaView: XDMF with u, v, w, theta_x, theta_y, theta_z on P1
and, for drilling runs, the element-wise maximum von Mises stress ``von_mises`` (DG0, Pa); the one
writer (:class:`FieldWriter`) and the one reader (:class:`FieldSnapshots`) of ``fields.xdmf/.h5``.

XDMFFile writes functions of the mesh's degree only, so each sub-field of the
mixed space is collapsed and interpolated to P1 (vertex values) before writing.
"""

from __future__ import annotations

from pathlib import Path

import basix.ufl
import h5py
import numpy as np
from dolfinx import fem, io

from fenics_drill.forms import FIELD_NAMES
from fenics_drill.model.discretization import BeamDiscretization


class FieldWriter:
    """Writes the six fields of full-space dof vectors at chosen times."""

    def __init__(self, disc: BeamDiscretization, path: str | Path, with_stress: bool = False):
        self.disc = disc
        self.file = io.XDMFFile(disc.comm, str(path), "w")
        self.file.write_mesh(disc.mesh)
        p1 = fem.functionspace(disc.mesh, basix.ufl.element("Lagrange", "interval", 1))
        self.mixed = fem.Function(disc.V)
        self.outputs = []
        for i, name in enumerate(FIELD_NAMES):
            f = fem.Function(p1, name=name)
            self.outputs.append((self.mixed.sub(i), f))
        dg0 = fem.functionspace(disc.mesh, basix.ufl.element("DG", "interval", 0))
        self.stress = fem.Function(dg0, name="von_mises") if with_stress else None

    def write(self, dofs: np.ndarray, t: float, cell_stress: np.ndarray | None = None) -> None:
        """The six fields at time t, and the element-wise maximum von Mises stress if given [Pa]."""
        self.mixed.x.array[:] = dofs
        for sub, out in self.outputs:
            out.interpolate(sub)
            self.file.write_function(out, t)
        if self.stress is not None and cell_stress is not None:
            self.stress.x.array[:] = cell_stress
            self.file.write_function(self.stress, t)

    def close(self) -> None:
        self.file.close()


class FieldSnapshots:
    """The P1 fields of a ``fields.h5`` (dolfinx XDMF) at every snapshot time."""

    def __init__(self, h5_path: Path):
        with h5py.File(h5_path, "r") as f:
            self.x = f["Mesh/mesh/geometry"][:, 0]
            order = np.argsort(self.x)
            self.x = self.x[order]
            self.fields: dict[str, np.ndarray] = {}
            self.cell_fields: dict[str, np.ndarray] = {}
            for name, group in f["Function"].items():
                keys = sorted(group, key=lambda k: float(k.replace("_", ".")))
                self.times = np.array([float(k.replace("_", ".")) for k in keys])
                values = np.stack([group[k][:, 0] for k in keys])
                if values.shape[1] == len(order):
                    self.fields[name] = values[:, order]
                else:  # DG0: one value per cell, cells ordered along x for an interval mesh
                    self.cell_fields[name] = values

    def index_near(self, t: float) -> int:
        return int(np.argmin(np.abs(self.times - t)))

    def vertex_stress(self, k: int) -> np.ndarray | None:
        """Von Mises stress at the vertices (average of the adjacent cells) [Pa], if recorded."""
        if "von_mises" not in self.cell_fields:
            return None
        c = self.cell_fields["von_mises"][k]
        return np.concatenate([[c[0]], 0.5 * (c[1:] + c[:-1]), [c[-1]]])
