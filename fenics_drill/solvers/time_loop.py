"""The time loop of a drilling run: static start (Section 6.4), initial conditions (Section 3.2),
adaptive Newmark/Newton steps, impact counting, the energy budget and the check of a hyper-reduced
model's element sample.

It knows nothing about files: every accepted step is handed to ``on_step`` as a
:class:`StepRecord`, and the I/O layer decides what to keep.
"""

from __future__ import annotations

import collections
import contextlib
import math

import time
from dataclasses import dataclass

import numpy as np

from fenics_drill.model.drillstring import DrillstringModel, Evaluation
from fenics_drill.model.reduction.hyper_reduction import CHECK_INTERVAL
from fenics_drill.solvers.energy_budget import EnergyBudget, PowerTerms
from fenics_drill.solvers.impacts import ImpactCounter
from fenics_drill.solvers.newmark import NewmarkNewton, NewtonFailure, State
from fenics_drill.solvers.step_control import RunFailure, StepController


#: A string whose top moves axially faster than this many times the set rate V0 (and than RUNAWAY_FLOOR) under a
#: hook-load drive, on average over the axial wave's round trip 2 L / c along the string, falls or is pulled out:
#: the hook load does not hold it, and the run ends "failed".  The mean, not the top's speed at one instant: the
#: axial wave that a bit leaving the rock sends up a long string swings the top by F / (rho c A) (60 kN on 5 in drill
#: pipe: 0.44 m/s) and back within that round trip, while the string stays held.
RUNAWAY_FACTOR = 100.0
RUNAWAY_FLOOR = 0.5  # [m/s], 1800 m/h: faster than any drilling


class Runaway(RunFailure):
    """The top of a string held by its hook load moves far faster than the set rate: it falls or runs away."""


@dataclass
class StepRecord:
    """What an observer may want of one accepted step."""

    state: State
    dt: float
    newton_iterations: int
    evaluation: Evaluation
    impacts: np.ndarray  # the vertices whose impact began during the step (indices; solvers/impacts.py)
    in_contact: np.ndarray  # vertices in contact at the end of the step
    budget: EnergyBudget | None  # None in a simulation that keeps no budget
    step_index: int


class Simulation:
    """Integrates one scene's model from a given initial displacement."""

    def __init__(self, model: DrillstringModel, scene, energy_budget: bool = True):
        """``energy_budget``: book the energy balance of every step (a run's summary reports it; a study
        that reads none of it, a Monte Carlo realisation, saves its cost)."""
        model = model.fresh()  # its own cut surface and controller memory
        self.keeps_budget = energy_budget
        self.model, self.scene = model, scene
        self._factorisations_at_start = model.space.factorisations
        solver = scene.solver
        self.stepper = NewmarkNewton(model, scene.time.newmark_alpha, solver.newton_tolerance,
                                     solver.newton_max_iterations, solver.tangent_reuse, scene.time.error_tolerance,
                                     solver.compiled_step)
        self.controller = StepController(scene, self.stepper.beta, model.error_rows)
        self.impacts = ImpactCounter(len(model.disc.vertex_x), model.vertex_gap)
        self.stats = {"steps": 0, "rejected_steps": 0, "newton_failures": 0, "newton_iterations": 0,
                      "min_dt": np.inf, "max_dt": 0.0, "forced_steps": 0, "max_penetration": 0.0,
                      "sampling_checks": 0, "max_sampling_error": 0.0, "sample_retrainings": 0}
        self._next_sampling_check = 0.0
        self.last_state: State | None = None  # the latest accepted state (what an interrupted run keeps)
        p = scene.beam_properties
        self._round_trip = 2.0 * model.disc.properties.length / math.sqrt(p.young_modulus / p.density)
        self._top_travel = collections.deque()  # (t, the top's travel since the start, its speed) over a round trip

    def initial_state(self, q0: np.ndarray, qd0: np.ndarray | None = None) -> State:
        """Displacement q0 (the static equilibrium), velocity (V0, Omega) of Section 3.2 (or ``qd0``), and the
        consistent acceleration and multipliers; the memories of the model start here."""
        self.model.begin(0.0, q0)
        qd0 = self.model.drive_velocity_field() if qd0 is None else qd0
        qdd0, mu = self.stepper.initial_acceleration(q0, qd0)
        return State(0.0, q0, qd0, qdd0, mu)

    def _power_terms(self, state: State, ev: Evaluation) -> PowerTerms:
        return PowerTerms(
            drive=-state.mu,
            drive_displacement=self.model.constraints @ state.q,
            drive_loads=ev.drive.generalised,
            damping=self.model.internal.damping_force(state.qd),
            laws={name: law for f in self.model.forces for name, law in ev.forces[f.name].laws.items()},
        )

    def mechanical_energy(self, state: State, ev: Evaluation) -> tuple[float, float, float]:
        """Kinetic, strain, and potential (of the point forces: gravity, wall springs) energies."""
        kinetic = self.model.kinetic_energy(state.q, state.qd)
        strain = self.model.internal.strain_energy(state.q)
        return kinetic, strain, self.model.potential_energy(ev)

    @staticmethod
    def _penetration(ev: Evaluation) -> float:
        """Deepest indentation of the string into the wall at an evaluated state [m] (0 without contact)."""
        wall = ev.forces.get("wall")
        return float(wall.delta.max(initial=0.0)) if wall is not None else 0.0

    @property
    def factorisations(self) -> int:
        """The saddle matrices (76) factorised since :meth:`run` started (failed Newton solves included)."""
        return self.model.space.factorisations - self._factorisations_at_start

    @property
    def impacts_per_vertex(self) -> np.ndarray:
        """Impacts counted at each vertex so far."""
        return self.impacts.per_vertex

    def _check_sample(self, state: State) -> None:
        """Every CHECK_INTERVAL: the element sample against all elements; retrained where it misses
        (the internal tangent kept by the stepper is then stale and is assembled afresh)."""
        if self.model.exact_internal is None or state.t < self._next_sampling_check - 1e-12:
            return
        error, retrained = self.model.check_sample(state.q, state.qd, state.qdd)
        self.stats["sampling_checks"] += 1
        self.stats["max_sampling_error"] = max(self.stats["max_sampling_error"], error)
        if retrained:
            self.stats["sample_retrainings"] += 1
            self.stepper.forget_tangent()
        self._next_sampling_check = CHECK_INTERVAL * (np.floor(state.t / CHECK_INTERVAL + 1e-9) + 1)

    def _check_top(self, state: State) -> None:
        """Raise Runaway where the drive leaves the top free axially (a hook load) and it moves faster than
        RUNAWAY_FACTOR times the set rate V0 (at least RUNAWAY_FLOOR) on average over the last axial round trip (over
        the run so far, before one has passed)."""
        drive = self.model.drive
        if drive.held[0]:
            return
        speed = drive.velocities(state.qd)[0]
        travel = self._top_travel
        if travel:
            t0, s0, v0 = travel[-1]
            travel.append((state.t, s0 + 0.5 * (v0 + speed) * (state.t - t0), speed))
        else:
            travel.append((state.t, 0.0, speed))
        while len(travel) > 2 and travel[1][0] <= state.t - self._round_trip:
            travel.popleft()
        (t_first, s_first, v_first), (t_now, s_now, _) = travel[0], travel[-1]
        mean = (s_now - s_first) / (t_now - t_first) if t_now > t_first else v_first
        limit = max(RUNAWAY_FACTOR * abs(drive.rate[0]), RUNAWAY_FLOOR)
        if abs(mean) > limit:
            way = "falls" if mean > 0 else "is pulled out of the hole"
            raise Runaway(f"at t = {state.t:.4g} s the top has moved at {mean:.3g} m/s ({mean * 3600:.4g} m/h) on "
                          f"average over the last {t_now - t_first:.3g} s (the axial round trip is "
                          f"{self._round_trip:.3g} s), more than {limit:.3g} m/s: the string {way}; the hook load "
                          f"{-drive.top_force / 1e3:.4g} kN does not hold it (check drive.weight_on_bit and the bit's "
                          "law)")

    def run(self, state: State, t_end: float, on_step=None, progress=None, atomic=contextlib.nullcontext) -> State:
        """Step from ``state`` to t_end; raises StepTooSmall (with when and why) if the step collapses, Runaway if a
        string held by its hook load falls.

        ``on_step`` sees the initial state (step_index 0) and then every accepted step.  Each step (its Newton
        solve, its acceptance, the budget's and the memories' updates, ``on_step``) runs inside ``atomic()``: a
        command passes :func:`fenics_drill.studies.lifecycle.uninterrupted`, so that Ctrl-C or SIGTERM stops the
        run between two steps, never with a step half booked."""
        model = self.model
        self._factorisations_at_start = model.space.factorisations
        with atomic():  # the initial state, booked whole
            ev = model.evaluate(state.q, state.qd, state.qdd, state.mu)
            h0 = model.constraints @ state.q - model.drive_rate * state.t
            budget = powers = None
            if self.keeps_budget:
                energies = self.mechanical_energy(state, ev)
                budget = EnergyBudget(initial_energy=sum(energies), energies=model.mechanical_energies)
                budget.record(*energies, step=0)
                powers = self._power_terms(state, ev)
            self.budget = budget
            self.impacts.start(ev.forces.get("wall"))
            clock = time.perf_counter()
            self.last_state = state
            if on_step is not None:
                on_step(StepRecord(state, 0.0, 0, ev, np.zeros(0, dtype=np.int64), self.impacts.in_contact.copy(),
                                   budget, 0))
        while state.t < t_end * (1 - 1e-12):
            with atomic():  # a signal stops the run between steps, never inside one's bookkeeping
                dt = self.controller.step_towards(state.t, t_end)
                model.start_step(state.t + dt)
                try:
                    new, iterations, new_ev = self.stepper.step(state, dt, h0)
                except NewtonFailure as failure:
                    self.stats["newton_failures"] += 1
                    self.controller.cut(dt, str(failure), state.t)
                    continue
                self.stats["newton_iterations"] += iterations
                ratio = self.controller.error_ratio(state.t, dt, state.qdd, new.qdd)
                if not self.controller.judge(dt, ratio):
                    self.stats["rejected_steps"] += 1
                    continue
                model.accept(new.t, new.q, new.qd)
                self.stats["steps"] += 1
                new_powers = None
                if budget is not None:
                    new_powers = self._power_terms(new, new_ev)
                    budget.advance(powers, new_powers, new.q - state.q)
                    budget.defer(self.stats["steps"], new.q, new.qd, model.potential_energy(new_ev))
                impacts = self.impacts.step(new_ev.forces.get("wall"))
                self.stats["min_dt"] = min(self.stats["min_dt"], dt)
                self.stats["max_dt"] = max(self.stats["max_dt"], dt)
                self.stats["forced_steps"] = self.controller.forced_steps
                self.stats["max_penetration"] = max(self.stats["max_penetration"], self._penetration(new_ev))
                state, ev, powers = new, new_ev, new_powers
                self.last_state = state
                self._check_sample(state)
                self._check_top(state)
                if on_step is not None:
                    on_step(StepRecord(state, dt, iterations, ev, impacts, self.impacts.in_contact.copy(), budget,
                                       self.stats["steps"]))
                if progress is not None:
                    progress(state.t, t_end, self.stats, dt, time.perf_counter() - clock)
        return state
