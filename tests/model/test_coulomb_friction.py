"""Wall friction as one Coulomb force at the contact point (contact.friction_model = 'coulomb'), against closed
forms: a string sliding on the wall feels mu N of drag, a spinning one climbs the wall until friction balances
gravity and feels the torque mu N R_ext, one that spins while it slides splits mu N by the slip's direction, and a
pipe that rolls on the wall whirls backward at R_ext Omega / r.  The pointwise law never exceeds mu |F_n|, never
does positive work, and its tangent is the derivative of its loads."""

import math

import numpy as np
import pytest

from conftest import scene_with
from fenics_drill.model.discretization import THETA_X, U, V, W
from fenics_drill.model.forces.wall.coulomb import coulomb_friction
from fenics_drill.model.forces.wall.vertex_passes import _contact_blocks, _vertex_loads
from fenics_drill.observables.whirl import whirl
from fenics_drill.studies.prepare import prepare
from fenics_drill.solvers.time_loop import Simulation

MU = 0.25
#: A 20 m string of the paper's pipe sags onto the wall between 9 and 13 m; no bit, so that the drive's
#: force and torque balance the wall's friction (and the damping (38), computed exactly below).
ON_THE_WALL = ("contact.friction_model='coulomb'", "contact.sliding_velocity_scale=1e-5", "beam.length=20.0",
               "beam.elements=80", "model.bit_rock=false", f"contact.friction={MU}", "output.field_interval=0")


def run(scene, t_end):
    """Run the prepared scene to ``t_end``; the final state, the drive's applied force and torque along the run, and
    the model."""
    prepared = prepare(scene, dynamics=False)
    model = prepared.model
    simulation = Simulation(model, scene)
    rows = []

    def keep(record):
        force, torque = model.drive.applied(record.state.mu, record.evaluation.drive)
        rows.append((record.state.t, force, torque))

    final = simulation.run(simulation.initial_state(prepared.equilibrium.q), t_end, keep)
    return final, np.array(rows), simulation.model


def wall_at(model, state):
    """The wall law at a state, at the vertices in contact: their x, normal forces, nodal loads (F_a, F_v, F_w, T)
    and lateral positions (v, w)."""
    forces = model.force("wall").evaluate(state.q, state.qd)
    vertices = forces.vertices[forces.delta > 0]
    lateral = np.column_stack([model.lateral_rows[0] @ state.q, model.lateral_rows[1] @ state.q])[vertices]
    return model.disc.vertex_x[vertices], forces.normal, forces.nodal[forces.delta > 0], lateral


def damping_loads(model, scene, axial_velocity, spin):
    """The axial force and torque the damping (38), c times the mass pairing, takes from a rigid feed and spin:
    c 1_u^T M 1_u V0 and c 1_theta^T M 1_theta Omega."""
    disc, mass = model.disc, model.operators.mass
    rigid_u, rigid_t = np.zeros(disc.ndofs), np.zeros(disc.ndofs)
    rigid_u[disc.field_dofs[U]], rigid_t[disc.field_dofs[THETA_X]] = 1.0, 1.0
    c = scene.beam.damping
    return c * float(rigid_u @ (mass @ rigid_u)) * axial_velocity, c * float(rigid_t @ (mass @ rigid_t)) * spin


# The pointwise law


def test_the_force_never_exceeds_mu_fn_opposes_the_slip_and_its_tangent_is_its_derivative():
    """The return mapping: stuck, the force is the trial F_0 - k_t g; beyond mu |F_n| it is mu |F_n| along the
    trial; it never leaves the cone, and never does positive work on the slip from a force at rest (F_0 = 0)."""
    rng = np.random.default_rng(7)
    count, k_t = 2000, 1e10
    normal = -rng.uniform(0.0, 5e3, count)
    held = rng.normal(size=(count, 2)) * MU * np.abs(normal)[:, None] / 2
    slips = rng.normal(size=(count, 2)) * rng.choice([1e-10, 1e-8, 1e-6, 1e-3], size=(count, 1))
    axial, tangential = coulomb_friction(normal, held[:, 0], held[:, 1], slips[:, 0], slips[:, 1], MU, k_t)
    magnitude = np.hypot(axial, tangential)
    assert np.all(magnitude <= MU * np.abs(normal) * (1 + 1e-12))  # round-off of the scaling back
    trial = held - k_t * slips
    stuck = np.hypot(*trial.T) <= MU * np.abs(normal)
    assert np.array_equal(np.column_stack([axial, tangential])[stuck], trial[stuck])
    along = (axial * trial[:, 1] - tangential * trial[:, 0])[~stuck]  # parallel to the trial where it slips
    assert np.all(np.abs(along) <= 1e-12 * (magnitude * np.hypot(*trial.T))[~stuck])
    # scaled back onto the cone: mu |F_n| F* / |F*| has the magnitude mu |F_n| to a few ulps of the hypot and division
    assert magnitude[~stuck] == pytest.approx(MU * np.abs(normal[~stuck]), rel=1e-12)
    fresh_a, fresh_t = coulomb_friction(normal, 0 * normal, 0 * normal, slips[:, 0], slips[:, 1], MU, k_t)
    assert np.all(fresh_a * slips[:, 0] + fresh_t * slips[:, 1] <= 0.0)

    gap = 0.015
    worst = 0.0
    for _ in range(200):
        angle, indentation = rng.uniform(0, 2 * np.pi), rng.uniform(1e-7, 3e-6)
        position = np.concatenate([[rng.normal() * 1e-3], (gap + indentation) * np.array([np.cos(angle),
                                                                                        np.sin(angle)]),
                                   [rng.normal()]])
        # the anchor a little way back, a held force inside the cone: stick or slip, as the trial falls
        anchor = position - rng.normal(size=4) * rng.choice([1e-10, 1e-8, 1e-7, 1e-5])
        held_force = rng.normal(size=2) * 100.0
        law = (np.array([gap]), 1e10, 1e16, 1e6, False, MU, MU, np.array([0.08]), 1e-5, True, k_t, anchor[None],
               held_force[None], True)
        rates = rng.normal(size=4) * rng.choice([1e-6, 1e-3, 0.5])
        c_u, c_v = 1.7, 0.9
        block = _contact_blocks(np.array([0]), position[None], rates[None], *law, c_u, c_v)[0]
        loads = lambda p, r: _vertex_loads(p[None], r[None], *law)[1][0]  # noqa: E731
        numeric = np.zeros((4, 4))
        for j in range(4):
            h = 1e-11  # within stick or slip (k_t h = 0.1 N << mu |F_n|), and above the round-off of 1e10 N/m springs
            up, down = position.copy(), position.copy()
            up[j] += h
            down[j] -= h
            numeric[:, j] += c_u * (loads(up, rates) - loads(down, rates)) / (2 * h)
            h = max(abs(rates[j]), 1e-7) * 1e-6
            up, down = rates.copy(), rates.copy()
            up[j] += h
            down[j] -= h
            numeric[:, j] += c_v * (loads(position, up) - loads(position, down)) / (2 * h)
        worst = max(worst, np.abs(block - numeric).max() / np.abs(numeric).max())
    assert worst < 1e-6  # central differences: measured 1.6e-7 (1e-5 at h = 1e-13 m, round-off)


# A string on a straight horizontal wall


@pytest.mark.parametrize("feed_m_per_h", [1.0, 5.0, 20.0])
def test_a_string_sliding_without_rotation_drags_mu_n(feed_m_per_h):
    """Pushed at V0 without spin, every resting vertex slides axially: the drive pushes with mu sum |F_n|, plus the
    damping (38) of the rigid feed (c m V0).  1 m/h is 28 v_s: tanh is 1 to 1e-24.  Friction that never reverses
    does not damp the axial waves that its onset at t = 0 sends along the string, so the damping is raised to let
    them die out (ratio 0.025 on the first axial mode) before the window."""
    feed = feed_m_per_h / 3600.0
    scene = scene_with(*ON_THE_WALL, f"drive.axial_velocity={feed}", "drive.rotation_speed=0.0", "beam.damping=20.0")
    final, rows, model = run(scene, 0.5)
    _, normal, nodal, _ = wall_at(model, final)
    damping_force, _ = damping_loads(model, scene, feed, 0.0)
    expected = MU * np.sum(np.abs(normal)) + damping_force
    late = rows[rows[:, 0] > 0.3]
    assert np.mean(late[:, 1]) == pytest.approx(expected, rel=1e-2)  # the 1 %
    # the slip is axial: the vertices' lateral micro-vibrations tilt it by less than 1e-4 (measured 2e-7)
    assert np.sum(nodal[:, 0]) == pytest.approx(-MU * np.sum(np.abs(normal)), rel=1e-4)


def test_a_spinning_string_climbs_the_wall_until_friction_balances_gravity_and_feels_mu_n_r_ext():
    """Spun without feed, the contact point slips at R_ext Omega: the tangential friction mu |F_n| pushes the string
    up the wall until the weight's component along the wall balances it, tan(phi) = mu, and the wall's torque is
    mu R_ext sum |F_n|.  The damping (38) is raised so that the swing about phi dies out within the run."""
    scene = scene_with(*ON_THE_WALL, "beam.length=60.0", "beam.elements=120", "drive.axial_velocity=0.0",
                       "drive.rotation_speed=6.283185307179586", "beam.damping=20.0")
    final, rows, model = run(scene, 1.5)
    assert model.space.sparse  # the 'auto' rule takes the full order for a string that climbs
    x, normal, nodal, lateral = wall_at(model, final)
    angle = np.arctan2(-lateral[:, 0], -lateral[:, 1])  # a positive spin turns the contact point towards +v
    inner = (x > 20.0) & (x < 40.0)  # the flat resting length, away from the supports' bending (lift-off 7-9 m)
    assert np.mean(angle[inner]) == pytest.approx(math.atan(MU), rel=1e-2)
    torque = np.sum(nodal[:, 3])
    assert torque == pytest.approx(-MU * 0.08 * np.sum(np.abs(normal)), rel=1e-2)
    _, damping_torque = damping_loads(model, scene, 0.0, 2 * math.pi)
    assert rows[-1, 2] == pytest.approx(-torque + damping_torque, rel=1e-2)  # the drive turns against both


def test_a_string_spinning_while_it_slides_splits_mu_n_by_the_direction_of_slip():
    """Fed at V0 and spun so that R_ext Omega = V0: the slip points 45 degrees between the axis and the wall's
    tangent, and the drag and the torque are mu N V0 / |s| and mu N R_ext (R_ext Omega) / |s|."""
    radius, feed = 0.08, 0.1
    spin = feed / radius
    scene = scene_with(*ON_THE_WALL, f"drive.axial_velocity={feed}", f"drive.rotation_speed={spin}",
                       "beam.damping=20.0")
    final, rows, model = run(scene, 1.5)
    _, normal, nodal, _ = wall_at(model, final)
    total = np.sum(np.abs(normal))
    slip = math.hypot(feed, radius * spin)
    damping_force, damping_torque = damping_loads(model, scene, feed, spin)
    assert rows[-1, 1] == pytest.approx(MU * total * feed / slip + damping_force, rel=2e-2)
    assert rows[-1, 2] == pytest.approx(MU * total * radius * (radius * spin) / slip + damping_torque, rel=2e-2)


def test_a_pipe_rolling_on_the_wall_whirls_backward_at_r_ext_omega_over_r():
    """A pinned 10 m pipe spun at 10 rad/s, without gravity, bent onto the wall in its first mode and set orbiting
    as rolling without slip would have it: the contact point at rest on the wall needs the centre at radius r to
    orbit at -R_ext Omega / r, backward.  The centrifugal load of that whirl (53 rad/s, above the first bending
    frequency, 24 rad/s) keeps it on the wall, and friction keeps it rolling."""
    spin, radius = 10.0, 0.08
    scene = scene_with("contact.friction_model='coulomb'", "contact.sliding_velocity_scale=1e-5",
                       "beam.length=10.0", "beam.elements=20", "model.supports='pinned'", "model.gravity=false",
                       "model.bit_rock=false", "drive.axial_velocity=0.0", f"drive.rotation_speed={spin}",
                       "contact.friction=0.3", "reduction.rule='none'", "output.field_interval=0")
    prepared = prepare(scene, dynamics=False)
    model = prepared.model
    disc = model.disc
    gap = scene.borehole.radius - radius
    x_w = disc.dof_coordinates[disc.field_dofs[W]]
    shape = lambda x: np.sin(np.pi * x / scene.beam.length)  # noqa: E731
    q0 = np.zeros(disc.ndofs)
    q0[disc.field_dofs[W]] = -(gap + 2e-7) * shape(x_w)
    whirl_rate = -radius * spin / gap
    qd = model.space.expand(model.drive_velocity_field())  # the spin
    qd[disc.field_dofs[V]] = -whirl_rate * q0[disc.field_dofs[W]]  # d/dt (v, w) = whirl_rate (-w, v)
    simulation = Simulation(model, scene)
    state = simulation.initial_state(model.space.project(q0), model.space.project(qd))
    section = int(np.argmin(np.abs(disc.vertex_x - scene.beam.length / 2)))
    picks = [model.lateral_rows[0][[section]], model.lateral_rows[1][[section]],
             model.space.rows(disc.vertex_dofs(THETA_X))[[section]]]
    rows = []

    def keep(record):
        s = record.state
        v, w, _ = (float(np.ravel(p @ s.q)[0]) for p in picks)
        dv, dw, dtx = (float(np.ravel(p @ s.qd)[0]) for p in picks)
        rows.append((s.t, v, w, dv, dw, dtx))

    simulation.run(state, 0.3, keep)
    t, v, w, dv, dw, dtx = np.array(rows).T
    result = whirl(t, v, w, dv, dw, dtx, gap, radius)
    assert result["direction"] == "backward"
    assert result["rolling_share"] > 0.9
    r = np.mean(np.hypot(v, w)[t > t[-1] / 2])
    assert result["frequency_hz"] == pytest.approx(radius * spin / r / (2 * math.pi), rel=2e-2)


def test_the_energy_budget_books_the_coulomb_force_and_closes():
    """Spun and fed on the wall without Newmark's numerical damping (alpha = 0): the drive's work equals the change
    of energy plus what the damping (38), the wall's damper and the two parts of the Coulomb force took, each booked
    under its name, to the step's truncation (measured 1.7e-6; 3e-4 leaves room for the adaptive steps)."""
    scene = scene_with(*ON_THE_WALL, "drive.axial_velocity=0.05", "drive.rotation_speed=3.0",
                       "time.newmark_alpha=0.0")
    prepared = prepare(scene, dynamics=False)
    simulation = Simulation(prepared.model, scene)
    simulation.run(simulation.initial_state(prepared.equilibrium.q), 0.3)
    budget = simulation.budget
    work = budget.work_by_law
    assert work["wall_friction_axial"] < 0 and work["wall_friction_tangential"] < 0  # friction only takes
    assert budget.balance_error < 3e-4
