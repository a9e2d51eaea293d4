"""The wall's laws at every vertex, compiled: the geometry of each vertex against the wall (radius, indentation,
normal and tangent), the law the scene chose (:mod:`~fenics_drill.model.forces.wall.coulomb` or
:mod:`~fenics_drill.model.forces.wall.paper_friction`, with :mod:`~fenics_drill.model.forces.wall.normal_force`), the
nodal loads and their 4 x 4 tangent blocks, and their projection on a modal space.

Data layout: a vertex's (u, v, w, theta_x) are one row of ``positions`` and ``rates``; its loads one row
(F_a, F_v, F_w, T) of ``nodal``; ``laws[i, field, law]`` splits them into the damper and the two parts of friction;
a block's rows and columns follow FIELDS.  In a modal space the rows of [Phi] of the four fields at each vertex are
interleaved (row 4 i + k: field k at vertex i) and packed by field (:mod:`~fenics_drill.model.kernels.packed_rows`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

from fenics_drill.model.discretization import THETA_X as TX_FIELD
from fenics_drill.model.discretization import U as U_FIELD
from fenics_drill.model.discretization import V as V_FIELD
from fenics_drill.model.discretization import W as W_FIELD
from fenics_drill.model.forces.wall.coulomb import _contact_slip, _coulomb_block, _return_map
from fenics_drill.model.forces.wall.normal_force import _damper, _normal_force
from fenics_drill.model.forces.wall.paper_friction import _friction, _paper_block
from fenics_drill.model.kernels.compiled import REASSOCIATE, kernel
from fenics_drill.model.kernels.packed_rows import add_row, dot_row_twice, gathered, scatter

FIELDS = (U_FIELD, V_FIELD, W_FIELD, TX_FIELD)  # the fields the wall acts on: F_a, F_v, F_w, T_FS


@njit(cache=True, inline="always")
def _vertex_law(i, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                stick_stiffness, anchor, held, sticking, delta, nodal, laws):
    """Eqs. (16)-(19) at vertex i with position (u, v, w, theta_x) (row i of ``positions``) and rates (their
    time derivatives, row i of ``rates``; both read in place: a row view per vertex costs more than the law out of
    contact): its indentation, nodal loads and the loads of each law (the damper; the axial friction; the
    friction torque, or with ``coulomb`` the tangential part of the one friction force, lateral and torque);
    returns the springs' energy.  ``gap``: each vertex's clearance; ``arm``: each vertex's friction torque's arm,
    its contact radius for the Coulomb force at the contact point, R_bh in (19).  The Coulomb force
    (:func:`_return_map`) starts from each vertex's ``anchor`` and ``held`` force at the step's start; without
    ``sticking`` (no step under way: a static state) it is zero."""
    v, w = positions[i, 1], positions[i, 2]
    r = np.hypot(v, w)
    d = r - gap[i]
    delta[i] = d
    if d <= 0.0:
        return 0.0
    n_v, n_w = v / r, w / r
    normal = _normal_force(d, n_v * rates[i, 1] + n_w * rates[i, 2], k1, k2, damping, printed)
    damper = normal + k1 * d + k2 * d**3  # with the clip that keeps the wall from pulling
    laws[i, 1, 0], laws[i, 2, 0] = damper * n_v, damper * n_w
    if coulomb:  # t = (-n_w, n_v): the wall's tangent, the direction the contact point turns with theta_x
        axial = tangential = 0.0
        if sticking:
            g_a, g_t = _contact_slip(i, v, w, n_v, n_w, positions, anchor, arm)
            axial, tangential, _ = _return_map(normal, held[i, 0], held[i, 1], g_a, g_t, mu_axial, stick_stiffness)
        nodal[i, 0], nodal[i, 3] = axial, arm[i] * tangential
        nodal[i, 1], nodal[i, 2] = normal * n_v - tangential * n_w, normal * n_w + tangential * n_v
        laws[i, 0, 1] = axial
        laws[i, 1, 2], laws[i, 2, 2], laws[i, 3, 2] = -tangential * n_w, tangential * n_v, arm[i] * tangential
    else:
        axial, torque = _friction(normal, rates[i, 0], rates[i, 3], mu_axial, mu_torque, arm[i], v_s)
        nodal[i, 0], nodal[i, 1], nodal[i, 2], nodal[i, 3] = axial, normal * n_v, normal * n_w, torque
        laws[i, 0, 1] = axial
        laws[i, 3, 2] = torque
    return 0.5 * k1 * d**2 + 0.25 * k2 * d**4


@kernel
def _vertex_loads(positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                  stick_stiffness, anchor, held, sticking):
    """Eqs. (16)-(19) at every vertex of (u, v, w, theta_x) ``positions`` and their ``rates``: indentation, nodal
    loads (F_a, F_v, F_w, T), the loads of the damper and of the two parts of friction (vertex, field, law), and
    the springs' energy."""
    n = positions.shape[0]
    delta, nodal, laws = np.empty(n), np.zeros((n, 4)), np.zeros((n, 4, 3))
    potential = 0.0
    for i in range(n):
        potential += _vertex_law(i, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm,
                                 v_s, coulomb, stick_stiffness, anchor, held, sticking, delta, nodal, laws)
    return delta, nodal, laws, potential


@kernel(fastmath=REASSOCIATE)
def _modal_pass(packed, size, q, qd, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                stick_stiffness, anchor, held, sticking):
    """:func:`_vertex_loads` in a modal space (``size`` coordinates), in one pass over the rows of [Phi] of
    (u, v, w, theta_x) at each vertex, interleaved and packed by field (``packed``: :meth:`~fenics_drill.model.
    packed_rows.FieldPackedRows.kernel_data`, groups in the order of FIELDS): each vertex's positions and
    rates, its law, and [Phi]^T of its nodal loads, while its rows are in cache.  Also returns the positions
    and rates.  The split by law is left to :func:`_projected_laws` (the budget reads it at accepted steps
    only: in the pass it cost a sixth of the pass at every Newton iterate)."""
    values, _, columns, counts = packed
    n = values.shape[0] // 4
    q_at, qd_at = gathered(q, columns), gathered(qd, columns)
    q_u, q_v, q_w, q_t = q_at[0], q_at[1], q_at[2], q_at[3]
    qd_u, qd_v, qd_w, qd_t = qd_at[0], qd_at[1], qd_at[2], qd_at[3]
    c_u, c_v, c_w, c_t = counts[0], counts[1], counts[2], counts[3]
    loads = np.zeros(columns.shape)
    load_u, load_v, load_w, load_t = loads[0], loads[1], loads[2], loads[3]
    delta, nodal, laws = np.empty(n), np.zeros((n, 4)), np.zeros((n, 4, 3))
    positions, rates = np.empty((n, 4)), np.empty((n, 4))
    potential = 0.0
    for i in range(n):
        r = 4 * i
        positions[i, 0], rates[i, 0] = dot_row_twice(values, r, q_u, qd_u, c_u)
        positions[i, 1], rates[i, 1] = dot_row_twice(values, r + 1, q_v, qd_v, c_v)
        positions[i, 2], rates[i, 2] = dot_row_twice(values, r + 2, q_w, qd_w, c_w)
        positions[i, 3], rates[i, 3] = dot_row_twice(values, r + 3, q_t, qd_t, c_t)
        potential += _vertex_law(i, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s,
                                 coulomb, stick_stiffness, anchor, held, sticking, delta, nodal, laws)
        if delta[i] > 0.0:
            add_row(load_u, values, r, nodal[i, 0], c_u)
            add_row(load_v, values, r + 1, nodal[i, 1], c_v)
            add_row(load_w, values, r + 2, nodal[i, 2], c_w)
            add_row(load_t, values, r + 3, nodal[i, 3], c_t)
    generalised = np.zeros(size)
    scatter(generalised, columns, counts, loads)
    return delta, nodal, laws, potential, generalised, positions, rates


#: :func:`_modal_pass` itself, for compiled code that evaluates the wall (solvers/compiled_residual.py).
MODAL_PASS = _modal_pass.compiled


@kernel(fastmath=REASSOCIATE)
def _projected_laws(packed, size, delta, laws):
    """[Phi]^T of the loads of each law (the damper and the two parts of friction: rows of the result), over the
    vertices in contact (delta > 0) of the packed rows of :func:`_modal_pass`."""
    values, _, columns, counts = packed
    by_law = np.zeros((3,) + columns.shape)  # each law's packed sums, by field
    for i in range(delta.size):
        if delta[i] > 0.0:
            r = 4 * i
            for law in range(3):
                for f in range(4):
                    if laws[i, f, law] != 0.0:
                        add_row(by_law[law, f], values, r + f, laws[i, f, law], counts[f])
    projected = np.zeros((3, size))
    for law in range(3):
        scatter(projected[law], columns, counts, by_law[law])
    return projected


@kernel
def _contact_blocks(active, positions, rates, gap, k1, k2, damping, printed, mu_axial, mu_torque, arm, v_s, coulomb,
                    stick_stiffness, anchor, held, sticking, c_u, c_v):
    """c_u d(F_a, F_v, F_w, T)/d(u, v, w, theta_x) + c_v d(...)/d(velocities) at every vertex in contact:
    one 4 x 4 block per vertex, rows and columns in the order of FIELDS."""
    blocks = np.zeros((active.size, 4, 4))
    for k in range(active.size):
        i = active[k]
        v, w = positions[i, 1], positions[i, 2]
        r = np.hypot(v, w)
        d = r - gap[i]
        n_v, n_w = v / r, w / r
        dv, dw = rates[i, 1], rates[i, 2]
        d_rate = n_v * dv + n_w * dw
        normal = _normal_force(d, d_rate, k1, k2, damping, printed)
        if normal >= 0.0:  # where the clip of (17) is active the force and its derivatives vanish
            continue
        _, damper_by_delta, damper_by_rate = _damper(d, d_rate, damping, printed)
        spring = -k1 - 3.0 * k2 * d * d + damper_by_delta
        # F_n of (v, w, v_dot, w_dot): d delta / d(v, w) = n, d delta_rate / d(v, w) = (v_dot - delta_rate n) / r,
        # d delta_rate / d(v_dot, w_dot) = n
        dfn_v = c_u * (spring * n_v + damper_by_rate * (dv - d_rate * n_v) / r) + c_v * damper_by_rate * n_v
        dfn_w = c_u * (spring * n_w + damper_by_rate * (dw - d_rate * n_w) / r) + c_v * damper_by_rate * n_w
        if coulomb:
            _coulomb_block(blocks[k], i, normal, dfn_v, dfn_w, n_v, n_w, r, positions, anchor, held, sticking,
                           mu_axial, arm, stick_stiffness, c_u)
            continue
        _paper_block(blocks[k], normal, dfn_v, dfn_w, n_v, n_w, r, rates[i, 0], rates[i, 3], mu_axial, mu_torque,
                     arm[i], v_s, c_u, c_v)
    return blocks


@kernel
def _weighted_rows(packed, active, blocks):
    """R and A R by field, in single precision, from the rows of (u, v, w, theta_x) at the vertices ``active``,
    packed by field (:meth:`~fenics_drill.model.kernels.packed_rows.FieldPackedRows.kernel_data`, groups in the order of
    FIELDS), and the blocks A of :func:`_contact_blocks`.  With the fields' columns concatenated (field g's at
    ``offsets[g]``), ``rows[f]`` holds each vertex's row of field f on its own columns and ``weighted[f]`` its
    row f of A R on all of them; the wall's tangent is the sum over f of rows[f]^T weighted[f] (block row f),
    scattered onto the columns (:func:`_scattered_square`): a quarter of the dense product R^T (A R)."""
    values, _, columns, counts = packed
    offsets = np.zeros(5, dtype=np.int64)
    for f in range(4):
        offsets[f + 1] = offsets[f] + counts[f]
    rows = np.zeros((4, active.size, columns.shape[1]), dtype=np.float32)
    weighted = np.zeros((4, active.size, offsets[4]), dtype=np.float32)
    for k in range(active.size):
        base = 4 * active[k]
        for f in range(4):
            for c in range(counts[f]):
                rows[f, k, c] = values[base + f, c]
        for o in range(4):
            for f in range(4):
                a = blocks[k, o, f]
                if a != 0.0:
                    for c in range(counts[f]):
                        weighted[o, k, offsets[f] + c] += a * values[base + f, c]
    return rows, weighted, offsets


@kernel
def _scattered_square(matrix, columns, counts, packed):
    """matrix[i, j] += packed[a, b] with i, j the columns of the packed rows' concatenated fields a, b."""
    index = np.empty(packed.shape[0], dtype=np.int64)
    at = 0
    for f in range(counts.size):
        for c in range(counts[f]):
            index[at] = columns[f, c]
            at += 1
    for a in range(index.size):
        for b in range(index.size):
            matrix[index[a], index[b]] += packed[a, b]
    return matrix


@kernel
def _moved_blocks(vertices, blocks, kept, tolerance):
    """The vertices whose block moved by more than ``tolerance`` times the largest block, (vertex, field,
    field) ``kept`` against the ``blocks`` of the ``vertices`` in contact (zero elsewhere): their indices,
    the increments of their blocks, and the kept blocks with theirs replaced.  Scalar loops, without
    temporaries or views: it runs at every wall tangent."""
    n, fields = kept.shape[0], kept.shape[1]
    at = np.full(n, -1)  # each vertex's block among ``blocks`` (-1: out of contact, a zero block)
    for k in range(vertices.size):
        at[vertices[k]] = k
    scale = 0.0
    for value in kept.reshape(-1):
        scale = max(scale, abs(value))
    for value in blocks.reshape(-1):
        scale = max(scale, abs(value))
    limit = tolerance * scale
    moved = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        k = at[i]
        for a in range(fields):
            for b in range(fields):
                if abs((blocks[k, a, b] if k >= 0 else 0.0) - kept[i, a, b]) > limit:
                    moved[i] = True
    changed = np.flatnonzero(moved)
    increments = np.empty((changed.size, fields, fields))
    updated = kept.copy()
    for j in range(changed.size):
        i = changed[j]
        k = at[i]
        for a in range(fields):
            for b in range(fields):
                current = blocks[k, a, b] if k >= 0 else 0.0
                increments[j, a, b] = current - kept[i, a, b]
                updated[i, a, b] = current
    return changed, increments, updated


@kernel
def _selected_block_entries(active, columns, values, blocks):
    """The full space's tangent entries (value, row, column) of the vertices ``active``' 4 x 4 blocks, whose rows
    select the dofs ``columns`` with ``values`` (:func:`_selection`, -1: none): s_a A_ab s_b at (dof_a, dof_b), row by
    row, leaving out unselected dofs and zero values."""
    fields = blocks.shape[1]
    count = active.size * fields * fields
    data, rows, cols = np.empty(count), np.empty(count, dtype=np.int64), np.empty(count, dtype=np.int64)
    n = 0
    for k in range(active.size):
        for a in range(fields):
            row, scale_a = columns[fields * active[k] + a], values[fields * active[k] + a]
            for b in range(fields):
                column, scale_b = columns[fields * active[k] + b], values[fields * active[k] + b]
                value = scale_a * blocks[k, a, b] * scale_b
                if row >= 0 and column >= 0 and value != 0.0:
                    data[n], rows[n], cols[n] = value, row, column
                    n += 1
    return data[:n], rows[:n], cols[:n]


def _selection(rows: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
    """(column, value) of each row of a full space's [Phi] rows, which hold one entry or none (a dof held by
    a support: column -1, value 0)."""
    counts = np.diff(rows.indptr)
    if counts.max(initial=0) > 1:
        raise ValueError("rows of the full space's [Phi] hold one entry each")
    columns, values = np.full(rows.shape[0], -1, dtype=np.int64), np.zeros(rows.shape[0])
    first = rows.indptr[:-1][counts == 1]
    columns[counts == 1], values[counts == 1] = rows.indices[first], rows.data[first]
    return columns, values
