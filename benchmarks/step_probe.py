"""The cost of one Newmark step and of its parts at a fixed state of the paper scene, with little noise.

    python benchmarks/step_probe.py [T_START]

Runs the paper scene for T_START seconds (default 0.3, no field output), then repeats the step from the
state it reached, at the nominal step, and reports the best of 7 rounds per part: the whole step (Newton
with its evaluations, tangent and saddle solves), one evaluation of the model, its tangent, and the energy
budget's update, energies and power terms.  A whole run varies by 1-2 % between identical runs on this
machine; a part timed here by a few tenths of a microsecond, so changes of a few microseconds show
(benchmarks/RESULTS.md, twelfth sitting).  The stepper's memories (kept tangents, force level) carry over
between repeats as they do between steps.
"""

from __future__ import annotations

import sys
import tempfile
import time

import numpy as np

import fenics_drill  # noqa: F401  (dolfinx_solver and h5py first)
import fenics_drill.solvers.time_loop as time_loop
from fenics_drill.scene import load_scene
from fenics_drill.solvers.energy_budget import EnergyBudget
from fenics_drill.studies.run import run_scene

ROUNDS, REPEATS = 7, 300
BATCH = EnergyBudget.BATCH


def best_of(function) -> float:
    """The least mean time of ``function()`` over ROUNDS rounds of REPEATS calls [us]."""
    function()
    times = []
    for _ in range(ROUNDS):
        clock = time.perf_counter()
        for _ in range(REPEATS):
            function()
        times.append((time.perf_counter() - clock) / REPEATS)
    return min(times) * 1e6


def reached_state(t_start: float):
    """The simulation of the paper scene and the state it reached at t_start."""
    kept = {}
    run = time_loop.Simulation.run

    def keep(self, state, t_end, on_step=None, progress=None, **options):
        kept["simulation"], kept["state"] = self, run(self, state, t_end, on_step, progress, **options)
        return kept["state"]

    time_loop.Simulation.run = keep
    try:
        scene = load_scene("demos/scenes/paper.toml", [f"time.t_end={t_start}", "output.field_interval=0"])
        with tempfile.TemporaryDirectory() as out:
            run_scene(scene, out, progress=False, overwrite=True)
    finally:
        time_loop.Simulation.run = run
    return kept["simulation"], kept["state"]


def main() -> None:
    t_start = float(sys.argv[1]) if len(sys.argv) > 1 else 0.3
    simulation, state = reached_state(t_start)
    model, stepper = simulation.model, simulation.stepper
    dt = simulation.controller.nominal
    h0 = model.constraints @ state.q - model.drive_rate * state.t
    new, iterations, evaluation = stepper.step(state, dt, h0)
    coefficients = (1.0, stepper.gamma / (stepper.beta * dt), 1.0 / (stepper.beta * dt * dt))
    with_tangent = model.evaluate(new.q, new.qd, new.qdd, new.mu, coefficients, stepper._internal_parts)
    old_terms, new_terms = simulation._power_terms(state, evaluation), simulation._power_terms(new, evaluation)
    budget = EnergyBudget(initial_energy=0.0)
    batch_q, batch_qd = np.tile(new.q, (BATCH, 1)), np.tile(new.qd, (BATCH, 1))
    parts = {
        f"Newmark step ({iterations} iterations)": lambda: stepper.step(state, dt, h0),
        "model evaluation": lambda: model.evaluate(new.q, new.qd, new.qdd, new.mu),
        "model tangent": lambda: model._tangent(coefficients, stepper._internal_parts, with_tangent.forces,
                                                with_tangent.drive),
        "budget: power terms (laws projected)": lambda: simulation._power_terms(new, evaluation),
        "budget: energies of one state": lambda: simulation.mechanical_energy(new, evaluation),
        "budget: energies of 64 states, per state": lambda: model.mechanical_energies(batch_q, batch_qd),
        "budget: update": lambda: budget.advance(old_terms, new_terms, new.q - state.q),
    }
    print(f"paper scene at t = {state.t:.4f} s, step {dt:.3e} s, {model.size} unknowns; best of {ROUNDS} x {REPEATS}:")
    for name, function in parts.items():
        per = BATCH if "64 states" in name else 1
        print(f"  {name:44s} {best_of(function) / per:7.1f} us")


if __name__ == "__main__":
    main()
