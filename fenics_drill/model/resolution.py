"""What a discretisation resolves: the band's highest frequency f_max (Eq. 95), the string's flexural wavelength
there, and how many displacement nodes of the mesh a wavelength holds.

A mesh with few nodes per flexural wavelength at f_max does not carry the band it is asked for.  Measured on the
paper's string against 1000 elements (``python benchmarks/mesh_resolution.py``): the flexural frequencies above
150 Hz (f_max = 203 Hz) are 0.65 %, 3.2 %, 9.2 % and 20 % off at 27, 14, 8 and 5 nodes per wavelength (500, 250,
150 and 100 elements of degree 2).  Below :data:`MIN_NODES_PER_WAVELENGTH` a run or a static state is
"suspect" with the reason (:func:`mesh_advice`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from fenics_drill.model.well import string_in_well
from fenics_drill.model.well import hanging_tension

#: Fewest displacement nodes (elements x degree) per flexural wavelength at f_max for the band to be carried
#: within about 10 %.
MIN_NODES_PER_WAVELENGTH = 8.0


def band_frequency(scene) -> float:
    """f_max = f*_max c_L / L, the highest frequency of the band B [Hz]."""
    p = scene.beam_properties
    return scene.modal.f_star_max * p.longitudinal_wave_speed / p.length


def flexural_wavelength(properties, frequency_hz: float, tension=0.0):
    """Wavelength [m] of a bending wave of the pipe at ``frequency_hz`` under the axial ``tension`` T [N]: 2 pi / k
    with E I k^4 + T k^2 = rho A omega^2 (the tensioned Euler-Bernoulli beam; shear shortens it a little at high
    frequency).  Tension lengthens the wave, compression shortens it."""
    s = properties.section
    omega = 2.0 * math.pi * frequency_hz
    bending, inertia = properties.young_modulus * s.I4 * properties.inertia_stiffness_factor, properties.density * s.area
    tension = np.asarray(tension, dtype=float)
    k2 = (np.sqrt(tension**2 + 4.0 * bending * inertia * omega**2) - tension) / (2.0 * bending)
    return 2.0 * math.pi / np.sqrt(k2)


#: Points per element at which :func:`nodes_per_wavelength` reads the hanging tension.
TENSION_SAMPLES = 2


def nodes_per_wavelength(scene) -> float:
    """Displacement nodes of the mesh (elements x degree over the length) per flexural wavelength at f_max, where
    it is the shortest: each section's pipe (its homogenised tool joints' bending stiffness included) under the
    tension it hangs with in a well (:func:`hanging_tension`), or unloaded in the straight horizontal hole; only
    along the lateral length (``model.lateral_length``) where the lateral fields are not solved everywhere."""
    b = scene.beam
    length = scene.string_length
    spacing = length / (b.elements * b.element_degree)
    p, f_max = scene.beam_properties, band_frequency(scene)
    if not scene.string.sections:
        md = np.linspace(0.0, length, TENSION_SAMPLES * b.elements + 1)
        return float(np.min(flexural_wavelength(p, f_max, hanging_tension(scene, md, scene.modal_weight_on_bit)))) / spacing
    sections = string_in_well(scene).sections
    lateral_top = length - scene.model.lateral_length if scene.model.lateral_length > 0 else 0.0
    shortest = np.inf
    for s in sections:
        if s.bottom <= lateral_top:
            continue  # held on the axis: no bending
        pipe = replace(p, outer_radius=s.outer_radius, inner_radius=s.inner_radius, young_modulus=s.young_modulus,
                       density=s.mass_per_length / (math.pi * (s.outer_radius**2 - s.inner_radius**2)),
                       inertia_stiffness_factor=s.stiffness_factors[1])
        top = max(s.top, lateral_top)
        md = np.linspace(top, s.bottom, max(2, math.ceil(TENSION_SAMPLES * b.elements * (s.bottom - top) / length)))
        shortest = min(shortest, float(np.min(flexural_wavelength(pipe, f_max,
                                                                   hanging_tension(scene, md, scene.modal_weight_on_bit)))))
    return shortest / spacing


def mesh_advice(scene) -> str | None:
    """Why the mesh is too coarse for the band, or None (an axial-torsional string has no bending to resolve)."""
    if scene.model.lateral_length == 0:
        return None
    nodes = nodes_per_wavelength(scene)
    if nodes >= MIN_NODES_PER_WAVELENGTH:
        return None
    b = scene.beam
    needed = math.ceil(b.elements * MIN_NODES_PER_WAVELENGTH / nodes)
    return (f"the mesh has {nodes:.2g} nodes per flexural wavelength at the band's top f_max = "
            f"{band_frequency(scene):.4g} Hz (fewer than {MIN_NODES_PER_WAVELENGTH:g}): the band's bending is not "
            f"resolved; use beam.elements >= {needed}, a higher beam.element_degree, or a narrower modal.f_star_max")
