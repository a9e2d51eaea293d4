"""The pointwise force laws (16)-(22) in their physically consistent form (docs/errata.md)."""

import numpy as np
import pytest

from fenics_drill.model.forces import bit_rock
from fenics_drill.model.forces.wall import normal_force, paper_friction

VELOCITIES = np.concatenate([-np.logspace(-6, 1, 50), [0.0], np.logspace(-6, 1, 50)])


def test_wall_friction_never_does_positive_work():
    """Over a sweep of u_dot, theta_x_dot of both signs and contact states, F_a u_dot <= 0 and T theta_x_dot <= 0."""
    delta = np.array([-1e-3, 0.0, 1e-6, 1e-4, 2e-3])[:, None]
    delta_rate = np.array([-0.5, 0.0, 0.5])[:, None, None]
    normal = normal_force.hunt_crossley_normal_force(delta, delta_rate, 1e10, 1e16, 1e6)
    assert np.all(normal <= 0)
    for vel in VELOCITIES:
        force, torque = paper_friction.wall_friction(normal, vel, vel * 50, 0.25, 0.095, 1e-4)
        assert np.all(force * vel <= 0) and np.all(torque * vel * 50 <= 0)


def test_bit_rock_force_and_torque_never_do_positive_work():
    for u_dot in VELOCITIES:
        force = bit_rock.bit_rock_force(u_dot, 30e3, 400.0)
        assert force * u_dot <= 0
        for omega in VELOCITIES * 10:
            torque = bit_rock.bit_rock_torque(force, omega, 0.4, 0.095)
            assert torque * omega <= 0


def test_hunt_crossley_damper_dissipates_and_has_force_units():
    """With c |delta|^3 delta_dot, c in N s / m^4 gives newtons; the damper opposes delta_dot."""
    c, delta, rate = 1e6, 1e-3, 0.1  # springs off to isolate the damper
    approaching = normal_force.hunt_crossley_normal_force(delta, rate, 0.0, 0.0, c)
    assert approaching == pytest.approx(-c * delta**3 * rate, rel=1e-14)
    assert approaching * rate < 0
    # receding, the bare damper would pull towards the wall: the law clips it to zero
    assert normal_force.hunt_crossley_normal_force(delta, -rate, 0.0, 0.0, c) == 0.0


def test_printed_damper_grows_with_the_impact_speed_and_still_dissipates():
    """As printed, (17)'s damper is c |delta_dot|^3 delta_dot: independent of the indentation, quartic in
    the speed, and opposing it; its derivatives are the closed forms 0 and -4 c |delta_dot|^3."""
    c, rate = 1e6, np.array([-0.3, -1e-3, 0.0, 2e-2, 0.5])
    # the same arithmetic as the law, a few float operations apart: 1e-14 is round-off
    for delta in (1e-6, 1e-3):
        force, by_delta, by_rate = normal_force.hunt_crossley_damper(delta, rate, c, "printed")
        np.testing.assert_allclose(force, -c * np.abs(rate) ** 3 * rate, rtol=1e-14)
        assert np.all(force * rate <= 0)
        np.testing.assert_allclose(by_delta, 0.0)
        np.testing.assert_allclose(by_rate, -4 * c * np.abs(rate) ** 3, rtol=1e-14)
    # at an impact of 0.5 m/s and 0.1 mm indentation the printed damper is 10^12 times the consistent one
    printed = normal_force.hunt_crossley_damper(1e-4, 0.5, c, "printed")[0]
    consistent = normal_force.hunt_crossley_damper(1e-4, 0.5, c, "consistent")[0]
    assert printed / consistent == pytest.approx(0.5**3 / 1e-12, rel=1e-12)  # a ratio of two products: round-off


def test_the_regularised_sign_is_tanh_to_the_last_bit_where_it_saturates_too():
    """The friction's sgn skips tanh where it rounds to +-1 (|x / v_s| > SATURATED): over 1e-3 to 1e300 of
    either sign, and at NaN, it returns exactly what the compiled tanh returns (NumPy's own tanh may differ
    from LLVM's by an ulp, which is not what this checks)."""
    from numba import njit

    sign = njit(lambda x, scale: paper_friction._regularised_sign(x, scale))
    tanh = njit(lambda x, scale: np.tanh(x / scale))
    ratios = np.concatenate(([0.0], np.geomspace(1e-3, 1e300, 20000)))
    for x in np.concatenate((ratios, -ratios)) * 1e-3:
        assert sign(x, 1e-3) == tanh(x, 1e-3)
    assert np.isnan(sign(np.nan, 1e-3))


def test_the_paper_bit_torque_in_a_well_turns_on_the_hole_the_bit_drills():
    """A scene whose well gives its hole leaves ``borehole.radius`` unused (95 mm by default); the bit torque (21),
    T = -mu_BR |F_BR| R_bh xi(omega), takes the well's hole at the bit as R_bh (here 4.25 in, the build-and-hold
    well's), in the finite-element model's law and in the axial-torsional string's compiled one.  At the bit cutting at
    V0 and spinning at Omega, T / (-mu_BR F_BR xi(Omega)) is that radius to round-off (1e-12: one product and one
    quotient of the same doubles)."""
    import math

    import fenics_drill as fd
    from fenics_drill.model.axial_torsional_string import axial_torsional_string
    from fenics_drill.model.drillstring import build_model
    from fenics_drill.studies.stick_slip import _bit_law

    scene = fd.load_scene("demos/scenes/well_build_hold.toml", [
        "bit_rock.law='paper'", "drive.weight_on_bit='20 kN'", "model.lateral_length=0.0", "beam.elements=30"])
    hole = 4.25 * 0.0254
    assert scene.borehole.radius != pytest.approx(hole)  # the default, which the well leaves unused
    v0, omega, b = scene.drive.axial_velocity, scene.drive.rotation_speed, scene.bit_rock
    expected = -b.friction * bit_rock.bit_rock_force(v0, b.limit_force, b.rate) * float(
        bit_rock.torque_regularisation(omega))
    model = build_model(scene)
    law = model.force("bit_rock")
    rows = model.bit_rows.toarray() if hasattr(model.bit_rows, "toarray") else model.bit_rows  # q -> u(L), theta_x(L)
    qd = np.linalg.lstsq(rows, np.array([v0, omega]), rcond=None)[0]  # the bit at (V0, Omega)
    evaluated = law.evaluate(np.zeros(model.size), qd)
    assert -evaluated.torque / expected == pytest.approx(hole, rel=1e-12)
    kind, constants = _bit_law(scene, axial_torsional_string(scene))
    force, torque, *_ = bit_rock.LAW(v0, omega, *constants[:4])
    assert -torque / expected == pytest.approx(hole, rel=1e-12) and math.isfinite(force)
