"""The wall's static friction on the axial-torsional string (``contact.static_friction``): a string rotating off
bottom in an inclined hole winds up, breaks loose and sticks again (the off-bottom torsional oscillation of Aarsnes
& Shor, J. Pet. Sci. Eng. 163, 2018).  Checked against an energy balance, the published characterisation's static
torque, the same string as a torsional wave guide with the same wall law solved along its characteristics, and the
finite-element model's run."""

import dataclasses

import numpy as np
import pytest
from torsional_waves import inclined_wall_friction_case, limit_cycle_statistics

import fenics_drill as fd
from fenics_drill.studies.stick_slip import start

#: 120 s of the 2000 m string at 60 degrees, 10 m elements; its cycles over the last 60 s (about 11 of them).
DURATION, AFTER = 120.0, 60.0


@pytest.fixture(scope="module")
def off_bottom_cycles():
    scene, reference, static_torque = inclined_wall_friction_case()
    omega = scene.drive.rotation_speed
    mine = start(scene).run(DURATION)
    exact = reference(DURATION)
    return scene, static_torque, limit_cycle_statistics(mine, omega, AFTER), limit_cycle_statistics(exact, omega, AFTER), \
        {name: series["top_torque"][series["time"] > AFTER] for name, series in (("mine", mine), ("exact", exact))}


def test_the_mean_surface_torque_is_the_kinetic_friction_torque(off_bottom_cycles):
    """Energy: over whole cycles the drive's work Omega <T> is what the wall's friction and the string's damping
    dissipate.  Every vertex turns at Omega on average and slides at the kinetic factor, so <T> is at least the
    kinetic torque sum mu_k N' R L (the static factor 0.65 higher in slips slower than the static slip speed, and the
    damping c rho I_p L <omega^2> / Omega, some 0.1-0.5 %, only add to it): measured +0.9 % (steps) and +0.5 % (wave
    guides).  Bounds [-0.5 %, +1.5 %]: the cycles' stored energy at the window's two ends differs a little."""
    scene, static_torque, mine, exact, _ = off_bottom_cycles
    kinetic = static_torque * scene.contact.friction / scene.contact.static_friction
    for stats in (mine, exact):
        assert stats["cycles"] >= 8 and stats["stuck_share"] > 0.3  # an off-bottom stick-slip, many cycles
        assert -0.005 <= stats["surface_torque"] / kinetic - 1.0 <= 0.015


def test_the_surface_torque_climbs_to_the_static_torque_before_the_string_breaks_loose(off_bottom_cycles):
    """Aarsnes & Shor's characterisation: the surface torque climbs to the static friction torque of the whole
    string, sum mu_s N' R L, before it breaks loose.  The peak within [1, 1.1] of it: measured 1.065 (steps) and
    1.063 (wave guides), the excess the torsional waves' overshoot of the breakaway."""
    _, static_torque, _, _, torques = off_bottom_cycles
    for torque in torques.values():
        assert 1.0 <= torque.max() / static_torque <= 1.1


def test_the_cycle_is_the_wave_guides_with_the_same_wall_law(off_bottom_cycles):
    """The compiled steps (10 m elements, the default step) against the string as a torsional wave guide with the
    wall law cell by cell (tests/torsional_waves.py, 1 m cells; on 0.5 m cells the same to 0.02 % in the period and
    0.001 in the stuck share).  The cycles are irregular (the bit's fastest spin moves between 13 and 18 rad/s from
    one to the next, in both), so the tolerances are those of statistics over 10 and 11 of them: the mean cycle within 3 %
    (measured 1.3 %), the stuck share within 0.03 (0.020), the mean surface torque within 1 % (0.4 %), the peak
    surface torque within 3 % (0.2 %) and the fastest spin within 10 % (6 %)."""
    _, _, mine, exact, torques = off_bottom_cycles
    assert mine["period"] == pytest.approx(exact["period"], rel=0.03)
    assert abs(mine["stuck_share"] - exact["stuck_share"]) < 0.03
    assert mine["surface_torque"] == pytest.approx(exact["surface_torque"], rel=0.01)
    assert torques["mine"].max() == pytest.approx(torques["exact"].max(), rel=0.03)
    assert mine["max_spin"] == pytest.approx(exact["max_spin"], rel=0.10)


def test_the_finite_element_run_breaks_loose_as_the_compiled_steps_do():
    """``fenics-drill run`` of the same string (the wall's force module, lateral_length = 0) at its default adaptive
    step, whose nominal step the wall's static friction caps at an element's torsional transit (3.2 ms), against the
    compiled steps, over the first breakaway (6 s): the peak surface torque within 2 % (measured 0.4 %), its time
    within 0.15 s (0.03 s) and the mean surface torque within 2 % (1.4 %): two integrations of one stick-slip drift
    apart by their steps' errors.  Uncapped, the steps grew to 7-12 ms and the peak came out 13.2 kN m against
    15.45 kN m."""
    scene, _, _ = inclined_wall_friction_case()
    scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, t_end=6.0),
                                output=dataclasses.replace(scene.output, field_interval=0))
    result = fd.run(scene)
    transit = scene.string_length / scene.beam.elements / scene.beam_properties.torsional_wave_speed
    assert result.summary["nominal_dt"] == pytest.approx(transit, rel=1e-12)  # one closed form: round-off only
    assert "torsional transit" in result.summary["nominal_dt_reason"]
    assert not result.summary.get("advice")
    fe = result.series
    compiled = start(scene).run(6.0)
    t_fe, torque_fe = fe["time"].values, -fe["lambda_4"].values
    assert np.diff(t_fe).max() <= transit * (1 + 1e-9)
    t, torque = compiled["time"], compiled["top_torque"]
    assert torque.max() == pytest.approx(torque_fe.max(), rel=0.02)
    assert abs(t[np.argmax(torque)] - t_fe[np.argmax(torque_fe)]) < 0.15
    assert np.trapezoid(torque, t) / t[-1] == pytest.approx(np.trapezoid(torque_fe, t_fe) / t_fe[-1], rel=0.02)


def test_a_run_whose_chosen_step_outgrows_the_torsional_transit_is_told_to_shorten_it():
    """The same run at a fixed 12 ms step, the scene's own choice: four times the transit, which smooths the
    breakaway, so the summary's advice names the step that resolves it."""
    scene, _, _ = inclined_wall_friction_case()
    scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, t_end=1.0, adaptive=False, dt=0.012),
                                output=dataclasses.replace(scene.output, field_interval=0))
    summary = fd.run(scene).summary
    assert "nominal_dt_reason" not in summary
    advice = " ".join(summary.get("advice", []))
    assert "static friction" in advice and "time.dt = 0.0032 or less" in advice


#: Aarsnes & Shor's published off-bottom model on the side-by-side case (demos/scenes/off_bottom_side_by_side.toml),
#: run by ``python benchmarks/published_off_bottom_model.py --published PATH`` from a checkout of their code, on their
#: 2.5 m cells, over the whole cycles in [60, 300] s (benchmarks/results/published_off_bottom_model.md): the mean
#: motor torque [N m], the bit's fastest spin [rad/s] and the motor torque's peak [N m].
PUBLISHED_SIDE_BY_SIDE = {"surface_torque": 18244.0, "max_spin": 17.86, "peak_torque": 27790.0}


def test_the_published_off_bottom_model_side_by_side():
    """The compiled steps on the case both models state alike, against the authors' published code, on this string's
    default 10 m elements: the mean motor torque within 0.5 % (measured 0.001 %), the torque's peak within 2 % (0.3 %)
    and the fastest spin within 3 % (0.8 %).  The oscillation is irregular, and its statistics move with the mesh's
    dissipation in both models and in the exact characteristics (the benchmark's table): the two torques stay within
    0.6 % of the published ones on every mesh of all three, the fastest spin within 1.2 % on this string's 5 and 2.5
    m elements (their own 1.25 m cells give 9 % less); the mean cycle and the stuck share agree on these meshes (6.90
    against 6.88 s, 0.455 against 0.458) but move by up to 4 s and 0.2 on others, so they are not asserted."""
    scene = fd.load_scene("demos/scenes/off_bottom_side_by_side.toml")
    series = start(scene).run(300.0)
    mine = limit_cycle_statistics(series, scene.drive.rotation_speed, 60.0)
    peak = series["top_torque"][series["time"] > 60.0].max()
    assert mine["surface_torque"] == pytest.approx(PUBLISHED_SIDE_BY_SIDE["surface_torque"], rel=0.005)
    assert mine["max_spin"] == pytest.approx(PUBLISHED_SIDE_BY_SIDE["max_spin"], rel=0.03)
    assert peak == pytest.approx(PUBLISHED_SIDE_BY_SIDE["peak_torque"], rel=0.02)


def test_the_step_cap_follows_the_axial_torsional_elements():
    """The nominal step of a run with the wall's static friction is an element's torsional transit h / sqrt(G / rho),
    G and rho the sections' (E = 158.6 GPa and nu = 0.3: G = 61 GPa): the string's length over beam.elements by
    default, the axial-torsional elements' length where the scene sets it (to round-off: the same closed form)."""
    from fenics_drill.solvers.step_control import nominal_step

    scene = fd.load_scene("demos/scenes/off_bottom_side_by_side.toml")
    speed = (61e9 / 7850.0) ** 0.5
    assert nominal_step(scene) == pytest.approx(2500.0 / 250 / speed, rel=1e-12)
    finer = scene.with_changes(model={"axial_torsional_element_length": 5.0})
    assert nominal_step(finer) == pytest.approx(5.0 / speed, rel=1e-12)
    assert nominal_step(scene.with_changes(contact={"static_friction": -1.0})) > 3.0 * nominal_step(scene)
