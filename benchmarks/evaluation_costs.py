"""What one Newton iterate of the scene's model costs, part by part, at a state of a drilling run.

    python benchmarks/evaluation_costs.py [--scene FILE] [T_STATE] [SECTION.KEY=VALUE ...]

Prepares the paper scene, or the scene FILE (with the settings given: ``beam.length=3000 beam.elements=6000`` for
3 km of the paper's string), runs it for
T_STATE seconds (default 0.5), and times at the last state each part of a Newton iterate (the model's residual, its
tangent, the internal force and its tangent parts, every point force with and without its tangent, the saddle
system (76) factorised and solved, a solve with the factorisation kept, the von Mises maximum of an accepted step),
each called many times in a row (milliseconds per call, the median of five rounds).  Parts that run alone stay in
cache, so a part costs more inside the time loop than here (docs/performance.md).
"""

from __future__ import annotations

import sys
import time

import numpy as np

import fenics_drill  # noqa: F401  (dolfinx_solver and h5py first)
from fenics_drill.observables.von_mises import VonMisesProbe
from fenics_drill.scene import load_scene
from fenics_drill.solvers.time_loop import Simulation
from fenics_drill.studies.prepare import prepare


def per_call(function, calls: int, rounds: int = 5) -> float:
    """Milliseconds per call, after one call to warm up: the median over ``rounds`` of ``calls`` calls each."""
    function()
    times = []
    for _ in range(rounds):
        clock = time.perf_counter()
        for _ in range(calls):
            function()
        times.append((time.perf_counter() - clock) / calls * 1e3)
    return float(np.median(times))


def main() -> None:
    arguments, path = sys.argv[1:], "demos/scenes/paper.toml"
    if arguments[:1] == ["--scene"]:
        path, arguments = arguments[1], arguments[2:]
    t_state = float(arguments[0]) if arguments and "=" not in arguments[0] else 0.5
    overrides = [a for a in arguments if "=" in a]
    scene = load_scene(path, [f"time.t_end={t_state}", "output.field_interval=0", *overrides])
    prepared = prepare(scene)
    model = prepared.model
    simulation = Simulation(model, scene)
    states = []
    simulation.run(simulation.initial_state(prepared.equilibrium.q), t_state,
                   lambda record: states.append(record.state))
    s = states[-1]
    coefficients = (1.0, 1e3, 1e6)
    rows = {
        "model residual": (lambda: model.evaluate(s.q, s.qd, s.qdd, s.mu), 1000),
        "model residual and tangent": (lambda: model.evaluate(s.q, s.qd, s.qdd, s.mu, coefficients).tangent, 200),
        "internal force": (lambda: model.internal.evaluate(s.q, s.qd, s.qdd), 1000),
        "internal tangent parts": (lambda: model.internal.tangent_parts(), 100),
    }
    for force in model.forces:
        rows[f"{force.name} force"] = (lambda f=force: f.evaluate(s.q, s.qd), 1000)
        evaluation = force.evaluate(s.q, s.qd, with_tangent=True)
        rows[f"{force.name} tangent"] = (lambda f=force, e=evaluation: f.tangent(e, 1.0, 1e3), 300)
    rhs, held = np.ones(model.size), np.zeros(model.constraints.shape[0])
    kept = model.evaluate(s.q, s.qd, s.qdd, s.mu, coefficients).tangent
    rows["tangent factorised and solved"] = (lambda: model.space.saddle_solve(
        model.evaluate(s.q, s.qd, s.qdd, s.mu, coefficients).tangent, model.constraints, rhs, held), 20)
    rows["solve, factorisation kept"] = (lambda: model.space.saddle_solve(kept, model.constraints, rhs, held), 100)
    probe, dofs = VonMisesProbe(model.disc), model.space.expand(s.q)
    rows["von Mises maximum"] = (lambda: probe.maximum(dofs), 300)
    wall = model.force("wall")
    contact = int(wall.evaluate(s.q, s.qd).in_contact.sum()) if wall is not None else 0
    print(f"state at t = {s.t:.3f} s; {model.size} generalised coordinates; {contact} vertices on the wall")
    for name, (function, calls) in rows.items():
        print(f"  {name:30s} {per_call(function, max(1, calls // 5)):8.3f} ms")


if __name__ == "__main__":
    main()
