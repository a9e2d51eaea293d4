"""Gravity load F_G, Eq. (52): a constant generalised force with potential -F_G . q."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from fenics_drill.model.forces.protocol import ForceEvaluation


class Gravity:
    """The self-weight of the string along -z (assembled once by :mod:`fenics_drill.model.operators`)."""

    name: ClassVar[str] = "gravity"
    switch: ClassVar[str] = "gravity"
    conservative: ClassVar[bool] = True
    recorded: ClassVar[dict] = {}

    def __init__(self, load: np.ndarray):
        self.load = load  # [Phi]^T F_G

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "Gravity":
        return cls(space.project(operators.gravity))

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> ForceEvaluation:
        return ForceEvaluation(self.load, -float(self.load @ q), {})

    def tangent(self, evaluation: ForceEvaluation, c_u: float, c_v: float):
        return None

    def record(self, evaluation: ForceEvaluation) -> dict[str, float]:
        return {}
