"""The drillstring as its sections, from the bit up, placed along measured depth from the surface, with the
properties a torque-and-drag or buckling model needs: section moments, weight in air and in the mud (buoyancy of
the fluid outside and inside), and the contact radius (the tool joints', where they touch the wall).

Tool joints count as added steel: a joint of outer radius R_tj and length l every ``spacing`` adds
pi (R_tj^2 - R^2) l / spacing of steel area per length to the weight and to the displaced mud, and makes R_tj
the radius at which the pipe meets the wall.  The buoyed weight per length is
g (rho_s A_steel + rho_in A_in - rho_out A_out) (Archimedes, the effective-tension convention of Lubinski).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fenics_drill.forms.properties import section_constants


@dataclass(frozen=True)
class StringSection:
    """One section of the string, between measured depths ``top`` and ``bottom`` from the surface."""

    name: str
    top: float
    bottom: float
    outer_radius: float
    inner_radius: float
    density: float
    young_modulus: float
    poisson_ratio: float
    contact_radius: float  # where it touches the wall: the tool joints', or the body's
    mass_per_length: float  # steel, tool joints included [kg/m]
    displaced_area: float  # outer area, tool joints included [m^2]
    inner_area: float  # [m^2]

    @property
    def bending_stiffness(self) -> float:
        """E I of the pipe body [N m^2]."""
        return self.young_modulus * section_constants(self.outer_radius, self.inner_radius).I4

    def buoyed_weight(self, gravity: float, outer_density: float, inner_density: float) -> float:
        """Weight per length in the fluids [N/m]."""
        return gravity * (self.mass_per_length + inner_density * self.inner_area - outer_density * self.displaced_area)


def string_sections(scene) -> list[StringSection]:
    """The scene's string, from the surface down (the bit at the bottom of the last): its ``string.sections``
    (given from the bit up), or the one pipe of ``[beam]``."""
    beam = scene.beam
    given = list(scene.string.sections) or [{"name": "pipe", "length": beam.length, "outer_radius": beam.outer_radius,
                                             "inner_radius": beam.inner_radius}]
    out, top = [], 0.0
    for raw in reversed(given):  # from the top down
        density = raw.get("density", beam.density)
        outer, inner = raw["outer_radius"], raw["inner_radius"]
        joint = raw.get("tool_joint_outer_radius", 0.0)
        extra = math.pi * (joint**2 - outer**2) * raw["tool_joint_length"] / raw["tool_joint_spacing"] if joint else 0.0
        steel = math.pi * (outer**2 - inner**2) + extra
        out.append(StringSection(
            name=str(raw.get("name", "section")), top=top, bottom=top + raw["length"], outer_radius=outer,
            inner_radius=inner, density=density, young_modulus=raw.get("young_modulus", beam.young_modulus),
            poisson_ratio=raw.get("poisson_ratio", beam.poisson_ratio), contact_radius=joint or outer,
            mass_per_length=density * steel, displaced_area=math.pi * outer**2 + extra, inner_area=math.pi * inner**2))
        top += raw["length"]
    return out


def section_at(sections: list[StringSection], md) -> np.ndarray:
    """The index of the section at each measured depth (the deepest section below its bottom)."""
    bottoms = np.array([s.bottom for s in sections])
    return np.clip(np.searchsorted(bottoms, np.atleast_1d(np.asarray(md, dtype=float)), side="left"), 0,
                   len(sections) - 1)
