"""Weak forms of the horizontal drillstring model (Cunha Jr, Soize, Sampaio 2015).

Pure UFL: every function here takes UFL arguments (trial/test functions or
coefficients) and a :class:`BeamProperties` object and returns a UFL form or
expression.  No meshes, PETSc objects or I/O live in this package, so each form
can be printed, differentiated and compared on its own.

Field ordering everywhere is the paper's: ``U = (u, v, w, theta_x, theta_y, theta_z)``.
"""

from .properties import BeamProperties, SectionConstants, section_constants
from .linear import mass_form, damping_form, stiffness_form, gravity_form, geometric_stiffness_form

FIELD_NAMES = ("u", "v", "w", "theta_x", "theta_y", "theta_z")

__all__ = [
    "BeamProperties",
    "SectionConstants",
    "section_constants",
    "mass_form",
    "damping_form",
    "stiffness_form",
    "gravity_form",
    "geometric_stiffness_form",
    "FIELD_NAMES",
]
