"""The string's axial and torsional fields alone, as one narrow band: what a stick-slip study steps.

With ``model.lateral_length = 0`` the string has no lateral fields: it lies on the well's axis, and its energies
(44)-(46), (52) restricted to u and theta_x are linear in them but for the Green-Lagrange axial strain's second-order
terms ((u'^2 + r^2 theta_x'^2) / 2 and their products), which this band leaves out: against the linear terms they are
of the size of the strains u' and r theta_x' themselves (steel's yield strain is 1e-3).  The finite-element run of the
same string keeps them (:class:`~fenics_drill.model.internal_force.LateralZoneInternalForce`'s restricted forms).
:func:`axial_torsional_string` assembles M, C and K from those forms on the scene's own mesh and sections,
keeps the rows and columns of u and theta_x, and orders them along the string (u before theta_x at one x), which
makes them a band of half-width 3-4 for quadratic u and linear theta_x.  The wall acts through its Coulomb friction
at each vertex, pressed by the soft string's normal force (:func:`~fenics_drill.model.forces.axial_torsional_wall.
vertex_normal_forces`), and the top drive's inertia sits on theta_x(0) where a controller drives it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fenics_drill.model.discretization import THETA_X, U, BeamDiscretization
from fenics_drill.model.forces.axial_torsional_wall import vertex_normal_forces
from fenics_drill.model.operators import assemble_linear


@dataclass(frozen=True)
class AxialTorsionalString:
    """M, C, K of the string's (u, theta_x) in band storage (``band[i, j - i + half_width] = A[i, j]``), its gravity
    load, and where its ends and wall vertices are among the band's dofs.  SI units."""

    x: np.ndarray  # measured depth of each dof [m]
    angle: np.ndarray  # True where the dof is theta_x
    half_width: int
    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    gravity: np.ndarray  # F_G (52) on the dofs [N]
    top: tuple[int, int]  # (u(0), theta_x(0))
    bit: tuple[int, int]  # (u(L), theta_x(L))
    wall_dofs: np.ndarray  # (vertices, 2): u and theta_x of each vertex
    wall_normal: np.ndarray  # the soft string's normal force at each vertex [N]
    wall_arm: np.ndarray  # the contact radius at each vertex [m]
    polar_inertia_at_top: float  # rho I_p of the top section [kg m]
    torsional_wave_speed_at_top: float  # [m/s]
    axial_wave_speed: float  # the fastest section's sqrt(E A / rho A) [m/s]
    length: float

    @property
    def size(self) -> int:
        return self.x.size

    def dense(self, band: np.ndarray) -> np.ndarray:
        """The band as a dense matrix (for checks)."""
        n, w = self.size, self.half_width
        out = np.zeros((n, n))
        for i in range(n):
            for j in range(max(0, i - w), min(n, i + w + 1)):
                out[i, j] = band[i, j - i + w]
        return out


def wall_normal_forces(scene, vertex_x: np.ndarray) -> np.ndarray:
    """|N_i| [N] at each vertex for the scene's operation (none without ``model.contact``)."""
    if not scene.model.contact:
        return np.zeros(len(vertex_x))
    return np.abs(vertex_normal_forces(scene, vertex_x))


def pressed_for(string: AxialTorsionalString, scene) -> AxialTorsionalString:
    """The same string pressed on the wall as ``scene``'s operation presses it (another weight on bit)."""
    return replace(string, wall_normal=wall_normal_forces(scene, string.x[string.wall_dofs[:, 0]]))


def _band(matrix, order: np.ndarray, half_width: int) -> np.ndarray:
    coo = matrix[order][:, order].tocoo()
    kept = coo.data != 0.0  # the assembled pattern stores the fields' couplings that vanish here as zeros
    band = np.zeros((order.size, 2 * half_width + 1))
    np.add.at(band, (coo.row[kept], coo.col[kept] - coo.row[kept] + half_width), coo.data[kept])
    return band


def axial_torsional_string(scene) -> AxialTorsionalString:
    """The scene's string with only u and theta_x (module doc); the scene's ``model.lateral_length`` is taken as 0."""
    scene = scene.with_changes(model={"lateral_length": 0.0})
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    dofs = np.concatenate([disc.field_dofs[U], disc.field_dofs[THETA_X]])
    x = disc.dof_coordinates[dofs]
    angle = np.concatenate([np.zeros(disc.field_dofs[U].size, bool), np.ones(disc.field_dofs[THETA_X].size, bool)])
    order = np.lexsort((angle, x))
    dofs, x, angle = dofs[order], x[order], angle[order]
    position = np.full(disc.ndofs, -1)
    position[dofs] = np.arange(dofs.size)
    pattern = (abs(operators.mass) + abs(operators.damping) + abs(operators.stiffness))[dofs][:, dofs].tocoo()
    pattern.eliminate_zeros()
    half_width = int(np.max(np.abs(pattern.row - pattern.col)))
    vertex = np.stack([position[disc.vertex_dofs(U)], position[disc.vertex_dofs(THETA_X)]], axis=1)
    contact_radius, _ = disc.vertex_radii(scene.borehole.radius)
    cells = disc.element_properties  # one value, or one per element along x (a string of sections)
    polar = float(np.atleast_1d(cells.polar_inertia_per_length)[0])
    wave = math.sqrt(float(np.atleast_1d(cells.torsional_rigidity)[0]) / polar)
    axial = float(np.max(np.sqrt(cells.young_modulus * np.atleast_1d(cells.stiffness_section.area)
                                 / (cells.density * np.atleast_1d(cells.section.area)))))
    return AxialTorsionalString(
        x=x, angle=angle, half_width=half_width, mass=_band(operators.mass, dofs, half_width),
        damping=_band(operators.damping, dofs, half_width), stiffness=_band(operators.stiffness, dofs, half_width),
        gravity=operators.gravity[dofs],
        top=(int(position[disc.end_dof(U, 0)]), int(position[disc.end_dof(THETA_X, 0)])),
        bit=(int(position[disc.end_dof(U, 1)]), int(position[disc.end_dof(THETA_X, 1)])),
        wall_dofs=vertex, wall_normal=wall_normal_forces(scene, disc.vertex_x),
        wall_arm=np.asarray(contact_radius, float),
        polar_inertia_at_top=polar, torsional_wave_speed_at_top=wave, axial_wave_speed=axial,
        length=float(disc.properties.length))


def mesh_viscosity(string: AxialTorsionalString, zeta: float, axial: bool = False) -> np.ndarray:
    """The damping band S K S, S = diag(sqrt(zeta h_i / (2 c))) on theta_x and 0 on u: a Kelvin-Voigt viscosity
    zeta h c / 2 on the torsional wave alone, h_i the element length at dof i (the mean of a vertex's two) and c the
    top section's torsional wave speed (``axial``: on the axial wave too, at the fastest section's axial speed, which
    benchmarks/stick_slip_mesh_convergence.py measures).  Its damping ratio at a torsional mode of circular frequency
    omega is zeta h omega / (4 c): of order zeta at the mesh's shortest waves (omega ~ 2 c / h), zeta pi h / (8 L) at the first
    torsional mode of a string of length L held at its top; zeta = 1 is the numerical viscosity of first-order
    upwinding at a Courant number of 0.  The axial wave is left sharp: smoothing it removes the bit's stick on a calm
    cycle the exact model sticks on (docs/guide/stick_slip_maps.md)."""
    vertices = np.sort(string.x[string.wall_dofs[:, 0]])
    lengths = np.diff(vertices)
    k = np.clip(np.searchsorted(vertices, string.x), 0, vertices.size - 1)
    at_vertex = np.isclose(vertices[k], string.x, rtol=0.0, atol=1e-9 * string.length)
    before = lengths[np.clip(k - 1, 0, lengths.size - 1)]
    after = lengths[np.clip(k, 0, lengths.size - 1)]
    first, last = k == 0, k == vertices.size - 1
    h = np.where(at_vertex, np.where(first, after, np.where(last, before, 0.5 * (before + after))), before)
    speed = np.where(string.angle, string.torsional_wave_speed_at_top, string.axial_wave_speed)
    scale = np.where(string.angle | axial, np.sqrt(zeta * h / (2.0 * speed)), 0.0)
    w, n = string.half_width, string.size
    band = np.zeros_like(string.stiffness)
    for i in range(n):
        for j in range(max(0, i - w), min(n, i + w + 1)):
            band[i, j - i + w] = scale[i] * string.stiffness[i, j - i + w] * scale[j]
    return band
