"""The residual (65) of a modal model with the usual forces, in one compiled call.

:meth:`DrillstringModel.evaluate` runs each force's kernel from Python and sums their loads there; at the
paper scene's two evaluations per step that glue costs about as much as the kernels (docs/performance.md).  :func:`residual_at` runs the same kernels (the sampled internal force of
:mod:`~fenics_drill.model.kernels.cell_kernels`, the wall's :func:`~fenics_drill.model.forces.wall.vertex_passes._modal_pass`,
the bit law (20)-(22)) and the same sums, in the same order, for the compiled Newton step of
:mod:`fenics_drill.solvers.compiled_step`.

It covers a modal model whose drive holds the top's rotation (and its axial motion, or pushes it with a hook
load), and whose point forces are gravity, the wall, the paper's bit-rock law and the damping above the band
(:func:`CompiledResidual.of` returns None for any other model, which then runs in Python).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fenics_drill.model.kernels.cell_kernels import ASSEMBLE_CELLS_AT
from fenics_drill.model.forces.bit_rock import LAW as BIT_LAW
from fenics_drill.model.forces.bit_rock import BitRock
from fenics_drill.model.forces.gravity import Gravity
from fenics_drill.model.forces.wall.vertex_passes import MODAL_PASS as WALL_PASS
from fenics_drill.model.forces.wall_contact import WallContact
from fenics_drill.model.internal_force import AssembledInternalForce
from fenics_drill.model.reduction.out_of_band_damping import OutOfBandDamping
from fenics_drill.model.kernels.packed_rows import NO_ROWS

#: The kinds of point force :func:`residual_at` sums, in the order of the model's list.
GRAVITY, WALL, BIT_ROCK, DAMPING = 0, 1, 2, 3
_KINDS = {Gravity: GRAVITY, WallContact: WALL, BitRock: BIT_ROCK, OutOfBandDamping: DAMPING}

#: What :func:`residual_at` gives of a wall and a bit the model does not have.
NO_WALL = (np.empty(0), np.empty((0, 4)), np.empty((0, 4, 3)), 0.0, np.empty(0), np.empty((0, 4)), np.empty((0, 4)))
NO_BIT = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
#: The wall law's constants (:meth:`WallContact._law`'s order and types) of a model without a wall.
NO_WALL_LAW = (np.empty(0), 0.0, 0.0, 0.0, False, 0.0, 0.0, np.empty(0), 0.0, False, 0.0, np.empty((0, 4)),
               np.empty((0, 2)), False)


@njit(cache=True)
def _internal_force(internal, q, qd, qdd):
    """:meth:`AssembledInternalForce.evaluate` of a modal space: [K C M] (q, qd, qdd) plus the sampled
    remainder (a sample), or the cells' force alone (all cells)."""
    sampled, linear_rows, offset, rows, row_function, row_dof, basis, basis_by_field, address, constants, \
        coordinates, cell_dofs, size = internal
    state = np.concatenate((q, qd, qdd))
    cells = ASSEMBLE_CELLS_AT(address, offset, rows, row_function, row_dof, state, constants, coordinates,
                               cell_dofs, size, False, basis, basis_by_field, True)
    if not sampled:
        return cells
    return np.dot(linear_rows, state) + cells


@njit(cache=True)
def residual_at(internal, forces, order, constraints, drive_loads, q, qd, qdd, mu):
    """The residual, internal and external forces of :meth:`DrillstringModel.evaluate` at (q, qd, qdd, mu), with
    what the wall's pass and the bit law gave (for the step's evaluation object), and whether q is still within
    the bound of the wall's culled vertices (False: the evaluation is not the model's, which would cull anew).

    ``forces``: (gravity load, wall rows (packed by field: FieldPackedRows.kernel_data), wall law, culling
    bound, reference q, reach, bit rows, bit unit loads, bit law constants, damping matrix); ``order``: the kinds
    of the model's forces in its order; ``drive_loads``: the drive's generalised loads, the same at every state
    (:meth:`~fenics_drill.model.top_drive.TopDrive.constant_loads`)."""
    gravity, wall_rows, law, column_bound, q_ref, reach, bit_rows, bit_units, bit_law, damping = forces
    internal_force = _internal_force(internal, q, qd, qdd)
    external = drive_loads.copy()
    within = True
    wall, bit = NO_WALL, NO_BIT
    for kind in order:
        if kind == GRAVITY:
            external += gravity
        elif kind == WALL:
            within = np.dot(column_bound, np.abs(q - q_ref)) < reach
            wall = WALL_PASS(wall_rows, q.size, q, qd, law[0], law[1], law[2], law[3], law[4], law[5], law[6], law[7],
                             law[8], law[9], law[10], law[11], law[12], law[13])
            external += wall[4]
        elif kind == BIT_ROCK:
            rates = np.dot(bit_rows, qd)
            force, torque, d_force, d_torque_velocity, d_torque_spin = BIT_LAW(
                rates[0], rates[1], bit_law[0], bit_law[1], bit_law[2], bit_law[3])
            external += force * bit_units[0] + torque * bit_units[1]
            bit = (rates[0], rates[1], force, torque, d_force, d_torque_velocity, d_torque_spin)
        else:
            external += -np.dot(damping, qd)
    residual = internal_force - external
    if mu.size:
        residual += np.dot(constraints.T, mu)
    return residual, internal_force, external, wall, bit, within


class CompiledResidual:
    """What :func:`residual_at` needs of one model: its internal force's cells and the forces' data."""

    def __init__(self, model, internal: tuple, order: np.ndarray, drive_loads: np.ndarray):
        self.model, self.internal, self.order, self.drive_loads = model, internal, order, drive_loads
        self.wall = model.force(WallContact.name)
        self._forces = (None, None)  # ((the wall's vertex set, its memory), the forces' data for them) last given

    @classmethod
    def of(cls, model) -> "CompiledResidual | None":
        """The compiled residual of ``model``, or None where it does not cover the model (module doc)."""
        internal = (model.internal.kernel_data() if isinstance(model.internal, AssembledInternalForce) else None)
        drive_loads = model.drive.constant_loads(model.size)
        if (internal is None or drive_loads is None or model.drive.inertia
                or any(type(f) not in _KINDS for f in model.forces)
                or len({type(f) for f in model.forces}) != len(model.forces)):
            return None
        return cls(model, internal, np.array([_KINDS[type(f)] for f in model.forces], dtype=np.int64), drive_loads)

    def forces(self):
        """The forces' data of :func:`residual_at` now (the wall's culled vertices are the last evaluation's),
        or None if the wall has culled none yet; formed again only when the wall's vertex set or its friction's
        memory has changed."""
        vertices = self.wall.evaluated_vertices() if self.wall is not None else None
        if self.wall is not None and vertices is None:
            return None
        memory = self.wall.memory() if self.wall is not None else None
        key = self._forces[0]
        if self._forces[1] is None or vertices is not key[0] or memory is not key[1]:
            self._forces = ((vertices, memory), self._formed_forces(vertices))
        return self._forces[1]

    def _formed_forces(self, vertices) -> tuple:
        size = self.model.size
        gravity, bit, damping = (self.model.force(name) for name in (Gravity.name, BitRock.name,
                                                                    OutOfBandDamping.name))
        wall = (self.wall.kernel_data(vertices) if self.wall is not None else
                (NO_ROWS, NO_WALL_LAW, np.zeros(size), np.zeros(size), np.inf))
        bit_data = bit.kernel_data() if bit is not None else (np.empty((2, size)), np.empty((2, size)), (0.0,) * 4)
        return (np.zeros(size) if gravity is None else gravity.load, *wall, *bit_data,
                np.empty((0, size)) if damping is None else damping.damping)

    def evaluations(self, q, qd, wall_passed) -> dict:
        """The forces' evaluation objects at an accepted (q, qd), each as its own ``evaluate`` gives it (the wall's
        from what the compiled pass gave)."""
        out = {}
        for force in self.model.forces:
            if force is self.wall:
                out[force.name] = force.forces_of(force.evaluated_vertices(), wall_passed, True)
            else:
                out[force.name] = force.evaluate(q, qd, with_tangent=True)
        return out
