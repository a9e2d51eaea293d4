"""Drives that apply loads instead of holding the top: the hook load (weight on bit) and the top drive
with a speed controller (fenics_drill/model/top_drive.py)."""

import math

import numpy as np
import pytest
from conftest import scene_with
from scipy.optimize import brentq

from fenics_drill.model.drillstring import build_model
from fenics_drill.model.top_drive import controller_gains
from fenics_drill.solvers.time_loop import Simulation

SHORT_STRING = ("beam.length=10.0", "beam.elements=10", "reduction.rule='none'", "model.gravity=false",
                "model.contact=false", "beam.damping=200.0", "time.dt=1e-3")


def run_short(*overrides, t_end=1.0):
    """Run the short, well-damped string; per step: t, bit velocity, top velocity and spin, drive force
    and torque; and the simulation."""
    scene = scene_with(*SHORT_STRING, f"time.t_end={t_end}", *overrides)
    model = build_model(scene)
    simulation = Simulation(model, scene)
    start = simulation.initial_state(np.zeros(model.size))
    rows = []

    def on_step(record):
        s = record.state
        force, torque = simulation.model.drive.applied(s.mu, record.evaluation.drive)
        top_velocity, top_spin = simulation.model.drive.velocities(s.qd)
        rows.append((s.t, simulation.model.bit_state(s.q, s.qd)[1], top_velocity, top_spin, force, torque))

    simulation.run(start, t_end, on_step)
    return scene, simulation, np.array(rows).T


def late_mean(t, x, start=0.5):
    keep = t >= start
    return np.trapezoid(x[keep], t[keep]) / (t[keep][-1] - t[keep][0])


def rigid_damping_force(scene, velocity):
    """The damping (38) on the whole string moving at ``velocity``: c rho A L v (it acts on absolute
    velocities, so it resists the rigid feed too)."""
    p = scene.beam_properties
    return p.damping * p.mass_per_length * p.length * velocity


def test_a_hook_load_drills_where_the_paper_law_holds_the_weight_on_bit():
    """Pushed with W = 20 kN, the bit settles at the feed v where the law (20) and the damping hold W:
    W = Gamma_BR (1 - exp(-alpha_BR v)) + c rho A L v (a steady state of a rigid feed; 0.26 % below
    -ln(1 - W/Gamma)/alpha here).  The top is free: it moves at the bit's speed."""
    scene, _, (t, bit_velocity, top_velocity, _, force, _) = run_short("drive.mode='hook_load'",
                                                                       "drive.weight_on_bit=20e3")
    b = scene.bit_rock
    v = brentq(lambda v: b.limit_force * -math.expm1(-b.rate * v) + rigid_damping_force(scene, v) - 20e3, 0, 1)
    # the feed settles within ~0.1 s (time constant m / (Gamma alpha e^(-alpha v)) < 1 ms, plus the axial
    # waves damped at c = 200 1/s): 1e-4 is round-off and the tail of the start-up
    assert late_mean(t, bit_velocity) == pytest.approx(v, rel=1e-4)
    assert late_mean(t, top_velocity) == pytest.approx(v, rel=1e-4)
    assert np.all(force == 20e3)


@pytest.mark.parametrize("rule", ["none", "auto"])
def test_a_hook_load_with_a_speed_controller_holds_no_dof(rule):
    """A hook load and a PI top drive together leave [B] without rows (the saddle system is J alone),
    reduced or full: the load is applied as set and the top turns at Omega on average.  The reduced model
    stopped with "zero-size array" before (the scale of an empty [B])."""
    scene, simulation, (t, _, _, top_spin, force, _) = run_short(
        "drive.mode='hook_load'", "drive.weight_on_bit=20e3", "drive.controller='pi'", f"reduction.rule='{rule}'",
        t_end=0.6)
    assert simulation.model.constraints.shape[0] == 0
    assert np.all(force == 20e3)
    # the PI's integral removes the steady speed error; what is left in the mean over 0.3-0.6 s is the part of
    # the torsional oscillation that a finite window does not average out, below 1e-3 (as in the test below)
    assert late_mean(t, top_spin, 0.3) == pytest.approx(scene.drive.rotation_speed, rel=1e-3)


@pytest.mark.parametrize("controller", ["pi", "soft_torque"])
def test_a_speed_controller_holds_the_set_speed_and_its_motor_work_closes_the_budget(controller):
    """The PI's integral removes the steady speed error: the top turns at Omega on average.  With
    alpha = 0 (no numerical dissipation) the budget E(t) - E(0) = W_drive + W_laws - D closes when W_drive
    is the motor's work int T_m theta_x_dot(0) dt plus the multiplier's axial work, and that work is the one
    integrated from the recorded torque and speed (trapezoidal in time, so equal to O(dt^2))."""
    scene, simulation, (t, _, top_velocity, top_spin, force, torque) = run_short(
        f"drive.controller='{controller}'", "bit_rock.law='detournay'", "time.newmark_alpha=0.0", t_end=0.6)
    omega = scene.drive.rotation_speed
    assert late_mean(t, top_spin, 0.3) == pytest.approx(omega, rel=1e-3)
    budget = simulation.budget
    assert budget.balance_error < 1e-5, budget.summary()  # measured 6e-6 at alpha = 0.015, all terms booked
    motor_work = np.trapezoid(torque * top_spin + force * top_velocity, t)
    assert budget.input_work == pytest.approx(motor_work, rel=1e-3)
    assert budget.kinetic > 0.5 * scene.drive.top_drive_inertia * omega**2 * 0.99  # the top drive's own energy


def test_the_soft_torque_tuning_matches_the_pipe_impedance_at_the_stick_slip_frequency():
    """The top drive's impedance Z_td(i w) = k_p + k_i / (i w) + i w J_td equals the pipe's characteristic
    impedance Z = sqrt(k_t rho I_xx) (k_t = G I_xx, St-Venant's torsional stiffness) at the first
    torsional quarter wave w_s: the reflection coefficient (Z_td - Z) / (Z_td + Z) vanishes there and grows
    away from it."""
    scene = scene_with("drive.controller='soft_torque'")
    p = scene.beam_properties
    polar = 2 * p.section.I4
    impedance = math.sqrt(p.shear_modulus * polar * p.density * polar)
    w_s = 2 * math.pi * math.sqrt(p.shear_modulus / p.density) / (4 * p.length)
    k_p, k_i = controller_gains(scene.drive, p)

    def reflection(w):
        z_td = k_p + k_i / (1j * w) + 1j * w * scene.drive.top_drive_inertia
        return abs((z_td - impedance) / (z_td + impedance))

    assert reflection(w_s) < 1e-12
    assert reflection(0.5 * w_s) > 0.5 and reflection(2 * w_s) > 0.5
    stiff_k_p, _ = controller_gains(scene_with("drive.controller='pi'").drive, p)
    assert stiff_k_p > 10 * impedance  # the default PI is stiff: it reflects torsional waves
