"""Newmark time stepping (67)-(68) solved by Newton with Lagrange multipliers (70)-(76).

gamma = 1/2 + alpha and beta = (1/2 + gamma)^2 / 4 (Section 4.3).  Each step
solves the saddle-point system (76) for (q_{n+1}, mu_{n+1}) by Newton.  The
internal tangent (the only assembled matrix) is kept for a number of steps and
re-assembled after that or after a failed step; the tangents of the force laws
are fresh at every iteration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fenics_drill.solvers.compiled_residual import CompiledResidual
from fenics_drill.model.drillstring import DrillstringModel, Evaluation
from fenics_drill.model.reduction.spaces import column_bound
from fenics_drill.solvers.compiled_step import kept_tangent_step
from fenics_drill.solvers.newton import ARMIJO, KeptTangent, saddle_newton


#: A Newton iterate keeps the tangent of the previous one while the residual shrinks at least this much
#: per update (the stiff bit and wall laws make it rarely so in their transients: then it is fresh) ...
TANGENT_REUSE_RATE = 0.1
#: ... and in the full space this much.  There a fresh tangent's banded factorisation costs about an evaluation,
#: where a modal space's dense one costs several: a tangent that contracts by less than 30 times per update is
#: worth its refresh.  Measured on the VBH well's 150 m BHA split over its first 3 s: 6 % fewer Newton iterations
#: than at 0.1 for as many factorisations; over 10 s of stick-slip its severity, rop and surface torque within
#: 1.3 %, 0.24 % and 0.1 % of those at 0.1 (docs/performance.md, "The BHA split").
TANGENT_REUSE_RATE_FULL = 0.03
#: A Newton update that shrinks the residual less than this (where a consistent tangent gives quadratic
#: convergence) has the stiffness part df/dq of the internal tangent of earlier steps assembled afresh for the
#: next one.  It is the part that drifts between the periodic refreshes: the spin turns the stiffness of a
#: deflected string, and the printed kinematics' strains turn with theta_x itself; df/dqd and df/dqdd are kept
#: up to ``tangent_reuse`` steps (measured: the same Newton iterations as a refresh of all three, at a third
#: of the assembly; docs/performance.md).
SLOW_CONTRACTION = 0.25
#: An iterate is the step's result, without another evaluation, when Newton's next update would move no point
#: of the string's surface by more than this share of time.error_tolerance (the role of kappa in Hairer &
#: Wanner's stopping test, Sec. IV.8, there 0.01-0.1; here smaller, for the efficiency (96), which rectifies
#: the drive torque).  In a modal space, against 1e-4: the paper scene's 10 s and ten random scenes give the same
#: rop, efficiency and peak stress to 1e-5 (the paper scene's full order over 1 s and 3 s moved by 3e-5 and 7e-5),
#: for 7 % fewer evaluations (docs/performance.md) ...
SETTLED_SHARE = 1e-3
#: ... and in the full space this share.  There every vertex on the wall is a mass on its own spring
#: (k_FS1 = 1e10 N/m), and a vertex left 1e-8 m from its converged place carries a force error of 100 N, about the
#: weight it rests under: at 1e-3, full orders resting on the wall were lifted off it within 0.14-0.6 s and
#: bounced thousands of times, which their refined runs and the reduced models do not; at 1e-4 one of the five
#: scenes found still was (a light pipe, 130 N per vertex).  At 1e-5 and 1e-6 all five rest, with the same rop,
#: efficiency and peak stress to 1e-4; the paper scene's full order takes 12 % more evaluations than at 1e-3
#: (docs/verification.md, "The reduced model against its full order"; docs/performance.md).
SETTLED_SHARE_FULL = 1e-5
#: ... and each of the drive's multipliers by less than this share of the largest it has been: four orders
#: below the 1 % that the efficiency, which reads the drive torque lambda_4, is asked to meet ...
SETTLED_FORCE_SHARE = 1e-6
#: ... after an update that at least halved the residual: Newton contracts, so what is left of the error is
#: at most twice the next update.
SETTLED_CONTRACTION = 0.5

#: A step's last tangent (and its factorisation) starts the next step's Newton when that step has the same size
#: and this one converged within this many evaluations (its tangent still described the motion well); the
#: rate test of TANGENT_REUSE_RATE then judges it.  Measured on the paper scene's 10 s: 5 % less wall time at
#: 5 % more evaluations, the same rop and efficiency; carried after any step, 16 % more evaluations for the
#: same time (docs/performance.md).
CARRY_WITHIN = 2

#: The predictor's forces of a compiled step that evaluates them itself.
_NOT_EVALUATED = (np.empty(0), np.empty(0), np.empty(0))

#: Which parts (df/dq, df/dqd, df/dqdd) of the internal tangent an evaluation assembles afresh.
ALL_PARTS, STIFFNESS_PART, NO_PART = (True, True, True), (True, False, False), (False, False, False)


class NewtonFailure(RuntimeError):
    """Newton did not converge within the allowed iterations (or produced non-finite values)."""


@dataclass
class State:
    """Reduced displacement, velocity, acceleration and multipliers mu (the lambda of (74)) at time t."""

    t: float
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    mu: np.ndarray


def newmark_parameters(alpha: float) -> tuple[float, float]:
    """(gamma, beta) of Section 4.3."""
    gamma = 0.5 + alpha
    return gamma, 0.25 * (0.5 + gamma) ** 2


#: Relative round-off of a displacement, in units of machine epsilon's worth of cancellations.
ROUND_OFF = 1e3 * np.finfo(float).eps


class NewmarkNewton:
    """One Newmark step of (65) with the constraints (72) enforced by multipliers."""

    def __init__(self, model: DrillstringModel, alpha: float, tolerance: float, max_iterations: int,
                 tangent_reuse: int = 20, settle_length: float | None = None, compiled: bool = True):
        """``tangent_reuse``: steps over which an assembled internal tangent is kept (the displacements
        are small, so it changes slowly; contact and bit-rock tangents are fresh at every iteration).
        ``settle_length`` [m]: Newton also stops at an iterate whose next update would move no point of the
        string's surface by more than SETTLED_SHARE (SETTLED_SHARE_FULL in the full space) of it (the step's
        error tolerance); None: on its residual alone.  ``compiled``: the steps that keep their tangent are
        taken by :func:`~fenics_drill.solvers.compiled_step.kept_tangent_step` where the model allows it."""
        self.model = model
        self.tangent_reuse = tangent_reuse
        self.gamma, self.beta = newmark_parameters(alpha)
        self.tolerance, self.max_iterations = tolerance, max_iterations
        self._internal_parts = None
        # accepted steps since all parts of the internal tangent, and since its df/dq, were assembled
        self._steps_since_tangent = self._steps_since_stiffness = 0
        self._force_level = 0.0
        self._multiplier_level = np.zeros(model.constraints.shape[0])  # the largest |mu_i| of the accepted steps
        self.settle_length = settle_length
        self.settled_share = SETTLED_SHARE_FULL if model.space.sparse else SETTLED_SHARE
        self.reuse_rate = TANGENT_REUSE_RATE_FULL if model.space.sparse else TANGENT_REUSE_RATE
        self._motion_bound = column_bound(model.motion_rows)
        self._carried = KeptTangent()  # the last step's tangent, for the next step of the same size
        self._carried_dt = None
        self.compiled = compiled
        self._compiled = CompiledResidual.of(model) if compiled else None
        self.compiled_steps = 0  # steps solved by the compiled step (the step controller may reject some)

    def forget_tangent(self) -> None:
        """Assemble the internal tangent afresh at the next step (the internal force has changed)."""
        self._internal_parts = None
        self._carried.matrix = None
        self._compiled = CompiledResidual.of(self.model) if self.compiled else None

    def constraint_target(self, t: float, h0: np.ndarray) -> np.ndarray:
        """h(t) of (71) for the rows the basis leaves: u(0, t) = V0 t, theta_x(0, t) = Omega t."""
        return h0 + self.model.drive_rate * t

    @staticmethod
    def _scale(ev: Evaluation, mu_force: np.ndarray, inertia: np.ndarray) -> float:
        """The size of the forces that balance at a state: internal, external, constraint and inertia
        (M qdd, so that a free vibration, where M qdd + K q cancel, still has a scale)."""
        return math.sqrt(max(ev.internal @ ev.internal, ev.external @ ev.external, mu_force @ mu_force,
                             inertia @ inertia, 1e-60))

    def _moves_less_than(self, dq: np.ndarray, length: float) -> bool:
        """Whether the increment dq of q moves every vertex's (u, v, w, r theta_x) by at most ``length``: the
        bound of the rows' largest columns first, the rows' product only where it does not tell."""
        if float(self._motion_bound @ np.abs(dq)) <= length:
            return True
        return float(np.max(np.abs(self.model.motion_rows @ dq))) <= length

    def initial_acceleration(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """qdd(0) and mu(0) from (65) and the twice-differentiated constraint (h'' = 0)."""
        zero = np.zeros_like(q)
        held = np.zeros(self.model.constraints.shape[0])
        ev = self.model.evaluate(q, qd, zero, held, tangent_coefficients=(0.0, 0.0, 1.0))
        self._internal_parts, self._steps_since_tangent, self._steps_since_stiffness = ev.internal_parts, 0, 0
        qdd, mu = self.model.space.saddle_solve(ev.tangent, self.model.constraints, -ev.residual, held)
        return qdd, mu

    def step(self, state: State, dt: float, h0: np.ndarray) -> tuple[State, int, Evaluation]:
        """Advance by dt; returns the new state, the Newton iterations and the final evaluation.

        Newton (:func:`~fenics_drill.solvers.newton.saddle_newton`) is globalised by backtracking
        on the residual norm: the bit-rock law (20) has a kink at u_dot_bit = 0 and the wall law (17)
        one at first contact, where plain Newton can cycle between the two branches.
        """
        taken = self._compiled_step(state, dt, h0)
        if taken is not None:
            return taken
        g, b = self.gamma, self.beta
        q_pred = state.q + dt * state.qd + dt * dt * (0.5 - b) * state.qdd
        qd_pred = state.qd + dt * (1.0 - g) * state.qdd
        c_v, c_a = g / (b * dt), 1.0 / (b * dt * dt)
        coefficients = (1.0, c_v, c_a)
        target = self.constraint_target(state.t + dt, h0)

        def rates(q):
            """(qd, qdd) of (67)-(68) at the end-of-step displacement q."""
            qdd = (q - q_pred) * c_a
            return qd_pred + g * dt * qdd, qdd

        def evaluate(q, mu, fresh=NO_PART):
            """The evaluation at q, with the ``fresh`` parts of the internal tangent assembled at it (all of
            them when none are kept) and the others kept from earlier steps."""
            qd, qdd = rates(q)
            if self._internal_parts is None:
                fresh = ALL_PARTS
            kept = None if fresh == ALL_PARTS else tuple(None if new else part
                                                         for new, part in zip(fresh, self._internal_parts))
            ev = self.model.evaluate(q, qd, qdd, mu, coefficients, internal_parts=kept)
            if any(fresh):
                self._internal_parts, self._steps_since_stiffness = ev.internal_parts, 0
                if fresh == ALL_PARTS:
                    self._steps_since_tangent = 0
            return ev

        def check(iteration, q, mu, ev, norm, gap):
            if not math.isfinite(norm):
                raise NewtonFailure(f"Newton produced non-finite values at dt = {dt:.3e} s")
            # the residual is measured against the forces that balance at this iterate and at the states
            # accepted before (never against a predictor's residual: an explosive predictor would make
            # any iterate look converged)
            scale = self._scale(ev, self.model.constraints_transposed @ mu, self.model.mass @ ((q - q_pred) * c_a))
            norms.append(norm)
            scales.append(scale)
            if norm > self.tolerance * max(self._force_level, scale):
                # the inertia M (q - q_pred) / (beta dt^2) cannot be known better than round-off in q: a
                # string that only spins, unloaded, has nothing else to measure its residual against
                mass_q = self.model.mass @ q
                if norm > ROUND_OFF * c_a * math.sqrt(mass_q @ mass_q):
                    return None
            return accepted(iteration, q, mu, ev, gap, scale)

        def accepted(iteration, q, mu, ev, gap, scale):
            """The step's result at an iterate whose forces balance, if it also meets the constraints."""
            if all(abs(g) <= self.tolerance * max(abs(t), 1.0) for g, t in zip(gap.tolist(), target.tolist())):
                self._force_level = max(self._force_level, scale)
                self._multiplier_level = np.maximum(self._multiplier_level, np.abs(mu))
                self._steps_since_tangent += 1
                self._steps_since_stiffness += 1
                return State(state.t + dt, q, *rates(q), mu), iteration, ev
            return None

        def settled(iteration, q, mu, ev, dq, dmu, gap):
            """The iterate as the step's result, when the next update (dq, dmu) is negligible against what the
            step's error and the efficiency may be (SETTLED_SHARE, SETTLED_FORCE_SHARE): the iterate whose
            residual is still above the tolerance need not be moved and evaluated once more.  Measured: a
            quarter of the paper scene's evaluations saved, its efficiency unchanged to 1e-5
            (docs/performance.md)."""
            if self.settle_length is None or len(norms) < 2 or norms[-1] > SETTLED_CONTRACTION * norms[-2]:
                return None
            if not self._moves_less_than(dq, self.settled_share * self.settle_length):
                return None
            if np.any(np.abs(dmu) > SETTLED_FORCE_SHARE * self._multiplier_level):
                return None
            return accepted(iteration, q, mu, ev, gap, scales[-1])  # the scale check measured this iterate with

        q = state.q + dt * state.qd + 0.5 * dt * dt * state.qdd
        wall = self.model.force("wall")
        if self.model.space.sparse and wall is not None:
            # the resting vertices start on the round wall, not on the predictor's straight line: Newton then
            # starts with the contacts it ends with (measured on the full order: 11 % fewer Newton iterations
            # over 2 s of the paper scene, 14 % over 0.6 s of a 1000 m string; docs/performance.md)
            q = wall.kept_on_wall(state.q, q)
        mu = state.mu.copy()
        stale = self._internal_parts is None or self._steps_since_tangent >= self.tangent_reuse
        ev = evaluate(q, mu, ALL_PARTS if stale and self.model.internal.state_dependent else NO_PART)
        norms, scales = [], []  # the residual norm and force scale of each iterate of this step, as check sees them

        def trial(q, mu):
            """An iterate's evaluation.  Newton that contracts slowly although its tangent is fresh has an
            internal stiffness df/dq of earlier steps that drifted (the large deflections of a full-order
            string, the spin): the next evaluation assembles it afresh, once per step."""
            slow = len(norms) >= 2 and norms[-1] > SLOW_CONTRACTION * norms[-2]
            drifted = self._steps_since_stiffness > 0 and self.model.internal.state_dependent
            return evaluate(q, mu, STIFFNESS_PART if slow and drifted else NO_PART)

        if stale or dt != self._carried_dt:  # another system: the carried tangent does not describe it
            self._carried.matrix = None
        self._carried_dt = dt
        if self._carried.matrix is None and self._compiled is not None:
            # the tangent Newton takes at its first update, formed now: the rest of the step is the compiled one
            self._carried.matrix = ev.tangent
            taken = self._compiled_step(state, dt, h0, ev)
            if taken is not None:
                if taken[1] == 1:  # converged at the predictor: this Newton forms no tangent, and carries none
                    self._carried.matrix = None
                return taken
        result = saddle_newton(trial, self.model.space, self.model.constraints, target,
                               q, mu, ev, check, self.max_iterations, reuse_rate=self.reuse_rate,
                               kink_step=lambda ev, dq: self.model.kink_step(ev, dq, c_v), settled=settled,
                               kept=self._carried)
        if result is None or result[1] > CARRY_WITHIN:
            self._carried.matrix = None
        if result is None:
            # the internal tangent parts assembled at this step's iterates may be those of a diverging one: the
            # retry (a shorter step) assembles them afresh at its predictor.  Kept, they failed every cut of a
            # 6000 m string's first step down to the smallest; fresh, its fifth cut converges in 9 iterations.
            self._internal_parts = None
            raise NewtonFailure(f"Newton did not converge in {self.max_iterations} iterations at dt = {dt:.3e} s")
        return result

    def _compiled_step(self, state: State, dt: float, h0: np.ndarray,
                       predicted: Evaluation | None = None) -> tuple[State, int, Evaluation] | None:
        """The step as :meth:`step` takes it, by :func:`~fenics_drill.solvers.compiled_step.kept_tangent_step`,
        when it starts with a tangent kept for it (the last step's, or the one :meth:`step` formed at its
        predictor, whose evaluation ``predicted`` is not repeated) and its internal parts are not due to be
        assembled; None when it does not, or when the compiled step hands it back (then :meth:`step` takes it in
        Python)."""
        if (self._compiled is None or self._carried.matrix is None or dt != self._carried_dt
                or self._internal_parts is None or self._steps_since_tangent >= self.tangent_reuse):
            return None
        forces = self._compiled.forces()
        if forces is None:
            return None
        model = self.model
        lu = model.space.factorised(self._carried.matrix, model.constraints)
        settle = -1.0 if self.settle_length is None else self.settle_length
        rates = (self.reuse_rate, SLOW_CONTRACTION, SETTLED_CONTRACTION, SETTLED_FORCE_SHARE, ROUND_OFF, ARMIJO,
                 self.tolerance)
        taken, q, qd, qdd, mu, iterations, ev, force_level, multipliers, kept = kept_tangent_step(
            self._compiled.internal, forces, self._compiled.order, model.constraints, self._compiled.drive_loads,
            (lu.factors, lu.pivots, lu.scale), model.mass, model.motion_rows, self._motion_bound, state.q, state.qd,
            state.qdd, state.mu, dt, (self.gamma, self.beta), self.constraint_target(state.t + dt, h0),
            (self._force_level, self._multiplier_level), (settle, self.settled_share), self.max_iterations,
            self._steps_since_stiffness > 0 and model.internal.state_dependent, rates,
            _NOT_EVALUATED if predicted is None else (predicted.residual, predicted.internal, predicted.external))
        if not taken:
            return None
        self._force_level, self._multiplier_level = force_level, multipliers
        self._steps_since_tangent += 1
        self._steps_since_stiffness += 1
        if not kept or iterations > CARRY_WITHIN:
            self._carried.matrix = None
        self.compiled_steps += 1
        if predicted is not None and iterations == 1:  # the predictor is the step's result
            return State(state.t + dt, q, qd, qdd, mu), iterations, predicted
        residual, internal, external, wall, _, _ = ev
        coefficients = (1.0, self.gamma / (self.beta * dt), 1.0 / (self.beta * dt * dt))
        evaluation = model.evaluation_at(q, qd, residual, internal, external, self._compiled.evaluations(q, qd, wall),
                                         coefficients, self._internal_parts)
        return State(state.t + dt, q, qd, qdd, mu), iterations, evaluation
