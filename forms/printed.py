"""The nonlinear operators exactly as printed: F_KE (48) and F_SE (49) with Gamma_1..Gamma_9
of Appendix A (105)-(113).  Kept for comparison with the energy-derived forces of
:mod:`energies`; the solver never uses them.  ``s`` is the slot dict of
:func:`energies.strain_slots` (theta_x, ..., dtheta_z).
"""

from __future__ import annotations

import ufl

from .properties import BeamProperties

GAMMA_SLOTS = ("theta_x", "theta_y", "theta_z", "du", "dv", "dw", "dtheta_x", "dtheta_y", "dtheta_z")


def printed_inertial_nonlinear_force(p: BeamProperties, psi, U, V, A, dx):
    """F_KE(psi), Eq. (48) as printed."""
    rI = p.density * p.section.I4 * p.rotary_inertia_factor
    tx, ty = U[3], U[4]
    vx, vy, vz = V[3], V[4], V[5]
    ax, az = A[3], A[5]
    return (
        -2 * rI * psi[3] * (ty * az + vy * vz)
        + 2 * rI * psi[4] * (ty * vz**2 + vx * vz)
        - 2 * rI * psi[5] * (ty * ax + ty**2 * az)
        - 2 * rI * psi[5] * (vx * vy + 2 * ty * vy * vz)
    ) * dx


def printed_gammas(p: BeamProperties, s: dict) -> dict:
    """Gamma_1..Gamma_9 of Appendix A as printed, keyed by the slot they multiply in (49)."""
    sec = p.stiffness_section
    E, kG = p.young_modulus, p.shear_factor * p.shear_modulus
    EA, EI4, EI6, kGA, kGI4 = E * sec.area, E * sec.I4, E * sec.I6, kG * sec.area, kG * sec.I4
    S, C = ufl.sin(s["theta_x"]), ufl.cos(s["theta_x"])
    ty, tz = s["theta_y"], s["theta_z"]
    u1, v1, w1 = s["du"], s["dv"], s["dw"]
    tx1, ty1, tz1 = s["dtheta_x"], s["dtheta_y"], s["dtheta_z"]
    g1 = (
        EI4 * (1 + u1) * (v1 * ty1 + w1 * tz1) * S * tx1
        + EI4 * (1 + u1) * (v1 * tz1 - w1 * ty1) * C * tx1
        + kGA * (1 + u1) * (tz * v1 - ty * w1) * S
        - kGA * (1 + u1) * (ty * v1 + tz * w1) * C
    )
    g2 = (
        kGI4 * (ty * (tx1**2 + tz1**2) - tx1 * tz1)
        + kGA * (-w1 + u1 * ty * (2 + u1))
        - kGA * (1 + u1) * (v1 * S - w1 * C)
    )
    g3 = (
        kGI4 * (tz * (ty1**2 + tz1**2) + ty1 * tz1)
        + kGA * (v1 + u1 * tz * (2 + u1))
        - kGA * (1 + u1) * (w1 * S + v1 * C)
    )
    g4 = (
        EA * (0.5 * (1 + u1) * (v1**2 + w1**2) + 0.5 * u1**2 * (3 + u1))
        + EI4 * (S * (v1 * tz1 - w1 * ty1) - C * (v1 * ty1 + w1 * tz1)) * tx1
        + EI4 * (1 + u1) * (tx1**2 + 1.5 * (ty1**2 + tz1**2))
        + kGA * (C * (ty * w1 - tz * v1) - S * (ty * v1 + tz * w1))
        + kGA * (1 + u1) * (ty1**2 + tz1**2)
    )
    g5 = (
        EA * (u1 + 0.5 * (u1**2 + v1**2 + w1**2)) * v1
        + EI4 * (2 * tx1**2 + 0.5 * (ty1**2 + tz1**2)) * v1
        + EI4 * (1 + u1) * (tz1 * S - ty1 * C) * tx1
        + kGA * (1 + u1) * (tz - ty * S - tz * C)
    )
    g6 = (
        EA * (u1 + 0.5 * (u1**2 + v1**2 + w1**2)) * w1
        + EI4 * (2 * tx1**2 + 0.5 * (ty1**2 + tz1**2)) * w1
        + EI4 * (1 + u1) * (-ty1 * S - tz1 * C) * tx1
        + kGA * (1 + u1) * (-ty + ty * C - tz * S)
    )
    g7 = (
        EI4 * (u1**2 + 2 * (u1 + v1**2 + w1**2)) * tx1
        + EI4 * (1 + u1) * (v1 * tz1 - w1 * ty1) * S
        - EI4 * (1 + u1) * (v1 * ty1 + w1 * tz1) * C
        + EI6 * (4 * tx1**2 + 2 * (ty1**2 + tz1**2)) * tx1
        + kGA * (tz * ty1 - ty * tz1)
    )
    g8 = (
        EI4 * (3 * u1 + 0.5 * (3 * u1**2 + v1**2 + w1**2)) * ty1
        + EI4 * (1 + u1) * (-w1 * S - v1 * C) * tx1
        + EI6 * (2 * tx1**2 + 1.5 * (ty1**2 + tz1**2)) * ty1
        + kGI4 * (tz * tx1 + ty1 * (ty1**2 + tz1**2))
    )
    g9 = (
        EI4 * (3 * u1 + 0.5 * (3 * u1**2 + v1**2 + w1**2)) * tz1
        + EI4 * (1 + u1) * (v1 * S - w1 * C) * tx1
        + EI6 * (2 * tx1**2 + 1.5 * (ty1**2 + tz1**2)) * tz1
        + kGI4 * (-ty * tx1 + tz1 * (ty1**2 + tz1**2))
    )
    return dict(zip(GAMMA_SLOTS, (g1, g2, g3, g4, g5, g6, g7, g8, g9)))


def printed_geometric_nonlinear_force(p: BeamProperties, psi, s: dict, dx):
    """F_SE(psi), Eq. (49) as printed."""
    g = printed_gammas(p, s)
    tests = (psi[3], psi[4], psi[5], psi[0].dx(0), psi[1].dx(0), psi[2].dx(0),
             psi[3].dx(0), psi[4].dx(0), psi[5].dx(0))
    return sum(t * g[name] for t, name in zip(tests, GAMMA_SLOTS)) * dx


#: Printed terms that differ from the energy derivation (see docs/errata.md).  Keys are the
#: term names used by fenics_drill.form_check.
PRINTED_ERRATA = {
    "F_SE[sign]": "the Gamma_k are internal forces: (49) must enter (47) with a minus sign",
    "Gamma_2[theta_y]": "k_s G I4 terms do not follow from the strain energy (30)",
    "Gamma_3[theta_z]": "k_s G I4 terms do not follow from the strain energy (30)",
    "Gamma_4[du]": "E A, E I4 and k_s G A terms differ from dW/du' (e.g. k_s G A (1+u')(theta_y'^2+theta_z'^2))",
    "Gamma_5[dv]": "terms differ from dW/dv'",
    "Gamma_6[dw]": "terms differ from dW/dw'",
    "Gamma_7[dtheta_x]": "does not follow from the strain energy: wrong in magnitude and structure",
    "Gamma_8[dtheta_y]": "terms differ from dW/dtheta_y' (k_s G I4 and E I6 terms)",
    "Gamma_9[dtheta_z]": "terms differ from dW/dtheta_z' (k_s G I4 and E I6 terms)",
}
