"""Energies of the rotating beam and the forces derived from them with ``ufl.derivative``.

Kinetic energy (23)-(24) with the angular velocity (13); Green-Lagrange strains
(31)-(33) computed from the kinematics (14) as polynomials in (y, z) and the
strain energy (30) integrated exactly over the annulus; dissipation function (38).

The generalised forces follow Lagrange's equations.  With U, V, A the
displacement, velocity and acceleration coefficients::

    inertial(psi) = d/dt dT/dV [psi] - dT/dU [psi]
                  = D_U(dT/dV[psi])[V] + D_V(dT/dV[psi])[A] - dT/dU[psi]
    elastic(psi)  = dV/dU [psi]          damping(psi) = dD/dV [psi]

and the equation of motion (43) reads inertial + damping + elastic = F_FS + F_BR + F_G.
"""

from __future__ import annotations

import ufl

from .properties import BeamProperties, CurvedAxis
from .section_polynomial import SectionPolynomial

#: Arguments of the strain energy density: the only ways it depends on U.
STRAIN_SLOTS = ("theta_x", "theta_y", "theta_z", "du", "dv", "dw", "dtheta_x", "dtheta_y", "dtheta_z")


def axial_derivatives(U, axis: CurvedAxis | None = None, finite_spin: bool = False) -> tuple:
    """The derivatives along the axis of the displacement (u, v, w) and rotation (theta_x, theta_y, theta_z)
    vectors, as components in the axis' frame.  On a curved axis (Bishop frame, curvature (k2, k3)) the frame turns:
    (a t + b d2 + c d3)' = (a' - k2 b - k3 c) t + (b' + k2 a) d2 + (c' + k3 a) d3 (docs/wells.md).

    The spin theta_x enters the bending of a curved axis as k theta_x only while it is small: the section spun by
    theta_x about the tangent sees the axis' curvature turned by theta_x, (k2, k3) -> (k2 cos + k3 sin,
    -k2 sin + k3 cos), so with ``finite_spin`` the bending slots take the change of curvature
    (k2 sin theta_x + k3 (1 - cos theta_x), k3 sin theta_x - k2 (1 - cos theta_x)): bounded and periodic in the spin,
    k theta_x to first order.  The linear form (46) and its tangent at rest keep k theta_x (docs/wells.md,
    "A string spinning in a curved hole")."""
    d = [U[i].dx(0) for i in range(6)]
    if axis is None:
        return tuple(d)
    k2, k3 = axis.curvature
    if finite_spin:
        sin, versine = ufl.sin(U[3]), 1.0 - ufl.cos(U[3])
        spin_y, spin_z = k2 * sin + k3 * versine, k3 * sin - k2 * versine
    else:
        spin_y, spin_z = k2 * U[3], k3 * U[3]
    return (d[0] - k2 * U[1] - k3 * U[2], d[1] + k2 * U[0], d[2] + k3 * U[0],
            d[3] - k2 * U[4] - k3 * U[5], d[4] + spin_y, d[5] + spin_z)


def strain_slots(U, axis: CurvedAxis | None = None, finite_spin: bool = False) -> dict:
    """theta_x, theta_y, theta_z and the axial derivatives u', v', w', theta_x', theta_y', theta_z' (in the frame
    of a curved ``axis``: :func:`axial_derivatives`, with its ``finite_spin``)."""
    return dict(zip(STRAIN_SLOTS, (U[3], U[4], U[5], *axial_derivatives(U, axis, finite_spin))))


#: Kinematics of the cross-section (docs/errata.md, "Kinematics (14)"):
#: 'printed' is Eq. (14), u_x = u - y theta_z + z theta_y with (y, z) the undeformed
#: position, whose strains (35)-(36) change under a rigid spin theta_x; 'objective'
#: tilts the section about the inertial axes at its spun position
#: (Y, Z) = (y cos theta_x - z sin theta_x, y sin theta_x + z cos theta_x).
KINEMATICS = ("objective", "printed")


def _axial_tilt(s: dict, kinematics: str):
    """u_x - u = y a + z b: the coefficients (a, b) and their axial derivatives."""
    if kinematics == "printed":
        return -s["theta_z"], s["theta_y"], -s["dtheta_z"], s["dtheta_y"]
    if kinematics != "objective":
        raise ValueError(f"unknown kinematics {kinematics!r}; expected one of {KINEMATICS}")
    S, C = ufl.sin(s["theta_x"]), ufl.cos(s["theta_x"])
    ty, tz, dtx, dty, dtz = s["theta_y"], s["theta_z"], s["dtheta_x"], s["dtheta_y"], s["dtheta_z"]
    a = -C * tz + S * ty
    b = S * tz + C * ty
    da = dtx * (S * tz + C * ty) - C * dtz + S * dty
    db = dtx * (C * tz - S * ty) + S * dtz + C * dty
    return a, b, da, db


def green_lagrange_strains(s: dict, kinematics: str = "objective") -> tuple[SectionPolynomial, SectionPolynomial, SectionPolynomial]:
    """(eps_xx, eps_xy, eps_xz) of Eqs. (31)-(33) for the kinematics (14), as polynomials in (y, z)."""
    S, C = ufl.sin(s["theta_x"]), ufl.cos(s["theta_x"])
    P = SectionPolynomial
    tx1 = s["dtheta_x"]
    a, b, da, db = _axial_tilt(s, kinematics)
    # displacement gradient: d(u_x, u_y, u_z)/d(x, y, z)
    dux_dx = P({(0, 0): s["du"], (1, 0): da, (0, 1): db})
    duy_dx = P({(0, 0): s["dv"], (1, 0): -S * tx1, (0, 1): -C * tx1})
    duz_dx = P({(0, 0): s["dw"], (1, 0): C * tx1, (0, 1): -S * tx1})
    dux_dy, duy_dy, duz_dy = P.constant(a), P.constant(C - 1.0), P.constant(S)
    dux_dz, duy_dz, duz_dz = P.constant(b), P.constant(-S), P.constant(C - 1.0)
    eps_xx = dux_dx + (dux_dx * dux_dx + duy_dx * duy_dx + duz_dx * duz_dx).scale(0.5)
    eps_xy = (duy_dx + dux_dy).scale(0.5) + (dux_dx * dux_dy + duy_dx * duy_dy + duz_dx * duz_dy).scale(0.5)
    eps_xz = (duz_dx + dux_dz).scale(0.5) + (dux_dx * dux_dz + duy_dx * duy_dz + duz_dx * duz_dz).scale(0.5)
    return eps_xx, eps_xy, eps_xz


def linear_strains(s: dict) -> tuple[SectionPolynomial, SectionPolynomial, SectionPolynomial]:
    """The strains linearised about the undeformed state (what the stiffness (46) integrates)."""
    P = SectionPolynomial
    eps_xx = P({(0, 0): s["du"], (1, 0): -s["dtheta_z"], (0, 1): s["dtheta_y"]})
    eps_xy = P({(0, 0): 0.5 * (s["dv"] - s["theta_z"]), (0, 1): -0.5 * s["dtheta_x"]})
    eps_xz = P({(0, 0): 0.5 * (s["dw"] + s["theta_y"]), (1, 0): 0.5 * s["dtheta_x"]})
    return eps_xx, eps_xy, eps_xz


def strain_energy_density(p: BeamProperties, s: dict, geometric_nonlinearity: bool = True,
                          kinematics: str = "objective"):
    """Strain energy per unit length, Eq. (30), with the shear factor on the transverse shear only:
    1/2 int_S E e_xx^2 dA + 2 G [int_S (e_xy^2 + e_xz^2) dA - (1 - ks) (m_xy^2 + m_xz^2) / A], m = int_S e dA.
    The section's mean shear strain carries ks (Timoshenko's correction); what varies over the section, the
    St-Venant torsion, does not (its stiffness is G J; docs/errata.md, "Torsional stiffness").  With
    ``p.torsion = 'printed'`` the whole shear energy carries ks, as (30) is printed."""
    exx, exy, exz = green_lagrange_strains(s, kinematics) if geometric_nonlinearity else linear_strains(s)
    E, G, ks = p.young_modulus, p.shear_modulus, p.shear_factor
    ro, ri = p.outer_radius, p.inner_radius
    factors = (p.area_stiffness_factor, p.inertia_stiffness_factor, p.sixth_moment_stiffness_factor)
    axial = E * (exx * exx).integrate(ro, ri, factors)
    shear = (exy * exy + exz * exz).integrate(ro, ri, factors)
    if p.torsion == "printed":
        return 0.5 * axial + 2.0 * ks * G * shear
    area = p.stiffness_section.area
    mean_xy, mean_xz = exy.integrate(ro, ri, factors), exz.integrate(ro, ri, factors)
    return 0.5 * axial + 2.0 * G * (shear - (1.0 - ks) * (mean_xy**2 + mean_xz**2) / area)


#: Angular velocity of the section (docs/errata.md, "Angular velocity (13)"): 'consistent' takes the
#: tilts theta_y, theta_z about the inertial axes, as the strains do (theta_y = -w', theta_z = v' at
#: zero shear), so the spin component is theta_x_dot - theta_z_dot theta_y and a spinning shaft's
#: forward whirl stiffens; 'printed' is Eq. (13), theta_x_dot + theta_z_dot theta_y, whose gyroscopic
#: coupling has the opposite sign (forward whirl softens).
ANGULAR_VELOCITY = ("consistent", "printed")


def angular_velocity(U, V, inertial_nonlinearity: bool = True, form: str = "consistent"):
    """omega in the inertial frame (small transverse rotations), Eq. (13) with the sign of ``form``;
    linearised if asked."""
    if form not in ANGULAR_VELOCITY:
        raise ValueError(f"unknown angular velocity {form!r}; expected one of {ANGULAR_VELOCITY}")
    if not inertial_nonlinearity:
        return V[3], V[4], V[5]
    S, C = ufl.sin(U[3]), ufl.cos(U[3])
    spin_sign = 1.0 if form == "printed" else -1.0
    return V[3] + spin_sign * V[5] * U[4], V[4] * C - V[5] * S, V[4] * S + V[5] * C


def kinetic_energy_density(p: BeamProperties, U, V, inertial_nonlinearity: bool = True,
                           angular_velocity_form: str = "consistent"):
    """Kinetic energy per unit length, Eq. (24): translation plus omega . J omega / 2 with the
    section inertia tensor J = rho diag(2 I4, I4, I4) of Eq. (23)."""
    s = p.section
    w1, w2, w3 = angular_velocity(U, V, inertial_nonlinearity, angular_velocity_form)
    translational = 0.5 * p.density * s.area * (V[0] ** 2 + V[1] ** 2 + V[2] ** 2)
    rotational = 0.5 * p.density * s.I4 * p.rotary_inertia_factor * (2.0 * w1**2 + w2**2 + w3**2)
    fluid = 0.5 * p.lateral_added_mass * (V[1] ** 2 + V[2] ** 2)
    return translational + rotational + fluid


def dissipation_density(p: BeamProperties, V):
    """Dissipation function per unit length, Eq. (38), plus the fluid's lateral viscous damping."""
    s = p.section
    return 0.5 * p.damping * p.density * (
        s.area * (V[0] ** 2 + V[1] ** 2 + V[2] ** 2)
        + s.I4 * p.rotary_inertia_factor * (2.0 * V[3] ** 2 + V[4] ** 2 + V[5] ** 2)
    ) + 0.5 * p.lateral_fluid_damping * (V[1] ** 2 + V[2] ** 2)


def inertial_force(p: BeamProperties, psi, U, V, A, dx, inertial_nonlinearity: bool = True,
                   angular_velocity_form: str = "consistent", weight=1.0):
    """Lagrange's d/dt dT/dV - dT/dU as a linear form in psi (= M(psi, A) - F_KE(psi), Eqs. 44, 48);
    ``weight`` multiplies the energy density (the element weights of a hyper-reduced sample)."""
    T = weight * kinetic_energy_density(p, U, V, inertial_nonlinearity, angular_velocity_form) * dx
    momentum = ufl.derivative(T, V, psi)
    return ufl.derivative(momentum, U, V) + ufl.derivative(momentum, V, A) - ufl.derivative(T, U, psi)


def elastic_force(p: BeamProperties, psi, U, dx, geometric_nonlinearity: bool = True, kinematics: str = "objective",
                  weight=1.0):
    """dV/dU [psi] (= K(psi, U) - F_SE(psi), Eqs. 46, 49); ``weight`` as for :func:`inertial_force`."""
    W = strain_energy_density(p, strain_slots(U, p.axis, geometric_nonlinearity), geometric_nonlinearity, kinematics)
    return ufl.derivative(weight * W * dx, U, psi)


def damping_force(p: BeamProperties, psi, V, dx):
    """dD/dV [psi] (= C(psi, V), Eq. 45)."""
    return ufl.derivative(dissipation_density(p, V) * dx, V, psi)


def strain_energy_gradient_terms(p: BeamProperties, U, geometric_nonlinearity: bool = True,
                                 kinematics: str = "objective") -> dict:
    """dW/d(slot) for each slot of :data:`STRAIN_SLOTS`: the factors multiplying psi_tx, ...,
    psi_tz' in dV/dU[psi] (the energy-derived counterparts of Gamma_1..Gamma_9 plus K)."""
    slots = {name: ufl.variable(expr) for name, expr in strain_slots(U, p.axis).items()}
    W = strain_energy_density(p, slots, geometric_nonlinearity, kinematics)
    return {name: ufl.diff(W, var) for name, var in slots.items()}
