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

from fenics_drill.model.string_sections import string_sections

#: Fewest displacement nodes (elements x degree) per flexural wavelength at f_max for the band to be carried
#: within about 10 %.
MIN_NODES_PER_WAVELENGTH = 8.0


def band_frequency(scene) -> float:
    """f_max = f*_max c_L / L, the highest frequency of the band B [Hz]."""
    p = scene.beam_properties
    return scene.modal.f_star_max * p.longitudinal_wave_speed / p.length


def flexural_wavelength(properties, frequency_hz: float) -> float:
    """Wavelength [m] of a bending wave of the pipe at ``frequency_hz``: 2 pi / k with k^4 = rho A omega^2 / E I
    (Euler-Bernoulli; shear shortens it a little at high frequency)."""
    s = properties.section
    omega = 2.0 * math.pi * frequency_hz
    k = (properties.density * s.area * omega**2 / (properties.young_modulus * s.I4)) ** 0.25
    return 2.0 * math.pi / k


def nodes_per_wavelength(scene) -> float:
    """Displacement nodes of the mesh (elements x degree over the length) per flexural wavelength at f_max, in the
    section whose wavelength is the shortest."""
    b = scene.beam
    spacing = scene.string_length / (b.elements * b.element_degree)
    p, f_max = scene.beam_properties, band_frequency(scene)
    pipes = [replace(p, outer_radius=s.outer_radius, inner_radius=s.inner_radius, young_modulus=s.young_modulus,
                     density=s.mass_per_length / (math.pi * (s.outer_radius**2 - s.inner_radius**2)))
             for s in string_sections(scene)] if scene.string.sections else [p]
    return min(flexural_wavelength(pipe, f_max) for pipe in pipes) / spacing


def mesh_advice(scene) -> str | None:
    """Why the mesh is too coarse for the band, or None."""
    nodes = nodes_per_wavelength(scene)
    if nodes >= MIN_NODES_PER_WAVELENGTH:
        return None
    b = scene.beam
    needed = math.ceil(b.elements * MIN_NODES_PER_WAVELENGTH / nodes)
    return (f"the mesh has {nodes:.2g} nodes per flexural wavelength at the band's top f_max = "
            f"{band_frequency(scene):.4g} Hz (fewer than {MIN_NODES_PER_WAVELENGTH:g}): the band's bending is not "
            f"resolved; use beam.elements >= {needed}, a higher beam.element_degree, or a narrower modal.f_star_max")
