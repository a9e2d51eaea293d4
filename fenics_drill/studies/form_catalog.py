"""Named forms a user can list and print (``fenics-drill forms``), built on a 2-element mesh."""

from __future__ import annotations

import ufl
from dolfinx import fem

from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.forms import damping_form, gravity_form, mass_form, stiffness_form
from fenics_drill.forms import energies, printed


def form_catalog(disc: BeamDiscretization) -> dict[str, tuple[str, object]]:
    """name -> (description with equation number, UFL form or expression)."""
    p = disc.properties
    psi, dU = ufl.TestFunction(disc.V), ufl.TrialFunction(disc.V)
    U, V, A = (fem.Function(disc.V, name=n) for n in ("U", "V", "A"))
    dx = ufl.Measure("dx", domain=disc.mesh)
    slots = energies.strain_slots(U)
    catalog = {
        "mass": ("mass operator M(psi, U), Eq. (44)", mass_form(p, psi, dU, dx)),
        "damping": ("damping operator C(psi, U), Eq. (45)", damping_form(p, psi, dU, dx)),
        "stiffness": ("stiffness operator K(psi, U), Eq. (46)", stiffness_form(p, psi, dU, dx)),
        "gravity": ("gravity load F_G(psi), Eq. (52)", gravity_form(p, psi, dx)),
        "kinetic_energy": ("kinetic energy density, Eq. (24)", energies.kinetic_energy_density(p, U, V)),
        "strain_energy": ("strain energy density, Eqs. (30)-(36)", energies.strain_energy_density(p, slots)),
        "dissipation": ("dissipation function, Eq. (38)", energies.dissipation_density(p, V)),
        "inertial_force": ("d/dt dT/dV - dT/dU = M(psi, A) - F_KE", energies.inertial_force(p, psi, U, V, A, dx)),
        "elastic_force": ("dV/dU[psi] = K(psi, U) - F_SE", energies.elastic_force(p, psi, U, dx)),
        "damping_force": ("dD/dV[psi] = C(psi, V)", energies.damping_force(p, psi, V, dx)),
        "printed_F_KE": ("F_KE as printed, Eq. (48)", printed.printed_inertial_nonlinear_force(p, psi, U, V, A, dx)),
        "printed_F_SE": ("F_SE as printed, Eq. (49)", printed.printed_geometric_nonlinear_force(p, psi, slots, dx)),
    }
    nonlinear = energies.strain_energy_gradient_terms(p, U, geometric_nonlinearity=True, kinematics="printed")
    linear = energies.strain_energy_gradient_terms(p, U, geometric_nonlinearity=False)
    for k, (slot, gamma) in enumerate(printed.printed_gammas(p, slots).items(), start=1):
        catalog[f"Gamma_{k}"] = (f"Gamma_{k} as printed, Eq. ({104 + k}), multiplies psi slot {slot}", gamma)
        catalog[f"derived_Gamma_{k}"] = (
            f"Gamma_{k} from the strain energy, -(dW/d{slot} - linear part): the corrected coefficient",
            -(nonlinear[slot] - linear[slot]),
        )
    return catalog
