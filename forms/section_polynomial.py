"""Polynomials in the section coordinates (y, z) with UFL coefficients, integrated exactly
over the annulus R_int <= sqrt(y^2 + z^2) <= R_ext.

The strains (34)-(36) are polynomials of degree <= 2 in (y, z), so the strain
energy density needs the section moments up to degree 4: A, I4, I6 (Eqs. 3-10).
"""

from __future__ import annotations

import math


def annulus_moment(a: int, b: int, outer_radius: float, inner_radius: float) -> float:
    """int_S y^a z^b dy dz over the annulus (zero when a or b is odd).

    In polar form: (R^(n+2) - r^(n+2)) / (n + 2) * 2 G((a+1)/2) G((b+1)/2) / G((n+2)/2), n = a + b.
    """
    if a % 2 or b % 2:
        return 0.0
    n = a + b
    radial = (outer_radius ** (n + 2) - inner_radius ** (n + 2)) / (n + 2)
    angular = 2.0 * math.gamma((a + 1) / 2) * math.gamma((b + 1) / 2) / math.gamma((n + 2) / 2)
    return radial * angular


class SectionPolynomial:
    """sum_(a,b) c_ab y^a z^b with UFL (or float) coefficients c_ab."""

    def __init__(self, terms: dict[tuple[int, int], object]):
        self.terms = dict(terms)

    @classmethod
    def constant(cls, c) -> "SectionPolynomial":
        return cls({(0, 0): c})

    def __add__(self, other: "SectionPolynomial") -> "SectionPolynomial":
        terms = dict(self.terms)
        for key, c in other.terms.items():
            terms[key] = terms[key] + c if key in terms else c
        return SectionPolynomial(terms)

    def scale(self, factor) -> "SectionPolynomial":
        return SectionPolynomial({k: factor * c for k, c in self.terms.items()})

    def __mul__(self, other: "SectionPolynomial") -> "SectionPolynomial":
        terms: dict[tuple[int, int], object] = {}
        for (a1, b1), c1 in self.terms.items():
            for (a2, b2), c2 in other.terms.items():
                key = (a1 + a2, b1 + b2)
                terms[key] = terms[key] + c1 * c2 if key in terms else c1 * c2
        return SectionPolynomial(terms)

    def integrate(self, outer_radius: float, inner_radius: float, degree_factors=(1.0, 1.0, 1.0)):
        """int_S p(y, z) dy dz, exactly; the moments of degree 0, 2 and 4 (those of A, I4 and I6) times
        ``degree_factors`` (a section stiffened by homogenised tool joints: :attr:`BeamProperties.stiffness_section`)."""
        total = 0.0
        for (a, b), c in self.terms.items():
            m = annulus_moment(a, b, outer_radius, inner_radius)
            if m != 0.0:
                total = total + degree_factors[(a + b) // 2] * m * c
        return total
