"""Wall impacts at the mesh vertices, Eqs. (16)-(19), (40), (50), with their tangents.

Every vertex in contact carries the Hunt-Crossley normal force (17) (damper c |delta|^3 delta_dot) and friction,
by one of two laws (``contact.friction_model``):

- ``coulomb`` (the default): one Coulomb force at the contact point, opposing the slip velocity of the pipe's
  surface against the wall, s = (u_dot, t . (v_dot, w_dot) + R_ext theta_x_dot), with t the wall's tangent in
  the cross-section, with |F| <= mu |F_n|.  It is computed by return mapping (Simo & Hughes 1998, Sec. 1.2;
  Wriggers 2006, Sec. 5.2): over a step the contact point's slip g since the step's start loads a stiff tangential
  spring k_t (``contact.stick_stiffness``) from the force F_0 the vertex held then, F* = F_0 - k_t g, and the force
  is F* while |F*| <= mu |F_n| (stick; the spring's give is mu |F_n| / k_t, 0.6 um on the paper's string) and
  mu |F_n| F* / |F*| otherwise (slip, opposing it).  It acts as an axial force, a lateral force along t and a
  torque R_ext F_t about the pipe's axis.  So rotation takes the drag away (the axial share is u_dot / |s|), and
  the string can climb the wall, roll and whirl.  Stick and slip are each linear or constant in the step's
  unknowns, where a velocity regularisation tanh(|s| / v_s) is neither on the scale of v_s.  k_t = 1e8 N/m puts
  the switch between them on the scale of a Newton update (1e-7 - 1e-6 m): at 1e10 N/m, as stiff as the wall,
  a 1000 m string whose far part stops spinning under friction all at once (0.16-0.26 s after the start) had
  hundreds of vertices switch within 1e-8 m, Newton's line search stalled on the switches and the step
  collapsed (over 0.16-0.25 s: 194 steps, 190 failed Newton solves and 3479 iterations, where 1e8 N/m takes 33
  steps and 433 iterations); the paper's nominal scene gives the same rop and efficiency at both to 1e-6.
- ``paper``: (18) and (19) as two separate laws, -mu |F_n| sgn(u_dot) and -mu |F_n| R_bh sgn(theta_x_dot), with
  the borehole radius as the torque's arm (docs/errata.md); their signs as printed are a further option.

The pointwise laws come first, then :class:`WallContact` projects them on the solution space and differentiates
them for the Newton tangent.
"""

from __future__ import annotations

import copy
import functools
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.forces.protocol import ForceEvaluation
from fenics_drill.model.forces.wall.vertex_passes import (FIELDS, _contact_blocks, _modal_pass, _moved_blocks,
                                                          _projected_laws, _scattered_square, _selected_block_entries,
                                                          _selection, _vertex_loads, _weighted_rows)
from fenics_drill.model.kernels.banded_saddle import Triplets
from fenics_drill.model.kernels.packed_rows import FieldPackedRows
from fenics_drill.scene import LAW_SIGN


class ProjectedLaws(Mapping):
    """The generalised forces of the non-conservative wall laws (the damper of (17) and the two parts of friction:
    axial and tangential for the Coulomb force, (18) and (19) for the paper's), projected on first use: the energy
    budget reads them at accepted steps only, not at Newton's iterates."""

    def __init__(self, vertex_set: "VertexSet", delta: np.ndarray, loads: np.ndarray, names: tuple[str, ...]):
        """``vertex_set``: the vertices evaluated, with their rows; ``delta``, ``loads``: their indentations and the
        loads of each law (vertex, field, law), named ``names``."""
        self._rows, self._delta, self._loads, self._projected = vertex_set, delta, loads, None
        self.NAMES = names

    def _laws(self) -> dict[str, np.ndarray]:
        if self._projected is None:
            rows = self._rows
            if sp.issparse(rows.flat):
                projected = np.asarray(rows.flat_transposed @ self._loads.reshape(-1, len(self.NAMES))).T
            else:
                projected = _projected_laws(rows.packed.kernel_data(), rows.flat.shape[1], self._delta,
                                            self._loads)
            self._projected = dict(zip(self.NAMES, projected))
        return self._projected

    def __getitem__(self, name: str) -> np.ndarray:
        return self._laws()[name]

    def __iter__(self):
        return iter(self.NAMES)

    def __len__(self) -> int:
        return len(self.NAMES)


@dataclass
class WallForces(ForceEvaluation):
    """Nodal state and forces of one evaluation.

    ``generalised`` is [Phi]^T of (50); ``laws`` splits its non-conservative part into the damper of
    (17), the axial friction (18) and the friction torque (19); ``potential`` is the sum of
    k1 delta^2 / 2 + k2 delta^4 / 4 over the vertices in contact.  The arrays over the vertices are
    derived on first read (Newton's iterates read none of them)."""

    vertex_count: int = 0
    vertices: np.ndarray = None  # the vertices evaluated
    delta: np.ndarray = None  # their indentations
    nodal: np.ndarray = None  # their loads (F_a, F_v, F_w, T)
    tangent_data: tuple | None = None  # what :meth:`WallContact.tangent` needs, if asked for
    tangential_arm: np.ndarray | None = None  # Coulomb force: each vertex's torque arm (T = R F_t); None: no lateral part

    @functools.cached_property
    def indentation(self) -> np.ndarray:
        """delta of (16) at every vertex; -inf at the vertices left out (too far from the wall)."""
        out = np.full(self.vertex_count, -np.inf)
        out[self.vertices] = self.delta
        return out

    @functools.cached_property
    def in_contact(self) -> np.ndarray:
        """Whether each vertex touches the wall (delta > 0)."""
        out = np.zeros(self.vertex_count, dtype=bool)
        out[self.vertices[self.delta > 0]] = True
        return out

    @functools.cached_property
    def _active(self) -> np.ndarray:
        return self.nodal[self.delta > 0]

    @property
    def normal(self) -> np.ndarray:
        """F_n (<= 0) at the vertices in contact: the lateral load less its friction part along the wall, which is
        normal to it (|F_lateral|^2 = F_n^2 + F_t^2, F_t = T / R_ext)."""
        lateral = np.hypot(self._active[:, 1], self._active[:, 2])
        if self.tangential_arm is None:
            return -lateral
        tangential = self._active[:, 3] / self.tangential_arm[self.vertices[self.delta > 0]]
        return -np.sqrt(np.maximum(lateral**2 - tangential**2, 0.0))

    @property
    def axial(self) -> np.ndarray:
        """F_a at the vertices in contact."""
        return self._active[:, 0]

    @property
    def torque(self) -> np.ndarray:
        """T_FS at the vertices in contact."""
        return self._active[:, 3]


@dataclass(frozen=True)
class VertexSet:
    """Vertices the wall law is evaluated at, with their rows of [Phi]: all of them, or those that can
    reach the wall while q stays near ``q_ref`` (:meth:`WallContact._near_vertices`)."""

    vertices: np.ndarray
    lateral_rows: object  # (v, w) of each vertex, interleaved
    flat: object  # (u, v, w, theta_x) of each vertex, interleaved
    packed: FieldPackedRows | None  # the same, packed by field (a modal space's)
    q_ref: np.ndarray | None = None
    column_bound: np.ndarray | None = None
    reach: float = np.inf

    @functools.cached_property
    def flat_transposed(self):
        """``flat``'s transpose (the full space's, sparse), formed once: P^T f of the vertices' loads f."""
        return self.flat.T.tocsr()

    @functools.cached_property
    def selection(self) -> tuple[np.ndarray, np.ndarray]:
        """The full space's ``flat`` as a selection (:func:`_selection`): each row's dof (-1: none) and value."""
        return _selection(self.flat)

    @functools.cached_property
    def _selected(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rows of :attr:`selection` that select a dof, their dofs and their values."""
        columns, values = self.selection
        rows = np.flatnonzero(columns >= 0)
        return rows, columns[rows], values[rows]

    def gather(self, x: np.ndarray) -> np.ndarray:
        """``flat @ x`` in the full space, as a gather (each row selects one dof or none)."""
        rows, columns, values = self._selected
        out = np.zeros(self.flat.shape[0])
        out[rows] = values * x[columns]
        return out

    def scatter(self, loads: np.ndarray) -> np.ndarray:
        """``flat.T @ loads`` in the full space, as a scatter of the loads' selected entries."""
        rows, columns, values = self._selected
        return np.bincount(columns, values * loads[rows], minlength=self.flat.shape[1])


class WallContact:
    """Impact and friction forces of the borehole wall on the vertices of the mesh."""

    name: ClassVar[str] = "wall"
    switch: ClassVar[str] = "contact"
    conservative: ClassVar[bool] = False
    recorded: ClassVar[dict] = {
        "vertices_in_contact": ("1", "vertices in contact with the wall at the end of the step"),
    }

    def __init__(self, disc: BeamDiscretization, space, contact, borehole_radius: float,
                 law_sign: tuple[float, float] = (1.0, 1.0), damper_law: str = "consistent", culling: bool = True):
        """``contact``: the scene's [contact] section (its ``friction_model`` chooses the friction law);
        ``law_sign``: +1 (consistent) or -1 (as printed) for the axial friction (18) and the friction torque (19)
        of the paper's model; ``damper_law``: the damper of (17); ``culling``: evaluate the law only at the
        vertices that can reach the wall (exact)."""
        self.x = disc.vertex_x
        contact_radius, hole_radius = disc.vertex_radii(borehole_radius)
        self.gap = hole_radius - contact_radius  # per vertex
        self.coulomb = contact.friction_model == "coulomb"
        # the friction torque's arm: the pipe's surface, where the Coulomb force acts; the borehole's radius in (19)
        self.arm = contact_radius if self.coulomb else hole_radius
        self.law_names = ("wall_damper", "wall_friction_axial", "wall_friction_tangential") if self.coulomb else \
            ("wall_damper", "wall_axial_friction", "wall_friction_torque")
        self.k1, self.k2 = contact.stiffness_linear, contact.stiffness_cubic
        self.c = contact.damping
        self.damper_law = damper_law
        # the friction coefficient of each law, negative for a law taken as printed (scene.LAW_SIGN)
        self.mu_axial = law_sign[0] * contact.friction
        self.mu_torque = law_sign[1] * contact.friction
        self.v_s = contact.sliding_velocity_scale
        self.stick_stiffness = contact.stick_stiffness
        # the rows of [Phi] of (u, v, w, theta_x) at every vertex, interleaved: row 4 i + k is field k at
        # vertex i, so one product gives all four fields at all vertices and projects all their forces
        by_field = [space.rows(disc.vertex_dofs(f)) for f in FIELDS]
        n = len(self.x)
        order = (np.arange(len(FIELDS))[None, :] * n + np.arange(n)[:, None]).ravel()
        if space.sparse:
            self.flat = sp.vstack(by_field, format="csr")[order]
        else:
            self.flat = np.ascontiguousarray(np.vstack(by_field)[order])
        # the rows of (v, w) alone, interleaved the same way: who touches the wall is known from these
        lateral = (len(FIELDS) * np.arange(n)[:, None] + np.array([1, 2])).ravel()
        lateral_rows = self.flat[lateral] if space.sparse else np.ascontiguousarray(self.flat[lateral])
        field_of_row = np.tile(np.arange(len(FIELDS)), n)  # the groups of the packed rows: FIELDS' order
        self.every = VertexSet(np.arange(n), lateral_rows, self.flat,
                               None if space.sparse else FieldPackedRows.of(self.flat, field_of_row))
        # |P_i[:, j]|_1 of each vertex's (v, w) rows P_i: |(v, w)_i(q) - (v, w)_i(q_ref)| <= sum_j of it |dq_j|
        self._column_sizes = abs(lateral_rows[0::2]) + abs(lateral_rows[1::2])
        self.culling = culling
        self._near = None  # the VertexSet of the last culled evaluation
        self._kept_tangent = None  # (matrix, blocks, updates) of the modal tangent (:meth:`_updated_tangent`)
        # the Coulomb force's memory at the last accepted state: each vertex's (u, v, w, theta_x) and friction
        # (F_a, F_t); None outside a run (a static state: no friction)
        self._history = None
        # a full-order string split over MPI ranks: (comm, whether each vertex is this rank's); None: one rank
        self._share = None
        self._mine = None  # (vertex set, this rank's vertices among them, their rows) of the last shared evaluation

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "WallContact":
        signs = (LAW_SIGN[scene.law(scene.contact.axial_friction_law)],
                 LAW_SIGN[scene.law(scene.contact.friction_torque_law)])
        return cls(disc, space, scene.contact, scene.borehole.radius, signs, scene.law(scene.contact.damper_law),
                   scene.contact.culling)

    def with_stiffness_scale(self, factor: float) -> "WallContact":
        """A copy whose wall springs k_FS1, k_FS2 are scaled by ``factor`` (the static continuation)."""
        scaled = copy.copy(self)
        scaled.k1, scaled.k2 = factor * self.k1, factor * self.k2
        scaled._kept_tangent = None
        return scaled

    def fresh(self) -> "WallContact":
        """A copy whose modal tangent is formed afresh and whose friction has no memory yet (a simulation's results
        never depend on another's)."""
        changed = copy.copy(self)
        changed._kept_tangent = None
        changed._history = None
        return changed

    def split_over(self, comm, owned: np.ndarray) -> "WallContact":
        """A copy for a full-order string split over the ranks of ``comm`` (:mod:`~fenics_drill.model.kernels.
        split_band`): the law runs at the vertices this rank ``owned`` only and the ranks' loads are summed, so
        every rank holds the whole evaluation; the tangent is this rank's vertices' own.  The friction's memory,
        updated at accepted steps only, stays every vertex's on every rank."""
        split = copy.copy(self)
        split._share, split._mine, split._near = (comm, owned), None, None
        return split

    def begin(self, t: float, q: np.ndarray) -> None:
        """Start the Coulomb force's memory at the initial state: anchored at q, no force yet."""
        if self.coulomb:
            self._history = (self._at_vertices(q), np.zeros((len(self.x), 2)))

    def accept(self, t: float, q: np.ndarray, qd: np.ndarray) -> None:
        """Anchor the Coulomb force at an accepted state, holding the force each vertex feels there."""
        if not self.coulomb or self._history is None:
            return
        positions, rates = self._at_vertices(q), self._at_vertices(qd)
        _, nodal, _, _ = _vertex_loads(positions, rates, *self._law())
        self._history = (positions, np.column_stack([nodal[:, 0], nodal[:, 3] / self.arm]))

    def _at_vertices(self, x: np.ndarray) -> np.ndarray:
        """(u, v, w, theta_x) of every vertex (a row each) of the dofs' or reduced values x."""
        values = self.every.gather(x) if sp.issparse(self.flat) else self.flat @ x
        return values.reshape(-1, len(FIELDS))

    def kept_on_wall(self, q_from: np.ndarray, q: np.ndarray) -> np.ndarray:
        """q with each vertex that touched the wall at ``q_from`` moved radially to the indentation it had there
        (full space: its (v, w) rows select dofs): a Newmark predictor extrapolates along a straight line, off the
        round wall."""
        lateral = slice(1, 3)  # (v, w) among FIELDS
        before = self._at_vertices(q_from)[:, lateral]
        now = self._at_vertices(q)[:, lateral]
        r_before, r_now = np.hypot(*before.T), np.hypot(*now.T)
        touching = (r_before > self.gap) & (r_now > 0.0)
        scale = np.ones_like(r_now)
        scale[touching] = r_before[touching] / r_now[touching]
        columns = self.every.selection[0].reshape(-1, len(FIELDS))[:, lateral]
        out = q.copy()
        for k in range(2):
            free = columns[:, k] >= 0
            out[columns[free, k]] *= scale[free]
        return out

    def record(self, forces: "WallForces") -> dict[str, float]:
        return {"vertices_in_contact": int(np.count_nonzero(forces.delta > 0))}

    def _law(self, vertices: np.ndarray | None = None) -> tuple:
        """The law's constants at ``vertices`` (default: all), with the Coulomb force's memory there, in the order
        the compiled kernels take them."""
        at = slice(None) if vertices is None else vertices
        history = self._history
        count = len(self.x) if vertices is None else len(vertices)
        anchor, held = (np.zeros((count, len(FIELDS))), np.zeros((count, 2))) if history is None else \
            (np.ascontiguousarray(history[0][at]), np.ascontiguousarray(history[1][at]))
        return (np.ascontiguousarray(self.gap[at]), self.k1, self.k2, self.c, self.damper_law == "printed",
                self.mu_axial, self.mu_torque, np.ascontiguousarray(self.arm[at]), self.v_s, self.coulomb,
                self.stick_stiffness, anchor, held, history is not None)

    def memory(self):
        """What the law's constants depend on besides the vertices: the Coulomb force's memory (its identity
        changes at each accepted step)."""
        return self._history

    #: Vertices within this share of the gap from the wall are evaluated; the others are left out until
    #: q has moved enough, by the bound of :meth:`_near_vertices`, to possibly bring one of them to it.
    NEAR = 0.5

    def _near_vertices(self, q: np.ndarray) -> VertexSet:
        """The vertices that can touch the wall at q, exactly.  At a reference state q_ref the radius of
        every vertex is computed; those farther than NEAR gap from the wall are then left out while
        sum_j c_j |q_j - q_ref_j| < min of their distances to the wall, with c_j the largest
        |P_i[:, j]|_1 among them: by the triangle inequality none of them can have reached it."""
        near = self._near
        if near is not None and near.column_bound @ np.abs(q - near.q_ref) < near.reach:
            return near
        radius = np.hypot(*(self.every.lateral_rows @ q).reshape(-1, 2).T)
        slack = self.gap - radius  # each vertex's distance to the wall
        far = slack > self.NEAR * self.gap
        watched = far if far.any() else np.ones_like(far)  # without far vertices: every vertex, until q moves
        sizes = self._column_sizes[np.flatnonzero(watched)].max(axis=0)
        column_bound = sizes.toarray().ravel() if sp.issparse(sizes) else np.asarray(sizes).ravel()
        reach = float(np.min(slack[far])) if far.any() else self.NEAR * float(np.min(self.gap))
        vertices = np.flatnonzero(~far)
        rows = (len(FIELDS) * vertices[:, None] + np.arange(len(FIELDS))).ravel()
        lateral = (2 * vertices[:, None] + np.arange(2)).ravel()
        packed = None if self.every.packed is None else self.every.packed.at(rows)
        self._near = VertexSet(vertices, self.every.lateral_rows[lateral], self.flat[rows], packed, q.copy(),
                               column_bound, reach)
        return self._near

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> WallForces:
        """The wall force at (q, qd).  The rows of (v, w) find the vertices in contact, the law runs
        compiled over the vertices that can reach the wall, and the law-by-law split is projected only
        when read.  The indentation is -inf at the vertices left out."""
        vertex_set = self._near_vertices(q) if self.culling else self.every
        if self._share is not None:
            return self._shared_evaluation(vertex_set, q, qd, with_tangent)
        if sp.issparse(vertex_set.flat):  # the full space: the rows select dofs
            positions = vertex_set.gather(q).reshape(-1, len(FIELDS))
            rates = vertex_set.gather(qd).reshape(-1, len(FIELDS))
            delta, nodal, laws, potential = _vertex_loads(positions, rates, *self._law(vertex_set.vertices))
            generalised = vertex_set.scatter(nodal.ravel())
        else:
            delta, nodal, laws, potential, generalised, positions, rates = _modal_pass(
                vertex_set.packed.kernel_data(), q.size, q, qd, *self._law(vertex_set.vertices))
        return self.forces_of(vertex_set, (delta, nodal, laws, potential, generalised, positions, rates),
                              with_tangent)

    def _shared_evaluation(self, vertex_set: VertexSet, q: np.ndarray, qd: np.ndarray,
                           with_tangent: bool) -> WallForces:
        """:meth:`evaluate` on a string split over ranks (:meth:`split_over`): the law at this rank's vertices of
        ``vertex_set``; the generalised force, the indentations, the loads and the energy summed over the ranks in
        one collective (each vertex is one rank's, so each sum has one term but the energy's)."""
        comm, owned = self._share
        if self._mine is None or self._mine[0] is not vertex_set:
            mine = np.flatnonzero(owned[vertex_set.vertices])
            rows = (len(FIELDS) * mine[:, None] + np.arange(len(FIELDS))).ravel()
            self._mine = (vertex_set, mine, VertexSet(vertex_set.vertices[mine], None, vertex_set.flat[rows], None))
        _, mine, mine_set = self._mine
        flat = mine_set.flat
        positions = (flat @ q).reshape(-1, len(FIELDS))
        rates = (flat @ qd).reshape(-1, len(FIELDS))
        delta_mine, nodal_mine, laws_mine, potential = _vertex_loads(positions, rates,
                                                                     *self._law(vertex_set.vertices[mine]))
        m, size, names = vertex_set.vertices.size, q.size, len(self.law_names)
        ends = np.cumsum([size, m, m * len(FIELDS), m * len(FIELDS) * names, 1])
        part = np.zeros(ends[-1])
        generalised, delta, nodal, laws, energy = np.split(part, ends[:-1])
        generalised[:] = flat.T @ nodal_mine.ravel()
        delta.reshape(m)[mine] = delta_mine
        nodal.reshape(m, len(FIELDS))[mine] = nodal_mine
        laws.reshape(m, len(FIELDS), names)[mine] = laws_mine
        energy[0] = potential
        total = np.empty_like(part)
        comm.Allreduce(part, total)
        generalised, delta, nodal, laws, energy = np.split(total, ends[:-1])
        out = self.forces_of(vertex_set, (delta, nodal.reshape(m, len(FIELDS)), laws.reshape(m, len(FIELDS), names),
                                          float(energy[0]), generalised, None, None), False)
        if with_tangent:
            out.tangent_data = (mine_set, positions, rates, vertex_set.vertices[mine], delta_mine)
        return out

    def forces_of(self, vertex_set: VertexSet, passed: tuple, with_tangent: bool) -> WallForces:
        """The evaluation of the vertices ``vertex_set`` from what :func:`_modal_pass` gives for them (also what a
        compiled Newton step hands back: solvers/compiled_step.py)."""
        delta, nodal, laws, potential, generalised, positions, rates = passed
        by_law = ProjectedLaws(vertex_set, delta, laws, self.law_names)
        out = WallForces(generalised, potential, by_law, len(self.x), vertex_set.vertices, delta, nodal,
                         tangential_arm=self.arm if self.coulomb else None)
        if with_tangent:  # what the tangent needs, differentiated only if Newton asks for it
            out.tangent_data = (vertex_set, positions, rates, vertex_set.vertices, delta)
        return out

    def evaluated_vertices(self) -> VertexSet:
        """The vertices the next modal evaluation starts from: the culled set of the last one (None before any),
        or all of them without culling; each evaluation checks the culled set's bound itself."""
        return self._near if self.culling else self.every

    def kernel_data(self, vertex_set: VertexSet) -> tuple:
        """(the packed rows of ``vertex_set``, the law's constants, and the bound that keeps it: its columns'
        sizes, reference q and reach; none for every vertex) for
        :func:`~fenics_drill.solvers.compiled_residual.residual_at`."""
        size = vertex_set.flat.shape[1]
        law = tuple(value if isinstance(value, (bool, np.ndarray)) else float(value)
                    for value in self._law(vertex_set.vertices))
        rows = vertex_set.packed.kernel_data()
        if vertex_set.q_ref is None:
            return rows, law, np.zeros(size), np.zeros(size), np.inf
        return rows, law, vertex_set.column_bound, vertex_set.q_ref, float(vertex_set.reach)

    def tangent(self, forces: WallForces, c_u: float, c_v: float):
        """c_u d f/dq + c_v d f/dqd of the generalised wall force (None without contact):
        sum over the vertices in contact of R_i^T A_i R_i, with R_i the four rows of [Phi] of
        vertex i and A_i the 4 x 4 block of the pointwise derivatives.  In a modal space the product is
        formed in single precision (half the cost of the step's largest product): the tangent only steers
        Newton, and the residual, in double precision, decides when it has converged."""
        if forces.tangent_data is None:
            return None
        rows_of, positions, rates, vertices, delta = forces.tangent_data
        flat = rows_of.flat
        active = np.flatnonzero(delta > 0)
        if active.size == 0:
            return None
        blocks = _contact_blocks(active, positions, rates, *self._law(vertices), c_u, c_v)
        if sp.issparse(flat):  # the full space: each row of [Phi] selects one free dof (or none, at a support)
            return Triplets(*_selected_block_entries(active, *rows_of.selection, blocks), (flat.shape[1],) * 2)
        return self._updated_tangent(vertices[active], blocks)

    #: A vertex's block enters the modal tangent afresh when it changed by more than this share of the largest
    #: block since it last did; the tangent then differs from the exact one by less than that share of the
    #: largest block at each vertex (Newton's residual, exact, still decides convergence).
    BLOCK_TOLERANCE = 1e-4
    #: Updates of the kept tangent after which it is formed whole again: each adds the single-precision
    #: round-off of its own product, and this bounds their sum.
    UPDATES_BEFORE_REFORMING = 100

    def _updated_tangent(self, vertices: np.ndarray, blocks: np.ndarray) -> np.ndarray:
        """sum_i R_i^T A_i R_i in a modal space, with the blocks A_i of the vertices in contact, as an update
        of the last tangent formed: R_i^T (A_i - A_i_kept) R_i is added for the vertices whose block moved by
        more than BLOCK_TOLERANCE of the largest one, and the others keep theirs.  In steady contact a step's
        tangent changes at a fraction of the vertices, and so costs a fraction of the whole product; where
        most blocks moved it is formed whole."""
        kept = self._kept_tangent
        if kept is None or kept[2] >= self.UPDATES_BEFORE_REFORMING:
            size = self.flat.shape[1]
            kept = (np.zeros((size, size)), np.zeros((len(self.x), len(FIELDS), len(FIELDS))), 0)
            tolerance = 0.0  # every block in contact enters
        else:
            tolerance = self.BLOCK_TOLERANCE
        matrix, kept_blocks, updates = kept
        changed, increments, moved_blocks = _moved_blocks(vertices, blocks, kept_blocks, tolerance)
        if updates and 2 * changed.size > vertices.size:
            # most blocks moved (a change of step, contact lost): formed whole, as cheap, and without the
            # round-off of larger blocks that an update would leave in a smaller tangent
            self._kept_tangent = None
            return self._updated_tangent(vertices, blocks)
        kept_blocks = moved_blocks
        if changed.size:
            packed = self.every.packed
            rows, weighted, offsets = _weighted_rows(packed.kernel_data(), changed, increments)
            by_field = np.empty((offsets[-1], offsets[-1]), dtype=np.float32)
            for f in range(len(FIELDS)):  # block row f: R_f^T (A R)_f, one single-precision BLAS product
                by_field[offsets[f]:offsets[f + 1]] = rows[f, :, :packed.counts[f]].T @ weighted[f]
            matrix = _scattered_square(matrix.copy(), packed.columns, packed.counts, by_field.astype(float))
        self._kept_tangent = (matrix, kept_blocks, updates + 1)
        return matrix
