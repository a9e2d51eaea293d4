"""Linear operators of the weak equation of motion (43): Eqs. (44), (45), (46), (52), and the initial-stress
stiffness of a prestressed state.

``U`` and ``psi`` are 6-component UFL objects (trial/coefficient and test
function of the mixed space) ordered (u, v, w, theta_x, theta_y, theta_z);
``dx`` is the interval measure of the mesh.
"""

from __future__ import annotations

import ufl

from .energies import axial_derivatives
from .properties import BeamProperties


def _inertia_pairing(p: BeamProperties, psi, U):
    """rho A (psi_u u + psi_v v + psi_w w) + rho I4 (2 psi_tx tx + psi_ty ty + psi_tz tz)."""
    s = p.section
    rho = p.density
    translational = psi[0] * U[0] + psi[1] * U[1] + psi[2] * U[2]
    rotational = 2.0 * psi[3] * U[3] + psi[4] * U[4] + psi[5] * U[5]
    return rho * s.area * translational + rho * s.I4 * p.rotary_inertia_factor * rotational


def _lateral_pairing(psi, U):
    return psi[1] * U[1] + psi[2] * U[2]


def mass_form(p: BeamProperties, psi, U, dx):
    """Mass operator M(psi, U), Eq. (44), with the fluid's lateral added mass m_f (v, w)."""
    return (_inertia_pairing(p, psi, U) + p.lateral_added_mass * _lateral_pairing(psi, U)) * dx


def damping_form(p: BeamProperties, psi, U, dx):
    """Damping operator C(psi, U) = c M(psi, U), Eq. (45), from the dissipation function (38) (the steel's
    inertia), plus the fluid's lateral viscous damping c_f (v, w)."""
    return (p.damping * _inertia_pairing(p, psi, U) + p.lateral_fluid_damping * _lateral_pairing(psi, U)) * dx


def stiffness_form(p: BeamProperties, psi, U, dx):
    """Stiffness operator K(psi, U), Eq. (46).

    Axial E A u'; bending E I4 theta_y', theta_z'; torsion G J theta_x' with J = 2 I4 (St-Venant; the printed
    2 kappa_s G I4 with ``p.torsion = 'printed'``, docs/errata.md); shear kappa_s G A (theta_y + w') and
    (theta_z - v'); on a curved axis the derivatives are the frame's
    (:func:`~fenics_drill.forms.energies.axial_derivatives`).  A, I4 are the stiffness section's
    (:attr:`~fenics_drill.forms.properties.BeamProperties.stiffness_section`).
    """
    s = p.stiffness_section
    E, G, ks = p.young_modulus, p.shear_modulus, p.shear_factor
    du, dv, dw, dtx, dty, dtz = axial_derivatives(U, p.axis)
    dpu, dpv, dpw, dptx, dpty, dptz = axial_derivatives(psi, p.axis)
    axial = E * s.area * dpu * du
    bending = E * s.I4 * (dpty * dty + dptz * dtz)
    torsion = p.torsional_rigidity * dptx * dtx
    shear = ks * G * s.area * ((psi[4] + dpw) * (U[4] + dw) + (psi[5] - dpv) * (U[5] - dv))
    return (axial + bending + torsion + shear) * dx


def axial_force(p: BeamProperties, U0):
    """N = E A eps of a state U0, with the Green-Lagrange stretch eps = u' + (u'^2 + v'^2 + w'^2) / 2 (the frame's
    derivatives on a curved axis) [N, tension positive]."""
    du, dv, dw = axial_derivatives(U0, p.axis)[:3]
    return p.young_modulus * p.stiffness_section.area * (du + 0.5 * (du**2 + dv**2 + dw**2))


def geometric_stiffness_form(p: BeamProperties, psi, U, U0, dx):
    """The initial-stress stiffness of the axial force N of a state U0 (:func:`axial_force`):
    int N (psi_v' v' + psi_w' w') dx, the term -(N y')' of the tensioned beam, which the stiffness (46) lacks.
    K(46) + this is the prestressed string of a linear buckling or prestressed modal analysis: the lateral modes
    feel the hanging tension and the weight on bit, the axial and torsional ones keep the stiffness (46)."""
    N = axial_force(p, U0)
    _, dv, dw = axial_derivatives(U, p.axis)[:3]
    _, dpv, dpw = axial_derivatives(psi, p.axis)[:3]
    return N * (dpv * dv + dpw * dw) * dx


def gravity_form(p: BeamProperties, psi, dx):
    """Gravity load F_G(psi) = -int rho A g psi_w dx, Eq. (52); gravity points along -z.  On a curved axis,
    int rho A g (down_t psi_u + down_2 psi_v + down_3 psi_w) dx with the downward vertical in the axis' frame."""
    weight = p.density * p.section.area * p.gravity
    if p.axis is None:
        return -weight * psi[2] * dx
    down_t, down_2, down_3 = p.axis.down
    return weight * (down_t * psi[0] + down_2 * psi[1] + down_3 * psi[2]) * dx
