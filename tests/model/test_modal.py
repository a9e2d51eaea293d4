"""Modal analysis (62) against closed forms, the paper's quoted frequencies and Table 4."""

import math

import numpy as np
import pytest
from conftest import scene_with

from fenics_drill.model.discretization import DRIVE, BeamDiscretization
from fenics_drill.model.reduction import modes
from fenics_drill.model.reduction.modes import auto_bands, drive_held_modes, paper_bands, solve_modes, stuck_bit_modes
from fenics_drill.model.operators import assemble_linear
from fenics_drill.studies.modal_report import modal_report

# Roots of tan(x) = tanh(x): clamped-pinned Euler-Bernoulli beam (Blevins, Table 8-1).
CLAMPED_PINNED_ROOTS = (3.926602312, 7.068582745, 10.21017612, 13.35176878, 16.49336143)


def family_frequencies(basis, kind):
    return basis.frequencies_hz[np.array(basis.kinds) == kind]


def timoshenko_pinned_omega2(p, n):
    """Lower root of the simply supported Timoshenko frequency equation for mode n.

    With v = V sin(kx), theta = T cos(kx), k = n pi / L:
    (kGA k^2 - rho A w^2)(E I k^2 + kGA - rho I w^2) - (kGA k)^2 = 0.
    """
    s = p.section
    EI, kGA = p.young_modulus * s.I4, p.shear_factor * p.shear_modulus * s.area
    rA, rI = p.density * s.area, p.density * s.I4
    k = n * math.pi / p.length
    a = rA * rI
    b = -(rA * (EI * k**2 + kGA) + rI * kGA * k**2)
    c = kGA * k**2 * EI * k**2
    return (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)


@pytest.fixture(scope="module")
def slender_modes():
    """100 m paper beam on 300 elements, modes up to f* = 2.2."""
    scene = scene_with("beam.elements=300")
    disc = BeamDiscretization.from_scene(scene)
    return disc.properties, solve_modes(disc, 2.2)


def test_total_mass_and_rotary_inertia_of_mass_matrix(paper_properties):
    """1^T M_uu 1 = rho A L and 1^T M_txtx 1 = 2 rho I4 L (Eq. 44), to round-off."""
    disc = BeamDiscretization(paper_properties, 37, 3)
    M = assemble_linear(disc).mass
    p = paper_properties
    ones = {i: (disc.field_of_dof == i).astype(float) for i in range(6)}
    for field, expected in ((0, p.density * p.section.area), (2, p.density * p.section.area),
                            (3, 2 * p.density * p.section.I4), (5, p.density * p.section.I4)):
        assert ones[field] @ M @ ones[field] == pytest.approx(expected * p.length, rel=1e-12)


def test_axial_free_free_frequencies(slender_modes):
    """u is free at both ends: f_n = n c_L / (2L).

    u is quadratic like v and w (no membrane locking, docs/verification.md): with consistent
    mass its frequency error is of order (k h)^4 / 1440 < 3e-9 for n <= 4, k = n pi / L,
    h = L/300; tolerance 1e-8 (the eigensolver's own tolerance is 1e-10)."""
    p, basis = slender_modes
    f = family_frequencies(basis, "axial")
    n = np.arange(1, len(f) + 1)
    assert len(f) == 4  # f* = n/2 <= 2.2
    np.testing.assert_allclose(f, n * p.longitudinal_wave_speed / (2 * p.length), rtol=1e-8)


def st_venant_wave_speed(p):
    """c_T = sqrt(G J / rho J) = sqrt(G / rho) of a uniform round tube (St-Venant torsion, no shear factor)."""
    return math.sqrt(p.young_modulus / (2 * (1 + p.poisson_ratio)) / p.density)


def test_torsional_free_free_frequencies(slender_modes):
    """St-Venant torsion G J over the inertia rho J (J = 2 I4): a free-free tube's f_n = n c_T / (2L) with
    c_T = sqrt(G / rho) (the closed form of the wave equation; not the paper's sqrt(kappa_s G / rho)).
    theta_x is linear with a consistent mass: relative error (kh)^2 / 24 = 2.24e-4 for the 7th mode (k = 7 pi / L,
    h = L / 300), so 3e-4."""
    p, basis = slender_modes
    f = family_frequencies(basis, "torsional")
    n = np.arange(1, len(f) + 1)
    c_T = st_venant_wave_speed(p)
    assert len(f) == int(2 * 2.2 * p.longitudinal_wave_speed / c_T)  # f* = n c_T/(2 c_L) <= 2.2
    np.testing.assert_allclose(f, n * c_T / (2 * p.length), rtol=3e-4)  # (kh)^2 / 24 = 2.24e-4 at the 7th mode


def test_printed_torsion_is_the_papers_shear_corrected_wave_speed():
    """model.torsion = 'printed' gives the paper's torsional stiffness kappa_s G J: f_n = n sqrt(kappa_s G / rho)
    / (2L), lower than St-Venant's by the factor sqrt(kappa_s) = sqrt(6/7) (7.42 %), to the same
    discretisation error (2.24e-4 at the 7th mode, as above)."""
    scene = scene_with("beam.elements=300", "model.torsion='printed'")
    disc = BeamDiscretization.from_scene(scene)
    p = disc.properties
    f = family_frequencies(solve_modes(disc, 2.2), "torsional")
    n = np.arange(1, len(f) + 1)
    c_T = math.sqrt(p.shear_factor / (1 + p.poisson_ratio) / 2 * p.young_modulus / p.density)
    np.testing.assert_allclose(f, n * c_T / (2 * p.length), rtol=3e-4)  # (kh)^2 / 24 = 2.24e-4 at the 7th mode


def test_modes_held_by_the_drive_are_the_fixed_free_quarter_waves():
    """With u and theta_x held at x = 0 (as the drive holds them in a run), the axial and torsional
    modes are those of a bar and a shaft fixed at one end and free at the other: f_n = (2n - 1) c / (4L),
    with c_T = sqrt(G / rho) of St-Venant torsion (G J over rho J); no rigid mode.  The first torsional one,
    7.86 Hz, is next to the stick-slip line of Section 6.8 (7.92 Hz in the paper, which names the flexural
    7.63 Hz)."""
    scene = scene_with("beam.elements=300")
    disc = BeamDiscretization.from_scene(scene)
    held = solve_modes(disc, 2.2, held=DRIVE)
    p = disc.properties
    kinds = np.array(held.kinds)
    assert "rigid" not in kinds
    c_T = st_venant_wave_speed(p)
    for kind, c in (("axial", p.longitudinal_wave_speed), ("torsional", c_T)):
        f = held.frequencies_hz[kinds == kind]
        n = np.arange(1, len(f) + 1)
        assert len(f) == int(2 * 2.2 * p.longitudinal_wave_speed / c + 0.5)  # (2n - 1)/4 c/c_L <= 2.2
        # u quadratic: error ~(kh)^4; theta_x linear: (kh)^2 / 24 <= 2.6e-4 for the 8th torsional mode
        # (k = 15 pi / 2L, h = L / 300)
        np.testing.assert_allclose(f, (2 * n - 1) * c / (4 * p.length), rtol=5e-4)
    # c_T / 4L = 7.859 Hz for the paper string; 0.01 Hz is the rounding of 7.86
    assert held.frequencies_hz[kinds == "torsional"][0] == pytest.approx(7.86, abs=0.01)
    # the held dofs and the supports hold nothing of any mode: exactly zero, as the shift-and-invert operator
    # leaves them (which is why SLEPc's purification of the eigenvectors is switched off)
    constrained = np.concatenate([disc.support_dofs, [disc.end_dof(field, end) for field, end in DRIVE]]).astype(int)
    assert len(disc.support_dofs) > 0 and not held.vectors[constrained].any()


@pytest.mark.parametrize("dense_block", [modes.DENSE_BLOCK, 0], ids=["blocks dense", "blocks by Lanczos"])
def test_modes_held_by_the_drive_from_the_free_modes_and_two_blocks_are_the_whole_eigensolve(dense_block,
                                                                                             monkeypatch):
    """drive_held_modes (the free string's flexural modes, the axial and torsional blocks with u(0) and
    theta_x(0) held) gives the eigensolve of the whole string held by the drive: the same kinds in the same
    order and the same frequencies, to SLEPc's tolerance (1e-10 on the eigenpairs' residuals; 7e-12 measured
    on the frequencies, held to 1e-9, well below any discretization error), on a string with supports;
    with the blocks solved dense (LAPACK) and by shift-and-invert Lanczos (ARPACK), as larger blocks are."""
    monkeypatch.setattr(modes, "DENSE_BLOCK", dense_block)
    scene = scene_with("beam.elements=60", "beam.length=30.0")
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    assert len(disc.support_dofs) > 0
    whole = solve_modes(disc, 3.0, operators.mass, held=DRIVE)
    free = solve_modes(disc, 3.0, operators.mass)
    held = drive_held_modes(disc, free, 3.0, operators.mass, operators.stiffness)
    assert held.kinds == whole.kinds and {"flexural", "axial", "torsional"} <= set(held.kinds)
    # SLEPc converges the eigenpairs to a 1e-10 residual, so the two solves agree to about that (7.1e-12
    # measured); 1e-9 leaves room for it and is still far below any discretization error or wrong mode
    np.testing.assert_allclose(held.frequencies_hz, whole.frequencies_hz, rtol=1e-9)
    # M-orthonormal: the blocks' vectors to round-off (both solvers normalise them), against each other
    # exactly (disjoint fields, which M does not couple); the flexural ones as SLEPc delivers them, whose
    # degenerate v / w pairs are orthogonal to about its 1e-10 residual tolerance (1.7e-10 and, with nev + 32
    # Krylov vectors, 2.0e-10 measured), so 1e-9
    np.testing.assert_allclose(held.vectors.T @ operators.mass @ held.vectors, np.eye(len(held)), atol=1e-9)


def test_modes_of_a_stuck_bit_are_the_fixed_fixed_torsional_waves():
    """With theta_x held at both ends (the drive, and the bit stuck in the rock), the torsional modes are
    those of a shaft fixed at both ends: f_n = n c_T / (2L), every one up to the band."""
    scene = scene_with("beam.elements=300")
    disc = BeamDiscretization.from_scene(scene)
    p = disc.properties
    operators = assemble_linear(disc)
    stuck = stuck_bit_modes(disc, 2.2, operators.mass, operators.stiffness)
    c_T = st_venant_wave_speed(p)
    n = np.arange(1, len(stuck) + 1)
    assert set(stuck.kinds) == {"torsional"}
    assert len(stuck) == int(2 * 2.2 * p.longitudinal_wave_speed / c_T)  # n c_T / (2 c_L) <= 2.2
    # theta_x linear: relative error (kh)^2 / 24 <= 2.6e-4 up to k = 15 pi / 2L, h = L / 300 (as above)
    np.testing.assert_allclose(stuck.frequencies_hz, n * c_T / (2 * p.length), rtol=5e-4)


def test_auto_bands_are_the_paper_bands_at_the_paper_spin_and_step_and_follow_them():
    """The 'auto' rule reads the paper's Section 6.3 off the scene: at Omega = 2 pi rad/s and the nominal
    step its bands are the printed ones; the flexural band scales with the spin, the others with 1/dt."""
    scene = scene_with()
    p = scene.beam_properties
    assert auto_bands(scene) == pytest.approx(paper_bands(p.length, p.longitudinal_wave_speed), rel=1e-12)
    faster = auto_bands(scene_with("drive.rotation_speed=12.566370614359172"))  # 2 Hz
    assert faster["flexural"] == pytest.approx(10.0 * p.length / p.longitudinal_wave_speed, rel=1e-12)
    nominal_dt = p.length / (2 * 4.0 * p.longitudinal_wave_speed)  # 1 / (2 f_max), Section 6.2
    finer = auto_bands(scene_with(f"time.dt={2 * nominal_dt}", "modal.f_star_max=4.0"))
    assert finer["torsional"] == finer["axial"] == pytest.approx(2.0, rel=1e-12)


def test_two_rigid_body_modes(slender_modes):
    _, basis = slender_modes
    kinds = np.array(basis.kinds)
    assert (kinds == "rigid").sum() == 2
    rigid = np.flatnonzero(kinds == "rigid")
    fractions = basis.energy_fractions[rigid]
    # one pure axial translation, one pure rotation about x
    assert sorted(np.argmax(fractions, axis=1)) == [0, 3]
    assert np.all(fractions.max(axis=1) > 1 - 1e-9)


def test_clamped_pinned_flexural_frequencies_match_euler_bernoulli(slender_modes):
    """Paper supports give clamped-pinned bending in both planes, each root twice.

    For L/r_g ~ 2100 the Timoshenko correction of the first 5 modes is < 2e-4 and the
    P2/P1 mesh error on 300 elements ~ (beta h)^2 / 24 < 2e-4; tolerance 1e-3.
    """
    p, basis = slender_modes
    f = family_frequencies(basis, "flexural")[:10]
    s = p.section
    a = math.sqrt(p.young_modulus * s.I4 / (p.density * s.area))
    expected = np.repeat([(r / p.length) ** 2 * a / (2 * math.pi) for r in CLAMPED_PINNED_ROOTS], 2)
    np.testing.assert_allclose(f, expected, rtol=1e-3)


def test_pinned_pinned_stubby_beam_matches_timoshenko_not_euler_bernoulli():
    """L = 2 m (L/r_g ~ 42): shear and rotary inertia lower the frequencies by several %;
    the FE result must follow Timoshenko to 2e-4 (mesh error of 256 P2/P1 elements < 1e-4)."""
    scene = scene_with("beam.length=2", "beam.elements=256", "model.supports=pinned")
    disc = BeamDiscretization.from_scene(scene)
    p = disc.properties
    basis = solve_modes(disc, 0.6)
    f = family_frequencies(basis, "flexural")[:8]
    timoshenko = np.repeat([math.sqrt(timoshenko_pinned_omega2(p, n)) / (2 * math.pi) for n in (1, 2, 3, 4)], 2)
    np.testing.assert_allclose(f, timoshenko, rtol=2e-4)
    s = p.section
    euler_bernoulli = (4 * math.pi / p.length) ** 2 * math.sqrt(p.young_modulus * s.I4 / (p.density * s.area)) / (
        2 * math.pi
    )
    assert f[-1] < euler_bernoulli * (1 - 0.02)  # the test tells the two theories apart


@pytest.mark.parametrize("degree, rate", [(2, 2.0), (3, 4.0)])
def test_eigenvalue_convergence_rate(degree, rate):
    """Eigenvalue error O(h^(2p)) with p = k - 1, the degree of the rotations (and of u).

    Third flexural eigenvalue of a pinned 4 m beam against the Timoshenko closed form,
    meshes of 4, 8, 16, 32 elements; observed rate within 0.15 of the theory.
    """
    errors = []
    for n_el in (4, 8, 16, 32):
        scene = scene_with("beam.length=4", f"beam.elements={n_el}", f"beam.element_degree={degree}",
                           "model.supports=pinned")
        disc = BeamDiscretization.from_scene(scene)
        basis = solve_modes(disc, 0.6)
        omega2 = (2 * math.pi * family_frequencies(basis, "flexural")[2]) ** 2
        exact = timoshenko_pinned_omega2(disc.properties, 2)
        errors.append(abs(omega2 - exact) / exact)
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert rates[-1] == pytest.approx(rate, abs=0.15)


@pytest.fixture(scope="module")
def paper_report():
    """The paper's mesh (Section 6) and its torsion kappa_s G J, whose wave speed Table 4's counts use."""
    return modal_report(scene_with("beam.elements=500", "reduction.rule='paper'", "model.torsion='printed'"))


def test_paper_flexural_frequencies_of_section_6_8(paper_report):
    """Each flexural frequency quoted in Section 6.8 has a computed flexural mode within 1 %."""
    flexural = np.array([m["frequency_hz"] for m in paper_report["modes"] if m["kind"] == "flexural"])
    for quoted in (6.59, 7.63, 57.77, 83.65, 106.18, 114.27, 144.94, 174.07):
        nearest = flexural[np.argmin(abs(flexural - quoted))]
        assert nearest == pytest.approx(quoted, rel=0.01), quoted


def test_paper_rule_counts_match_closed_form_counts(paper_report):
    """The printed Section 6.3 rule on L = 100 m, counted independently from the closed forms:
    flexural clamped-pinned roots with f <= 5 Hz (x2 planes), torsional n c_T/(2 c_L) <= 4,
    axial n/2 <= 4 except n = 8, whose FE frequency lies just above f* = 4 (P1 stiffening)."""
    p = scene_with("model.torsion='printed'").beam_properties
    s = p.section
    a = math.sqrt(p.young_modulus * s.I4 / (p.density * s.area))
    roots = [(n + 0.25) * math.pi for n in range(1, 40)]  # asymptotic roots, exact to 1e-6 beyond n=3
    flexural = 2 * sum((r / p.length) ** 2 * a / (2 * math.pi) <= 5.0 for r in roots)
    torsional = int(8 * p.longitudinal_wave_speed / p.torsional_wave_speed)
    red = paper_report["reduced_basis"]
    assert red["counts"] == {"rigid": 2, "flexural": flexural, "torsional": torsional, "axial": 7}
    assert red["size"] == 2 + flexural + torsional + 7
    assert paper_report["full_dofs"] == 3 * (2 * 500 + 1) + 3 * 501  # u, v, w quadratic; rotations linear


def test_the_reduced_basis_does_not_depend_on_the_eigensolvers_round_off(monkeypatch):
    """The stuck-bit modes augmented onto a 10 m string's modes leave parts of 2e-11 to 8e-8 of themselves
    outside the basis that are the eigensolvers' error, not physics (they change up to 20x with SLEPc's
    purification on or off); with the modes' span tolerance (1e-6) none of them enters the basis, so both
    settings give the same basis: the same size and the same span.  The span within 1e-4 rad: the modes of
    the two settings differ by about 2e-10 (SLEPc's tolerance), which a direction kept with 6.5e-6 of its
    vector outside the modes turns into 3e-5 rad (measured 3.8e-5); the noise direction, had it entered
    one basis only, would stand at 90 degrees to the other."""
    from slepc4py import SLEPc

    from fenics_drill.model.drillstring import build_model

    scene = scene_with("beam.length=10.0", "beam.elements=20")
    default = build_model(scene)
    purify = SLEPc.EPS.setPurify
    monkeypatch.setattr(SLEPc.EPS, "setPurify", lambda eps, flag: purify(eps, True))
    purified = build_model(scene)
    assert purified.size == default.size
    mass = default.operators.mass
    overlap = purified.space.phi.T @ (mass @ default.space.phi)  # both M-orthonormal
    cosines = np.linalg.svd(overlap, compute_uv=False)
    assert np.all(cosines > 1.0 - 5e-9)  # 1 - cos(1e-4 rad)


def test_the_modes_solved_by_field_groups_are_those_of_the_whole_problem():
    """solve_modes splits (62) into the field groups K and M couple: for the straight string u, (v, theta_z),
    (w, theta_y), theta_x.  Its eigenvalues are those of the whole (K, M) on the free dofs, solved densely by
    LAPACK (an independent reference), to the eigensolver's tolerance, and each mode is M-orthonormal to the
    others across the groups."""
    import scipy.linalg as sla

    from fenics_drill.model.operators import assemble_modal_pair

    disc = BeamDiscretization.from_scene(scene_with("beam.elements=24", "supports.stabilisers=[40.0]"))
    K, M = assemble_modal_pair(disc, DRIVE)
    groups = modes.coupled_field_groups((K, M), disc.field_of_dof)
    assert [g.tolist() for g in groups] == [[0], [1, 5], [2, 4], [3]]
    basis = solve_modes(disc, 3.0, held=DRIVE)
    dense = [np.array(A.convert("dense").getDenseArray()) for A in (K, M)]
    free = np.flatnonzero(np.diag(dense[1]) != 0.0)  # the Dirichlet rows carry M = 0 on the diagonal
    reference = sla.eigh(dense[0][np.ix_(free, free)], dense[1][np.ix_(free, free)], eigvals_only=True)
    reference_hz = np.sqrt(np.clip(reference, 0.0, None)) / (2.0 * math.pi)
    below = reference_hz[reference_hz <= basis.frequencies_hz.max() * (1 + 1e-9)]
    assert len(below) == len(basis)
    elastic = below > 1e-3  # the rigid modes' round-off frequencies are not comparable
    # SLEPc's 1e-10 bounds the shift-inverted residual; the lowest elastic mode is then 2.7e-8 off, as it was
    # when the whole problem was solved in one piece (measured on this string, both ways)
    assert basis.frequencies_hz[elastic] == pytest.approx(below[elastic], rel=1e-7)
    mass = assemble_linear(disc).mass
    # modes of different groups have disjoint dofs (exact zeros); within a group SLEPc's GHEP basis is
    # M-orthonormal to round-off and solve_modes normalises again: measured 8e-16, allowed 1e-12 for sums over
    # ~150 dofs of vectors known to the eigensolver's residual
    assert basis.vectors.T @ mass @ basis.vectors == pytest.approx(np.eye(len(basis)), abs=1e-12)
    # without the vectors (the full order's spectra): the same frequencies, kinds and energy fractions, exactly
    bare = solve_modes(disc, 3.0, held=DRIVE, vectors=False)
    assert bare.vectors is None
    assert np.array_equal(bare.frequencies_hz, basis.frequencies_hz) and bare.kinds == basis.kinds
    assert np.array_equal(bare.energy_fractions, basis.energy_fractions)


def test_field_groups_merge_where_a_matrix_couples_two_fields():
    """A nonzero entry between the dofs of two fields puts them in one group (and with them, the fields
    already grouped with either); entries that are stored but zero couple nothing."""
    from petsc4py import PETSc

    field_of_dof = np.array([0, 1, 2, 3, 4, 5, 0, 1])
    A = PETSc.Mat().createAIJ((8, 8), nnz=8, comm=PETSc.COMM_SELF)
    for i in range(8):
        A.setValue(i, i, 1.0)
    A.setValue(0, 3, 0.0)  # stored, zero
    A.setValue(7, 2, 0.5)  # v with w
    A.setValue(4, 2, 0.5)  # theta_y with w
    A.assemble()
    groups = modes.coupled_field_groups((A,), field_of_dof)
    assert [g.tolist() for g in groups] == [[0], [1, 2, 4], [3], [5]]


def test_the_guard_measures_what_a_basis_misses_without_a_round_off_floor():
    """basis_error is the energy share of a static response the basis misses: for a response in the span it is
    zero to round-off (it takes no square root of a difference: 1 - captured / exact left a floor of
    sqrt(round-off), 1e-8 here and 1e-6 on a string), and for a basis of unit vectors and a diagonal
    stiffness it is the closed form sqrt(sum_out k v^2 / sum k v^2)."""
    import scipy.sparse as sp

    from fenics_drill.model.reduction.enrichment import basis_error

    rng = np.random.default_rng(0)
    k = rng.uniform(1.0, 1e6, size=40)
    stiffness = sp.diags(k)
    no_constraints = np.zeros((0, 25))
    rotated = np.linalg.qr(rng.normal(size=(40, 25)))[0]  # a basis the reduced solve meets with round-off
    inside = rotated @ rng.normal(size=25)
    # measured 2e-15 (the difference of energies gave 2.6e-8 here)
    assert basis_error(rotated, stiffness, no_constraints, stiffness @ inside, inside) < 1e-12
    phi = np.eye(40)[:, :25]  # the first 25 dofs
    anywhere = rng.normal(size=40)
    missed = np.sqrt(np.sum(k[25:] * anywhere[25:] ** 2) / np.sum(k * anywhere**2))
    # sums of 40 products and one square root (round-off ~1e-15; measured 2e-16); the reduced solve's own error
    # (at most eps times the stiffness ratio 1e6 on q) enters the missed energy squared, so 1e-12 holds it
    ours = basis_error(phi, stiffness, no_constraints, stiffness @ anywhere, anywhere)
    assert ours == pytest.approx(missed, rel=1e-12)
