"""Displacement and rotation fields for ParaView: XDMF with u, v, w, theta_x, theta_y, theta_z on the
vertices, the displacement vector (u, v, w) for "Warp By Vector", and, for drilling runs, the
element-wise maximum von Mises stress ``von_mises`` (Pa), the axial force and torque along the string
(``axial_force`` [N], ``torque`` [N m], element-wise) and the wall's normal force per length
(``wall_normal_force_per_length`` [N/m], at the vertices); the one writer (:class:`FieldWriter`) and the
one reader (:class:`FieldSnapshots`) of ``fields.xdmf`` + ``fields.h5``.

The vertex values are the Lagrange fields' nodal values (what P1 interpolation gives).  The
snapshots are buffered and written with the time series' rhythm (every few seconds of wall time)
to a copy of the HDF5 file renamed into place, and the XDMF index is rewritten whole after each
write, so both files stay readable whatever ends the run (dolfinx's XDMFFile keeps its HDF5 file
open, and a killed run left it unreadable).
"""

from __future__ import annotations

import time
from pathlib import Path

import h5py
import numpy as np

from fenics_drill.forms import FIELD_NAMES
from fenics_drill.io.files import FlushClock, UnreadableFile, update_hdf5, write_atomic
from fenics_drill.model.discretization import BeamDiscretization

_GRID = """      <Grid Name="string" GridType="Uniform">
        <Time Value="{t!r}"/>
        <Topology TopologyType="Polyline" NumberOfElements="{cells}" NodesPerElement="2">
          <DataItem Dimensions="{cells} 2" NumberType="Int" Format="HDF">{h5}:/Mesh/mesh/topology</DataItem>
        </Topology>
        <Geometry GeometryType="XYZ">
          <DataItem Dimensions="{nodes} 3" Format="HDF">{h5}:/Mesh/mesh/geometry</DataItem>
        </Geometry>
{attributes}      </Grid>
"""
_ATTRIBUTE = """        <Attribute Name="{name}" AttributeType="{kind}" Center="{center}">
          <DataItem Dimensions="{rows} {columns}" Format="HDF">{h5}:/Function/{name}/{key}</DataItem>
        </Attribute>
"""


def snapshot_key(t: float) -> str:
    """Name of the dataset of the snapshot at time t (dolfinx's convention: the dot written as _)."""
    return repr(float(t)).replace(".", "_")


class FieldWriter:
    """Writes the fields of full-space dof vectors at chosen times, whole files at every moment."""

    def __init__(self, disc: BeamDiscretization, path: str | Path, with_stress: bool = False,
                 clock: FlushClock | None = None, with_profiles: bool = False):
        """``with_stress``: each snapshot has the cells' von Mises maxima; ``with_profiles``: the axial force and
        torque on the cells and the wall's normal force per length at the vertices, given along x."""
        self.xdmf = Path(path)
        self.h5 = self.xdmf.with_suffix(".h5")
        self.vertex_dofs = [disc.vertex_dofs(i) for i in range(len(FIELD_NAMES))]
        x = disc.mesh.geometry.x[:, 0]
        cell_vertices = disc.mesh.geometry.dofmaps[0]
        self.cell_order = np.argsort(0.5 * (x[cell_vertices[:, 0]] + x[cell_vertices[:, 1]]))
        self.vertex_order = np.argsort(disc.vertex_x)
        self.with_stress = with_stress
        self.profile_cells = ("axial_force", "torque") if with_profiles else ()
        self.profile_points = ("wall_normal_force_per_length",) if with_profiles else ()
        self.nodes, self.cells = len(disc.vertex_x), len(self.cell_order)
        self.clock = clock or FlushClock()
        self.pending: list[tuple[float, dict]] = []
        self.written: list[float] = []
        geometry = np.zeros((self.nodes, 3))
        geometry[:, 0] = disc.vertex_x
        topology = np.column_stack([np.arange(self.cells), np.arange(1, self.cells + 1)]).astype(np.int64)

        def create(tmp: Path) -> None:
            with h5py.File(tmp, "w") as f:
                f["Mesh/mesh/geometry"] = geometry
                f["Mesh/mesh/topology"] = topology

        write_atomic(self.h5, create)
        self._write_index()

    def write(self, dofs: np.ndarray, t: float, cell_stress: np.ndarray | None = None,
              profiles: dict[str, np.ndarray] | None = None) -> None:
        """The fields at time t, the element-wise maximum von Mises stress if given [Pa], and the ``profiles``
        (:func:`fenics_drill.observables.torque_drag.string_profiles`, along x); written to disk when the clock
        says so (or at :meth:`flush`)."""
        values = {name: dofs[rows][:, None] for name, rows in zip(FIELD_NAMES, self.vertex_dofs)}
        values["displacement"] = np.column_stack([dofs[self.vertex_dofs[i]] for i in range(3)])
        if self.with_stress and cell_stress is not None:
            values["von_mises"] = np.asarray(cell_stress)[self.cell_order][:, None]
        for name in self.profile_cells:
            values[name] = np.asarray(profiles[name])[:, None]  # cells along x, as the index orders them
        for name in self.profile_points:
            at_vertices = np.empty(self.nodes)
            at_vertices[self.vertex_order] = profiles[name]
            values[name] = at_vertices[:, None]
        self.pending.append((t, values))
        if self.clock.due():
            self.flush()

    def flush(self) -> None:
        if not self.pending:
            return
        started = time.monotonic()

        def update(f) -> None:
            for t, values in self.pending:
                for name, data in values.items():
                    key = f"Function/{name}/{snapshot_key(t)}"
                    if key in f:
                        del f[key]
                    f[key] = data

        update_hdf5(self.h5, update)
        self.written += [t for t, _ in self.pending]
        self.pending.clear()
        self._write_index()
        self.clock.wrote(time.monotonic() - started)

    def _write_index(self) -> None:
        """The XDMF file: a temporal collection with one grid per written snapshot."""
        grids = []
        for t in self.written:
            attributes = "".join(
                _ATTRIBUTE.format(name=name, kind="Scalar", center="Node", rows=self.nodes, columns=1,
                                  h5=self.h5.name, key=snapshot_key(t)) for name in FIELD_NAMES)
            attributes += _ATTRIBUTE.format(name="displacement", kind="Vector", center="Node", rows=self.nodes,
                                            columns=3, h5=self.h5.name, key=snapshot_key(t))
            cells = (("von_mises",) if self.with_stress else ()) + self.profile_cells
            for name in cells:
                attributes += _ATTRIBUTE.format(name=name, kind="Scalar", center="Cell", rows=self.cells,
                                                columns=1, h5=self.h5.name, key=snapshot_key(t))
            for name in self.profile_points:
                attributes += _ATTRIBUTE.format(name=name, kind="Scalar", center="Node", rows=self.nodes,
                                                columns=1, h5=self.h5.name, key=snapshot_key(t))
            grids.append(_GRID.format(t=float(t), cells=self.cells, nodes=self.nodes, h5=self.h5.name,
                                      attributes=attributes))
        text = ('<?xml version="1.0"?>\n<Xdmf Version="3.0">\n  <Domain>\n'
                '    <Grid Name="fields" GridType="Collection" CollectionType="Temporal">\n'
                + "".join(grids) + "    </Grid>\n  </Domain>\n</Xdmf>\n")
        write_atomic(self.xdmf, lambda tmp: tmp.write_text(text))

    def close(self) -> None:
        self.flush()


class FieldSnapshots:
    """The vertex fields of a ``fields.h5`` at every snapshot time (the displacement vector left out)."""

    def __init__(self, h5_path: Path):
        try:
            self._read(h5_path)
        except (OSError, KeyError, ValueError) as err:
            raise UnreadableFile(f"{h5_path} is not a readable field file (truncated or corrupt?): {err}") from err

    def _read(self, h5_path: Path) -> None:
        with h5py.File(h5_path, "r") as f:
            self.x = f["Mesh/mesh/geometry"][:, 0]
            order = np.argsort(self.x)
            self.x = self.x[order]
            self.fields: dict[str, np.ndarray] = {}
            self.cell_fields: dict[str, np.ndarray] = {}
            for name, group in f["Function"].items():
                if name == "displacement":
                    continue
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
