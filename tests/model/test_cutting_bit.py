"""The cutting bit law (Richard, Germay & Detournay 2007): its delay buffer, its tangent, and steady
drilling against the law's closed form."""

import math

import numpy as np
import pytest
from conftest import scene_with

from fenics_drill.model.drillstring import build_model
from fenics_drill.model.forces.cutting_bit import CutSurface
from fenics_drill.solvers.time_loop import Simulation

BLADES = 4
PASSAGE = 2.0 * math.pi / BLADES


def prescribed_motion(t):
    """A bit turning at a non-uniform rate (never backwards) while advancing unevenly (never lifting off)."""
    angle = 2.0 * t + 0.8 * np.sin(1.3 * t)  # rate 2 - 1.04 > 0
    position = 1e-3 * t + 2e-4 * np.sin(3.1 * t) + 1e-4 * t**2  # rate 1e-3 - 6.2e-4 > 0
    return angle, position


def test_the_cut_surface_returns_the_position_one_blade_passage_ago():
    """Sampled at angles one passage / 8 apart (so every query falls on a stored angle) over 500 passages,
    past the buffer's compactions (it starts with room for 1024 entries): the surface one passage behind is the bit's position at the
    earlier angle to round-off; before the first sample, the steady drilling at the feed."""
    times = np.linspace(0.0, 400.0, 200001)
    angle_of_time, position_of_time = prescribed_motion(times)
    step = PASSAGE / 8
    sampled_angles = np.arange(0.0, angle_of_time[-1], step)
    sampled_times = np.interp(sampled_angles, angle_of_time, times)  # angle(t) is increasing
    positions = prescribed_motion(sampled_times)[1]
    feed = 1e-3 / 2.0
    surface = CutSurface(BLADES, sampled_angles[0], positions[0], feed)
    # before the first sample: the steady-drilling line S0 - (angle0 - angle) feed, one multiplication
    # (the value is 8e-4 m, so 1e-15 m is round-off)
    assert surface.previous_pass(0.0)[0] == pytest.approx(-PASSAGE * feed, abs=1e-15)
    errors = []
    for k in range(1, len(sampled_angles)):
        surface.advance(sampled_angles[k], positions[k])
        if k >= 8:
            errors.append(surface.previous_pass(sampled_angles[k])[0] - positions[k - 8])
    assert len(sampled_angles) > 3 * 1024
    # interpolation at a stored angle returns the stored value; only the angle arithmetic rounds
    assert np.max(np.abs(errors)) < 1e-15 * np.max(positions) * 100


def test_a_bit_off_the_bottom_leaves_the_surface_and_cuts_nothing():
    """The bit lifts off for one passage: the surface it passes over stays the one below it, so the next
    blade meets the older, deeper cut (S = max(u, S one passage before))."""
    surface = CutSurface(BLADES, 0.0, 0.0, 0.0)
    angles = np.arange(1, 25) * PASSAGE / 4
    positions = 1e-3 * angles
    positions[8:12] -= 5e-3  # off the bottom between angles 9 and 12 (quarter passages)
    for a, u in zip(angles, positions):
        surface.advance(a, u)
    # at angle 11 (off bottom) the surface is what the blade one passage before left at angle 7; both are
    # stored values, so equal up to the round-off of the interpolation weights (1e-12 relative)
    assert surface.at(angles[10])[0] == pytest.approx(positions[6], rel=1e-12)
    assert surface.at(angles[6])[0] == pytest.approx(positions[6], rel=1e-12)


@pytest.fixture(scope="module")
def cutting_model():
    scene = scene_with("beam.length=10.0", "beam.elements=10", "reduction.rule='none'", "model.gravity=false",
                       "model.contact=false", "bit_rock.law='detournay'", "beam.damping=200.0", "time.dt=1e-3",
                       "time.t_end=1.0")
    return scene, build_model(scene)


def test_the_cutting_law_tangent_matches_finite_differences(cutting_model):
    """c_u df/dq + c_v df/dqd against central differences of the generalised force, at states inside each
    smooth piece of the regularised law: cutting with full contact, in the contact-velocity and spin ramps,
    and with the surface's slope (the delay's d(depth)/d(angle))."""
    scene, model = cutting_model
    bit = model.force("bit_rock").fresh()
    rows = bit.rows.dense()
    q0 = np.zeros(model.size)
    bit.begin(0.0, q0)
    angles = np.linspace(0.05, 2.0, 40)
    for a in angles:  # a wavy surface, so that the slope is not the feed
        bit.surface.advance(a, 1e-3 * a + 2e-4 * np.sin(7 * a))
    v_c, spin_c = scene.bit_rock.contact_velocity, scene.bit_rock.contact_velocity / scene.bit_rock.bit_radius
    rng = np.random.default_rng(7)
    # (u above the surface one passage behind [m], u_dot [m/s], omega [rad/s]) at the bit
    cases = [(2e-3, 5e-3, 6.0), (1.5e-3, 0.4 * v_c, 6.0), (2e-3, 5e-3, 0.3 * spin_c), (3e-4, 0.7 * v_c, -0.5 * spin_c)]
    pinv = np.linalg.pinv(rows)
    for over, u_dot, omega in cases:
        phi = 2.0 + PASSAGE * 0.37  # one passage back lies on the recorded surface
        cut = bit.surface.previous_pass(phi)[0]
        q = rng.normal(scale=1e-6, size=model.size)
        q += pinv @ (np.array([cut + over, phi]) - rows @ q)
        qd = rng.normal(scale=1e-6, size=model.size)
        qd += pinv @ (np.array([u_dot, omega]) - rows @ qd)
        ev = bit.evaluate(q, qd, with_tangent=True)
        for c_u, c_v in ((1.0, 0.0), (0.0, 1.0)):
            analytic = bit.tangent(ev, c_u, c_v)
            analytic = analytic.toarray() if hasattr(analytic, "toarray") else analytic
            direction = pinv @ rng.normal(size=2)
            h = 1e-9 if c_u else 1e-9 * min(v_c, spin_c)
            plus = bit.evaluate(q + c_u * h * direction, qd + c_v * h * direction).generalised
            minus = bit.evaluate(q - c_u * h * direction, qd - c_v * h * direction).generalised
            numeric = (plus - minus) / (2 * h)
            # central differences of a force of 1e4 N with h ~ 1e-9: round-off ~ 1e-16 * 1e4 / 1e-9 relative
            # to a derivative of ~1e7 N/m, i.e. ~1e-6
            assert np.allclose(analytic @ direction, numeric, rtol=1e-5, atol=1e-6 * np.abs(numeric).max()), \
                (over, u_dot, omega, c_u, c_v)


def test_steady_drilling_gives_the_law_closed_form(cutting_model):
    """A short, stiff, well-damped string (10 m, c = 200 1/s) driven at V0 = 1/180 m/s, Omega = 2 pi rad/s:
    after the start-up the time-averaged bit force and torque are the law's steady values at the depth of
    cut d = 2 pi V0 / Omega per revolution,
        W = zeta eps a d + sigma a l,   T = eps a^2 d / 2 + mu gamma a sigma a l / 2
    (forces on the string: -W on u(L), -T on theta_x(L)).  Measured 1e-4 over [0.5, 1] s, where the
    remaining axial oscillation is +-7 % of V0; 1e-3 leaves room for its phase at the window's ends."""
    scene, model = cutting_model
    simulation = Simulation(model, scene)
    start = simulation.initial_state(np.zeros(model.size))
    rows = []

    def on_step(record):
        bit = record.evaluation.forces["bit_rock"]
        rows.append((record.state.t, bit.force, bit.torque, bit.depth_of_cut))

    simulation.run(start, scene.time.t_end, on_step)
    t, force, torque, depth = np.array(rows).T
    late = t >= 0.5
    mean = [np.trapezoid(x[late], t[late]) / (t[late][-1] - t[late][0]) for x in (force, torque, depth)]
    b, drive = scene.bit_rock, scene.drive
    d = 2.0 * math.pi * drive.axial_velocity / drive.rotation_speed
    contact = b.contact_strength * b.bit_radius * b.wear_flat_length
    W = b.cutting_orientation * b.specific_energy * b.bit_radius * d + contact
    T = b.specific_energy * b.bit_radius**2 * d / 2 + b.friction * b.geometry_factor * b.bit_radius * contact / 2
    assert mean[2] == pytest.approx(d, rel=1e-3)
    assert -mean[0] == pytest.approx(W, rel=1e-3)
    assert -mean[1] == pytest.approx(T, rel=1e-3)
    assert simulation.budget.balance_error < 1e-4  # the law's work is booked (measured 2e-6)


def test_a_bit_held_against_turning_backwards_keeps_the_free_law_and_a_damper_on_its_backward_spin():
    """``bit_rock.backward_spin = 'held'``: the law's force and torque as when free, plus -c_h omega on the torque
    while omega < 0 (c_h = 1e6 N m s), its derivative too; at a forward spin the two laws are the same numbers.  On
    the 2000 m vertical string at 60 kN and 60 rpm, where the free bit turns backwards at tens of rad/s (the distributed
    model solved exactly does too, docs/guide/stick_slip_maps.md), the held bit's backward spin stays below 0.1 rad/s:
    the string's torque, under 20 kN m, over c_h is 0.02 rad/s."""
    import fenics_drill as fd
    from fenics_drill.model.forces.cutting_bit import HELD_BACKWARD_DAMPING, cutting_law, cutting_law_constants
    from fenics_drill.studies.stick_slip import start

    scene = fd.load_scene("demos/scenes/vertical_2000m.toml", ["beam.elements=200"])
    held_scene = scene.with_changes(bit_rock={"backward_spin": "held"})
    free, held = cutting_law_constants(scene.bit_rock), cutting_law_constants(held_scene.bit_rock)
    state = (1.0e-3, 2.0e-3, 0.0, 0.0)  # u 1 mm past the surface one passage behind, u_dot 2 mm/s; omega below
    for omega in (-0.3, 0.3, 5.0):
        a = cutting_law(state[0], state[1], omega, state[2], state[3], *free)
        b = cutting_law(state[0], state[1], omega, state[2], state[3], *held)
        extra = HELD_BACKWARD_DAMPING if omega < 0 else 0.0
        # 1e-12: the held torque is the free one plus one product, -c_h omega, in double precision (one rounding of
        # a sum whose terms are within a factor 1e3 of each other: 1e-13 at most)
        assert b[2] == pytest.approx(a[2] - extra * omega, rel=1e-12)
        assert b[9] == pytest.approx(a[9] - extra, rel=1e-12)
        assert b[:2] == a[:2] and b[3:9] == a[3:9]
    spins = [start(s).run(30.0)["bit_angular_velocity"] for s in (scene, held_scene)]
    assert spins[0].min() < -5.0
    assert spins[1].min() > -0.1


def test_the_kink_step_lands_just_past_the_first_kink_of_the_laws_ramps_along_an_update(cutting_model):
    """Newton's line search tries, after a failed full update, the step just past the first kink of the law along it
    (:meth:`CuttingBit.kink_step`): from states in each piece of the regularised law (cutting, in the contact-velocity
    ramp, in the spin ramp, off the surface) and updates that move the bit across one or more ramps, the branches of
    the three clipped ramps (spin, contact velocity, depth of cut) stay those of the state on [0, s - 1e-3] and have
    changed at s (sampled along the update: the rates move linearly with it, the depth with the surface's slope,
    which is constant between its recorded angles); an update that crosses none gives None."""
    scene, model = cutting_model
    bit = model.force("bit_rock").fresh()
    rows = bit.rows.dense()
    bit.begin(0.0, np.zeros(model.size))
    for a in np.linspace(0.05, 2.0, 40):
        bit.surface.advance(a, 1e-3 * a)
    b = scene.bit_rock
    v_c, spin_c, d_c = b.contact_velocity, b.contact_velocity / b.bit_radius, b.contact_depth
    pinv = np.linalg.pinv(rows)
    c_v = 2e3  # gamma / (beta dt) at dt = 1 ms

    def branches(ev):
        (u_dot, omega), (clearance, _) = ev.rates, ev.clearance
        return tuple(int(np.searchsorted([lo, hi], x, side="right")) for x, lo, hi in
                     ((omega / spin_c, -1, 1), (u_dot / v_c, 0, 1), (b.blades * clearance / d_c, 0, 1)))

    phi = 2.0 + PASSAGE * 0.37
    cut = bit.surface.previous_pass(phi)[0]
    # (u - S, u_dot, omega) at the bit, and the update's (du, dphi)
    cases = [((2e-3, 5e-3, 6.0), (0.0, -4.0 * 6.0 / c_v)),  # spinning to backwards past both spin kinks
             ((2e-3, 0.5 * v_c, 0.3 * spin_c), (-3.0 * v_c / c_v, 2.0 * spin_c / c_v)),  # two ramps left at once
             ((-1e-4, -1e-3, 6.0), (2e-4, 0.0)),  # off the surface, onto it
             ((0.5 * d_c / b.blades, 2.0 * v_c, 6.0), (-d_c / b.blades, 0.0)),  # in the depth ramp, leaving it
             ((2e-3, 5e-3, 6.0), (0.0, 1e-4))]  # inside one piece: no kink
    kinks = 0
    for (over, u_dot, omega), (du, dphi) in cases:
        q, qd = pinv @ np.array([cut + over, phi]), pinv @ np.array([u_dot, omega])
        dq = pinv @ np.array([du, dphi])
        ev = bit.evaluate(q, qd)
        s = bit.kink_step(ev, dq, c_v)
        along = [branches(bit.evaluate(q + t * dq, qd + c_v * t * dq)) for t in np.linspace(0.0, 1.0, 2001)]
        if s is None:
            assert len(set(along)) == 1, (over, u_dot, omega)
            continue
        kinks += 1
        start = branches(ev)
        assert branches(bit.evaluate(q + max(s - 1e-3, 0.0) * dq, qd + c_v * max(s - 1e-3, 0.0) * dq)) == start
        assert branches(bit.evaluate(q + s * dq, qd + c_v * s * dq)) != start
    assert kinks == 4
