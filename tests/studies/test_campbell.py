"""The spinning string's modes (critical-speed analysis) against closed forms.

* a pinned-pinned beam under axial compression P: f_n(P) = f_n(0) sqrt(1 - P / (n^2 P_cr)), P_cr = pi^2 EI / L^2;
* the forward/backward split of a spinning pinned-pinned Timoshenko shaft (frequency equation of
  Lalanne & Ferraris, Rotordynamics Prediction in Engineering, 2nd ed., Wiley 1998, Ch. 3, and
  Genta, Dynamics of Rotating Systems, Springer 2005, Sec. 5.4, with rotary inertia and shear);
* at Omega = 0 and P = 0, today's modal analysis held by the drive;
* a string lying in a horizontal hole: the sideways pendulum f = sqrt(g / gap) / 2 pi, which the
  axial load lowers towards zero at the Dawson-Paslay load 2 sqrt(EI w / gap) (Dawson & Paslay,
  J. Pet. Tech. 36 (1984) 1734-1738);
* a stabiliser at mid-span makes the first mode that of a pinned beam of half the length.
"""

import math

import numpy as np
import pytest
from conftest import PAPER

from fenics_drill.model.discretization import DRIVE, BeamDiscretization
from fenics_drill.model.reduction.modes import solve_modes
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.rotating_modes import held_space, linearise_about_spin, solve_whirl_modes
from fenics_drill.scene import load_scene
from fenics_drill.studies.campbell import CampbellError, campbell_report, critical_speeds

#: A bare string: no gravity, wall or bit; pinned-pinned.
BARE = ["model.gravity=false", "model.contact=false", "model.bit_rock=false", "model.supports=pinned"]


def bare_scene(length, elements, *extra):
    return load_scene(PAPER, [f"beam.length={length}", f"beam.elements={elements}", *BARE, *extra])


def lateral(report, at=0):
    """Frequencies of the flexural branches at speed index ``at``."""
    return np.array([b["frequency_hz"][at] for b in report["branches"] if b["kind"][at] == "flexural"])


def test_axial_compression_lowers_the_pinned_frequencies_as_the_euler_formula_says():
    length = 20.0
    base = bare_scene(length, 60, "campbell.rotation_speed=[0, 0, 1]", "campbell.modes=6")
    p = base.beam_properties
    critical = math.pi**2 * p.young_modulus * p.section.I4 / length**2
    unloaded = lateral(campbell_report(base))[::2]  # each frequency twice (v and w)
    loaded = lateral(campbell_report(base.with_changes(campbell={"axial_force": 0.5 * critical})))[::2]
    for n in (1, 2, 3):
        expected = math.sqrt(1.0 - 0.5 / n**2)
        # 1e-3: the Euler formula leaves out shear and the prestrain P / EA (1e-4 at L / r = 270)
        assert loaded[n - 1] / unloaded[n - 1] == pytest.approx(expected, rel=1e-3)


def test_a_compression_beyond_the_buckling_load_is_refused_as_divergence():
    """1.2 times the pinned-pinned Euler load pi^2 E I / L^2: the tangent about the straight state has a negative
    eigenvalue, so the string is buckled and has no critical speed; refused before the sweep, naming the mode and
    where it bends most (the pinned-pinned column's first mode: at mid-span)."""
    length = 20.0
    scene = bare_scene(length, 40, "campbell.rotation_speed=[0, 0, 1]", "campbell.modes=2")
    p = scene.beam_properties
    critical = math.pi**2 * p.young_modulus * p.section.I4 / length**2
    with pytest.raises(CampbellError, match=r"buckled under .*the first, flexural, bends most at x = 10 m"):
        campbell_report(scene.with_changes(campbell={"axial_force": 1.2 * critical}))


def timoshenko_whirl(p, length, n, spin):
    """(forward, backward) first-branch whirl frequencies [Hz] of mode n of a pinned-pinned spinning
    Timoshenko shaft.  With r = v + i w = R sin(kx) e^{i omega t}, the tilt theta_z - i theta_y =
    Phi cos(kx) e^{i omega t} and the gyroscopic moment -i rho Ip Omega Phi_dot:
    (kGA k^2 - rho A omega^2)(EI k^2 + kGA - rho I omega^2 + rho Ip Omega omega) - (kGA k)^2 = 0.
    A root omega > 0 turns with the spin (forward), omega < 0 against it (backward)."""
    s = p.section
    k = n * math.pi / length
    kGA = p.shear_factor * p.shear_modulus * s.area
    EI, rA, rI, rIp = p.young_modulus * s.I4, p.density * s.area, p.density * s.I4, 2 * p.density * s.I4
    a, b, c, d, e = kGA * k**2, rA, EI * k**2 + kGA, rI, rIp * spin
    roots = np.roots([b * d, -b * e, -(a * d + b * c), a * e, a * c - kGA**2 * k**2])
    real = roots[np.abs(roots.imag) < 1e-9 * np.abs(roots)].real
    return real[real > 0].min() / (2 * math.pi), -real[real < 0].max() / (2 * math.pi)


def test_a_spinning_timoshenko_shaft_splits_into_forward_and_backward_whirl_as_the_closed_form():
    length, spin = 2.0, 3000.0  # a short thick shaft spun fast: the split is 5 % of the frequency
    scene = bare_scene(length, 80, f"campbell.rotation_speed=[0, {spin}, 2]", "campbell.modes=9")
    report = campbell_report(scene)
    p = scene.beam_properties
    spinning = sorted((b["frequency_hz"][1], b["whirl"][1]) for b in report["branches"] if b["kind"][1] == "flexural")
    for n in (1, 2, 3):
        forward, backward = timoshenko_whirl(p, length, n, spin)
        by_whirl = {whirl: f for f, whirl in spinning[2 * (n - 1): 2 * n]}
        assert set(by_whirl) == {"forward", "backward"}
        # the discretisation error is O((n pi h / L)^2): 6e-5 for n = 1 at 80 quadratic elements (measured,
        # Omega = 0), so 1.5e-4 n^2; the split itself is 5e-2 of the frequency
        tolerance = 1.5e-4 * n**2
        assert by_whirl["forward"] == pytest.approx(forward, rel=tolerance)
        assert by_whirl["backward"] == pytest.approx(backward, rel=tolerance)
        assert forward > backward  # gyroscopic stiffening of forward whirl
        at_rest = timoshenko_whirl(p, length, n, 0.0)[0]
        assert lateral(report)[2 * (n - 1)] == pytest.approx(at_rest, rel=tolerance)


def test_the_printed_angular_velocity_reverses_the_gyroscopic_coupling():
    length, spin = 2.0, 3000.0
    scene = bare_scene(length, 80, f"campbell.rotation_speed=[{spin}, {spin}, 1]", "campbell.modes=2",
                       "model.angular_velocity=printed")
    forward, backward = timoshenko_whirl(scene.beam_properties, length, 1, spin)
    by_whirl = {b["whirl"][0]: b["frequency_hz"][0] for b in campbell_report(scene)["branches"]}
    # printed Eq. (13): the forward whirl takes the backward frequency and vice versa (docs/errata.md);
    # 1.5e-4 as in the test above
    assert by_whirl["forward"] == pytest.approx(backward, rel=1.5e-4)
    assert by_whirl["backward"] == pytest.approx(forward, rel=1.5e-4)


def test_at_rest_the_modes_are_those_of_the_modal_analysis_held_by_the_drive():
    scene = load_scene(PAPER, ["beam.length=30", "beam.elements=40", "campbell.rotation_speed=[0, 0, 1]",
                               "campbell.modes=12"])
    report = campbell_report(scene)
    disc = BeamDiscretization.from_scene(scene)
    modes = solve_modes(disc, scene.modal.f_star_max, assemble_linear(disc).mass, held=DRIVE)
    ours = np.array([b["frequency_hz"][0] for b in report["branches"]])
    # the same discrete problem solved by two eigensolvers (GHEP and PEP): agreement to their tolerance
    np.testing.assert_allclose(ours, modes.frequencies_hz[:12], rtol=1e-7)
    assert [b["kind"][0] for b in report["branches"]] == modes.kinds[:12]


def test_the_linearised_stiffness_does_not_depend_on_the_spin_and_the_gyroscopic_term_is_linear_in_it():
    scene = load_scene(PAPER, ["beam.length=10", "beam.elements=20"])
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    space = held_space(disc)
    rng = np.random.default_rng(3)
    state = 1e-3 * rng.standard_normal(disc.ndofs)  # a bent, twisted, stretched string
    from fenics_drill.model.internal_force import internal_force
    from fenics_drill.model.rotating_modes import spin_velocity

    internal = internal_force(disc, space, operators, scene.model)
    parts = {}
    for spin in (0.0, 1.0, 50.0):
        q0 = space.project(state)
        internal.evaluate(q0, space.project(spin_velocity(disc, spin)), np.zeros_like(q0))
        parts[spin] = internal.tangent_parts()
    K0, K50 = parts[0.0][0], parts[50.0][0]
    assert abs(K50 - K0).max() <= 1e-12 * abs(K0).max()  # no spin softening in the energies
    D0, D1, D50 = parts[0.0][1], parts[1.0][1], parts[50.0][1]
    gyro = D1 - D0
    assert abs(gyro).max() > 0
    assert abs((D50 - D0) - 50.0 * gyro).max() <= 1e-10 * abs(50.0 * gyro).max()
    assert abs(gyro + gyro.T).max() <= 1e-12 * abs(gyro).max()  # skew: does no work
    assert abs(D0 - D0.T).max() <= 1e-12 * abs(D0).max()  # the dissipation (38) is symmetric


def on_the_wall(*extra):
    return load_scene(PAPER, ["beam.length=100", "beam.elements=200", "campbell.state=static",
                              "campbell.rotation_speed=[0, 0, 1]", "campbell.modes=1", *extra])


def test_a_string_lying_in_a_horizontal_hole_swings_sideways_as_a_pendulum_and_buckles_at_dawson_paslay():
    scene = on_the_wall()
    p = scene.beam_properties
    gap = scene.borehole.radius - p.outer_radius
    report = campbell_report(scene)
    assert report["steady_state"]["vertices_on_the_wall"] > 100  # most of the 201 vertices rest on the wall
    pendulum = math.sqrt(p.gravity / gap) / (2 * math.pi)
    # 1e-3: the bending of the sideways mode adds EI k^4 with k ~ pi / 80 m (4e-4), the ends held off the wall
    assert report["branches"][0]["frequency_hz"][0] == pytest.approx(pendulum, rel=1e-3)
    # Dawson-Paslay: sideways waves of wavenumber k have m omega^2 = EI k^4 - P k^2 + w / gap, lowest
    # at k^2 = P / 2EI: omega^2 = (w / gap - P^2 / 4EI) / m, zero at P_DP = 2 sqrt(EI w / gap)
    EI, w = p.young_modulus * p.section.I4, p.mass_per_length * p.gravity
    dawson_paslay = 2.0 * math.sqrt(EI * w / gap)
    frequency = {}
    for share in (0.3, 0.9):
        load = share * dawson_paslay
        loaded = campbell_report(scene.with_changes(campbell={"axial_force": load}))
        expected = math.sqrt((w / gap - load**2 / (4 * EI)) / p.mass_per_length) / (2 * math.pi)
        frequency[share] = (loaded["branches"][0]["frequency_hz"][0], expected)
    # the formula is the limit of an endless string; this one is 100 m with its ends held at the centre,
    # 8 m off the wall each: measured 0.6 % above it at 0.3 P_DP (1.6 % at 0.6, 4.5 % at 0.9)
    assert frequency[0.3][0] == pytest.approx(frequency[0.3][1], rel=0.01)
    # near the load the sideways mode goes soft: sqrt(1 - 0.81) = 0.44 of the pendulum in the limit
    assert frequency[0.9][0] < 0.5 * pendulum


def test_a_stabiliser_at_mid_span_gives_the_first_mode_of_the_half_span():
    length = 20.0
    whole = campbell_report(bare_scene(length, 40, "campbell.rotation_speed=[0, 0, 1]", "campbell.modes=4"))
    held = campbell_report(bare_scene(length, 40, "campbell.rotation_speed=[0, 0, 1]", "campbell.modes=2",
                                      f"supports.stabilisers=[{length / 2}]"))
    assert held["stabilisers_m"] == [length / 2]
    # pinned at mid-span the first mode is the second of the whole span (antisymmetric, node at L/2)
    assert held["branches"][0]["frequency_hz"][0] == pytest.approx(whole["branches"][2]["frequency_hz"][0],
                                                                   rel=1e-9)


def test_critical_speeds_are_where_a_branch_meets_the_excitation_line():
    speeds = np.linspace(0.0, 10.0, 11)
    branch = 0.5 + 0.01 * speeds  # Hz; meets 1 x Omega / 2 pi at Omega = 2 pi 0.5 / (1 - 0.02 pi)
    found = critical_speeds(speeds, branch[:, None], [["forward"]] * 11, [["flexural"]] * 11, [1.0])
    assert len(found) == 1
    assert found[0]["speed_rad_s"] == pytest.approx(2 * math.pi * 0.5 / (1 - 0.02 * math.pi), rel=1e-12)
    assert found[0]["frequency_hz"] == pytest.approx(0.5 + 0.01 * found[0]["speed_rad_s"], rel=1e-12)
