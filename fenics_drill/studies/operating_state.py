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

from fenics_drill.model.discretization import DRIVE, THETA_X, THETA_Y, THETA_Z, U, V, W
from fenics_drill.model.drillstring import DrillstringModel
from fenics_drill.model.forces.axial_tip_load import AxialTipLoad
from fenics_drill.model.forces.wall_contact import WallContact
from fenics_drill.model.kernels.banded_saddle import as_csr
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
    springs = sp.csr_matrix(as_csr(wall.tangent(wall.evaluate(q, np.zeros_like(q), with_tangent=True), 1.0, 0.0)))
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


def unstable_modes(scene, disc, operators, state: OperatingState) -> list[dict]:
    """The modes of the drive-held string that have no positive stiffness about ``state``: none where it is stable.

    Whether there is one is settled by the sign of the lowest eigenvalue of the prestressed tangent (:func:
    `loaded_stiffness`) on the drive-held dofs (Sylvester: the generalised problem with the mass has as many negative
    eigenvalues), a banded symmetric eigenvalue problem in the dofs' order along the string; the modes themselves
    are the band's lowest modes (:func:`buckled_modes` up to STABILITY_F_STAR), or, where the compression is so far
    beyond the buckling load that their frequencies lie below the band's shift, the lowest eigenvector itself."""
    stiffness = loaded_stiffness(scene, disc, operators, state)
    held = [disc.end_dof(field, end) for field, end in DRIVE]
    free = np.setdiff1d(np.arange(disc.ndofs), np.union1d(disc.support_dofs, held))
    lowest, vector = lowest_eigenpair(stiffness[free][:, free], disc.dof_coordinates[free])
    if lowest >= -BUCKLING_ROUND_OFF * float(np.abs(stiffness.diagonal()).max()):
        return []
    spectrum = solve_modes(disc, STABILITY_F_STAR, operators.mass, held=DRIVE, vectors=False, stiffness=stiffness)
    p = disc.properties
    found = buckled_modes(spectrum, p.length, p.longitudinal_wave_speed)
    if found:
        return found
    fields = disc.field_of_dof[free]
    lateral = np.isin(fields, (V, W))
    share = np.array([np.sum(vector[fields == f] ** 2) for f in range(6)])
    kind = "flexural" if share[[V, W, THETA_Y, THETA_Z]].sum() >= 0.5 * share.sum() else \
        ("axial" if share[U] >= share[THETA_X] else "torsional")
    where = float(disc.dof_coordinates[free][lateral][np.argmax(np.abs(vector[lateral]))]) if lateral.any() else np.nan
    return [{"index": 0, "kind": kind, "omega_squared": None, "stiffness_eigenvalue": float(lowest),
             "largest_lateral_displacement_at_m": where}]


#: The tangent's lowest eigenvalue below -this share of its largest diagonal entry is negative beyond round-off.
BUCKLING_ROUND_OFF = 1e-10


def lowest_eigenpair(matrix: sp.spmatrix, position: np.ndarray) -> tuple[float, np.ndarray]:
    """The lowest eigenvalue of the symmetric ``matrix`` and its eigenvector, from its band once the dofs are ordered
    by ``position`` along the string (LAPACK's banded eigensolver for the first eigenvalue alone)."""
    from scipy.linalg import eig_banded

    order = np.argsort(position, kind="stable")
    ordered = sp.coo_matrix(matrix.tocsr()[order][:, order])
    ordered.sum_duplicates()
    lower = ordered.row >= ordered.col
    width = int(np.max(ordered.row[lower] - ordered.col[lower])) if lower.any() else 0
    band = np.zeros((width + 1, matrix.shape[0]))
    band[ordered.row[lower] - ordered.col[lower], ordered.col[lower]] = ordered.data[lower]
    values, vectors = eig_banded(band, lower=True, select="i", select_range=(0, 0))
    vector = np.empty(matrix.shape[0])
    vector[order] = vectors[:, 0]
    return float(values[0]), vector


def state_of(model: DrillstringModel, q: np.ndarray) -> OperatingState:
    """The static state ``q`` of ``model`` as an OperatingState (on the wall where a vertex rests on it)."""
    wall = model.force("wall")
    on_wall = bool(wall is not None and wall.evaluate(q, np.zeros_like(q)).in_contact.any())
    return OperatingState(model.space.expand(q), {}, on_wall)


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
