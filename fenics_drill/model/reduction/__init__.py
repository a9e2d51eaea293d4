"""The reduced model (Eqs. 62-66): modes and the basis rule, solution spaces, the basis guard and its
enrichment, hyper-reduction of the internal forces (ECSW) and the damping of the basis above the band.

May import :mod:`fenics_drill.model.kernels` and the string's physics (discretisation, operators, internal
force, forces); never :mod:`fenics_drill.model.drillstring`, which assembles everything."""
