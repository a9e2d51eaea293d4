"""Von Mises equivalent stress of the string, for the structural limit (100).

The strains (34)-(36) (or their linearisation, or the objective kinematics of
docs/errata.md, whichever the model integrates) are polynomials of degree <= 2 in
the section coordinates (y, z).  A ``dolfinx.fem.Expression`` evaluates their
coefficients at three points of every element (both vertices and the midpoint);
Hooke's law gives sigma_xx = E eps_xx and tau_xy = 2 G eps_xy, tau_xz = 2 G eps_xz
(no shear correction: kappa_s corrects the shear energy of the section, not the
stress at a point), and

    sigma_VM = sqrt(sigma_xx^2 + 3 (tau_xy^2 + tau_xz^2)).

The section is sampled on its outer fibre r = R_ext at SECTION_ANGLES equally
spaced angles: the stresses of axial load, bending and torsion, and of their
combinations, grow with r, so the maximum over the annulus sits on the outer fibre.
The angular sampling misses the peak of a pure bending stress by at most a factor
cos(pi / SECTION_ANGLES) (0.2 % for 48 angles) and misses nothing of torsion or
axial load.

At the string's two ends the strains are also recovered: the linear rotations give each element the
curvature averaged over it, so where the moment falls steeply from a held end (the sagging string at the
drive) the sampled stress of the end element is the one of its middle, low by half an element's slope.
The strains' coefficients of the two end elements' midpoints, extrapolated linearly to the end vertex
(1.5 c_1 - 0.5 c_2), recover it to second order; on the paper string at 120 rpm that gives 44.17 MPa at 500
elements against a mesh-converged 44.2 MPa, where the sampled peak is 42.73 MPa (docs/verification.md).

The maximum over the string (:meth:`VonMisesProbe.maxima`, at every accepted step) samples only both ends of
each element, and the midpoints of the two end elements at each end for the recovery.  With P2
displacements and P1 rotations the linear strains are affine along an element, so on each sample line of the
outer fibre sigma_VM, the norm of an affine function of x, is convex and largest at an end of the element;
the midpoint can hold more only through the strains' quadratic terms.  Measured on random states from 1e-5 to
1e-1 (m, rad) of every field, for each strain model, it never did (tests/observables/test_observables.py),
and the probe costs a third less (docs/performance.md).
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem
from numba import njit

from fenics_drill.model.kernels.cell_kernels import CellExpression, tabulate_at_cells
from fenics_drill.model.kernels.compiled import kernel
from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.forms.energies import green_lagrange_strains, linear_strains, strain_slots

#: Monomials y^a z^b of the strain polynomials (degree <= 2).
MONOMIALS = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
#: Points per element where the stress is evaluated (reference coordinate).
ELEMENT_POINTS = np.array([[0.0], [0.5], [1.0]])
#: The points of ELEMENT_POINTS where the maximum over an element lies (module doc): its ends.
ELEMENT_ENDS = np.array([[0.0], [1.0]])
SECTION_ANGLES = 48


@njit(cache=True)
def _von_mises_squared(exx, exy, exz, young_modulus, shear_modulus):
    """sigma_VM^2 = sigma_xx^2 + 3 (tau_xy^2 + tau_xz^2) with sigma_xx = E eps_xx, tau = 2 G eps."""
    return young_modulus**2 * exx * exx + 12.0 * shear_modulus**2 * (exy * exy + exz * exz)


@njit(cache=True, inline="always")
def _sampled_at(c, p, monomials, young_modulus, shear_modulus):
    """The largest sigma_VM^2 over the outer fibre's samples at point p, from the monomial coefficients ``c``
    (points, 3 strains, 6 monomials) and the monomials at the samples (6, samples)."""
    largest = 0.0
    for s in range(monomials.shape[1]):
        exx = exy = exz = 0.0
        for m in range(monomials.shape[0]):
            exx += c[p, 0, m] * monomials[m, s]
            exy += c[p, 1, m] * monomials[m, s]
            exz += c[p, 2, m] * monomials[m, s]
        largest = max(largest, _von_mises_squared(exx, exy, exz, young_modulus, shear_modulus))
    return largest


@njit(cache=True, inline="always")
def _monomial_bound_at(c, p, monomial_bounds, young_modulus, shear_modulus):
    """A cheaper, looser bound than :func:`_bound_at`: each strain bounded by the sum of its monomials'
    largest magnitudes on the fibre (``monomial_bounds``)."""
    exx = exy = exz = 0.0
    for m in range(monomial_bounds.size):
        exx += abs(c[p, 0, m]) * monomial_bounds[m]
        exy += abs(c[p, 1, m]) * monomial_bounds[m]
        exz += abs(c[p, 2, m]) * monomial_bounds[m]
    return _von_mises_squared(exx, exy, exz, young_modulus, shear_modulus)


@njit(cache=True, inline="always")
def _largest_singular_value(a, b, c, d):
    """The largest singular value of [[a, b], [c, d]], in a form free of cancellation."""
    return 0.5 * (math.sqrt((a + d) ** 2 + (c - b) ** 2) + math.sqrt((a - d) ** 2 + (b + c) ** 2))


@njit(cache=True, inline="always")
def _bound_at(c, p, radius, young_modulus, shear_modulus):
    """An upper bound of sigma_VM^2 over the whole outer fibre r = R at point p.  On the fibre
    (y, z) = R (cos phi, sin phi) each strain is a0 + a1 cos phi + b1 sin phi + a2 cos 2phi + b2 sin 2phi, so
    |eps_xx| <= |a0| + |(a1, b1)| + |(a2, b2)|, and the shear vector (eps_xy, eps_xz) is at most as long as its
    constant part plus the largest singular values of its two harmonics' 2x2 matrices.  The bound is the
    stress itself where axial load, bending and torsion combine (the shear's length is then constant
    around the fibre); a relative 1e-9 covers the round-off of the sampled stress it is compared with."""
    half_r2 = 0.5 * radius * radius
    mean_xx = c[p, 0, 0] + half_r2 * (c[p, 0, 3] + c[p, 0, 5])
    mean_xy = c[p, 1, 0] + half_r2 * (c[p, 1, 3] + c[p, 1, 5])
    mean_xz = c[p, 2, 0] + half_r2 * (c[p, 2, 3] + c[p, 2, 5])
    axial = (abs(mean_xx) + radius * math.sqrt(c[p, 0, 1] ** 2 + c[p, 0, 2] ** 2)
             + half_r2 * math.sqrt((c[p, 0, 3] - c[p, 0, 5]) ** 2 + c[p, 0, 4] ** 2))
    shear = (math.sqrt(mean_xy ** 2 + mean_xz ** 2)
             + radius * _largest_singular_value(c[p, 1, 1], c[p, 1, 2], c[p, 2, 1], c[p, 2, 2])
             + half_r2 * _largest_singular_value(c[p, 1, 3] - c[p, 1, 5], c[p, 1, 4], c[p, 2, 3] - c[p, 2, 5],
                                                 c[p, 2, 4]))
    return (1.0 + 1e-9) * _von_mises_squared(axial, shear, 0.0, young_modulus, shear_modulus)


@kernel
def _sampled_maxima(c, points, monomials, young_modulus, shear_modulus):
    """:func:`_sampled_at` at each of ``points``."""
    out = np.empty(points.size)
    for k in range(points.size):
        out[k] = _sampled_at(c, points[k], monomials, young_modulus, shear_modulus)
    return out


@njit(cache=True)
def _largest(c, monomials, monomial_bounds, radius, young_modulus, shear_modulus):
    """(the largest sampled sigma_VM^2 over all points of ``c``, its point): the sections are sampled only
    where the bounds of :func:`_monomial_bound_at` and :func:`_bound_at` reach the stress sampled at the
    point of largest cheap bound (NaN if no bound does: a non-finite state)."""
    n = c.shape[0]
    bound = np.empty(n)
    first = 0
    for p in range(n):
        bound[p] = _monomial_bound_at(c, p, monomial_bounds, young_modulus, shear_modulus)
        if bound[p] > bound[first]:
            first = p
    # (1 - 1e-9): the bound and the sampled stress are equal where one monomial carries the strain, and
    # round-off must not drop that section
    reached = (1.0 - 1e-9) * _sampled_at(c, first, monomials, young_modulus, shear_modulus)
    largest, at = np.nan, first
    for p in range(n):
        if bound[p] >= reached and _bound_at(c, p, radius, young_modulus, shear_modulus) >= reached:
            value = _sampled_at(c, p, monomials, young_modulus, shear_modulus)
            if not value <= largest:  # the first of the largest (and any value beats NaN)
                largest, at = value, p
    return largest, at


@njit(cache=True)
def _at_ends(c, ends):
    """The strains' coefficients recovered at the string's two ends from the points ``c`` (cells * points, 3,
    monomials): 1.5 times those of the end element's midpoint less 0.5 times its neighbour's (rows of
    ``ends``: the point indices of the two midpoints at each end)."""
    out = np.empty((ends.shape[0], c.shape[1], c.shape[2]))
    for e in range(ends.shape[0]):
        out[e] = 1.5 * c[ends[e, 0]] - 0.5 * c[ends[e, 1]]
    return out


@kernel
def _batch_maxima(sampled, end_cells, dofs_rows, monomials, monomial_bounds, radius, young_modulus,
                  shear_modulus, ends):
    """:func:`_largest` of each state (a row of ``dofs_rows``) over the strains' coefficients of the expression
    ``sampled`` (address, cell dofs, constants, coordinates, size: :func:`~fenics_drill.model.kernels.cell_kernels.
    tabulate_at_cells`), or the stress recovered at an end (:func:`_at_ends` of the coefficients that the
    expression ``end_cells`` gives; index points + e of end e) where that is larger: one call for many steps."""
    address, cell_dofs, constants, coordinates, size = sampled
    end_address, end_dofs, end_constants, end_coordinates, end_size = end_cells
    strains, at_end_cells = np.empty((cell_dofs.shape[0], size)), np.empty((end_dofs.shape[0], end_size))
    values, at = np.empty(dofs_rows.shape[0]), np.empty(dofs_rows.shape[0], dtype=np.int64)
    for s in range(dofs_rows.shape[0]):
        tabulate_at_cells(address, dofs_rows[s], cell_dofs, constants, coordinates, strains)
        c = strains.reshape(-1, 3, monomials.shape[0])
        values[s], at[s] = _largest(c, monomials, monomial_bounds, radius, young_modulus, shear_modulus)
        tabulate_at_cells(end_address, dofs_rows[s], end_dofs, end_constants, end_coordinates, at_end_cells)
        recovered = _at_ends(at_end_cells.reshape(-1, 3, monomials.shape[0]), ends)
        for e in range(ends.shape[0]):
            value = _sampled_at(recovered, e, monomials, young_modulus, shear_modulus)
            if value > values[s]:
                values[s], at[s] = value, c.shape[0] + e
    return values, at


def outer_fibre(outer_radius: float, angles: int = SECTION_ANGLES) -> np.ndarray:
    """(y, z) of the sample points on the outer fibre, shape (angles, 2)."""
    phi = 2.0 * np.pi * np.arange(angles) / angles
    return outer_radius * np.column_stack([np.cos(phi), np.sin(phi)])


def _section_scales(disc: BeamDiscretization) -> list:
    """For a string of sections, the factor of each strain coefficient (eps_xx, eps_xy, eps_xz times y^a z^b) that
    makes the stress of the section at the bit (E, G, R_ext of :attr:`~BeamDiscretization.properties`) the cell's
    pipe body's: E_cell / E (G_cell / G for the shears) times (R_cell / R_ext)^(a + b), times the homogenised tool
    joints' stiffness factor (the body carries the pitch's force and moment on its own section: its strain is the
    pitch's mean strain times A_pitch / A_body for a + b = 0, I_pitch / I_body above), as UFL coefficients."""
    p, cell = disc.properties, disc.form_properties
    moduli = (cell.young_modulus / p.young_modulus, cell.shear_modulus / p.shear_modulus,
              cell.shear_modulus / p.shear_modulus)
    body = (cell.area_stiffness_factor, cell.inertia_stiffness_factor)
    return [modulus * body[min(a + b, 1)] * (cell.outer_radius / p.outer_radius) ** (a + b)
            for modulus in moduli for a, b in MONOMIALS]


class VonMisesProbe:
    """Maximum von Mises stress over the cross-sections of a displacement field."""

    def __init__(self, disc: BeamDiscretization, geometric_nonlinearity: bool = True, kinematics: str = "objective"):
        p = disc.properties
        self.E, self.G = p.young_modulus, p.shear_modulus
        self.field = fem.Function(disc.V)
        slots = strain_slots(self.field, p.axis, geometric_nonlinearity)
        strains = green_lagrange_strains(slots, kinematics) if geometric_nonlinearity else linear_strains(slots)
        coefficients = [poly.terms.get(m, 0.0) for poly in strains for m in MONOMIALS]
        if disc.sections is not None:  # each cell's E, G and radius: its strains scaled to the section at the bit's
            coefficients = [c * factor for c, factor in zip(coefficients, _section_scales(disc))]
        expression = ufl.as_vector([c if isinstance(c, ufl.core.expr.Expr) else ufl.as_ufl(c) for c in coefficients])
        self.expression = fem.Expression(expression, ELEMENT_POINTS)
        self._at_cells = CellExpression(self.expression, self.field)
        self.cells = np.arange(disc.mesh.topology.index_map(1).size_local, dtype=np.int32)
        y, z = outer_fibre(p.outer_radius).T
        self.monomials = np.stack([y**a * z**b for a, b in MONOMIALS])  # (6, samples)
        self.outer_radius = p.outer_radius
        # max |y^a z^b| on the circle r = R_ext: R^(a+b) times max |cos^a sin^b| (1 or 1/2 for a = b = 1)
        self.monomial_bounds = np.array([p.outer_radius ** (a + b) * (0.5 if a == b == 1 else 1.0)
                                         for a, b in MONOMIALS])
        x = disc.mesh.geometry.x[:, 0]
        cell_vertices = disc.mesh.geometry.dofmaps[0]  # (cells, 2) for the affine interval
        x0, x1 = x[cell_vertices[:, 0]], x[cell_vertices[:, 1]]
        self.x = x0[:, None] + ELEMENT_POINTS[:, 0][None, :] * (x1 - x0)[:, None]  # (cells, points)
        # the midpoints of the two elements at each end, as point indices, and the ends' x
        along = np.argsort(x0, kind="stable")
        middle = int(np.flatnonzero(ELEMENT_POINTS[:, 0] == 0.5)[0])
        points = len(ELEMENT_POINTS)
        self.ends = np.array([[along[0], along[1]], [along[-1], along[-2]]], dtype=np.int64) * points + middle
        self.end_x = np.array([x0[along[0]], x1[along[-1]]])
        # what :meth:`maxima` evaluates: the ends of every element, and all points of the four end elements
        # (the recovery reads their midpoints: those of self.ends, numbered among these cells)
        self._at_element_ends = CellExpression(fem.Expression(expression, ELEMENT_ENDS), self.field)
        end_cells = np.array([along[0], along[1], along[-1], along[-2]], dtype=np.int32)
        self._at_end_cells = CellExpression(self.expression, self.field, end_cells)
        self._end_midpoints = np.array([[0, 1], [2, 3]], dtype=np.int64) * points + middle
        # where each point of :meth:`maxima` sits: the elements' ends, then the two recovered ends
        ends_x = x0[:, None] + ELEMENT_ENDS[:, 0][None, :] * (x1 - x0)[:, None]
        self._point_x = np.concatenate((ends_x.ravel(), self.end_x))

    def _coefficients(self, dofs: np.ndarray) -> np.ndarray:
        """Monomial coefficients of (eps_xx, eps_xy, eps_xz) at every point: (cells * points, 3, 6)."""
        return self._at_cells(dofs).reshape(-1, 3, len(MONOMIALS))

    def stress(self, dofs: np.ndarray) -> np.ndarray:
        """Maximum of sigma_VM over each sampled section, shape (cells, points) [Pa]."""
        c = self._coefficients(dofs)
        squared = _sampled_maxima(c, np.arange(len(c)), self.monomials, self.E, self.G)
        return np.sqrt(squared).reshape(len(self.cells), len(ELEMENT_POINTS))

    def end_stress(self, dofs: np.ndarray) -> np.ndarray:
        """sigma_VM recovered at the string's two ends (its start, then its end) [Pa]: the sampled sections of
        the strains extrapolated from the two end elements' midpoints (module doc)."""
        recovered = _at_ends(self._coefficients(dofs), self.ends)
        return np.sqrt(_sampled_maxima(recovered, np.arange(len(recovered)), self.monomials, self.E, self.G))

    def maxima(self, dofs_rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(max sigma_VM [Pa], x where it occurs [m]) over the whole string for each row of ``dofs_rows``
        (states x dofs), in one compiled call.

        The larger of :meth:`stress` at the elements' ends (where an element's largest stress lies: module
        doc) and :meth:`end_stress`, at a fraction of their cost: the sections are sampled only where an upper
        bound of the stress reaches the stress sampled at the section of largest bound."""
        expressions = tuple((e.address, e.cell_dofs, e.constants, e.coordinates, e.size)
                            for e in (self._at_element_ends, self._at_end_cells))
        squared, at = _batch_maxima(*expressions, self._at_element_ends.with_fixed(dofs_rows), self.monomials,
                                    self.monomial_bounds, self.outer_radius, self.E, self.G,
                                    self._end_midpoints)
        return np.sqrt(squared), self._point_x[at]

    def maximum(self, dofs: np.ndarray) -> tuple[float, float]:
        """:meth:`maxima` of one state."""
        values, where = self.maxima(np.asarray(dofs)[None, :])
        return float(values[0]), float(where[0])

    def cell_stress(self, dofs: np.ndarray) -> np.ndarray:
        """Maximum of sigma_VM over each element (for field output and pictures) [Pa]."""
        return self.stress(dofs).max(axis=1)
