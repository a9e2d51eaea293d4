"""The cutting bit law of Richard, Germay & Detournay (2007) at x = L (``bit_rock.law = "detournay"``).

The rock pushes the bit back with W >= 0 and resists its rotation with T, each a cutting part
proportional to the depth of cut per revolution d and a frictional-contact part of the wear flats:

    W = zeta eps a d + W_f,          W_f = sigma a l   (bit cutting, u_dot_bit > 0)
    T = eps a^2 d / 2 + mu gamma a W_f / 2

(Detournay & Defourny 1992; Richard, Germay & Detournay, J. Sound Vib. 305, 2007, Eqs. (1)-(4)).
W [N], T [N m]; on the string they act as -W on u(L) and -T on theta_x(L).

**The delay.**  Each of the n blades cuts the surface the previous blade left one blade passage
(2 pi / n of the bit's own rotation) before: d = n max(0, u_bit - S(phi_bit - 2 pi / n)), where
S(psi) = max(u_bit(psi), S(psi - 2 pi / n)) is the bottom-hole surface (:class:`CutSurface`): a
bit off the bottom cuts nothing and leaves the surface as it was.  Before t = 0 the bit is taken
as drilling steadily at the drive speeds (V0, Omega).

**Regularisation** (scene keys ``contact_velocity`` v_c, ``contact_depth`` d_c).  The contact force
is set-valued when the bit stops (0 <= W_f <= sigma a l) and vanishes off the bottom; here
W_f = sigma a l clip(u_dot_bit / v_c, 0, 1) clip(d / d_c, 0, 1), and the torque opposes the spin
through clip(omega_bit a / v_c, -1, 1).  The tangent is consistent with these piecewise-linear
forms, including d(d)/d(phi_bit) through the surface's slope.  With ``bit_rock.backward_spin = 'held'`` a damper
:data:`HELD_BACKWARD_DAMPING` adds -c_h omega to the torque while omega < 0: the bit does not turn backwards.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from fenics_drill.model.discretization import THETA_X, U, BeamDiscretization
from fenics_drill.model.forces.bit_rock import fraction_past_kink
from fenics_drill.model.forces.protocol import ForceEvaluation


@njit(cache=True, inline="always")
def clip_ramp(x: float, low: float = 0.0) -> tuple[float, float]:
    """(clip(x, low, 1), its slope)."""
    if x <= low:
        return low, 0.0
    if x >= 1.0:
        return 1.0, 0.0
    return x, 1.0


@njit(cache=True)
def surface_at(angles, surfaces, pruned, feed, angle):
    """(S(angle), dS/dangle) of the recorded surface (``angles`` increasing): linear between its entries, the
    last one beyond them, and before the first the steady drilling at ``feed`` [m/rad] (its last entry where
    older ones were dropped, ``pruned``)."""
    if angle <= angles[0]:
        if pruned:
            return surfaces[0], 0.0
        return surfaces[0] - (angles[0] - angle) * feed, feed  # steady drilling before t = 0
    k = np.searchsorted(angles, angle)
    if k >= angles.size:
        return surfaces[-1], 0.0
    slope = (surfaces[k] - surfaces[k - 1]) / (angles[k] - angles[k - 1])
    return surfaces[k - 1] + slope * (angle - angles[k - 1]), slope


#: ``bit_rock.backward_spin = 'held'``: the damping [N m s] that holds a bit the string turns backwards.  A backward
#: spin of 1 rad/s would take 1 MN m, a hundred times a long string's torque: under 10 kN m the bit creeps back at
#: 0.01 rad/s, where the distributed model of Aarsnes's published code (github.com/ulfjakob/AxialTorsionalDrillString)
#: holds it at rest.
HELD_BACKWARD_DAMPING = 1e6


def cutting_law_constants(bit) -> tuple:
    """The constants of :func:`cutting_law` from the scene's [bit_rock]: (n, zeta eps a, eps a^2 / 2, sigma a l,
    mu gamma a / 2, v_c, d_c, v_c / a, the damping that holds a backward spin)."""
    a = bit.bit_radius
    return (float(bit.blades), bit.cutting_orientation * bit.specific_energy * a, bit.specific_energy * a * a / 2.0,
            bit.contact_strength * a * bit.wear_flat_length,  # sigma a l
            bit.friction * bit.geometry_factor * a / 2.0,  # T_f = mu gamma a W_f / 2
            bit.contact_velocity, bit.contact_depth, bit.contact_velocity / a,
            HELD_BACKWARD_DAMPING if bit.backward_spin == "held" else 0.0)


@njit(cache=True)
def cutting_law(u, u_dot, omega, cut, slope, blades, zeta_eps_a, eps_a2_half, contact_force, torque_arm,
                contact_velocity, contact_depth, spin_scale, backward_damping):
    """The law (module doc) at the bit's (u, u_dot, omega) over the surface (``cut``, ``slope``) one blade passage
    behind: (d, force on u(L), torque on theta_x(L), d(force, torque)/d(u, phi) row by row, d force/d u_dot,
    d torque/d u_dot, d torque/d omega); the force's derivative by omega is 0.  ``backward_damping`` > 0 adds
    -backward_damping omega to the torque while omega < 0 (``bit_rock.backward_spin = 'held'``)."""
    cutting = u > cut
    d = blades * (u - cut) if cutting else 0.0
    dd_u, dd_phi = (blades, -blades * slope) if cutting else (0.0, 0.0)  # d(d) / d(u, phi)
    g_v, dg_v = clip_ramp(u_dot / contact_velocity, 0.0)
    g_d, dg_d = clip_ramp(d / contact_depth, 0.0)
    contact = contact_force * g_v * g_d
    contact_by_d = contact_force * g_v * dg_d / contact_depth
    d_contact_v = contact_force * dg_v / contact_velocity * g_d
    weight = zeta_eps_a * d + contact
    magnitude = eps_a2_half * d + torque_arm * contact
    s, ds = clip_ramp(omega / spin_scale, -1.0)
    weight_by_d = zeta_eps_a + contact_by_d
    torque_by_d = (eps_a2_half + torque_arm * contact_by_d) * s
    held = backward_damping if omega < 0.0 else 0.0
    return (d, -weight, -magnitude * s - held * omega, -weight_by_d * dd_u, -weight_by_d * dd_phi,
            -torque_by_d * dd_u, -torque_by_d * dd_phi, -d_contact_v, -torque_arm * d_contact_v * s,
            -magnitude * ds / spin_scale - held)


@njit(cache=True)
def cutting_law_kink(u_dot, omega, clearance, slope, du, dphi, c_v, blades, contact_velocity, contact_depth,
                     spin_scale, backward_damping):
    """The fraction of a Newton update (du, dphi) of the bit's (u, phi), which moves its rates by c_v (du, dphi),
    just past the first kink of :func:`cutting_law`'s clipped ramps along it, linearised
    (:func:`~fenics_drill.model.forces.bit_rock.fraction_past_kink`): the spin's at omega = -v_c / a, v_c / a (and 0
    with a held backward spin), the wear flats' at u_dot = 0, v_c and at the clearance u - S = 0, d_c / n (which
    moves by du - dS/dphi dphi); infinity if it crosses none."""
    step = min(fraction_past_kink(omega - -spin_scale, c_v * dphi), fraction_past_kink(omega - spin_scale, c_v * dphi))
    if backward_damping > 0:
        step = min(step, fraction_past_kink(omega - 0.0, c_v * dphi))
    for kink in (0.0, contact_velocity):
        step = min(step, fraction_past_kink(u_dot - kink, c_v * du))
    for kink in (0.0, contact_depth / blades):
        step = min(step, fraction_past_kink(clearance - kink, du - slope * dphi))
    return step


class CutSurface:
    """The bottom-hole surface S against the bit angle: the delay buffer of the cutting law.

    It keeps (phi_k, S_k) at the accepted steps where the bit turned further than ever before, and
    interpolates linearly between them; entries more than two revolutions behind are dropped.
    """

    def __init__(self, blades: int, angle: float, position: float, feed_per_radian: float):
        """Start at the bit's (angle, position) with the surface of steady drilling at ``feed_per_radian``
        (V0 / Omega) behind it."""
        self.passage = 2.0 * math.pi / blades
        self.feed = feed_per_radian
        self._angle = np.empty(1024)
        self._surface = np.empty(1024)
        self._angle[0], self._surface[0] = angle, position
        self._start, self._end = 0, 1
        self._pruned = False

    @property
    def angles(self) -> np.ndarray:
        return self._angle[self._start:self._end]

    @property
    def surfaces(self) -> np.ndarray:
        return self._surface[self._start:self._end]

    def at(self, angle: float) -> tuple[float, float]:
        """(S(angle), dS/dangle) (:func:`surface_at`)."""
        value, slope = surface_at(self.angles, self.surfaces, self._pruned, self.feed, float(angle))
        return float(value), float(slope)

    def previous_pass(self, angle: float) -> tuple[float, float]:
        """(S, dS/dangle) one blade passage behind ``angle``: what the blade at ``angle`` cuts into."""
        return self.at(angle - self.passage)

    def advance(self, angle: float, position: float) -> None:
        """Record an accepted bit state: the blade at ``angle`` leaves max(position, the surface it met)."""
        if angle <= self._angle[self._end - 1]:
            return  # the bit turned back: the surface ahead is the one already recorded
        surface = max(position, self.previous_pass(angle)[0])
        if self._end == len(self._angle):
            self._compact(angle)
        self._angle[self._end], self._surface[self._end] = angle, surface
        self._end += 1

    def _compact(self, angle: float) -> None:
        """Drop what lies more than two revolutions behind, then grow the storage if still needed."""
        keep = max(self._start, int(np.searchsorted(self.angles, angle - 4.0 * math.pi)) + self._start - 1)
        if keep > self._start:
            self._pruned = True
        n = self._end - keep
        size = len(self._angle) if n < len(self._angle) // 2 else 2 * len(self._angle)
        angles, surfaces = np.empty(size), np.empty(size)
        angles[:n], surfaces[:n] = self._angle[keep:self._end], self._surface[keep:self._end]
        self._angle, self._surface, self._start, self._end = angles, surfaces, 0, n


@dataclass
class CuttingForces(ForceEvaluation):
    """The bit's state and the law's reaction (W, T >= 0 while cutting) with its derivatives."""

    depth_of_cut: float = 0.0  # d per revolution [m]
    force: float = 0.0  # -W, the force on u(L) [N]
    torque: float = 0.0  # -T, the torque on theta_x(L) [N m]
    jacobian_q: np.ndarray | None = None  # d(force, torque) / d(u, phi) at the bit
    jacobian_qd: np.ndarray | None = None  # d(force, torque) / d(u_dot, omega) at the bit
    rates: tuple = (0.0, 0.0)  # (u_dot, omega) at the bit
    clearance: tuple = (0.0, 0.0)  # (u - S, dS/dphi): the bit above the surface one blade passage behind, its slope


class CuttingBit:
    """Reaction of the rock on a cutting bit (x = L): -W on u, -T on theta_x (module doc)."""

    name: ClassVar[str] = "bit_rock"
    switch: ClassVar[str] = "bit_rock"
    conservative: ClassVar[bool] = False
    recorded: ClassVar[dict] = {
        "bit_force": ("N", "bit-rock force on the string at x = L (F_BR of (20), or -W of the cutting law)"),
        "bit_torque": ("N m", "bit-rock torque on the string at x = L (T_BR of (21), or -T of the cutting law)"),
        "depth_of_cut": ("m", "depth of cut per revolution d of the cutting law (0 for the paper's law)"),
    }

    def __init__(self, disc: BeamDiscretization, space, bit_rock, drive):
        self.rows = space.point_rows([disc.end_dof(U, 1), disc.end_dof(THETA_X, 1)])  # q -> u(L), theta_x(L)
        self._unit_loads = self.rows.unit_loads()  # P^T of a unit force on u(L) and a unit torque on theta_x(L)
        self._set_parameters(bit_rock)
        self.feed_per_radian = drive.axial_velocity / drive.rotation_speed if drive.rotation_speed > 0 else 0.0
        self.surface: CutSurface | None = None  # no rock cut before the drilling run begins

    def _set_parameters(self, bit) -> None:
        self.blades = bit.blades
        #: :func:`cutting_law`'s constants after the bit's state and the surface.
        self.law_constants = cutting_law_constants(bit)

    @classmethod
    def chosen(cls, scene) -> bool:
        return scene.bit_rock.law == "detournay"

    @classmethod
    def from_scene(cls, scene, disc, space, operators) -> "CuttingBit":
        return cls(disc, space, scene.bit_rock, scene.drive)

    def with_parameters(self, bit_rock) -> "CuttingBit":
        changed = copy.copy(self)
        changed._set_parameters(bit_rock)
        return changed

    def with_drive(self, axial_velocity: float, rotation_speed: float) -> "CuttingBit":
        """The same law with the steady drilling before t = 0 at other drive speeds."""
        changed = copy.copy(self)
        changed.feed_per_radian = axial_velocity / rotation_speed if rotation_speed > 0 else 0.0
        return changed

    # --- the delay buffer's life, one per simulation -------------------------------------------------------

    def fresh(self) -> "CuttingBit":
        changed = copy.copy(self)
        changed.surface = None
        return changed

    def _bit(self, vector: np.ndarray) -> tuple[float, float]:
        u, phi = self.rows.values(vector)
        return float(u), float(phi)

    def begin(self, t: float, q: np.ndarray) -> None:
        u, phi = self._bit(q)
        self.surface = CutSurface(self.blades, phi, u, self.feed_per_radian)

    def accept(self, t: float, q: np.ndarray, qd: np.ndarray) -> None:
        u, phi = self._bit(q)
        self.surface.advance(phi, u)

    # --- the law -------------------------------------------------------------------------------------------

    def record(self, forces: CuttingForces) -> dict[str, float]:
        return {"bit_force": forces.force, "bit_torque": forces.torque, "depth_of_cut": forces.depth_of_cut}

    def evaluate(self, q: np.ndarray, qd: np.ndarray, with_tangent: bool = False) -> CuttingForces:
        (u, phi), (u_dot, omega) = self._bit(q), self._bit(qd)
        if self.surface is None:
            cut, slope = u, 0.0  # at rest before drilling: the bit sits on the bottom, nothing to cut
        else:
            cut, slope = self.surface.previous_pass(phi)
        d, f_u, f_t, *law = cutting_law(u, u_dot, omega, cut, slope, *self.law_constants)
        jac_q = np.array(law[:4]).reshape(2, 2)
        jac_qd = np.array([[law[4], 0.0], [law[5], law[6]]])
        laws = {"bit_rock_force": f_u * self._unit_loads[0], "bit_rock_torque": f_t * self._unit_loads[1]}
        generalised = laws["bit_rock_force"] + laws["bit_rock_torque"]
        return CuttingForces(generalised, 0.0, laws, d, f_u, f_t, jac_q, jac_qd, (u_dot, omega), (u - cut, slope))

    def kink_step(self, forces: CuttingForces, dq: np.ndarray, c_v: float) -> float | None:
        """The fraction of a Newton update dq (which moves qd by c_v dq) just past the first kink of the law's clipped
        ramps along it, linearised: the spin's at omega a = -v_c, v_c (and 0 with a held backward spin), the wear
        flats' at u_dot = 0, v_c and at d = 0, d_c; None if it crosses none.  A full update that jumps a ramp lands
        on a branch the tangent did not see (the stuck bit's torque ramp is v_c / a = 1e-3 rad/s wide)."""
        du, dphi = (float(v) for v in self.rows.values(dq))
        (u_dot, omega), (clearance, slope) = forces.rates, forces.clearance
        blades, *_, contact_velocity, contact_depth, spin_scale, backward_damping = self.law_constants
        step = cutting_law_kink(float(u_dot), float(omega), float(clearance), float(slope), du, dphi, c_v, blades,
                                contact_velocity, contact_depth, spin_scale, backward_damping)
        return None if step == math.inf else step

    def tangent(self, forces: CuttingForces, c_u: float, c_v: float):
        """c_u df/dq + c_v df/dqd: the 2 x 2 law Jacobians at the bit, projected."""
        block = c_u * forces.jacobian_q + c_v * forces.jacobian_qd
        return self.rows.block(block)
