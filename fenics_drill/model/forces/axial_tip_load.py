"""A constant axial compression P at the bit (x = L): the preload of a critical-speed analysis.

Not a [model] switch of the dynamics (the bit-rock law (20) gives the bit force of a run); the
Campbell study adds it to a model to linearise the string about its steady weight on bit.
Generalised force -P [Phi]^T e_u(L), potential P u(L).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from fenics_drill.model.discretization import U, BeamDiscretization
from fenics_drill.model.forces.gravity import Gravity


class AxialTipLoad(Gravity):
    """Compression ``force`` [N] (> 0 pushes the bit towards x = 0) at x = L: a constant load like
    gravity, whose evaluation, tangent and record it shares."""

    name: ClassVar[str] = "axial_tip_load"
    switch: ClassVar[str] = ""

    def __init__(self, disc: BeamDiscretization, space, force: float):
        self.force = force
        at_bit = np.zeros(disc.ndofs)
        at_bit[disc.end_dof(U, 1)] = -force
        super().__init__(space.project(at_bit))
