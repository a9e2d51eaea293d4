"""The model layer: discretisation, operators, modes and spaces, the internal force, the point forces,
and the drillstring model that assembles them (Eqs. 43-76).  Nothing here knows about time stepping,
files or studies."""
