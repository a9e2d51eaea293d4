"""Internal generalised forces of the beam in the solution space, with their tangents.

f_int(q, qd, qdd) = [Phi]^T (inertial + damping + elastic)(Phi q, Phi qd, Phi qdd), i.e. the
left-hand side M a + C v + K u - F_KE - F_SE of Eqs. (43)-(49), projected as in (65).

* :class:`LinearInternalForce` - both nonlinearities off: the projected constant
  matrices M, C, K and nothing is assembled while stepping.
* :class:`AssembledInternalForce` - the energy-derived UFL forms of
  ``forms.energies`` assembled at the current state, tangent from ``ufl.derivative``.
* :class:`LateralZoneInternalForce` - the full order of a string whose lateral fields are held above a
  length (``model.lateral_length``): the forms assembled where the lateral fields are solved, M, C, K above.

Both give the three parts of the tangent  c_u df/dq + c_v df/dqd + c_a df/dqdd  that
Newton combines (for Newmark: c_u = 1, c_v = gamma / (beta dt), c_a = 1 / (beta dt^2)),
so a change of step size needs no re-assembly.
"""

from __future__ import annotations

import functools
import weakref
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import ufl
from dolfinx import fem
from petsc4py import PETSc

from fenics_drill.forms import energies
from fenics_drill.model.kernels.banded_saddle import SparseSum
from fenics_drill.model.kernels.cell_kernels import CellAssembly
from fenics_drill.model.kernels.compiled import form as compiled_form
from fenics_drill.model.kernels.compiled import kernel
from fenics_drill.model.discretization import THETA_Y, THETA_Z, V, W, BeamDiscretization
from fenics_drill.model.operators import LinearOperators
from fenics_drill.model.kernels.packed_rows import FieldPackedRows


def quadratic_forms(matrix: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """x^T A x / 2 for each row x of ``rows`` (A symmetric)."""
    return 0.5 * np.einsum("ij,ij->i", rows, rows @ matrix)


class LinearInternalForce:
    """M qdd + C qd + K q with projected constant matrices (Eqs. 44-46)."""

    def __init__(self, space, operators: LinearOperators):
        self.mass = space.project_matrix(operators.mass)
        self.damping = space.project_matrix(operators.damping)
        self.stiffness = space.project_matrix(operators.stiffness)

    def evaluate(self, q, qd, qdd) -> np.ndarray:
        return self.mass @ qdd + self.damping @ qd + self.stiffness @ q

    #: The tangent does not depend on the state: never worth re-assembling.
    state_dependent = False

    def tangent_parts(self, needed=(True, True, True)):
        """(df/dq, df/dqd, df/dqdd); constant, so always all three."""
        return self.stiffness, self.damping, self.mass

    def kinetic_energy(self, q, qd) -> float:
        return 0.5 * float(qd @ (self.mass @ qd))

    def strain_energy(self, q) -> float:
        return 0.5 * float(q @ (self.stiffness @ q))

    def energies(self, qs: np.ndarray, qds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic and strain energies of many states (rows of qs and qds)."""
        return quadratic_forms(self.mass, qds), quadratic_forms(self.stiffness, qs)

    def damping_force(self, qd) -> np.ndarray:
        return self.damping @ qd


@dataclass(frozen=True)
class ElementSample:
    """A reduced quadrature over the elements: the cells evaluated and their weights (ECSW,
    :mod:`fenics_drill.model.reduction.hyper_reduction`)."""

    cells: np.ndarray
    weights: np.ndarray


class InternalForms:
    """The UFL forms of the internal force of one string: the residual of (43), its derivatives by the
    displacement, velocity and acceleration fields, and the kinetic and strain energies; whole, or
    ``sampled``: the nonlinear remainder only, weighted cell by cell by the DG0 function ``weight``.

    Building them costs about 0.3 s, and they depend neither on the solution space nor on the sample:
    :meth:`of` builds them once per string and switches, and the models of a string (reduced, enriched,
    full order; each element sample and the trainer of a sample) share them and their functions U, V, A.
    A sample is a choice of cells and their weights (:class:`SampledCoefficients`), not a form."""

    def __init__(self, disc: BeamDiscretization, switches: tuple, sampled: bool, cells: np.ndarray | None = None,
                 axial_torsional: bool = False):
        """``cells``: the forms integrate over these elements only (a rank's share of a split string); None: all.
        ``axial_torsional``: the energies of u and theta_x alone (v, w, theta_y, theta_z and their tests set to zero
        in the UFL: the elements where the lateral fields are held, :class:`LateralZoneInternalForce`)."""
        geometric_nonlinearity, inertial_nonlinearity, kinematics, angular_velocity = switches
        p = disc.form_properties
        # Energies are polynomials of degree <= 4 in the fields up to sin/cos(theta_x):
        # 2k integrates the mass exactly for v, w of degree k and keeps the kernels small.
        metadata = {"quadrature_degree": 2 * disc.element_degree}
        self.functions = U, V, A = tuple(fem.Function(disc.V) for _ in range(3))
        psi, dU = ufl.TestFunction(disc.V), ufl.TrialFunction(disc.V)
        dx = ufl.Measure("dx", domain=disc.mesh, metadata=metadata) if cells is None else ufl.Measure(
            "dx", domain=disc.mesh, metadata=metadata, subdomain_data=[(1, cells)], subdomain_id=1)
        weight = self.weight = fem.Function(fem.functionspace(disc.mesh, ("DG", 0))) if sampled else 1.0

        def inertial(nonlinear):
            return energies.inertial_force(p, psi, U, V, A, dx, nonlinear, angular_velocity, weight)

        def elastic(nonlinear):
            return energies.elastic_force(p, psi, U, dx, nonlinear, kinematics, weight)

        def energy(density, linear_density):
            return weight * (density - linear_density if sampled else density) * dx

        kinetic = energies.kinetic_energy_density(p, U, V, inertial_nonlinearity, angular_velocity)
        strain = energies.strain_energy_density(p, energies.strain_slots(U, p.axis, geometric_nonlinearity),
                                                geometric_nonlinearity, kinematics)
        if not sampled:
            residual = (inertial(inertial_nonlinearity) + elastic(geometric_nonlinearity)
                        + energies.damping_force(p, psi, V, dx))
        else:  # the nonlinear remainder of each force that has one; the linear part is applied with projected
            # matrices (a linear force less itself is left out: UFL would keep the difference, and its fields)
            remainders = [force(True) - force(False) for force, on in ((inertial, inertial_nonlinearity),
                                                                        (elastic, geometric_nonlinearity)) if on]
            residual = sum(remainders[1:], remainders[0])
        kinetic = energy(kinetic, energies.kinetic_energy_density(p, U, V, False))
        strain = energy(strain, energies.strain_energy_density(p, energies.strain_slots(U, p.axis), False))
        if axial_torsional:  # what the forms read of the fields and tests: u and theta_x only
            held = {f: ufl.as_vector([f[0], 0.0, 0.0, f[3], 0.0, 0.0]) for f in (U, V, A, psi)}
            kinetic, strain, residual = (ufl.replace(form, held) for form in (kinetic, strain, residual))
        self.kinetic, self.strain, self.residual = (compiled_form(form) for form in (kinetic, strain, residual))
        # one form per derivative df/dq, df/dqd, df/dqdd (None where the residual does not hold the field): each
        # part is assembled by a kernel of its own, not by the whole Jacobian's kernel with two coefficients zero.
        # Which fields it holds is read off the form, not by expanding the derivatives (0.2 s of UFL per string)
        held = set(residual.coefficients())
        self.jacobians = tuple(compiled_form(ufl.derivative(residual, field, dU)) if field in held else None
                               for field in (U, V, A))

    @classmethod
    def of(cls, disc: BeamDiscretization, switches: tuple, sampled: bool,
           cells: np.ndarray | None = None, axial_torsional: bool = False) -> "InternalForms":
        """The forms of a string, whole or ``sampled``, over all its elements or ``cells``: built on first use, then
        shared."""
        built = _FORMS.setdefault(disc, {})
        key = (switches, sampled, None if cells is None else cells.tobytes(), axial_torsional)
        if key not in built:
            built[key] = cls(disc, switches, sampled, cells, axial_torsional)
        return built[key]


#: The forms of each string (discretization) alive, by their switches and whether they are sampled.
_FORMS: "weakref.WeakKeyDictionary[BeamDiscretization, dict]" = weakref.WeakKeyDictionary()


class AssembledInternalForce:
    """Inertial (24), damping (38) and elastic (30) forces assembled from their energies.

    With an :class:`ElementSample` (a modal space only), the linear part M a + C v + K u is applied
    with projected matrices and only the nonlinear remainder (-F_KE - F_SE, Eqs. 48-49) is assembled,
    on the sampled cells with their weights: the weighted sum of the element energies, so the forces
    stay the gradients of an energy and the budget still closes (Farhat et al. 2014).

    A modal space's force and energies come from the cells' kernels (:class:`SampledCoefficients`: all
    cells, or the sample's), a third faster than DOLFINx's assembly and projection over all cells.  Its tangents
    over all cells come from the same kernels over every cell, with the coefficients packed by DOLFINx
    (:class:`TangentEntries`); the full order's force and tangents from them too, with the coefficients read off
    its state (:class:`FullSpacePacking`), and its energies the same way.
    """

    def __init__(self, disc: BeamDiscretization, space, operators: LinearOperators,
                 geometric_nonlinearity: bool, inertial_nonlinearity: bool, kinematics: str = "objective",
                 angular_velocity: str = "consistent", sample: ElementSample | None = None,
                 cells: np.ndarray | None = None, axial_torsional: bool = False):
        """``cells``: the force of these elements only (a rank's share of a split string, full order); None: all.
        ``axial_torsional``: of u and theta_x alone (:class:`InternalForms`)."""
        self.space, self.sample = space, sample
        self._field_of_dof = disc.field_of_dof
        self.switches = (geometric_nonlinearity, inertial_nonlinearity, kinematics, angular_velocity)
        forms = InternalForms.of(disc, self.switches, sample is not None, cells, axial_torsional)
        self.U, self.V, self.A = forms.functions
        self._kinetic, self._strain, self._residual, self._jacobians = (forms.kinetic, forms.strain, forms.residual,
                                                                       forms.jacobians)
        # the dofs of the sampled cells: the only ones their kernels read
        self.dofs = None if sample is None else np.unique(disc.V.dofmap.list[sample.cells]).astype(PETSc.IntType)
        # the cells whose kernels a modal space's force runs on from q, and their dofs (None: the full space's, whose
        # coefficients are read off its state: :class:`FullSpacePacking`)
        self._kernel_cells = None if space.sparse else (
            (sample.cells, self.dofs) if sample is not None else
            (np.arange(disc.elements, dtype=np.int32), np.arange(disc.ndofs)))
        if sample is None:  # the kernels' element matrices, read at the entries that matter
            self._matrices = tuple(TangentEntries(form, space, forms.functions) if form is not None
                                   else None for form in self._jacobians)
        else:  # the nonlinear remainder on the sampled cells, from (q, qd, qdd) through their kernels
            self.linear = tuple(space.project_matrix(m) for m in (operators.stiffness, operators.damping,
                                                                   operators.mass))
            self._linear_rows = np.hstack(self.linear)  # [K C M]: the linear part of (q, qd, qdd) stacked
            self.weight, self.phi_rows = forms.weight, space.phi[self.dofs]  # the sample's weight per cell
        self._damping = space.project_matrix(operators.damping)  # (45) is linear: reused for the budget
        # (q, qd, qdd) of the last evaluation, set on the functions when a tangent needs it (other forces on
        # the same string share the functions, so a tangent never assumes they still hold this state)
        self._state = None

    def _sampled(self, form: fem.Form, functions) -> "SampledCoefficients":
        cells, dofs = self._kernel_cells
        if self.sample is not None:  # the forms' weight is shared: this sample's is set where it is packed
            self.weight.x.array[:] = 0.0
            self.weight.x.array[cells] = self.sample.weights
        return SampledCoefficients(form, functions, dofs, self.space.phi if self.sample is None else self.phi_rows,
                                   cells, self._field_of_dof[dofs])

    # the cells' kernels of the forms, built on first use (a trainer of a sample assembles through DOLFINx and
    # never needs them)
    @functools.cached_property
    def _packing(self) -> "SampledCoefficients":
        return self._sampled(self._residual, (self.U, self.V, self.A))

    @functools.cached_property
    def _residual_cells(self) -> CellAssembly:
        """The residual form's kernels over all its cells, into a vector at every dof (:meth:`assembled_vector`)."""
        index_map = self._residual.function_spaces[0].dofmap.index_map
        return CellAssembly(self._residual, np.arange(index_map.size_local + index_map.num_ghosts))

    @functools.cached_property
    def _tangent_cells(self) -> tuple:
        return tuple(self._sampled(form, (self.U, self.V, self.A)) if form is not None else None
                     for form in self._jacobians)

    @functools.cached_property
    def _kinetic_cells(self) -> "SampledCoefficients":
        return self._sampled(self._kinetic, (self.U, self.V))

    @functools.cached_property
    def _strain_cells(self) -> "SampledCoefficients":
        return self._sampled(self._strain, (self.U,))

    def _set(self, function: fem.Function, values: np.ndarray) -> None:
        if self.dofs is None:
            function.x.array[:] = self.space.expand(values)
        else:  # only the dofs of the sampled cells enter their kernels
            function.x.array[self.dofs] = self.phi_rows @ values

    def assembled_vector(self, q, qd, qdd) -> np.ndarray:
        """The assembled (full-space) vector of the residual form at a state: the whole force, or the
        nonlinear remainder weighted by the forms' ``weight`` on every cell (what a trainer of a sample sets)."""
        self._set(self.U, q)
        self._set(self.V, qd)
        self._set(self.A, qdd)
        (packed,) = fem.pack_coefficients(self._residual).values()
        return self._residual_cells(packed)

    def element_vectors(self, q, qd, qdd) -> np.ndarray:
        """Each sampled cell's element vector of the residual form, weighted, in the order of its dofs
        (cells x dofs per cell): what the ECSW trainer projects element by element."""
        return self._packing.element_tensors(np.concatenate((q, qd, qdd)))

    def kernel_data(self) -> tuple | None:
        """What :func:`~fenics_drill.solvers.compiled_residual.residual_at` needs to evaluate this force as
        :meth:`evaluate` does: (sampled, [K C M] or an empty matrix, the packed coefficients' placement, the
        basis rows, dense and packed by field, and the residual kernel's address, constants, coordinates, cell
        dofs and size); None in the full space."""
        if self._kernel_cells is None:
            return None
        packing, sampled = self._packing, self.sample is not None
        cells = packing.cells
        return (sampled, self._linear_rows if sampled else np.empty((0, 0)), packing.offset, packing.rows,
                packing.row_function, packing.row_dof, packing.basis, packing.basis_by_field, cells.address,
                cells.constants, cells.coordinates, cells.cell_dofs, cells.size)

    @functools.cached_property
    def _full_packing(self) -> "FullSpacePacking":
        return FullSpacePacking(self._residual, (self.U, self.V, self.A), self.space)

    def evaluate(self, q, qd, qdd) -> np.ndarray:
        self._state = (q, qd, qdd)
        state = np.concatenate((q, qd, qdd))
        if self._kernel_cells is None:
            return self.space.project(self._residual_cells(self._full_packing.packed(state)))
        if self.sample is None:
            return self._packing.assemble(state)
        return self._linear_rows @ state + self._packing.assemble(state)

    state_dependent = True

    def _part(self, k: int):
        """The k-th derivative (df/dq, df/dqd, df/dqdd) at the last evaluated state, projected."""
        linear = self.linear[k] if self.dofs is not None else None
        if self._jacobians[k] is None:
            return linear if linear is not None else self.space.zeros_matrix()
        if self.dofs is None:
            return self._matrices[k].assemble(np.concatenate(self._state))
        return self._tangent_cells[k].assemble(np.concatenate(self._state)) + linear

    def tangent_parts(self, needed=(True, True, True)):
        """(df/dq, df/dqd, df/dqdd) at the state of the last :meth:`evaluate`; None for a part not
        ``needed`` (a static solve needs df/dq only: one assembly instead of three)."""
        if self.dofs is None and not self.space.sparse and self._state is not None:  # other models share them
            for function, values in zip((self.U, self.V, self.A), self._state):
                self._set(function, values)
        return tuple(self._part(k) if want else None for k, want in enumerate(needed))

    def kinetic_energy(self, q, qd) -> float:
        return float(self._kinetic_energies(q[None, :], qd[None, :])[0])

    def strain_energy(self, q) -> float:
        return float(self._strain_energies(q[None, :])[0])

    def energies(self, qs: np.ndarray, qds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic (24) and strain (30) energies of many states (rows of qs and qds): in a modal space one
        compiled call per energy for all of them (the budget's energies of a batch of accepted steps)."""
        return self._kinetic_energies(qs, qds), self._strain_energies(qs)

    def _kinetic_energies(self, qs, qds) -> np.ndarray:
        if self._kernel_cells is None:
            return self._full_space_functional(self._kinetic_full, np.hstack((qs, qds)))
        energies = self._kinetic_cells.assemble_rows(np.hstack((qs, qds)))
        return energies if self.sample is None else energies + quadratic_forms(self.linear[2], qds)

    def _strain_energies(self, qs) -> np.ndarray:
        if self._kernel_cells is None:
            return self._full_space_functional(self._strain_full, qs)
        energies = self._strain_cells.assemble_rows(qs)
        return energies if self.sample is None else energies + quadratic_forms(self.linear[0], qs)

    @functools.cached_property
    def _kinetic_full(self) -> tuple["FullSpacePacking", CellAssembly]:
        return FullSpacePacking(self._kinetic, (self.U, self.V), self.space), CellAssembly(self._kinetic)

    @functools.cached_property
    def _strain_full(self) -> tuple["FullSpacePacking", CellAssembly]:
        return FullSpacePacking(self._strain, (self.U,), self.space), CellAssembly(self._strain)

    @staticmethod
    def _full_space_functional(assembly, states: np.ndarray) -> np.ndarray:
        """An energy of the full space at each row of ``states`` (its functions' values stacked), from its cells'
        kernels with the coefficients read off the state."""
        packing, cells = assembly
        return np.array([cells(packing.packed(state)) for state in states])

    def damping_force(self, qd) -> np.ndarray:
        return self._damping @ qd


class SplitInternalForce:
    """The internal force of a full-order string split over two MPI ranks
    (:mod:`~fenics_drill.model.kernels.split_band`): assembled over this rank's elements (``share``) and summed over
    the ranks, so every rank holds the whole force; its tangent parts are this rank's own
    (:class:`~fenics_drill.model.kernels.banded_saddle.SparseSum` ``own``).  The energies and the damping force,
    which the energy budget and the outputs read at accepted steps only, are the ``whole`` string's."""

    state_dependent = True

    def __init__(self, whole: AssembledInternalForce, share: AssembledInternalForce, comm):
        self.whole, self.share, self.comm = whole, share, comm
        self.switches = whole.switches

    def evaluate(self, q, qd, qdd) -> np.ndarray:
        part = np.ascontiguousarray(self.share.evaluate(q, qd, qdd))
        out = np.empty_like(part)
        self.comm.Allreduce(part, out)
        return out

    def tangent_parts(self, needed=(True, True, True)):
        return tuple(None if part is None else SparseSum([(1.0, part)], part.shape, own=True)
                     for part in self.share.tangent_parts(needed))

    def kinetic_energy(self, q, qd) -> float:
        return self.whole.kinetic_energy(q, qd)

    def strain_energy(self, q) -> float:
        return self.whole.strain_energy(q)

    def energies(self, qs: np.ndarray, qds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.whole.energies(qs, qds)

    def damping_force(self, qd) -> np.ndarray:
        return self.whole.damping_force(qd)


def packed_placement(form: fem.Form, functions, dofs: np.ndarray, cells: np.ndarray | None = None):
    """Where DOLFINx packs the values of ``functions`` at ``dofs`` among the coefficients of ``form`` on ``cells``
    (None: the form's own; what ``dolfinx.fem.pack_coefficients`` gives, cells x per cell, flattened): (a function
    reading DOLFINx's packing there, the packing with the functions zero, and the packed entries that hold a
    function's value at a dof: their index, function and dof's index in ``dofs``).  Found by numbering the dofs
    1, 2, ... in each function in turn; the functions are left zero."""
    for function in functions:
        function.x.array[:] = 0.0
    (key, packed), = fem.pack_coefficients(form).items()
    if cells is None:
        at = slice(None)
    else:
        position = np.full(form.mesh.topology.index_map(form.mesh.topology.dim).size_local, -1)
        position[form._cpp_object.domains(fem.IntegralType.cell, 0)] = np.arange(len(packed))
        at = position[cells]

    def pack() -> np.ndarray:
        return fem.pack_coefficients(form)[key][at].ravel()

    offset = pack().copy()
    rows, row_function, row_dof = [], [], []
    for f, function in enumerate(functions):  # each dof numbered 1, 2, ...: where is it packed?
        function.x.array[dofs] = np.arange(1, len(dofs) + 1)
        numbered = pack() - offset
        function.x.array[:] = 0.0
        entries = np.flatnonzero(numbered)
        rows.append(entries)
        row_function.append(np.full(entries.size, f))
        row_dof.append(np.rint(numbered[entries]).astype(np.int64) - 1)
    rows, row_function, row_dof = (np.concatenate(a) for a in (rows, row_function, row_dof))
    if np.unique(rows).size != rows.size:
        raise ValueError("a packed coefficient depends on more than one function")
    return pack, offset, rows, row_function, row_dof


class FullSpacePacking:
    """The packed coefficients of a form over its cells at a full-space state (q, qd, qdd stacked; the held dofs
    zero), formed without setting the functions or DOLFINx's packing: the offset (the functions zero) plus each
    packed value read from the state (:func:`packed_placement`, checked once against DOLFINx's packing)."""

    def __init__(self, form: fem.Form, functions, space):
        pack, self.offset, rows, row_function, row_dof = packed_placement(form, functions, np.arange(space.ndofs))
        unknown = space.position[row_dof]
        solved = unknown >= 0  # a held dof's value is zero: its entries keep the offset's
        self.rows, self.index = rows[solved], row_function[solved] * space.size + unknown[solved]
        self.cells = len(form._cpp_object.domains(fem.IntegralType.cell, 0))
        rng = np.random.default_rng(0)
        state = rng.standard_normal(len(functions) * space.size)
        for function, values in zip(functions, state.reshape(len(functions), -1)):
            function.x.array[:] = space.expand(values)
        expected = pack()
        for function in functions:
            function.x.array[:] = 0.0
        if not np.allclose(self.packed(state).ravel(), expected, rtol=1e-12,
                           atol=1e-12 * np.abs(expected).max(initial=0.0)):  # a constant form packs nothing
            raise ValueError("the packed coefficients are not the functions' values at the dofs")

    def packed(self, state: np.ndarray) -> np.ndarray:
        """The cells' packed coefficients (cells x per cell) at the stacked full-space ``state``."""
        return _offset_plus_placed(self.offset, self.rows, self.index, state).reshape(self.cells, -1)


@kernel
def _offset_plus_placed(offset, rows, index, state):
    """offset with state[index[k]] added at rows[k] (the rows are distinct: :func:`packed_placement`)."""
    out = offset.copy()
    for k in range(rows.size):
        out[rows[k]] += state[index[k]]
    return out


class SampledCoefficients:
    """A form on the sampled cells (the force, a tangent, an energy) assembled from coefficients packed
    directly from the reduced values of its ``functions`` (q, qd, qdd of U, V, A, stacked).

    The packed coefficients of the cells (what ``dolfinx.fem.pack_coefficients`` gives: the weight and
    the dofs of the functions on each cell) are the weight and the functions' values at the sampled dofs.
    An evaluation forms those values, the sampled rows of [Phi] times the reduced values of each function
    (one product that reads the rows once; a map per packed entry would read each shared dof's row again
    for every cell and function), places them where DOLFINx packs them (found once), and runs the cells'
    kernels (:class:`~fenics_drill.model.kernels.cell_kernels.CellAssembly`), without setting the functions or
    DOLFINx's packing and assembly paths."""

    def __init__(self, form: fem.Form, functions, dofs: np.ndarray, phi_rows: np.ndarray, cells: np.ndarray,
                 fields: np.ndarray):
        """``cells``: the sample (the form is integrated over all cells: its packing is read at these);
        ``fields``: the field of each dof (the rows are packed by it: :mod:`~fenics_drill.model.kernels.packed_rows`)."""
        pack, self.offset, self.rows, self.row_function, self.row_dof = packed_placement(form, functions, dofs, cells)
        self.basis = np.ascontiguousarray(phi_rows)
        self.basis_by_field = FieldPackedRows.of(self.basis, fields).kernel_data()
        self.cells = CellAssembly(form, dofs, cells)
        # a packed entry that is not one dof's value as it is (a scaled or combined dof) would be misplaced:
        # the placement must give DOLFINx's own packing at a random state
        rng = np.random.default_rng(0)
        state = rng.standard_normal(len(functions) * phi_rows.shape[1])
        for function, values in zip(functions, state.reshape(len(functions), -1)):
            function.x.array[dofs] = phi_rows @ values
        expected = pack()
        for function in functions:
            function.x.array[:] = 0.0
        if not np.allclose(self.packed(state), expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max()):
            raise ValueError("the packed coefficients are not the functions' values at the dofs")

    def packed(self, state: np.ndarray) -> np.ndarray:
        """The cells' packed coefficients at a reduced state (for checks; :meth:`assemble` forms them
        compiled)."""
        values = self.basis @ state.reshape(-1, self.basis.shape[1]).T  # (dofs, functions)
        out = self.offset.copy()
        out[self.rows] += values[self.row_dof, self.row_function]
        return out

    def element_tensors(self, state: np.ndarray) -> np.ndarray:
        """Each cell's element tensor at a reduced state (cells x tensor size), as its kernel gives it."""
        return self.cells.element_tensors(self.packed(state))

    def assemble(self, state: np.ndarray):
        """The assembled number, or the vector or matrix projected on [Phi] (cell by cell), at the reduced
        state of the functions stacked in one vector."""
        return self.cells.projected(self.offset, self.rows, self.row_function, self.row_dof, state, self.basis,
                                    self.basis_by_field)

    def assemble_rows(self, states: np.ndarray) -> np.ndarray:
        """The assembled number of a functional (an energy) at each row of ``states``, in one call."""
        return self.cells.functionals(self.offset, self.rows, self.row_function, self.row_dof, states, self.basis,
                                      self.basis_by_field)


class TangentEntries:
    """A tangent form assembled by its FFCx kernel cell by cell (:class:`~fenics_drill.model.kernels.cell_kernels.
    CellAssembly`: no DOLFINx matrix) and read as COO at the element entries that are not zero for every state and,
    in the full space, couple two free dofs (renumbered as the space's unknowns); a pair of dofs that two cells share
    is one entry of each (COO adds them up).

    The form's element matrix couples every field of an element with every other, most of them with zeros (225
    entries per element, about a third nonzero): the entries to keep are those nonzero at two random states, found
    once, so an assembly is the kernels' loop and one gather.  Against DOLFINx's assembly into its CSR matrix and
    a gather of that: 2.5 times less time for df/dq, 7 times less for df/dqd and df/dqdd (3 km, docs/performance.md)."""

    #: Random states that find the entries to keep: displacements and rates of this size (rotations in
    #: rad), so that no term of the energies' polynomials and sines vanishes by accident.
    PROBE_SIZE, PROBES = 0.3, 2

    def __init__(self, form: fem.Form, space, functions):
        self.form, self.space = form, space
        index_map = form.function_spaces[0].dofmap.index_map
        n_dofs = index_map.size_local + index_map.num_ghosts
        self.cells = CellAssembly(form, np.arange(n_dofs))
        cell_dofs, n = self.cells.cell_dofs, self.cells.cell_dofs.shape[1]
        rows = np.repeat(cell_dofs, n, axis=1).ravel()  # entry k n + m of a cell's matrix: (its dof k, its dof m)
        columns = np.tile(cell_dofs, (1, n)).ravel()
        # the full space keeps the free dofs, renumbered; a modal space projects every dof's entries
        position = space.position if space.sparse else np.arange(n_dofs)
        self.shape = (space.size,) * 2 if space.sparse else (n_dofs,) * 2
        kept = (position[rows] >= 0) & (position[columns] >= 0)
        saved = [function.x.array.copy() for function in functions]
        rng, nonzero = np.random.default_rng(0), np.zeros(rows.size, dtype=bool)
        for _ in range(self.PROBES):
            for function in functions:
                function.x.array[:] = self.PROBE_SIZE * rng.standard_normal(function.x.array.size)
            (packed,) = fem.pack_coefficients(self.form).values()
            nonzero |= self.cells.element_tensors(packed).ravel() != 0.0
        for function, values in zip(functions, saved):
            function.x.array[:] = values
        keep = np.flatnonzero(kept & nonzero)
        self.layout = self.cells.kept_layout(keep)
        # the full space's coefficients packed from its state; a modal space's from the functions, set by the caller
        self.packing = FullSpacePacking(form, functions, space) if space.sparse else None
        # scipy's index type below 2^31 unknowns: a COO matrix built on them takes them as they are, without a cast
        index = np.int32 if max(self.shape) < 2**31 else np.int64
        self.rows, self.columns = position[rows[keep]].astype(index), position[columns[keep]].astype(index)

    def assemble(self, state: np.ndarray):
        """The projected form at the stacked full-space ``state`` (COO), or at the functions' current values in a
        modal space (dense)."""
        (packed,) = ((self.packing.packed(state),) if self.packing is not None
                     else fem.pack_coefficients(self.form).values())
        entries = sp.coo_matrix((self.cells.kept_entries(packed, self.layout), (self.rows, self.columns)),
                                shape=self.shape)
        return entries if self.space.sparse else self.space.project_matrix(entries)


class LateralZoneInternalForce:
    """The internal force of a full-order string whose lateral fields are held at zero on some elements (above
    ``model.lateral_length``): there the energies (24), (30), (38) of u and theta_x alone are assembled (the same
    forms with v, w, theta_y, theta_z and their tests set to zero, whose kernels are a fraction of the whole's),
    and the whole forms over the others (the ``zone``: the elements with a lateral dof the space solves).  The same
    force as :class:`AssembledInternalForce` over all elements, to round-off."""

    state_dependent = True

    def __init__(self, disc: BeamDiscretization, space, operators: LinearOperators, switches: tuple,
                 zone: np.ndarray, above: np.ndarray):
        """``zone``, ``above``: the elements of each kind this force holds (all of the string's, or a rank's share;
        either may be empty, not both)."""
        self.switches = switches
        self._built = (disc, operators)
        self.parts = tuple(AssembledInternalForce(disc, space, operators, *switches, cells=cells,
                                                  axial_torsional=restricted)
                           for cells, restricted in ((zone, False), (above, True)) if cells.size)

    @staticmethod
    def cells_of(disc: BeamDiscretization, space) -> tuple[np.ndarray, np.ndarray]:
        """(zone, the others): the elements with a lateral dof that ``space`` solves, and those without one."""
        cell_dofs = disc.V.dofmap.list
        lateral = np.isin(disc.field_of_dof[cell_dofs], (V, W, THETA_Y, THETA_Z))
        solved = (lateral & (space.position[cell_dofs] >= 0)).any(axis=1)
        return np.flatnonzero(solved).astype(np.int32), np.flatnonzero(~solved).astype(np.int32)

    def over(self, cells: np.ndarray, space) -> "LateralZoneInternalForce":
        """The same force of ``cells`` only (a rank's share of a string split over MPI ranks), in ``space``."""
        disc, operators = self._built
        zone, above = self.cells_of(disc, space)
        return LateralZoneInternalForce(disc, space, operators, self.switches, np.intersect1d(zone, cells),
                                        np.intersect1d(above, cells))

    def evaluate(self, q, qd, qdd) -> np.ndarray:
        return sum(part.evaluate(q, qd, qdd) for part in self.parts)

    def tangent_parts(self, needed=(True, True, True)):
        """(df/dq, df/dqd, df/dqdd) at the state of the last :meth:`evaluate` (COO: the zone's entries, then those
        above it); None for a part not ``needed``."""
        out = []
        for terms in zip(*(part.tangent_parts(needed) for part in self.parts)):
            if terms[0] is None:
                out.append(None)
                continue
            terms = [sp.coo_matrix(term) for term in terms]
            out.append(sp.coo_matrix((np.concatenate([t.data for t in terms]),
                                      (np.concatenate([t.row for t in terms]), np.concatenate([t.col for t in terms]))),
                                     shape=terms[0].shape))
        return tuple(out)

    def kinetic_energy(self, q, qd) -> float:
        return sum(part.kinetic_energy(q, qd) for part in self.parts)

    def strain_energy(self, q) -> float:
        return sum(part.strain_energy(q) for part in self.parts)

    def energies(self, qs: np.ndarray, qds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic (24) and strain (30) energies of many states (rows of qs and qds)."""
        kinetic, strain = zip(*(part.energies(qs, qds) for part in self.parts))
        return sum(kinetic), sum(strain)

    def damping_force(self, qd) -> np.ndarray:
        return self.parts[0].damping_force(qd)  # (45) of the whole string


def internal_force(disc: BeamDiscretization, space, operators: LinearOperators, model,
                   sample: ElementSample | None = None):
    """The internal force the scene's [model] switches ask for: nothing nonlinear is assembled when off;
    with ``sample``, the nonlinear part on those elements only; in the full space of a string whose lateral
    fields are held on some elements, the forms on the others only (:class:`LateralZoneInternalForce`)."""
    geometric, inertial = model.geometric_nonlinearity, model.inertial_nonlinearity
    if not (geometric or inertial):
        return LinearInternalForce(space, operators)
    switches = (geometric, inertial, model.kinematics, model.angular_velocity)
    if space.sparse and sample is None:
        zone, above = LateralZoneInternalForce.cells_of(disc, space)
        if zone.size and above.size:
            return LateralZoneInternalForce(disc, space, operators, switches, zone, above)
        if above.size:  # no lateral dof solved: u and theta_x's energies alone, everywhere
            return AssembledInternalForce(disc, space, operators, *switches, axial_torsional=True)
    return AssembledInternalForce(disc, space, operators, *switches, sample)
