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

import math
from dataclasses import replace
from functools import cached_property

import basix.ufl
import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_drill.forms import FIELD_NAMES, BeamProperties
from fenics_drill.forms.properties import CurvedAxis
from fenics_drill.model.resources import check_memory
from fenics_drill.model.string_sections import fe_sections
from fenics_drill.model.well import Trajectory, string_in_well

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


def mesh_vertices(length: float, elements: int, breaks, coarse: tuple[float, float] | None = None) -> np.ndarray:
    """Vertices on [0, length] about ``length / elements`` apart that fall on every break inside it: each interval
    between consecutive breaks is cut into equal elements no longer than that (so there are at least
    ``elements``).  ``coarse`` = (x_top, h): the intervals above x_top (which must be a break) into elements no
    longer than h instead."""
    h = length / elements
    points = np.unique(np.clip(np.array([0.0, length, *breaks], dtype=float), 0.0, length))
    points = points[np.concatenate([[True], np.diff(points) > 1e-9 * length])]  # breaks closer than round-off: one
    points[-1] = length

    def spacing(b):
        return coarse[1] if coarse is not None and b <= coarse[0] * (1 + 1e-12) else h

    pieces = [np.linspace(a, b, max(1, math.ceil((b - a) / spacing(b) - 1e-9)) + 1)[:-1]
              for a, b in zip(points[:-1], points[1:])]
    return np.concatenate([*pieces, [length]])


class BeamDiscretization:
    """The interval mesh [0, L], the mixed space and the dofs of each field (serial, COMM_SELF)."""

    def __init__(self, properties: BeamProperties, elements: int, element_degree: int = 2, supports: str = "paper",
                 stabilisers: tuple = (), trajectory: Trajectory | None = None, sections=None, breaks: tuple = (),
                 lateral_length: float = -1.0, axial_torsional_element_length: float = -1.0):
        """``stabilisers``: x of pinned lateral supports inside the string (v = w = 0 at the nearest vertex);
        ``trajectory``: the well's axis the string lies along from its top (x = measured depth), or None for the
        straight horizontal hole; ``sections``: None for one pipe (``properties``), or what the string is made of
        along x, ``sections(cell midpoints, vertex x)`` -> :class:`~fenics_drill.model.string_sections.FESections`
        (``properties`` then holds the section at the bit, for what needs one number); ``breaks``: x where a
        vertex must fall (the ends of sections and of the survey's arcs: :func:`mesh_vertices`);
        ``lateral_length``: the length above the bit over which v, w, theta_y and theta_z are solved (-1: the whole
        string; 0: none, an axial-torsional string): above it they are held at zero (:attr:`lateral_held_dofs`);
        ``axial_torsional_element_length``: the elements' length there, if > 0 (else ``properties.length /
        elements``, as below it)."""
        if supports not in SUPPORTS:
            raise ValueError(f"unknown supports {supports!r}; expected one of {', '.join(SUPPORTS)}")
        self.element_degree = element_degree
        self.supports = supports
        self.stabilisers = tuple(stabilisers)
        self.lateral_length = lateral_length
        self.comm = MPI.COMM_SELF
        coarse = None
        if axial_torsional_element_length > 0 and lateral_length >= 0:
            top = properties.length - lateral_length
            coarse, breaks = (top, axial_torsional_element_length), (*breaks, top)
        if breaks:
            x = mesh_vertices(properties.length, elements, breaks, coarse)
            cells = np.stack([np.arange(x.size - 1), np.arange(1, x.size)], axis=1).astype(np.int64)
            line = ufl.Mesh(basix.ufl.element("Lagrange", "interval", 1, shape=(1,)))
            self.mesh = mesh.create_mesh(self.comm, cells, line, x[:, None])
        else:
            self.mesh = mesh.create_interval(self.comm, elements, [0.0, properties.length])
        self.elements = self.mesh.topology.index_map(1).size_local
        sub = [basix.ufl.element("Lagrange", "interval", d) for d in field_degrees(self.element_degree)]
        self.V = fem.functionspace(self.mesh, basix.ufl.mixed_element(sub))
        self.trajectory = trajectory
        self.properties = properties
        if trajectory is not None:
            self.properties = replace(properties, axis=self._axis(trajectory))
        self.sections = None
        #: What the forms take: :attr:`properties`, with each section's values on its cells for a string of sections.
        self.form_properties = self.properties
        if sections is not None:
            cell_x = self.cell_space.tabulate_dof_coordinates()[:, 0]
            self.sections = sections(cell_x, self.vertex_x)
            cells = self.sections.cells
            bit = int(np.argmax(cell_x))
            self.properties = replace(self.properties, **{name: float(values[bit]) for name, values in cells.items()})
            self.form_properties = replace(self.properties, **{name: self._cell_function(name, values)
                                                               for name, values in cells.items()})

    def vertex_radii(self, borehole_radius: float) -> tuple[np.ndarray, np.ndarray]:
        """(contact radius, hole radius) [m] at each vertex: the pipe's outer radius in ``borehole_radius``, or the
        string's and the well's sections."""
        if self.sections is not None:
            return self.sections.contact_radius, self.sections.hole_radius
        n = len(self.vertex_x)
        return np.full(n, self.properties.outer_radius), np.full(n, borehole_radius)

    def vertex_gap(self, borehole_radius: float) -> np.ndarray:
        """The radial clearance between the pipe and the hole at each vertex [m] (:meth:`vertex_radii`)."""
        contact_radius, hole_radius = self.vertex_radii(borehole_radius)
        return hole_radius - contact_radius

    @cached_property
    def element_properties(self) -> BeamProperties:
        """:attr:`properties`, with one value per element between consecutive vertices (along x) for a string of
        sections (what reading a state's axial force and torque needs)."""
        if self.sections is None:
            return self.properties
        order = np.argsort(self.cell_space.tabulate_dof_coordinates()[:, 0])
        return replace(self.properties, **{name: values[order] for name, values in self.sections.cells.items()})

    @property
    def weight(self) -> float:
        """The string's weight (in the fluids) [N]: rho A g over its length, section by section."""
        p = self.element_properties
        if self.sections is None:
            return p.density * p.section.area * p.gravity * p.length
        return float(np.sum(p.density * p.section.area * p.gravity * np.diff(self.vertex_x)))

    @cached_property
    def cell_space(self) -> fem.FunctionSpace:
        """The piecewise-constant space: one value per cell."""
        return fem.functionspace(self.mesh, ("DG", 0))

    def _cell_function(self, name: str, values: np.ndarray) -> fem.Function:
        function = fem.Function(self.cell_space, name=name)
        function.x.array[:] = values
        return function

    def _axis(self, trajectory: Trajectory) -> CurvedAxis:
        """The well's axis on the mesh: its curvature in the Bishop frame at each cell's midpoint (constant along
        each arc of the survey) and the downward vertical in the frame at each vertex, interpolated linearly.

        Above :attr:`lateral_top` the curvature is 0: there the string has no lateral fields and lies on the hole's
        axis whatever its axial motion, so u is an arc length along the axis and a slide along it strains nothing
        (the curved beam's coupling k u would be a shear strain against the held lateral fields, a spurious spring
        G A k^2 u^2 on the string's axial motion: 40 kN of the hook load through the 4.5 deg/30 m build of the
        build-and-hold demo well).  Gravity keeps the axis' frame."""
        vertices = fem.functionspace(self.mesh, ("Lagrange", 1))
        cell_x = self.cell_space.tabulate_dof_coordinates()[:, 0]
        frames = trajectory.bishop_frames(cell_x)
        followed = cell_x < self.lateral_top  # the cells of the string without lateral fields
        curvature = tuple(self._cell_function(name, np.where(followed, 0.0, k))
                          for name, k in (("k2", frames.k2), ("k3", frames.k3)))
        down = trajectory.bishop_frames(vertices.tabulate_dof_coordinates()[:, 0]).down()
        components = tuple(fem.Function(vertices, name=name) for name in ("down_t", "down_2", "down_3"))
        for i, component in enumerate(components):
            component.x.array[:] = down[:, i]
        return CurvedAxis(curvature, components)

    @classmethod
    def from_scene(cls, scene) -> "BeamDiscretization":
        """The discretization a scene asks for (``beam.*``, ``model.supports``); refused before any
        allocation if it does not fit in memory (:mod:`fenics_drill.model.resources`).  The string lies along the
        well's survey from the surface (``[well]``), or in the straight horizontal hole of ``beam.length``.  It is the
        one pipe of [beam] in the hole of ``borehole.radius``, or the sections of ``string.sections`` (their length
        is the string's) in the hole sections of ``[well]``."""
        check_memory(scene.beam.elements, scene.beam.element_degree)
        sectioned = bool(scene.string.sections or scene.well.hole_radius)
        lateral, coarse = scene.model.lateral_length, scene.axial_torsional_element_length
        if not (sectioned or scene.well.survey or scene.well.md):
            return cls(scene.beam_properties, scene.beam.elements, scene.beam.element_degree, scene.model.supports,
                       scene.supports.stabilisers, lateral_length=lateral, axial_torsional_element_length=coarse)
        resolved = string_in_well(scene)
        strings, well = resolved.sections, resolved.well
        properties = replace(scene.beam_properties, length=strings[-1].bottom)
        layout = (lambda cells, vertices: fe_sections(scene, strings, well.hole.radius, cells, vertices)) if sectioned else None
        trajectory = well.trajectory if (scene.well.survey or scene.well.md) else None
        # a vertex at every survey station keeps each element on one arc of constant curvature; a survey denser
        # than the mesh (a station every few cm) would make the mesh its own: its elements then take the
        # curvature at their midpoints
        stations = well.trajectory.md if trajectory and len(well.trajectory.md) <= scene.beam.elements else ()
        top = (strings[-1].bottom - lateral,) if lateral > 0 else ()  # a vertex at the lateral length's top
        breaks = (*(s.bottom for s in strings), *well.hole.bottoms, *stations, *top)
        return cls(properties, scene.beam.elements, scene.beam.element_degree, scene.model.supports,
                   scene.supports.stabilisers, trajectory, layout, breaks, lateral, coarse)

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
    def lateral_top(self) -> float:
        """x of the top of the length whose lateral fields are solved (0: the whole string; the vertex nearest
        L - ``lateral_length``; L for an axial-torsional string)."""
        if self.lateral_length < 0:
            return 0.0
        if self.lateral_length == 0:
            return self.properties.length
        return float(self.vertex_x[np.argmin(np.abs(self.vertex_x - (self.properties.length - self.lateral_length)))])

    @cached_property
    def lateral_held_dofs(self) -> list[tuple[int, int]]:
        """(field, dof) of the lateral dofs held at zero above the lateral length (``lateral_length``): every v, w,
        theta_y, theta_z above :attr:`lateral_top`, and v, w at it (the string's axis there: the lateral part is
        pinned on the well's axis at its top, its tilt free); every one of them for an axial-torsional string."""
        if self.lateral_length < 0:
            return []
        top, whole = self.lateral_top, self.lateral_length == 0
        tolerance = 1e-9 * self.properties.length
        held = []
        for field in (V, W, THETA_Y, THETA_Z):
            x = self.dof_coordinates[self.field_dofs[field]]
            above = (x < top - tolerance) | (whole | (field in (V, W))) & (x <= top + tolerance)
            held += [(field, int(dof)) for dof in self.field_dofs[field][above]]
        return held

    @cached_property
    def support_dofs(self) -> np.ndarray:
        """Dofs held at zero by the supports, the stabilisers and the lateral length (the Dirichlet rows of the modal
        problem)."""
        ends = [self.end_dof(f, e) for f, e in SUPPORTS[self.supports]]
        extra = [dof for _, dof in self._stabiliser_dofs()] + [dof for _, dof in self.lateral_held_dofs]
        return np.unique(np.array(ends + extra, dtype=np.int32))

    def support_bcs(self, held: tuple = ()) -> list[fem.DirichletBC]:
        """Homogeneous Dirichlet conditions for the supports, the stabilisers, the lateral length and the ``held``
        (field, end) pairs (for example :data:`DRIVE`), one per field and set of constrained dofs."""
        dofs = [(field, self.end_dof(field, end)) for field, end in (*SUPPORTS[self.supports], *held)]
        dofs += self._stabiliser_dofs() + self.lateral_held_dofs
        by_field = {}
        for field, dof in dofs:
            by_field.setdefault(field, set()).add(dof)
        return [fem.dirichletbc(np.float64(0.0), np.array(sorted(d), dtype=np.int32), self.V.sub(field))
                for field, d in by_field.items()]

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
