"""The compiled Newmark step (solvers/compiled_step.py) and its residual (solvers/compiled_residual.py) against the
Python step and the model's own evaluation."""

import numpy as np
import pytest

from conftest import scene_with
from fenics_drill.solvers.compiled_residual import CompiledResidual, residual_at
from fenics_drill.model.drillstring import build_model
from fenics_drill.model.reduction.spaces import SaddleLU
from fenics_drill.solvers.compiled_step import _saddle_solve
from fenics_drill.solvers.time_loop import Simulation
from fenics_drill.studies.prepare import prepare

#: A 30 m string drilling: it rests on the wall (culled contact), the bit bounces, both drive dofs held.
STRING = ("beam.length=30.0", "beam.elements=60")


def _states(scene, t_end):
    """The prepared scene and the accepted states of its run in Python over t_end."""
    prepared = prepare(scene)
    simulation = Simulation(prepared.model, scene)
    states = []
    simulation.run(simulation.initial_state(prepared.equilibrium.q), t_end, on_step=lambda r: states.append(r.state))
    return simulation, states


@pytest.mark.parametrize("overrides", [("model.kinematics='objective'",), ("model.kinematics='printed'",),
                                       ("drive.mode='hook_load'", "drive.weight_on_bit=20e3")],
                         ids=["objective", "printed kinematics", "hook load"])
def test_the_compiled_residual_is_the_models_own_evaluation(overrides):
    """At the states a run passes through (on and off the wall, the bit cutting and lifted), the compiled
    residual, internal and external forces, the wall's indentations and the bit's force are the model's own:
    the same kernels summed in the same order, so equal to the round-off of a BLAS product (1e-12 of the
    largest entry; measured: bitwise equal), with either kinematics and with the drive's weight on bit."""
    scene = scene_with(*STRING, "solver.compiled_step=false", *overrides)
    simulation, states = _states(scene, 0.05)
    model = simulation.model
    compiled = CompiledResidual.of(model)
    assert compiled is not None
    for state in states[:: max(1, len(states) // 12)]:
        ev = model.evaluate(state.q, state.qd, state.qdd, state.mu)
        forces = compiled.forces()
        residual, internal, external, wall, bit, within = residual_at(compiled.internal, forces, compiled.order,
                                                                      model.constraints, compiled.drive_loads,
                                                                      state.q, state.qd, state.qdd, state.mu)
        assert within
        # 1e-12 of the largest force: a BLAS product summed in another order (one matrix-vector product of the
        # linear part, and the constraint rows) differs from NumPy's by a few ulps of the largest term
        for mine, theirs in ((residual, ev.residual), (internal, ev.internal), (external, ev.external)):
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12 * np.abs(ev.internal).max())
        # the indentations come from the same compiled pass on the same rows (measured: equal); 1e-15 m is a few
        # hundred ulps of the 15 mm radius they are a difference of, and 1e-8 of the 1e-7 m indentations at rest
        np.testing.assert_allclose(wall[0], ev.forces["wall"].delta, rtol=0, atol=1e-15)
        # the same law at the same bit velocity, to round-off; abs 1e-9 N where the bit is lifted (F_BR = 0)
        assert bit[2] == pytest.approx(ev.forces["bit_rock"].force, rel=1e-12, abs=1e-9)


def test_the_compiled_saddle_solve_is_lapacks():
    """The compiled forward and back substitution of getrf's LU gives getrs's solution of the saddle system (76),
    to round-off (1e-12 of the solution's size), on a random tangent with two constraint rows."""
    rng = np.random.default_rng(3)
    tangent = rng.standard_normal((40, 40)) + 40.0 * np.eye(40)
    constraints = rng.standard_normal((2, 40))
    lu = SaddleLU(tangent, constraints)
    rhs_q, rhs_c = rng.standard_normal(40), rng.standard_normal(2)
    expected = lu(rhs_q, rhs_c)
    dq, mu = _saddle_solve(lu.factors, lu.pivots, lu.scale, rhs_q, rhs_c)
    scale = max(np.abs(expected[0]).max(), np.abs(expected[1]).max())
    np.testing.assert_allclose(dq, expected[0], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(mu, expected[1], rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("drive", [(), ("drive.mode='hook_load'", "drive.weight_on_bit=20e3")],
                         ids=["held drive", "hook load"])
def test_a_run_with_compiled_steps_is_the_python_run(drive):
    """Over 0.25 s of the 30 m string (resting on the wall, the bit bouncing off the rock), the run whose steps
    that keep their tangent are compiled takes the same steps and Newton iterations as the run in Python, most of
    its steps compiled, and ends at the same state to the round-off of its products and solves, far inside the
    stopping test's bound (SETTLED_SHARE of the error tolerance per step): measured 4e-14 m apart on the surface
    (7e-14 m under the hook load), asserted 1e-3 of one step's bound; the drive's work 3e-9 J apart (6e-9 J),
    asserted 1e-9 of it."""
    runs = []
    for compiled in ("true", "false"):
        scene = scene_with(*STRING, *drive, f"solver.compiled_step={compiled}")
        prepared = prepare(scene)
        simulation = Simulation(prepared.model, scene)
        final = simulation.run(simulation.initial_state(prepared.equilibrium.q), 0.25)
        runs.append((final, simulation.stats, simulation.stepper.compiled_steps, simulation.budget))
    (final, stats, compiled_steps, budget), (python, python_stats, python_compiled, python_budget) = runs
    assert python_compiled == 0
    # measured 0.91 of the steps (0.97 under the hook load); the rest start with a fresh tangent (every
    # tangent_reuse steps, after a step of three evaluations) or hand the step back
    assert compiled_steps > 0.5 * stats["steps"]
    assert (stats["steps"], stats["newton_iterations"]) == (python_stats["steps"], python_stats["newton_iterations"])
    moved = np.max(np.abs(prepared.model.motion_rows @ (final.q - python.q)))
    assert moved <= 1e-3 * simulation.stepper.settled_share * scene.time.error_tolerance
    assert budget.input_work == pytest.approx(python_budget.input_work, rel=1e-9)


@pytest.mark.parametrize("overrides", [("reduction.rule='none'",), ("bit_rock.law='detournay'",),
                                       ("drive.controller='pi'",)],
                         ids=["full order", "cutting bit", "PI top drive"])
def test_models_it_does_not_cover_run_in_python(overrides):
    """The full order, a top drive's inertia and torque controller and a bit law with a memory are not what the
    compiled residual sums: their models have none, and every step is Python's."""
    model = build_model(scene_with(*STRING, *overrides))
    assert CompiledResidual.of(model) is None
