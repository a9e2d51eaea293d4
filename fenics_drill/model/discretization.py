"""Mesh, mixed function space and support conditions of the beam (Section 4.1).

The six fields (u, v, w, theta_x, theta_y, theta_z) live in one mixed space of
scalar Lagrange elements: u, v and w of degree k (the scene's
``beam.element_degree``), the three rotations of degree k - 1.  The degree
mismatch between transverse displacements and rotations avoids shear locking
(it replaces the paper's Hermite interdependent element, which DOLFINx does not
offer); u of the same degree as v and w avoids membrane locking at large
deflection, where the membrane strain u' + (v'^2 + w'^2)/2 must be able to vanish
(a linear u left the sag of a 40 m string 14 % short at 60 elements and 5 % at
240; docs/verification.md, "Static equilibrium").
"""

from __future__ import annotations

from dataclasses import replace
from functools import cached_property

import basix.ufl
import numpy as np
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_drill.forms import FIELD_NAMES, BeamProperties
from fenics_drill.forms.properties import CurvedAxis
from fenics_drill.model.resources import check_memory
from fenics_drill.model.well import Trajectory, well_of
from fenics_drill.scene import SceneError

#: Index of each field in the mixed space, in the paper's order (the one place they are declared).
U, V, W, THETA_X, THETA_Y, THETA_Z = range(6)

#: Fields held fixed by each support type of ``model.supports``: (field index, end).
SUPPORTS = {
    # Section 4.4: v, w, theta_y, theta_z fixed at x = 0; v, w fixed at x = L.
    "paper": ((V, 0), (W, 0), (THETA_Y, 0), (THETA_Z, 0), (V, 1), (W, 1)),
    # v, w fixed at both ends, all rotations free.
    "pinned": ((V, 0), (W, 0), (V, 1), (W, 1)),
}
#: What the drive holds during a run (the Lagrange multipliers of (70)-(76)): u and theta_x at x = 0.
DRIVE = ((U, 0), (THETA_X, 0))


def field_degrees(element_degree: int) -> tuple[int, ...]:
    """Polynomial degree of each of the six fields for a transverse degree k."""
    k = element_degree
    return (k, k, k, k - 1, k - 1, k - 1)


class BeamDiscretization:
    """The interval mesh [0, L], the mixed space and the dofs of each field (serial, COMM_SELF)."""

    def __init__(self, properties: BeamProperties, elements: int, element_degree: int = 2, supports: str = "paper",
                 stabilisers: tuple = (), trajectory: Trajectory | None = None):
        """``stabilisers``: x of pinned lateral supports inside the string (v = w = 0 at the nearest vertex);
        ``trajectory``: the well's axis the string lies along from its top (x = measured depth), or None for the
        straight horizontal hole."""
        if supports not in SUPPORTS:
            raise ValueError(f"unknown supports {supports!r}; expected one of {', '.join(SUPPORTS)}")
        self.elements = elements
        self.element_degree = element_degree
        self.supports = supports
        self.stabilisers = tuple(stabilisers)
        self.comm = MPI.COMM_SELF
        self.mesh = mesh.create_interval(self.comm, self.elements, [0.0, properties.length])
        sub = [basix.ufl.element("Lagrange", "interval", d) for d in field_degrees(self.element_degree)]
        self.V = fem.functionspace(self.mesh, basix.ufl.mixed_element(sub))
        self.trajectory = trajectory
        self.properties = properties if trajectory is None else replace(properties, axis=self._axis(trajectory))

    def _axis(self, trajectory: Trajectory) -> CurvedAxis:
        """The well's axis on the mesh: its curvature in the Bishop frame at each cell's midpoint (constant along
        each arc of the survey) and the downward vertical in the frame at each vertex, interpolated linearly."""
        cells = fem.functionspace(self.mesh, ("DG", 0))
        vertices = fem.functionspace(self.mesh, ("Lagrange", 1))
        midpoints = cells.tabulate_dof_coordinates()[:, 0]
        frames = trajectory.bishop_frames(midpoints)
        curvature = tuple(fem.Function(cells, name=name) for name in ("k2", "k3"))
        curvature[0].x.array[:], curvature[1].x.array[:] = frames.k2, frames.k3
        down = trajectory.bishop_frames(vertices.tabulate_dof_coordinates()[:, 0]).down()
        components = tuple(fem.Function(vertices, name=name) for name in ("down_t", "down_2", "down_3"))
        for i, component in enumerate(components):
            component.x.array[:] = down[:, i]
        return CurvedAxis(curvature, components)

    @classmethod
    def from_scene(cls, scene) -> "BeamDiscretization":
        """The discretization a scene asks for (``beam.*``, ``model.supports``); refused before any
        allocation if it does not fit in memory (:mod:`fenics_drill.model.resources`).  The beam lies along the
        well's survey from the surface (``[well]``), or in the straight horizontal hole of ``beam.length``.  Its
        section is one pipe's ([beam]) in the hole of ``borehole.radius``: string sections and hole sections are
        refused (those are read by the soft-string model, ``fenics-drill torque-drag``)."""
        given = [name for name, value in (("well.hole_radius", scene.well.hole_radius),
                                          ("string.sections", scene.string.sections)) if value]
        if given:
            raise SceneError(f"{' and '.join(given)} describe a string or hole of several sections, which "
                             "'fenics-drill torque-drag' (the soft-string model) reads; the finite-element model "
                             "runs one pipe of [beam] in the hole of borehole.radius: leave them out for run, static, "
                             "modal, campbell, mc and optimize")
        check_memory(scene.beam.elements, scene.beam.element_degree)
        trajectory = well_of(scene, scene.beam.length).trajectory if (scene.well.survey or scene.well.md) else None
        return cls(scene.beam_properties, scene.beam.elements, scene.beam.element_degree, scene.model.supports,
                   scene.supports.stabilisers, trajectory)

    @property
    def ndofs(self) -> int:
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs

    @cached_property
    def field_dofs(self) -> tuple[np.ndarray, ...]:
        """For each field, the indices of its dofs in the mixed space (local numbering)."""
        return tuple(np.asarray(self.V.sub(i).collapse()[1], dtype=np.int32).ravel() for i in range(6))

    @cached_property
    def field_of_dof(self) -> np.ndarray:
        """Field index (0..5) of every dof of the mixed space."""
        out = np.empty(self.ndofs, dtype=np.int8)
        for i, dofs in enumerate(self.field_dofs):
            out[dofs] = i
        return out

    def end_dof(self, field: int, end: int) -> int:
        """Index of the dof of ``field`` at x = 0 (end=0) or x = L (end=1)."""
        x_end = 0.0 if end == 0 else self.properties.length
        vertices = mesh.locate_entities_boundary(self.mesh, 0, lambda x: np.isclose(x[0], x_end))
        dofs = fem.locate_dofs_topological(self.V.sub(field), 0, vertices)
        if len(dofs) != 1:
            raise RuntimeError(f"expected one dof of {FIELD_NAMES[field]} at x = {x_end}, got {len(dofs)}")
        return int(dofs[0])

    @cached_property
    def stabiliser_vertices(self) -> np.ndarray:
        """Indices into :attr:`vertex_x` of the vertices nearest the stabilisers (v = w = 0 there)."""
        return np.array(sorted({int(np.argmin(np.abs(self.vertex_x - x))) for x in self.stabilisers}), dtype=int)

    def _stabiliser_dofs(self) -> list[tuple[int, int]]:
        """(field, dof) of v and w at every stabiliser vertex."""
        return [(field, int(self.vertex_dofs(field)[i])) for i in self.stabiliser_vertices for field in (V, W)]

    @cached_property
    def support_dofs(self) -> np.ndarray:
        """Dofs held at zero by the supports and stabilisers (the Dirichlet rows of the modal problem)."""
        ends = [self.end_dof(f, e) for f, e in SUPPORTS[self.supports]]
        return np.array(sorted(ends + [dof for _, dof in self._stabiliser_dofs()]), dtype=np.int32)

    def support_bcs(self, held: tuple = ()) -> list[fem.DirichletBC]:
        """Homogeneous Dirichlet conditions for the supports, the stabilisers and the ``held`` (field, end)
        pairs (for example :data:`DRIVE`), one per constrained dof."""
        dofs = [(field, self.end_dof(field, end)) for field, end in (*SUPPORTS[self.supports], *held)]
        return [fem.dirichletbc(np.float64(0.0), np.array([dof], dtype=np.int32), self.V.sub(field))
                for field, dof in dofs + self._stabiliser_dofs()]

    @cached_property
    def dof_coordinates(self) -> np.ndarray:
        """x coordinate of every dof of the mixed space."""
        x = np.empty(self.ndofs)
        for i, dofs in enumerate(self.field_dofs):
            Vi, _ = self.V.sub(i).collapse()
            x[dofs] = Vi.tabulate_dof_coordinates()[:, 0]
        return x

    @cached_property
    def element_curvature(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The axis' curvature (k2, k3) [1/m] at the midpoints between consecutive vertices (None: straight)."""
        if self.trajectory is None:
            return None
        frames = self.trajectory.bishop_frames(0.5 * (self.vertex_x[1:] + self.vertex_x[:-1]))
        return frames.k2, frames.k3

    @cached_property
    def vertex_x(self) -> np.ndarray:
        """x of the mesh vertices, increasing (the nodes where wall impacts act, Section 2.3)."""
        return np.sort(self.mesh.geometry.x[:, 0])

    def vertex_dofs(self, field: int) -> np.ndarray:
        """Dofs of ``field`` at the mesh vertices, in the order of :attr:`vertex_x`."""
        dofs = self.field_dofs[field]
        x = self.dof_coordinates[dofs]
        order = np.argsort(x)
        xs = x[order]
        right = np.clip(np.searchsorted(xs, self.vertex_x), 1, len(xs) - 1)
        nearest = np.where(np.abs(xs[right - 1] - self.vertex_x) <= np.abs(xs[right] - self.vertex_x), right - 1, right)
        found = dofs[order][nearest]
        if not np.allclose(self.dof_coordinates[found], self.vertex_x, atol=1e-9 * self.properties.length):
            raise RuntimeError(f"field {FIELD_NAMES[field]} has no dof at every vertex")
        return found
