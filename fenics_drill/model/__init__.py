"""The model layer (Eqs. 43-76): the string and its forces, the reduced model, and the compiled kernels both
run on.  Nothing here knows about time stepping, files or studies.

Three concerns, from the bottom up (``tests/test_architecture.py`` holds them to this order):

- :mod:`~fenics_drill.model.kernels`: compiled numerics (Numba, FFCx's element kernels, banded solves);
- the string's physics, in this package: discretisation and supports, linear operators, internal force,
  the point forces (:mod:`~fenics_drill.model.forces`), the top drive and memory estimates; the well from its
  survey (:mod:`~fenics_drill.model.well`), the string's sections (:mod:`~fenics_drill.model.string_sections`) and
  the soft-string torque-and-drag model on them (:mod:`~fenics_drill.model.soft_string`);
- :mod:`~fenics_drill.model.reduction`: modes, solution spaces, the basis guard, hyper-reduction;

and on top of them :mod:`~fenics_drill.model.drillstring` (the assembled model: residual, tangent, drive
constraints), :mod:`~fenics_drill.model.rotating_modes` (the string linearised about a steady spin) and
:mod:`~fenics_drill.model.axial_torsional_string` (the string's u and theta_x alone, one band for stick-slip).
"""
