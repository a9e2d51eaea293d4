"""The default reduced model against closed forms: it never answers silently wrong.

Strings from 5 to 40 m under their own weight, clamped-pinned (the paper's supports) and pinned-pinned,
with and without the geometric nonlinearity, in a borehole wide enough that they do not touch it; the
tip compliance under the bit loads; the guard that refuses or enriches a basis built to fail.
"""

import math

import numpy as np
import pytest
from conftest import PAPER, PAPER_FRICTION

from fenics_drill.model.discretization import THETA_X, U, W
from fenics_drill.model.reduction.spaces import BasisError
from fenics_drill.observables.von_mises import VonMisesProbe
from fenics_drill.scene import load_scene
from fenics_drill.studies.prepare import prepare

#: No wall within reach, no bit: gravity on the bare string.
FREE = ["borehole.radius=3.0", "model.bit_rock=false"]


def string(length, elements, *extra):
    scene = load_scene(PAPER, [*PAPER_FRICTION, f"beam.length={length}", f"beam.elements={elements}", *FREE, *extra])
    prepared = prepare(scene)
    model = prepared.model
    dofs = model.space.expand(prepared.equilibrium.q)
    return scene, model, dofs


def deflection_at(model, dofs, x):
    """w at the vertices nearest to the positions x."""
    vertices = np.searchsorted(model.disc.vertex_x, x)
    return dofs[model.disc.vertex_dofs(W)][vertices], model.disc.vertex_x[vertices]


def propped_cantilever(x, length, q, EI, kGA):
    """Timoshenko beam clamped at x = 0, pinned at x = L, under q: (sag w(x), reaction R at the pin).

    EI theta' = -M, w' = theta + M' / (kGA), M(x) = R (L - x) - q (L - x)^2 / 2; w(0) = theta(0) = 0 and
    w(L) = 0 give R = (q L^4 / 8EI + q L^2 / 2kGA) / (L^3 / 3EI + L / kGA) (3 q L / 8 without shear)."""
    L = length
    R = (q * L**4 / (8 * EI) + q * L**2 / (2 * kGA)) / (L**3 / (3 * EI) + L / kGA)

    def moment(s):
        return R * (L - s) - q * (L - s) ** 2 / 2

    bending = -(R * (L * x**2 / 2 - x**3 / 6) - q * (L**3 * x - (L**4 - (L - x) ** 4) / 4) / 6) / EI
    return bending + (moment(x) - moment(0.0)) / kGA, R


def weight_and_stiffness(scene):
    p = scene.beam_properties
    return p.density * p.section.area * p.gravity, p.young_modulus * p.section.I4, p


@pytest.mark.parametrize("length", [5.0, 12.0, 20.0])
@pytest.mark.parametrize("geometric", ["true", "false"])
def test_clamped_pinned_string_sags_as_a_propped_cantilever(length, geometric):
    """Timoshenko's propped cantilever (:func:`propped_cantilever`); its Euler-Bernoulli limit is the
    textbook q x^2 (L - x)(3L - 2x) / (48 EI)."""
    scene, model, dofs = string(length, 100, f"model.geometric_nonlinearity={geometric}")
    q, EI, p = weight_and_stiffness(scene)
    x = np.array([0.25, 0.4215, 0.75]) * length
    w, at = deflection_at(model, dofs, x)
    exact, _ = propped_cantilever(at, length, q, EI, p.shear_factor * p.shear_modulus * p.section.area)
    # 2e-3: 100 elements leave ~5e-4 of discretisation error, and the sag of 0.15 m at 20 m (w/L = 0.7 %)
    # moves by ~1e-3 through the geometric nonlinearity (0.7 % at w/L = 2.5 %, 30 m)
    np.testing.assert_allclose(-w, exact, rtol=2e-3)


@pytest.mark.parametrize("length", [6.0, 25.0])
def test_pinned_string_sags_as_a_timoshenko_beam_on_two_supports(length):
    """w(x) = q x (L^3 - 2 L x^2 + x^3) / (24 EI) + q x (L - x) / (2 kappa G A), exact for Timoshenko."""
    scene, model, dofs = string(length, 100, "model.supports='pinned'", "model.geometric_nonlinearity=false")
    q, EI, p = weight_and_stiffness(scene)
    kGA = p.shear_factor * p.shear_modulus * p.section.area
    x = np.array([0.2, 0.5, 0.9]) * length
    w, at = deflection_at(model, dofs, x)
    exact = q * at * (length**3 - 2 * length * at**2 + at**3) / (24 * EI) + q * at * (length - at) / (2 * kGA)
    # 100 P2/P1 elements: the discretisation error of the sag is ~1e-5 (rate h^2, tests/solvers)
    np.testing.assert_allclose(-w, exact, rtol=1e-3)


@pytest.mark.parametrize("length", [6.0, 20.0])
def test_clamp_stress_is_that_of_the_propped_cantilever(length):
    """At the clamp M = R L - q L^2 / 2 and V = q L - R (about q L^2 / 8 and 5 q L / 8):
    sigma_VM = sqrt((M R_ext / I)^2 + 3 (V / (kappa A))^2).  The probe's first point sits on the clamp and
    sees the curvature of the first element (P1 rotations), i.e. the mean moment over it, M(h/2) to O(h^2)."""
    elements = 200
    scene, model, dofs = string(length, elements, "model.geometric_nonlinearity=false")
    q, EI, p = weight_and_stiffness(scene)
    probe = VonMisesProbe(model.disc, geometric_nonlinearity=False)
    first = int(np.argmin(model.disc.mesh.geometry.x[model.disc.mesh.geometry.dofmaps[0]][:, :, 0].mean(axis=1)))
    stress = probe.stress(dofs)[first]
    at_clamp = stress[np.argmin(probe.x[first])]
    h = length / elements
    _, reaction = propped_cantilever(0.0, length, q, EI, p.shear_factor * p.shear_modulus * p.section.area)
    moment = reaction * (length - h / 2) - q * (length - h / 2) ** 2 / 2
    shear = q * (length - h / 2) - reaction
    exact = math.hypot(moment * p.outer_radius / p.section.I4, math.sqrt(3) * shear / (p.shear_factor * p.section.area))
    # the element means are M(h/2) and V(h/2) up to O(h^2) = 2.5e-5 of them (measured: 2e-5)
    assert at_clamp == pytest.approx(exact, rel=2e-4)


@pytest.mark.parametrize("length", [30.0, 40.0])
def test_a_long_string_with_large_sag_matches_the_converged_full_order(length):
    """The geometric nonlinearity at large deflection: the default reduced model within 0.1 % of the full
    order (its own static state is in the basis, docs/verification.md); the full order is converged."""
    _, model, dofs = string(length, 60)
    _, full, full_dofs = string(length, 60, "reduction.rule='none'")
    _, fine, fine_dofs = string(length, 120, "reduction.rule='none'")
    sag, full_sag, fine_sag = (-d[m.disc.vertex_dofs(W)].min() for d, m in ((dofs, model), (full_dofs, full),
                                                                            (fine_dofs, fine)))
    assert sag == pytest.approx(full_sag, rel=1e-3)
    assert full_sag == pytest.approx(fine_sag, rel=1e-3)  # 60 elements are converged to 0.1 %
    assert model.guard["static_state"]["error"] < 1e-6


def test_the_full_order_sag_at_large_deflection_converges_with_the_mesh():
    """No membrane locking: the 40 m sag (2.3 m, w/L = 6 %) converges at a rate above 2 (u quadratic like
    v, w); with a linear u it was 14 % short at 60 elements and still 5 % at 240."""
    sags = []
    for elements in (20, 40, 80):
        _, model, dofs = string(40.0, elements, "reduction.rule='none'")
        sags.append(-dofs[model.disc.vertex_dofs(W)].min())
    differences = np.abs(np.diff(sags))
    assert np.log2(differences[0] / differences[1]) > 2.0
    assert differences[1] / sags[-1] < 2e-3


def test_tip_compliance_under_the_bit_loads_is_exact_with_the_default_basis():
    """u(L) = F L / (E A) and theta_x(L) = T L / (G J), J = 2 I4 (St-Venant), with the drive end held (Eqs. 44, 46)."""
    scene = load_scene(PAPER, [*PAPER_FRICTION, "model.gravity=false", "model.contact=false", "model.geometric_nonlinearity=false",
                               "model.inertial_nonlinearity=false"])
    from fenics_drill.model.drillstring import build_model
    from fenics_drill.model.operators import assemble_linear

    model = build_model(scene)
    p = model.disc.properties
    K = model.space.project_matrix(assemble_linear(model.disc).stiffness)
    B = model.constraints
    system = np.block([[K, B.T * K.diagonal().max()], [B * K.diagonal().max(), np.zeros((2, 2))]])
    for field, exact in ((U, p.length / (p.young_modulus * p.section.area)),
                         (THETA_X, p.length / (2 * p.shear_modulus * p.section.I4))):  # St-Venant G J
        load = np.zeros(model.disc.ndofs)
        load[model.disc.end_dof(field, 1)] = 1.0
        q = np.linalg.solve(system, np.concatenate([model.space.project(load), np.zeros(2)]))[: model.size]
        tip = float((model.space.rows([model.disc.end_dof(field, 1)]) @ q)[0])
        # the basis holds the FE static responses, which are nodally exact for Lagrange bars and shafts
        assert tip == pytest.approx(exact, rel=1e-8)


def test_the_held_top_carries_the_whole_wall_friction_of_a_resting_string_with_the_default_basis():
    """The paper string rests on the wall; sliding along it, the axial friction (18) of every resting vertex
    adds up in the string's axial force, which the held top carries: E A u'(0) = sum of the friction loads (a
    bar held at x = 0, free at the bit, nodal loads: the FE strain of the first element is exact).  The band's
    axial modes miss 28 % of that static response and half of the strain at the top, where the peak stress
    sits; the guard finds it and the enrichment adds it (fenics_drill/model/reduction/enrichment.py)."""
    scene = load_scene(PAPER, [*PAPER_FRICTION, "model.geometric_nonlinearity=false", "model.inertial_nonlinearity=false"])
    from fenics_drill.model.drillstring import build_model
    from fenics_drill.model.reduction.enrichment import StaticSolver, wall_friction_loads, wall_rest_load
    from fenics_drill.model.operators import assemble_linear

    model = build_model(scene)
    verdict = model.guard["wall_axial_friction"]
    assert verdict["error_modes"] > scene.reduction.guard_tolerance and verdict["added"]
    disc, operators = model.disc, assemble_linear(model.disc)
    statics = StaticSolver(disc, operators)
    gap = scene.borehole.radius - scene.beam.outer_radius
    reaction = wall_rest_load(disc, operators.gravity, statics.responses(operators.gravity)[:, 0], gap)
    load = wall_friction_loads(disc, reaction)["wall_axial_friction"]
    K = model.space.project_matrix(operators.stiffness)
    B = model.constraints
    system = np.block([[K, B.T * K.diagonal().max()], [B * K.diagonal().max(), np.zeros((2, 2))]])
    q = np.linalg.solve(system, np.concatenate([model.space.project(load), np.zeros(2)]))[: model.size]
    first, second = np.argsort(disc.vertex_x)[:2]
    u = model.space.rows(disc.vertex_dofs(U)[[first, second]]) @ q
    p = disc.properties
    axial_force = p.young_modulus * p.section.area * (u[1] - u[0]) / (disc.vertex_x[second] - disc.vertex_x[first])
    carried = load[disc.vertex_dofs(U)].sum() - load[disc.vertex_dofs(U)[first]]  # the held vertex's own is held
    # the added static response is in the basis up to its M-orthogonalisation's round-off (error 1e-6 of energy)
    assert axial_force == pytest.approx(carried, rel=1e-4)


def test_the_guard_refuses_a_basis_that_misses_the_sag_and_enrichment_fixes_it():
    """A 6 m string: the paper's flexural band (f <= 5 Hz) holds no flexural mode, so its modes miss
    the whole sag. With enrichment off the command stops, naming the load and the remedy; with the
    default it sags as the propped cantilever does."""
    with pytest.raises(BasisError) as refusal:
        string(6.0, 60, "reduction.enrich=false")
    assert "gravity" in str(refusal.value) and "reduction.enrich = true" in str(refusal.value)
    scene, model, dofs = string(6.0, 60)
    assert model.guard["gravity"]["error_modes"] > 0.99  # the modes alone carry none of it
    q, EI, _ = weight_and_stiffness(scene)
    sag = -dofs[model.disc.vertex_dofs(W)].min()
    assert sag == pytest.approx(q * 6.0**4 / (185 * EI), rel=1e-2)  # shear adds 0.45 % at 6 m


def bit_motion(length, elements, *extra):
    """rop, mean and RMS of the bit velocity [m/s] and RMS of the bit spin [rad/s] of a short drilling run."""
    from fenics_drill.solvers.time_loop import Simulation

    scene = load_scene(PAPER, [*PAPER_FRICTION, f"beam.length={length}", f"beam.elements={elements}", "time.t_end=0.2",
                               "output.field_interval=0", *extra])
    prepared = prepare(scene)
    simulation = Simulation(prepared.model, scene)
    samples = []
    simulation.run(simulation.initial_state(prepared.equilibrium.q), scene.time.t_end,
                   lambda r: samples.append((r.state.t, *(simulation.model.bit_rows @ r.state.qd))))
    t, v, spin = np.array(samples).T

    def mean(f):
        return np.trapezoid(f, t) / t[-1]

    return {"rop": mean(np.maximum(v, 0.0)), "mean": mean(v), "rms": np.sqrt(mean((v - mean(v)) ** 2)),
            "spin_rms": np.sqrt(mean((spin - mean(spin)) ** 2))}


def test_the_default_reduced_drilling_run_matches_the_full_order_through_the_start_up():
    """A 20 m string on the wall starts drilling: the bit lands on the rock at V0 and the string winds up.
    With the step converged at the bit (time.error_tolerance = 1e-7 m; at the default 1e-5 m neither model
    resolves the bit's stiff start-up, docs/performance.md), the default reduced model (43 unknowns) and
    the full order (360) agree: measured 0.03 % on rop, 0.8 % on the RMS of the bit velocity and of the
    bit spin.  Tolerances: the reduced model's targets, 1 % on rop and mean velocity and 10 % on the RMS."""
    tight = "time.error_tolerance=1e-7"
    reduced = bit_motion(20.0, 40, tight)
    full = bit_motion(20.0, 40, tight, "reduction.rule='none'")
    assert reduced["rop"] == pytest.approx(full["rop"], rel=0.01)
    assert reduced["mean"] == pytest.approx(full["mean"], rel=0.01)
    assert reduced["rms"] == pytest.approx(full["rms"], rel=0.10)
    assert reduced["spin_rms"] == pytest.approx(full["spin_rms"], rel=0.10)


#: A 101 m string of 112/90 mm pipe at 39 m/h and 87 rpm (benchmarks/results/random_scenes/random_scenes_seed7.md, scene 6), which
#: sticks and slips from 0.5 s on.
STICKING = ["beam.length=101.068", "beam.elements=253", "beam.outer_radius=0.056008", "beam.inner_radius=0.0450352",
            "borehole.radius=0.0742886", "drive.axial_velocity=0.0109340101", "drive.rotation_speed=9.13149305",
            "bit_rock.limit_force=33151.7", "bit_rock.rate=455.199", "bit_rock.friction=0.4191",
            "output.field_interval=0"]


def test_the_basis_damps_its_directions_above_the_band_and_nothing_else():
    """fenics_drill/model/reduction/out_of_band_damping.py: every Ritz direction of the basis resting on the wall (its stiffness
    with the wall's springs, DrillstringModel.resting_at) above 2 f_max gets the modal
    damping 2 zeta omega (zeta = reduction.out_of_band_damping), those below and the rigid spin and feed none (to
    round-off of the largest damping), and the bit-local twist, the direction that moves the bit's rotation most
    per unit of kinetic energy (on this string 1555 Hz where f_max = 201 Hz), is among the damped."""
    import scipy.linalg as sl

    from fenics_drill.model.resolution import band_frequency
    from fenics_drill.model.reduction.out_of_band_damping import OUT_OF_BAND_FACTOR

    scene = load_scene(PAPER, [*PAPER_FRICTION, *STICKING, "reduction.out_of_band_damping=0.7"])
    prepared = prepare(scene, dynamics=False)
    model = prepared.model
    damping = model.force("out_of_band").damping
    stiffness = model.resting_stiffness(prepared.equilibrium.q)  # the Ritz directions of the string at rest
    eigenvalues, ritz = sl.eigh(stiffness, model.mass)
    omega = np.sqrt(np.maximum(eigenvalues, 0.0))
    above = omega > 2 * np.pi * OUT_OF_BAND_FACTOR * band_frequency(scene)
    assert 0 < above.sum() < len(omega)
    modal = ritz.T @ damping @ ritz  # diagonal in the mass-normalised Ritz vectors
    scale = 2 * 0.7 * omega[above].max()
    assert np.allclose(np.diag(modal)[above], 2 * 0.7 * omega[above], rtol=1e-9)
    assert np.abs(modal - np.diag(np.diag(modal))).max() < 1e-9 * scale
    assert np.abs(np.diag(modal)[~above]).max() < 1e-9 * scale
    rigid = model.drive_velocity_field()  # the spin Omega and the feed V0 of the whole string
    assert np.linalg.norm(damping @ rigid) < 1e-9 * scale * np.linalg.norm(model.mass @ rigid)
    bit_rotation = np.abs(model.bit_rows[1] @ ritz)
    assert above[np.argmax(bit_rotation)]


def test_a_reduced_bit_in_stick_slip_does_not_ring_and_matches_the_full_order(tmp_path):
    """Without the out-of-band damping the reduced bit of this string rang from 0.5 s on (its angular velocity
    zig-zagging from step to step, stick-slip severity 2.32 against the full order's 1.13, peak stress +6.8 %;
    tests/cli/test_extremes.py keeps that model as its example).  With it, over 0.8 s: peak stress within 1 % of
    the full order, severity within 2 % and efficiency within 0.5 % (measured: +0.22 %, +0.8 %, -0.07 %), and the
    bit's spin varies about as much as the full order's (ratio 0.96 against 0.89; 105 undamped)."""
    from fenics_drill.studies.run import run_scene

    runs = {rule: run_scene(load_scene(PAPER, [*PAPER_FRICTION, *STICKING, "time.t_end=0.8", f"reduction.rule='{rule}'"]),
                            tmp_path / rule, progress=False) for rule in ("auto", "none")}
    reduced, full = runs["auto"], runs["none"]
    assert reduced["max_von_mises"]["value"] == pytest.approx(full["max_von_mises"]["value"], rel=0.01)
    assert reduced["stick_slip"]["stick_slip_severity"] == pytest.approx(full["stick_slip"]["stick_slip_severity"],
                                                                         rel=0.02)
    assert reduced["efficiency"] == pytest.approx(full["efficiency"], rel=0.005)
    assert reduced["bit_spin_variation_ratio"] < 2 * full["bit_spin_variation_ratio"]


def test_a_pinned_string_resting_on_the_wall_takes_the_weight_on_bit_as_its_full_order_does():
    """A 40 m string pinned at both ends sags onto the wall and touches down 3.6 m from each end, where its peak
    stress sits: the bending moment has a kink at the touchdown vertex, which no mode of the free string
    carries.  Pushed at the bit by 30 kN (a weight on bit, statically), that peak grows from 16.8 to 18.6 MPa.
    The basis holds the string's responses at rest (its tangent, with the wall's springs) to the bit force and
    the wall's friction (studies/prepare.py, ``reduction.rest_response_tolerance``), so the reduced model's peak
    matches the full order's: measured -0.03 %; without them (tolerance 1) -1.3 %, the error the random pinned
    scenes showed in their runs (benchmarks/results/random_scenes/random_scenes_pinned.md).  Tolerance 0.2 %: the response is
    linearised at rest, and 30 kN moves the touchdown by about an element."""
    from fenics_drill.model.forces.axial_tip_load import AxialTipLoad
    from fenics_drill.solvers.static import solve_static

    base = ["beam.length=40", "beam.elements=100", "model.supports='pinned'"]

    def peak_stress(*extra):
        scene = load_scene(PAPER, [*PAPER_FRICTION, *base, *extra])
        prepared = prepare(scene, dynamics=False)
        pushed = prepared.model.with_added_force(AxialTipLoad(prepared.model.disc, prepared.model.space, 30e3))
        equilibrium = solve_static(pushed, initial=prepared.equilibrium.q)
        probe = VonMisesProbe(pushed.disc, scene.model.geometric_nonlinearity, scene.model.kinematics)
        return probe.maximum(pushed.space.expand(equilibrium.q))[0], prepared.model.guard

    full, _ = peak_stress("reduction.rule='none'")
    reduced, guard = peak_stress()
    assert guard["bit_force_at_rest"]["added"] and guard["wall_axial_friction_at_rest"]["added"]
    assert reduced == pytest.approx(full, rel=2e-3)
    without, guard = peak_stress("reduction.rest_response_tolerance=1")
    assert not guard["bit_force_at_rest"]["added"]
    assert abs(without / full - 1) > 5 * abs(reduced / full - 1)  # what the responses at rest bring


#: A 94 m string of 58/44 mm pipe in a 98 mm hole between two stabilisers (benchmarks/results/random_scenes/random_scenes_stabilisers.md,
#: scene 1): it rests on the wall from end to end but at the stabilisers, 40 mm above it.
STABILISED = ["beam.length=94.0786", "beam.elements=235", "beam.outer_radius=0.0578877", "beam.inner_radius=0.0444586",
              "borehole.radius=0.0976337", "drive.axial_velocity=0.00452349006", "drive.rotation_speed=11.3420693",
              "bit_rock.limit_force=35967.3", "bit_rock.rate=288.67", "bit_rock.friction=0.2962",
              "supports.stabilisers=[15.0, 30.0]", "output.field_interval=0", "time.t_end=0.7"]


def test_a_stabilised_thin_string_rests_on_the_wall_as_its_full_order_does(tmp_path):
    """The wall's springs stiffen the basis's directions that press the resting vertices into it far above the band,
    and the reduced model damps them as it damps its other directions above 2 f_max (DrillstringModel.resting_at).
    Without that, this string's reduced model lifted off the wall at 0.54 s and bounced (217 impacts by 0.7 s, rop
    +6.4 %) where its full order rests (2 impacts); with it, over 0.7 s: 2 impacts, rop -0.03 %, efficiency -0.05 %
    (docs/verification.md, "The reduced model against its full order").  Tolerances: 0.5 % on rop and efficiency, a few impacts more than the
    full order's (the reduced contact still flickers at a few vertices: its peak stress is 2.9 % low here)."""
    from fenics_drill.studies.run import run_scene

    runs = {rule: run_scene(load_scene(PAPER, [*PAPER_FRICTION, *STABILISED, f"reduction.rule='{rule}'"]), tmp_path / rule,
                            progress=False) for rule in ("auto", "none")}
    reduced, full = runs["auto"], runs["none"]
    assert reduced["impacts_total"] <= full["impacts_total"] + 5
    assert reduced["rop"] == pytest.approx(full["rop"], rel=0.005)
    assert reduced["efficiency"] == pytest.approx(full["efficiency"], rel=0.005)
    damped = prepare(load_scene(PAPER, [*PAPER_FRICTION, *STABILISED]), dynamics=False).model.force("out_of_band").frequencies_hz
    free = prepare(load_scene(PAPER, [*PAPER_FRICTION, *STABILISED, "model.contact=false"]), dynamics=False).model
    assert len(damped) > len(free.force("out_of_band").frequencies_hz)  # the wall's springs raised some above the cut
