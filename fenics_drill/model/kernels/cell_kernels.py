"""FFCx's element kernels called from Numba: a form assembled on an element sample without DOLFINx's
assembler, and an expression at every cell without DOLFINx's coefficient packing.

A sampled internal force (:mod:`fenics_drill.model.reduction.hyper_reduction`) lives on a handful of elements, and
at every Newton iterate DOLFINx's ``assemble_vector`` spent about ten times longer in its set-up than in
the kernels of those cells (docs/performance.md).  :class:`CellAssembly` calls the form's
generated ``tabulate_tensor`` directly, cell after cell, and adds each element tensor at its dofs: the
sampled force, its tangents and its energies.  The kernel is called through its address, so the compiled
loop is cached on disk like every other kernel.
:class:`CellExpression` does the same for the von Mises probe's strain expression, at every accepted step.
"""

from __future__ import annotations

import cffi
import numpy as np
import ufl
from dolfinx import fem
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from fenics_drill.model.kernels.compiled import REASSOCIATE, kernel
from fenics_drill.model.kernels.packed_rows import NO_ROWS, add_row, gathered, scatter

_FFI = cffi.FFI()


@intrinsic
def _call_at(typingctx, address, element, coefficients, constants, coordinates, entity, permutation, data):
    """Call the C function at ``address`` with the seven pointers of a ufcx ``tabulate_tensor``."""
    signature = types.void(address, element, coefficients, constants, coordinates, entity, permutation, data)

    def codegen(context, builder, sig, args):
        function = ir.FunctionType(ir.VoidType(), [context.get_value_type(t) for t in sig.args[1:]])
        builder.call(builder.inttoptr(args[0], function.as_pointer()), args[1:])
        return context.get_dummy_value()

    return signature, codegen


@njit(cache=True, inline="always")
def _cell_tensor(address, out, coefficients, constants, coordinates, entity, permutation):
    """One cell's element tensor into ``out`` by the kernel at ``address`` (ufcx ``tabulate_tensor``), from the cell's
    packed coefficients and coordinates (an interval's cells need no entity index or permutation: zeros)."""
    _call_at(address, _FFI.from_buffer(out), _FFI.from_buffer(coefficients), _FFI.from_buffer(constants),
             _FFI.from_buffer(coordinates), _FFI.from_buffer(entity), _FFI.from_buffer(permutation),
             _FFI.from_buffer(permutation))


@njit(cache=True, fastmath=set(REASSOCIATE))
def _add_cells(address, coefficients, constants, coordinates, cell_dofs, size, square, basis, basis_by_field, out):
    """Add every cell's element tensor to ``out``: at the positions ``cell_dofs`` (a vector of ``size``, or
    with ``square`` a (size x size) matrix, row-major: the element matrix's rows are its test functions);
    or, with a ``basis`` of N > 0 columns (the rows of [Phi] at the dofs), projected on it: P_c^T f_c (from
    the same rows packed by field, ``basis_by_field``: :mod:`~fenics_drill.model.kernels.packed_rows`), or
    P_c^T K_c P_c (N x N) with P_c the basis rows of cell c's dofs, summed over the cells as one product of
    the stacked P_c and K_c P_c (BLAS: three quarters of the work, 52 cells of the printed kinematics)."""
    n, modes = cell_dofs.shape[1], basis.shape[1]
    values, field, columns, counts = basis_by_field
    sums = np.zeros(columns.shape)  # P^T f on each field's columns
    element = np.empty(n * n if square else n)
    # a projected matrix: K_c P_c and P_c of every cell stacked, and P^T (K P) as one BLAS product at the end
    stacked = cell_dofs.shape[0] * n if square and modes > 0 else 0
    weighted, rows, cell_rows = np.empty((stacked, modes)), np.empty((stacked, modes)), np.empty((n, modes))
    entity, permutation = np.zeros(1, dtype=np.int32), np.zeros(1, dtype=np.uint8)
    for c in range(cell_dofs.shape[0]):
        element[:] = 0.0
        _cell_tensor(address, element, coefficients[c], constants, coordinates[c], entity, permutation)
        if modes == 0 and square:
            for k in range(n):
                for m in range(n):
                    out[cell_dofs[c, k] * size + cell_dofs[c, m]] += element[k * n + m]
        elif modes == 0:
            for k in range(n):
                out[cell_dofs[c, k]] += element[k]
        elif square:  # P_c, the rows of [Phi] at the cell's dofs, and K_c P_c (BLAS: a loop stores every sum)
            for k in range(n):
                cell_rows[k, :] = basis[cell_dofs[c, k], :]
            rows[c * n:(c + 1) * n, :] = cell_rows
            weighted[c * n:(c + 1) * n, :] = np.dot(element.reshape(n, n), cell_rows)
        else:
            for k in range(n):
                value, row = element[k], cell_dofs[c, k]
                add_row(sums[field[row]], values, row, value, counts[field[row]])
    if stacked:  # sum over the cells of P_c^T (K_c P_c)
        out += np.dot(rows.T, weighted).ravel()
    elif modes > 0 and not square:
        scatter(out, columns, counts, sums)


@njit(cache=True)
def _zeros_for(size, square, basis):
    """The output of :func:`_add_cells`: at the dofs, or projected on the basis's columns."""
    m = basis.shape[1] if basis.shape[1] > 0 else size
    return np.zeros(m * m if square else m)


@kernel
def _assemble_cells(address, coefficients, constants, coordinates, cell_dofs, size, square):
    """The sum of the cells' element tensors (:func:`_add_cells`) at their dofs from their packed coefficients."""
    none = np.empty((size, 0))
    out = _zeros_for(size, square, none)
    _add_cells(address, coefficients, constants, coordinates, cell_dofs, size, square, none, NO_ROWS, out)
    return out


@njit(cache=True, fastmath=set(REASSOCIATE))
def _packed_at(offset, rows, row_function, row_dof, state, basis_by_field, modes):
    """The packed coefficients ``offset`` plus the functions' values at the dofs: entry ``rows[i]`` is the value
    of function ``row_function[i]`` (its reduced values are that slice of ``state``) at dof ``row_dof[i]``, row
    ``row_dof[i]`` of the basis (``modes`` columns) times them; the rows packed by field, ``basis_by_field``
    (:meth:`~fenics_drill.model.kernels.packed_rows.FieldPackedRows.kernel_data`), take a quarter of the dense rows'
    products."""
    values, field, columns, counts = basis_by_field
    functions = state.size // modes  # one to three (U; U, V; U, V, A)
    at = np.zeros((3,) + columns.shape)  # each function's reduced values at every field's columns
    for f in range(functions):
        at[f] = gathered(state[f * modes:(f + 1) * modes], columns)
    dof_values = np.zeros((values.shape[0], 3))  # (dofs, functions): one pass over the rows, the sums at a time
    for d in range(values.shape[0]):
        g = field[d]
        u = v = a = 0.0
        if functions == 1:  # an energy of U alone: a third of the products
            for k in range(counts[g]):
                u += values[d, k] * at[0, g, k]
        elif functions == 2:
            for k in range(counts[g]):
                b = values[d, k]
                u += b * at[0, g, k]
                v += b * at[1, g, k]
        else:
            for k in range(counts[g]):
                b = values[d, k]
                u += b * at[0, g, k]
                v += b * at[1, g, k]
                a += b * at[2, g, k]
        dof_values[d, 0], dof_values[d, 1], dof_values[d, 2] = u, v, a
    out = offset.copy()
    for i in range(rows.size):
        out[rows[i]] += dof_values[row_dof[i], row_function[i]]
    return out


@kernel(fastmath=REASSOCIATE)
def _assemble_cells_at(address, offset, rows, row_function, row_dof, state, constants, coordinates, cell_dofs, size,
                       square, basis, basis_by_field, projected):
    """:func:`_assemble_cells` from the packed coefficients of :func:`_packed_at`, the result projected on
    ``basis`` if ``projected`` (a vector or matrix), else summed as it is (a number); ``basis_by_field``: the
    basis packed by field."""
    coefficients = _packed_at(offset, rows, row_function, row_dof, state, basis_by_field, basis.shape[1])
    projection = basis if projected else np.empty((basis.shape[0], 0))
    out = _zeros_for(size, square, projection)
    _add_cells(address, coefficients.reshape(coordinates.shape[0], -1), constants, coordinates, cell_dofs, size,
               square, projection, basis_by_field, out)
    return out


#: :func:`_assemble_cells_at` itself, for compiled code that assembles a force (solvers/compiled_residual.py).
ASSEMBLE_CELLS_AT = _assemble_cells_at.compiled


@kernel(fastmath=REASSOCIATE)
def _functionals_at(address, offset, rows, row_function, row_dof, states, constants, coordinates, cell_dofs, basis,
                    basis_by_field):
    """A functional (a form of rank 0) at each row of ``states``, as :func:`_assemble_cells_at` gives it for one:
    one call for many states (the energies of a batch of accepted steps)."""
    out = np.empty(states.shape[0])
    none = np.empty((basis.shape[0], 0))
    for s in range(states.shape[0]):
        coefficients = _packed_at(offset, rows, row_function, row_dof, states[s], basis_by_field, basis.shape[1])
        value = np.zeros(1)
        _add_cells(address, coefficients.reshape(coordinates.shape[0], -1), constants, coordinates, cell_dofs, 1, False,
                   none, NO_ROWS, value)
        out[s] = value[0]
    return out


@kernel
def _tabulate_cells(address, coefficients, constants, coordinates, size):
    """The element tensor of ``size`` values of every cell, one row per cell."""
    out = np.zeros((coordinates.shape[0], size))
    entity, permutation = np.zeros(1, dtype=np.int32), np.zeros(1, dtype=np.uint8)
    for c in range(coordinates.shape[0]):
        _cell_tensor(address, out[c], coefficients[c], constants, coordinates[c], entity, permutation)
    return out


@kernel
def _kept_cell_entries(address, coefficients, constants, coordinates, size, start, local):
    """Entries ``local[start[c]:start[c + 1]]`` of each cell c's element tensor (of ``size`` values), one cell after
    the other: the entries of a matrix that matter, without the whole tensors."""
    out = np.empty(local.size)
    element = np.empty(size)
    entity, permutation = np.zeros(1, dtype=np.int32), np.zeros(1, dtype=np.uint8)
    for c in range(coordinates.shape[0]):
        element[:] = 0.0
        _cell_tensor(address, element, coefficients[c], constants, coordinates[c], entity, permutation)
        for i in range(start[c], start[c + 1]):
            out[i] = element[local[i]]
    return out


@njit(cache=True)
def tabulate_at_cells(address, dofs, cell_dofs, constants, coordinates, out):
    """An expression of one function (block size 1) at every cell, into the rows of ``out`` (cells x its
    values), from the function's dof values ``dofs``, gathered cell by cell (for kernels that evaluate it
    for many states in one call)."""
    local = np.empty(cell_dofs.shape[1])
    entity, permutation = np.zeros(1, dtype=np.int32), np.zeros(1, dtype=np.uint8)
    for c in range(cell_dofs.shape[0]):
        for k in range(cell_dofs.shape[1]):
            local[k] = dofs[cell_dofs[c, k]]
        out[c, :] = 0.0
        _cell_tensor(address, out[c], local, constants, coordinates[c], entity, permutation)


@kernel
def _expression_at_cells(address, dofs, cell_dofs, constants, coordinates, size):
    """:func:`tabulate_at_cells` into a new array."""
    out = np.empty((cell_dofs.shape[0], size))
    tabulate_at_cells(address, dofs, cell_dofs, constants, coordinates, out)
    return out


def _cell_coordinates(mesh, cells: np.ndarray) -> np.ndarray:
    """The coordinates of the geometry nodes of each cell, as the kernels take them (cells x nodes * 3)."""
    return np.ascontiguousarray(mesh.geometry.x[mesh.geometry.dofmaps[0][cells]].reshape(len(cells), -1))


class CellExpression:
    """A ``dolfinx.fem.Expression`` of one function (block size 1) at every cell (or at some), from the
    function's dof values: what ``Expression.eval`` gives, without packing the coefficients through DOLFINx.
    The expression's other coefficients (a curved axis' curvature) are fixed: their values are appended to the
    function's (:meth:`with_fixed`), and each cell gathers them as it gathers the function's."""

    def __init__(self, expression: fem.Expression, function: fem.Function, cells: np.ndarray | None = None):
        """``cells``: the local cells to evaluate it at, in this order (default: all)."""
        ufcx = expression._ufcx_expression
        coefficients = ufl.algorithms.extract_coefficients(expression.ufl_expression)  # in the packing's order
        if function not in coefficients or any(c.function_space.dofmap.bs != 1 for c in coefficients):
            raise ValueError("CellExpression takes an expression of one function and fixed coefficients, all of "
                             "block size 1")
        assert ufcx.num_coefficients == len(coefficients)
        self.address = int(_FFI.cast("uintptr_t", ufcx.tabulate_tensor_float64))
        mesh = function.function_space.mesh
        if cells is None:
            cells = np.arange(mesh.topology.index_map(mesh.topology.dim).size_local, dtype=np.int32)
        self.coordinates = _cell_coordinates(mesh, cells)
        blocks, fixed, offset = [], [], function.x.array.size
        for c in coefficients:
            dofs = c.function_space.dofmap.list[cells]
            if c is function:
                blocks.append(dofs)
            else:
                blocks.append(dofs + offset)
                fixed.append(c.x.array.copy())
                offset += c.x.array.size
        self.cell_dofs = np.ascontiguousarray(np.hstack(blocks))
        self.fixed = np.concatenate(fixed) if fixed else np.empty(0)
        self.constants = np.ascontiguousarray(fem.pack_constants(expression), dtype=float)
        self.size = expression.X().shape[0] * int(np.prod(expression.value_shape, dtype=int))

    def with_fixed(self, dofs: np.ndarray) -> np.ndarray:
        """The function's dof values (a vector, or states in rows) followed by the fixed coefficients'."""
        dofs = np.asarray(dofs, dtype=float)
        if not self.fixed.size:
            return np.ascontiguousarray(dofs)
        fixed = np.broadcast_to(self.fixed, dofs.shape[:-1] + self.fixed.shape)
        return np.ascontiguousarray(np.concatenate((dofs, fixed), axis=-1))

    def __call__(self, dofs: np.ndarray) -> np.ndarray:
        """The expression at its points of each of its cells (cells x points * values)."""
        return _expression_at_cells(self.address, self.with_fixed(dofs), self.cell_dofs, self.constants,
                                    self.coordinates, self.size)


class CellAssembly:
    """A form with one cell integral assembled from packed coefficients: a functional (a number), a linear
    form (a vector at the dofs ``dofs``) or a bilinear form of one space (a dense matrix at those dofs)."""

    def __init__(self, form: fem.Form, dofs: np.ndarray | None = None, cells: np.ndarray | None = None):
        """``cells``: those of the form's cell integral to assemble (default: all), in the order of the
        packed coefficients given."""
        cell = fem.IntegralType.cell
        if set(form.integral_types) != {cell} or form.num_integrals(cell, 0) != 1:
            raise ValueError("CellAssembly takes a form with exactly one cell integral")
        if form.rank == 2 and form.function_spaces[0] is not form.function_spaces[1]:
            raise ValueError("CellAssembly takes a bilinear form of one space")
        integral = form.ufcx_form.form_integrals[0]
        self.address = int(_FFI.cast("uintptr_t", integral.tabulate_tensor_float64))
        if cells is None:
            cells = form._cpp_object.domains(cell, 0)  # in the order of the packed coefficients
        self.coordinates = _cell_coordinates(form.mesh, cells)
        self.rank = form.rank
        if self.rank == 0:
            self.cell_dofs, self.size = np.zeros((len(cells), 1), dtype=np.int64), 1
        else:
            space = form.function_spaces[0]
            if space.dofmap.bs != 1:
                raise ValueError("CellAssembly takes a space of block size 1")
            index_map = space.dofmap.index_map
            position = np.full(index_map.size_local + index_map.num_ghosts, -1, dtype=np.int64)
            position[dofs] = np.arange(len(dofs))
            self.cell_dofs = np.ascontiguousarray(position[space.dofmap.map()[cells]])
            if (self.cell_dofs < 0).any():
                raise ValueError("the sampled cells touch dofs outside the given ones")
            self.size = len(dofs)
        self.constants = np.ascontiguousarray(fem.pack_constants(form), dtype=float)

    def _shaped(self, out: np.ndarray):
        if self.rank == 0:
            return float(out[0])
        if self.rank == 2:
            side = int(round(np.sqrt(out.size)))
            return out.reshape(side, side)
        return out

    def __call__(self, coefficients: np.ndarray):
        """The assembled number, vector or matrix at the dofs, from the cells' packed coefficients
        (cells x per cell)."""
        return self._shaped(_assemble_cells(self.address, np.ascontiguousarray(coefficients, dtype=float),
                                            self.constants, self.coordinates, self.cell_dofs, self.size,
                                            self.rank == 2))

    def element_tensors(self, coefficients: np.ndarray) -> np.ndarray:
        """Each cell's element tensor (cells x its size: 1, the cell's dofs, or their square, row-major) from
        the cells' packed coefficients."""
        packed = np.ascontiguousarray(coefficients, dtype=float).reshape(len(self.coordinates), -1)
        return _tabulate_cells(self.address, packed, self.constants, self.coordinates, self._tensor_size())

    def _tensor_size(self) -> int:
        """The values of one cell's element tensor: 1, the cell's dofs, or their square."""
        n = self.cell_dofs.shape[1]
        return n * n if self.rank == 2 else (n if self.rank == 1 else 1)

    def kept_layout(self, kept: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where :meth:`kept_entries` reads the entries ``kept`` (increasing indices into the cells' element tensors
        flattened one after the other, as :meth:`element_tensors` gives them): each cell's first one, and each one's
        index in its cell's tensor."""
        cell, local = np.divmod(kept, self._tensor_size())
        return np.searchsorted(cell, np.arange(len(self.coordinates) + 1)), local

    def kept_entries(self, coefficients: np.ndarray, layout: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """The entries of :meth:`kept_layout` from the cells' packed coefficients."""
        packed = np.ascontiguousarray(coefficients, dtype=float).reshape(len(self.coordinates), -1)
        return _kept_cell_entries(self.address, packed, self.constants, self.coordinates, self._tensor_size(),
                                  *layout)

    def projected(self, offset, rows, row_function, row_dof, state, basis, basis_by_field):
        """The number, or the vector or matrix projected on ``basis`` (the rows of [Phi] at the dofs:
        P^T f, P^T K P), from the packed coefficients ``offset`` plus, at ``rows``, the values at the dofs
        ``row_dof`` of the functions ``row_function`` whose reduced values ``state`` stacks (the placement
        of :class:`~fenics_drill.model.internal_force.SampledCoefficients`); ``basis_by_field``: the basis packed
        by field (:meth:`~fenics_drill.model.kernels.packed_rows.FieldPackedRows.kernel_data`)."""
        return self._shaped(_assemble_cells_at(self.address, offset, rows, row_function, row_dof, state,
                                               self.constants, self.coordinates, self.cell_dofs, self.size,
                                               self.rank == 2, basis, basis_by_field, self.rank > 0))

    def functionals(self, offset, rows, row_function, row_dof, states, basis, basis_by_field) -> np.ndarray:
        """A functional's value at each row of ``states`` (:meth:`projected` of each, in one call)."""
        if self.rank != 0:
            raise ValueError("functionals() takes a form of rank 0")
        return _functionals_at(self.address, offset, rows, row_function, row_dof, np.ascontiguousarray(states),
                               self.constants, self.coordinates, self.cell_dofs, basis, basis_by_field)
