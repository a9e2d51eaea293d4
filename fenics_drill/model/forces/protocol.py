"""The protocol every force applied at points or vertices implements (gravity, wall impacts, bit-rock).

A force is built from a scene (:meth:`PointForce.from_scene`), evaluated at a state
(q, qd) into a :class:`ForceEvaluation`, and differentiated for Newton.  The model
sums the generalised forces, the energy budget books the work of each non-conservative
law under its name and each force's potential, and the time-series recorder asks
each force for its per-step quantities.  A pointwise law lives in the module of its
force, beside its derivative.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Protocol

import numpy as np


@dataclass
class ForceEvaluation:
    """What every force returns at one state (law-specific fields in subclasses)."""

    generalised: np.ndarray  # [Phi]^T f: the generalised force on the reduced unknowns
    potential: float  # stored energy of the conservative part [J]
    #: the non-conservative part of ``generalised``, law by law (the energy budget books the work of each
    #: under its name: negative for a law that dissipates, positive for one that injects energy)
    laws: dict[str, np.ndarray]


class PointForce(Protocol):
    """A force law acting at points of the string, projected on the solution space."""

    #: Key of the force in the energy budget (``dissipated_by``) and in :attr:`DrillstringModel.forces`.
    name: ClassVar[str]
    #: The [model] key that switches it on (``model.contact`` for the wall).
    switch: ClassVar[str]
    #: Whether the force does only conservative work (its potential carries all of it).
    conservative: ClassVar[bool]
    #: Per-step variables it records: name -> (units, long name); written 0 when the force is off.
    recorded: ClassVar[dict[str, tuple[str, str]]]

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "PointForce":
        """Build the force of a scene in a solution space."""

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> ForceEvaluation:
        """The force at (q, qd); with ``with_tangent`` also what :meth:`tangent` needs."""

    def tangent(self, evaluation: ForceEvaluation, c_u: float, c_v: float):
        """c_u df/dq + c_v df/dqd at the evaluated state, in the space's matrix kind (None if zero)."""

    def record(self, evaluation: ForceEvaluation) -> dict[str, float]:
        """The values of :attr:`recorded` at the evaluated state."""


class ForceWithMemory(PointForce, Protocol):
    """A force whose law depends on the history of the motion (the cutting bit's delay).

    The model gives each simulation its own copy (:meth:`fresh`), starts it at the initial state
    (:meth:`begin`) and shows it every accepted step (:meth:`accept`); rejected trial steps leave
    no trace.  Alternative laws of one force also define ``chosen(scene) -> bool``."""

    def fresh(self) -> "ForceWithMemory":
        """A copy with an empty memory."""

    def begin(self, t: float, q: np.ndarray) -> None:
        """Start the memory at the initial state."""

    def accept(self, t: float, q: np.ndarray, qd: np.ndarray) -> None:
        """Remember an accepted state."""
