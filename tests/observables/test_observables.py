"""Observables of a run: von Mises stress against closed forms, drilling
quantities of synthetic time series with known answers, spectra of sums of sinusoids."""

import numpy as np
import pytest
from conftest import scene_with

from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.observables import drilling_quantities as dq
from fenics_drill.observables.spectra import (dominant_period, event_rate, power_spectral_density, resample,
                                             spectral_peaks, to_db, uniform_grid)
from fenics_drill.observables.von_mises import VonMisesProbe


@pytest.fixture(scope="module")
def disc():
    return BeamDiscretization.from_scene(scene_with("beam.length=10", "beam.elements=8"))


def state(disc, **fields):
    """Dofs of the fields given as functions of x (u, v, w, tx, ty, tz)."""
    names = ("u", "v", "w", "tx", "ty", "tz")
    x = disc.dof_coordinates
    dofs = np.zeros(disc.ndofs)
    for i, name in enumerate(names):
        if name in fields:
            dofs[disc.field_dofs[i]] = fields[name](x)[disc.field_dofs[i]]
    return dofs


def cantilever(disc, kappa0):
    """A cantilever bent by a tip load as the elements hold it: theta_z, the P1 interpolant of
    kappa0 (x - x^2 / 2L), and v its integral (piecewise quadratic, held exactly), so no shear strain; its
    curvature kappa0 (1 - x / L) falls linearly from x = 0, and each element carries its mean."""
    L = disc.properties.length
    vertices = np.unique(disc.vertex_x)
    h = np.diff(vertices)
    slope = kappa0 * (vertices - 0.5 * vertices**2 / L)  # theta_z = v' at the vertices

    def theta_z(x):
        return np.interp(x, vertices, slope)

    def v(x):
        k = np.clip(np.searchsorted(vertices, x, side="right") - 1, 0, len(h) - 1)
        at_vertices = np.concatenate(([0.0], np.cumsum(0.5 * h * (slope[:-1] + slope[1:]))))
        return at_vertices[k] + 0.5 * (x - vertices[k]) * (slope[k] + theta_z(x))

    return state(disc, v=v, tz=theta_z)


def test_von_mises_of_uniform_axial_strain_is_e_times_green_lagrange_strain(disc):
    e = 2e-4
    p = disc.properties
    for nonlinear, strain in ((True, e + 0.5 * e**2), (False, e)):
        probe = VonMisesProbe(disc, geometric_nonlinearity=nonlinear)
        stress = probe.stress(state(disc, u=lambda x: e * x))
        np.testing.assert_allclose(stress, p.young_modulus * strain, rtol=1e-12)


def test_von_mises_of_pure_torsion_is_sqrt3_g_r_twist(disc):
    """theta_x = phi x: tau = G R phi on the outer fibre, plus the Green-Lagrange axial
    strain (R phi)^2 / 2 of the twisted fibre (Eqs. 34-36)."""
    phi = 1e-3
    p = disc.properties
    R = p.outer_radius
    probe = VonMisesProbe(disc)
    stress = probe.stress(state(disc, tx=lambda x: phi * x))
    exact = np.sqrt((p.young_modulus * 0.5 * (R * phi) ** 2) ** 2 + 3.0 * (p.shear_modulus * R * phi) ** 2)
    np.testing.assert_allclose(stress, exact, rtol=1e-12)


def test_von_mises_of_pure_bending_is_e_kappa_r_plus_the_green_lagrange_stretch(disc):
    """v = kappa x^2 / 2, theta_z = v' (no shear).  Linear strains: sigma = E kappa R on the outer
    fibre (y = -R is a sample point).  Green-Lagrange (34): the fibre also stretches by
    (kappa R)^2 / 2 + v'^2 / 2, largest at x = L; the shear it adds is ~1e-5 of sigma."""
    kappa = 1e-5
    p = disc.properties
    R, L, E = p.outer_radius, p.length, p.young_modulus
    bent = state(disc, v=lambda x: 0.5 * kappa * x**2, tz=lambda x: kappa * x)
    value, _ = VonMisesProbe(disc, geometric_nonlinearity=False).maximum(bent)
    assert value == pytest.approx(E * kappa * R, rel=1e-12)
    value, where = VonMisesProbe(disc).maximum(bent)
    assert value == pytest.approx(E * (kappa * R + 0.5 * kappa**2 * (R**2 + L**2)), rel=1e-4)
    assert where == pytest.approx(L)


def test_no_element_holds_more_stress_at_its_midpoint_than_at_its_ends(disc):
    """What lets maxima() sample the elements' ends only (von_mises module doc): with P2 displacements and P1
    rotations the linear strains are affine along an element, and sigma_VM on a line of the outer fibre, the
    norm of an affine function, is convex.  Exact for the linear strains; the quadratic terms of the other
    models could make the midpoint hold more, and on random states of every field from 1e-5 to 1e-1 (m, rad)
    they never do (measured: the midpoint's excess over the larger end is <= 0 in all 4000 states; the bound
    allows round-off only)."""
    rng = np.random.default_rng(11)
    for nonlinear, kinematics in ((False, "objective"), (True, "objective"), (True, "printed")):
        probe = VonMisesProbe(disc, geometric_nonlinearity=nonlinear, kinematics=kinematics)
        for amplitude in (1e-5, 1e-3, 1e-1):
            for _ in range(40):
                dofs = amplitude * rng.normal(size=disc.ndofs) * rng.uniform(0.0, 1.0, size=disc.ndofs) ** 4
                stress = probe.stress(dofs)  # (cells, [start, middle, end])
                excess = stress[:, 1] - stress[:, [0, 2]].max(axis=1)
                assert excess.max() <= 1e-12 * stress.max()


def test_the_fibre_bound_holds_the_stress_everywhere_on_the_fibre_and_is_exact_for_classic_loads():
    """The pruning bound of maxima() (_bound_at): on random strain polynomials it is at least sigma_VM^2 at 3600
    angles of the outer fibre (so it never prunes a section that holds the maximum); for an axial load, bending
    about any axis and torsion combined (eps_xx = e0 + ky y + kz z, (eps_xy, eps_xz) = gamma (-z, y) / 2) the
    shear's length is constant round the fibre and the bound is the stress itself, within its 1e-9 margin."""
    from fenics_drill.observables.von_mises import MONOMIALS, _bound_at

    rng = np.random.default_rng(5)
    radius, young, shear = 0.0635, 2.1e11, 8.1e10
    phi = np.linspace(0.0, 2.0 * np.pi, 3600, endpoint=False)
    y, z = radius * np.cos(phi), radius * np.sin(phi)
    monomials = np.stack([y**a * z**b for a, b in MONOMIALS])

    def on_fibre(c):
        exx, exy, exz = c[0] @ monomials, c[1] @ monomials, c[2] @ monomials
        return young**2 * exx**2 + 12.0 * shear**2 * (exy**2 + exz**2)

    for scale in (1e-6, 1e-3, 1.0):
        c = scale * rng.normal(size=(200, 3, 6)) * rng.uniform(0.0, 1.0, size=(200, 3, 6)) ** 3
        for p in range(len(c)):
            assert _bound_at(c, p, radius, young, shear) >= on_fibre(c[p]).max()
    classic = np.zeros((100, 3, 6))
    e0, ky, kz, gamma = rng.normal(size=(4, 100)) * np.array([[1e-4], [1e-3], [1e-3], [1e-3]])
    classic[:, 0, 0], classic[:, 0, 1], classic[:, 0, 2] = e0, ky, kz
    classic[:, 1, 2], classic[:, 2, 1] = -0.5 * gamma, 0.5 * gamma
    for p in range(len(classic)):
        # 3600 angles miss a bending peak by at most 1 - cos(pi / 3600)^2 ~ 8e-7
        assert _bound_at(classic, p, radius, young, shear) == pytest.approx(on_fibre(classic[p]).max(), rel=1e-6)


def test_the_pruned_maximum_is_the_maximum_over_every_sampled_section(disc):
    """maximum() samples only the elements' ends (the test above) and there only the sections whose bound
    reaches a sampled stress; on random states of every field (bending, torsion, shear, stretch mixed) it
    must find exactly what sampling every section at the elements' ends and the two recovered ends finds (the
    same arithmetic on the same points: equal to round-off), and maxima() of all the states at once what
    maximum() finds for each."""
    rng = np.random.default_rng(7)
    for nonlinear, kinematics in ((False, "objective"), (True, "objective"), (True, "printed")):
        _check_pruned_maximum(VonMisesProbe(disc, nonlinear, kinematics), disc, rng)


def _check_pruned_maximum(probe, disc, rng):
    states = [1e-3 * rng.normal(size=disc.ndofs) * rng.uniform(0.0, 1.0, size=disc.ndofs) ** 4 for _ in range(20)]
    # and cantilevers with a little of everything else, whose stress recovered at the held end is the largest
    states += [cantilever(disc, rng.uniform(1e-5, 1e-4)) + 1e-7 * rng.normal(size=disc.ndofs) for _ in range(10)]
    values, places = probe.maxima(np.array(states))  # all states in one call, as the step rows ask
    at_ends = 0
    for dofs, in_batch, batch_place in zip(states, values, places):
        value, where = probe.maximum(dofs)
        everywhere = np.concatenate((probe.stress(dofs)[:, [0, 2]].ravel(), probe.end_stress(dofs)))
        k = int(np.argmax(everywhere))
        assert value == pytest.approx(everywhere[k], rel=1e-14)
        assert where == np.concatenate((probe.x[:, [0, 2]].ravel(), probe.end_x))[k]
        assert (in_batch, batch_place) == (value, where)  # the same arithmetic, state by state
        at_ends += k >= probe.x[:, [0, 2]].size
    # both kinds of maxima occur (measured: 3 at the ends), or half of this tests nothing
    assert 0 < at_ends < len(states)


def test_the_stress_recovered_at_a_held_end_is_exact_for_a_moment_that_falls_linearly(disc):
    """A cantilever's moment under a tip load falls linearly from the held end, M(x) = M0 (1 - x / L): v'' =
    kappa0 (1 - x / L), theta_z = v' (no shear).  The linear rotations give each element its mean curvature,
    so the end element's sampled stress is that of its middle, E kappa0 (1 - h / 2L) R, low by h / 2L (1/16
    on 8 elements; :func:`cantilever` carries no shear strain).  Extrapolated from the two end elements'
    midpoints the end's stress is exact for a linear moment, E kappa0 R (to round-off: 1e-12), and the
    maximum is that, at x = 0.  Linear strains, so that nothing else varies along the string."""
    kappa0 = 1e-5
    p = disc.properties
    R, L, E = p.outer_radius, p.length, p.young_modulus
    h = L / 8
    bent = cantilever(disc, kappa0)
    probe = VonMisesProbe(disc, geometric_nonlinearity=False)
    # the P1 interpolant of theta_z has the exact mean curvature in each element: its middle's, h / 2 in
    assert probe.stress(bent).max() == pytest.approx(E * kappa0 * R * (1 - h / (2 * L)), rel=1e-12)
    value, where = probe.maximum(bent)
    assert value == pytest.approx(E * kappa0 * R, rel=1e-12)
    assert where == 0.0


#: A threshold crossing is located to one sample: two crossings per period of 1000 samples.
CROSSING = 2.0 / 1000


def test_rows_completed_in_batches_are_the_states_own_observables():
    """StepRows computes the bit, section and stress values of BATCH steps with one product of [Phi] with
    their states: each row must still hold its own state's values (the rows of [Phi] times that state, the
    probe's maximum of its dofs), whatever the batch boundaries, in a reduced and in the full space."""
    from fenics_drill.model.drillstring import build_model
    from fenics_drill.observables.step_rows import StepRows
    from fenics_drill.solvers.time_loop import Simulation

    scene = scene_with("beam.length=20.0", "beam.elements=16", "time.t_end=0.05")
    reduced = build_model(scene)
    for model in (reduced, reduced.full_order()):
        simulation = Simulation(model, scene, energy_budget=False)
        rows, states = StepRows(model, scene), []
        done = []

        def take(record):
            states.append(record.state)
            done.extend(rows.add(record))

        simulation.run(simulation.initial_state(np.zeros(model.size)), scene.time.t_end, take)
        assert len(states) > StepRows.BATCH  # a whole batch and a remainder
        done.extend(rows.complete())
        assert [row["time"] for row in done] == [s.t for s in states]
        for row, s in zip(done, states):
            u, du, tx, dtx = model.bit_state(s.q, s.qd)
            stress, where = rows.stress.maximum(model.space.expand(s.q))
            # a product of all states at once (BLAS's gemm) sums the 59 terms of a row in another order than
            # one state's gemv: 59 eps ~ 1.3e-14 relative, so 1e-12; the absolute floors are that round-off
            # of the terms' size where the value itself passes through zero (the string starts at rest:
            # displacements ~1e-5 m -> 1e-18 m, angular velocities ~1 rad/s -> 1e-15 rad/s)
            assert row["bit_displacement"] == pytest.approx(u, rel=1e-12, abs=1e-18)
            assert row["bit_angular_velocity"] == pytest.approx(dtx, rel=1e-12, abs=1e-15)
            # the stress from dofs that differ by that round-off; the probe's own pruning keeps sections
            # within 1e-9 of the largest sampled stress, which bounds how far a round-off tie can move it
            assert row["max_von_mises"] == pytest.approx(stress, rel=1e-9)
            assert row["max_von_mises_x"] == where


def synthetic_run(v0=0.005, omega=6.0, velocity_amplitude=0.002, omega_amplitude=0.0, periods=20, f=3.0):
    """Time series of a run with known answers: whole periods of sinusoids about the drive speeds."""
    t = np.linspace(0.0, periods / f, 20001)
    phase = 2 * np.pi * f * t
    return t, {
        "time": t, "lambda_1": np.full_like(t, -4e4), "lambda_4": np.full_like(t, -9e3),
        "bit_velocity": v0 + velocity_amplitude * np.sin(phase), "bit_force": np.full_like(t, -3e4),
        "bit_angular_velocity": omega * (1 + omega_amplitude * np.sin(phase)), "bit_torque": np.full_like(t, -2e3),
        "impacts": np.zeros_like(t),
    }


def test_efficiency_is_output_over_input_work_of_eqs_96_to_98():
    v0, omega = 0.005, 6.0
    t, series = synthetic_run(v0, omega)
    q = dq.drilling_quantities(series, v0, omega)
    # u_dot_bit > 0 throughout and the sinusoid integrates to zero over whole periods
    assert q["efficiency"] == pytest.approx((v0 * 3e4 + omega * 2e3) / (v0 * 4e4 + omega * 9e3), rel=1e-7)
    assert q["mean_input_power"] == pytest.approx(v0 * 4e4 + omega * 9e3, rel=1e-12)
    # the bit torque's magnitude counts the same while the torque resists the spin: identical integrands, so
    # only the order of the summation differs (1e-12)
    assert q["efficiency_torque_magnitude"] == pytest.approx(q["efficiency"], rel=1e-12)


def test_a_torque_that_drives_the_bit_adds_nothing_to_97_but_counts_by_its_magnitude():
    """With the bit torque (21) as printed, T_BR omega_bit > 0: (-T_BR)^+ = 0, so (97) keeps the axial
    power alone, while omega^+ |T_BR| counts it as the resisting torque would."""
    v0, omega = 0.005, 6.0
    t, series = synthetic_run(v0, omega)
    series["bit_torque"] = -series["bit_torque"]
    q = dq.drilling_quantities(series, v0, omega)
    work_in = v0 * 4e4 + omega * 9e3
    # 1e-7, as in the test above: the trapezoidal rule integrates the sinusoid to zero over whole periods only
    # up to the sampling of synthetic_run
    assert q["efficiency"] == pytest.approx(v0 * 3e4 / work_in, rel=1e-7)
    assert q["efficiency_torque_magnitude"] == pytest.approx((v0 * 3e4 + omega * 2e3) / work_in, rel=1e-7)


def test_rop_takes_the_positive_part_and_the_signed_variant_does_not():
    """u_dot = V0 + a sin: mean of the positive part a [c (pi + 2 asin c) + 2 sqrt(1 - c^2)] / (2 pi), c = V0/a."""
    v0, a = 0.002, 0.005
    t, series = synthetic_run(v0, velocity_amplitude=a)
    c = v0 / a
    exact = a * (c * (np.pi + 2 * np.arcsin(c)) + 2 * np.sqrt(1 - c**2)) / (2 * np.pi)
    q = dq.drilling_quantities(series, v0, 6.0)
    assert q["rop"] == pytest.approx(exact, rel=1e-6)
    assert q["signed_rop"] == pytest.approx(v0, rel=1e-7)
    # the bit moves backwards while sin < -c
    assert q["bit_bounce"]["off_bottom_fraction"] == pytest.approx((np.pi - 2 * np.arcsin(c)) / (2 * np.pi), abs=CROSSING)
    assert q["bit_bounce"]["velocity_min_ratio"] == pytest.approx(1 - a / v0, rel=1e-6)


def test_stick_slip_indicators_of_a_sinusoidal_bit_speed():
    """omega = Omega (1 + 1.5 sin): stuck (< 0.1 Omega) while sin < -0.6; severity (2.5 + 0.5) / 2."""
    t, series = synthetic_run(omega=6.0, omega_amplitude=1.5)
    s = dq.drilling_quantities(series, 0.005, 6.0)["stick_slip"]
    assert s["stick_fraction"] == pytest.approx((np.pi - 2 * np.arcsin(0.6)) / (2 * np.pi), abs=CROSSING)
    assert s["stick_slip_severity"] == pytest.approx(1.5, rel=1e-6)
    assert s["omega_max_ratio"] == pytest.approx(2.5, rel=1e-6)


def test_psd_of_two_sinusoids_peaks_at_their_frequencies_with_their_power():
    """Periodogram of A1 sin(2 pi f1 t) + A2 sin(2 pi f2 t) over whole periods: each line holds
    exactly A^2 / 2 (Parseval).  Non-uniform steps, resampled first, keep the peaks in place."""
    step = 1e-3
    (f1, a1), (f2, a2) = (57.0, 2.0), (143.0, 0.5)
    wave = lambda t: a1 * np.sin(2 * np.pi * f1 * t) + a2 * np.sin(2 * np.pi * f2 * t)  # noqa: E731
    t = step * np.arange(4000)  # 4 s: whole periods of both
    freq, psd = power_spectral_density(wave(t), step)
    df = freq[1] - freq[0]
    for f, a in ((f1, a1), (f2, a2)):
        line = np.abs(freq - f) < 0.5 * df
        assert np.sum(psd[line]) * df == pytest.approx(a**2 / 2, rel=1e-9)
    assert np.sum(psd) * df == pytest.approx((a1**2 + a2**2) / 2, rel=1e-9)
    rng = np.random.default_rng(3)
    t = np.cumsum(np.r_[0.0, step * rng.uniform(0.5, 1.5, 3999)])  # like an adaptive run
    grid = uniform_grid(t, step)
    freq, psd = power_spectral_density(resample(t, wave(t), grid), step)
    peaks = spectral_peaks(freq, to_db(psd), count=2)
    assert [p["frequency_hz"] for p in peaks] == pytest.approx([f1, f2], abs=freq[1] - freq[0])


@pytest.mark.parametrize("cycles", [3.0, 3.3, 30.0])
def test_the_dominant_period_of_a_stick_slip_signal_is_its_period(cycles):
    """A bit stuck 40 % of a 1.7 s period and slipping as a half sine of peak 3: the dominant period over 3, 3.3 and
    30 periods is 1.7 s within 1e-3 (measured 2e-4 on 3 periods: the Hann window's leakage of the harmonics into the
    peak's three bins biases the parabola a little on so short a record)."""
    period = 1.7
    t = np.linspace(0.0, cycles * period, int(cycles * period / 1e-3))
    phase = (t % period) / period
    spin = np.where(phase < 0.4, 0.0, 3.0 * np.sin(np.pi * (phase - 0.4) / 0.6))
    # 1e-3: five times the bias measured on 3 periods (2e-4), the harmonics' leakage into the peak's bins
    assert dominant_period(t, spin) == pytest.approx(period, rel=1e-3)
    assert dominant_period(t, np.full_like(t, 2.0)) is None


def test_event_rate_keeps_every_event():
    t = np.array([0.0, 0.0101, 0.0102, 0.5, 0.9999])
    counts = np.array([0, 2, 1, 3, 1])
    grid = uniform_grid(np.array([0.0, 1.0]), 0.01)
    rate = event_rate(t, counts, grid)
    assert np.sum(rate) * 0.01 == pytest.approx(counts.sum())
    assert rate[1] == pytest.approx(300.0)  # three events in the cell around t = 0.01


def test_shock_packages_are_groups_of_impacts_separated_by_quiet_time():
    t = np.linspace(0.0, 3.0, 3001)
    impacts = np.zeros_like(t)
    for start in (0.1, 1.1, 2.1):  # three bursts of 50 ms, one impact every 5 ms
        impacts[(t >= start) & (t < start + 0.05) & (np.round(t * 1000) % 5 == 0)] = 1
    assert dq.shock_packages(t, impacts) == 3
    assert dq.shock_packages(t, impacts, quiet_gap=1.5) == 1
    assert dq.shock_packages(t, np.zeros_like(t)) == 0
