"""The drillstring as its sections, from the bit up, placed along measured depth from the surface, with the
properties a torque-and-drag or buckling model needs: section moments, weight in air and in the mud (buoyancy of
the fluid outside and inside), and the contact radius (the tool joints', where they touch the wall).

Tool joints: a joint of outer radius R_tj, inner radius r_tj (the body's unless given) and length l every
``spacing`` takes the share f = l / spacing of the pipe.  The steel area, the displaced and the inner area per
length are the means over the pitch, (1 - f) A_body + f A_joint, and R_tj is the radius at which the pipe meets
the wall.  The buoyed weight per length is g (rho_s A_steel + rho_in A_in - rho_out A_out) (Archimedes, the
effective-tension convention of Lubinski).  For the FE string the joints are homogenised over the pitch
(docs/wells.md, "Tool joints"): body and joint in series for the stiffness, 1 / K = (1 - f) / K_body + f / K_joint
for each of E A, E I, G J (and the moment I6 of the nonlinear terms), and the mean inertia rho A, rho J over the
pitch: exact for waves much longer than the pitch.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from fenics_drill.forms.properties import section_constants
from fenics_drill.scene import SceneError


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
    #: The homogenised joints' stiffness over the body's, for A, I4 and I6 (series compliance; 1 without joints).
    stiffness_factors: tuple = (1.0, 1.0, 1.0)
    #: The pitch's mean rho I4 over the body's rho I4 times the density ratio mass_per_length / (rho A_body).
    rotary_inertia_factor: float = 1.0

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
        share = raw["tool_joint_length"] / raw["tool_joint_spacing"] if joint else 0.0
        joint_inner = raw.get("tool_joint_inner_radius", inner) if joint else inner
        body, joint_section = section_constants(outer, inner), section_constants(joint or outer, joint_inner)
        mean = lambda b, j: (1.0 - share) * b + share * j  # noqa: E731  (the pitch's mean)
        steel = mean(body.area, joint_section.area)
        stiffness = tuple(1.0 / mean(1.0, b / j) for b, j in ((body.area, joint_section.area),
                                                               (body.I4, joint_section.I4), (body.I6, joint_section.I6)))
        rotary = mean(1.0, joint_section.I4 / body.I4) / (steel / body.area)
        out.append(StringSection(
            name=str(raw.get("name", "section")), top=top, bottom=top + raw["length"], outer_radius=outer,
            inner_radius=inner, density=density, young_modulus=raw.get("young_modulus", beam.young_modulus),
            poisson_ratio=raw.get("poisson_ratio", beam.poisson_ratio), contact_radius=joint or outer,
            mass_per_length=density * steel, displaced_area=math.pi * mean(outer**2, (joint or outer) ** 2),
            inner_area=math.pi * mean(inner**2, joint_inner**2), stiffness_factors=stiffness,
            rotary_inertia_factor=rotary))
        top += raw["length"]
    return out


def check_sinks(sections: list[StringSection], outer_density: float, inner_density: float) -> None:
    """Raises SceneError where a section would float in the fluids (a buoyed weight <= 0): the string of these
    models hangs from the surface."""
    for s in sections:
        if s.buoyed_weight(1.0, outer_density, inner_density) <= 0:
            raise SceneError(f"string section '{s.name}' floats in the mud: its steel of {s.density:g} kg/m^3 is "
                             f"lighter than the fluid it displaces (fluid.density = {outer_density:g} kg/m^3); "
                             "check fluid.density and the section's density")


def section_at(sections: list[StringSection], md) -> np.ndarray:
    """The index of the section at each measured depth (the deepest section below its bottom)."""
    bottoms = np.array([s.bottom for s in sections])
    return np.clip(np.searchsorted(bottoms, np.atleast_1d(np.asarray(md, dtype=float)), side="left"), 0,
                   len(sections) - 1)


@dataclass(frozen=True)
class FESections:
    """The string of sections on the FE mesh (x = measured depth from the top): on each cell (at its midpoint) the
    pipe body's radii, the density that carries the tool joints' steel, E, nu, the gravity that makes rho A g the
    buoyed weight, the fluids' lateral added mass; at each vertex the contact radius and the hole's radius."""

    cells: dict  # name -> one value per cell, the BeamProperties fields the forms take
    contact_radius: np.ndarray  # [m], per vertex
    hole_radius: np.ndarray  # [m], per vertex

    @property
    def gap(self) -> np.ndarray:
        """The radial clearance at each vertex [m]."""
        return self.hole_radius - self.contact_radius


def fe_sections(scene, sections, hole_radius_at, cell_x: np.ndarray, vertex_x: np.ndarray) -> FESections:
    """The scene's string (``sections``, :func:`string_sections`) on cells with midpoints ``cell_x`` and on vertices
    ``vertex_x``, in a hole whose radius at measured depth s is ``hole_radius_at(s)``.  Tool joints are homogenised over their
    pitch: the density carries their steel, the stiffness and rotary-inertia factors their stiffness and polar
    inertia (module doc), and they give the contact radius; at a vertex between two sections the larger contact
    radius.  Raises SceneError where a section does not fit the hole."""
    g = scene.environment.gravity if scene.model.gravity else 0.0
    outer_fluid, inner_fluid = scene.fluid.density, scene.inner_fluid_density
    k = section_at(sections, cell_x)
    check_sinks(sections, outer_fluid, inner_fluid)
    body = np.array([math.pi * (s.outer_radius**2 - s.inner_radius**2) for s in sections])
    mass = np.array([s.mass_per_length for s in sections])
    buoyed = np.array([s.buoyed_weight(1.0, outer_fluid, inner_fluid) for s in sections])  # per unit g [kg/m]
    outer = np.array([s.outer_radius for s in sections])
    inner = np.array([s.inner_radius for s in sections])
    cells = {
        "outer_radius": outer[k], "inner_radius": inner[k], "density": (mass / body)[k],
        "young_modulus": np.array([s.young_modulus for s in sections])[k],
        "poisson_ratio": np.array([s.poisson_ratio for s in sections])[k],
        "gravity": g * (buoyed / mass)[k],
        "lateral_added_mass": scene.lateral_added_mass_of(outer[k], inner[k], hole_radius_at(cell_x)),
        "rotary_inertia_factor": np.array([s.rotary_inertia_factor for s in sections])[k],
    }
    factors = np.array([s.stiffness_factors for s in sections])
    for i, name in enumerate(("area_stiffness_factor", "inertia_stiffness_factor", "sixth_moment_stiffness_factor")):
        cells[name] = factors[k, i]
    contact = np.array([s.contact_radius for s in sections])
    length = sections[-1].bottom
    step = 1e-9 * length
    contact_radius = np.maximum(contact[section_at(sections, np.maximum(vertex_x - step, 0.0))],
                                contact[section_at(sections, np.minimum(vertex_x + step, length))])
    hole = hole_radius_at(vertex_x)
    bad = np.flatnonzero(hole - contact_radius <= 0)
    if bad.size:
        i = bad[0]
        name = sections[section_at(sections, vertex_x[i])[0]].name
        raise SceneError(f"string section '{name}' (contact radius {contact_radius[i]:g} m) does not fit the hole of "
                         f"radius {hole[i]:g} m at md = {vertex_x[i]:.1f} m")
    return FESections(cells, contact_radius, hole)


def string_at_bit_depth(sections: list[StringSection], depth: float) -> list[StringSection]:
    """The string with its bit at measured depth ``depth`` [m], as a rig makes it up: the same sections from the bit
    up, the top one (drill pipe) cut or lengthened to reach the surface; where the bit is shallower than the sections
    below the top one, the highest of them are cut too.  Sections from the surface down, as :func:`string_sections`."""
    if depth <= 0:
        raise ValueError(f"a bit depth must be > 0 m, got {depth!r}")
    kept, below = [], 0.0
    for section in reversed(sections):  # from the bit up
        length = section.bottom - section.top
        if section is sections[0] or below + length >= depth:
            length = depth - below  # the top one reaches the surface
            kept.append((section, length))
            break
        kept.append((section, length))
        below += length
    out, top = [], 0.0
    for section, length in reversed(kept):
        out.append(dataclasses.replace(section, top=top, bottom=top + length))
        top += length
    return out
