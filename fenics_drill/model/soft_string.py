"""The soft-string torque-and-drag model (Johancsik, Friesen & Dawson 1984), in vector form along a 3D well.

The string is a cable that lies on the wall: no bending stiffness, so the wall carries, element by element, what
the tension, the weight and the turn of the axis leave unbalanced.  Each element of length ds, between tangents
a_t (top) and a_b (bottom), with buoyed weight W = w ds (-z) and effective tensions F_t, F_b, is in equilibrium:

    N + f a = F_t a_t - F_b a_b - W,       a = (a_t + a_b) / |a_t + a_b|,

N perpendicular to the axis (the wall's contact force), f along it: the friction, mu |N| against the slip of the
contact point, shared between the axis and the circumference by the slip's components (the combined-velocity
friction of Aadnoy et al.): f = -mu |N| V / |v|, the torque dT = mu |N| r_c (r_c Omega) / |v|, |v| = sqrt(V^2 +
(r_c Omega)^2), V the axial speed (down-hole > 0), Omega the rotation speed, r_c the contact radius.  In a circular
arc this gives the capstan law F_t / F_b = (1 + mu tan(beta/2)) / (1 - mu tan(beta/2)) per element, exp(mu beta) as
the elements shrink (second order); in a straight hole N = w ds sin I and F_t = F_b + w ds (cos I -+ mu sin I).
Tensions are effective (Lubinski): buoyancy enters through the buoyed weight, and buckling is judged on them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from fenics_drill.model.kernels.compiled import kernel
from fenics_drill.model.string_sections import StringSection, section_at
from fenics_drill.model.well import Well


@dataclass(frozen=True)
class Operation:
    """What the string does: its axial speed (down-hole > 0) [m/s] and rotation speed [rad/s], and the force
    (tension > 0, so -WOB on bottom) [N] and torque [N m] at the bit."""

    name: str
    axial_velocity: float
    rotation_speed: float
    bit_force: float
    bit_torque: float


def operations(scene, names=None) -> list[Operation]:
    """The operations ``names`` (default: those ``torque_drag.operations`` names), with the scene's set points
    (:attr:`~fenics_drill.scene.Scene.set_points`: the drive's, or the study's own) and torque on bit.  Sliding drills
    with a downhole motor: the bit's weight and the motor's reactive torque, carried by a string that does not turn."""
    td, sp = scene.torque_drag, scene.set_points
    table = {
        "rotating_on_bottom": Operation("rotating_on_bottom", sp["rate_of_penetration"], sp["rotation_speed"],
                                        -sp["weight_on_bit"], td.torque_on_bit),
        "rotating_off_bottom": Operation("rotating_off_bottom", 0.0, sp["rotation_speed"], 0.0, 0.0),
        "sliding": Operation("sliding", sp["rate_of_penetration"], 0.0, -sp["weight_on_bit"], td.torque_on_bit),
        "tripping_in": Operation("tripping_in", td.trip_speed, 0.0, 0.0, 0.0),
        "tripping_out": Operation("tripping_out", -td.trip_speed, 0.0, 0.0, 0.0),
    }
    return [table[name] for name in (td.operations if names is None else names)]


@dataclass(frozen=True)
class StringMesh:
    """The string's nodes along measured depth (0 at the surface, the bit last) and each element's properties."""

    md: np.ndarray  # nodes [m]
    tangent: np.ndarray  # unit, down-hole, at the nodes
    weight: np.ndarray  # buoyed weight per length of each element [N/m]
    contact_radius: np.ndarray  # [m]
    friction: np.ndarray  # the hole's coefficient [-]
    section: np.ndarray  # index into the string's sections


def string_mesh(well: Well, sections: list[StringSection], element_length: float, weights: np.ndarray,
                friction_cased: float, friction_open: float) -> StringMesh:
    """Nodes at most ``element_length`` apart that fall on every survey station, section end and hole-section
    bottom, so that each element has one set of properties and lies on one arc.  ``weights``: each section's
    buoyed weight per length."""
    length = sections[-1].bottom
    breaks = {0.0, length, *(s.bottom for s in sections), *well.trajectory.md, *well.hole.bottoms}
    breaks = np.array(sorted(b for b in breaks if 0.0 <= b <= length))
    nodes = [breaks[:1]]
    for a, b in zip(breaks[:-1], breaks[1:]):
        count = max(1, math.ceil((b - a) / element_length - 1e-9))
        nodes.append(np.linspace(a, b, count + 1)[1:])
    md = np.concatenate(nodes)
    middle = 0.5 * (md[1:] + md[:-1])
    index = section_at(sections, middle)
    hole = well.hole.at(middle)
    return StringMesh(md=md, tangent=well.trajectory.tangents(md), weight=np.asarray(weights)[index],
                      contact_radius=np.array([sections[k].contact_radius for k in index]),
                      friction=np.where(well.hole.cased[hole], friction_cased, friction_open), section=index)


def soft_string(mesh: StringMesh, operation: Operation, iterations: int = 50) -> dict[str, np.ndarray]:
    """Effective tension [N] and torque [N m] at the nodes, from the bit up, and the wall's contact force per
    length [N/m] on each element with its direction (a unit vector, north-east-up; zero where the wall carries
    nothing), for one operation."""
    loads = soft_string_batch(mesh, [operation], mesh.friction[None, :], iterations)
    return {name: values[0] for name, values in loads.items()}


def soft_string_batch(mesh: StringMesh, batch: list[Operation], friction: np.ndarray, iterations: int = 50,
                      tangents: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """:func:`soft_string` of the operations ``batch`` at once, the k-th with the friction coefficients
    ``friction[k]`` on the elements (rows of a (B, elements) array) and, where ``tangents`` (B, nodes, 3) is given,
    its own axis tangents at the mesh's nodes (a perturbed survey): each result with a first axis over the batch.
    One compiled pass along the string (:func:`_soft_string_pass`), what a broomstick chart or a Monte Carlo of
    friction factors needs (thousands of operations)."""
    friction = np.ascontiguousarray(np.broadcast_to(np.asarray(friction, dtype=float),
                                                    (len(batch), mesh.md.size - 1)))
    columns = np.array([[o.axial_velocity, o.rotation_speed, o.bit_force, o.bit_torque] for o in batch], dtype=float)
    axis = mesh.tangent[None] if tangents is None else tangents
    tension, torque, normal, direction = _soft_string_pass(
        mesh.md, np.ascontiguousarray(axis, dtype=float), np.asarray(mesh.weight, dtype=float),
        np.asarray(mesh.contact_radius, dtype=float), friction, np.ascontiguousarray(columns), iterations)
    return {"tension": tension, "torque": torque, "wall_force_per_length": normal, "wall_force_direction": direction}


@njit(cache=True)
def _lateral_load(f_t, f_b, a_t, a_b, axis, down, load):
    """The element's load across its axis, f_t a_t - f_b a_b minus its weight (``down`` along -z), into ``load``;
    returns its magnitude, the wall's force on the element."""
    for i in range(3):
        load[i] = f_t * a_t[i] - f_b * a_b[i]
    load[2] -= down
    projected = load[0] * axis[0] + load[1] * axis[1] + load[2] * axis[2]
    for i in range(3):
        load[i] -= projected * axis[i]
    return math.sqrt(load[0] ** 2 + load[1] ** 2 + load[2] ** 2)


@kernel
def _soft_string_pass(md, tangents, weight, radius, friction, operations, iterations):
    """The element-by-element equilibrium of the module doc from the bit up, for each operation (rows of
    ``operations``: axial velocity, rotation speed, bit force, bit torque) with its friction coefficients and its
    axis' tangents (``tangents[b]``, or ``tangents[0]`` for all): the tension at the element's top by a fixed point on
    the wall force it sets (converged to 1e-12)."""
    batch, n = operations.shape[0], md.size
    tension, torque = np.empty((batch, n)), np.empty((batch, n))
    normal, direction = np.empty((batch, n - 1)), np.zeros((batch, n - 1, 3))
    axis, load = np.empty(3), np.empty(3)
    for b in range(batch):
        tangent = tangents[b if tangents.shape[0] > 1 else 0]
        velocity, spin = operations[b, 0], operations[b, 1]
        tension[b, n - 1], torque[b, n - 1] = operations[b, 2], operations[b, 3]
        for k in range(n - 2, -1, -1):
            for i in range(3):
                axis[i] = tangent[k, i] + tangent[k + 1, i]
            length = math.sqrt(axis[0] ** 2 + axis[1] ** 2 + axis[2] ** 2)
            for i in range(3):
                axis[i] /= length
            cos_half = tangent[k, 0] * axis[0] + tangent[k, 1] * axis[1] + tangent[k, 2] * axis[2]
            ds = md[k + 1] - md[k]
            down = -weight[k] * ds  # the element's weight, along -z
            along = down * axis[2]  # its component along the axis
            mu, r = friction[b, k], radius[k]
            surface = r * spin
            slip = math.hypot(velocity, surface)
            axial_share = velocity / slip if slip > 0 else 0.0
            turning_share = surface / slip if slip > 0 else 0.0
            f_b = tension[b, k + 1]
            f_t = f_b + along / cos_half
            for _ in range(iterations):
                wall = _lateral_load(f_t, f_b, tangent[k], tangent[k + 1], axis, down, load)
                updated = f_b + (along - mu * wall * axial_share) / cos_half
                converged = abs(updated - f_t) <= 1e-12 * (abs(updated) + abs(f_b) + 1.0)
                f_t = updated
                if converged:
                    break
            wall = _lateral_load(f_t, f_b, tangent[k], tangent[k + 1], axis, down, load)
            if wall > 0.0:
                for i in range(3):
                    direction[b, k, i] = load[i] / wall
            tension[b, k] = f_t
            torque[b, k] = torque[b, k + 1] + mu * wall * r * turning_share
            normal[b, k] = wall / ds
    return tension, torque, normal, direction


def stretch(mesh: StringMesh, sections: list[StringSection], tension: np.ndarray, depth: np.ndarray,
            gravity: float, outer_density: float, inner_density: float) -> float:
    """The string's elongation [m] under its loads in the mud: the axial strain of each element from the effective
    tension F and the hydrostatic pressures p = rho g z at its true vertical depth z (Lame's tube: the radial and hoop
    stresses sum to 2 (p_i A_i - p_o A_o) / A_s), eps = (F + (1 - 2 nu)(p_i A_i - p_o A_o)) / (E A_s), over the
    pipe body's areas.  A string hanging in one mud stretches g L^2 (rho_s - 2 rho_m (1 - nu)) / (2 E)."""
    total = 0.0
    force = 0.5 * (tension[1:] + tension[:-1])
    for k, ds in enumerate(np.diff(mesh.md)):
        section = sections[mesh.section[k]]
        outer, inner = math.pi * section.outer_radius**2, section.inner_area
        pressures = gravity * depth[k] * (inner_density * inner - outer_density * outer)
        steel = outer - inner
        total += (force[k] + (1 - 2 * section.poisson_ratio) * pressures) * ds / (section.young_modulus * steel)
    return total
