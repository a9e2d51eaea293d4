"""The string's modes as it hangs in a well, against exact references that share nothing with the FE model:
transfer-matrix roots of the composite rod (axial and St-Venant torsional waves, with and without discrete tool
joints) and a Chebyshev solve of the tensioned-beam equation (EI y'')'' - (T y')' + m y_tt = 0 for the lateral
modes under the hanging weight and a weight on bit (:mod:`string_references`)."""

import math

import numpy as np
import pytest
import scipy.optimize
from conftest import scene_with
from string_references import rod_frequencies, tensioned_beam_frequencies

from fenics_drill.forms.properties import section_constants
from fenics_drill.model.discretization import DRIVE, THETA_X, BeamDiscretization
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.reduction.modes import solve_modes
from fenics_drill.studies.modal_report import modal_report
from fenics_drill.studies.operating_state import loaded_stiffness, operating_state

E, NU, RHO = 203e9, 0.3, 7900.0
G = E / (2 * (1 + NU))
COLLAR = {"name": "collar", "length": 60.0, "outer_radius": 0.0857, "inner_radius": 0.0357}
HEAVY_WEIGHT = {"name": "heavy-weight", "length": 90.0, "outer_radius": 0.0635, "inner_radius": 0.0381}
PIPE = {"name": "drill pipe", "length": 350.0, "outer_radius": 0.0635, "inner_radius": 0.0543}
#: 5 in drill pipe with 6 5/8 in tool joints of 3 1/4 in bore, 0.5 m every 9.4 m.
JOINTED = dict(PIPE, length=470.0, tool_joint_outer_radius=0.0841, tool_joint_inner_radius=0.0413,
               tool_joint_length=0.5, tool_joint_spacing=9.4)


def toml_table(section: dict) -> str:
    return "{" + ", ".join(f'{k} = "{v}"' if isinstance(v, str) else f"{k} = {v!r}" for k, v in section.items()) + "}"


def vertical_string(sections, elements, *overrides):
    """The sections (from the bit up) hanging off bottom in a vertical hole of radius 0.108 m, in air, full order."""
    length = sum(s["length"] for s in sections)
    return scene_with(f"string.sections=[{', '.join(toml_table(s) for s in sections)}]",
                      f"well.md=[0.0, {length}]", "well.inclination=[0.0, 0.0]", "well.azimuth=[0.0, 0.0]",
                      f"well.hole_bottom=[{length}]", "well.hole_radius=[0.108]", "well.hole_cased=[false]",
                      f"beam.elements={elements}", f"beam.young_modulus={E}", f"beam.poisson_ratio={NU}",
                      f"beam.density={RHO}", "reduction.rule='none'", "drive.start='off_bottom'", *overrides)


def segments(sections, kind):
    """(length, stiffness, inertia) of each section from the top down: E A and rho A, or G J and rho J."""
    out = []
    for s in reversed(sections):
        c = section_constants(s["outer_radius"], s["inner_radius"])
        out.append((s["length"], E * c.area, RHO * c.area) if kind == "axial" else
                   (s["length"], G * 2 * c.I4, RHO * 2 * c.I4))
    return out


def fe_family(basis, kind, count):
    return basis.frequencies_hz[np.array(basis.kinds) == kind][:count]


@pytest.fixture(scope="module")
def composite():
    """Collar, heavy-weight and drill pipe (500 m), 1000 quadratic elements, modes up to f* = 2."""
    sections = [COLLAR, HEAVY_WEIGHT, PIPE]
    disc = BeamDiscretization.from_scene(vertical_string(sections, 1000))
    mass = assemble_linear(disc).mass
    return sections, {held: solve_modes(disc, 2.0, mass, held=DRIVE if held else (), vectors=False)
                      for held in (False, True)}


@pytest.mark.parametrize("held", [False, True], ids=["free-free", "drive-held"])
@pytest.mark.parametrize("kind", ["axial", "torsional"])
def test_composite_string_waves_are_the_transfer_matrix_roots(composite, kind, held):
    """The axial and torsional frequencies of a three-section string against the exact roots of its transfer
    matrix, free at both ends or held by the drive at the top (the bit free): the first three, within 1e-4.
    The discretisation error: u quadratic, (kh)^4 ~ 1e-9; theta_x linear, (kh)^2 / 24 <= 1.1e-5 at h = 0.5 m for
    the third torsional mode (k = 2 pi f / c_T ~ 0.013 /m in the collar-stiffened string)."""
    sections, spectra = composite
    fe = fe_family(spectra[held], kind, 3)
    exact = rod_frequencies(segments(sections, kind), "held" if held else "free", "free", 3, 1.2 * fe[-1])
    np.testing.assert_allclose(fe, exact, rtol=1e-4)


def test_the_stuck_bit_spectrum_of_the_modal_report_is_the_fixed_fixed_rod(composite):
    """``fenics-drill modal`` on the composite string hanging in the well: its spectrum with the bit stuck holds the
    torsional roots of the rod held at both ends, within 1e-4; with the bit off bottom, the first torsional period
    is the fixed-free rod's.  300 elements: theta_x linear, (kh)^2 / 24 ~ 2e-5 for the second root (6.9 Hz,
    h = 1.7 m; measured 2.2e-5); the report's lateral modes, dense in a 500 m string, set its cost."""
    sections = composite[0]
    report = modal_report(vertical_string(sections, 300, "modal.f_star_max=1.0"))
    assert report["linearised_about"]["state"] == "static"  # 'auto' in a well
    stuck = [m["frequency_hz"] for m in report["spectra"]["drive_held_bit_stuck"]["modes"] if m["kind"] == "torsional"]
    exact = rod_frequencies(segments(sections, "torsional"), "held", "held", 2, 1.2 * stuck[1])
    np.testing.assert_allclose(stuck[:2], exact, rtol=1e-4)
    first = rod_frequencies(segments(sections, "torsional"), "held", "free", 1, 2.0)[0]
    assert report["first_torsional_period_s"] == pytest.approx(1 / first, rel=1e-4)


def test_a_two_section_shaft_meets_its_transcendental_equation():
    """Collar below drill pipe, free-free torsion, against the two-section frequency equation written out by hand:
    Z1 sin(k L1) cos(k L2) + Z2 cos(k L1) sin(k L2) = 0 (Z = G J / c_T the torsional impedance, k = omega / c_T,
    the same in both sections of one steel); the FE within 1e-4 (as above)."""
    sections = [COLLAR, dict(PIPE, length=240.0)]
    disc = BeamDiscretization.from_scene(vertical_string(sections, 600))
    fe = fe_family(solve_modes(disc, 2.0, assemble_linear(disc).mass, vectors=False), "torsional", 3)
    c = math.sqrt(G / RHO)
    impedance = [G * 2 * section_constants(s["outer_radius"], s["inner_radius"]).I4 / c for s in (PIPE, COLLAR)]
    lengths = (240.0, COLLAR["length"])

    def equation(f):
        k = 2 * math.pi * f / c
        return impedance[0] * math.sin(k * lengths[0]) * math.cos(k * lengths[1]) + \
            impedance[1] * math.cos(k * lengths[0]) * math.sin(k * lengths[1])

    exact = [scipy.optimize.brentq(equation, 0.97 * f, 1.03 * f, xtol=1e-14) for f in fe]
    np.testing.assert_allclose(fe, exact, rtol=1e-4)


@pytest.fixture(scope="module")
def jointed_modes():
    """The jointed pipe's drive-held modes, 235 quadratic elements of 2 m (the third torsional mode, 8.5 Hz:
    (kh)^2 / 24 ~ 5e-5, small beside the 0.5 % asked)."""
    disc = BeamDiscretization.from_scene(vertical_string([JOINTED], 235))
    return solve_modes(disc, 1.5, assemble_linear(disc).mass, held=DRIVE, vectors=False)


@pytest.mark.parametrize("kind", ["axial", "torsional"])
def test_homogenised_tool_joints_match_discrete_joints(jointed_modes, kind):
    """Drill pipe with its tool joints homogenised over the pitch (series stiffness, mean inertia) against the
    transfer matrix of the same pipe with every 0.5 m joint its own segment (50 joints in 470 m), drive-held: the
    first three modes within 0.5 % (measured 0.21-0.25 %: the homogenised rod is exact as (k pitch)^2 -> 0, and
    these modes' wavelengths are 15 pitches and more).  Without the joints' stiffness (their steel as mass alone)
    the same modes are more than 1.5 % low (measured 2.1-2.2 %)."""
    fe = fe_family(jointed_modes, kind, 3)
    body = section_constants(JOINTED["outer_radius"], JOINTED["inner_radius"])
    joint = section_constants(JOINTED["tool_joint_outer_radius"], JOINTED["tool_joint_inner_radius"])
    pitch = []
    for c, l in ((body, 9.4 - 0.5), (joint, 0.5)):
        pitch.append((l, E * c.area, RHO * c.area) if kind == "axial" else (l, G * 2 * c.I4, RHO * 2 * c.I4))
    exact = rod_frequencies(pitch * 50, "held", "free", 3, 1.2 * fe[-1])
    np.testing.assert_allclose(fe, exact, rtol=5e-3)
    mass_only = [(l, pitch[0][1], inertia) for l, _, inertia in pitch]
    low = rod_frequencies(mass_only * 50, "held", "free", 3, 1.2 * fe[-1])
    assert np.all(low < (1 - 0.015) * exact)


def lateral_modes(scene, weight_on_bit):
    """The lateral frequencies of the FE string linearised about its static state with ``weight_on_bit``, held by
    the drive, and what it rests on; each lateral frequency once (v and w give each twice in a vertical hole)."""
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    state = operating_state(scene, disc, operators, weight_on_bit, on_wall=True)
    basis = solve_modes(disc, 0.05, operators.mass, held=DRIVE, vectors=False,
                        stiffness=loaded_stiffness(scene, disc, operators, state))
    flexural = fe_family(basis, "flexural", 20)
    return flexural[::2], state, disc


def lateral_against_tensioned_beam(section, elements, weight_on_bit):
    """The first five lateral frequencies of one section hanging in a vertical hole with ``weight_on_bit``, held
    against the tensioned-beam equation within 1e-3 (the discretisation: measured 9e-6 to 1.1e-4 at 0.5-2 m quadratic
    elements); returns (FE, reference, discretisation).  The string rests on nothing: no wall spring enters."""
    fe, state, disc = lateral_modes(vertical_string([section], elements), weight_on_bit)
    assert state.about["vertices_on_the_wall"] == 0
    c = section_constants(section["outer_radius"], section["inner_radius"])
    m = RHO * c.area
    exact = tensioned_beam_frequencies(section["length"], E * c.I4, m, m * 9.81, weight_on_bit, 5)
    np.testing.assert_allclose(fe[:5], exact, rtol=1e-3)
    return fe, exact, disc


def test_lateral_modes_of_a_hanging_string_are_the_tensioned_beams():
    """500 m of drill pipe hanging in a vertical hole in air, clamped by the drive at the top and pinned at the
    bit: its first five lateral frequencies about the static state against the tensioned-beam equation with
    T(s) = w (L - s) (Chebyshev collocation converged to 1e-6), within 1e-3 (the discretisation: measured 4e-5 to
    1e-4 at 2 m quadratic elements, where the tension's boundary layer at the top is sqrt(EI / T) = 3 m thick).
    The unloaded string's are 5 to 18 times lower: the tension, not the bending, sets them."""
    fe, exact, disc = lateral_against_tensioned_beam(dict(PIPE, length=500.0), 250, 0.0)
    unloaded = fe_family(solve_modes(disc, 0.05, assemble_linear(disc).mass, held=DRIVE, vectors=False),
                         "flexural", 10)[::2]
    assert np.all(fe[:5] > 5 * unloaded[:5])


def test_lateral_modes_of_a_bha_under_weight_on_bit_are_the_compressed_beams():
    """120 m of collars in a vertical hole, 30 kN on the bit (its lower 20 m in compression, below Lubinski's first
    critical weight on bit 1.94 (EI w^2)^(1/3) = 51 kN): the first five lateral frequencies about the static state
    against the same equation with T(s) = w (L - s) - P, within 1e-3 (measured 9e-6 to 1.1e-4, as above), and lower
    than without the weight on bit."""
    collar = dict(COLLAR, length=120.0)
    _, exact, _ = lateral_against_tensioned_beam(collar, 240, 30e3)
    c = section_constants(collar["outer_radius"], collar["inner_radius"])
    m = RHO * c.area
    hanging = tensioned_beam_frequencies(120.0, E * c.I4, m, m * 9.81, 0.0, 5)
    assert np.all(exact < hanging)


def test_the_reduced_basis_in_a_well_is_chosen_from_the_prestressed_modes():
    """A reduced model of the 500 m hanging string (the paper's friction laws, so the 'count' rule keeps a modal
    basis): its basis's flexural modes are the prestressed string's, the tensioned beam's within 1e-3 (as above),
    and the modal report's basis indexes the same free-free spectrum."""
    from fenics_drill.model.drillstring import build_model
    from fenics_drill.studies.operating_state import prestressed_modes

    scene = vertical_string([dict(PIPE, length=500.0)], 250, "contact.friction_model='paper'",
                            "reduction.rule='count'", "reduction.flexural=6", "reduction.torsional=2",
                            "reduction.axial=2", "modal.f_star_max=1.0")
    model = build_model(scene, prestressed_modes(scene))
    flexural = model.basis.frequencies_hz[np.array(model.basis.kinds) == "flexural"][::2]
    c = section_constants(PIPE["outer_radius"], PIPE["inner_radius"])
    m = RHO * c.area
    np.testing.assert_allclose(flexural, tensioned_beam_frequencies(500.0, E * c.I4, m, m * 9.81, 0.0, 3), rtol=1e-3)
    report = modal_report(scene)
    kept = [report["modes"][i]["frequency_hz"] for i in report["reduced_basis"]["mode_indices"]]
    np.testing.assert_allclose(sorted(kept), np.sort(model.basis.frequencies_hz), rtol=1e-9)


def test_modal_above_the_first_buckling_load_reports_buckling_not_a_critical_speed_of_zero(tmp_path, capsys):
    """A weightless 50 m pipe in a vertical hole, held at the top (clamped laterally by the drive) and pinned at the
    bit, pressed at the bit: Euler's fixed-pinned column buckles at P = (kL)^2 E I / L^2, tan kL = kL (kL = 4.4934).
    At 0.99 P the drive-held string still has a positive lowest lateral frequency; at 1.01 P the modal analysis says
    it is buckled, which mode and where it bends most (the fixed-pinned shape sin kx - kL cos kx - kx + kL peaks
    where cos kx + kL sin kx = 1), and gives no critical speed.  The 1 % margin is far above the discretisation's
    error (40 quadratic elements: the first lateral mode of the unloaded pipe within 1e-6 of the beam's)."""
    from fenics_drill.cli import main
    from fenics_drill.scene import load_scene

    brentq = scipy.optimize.brentq
    E_, R, r, L = 203e9, 0.08, 0.05, 50.0
    kL = brentq(lambda z: math.tan(z) - z, 4.4, 4.5)
    critical = kL**2 * E_ * math.pi / 4 * (R**4 - r**4) / L**2
    peak = brentq(lambda x: math.cos(kL * x) + kL * math.sin(kL * x) - 1.0, 0.3, 0.9) * L
    base = [f"beam.length={L}", "beam.elements=40", f"beam.outer_radius={R}", f"beam.inner_radius={r}",
            f"beam.young_modulus={E_}", "well.md=[0.0, 50.0]", "well.inclination=[0.0, 0.0]",
            "well.azimuth=[0.0, 0.0]", "model.gravity=false", "modal.state='static'", "reduction.rule='none'"]
    below = modal_report(load_scene(None, [*base, f"modal.weight_on_bit={0.99 * critical}"]))
    assert below["buckled"] is None and all(f > 0 for f in below["lateral_critical_speeds_rpm"])
    above = modal_report(load_scene(None, [*base, f"modal.weight_on_bit={1.01 * critical}"]))
    buckled = above["buckled"]
    assert buckled is not None and above["lateral_critical_speeds_rpm"] == []
    first = buckled["modes"][0]
    assert first["kind"] == "flexural" and first["omega_squared"] < 0
    assert abs(first["largest_lateral_displacement_at_m"] - peak) <= L / 40  # within one element
    assert buckled["weight_on_bit_N"] == pytest.approx(1.01 * critical, rel=1e-12)
    overrides = [arg for key in [*base, f"modal.weight_on_bit={1.01 * critical}"] for arg in ("--set", key)]
    assert main(["modal", *overrides, "--out", str(tmp_path / "modal")]) == 0
    out = capsys.readouterr().out
    assert "BUCKLED: the string is buckled at" in out and "critical speeds" not in out
    # far beyond the load (100 times: modes so unstable that the band's shift does not reach them), still said
    far = modal_report(load_scene(None, [*base, f"modal.weight_on_bit={100 * critical}"]))
    assert far["buckled"] is not None and far["lateral_critical_speeds_rpm"] == []


def test_campbell_of_a_buckled_string_says_so_instead_of_a_diagram(capsys, tmp_path):
    """The paper's 20 m pipe straight (no wall), compressed at 1 MN, 3.6 times its fixed-pinned Euler load
    (20.19 E I / L^2 = 279 kN): refused in one line saying it is buckled and has no critical speed."""
    from fenics_drill.cli import main

    code = main(["campbell", "--set", "beam.length=20", "--set", "beam.elements=40", "--set", "campbell.axial_force=1e6",
                 "--set", "campbell.state='straight'", "--set", "campbell.rotation_speed=[0.0, 6.0, 2]",
                 "--out", str(tmp_path / "c")])
    err = capsys.readouterr().err
    assert code == 2 and "the string is buckled under 1000 kN of axial compression" in err, err
    assert len(err.strip().splitlines()) == 1
