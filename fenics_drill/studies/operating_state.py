"""The static state a string's modes are linearised about: the string at rest on the wall under gravity (Section
6.4), compressed at the bit by a weight on bit, solved in the full order; and its tangent stiffness there.

The state is shared by the critical-speed analysis (``fenics-drill campbell``, which linearises the energies about
it) and the modal analysis of a string in a well (``fenics-drill modal``).  The modal analysis takes the prestressed
string: the stiffness (46), the initial-stress stiffness of the state's axial force (the hanging tension and the
weight on bit: :func:`~fenics_drill.forms.linear.geometric_stiffness_form`), and the wall's normal springs at the
vertices resting on it (with the pendulum term F_n / r of a preloaded radial spring).  The friction has no memory
at a static state, so no friction spring joins it: the modes are those of a string free to slide.  The full tangent
of the Green-Lagrange energy would also stiffen the axial and torsional waves with the strain (a St-Venant-Kirchhoff
material's, not steel's: +6e-4 to +8e-4 on the frequencies of a 1500 m string hanging in air), so it is not used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fenics_drill.model.discretization import DRIVE
from fenics_drill.model.drillstring import DrillstringModel
from fenics_drill.model.forces.axial_tip_load import AxialTipLoad
from fenics_drill.model.forces.wall_contact import WallContact
from fenics_drill.model.operators import assemble_geometric_stiffness
from fenics_drill.model.reduction.modes import solve_modes
from fenics_drill.model.reduction.spaces import FullSpace
from fenics_drill.solvers.static import LoadNotCarried, StaticFailure, solve_static
from fenics_drill.studies.torque_drag import buckling_on_bottom


@dataclass
class OperatingState:
    """The full-space displacement of the static state, what it holds (``about``: 'state', Newton iterations,
    vertices on the wall, the weight on bit) and the wall's law at it (None when no vertex rests on the wall)."""

    displacement: np.ndarray
    about: dict
    on_the_wall: bool


def operating_state(scene, disc, operators, weight_on_bit: float, on_wall: bool) -> OperatingState:
    """The static state under gravity and the wall (``on_wall``, as ``model.gravity`` and ``model.contact`` allow)
    with the compression ``weight_on_bit`` [N] at the bit; the straight string when nothing loads it.  The drive
    holds the top (u and theta_x at x = 0), the bit is free axially (the weight on bit is a load, not a support)."""
    switches = {"gravity": on_wall and scene.model.gravity, "contact": on_wall and scene.model.contact,
                "bit_rock": False}
    at_rest = scene.with_changes(model=switches, drive={"mode": "velocity"})  # at rest the drive holds the top
    model = DrillstringModel(at_rest, disc, FullSpace(disc), operators)
    if weight_on_bit != 0:
        model = model.with_added_force(AxialTipLoad(disc, model.space, weight_on_bit))
    state = "static" if on_wall else "straight"
    if not model.forces:
        return OperatingState(np.zeros(disc.ndofs), {"state": state, "newton_iterations": 0,
                                                     "weight_on_bit_N": weight_on_bit}, False)
    equilibrium = solve_pressed(model, scene, weight_on_bit)
    displacement = model.space.expand(equilibrium.q)
    wall = model.force("wall")
    in_contact = int(wall.evaluate(equilibrium.q, np.zeros_like(equilibrium.q)).in_contact.sum()) if wall else 0
    return OperatingState(displacement, {"state": state, "newton_iterations": equilibrium.iterations,
                                         "vertices_on_the_wall": in_contact, "weight_on_bit_N": weight_on_bit},
                          in_contact > 0)


def solve_pressed(model: DrillstringModel, scene, weight_on_bit: float, initial=None):
    """:func:`~fenics_drill.solvers.static.solve_static` of ``model`` with its bit pressed at ``weight_on_bit`` [N]; a
    weight it cannot carry is refused with what the soft string says of the string at that weight (where it is
    buckled)."""
    try:
        return solve_static(model, initial=initial)
    except LoadNotCarried as failure:
        raise StaticFailure(f"{failure}; {buckling_on_bottom(scene, weight_on_bit)}") from None


def loaded_stiffness(scene, disc, operators, state: OperatingState) -> sp.csr_matrix:
    """The stiffness of the prestressed string at ``state`` on every dof of the mixed space (SciPy CSR, free-free):
    K (46), the initial-stress stiffness of the state's axial force and the wall's normal springs (module doc)."""
    stiffness = operators.stiffness + assemble_geometric_stiffness(disc, state.displacement)
    if not state.on_the_wall:
        return stiffness.tocsr()
    space = FullSpace(disc)
    wall = WallContact.from_scene(scene, disc, space, operators)
    q = space.project(state.displacement)
    springs = sp.csr_matrix(wall.tangent(wall.evaluate(q, np.zeros_like(q), with_tangent=True), 1.0, 0.0))
    embed = sp.csr_matrix((np.ones(space.size), (space.free, np.arange(space.size))), shape=(disc.ndofs, space.size))
    return (stiffness - embed @ springs @ embed.T).tocsr()


#: A mode of the drive-held string whose omega^2 is below (2 pi f* c_L / L)^2 at this f* has lost its stiffness: the
#: string is buckled (round-off leaves the free-free string's rigid modes near f* = 1e-5; the drive holds them).
BUCKLED_F_STAR = 1e-4


#: The modes without stiffness a report lists (the lowest; their count is given beside).
REPORTED_MODES = 4


def buckled_modes(held, length: float, wave_speed: float) -> list[dict]:
    """The modes of the drive-held spectrum whose stiffness vanishes or is negative (omega^2 <= (2 pi BUCKLED_F_STAR
    c_L / L)^2): their index, kind, omega^2 [1/s^2] and where each bends most (x of its largest lateral
    displacement, the measured depth in a well)."""
    if held.eigenvalues is None:
        return []
    limit = (2.0 * np.pi * BUCKLED_F_STAR * wave_speed / length) ** 2
    return [{"index": int(i), "kind": held.kinds[i], "omega_squared": float(held.eigenvalues[i]),
             "largest_lateral_displacement_at_m": float(held.lateral_peak_x[i])}
            for i in np.flatnonzero(held.eigenvalues <= limit)]


def unstable_modes(scene, model: DrillstringModel, q: np.ndarray) -> list[dict]:
    """The modes of the drive-held string that have no positive stiffness about the static state ``q`` of ``model``
    (:func:`buckled_modes` of the prestressed tangent, :func:`loaded_stiffness`; the band up to
    STABILITY_F_STAR): none where the state is stable."""
    disc = model.disc
    displacement = model.space.expand(q)
    wall = model.force("wall")
    on_wall = bool(wall is not None and wall.evaluate(q, np.zeros_like(q)).in_contact.any())
    state = OperatingState(displacement, {}, on_wall)
    stiffness = loaded_stiffness(scene, disc, model.operators, state)
    held = solve_modes(disc, STABILITY_F_STAR, model.operators.mass, held=DRIVE, vectors=False, stiffness=stiffness)
    p = disc.properties
    return buckled_modes(held, p.length, p.longitudinal_wave_speed)


#: The band in which a static state's stability is judged (its lowest modes): f* = f L / c_L <= this.
STABILITY_F_STAR = 0.2


def linearised_state(scene) -> str:
    """'static' or 'unloaded': what ``modal.state`` chooses for this scene ('auto': static in a well)."""
    if scene.modal.state != "auto":
        return scene.modal.state
    return "static" if (scene.well.survey or scene.well.md) else "unloaded"


def prestressed_modes(scene):
    """What the reduced basis's modes are solved with: None (the stiffness (46)) for an unloaded
    ``modal.state``, else ``(disc, operators) -> K`` of the string prestressed by its static state
    (:func:`loaded_stiffness` about :func:`operating_state` with the scene's ``modal_weight_on_bit``)."""
    if linearised_state(scene) == "unloaded":
        return None

    def stiffness(disc, operators):
        state = operating_state(scene, disc, operators, scene.modal_weight_on_bit, on_wall=True)
        return loaded_stiffness(scene, disc, operators, state)

    return stiffness
