"""Forces applied at points or vertices of the string, one module per force, each law beside its
derivative; all implement :class:`~fenics_drill.model.forces.protocol.PointForce`.

:data:`FORCES` is the registry: the model builds, in this order, every force whose
[model] switch (its ``switch`` attribute) the scene turns on.  Adding a force law is one module here, one
entry in :data:`FORCES` and one scene section (docs/architecture.md).
"""

from fenics_drill.model.forces.axial_torsional_wall import AxialTorsionalWall
from fenics_drill.model.forces.bit_rock import BitRock
from fenics_drill.model.forces.cutting_bit import CuttingBit
from fenics_drill.model.forces.gravity import Gravity
from fenics_drill.model.forces.protocol import ForceEvaluation, PointForce
from fenics_drill.model.forces.wall_contact import WallContact

#: Every force the model knows, in the order their generalised forces are summed.
FORCES = (Gravity, WallContact, AxialTorsionalWall, BitRock, CuttingBit)


def _chosen(force, scene) -> bool:
    """Whether the scene switches ``force`` on: its [model] switch, and for alternative laws of one
    force (the bit-rock laws) the law the scene picks (the optional ``chosen`` classmethod)."""
    return getattr(scene.model, force.switch) and (not hasattr(force, "chosen") or force.chosen(scene))


def build_forces(scene, disc, space, operators) -> list:
    """The forces a scene switches on, built in the solution space."""
    return [force.from_scene(scene, disc, space, operators) for force in FORCES if _chosen(force, scene)]


def recorded_variables() -> dict[str, tuple[str, str]]:
    """name -> (units, long name) of every per-step quantity some force records."""
    return {name: meta for force in FORCES for name, meta in force.recorded.items()}


__all__ = ["FORCES", "AxialTorsionalWall", "BitRock", "CuttingBit", "ForceEvaluation", "Gravity", "PointForce", "WallContact", "build_forces",
           "recorded_variables"]
