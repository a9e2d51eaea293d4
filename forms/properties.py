"""Material and cross-section constants of the annular beam, Eqs. (3)-(10) and (27)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass(frozen=True)
class SectionConstants:
    """Moments of the annular section S_b (Eqs. 3-10), in m^2, m^4 and m^6.

    ``area`` = A (3); ``I4`` = I_yy = I_zz, with I_xx = 2 I4 (4-6);
    ``I6`` with I_yyzz = I6 and I_yyyy = I_zzzz = 3 I6 (7-8).
    """

    area: float
    I4: float
    I6: float


def section_constants(outer_radius: float, inner_radius: float) -> SectionConstants:
    """Return A, I4 and I6 of the annulus R_int <= r <= R_ext (Eqs. 3, 9, 10)."""
    ro, ri = outer_radius, inner_radius
    return SectionConstants(
        area=math.pi * (ro**2 - ri**2),
        I4=math.pi / 4.0 * (ro**4 - ri**4),
        I6=math.pi / 24.0 * (ro**6 - ri**6),
    )


@dataclass(frozen=True)
class CurvedAxis:
    """The borehole axis the beam lies along, as UFL coefficients on the mesh: the axis' curvature (k2, k3) [1/m]
    in its Bishop frame (t, d2, d3), with t' = k2 d2 + k3 d3, d2' = -k2 t, d3' = -k3 t, and the unit downward
    vertical's components (down_t, down_2, down_3) in that frame.  The fields (u, v, w) and (theta_x, theta_y,
    theta_z) are components along (t, d2, d3).  None (the default) is the straight axis with gravity along -z."""

    curvature: tuple
    down: tuple


#: The torsional stiffness: St-Venant's G J, or the paper's kappa_s G J (Table 4's torsional wave speed).
TORSION = ("st_venant", "printed")


@dataclass(frozen=True)
class BeamProperties:
    """Everything the beam forms need, in SI units.

    density rho [kg/m^3], young_modulus E [Pa], poisson_ratio nu [-],
    shear_factor kappa_s [-], damping c [1/s] (the paper's "dimensionless"
    constant of Eq. 38 multiplies rho, so it carries 1/s), gravity g [m/s^2] (the weight per length
    rho A g; in a fluid, reduced by its buoyancy); the fluid's lateral added mass m_f [kg/m] and
    viscous damping c_f [N s/m^2] act on the lateral translations v, w only (0 in air).
    """

    length: float
    outer_radius: float
    inner_radius: float
    density: float
    young_modulus: float
    poisson_ratio: float
    shear_factor: float
    damping: float
    gravity: float
    lateral_added_mass: float = 0.0  # fluid moving with the lateral motion (v, w) [kg/m]
    lateral_fluid_damping: float = 0.0  # viscous force per length and lateral velocity [N s/m^2]
    axis: CurvedAxis | None = field(default=None, compare=False)  # a well's axis; None: straight, horizontal
    #: 'st_venant': the torsional stiffness G J of a round tube (no shear correction); 'printed': the paper's
    #: kappa_s G J (docs/errata.md, "Torsional stiffness").
    torsion: str = "st_venant"
    #: Tool joints homogenised over their pitch (docs/wells.md): the stiffness moments A, I4, I6 of the body
    #: times these factors (series compliance of body and joint), and the rotary inertia rho I4 times
    #: ``rotary_inertia_factor`` (the pitch's mean rho I4 over the body's rho I4, with rho the cell's density).
    area_stiffness_factor: float = 1.0
    inertia_stiffness_factor: float = 1.0
    sixth_moment_stiffness_factor: float = 1.0
    rotary_inertia_factor: float = 1.0

    def __post_init__(self):
        if self.torsion not in TORSION:
            raise ValueError(f"unknown torsion {self.torsion!r}; expected one of {TORSION}")

    @property
    def section(self) -> SectionConstants:
        return section_constants(self.outer_radius, self.inner_radius)

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)), Eq. (27)."""
        return self.young_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def torsional_modulus(self):
        """The modulus of the torsional stiffness: G (St-Venant) or kappa_s G (the paper's, ``torsion='printed'``)."""
        return self.shear_modulus if self.torsion == "st_venant" else self.shear_factor * self.shear_modulus

    @property
    def stiffness_section(self) -> SectionConstants:
        """A, I4, I6 of the section as the stiffness sees them: the body's, stiffened by homogenised tool joints."""
        s = self.section
        return SectionConstants(s.area * self.area_stiffness_factor, s.I4 * self.inertia_stiffness_factor,
                                s.I6 * self.sixth_moment_stiffness_factor)

    @property
    def torsional_rigidity(self):
        """G J = G (2 I4) of St-Venant torsion (kappa_s G J with ``torsion='printed'``) [N m^2]."""
        return self.torsional_modulus * 2.0 * self.stiffness_section.I4

    @property
    def polar_inertia_per_length(self):
        """rho J = rho (2 I4) times the tool joints' rotary factor [kg m]."""
        return self.density * 2.0 * self.section.I4 * self.rotary_inertia_factor

    @property
    def longitudinal_wave_speed(self) -> float:
        """c_L = sqrt(E / rho), used in the dimensionless frequency (95)."""
        return math.sqrt(self.young_modulus / self.density)

    @property
    def torsional_wave_speed(self) -> float:
        """sqrt(G J / rho J): sqrt(G / rho) for a plain tube (sqrt(kappa_s G / rho) with ``torsion='printed'``)."""
        return math.sqrt(self.torsional_rigidity / self.polar_inertia_per_length)

    @property
    def mass_per_length(self) -> float:
        return self.density * self.section.area
