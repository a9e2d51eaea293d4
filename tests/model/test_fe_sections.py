"""The finite-element string of sections in a hole of sections: each section's mass, stiffness and weight in the
mud on its elements, the tool joints' steel and contact radius, each vertex's clearance.  Closed forms: the axial
modes of a two-section rod, a composite string hanging in a vertical hole, each section resting at its own
clearance; and the soft string's hook load on a realistic string in a 3D well."""

import math

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

from fenics_drill.model.discretization import U, BeamDiscretization
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.string_sections import section_at, string_sections
from fenics_drill.observables.von_mises import VonMisesProbe
from fenics_drill.scene import load_scene
from fenics_drill.studies.prepare import prepare
from fenics_drill.studies.torque_drag import torque_drag_study

PIPE = {"name": "drill pipe", "length": 60.0, "outer_radius": 0.0635, "inner_radius": 0.0543}
COLLAR = {"name": "collar", "length": 40.0, "outer_radius": 0.0857, "inner_radius": 0.0357}


def sectioned(sections, *overrides, **tables):
    """A scene with these string sections (from the bit up) and whole tables (``well={...}``), hanging off bottom."""
    from fenics_drill.scene import validate

    merged = load_scene(None, ["contact.friction_model='paper'", "contact.sliding_velocity_scale=1e-3",
                               "drive.start='off_bottom'", *overrides]).to_dict()
    merged["string"]["sections"] = list(sections)
    for name, table in tables.items():
        merged[name].update(table)
    return validate(merged)


def test_axial_modes_of_a_two_section_string_are_the_composite_rods():
    """u held at the top, free at the bit, a collar below drill pipe: Z1 cot(k1 L1) = Z2 tan(k2 L2) with
    Z = A sqrt(E rho) omega, k = omega sqrt(rho / E) (continuity of u and of E A u' at the joint).  The first three
    roots within 1e-6 (200 quadratic elements)."""
    scene = sectioned([COLLAR, PIPE], "beam.elements=200", "well.md=[0.0, 100.0]", "well.inclination=[90.0, 90.0]",
                      "well.azimuth=[0.0, 0.0]")
    disc = BeamDiscretization.from_scene(scene)
    ops = assemble_linear(disc)
    top = disc.end_dof(U, 0)
    dofs = np.setdiff1d(disc.field_dofs[U], [top])
    K = ops.stiffness[dofs][:, dofs].toarray()
    M = ops.mass[dofs][:, dofs].toarray()
    fe = np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True, subset_by_index=[0, 2])) / (2 * math.pi)
    E, rho = scene.beam.young_modulus, scene.beam.density
    area = [math.pi * (s["outer_radius"] ** 2 - s["inner_radius"] ** 2) for s in (PIPE, COLLAR)]  # top down
    lengths = (PIPE["length"], COLLAR["length"])
    c = math.sqrt(E / rho)

    def mismatch(f):
        k = 2 * math.pi * f / c
        return area[0] * math.cos(k * lengths[0]) * math.cos(k * lengths[1]) \
            - area[1] * math.sin(k * lengths[0]) * math.sin(k * lengths[1])

    grid = np.linspace(1.0, 1.2 * fe[-1], 20000)
    values = np.array([mismatch(f) for f in grid])
    roots = [scipy.optimize.brentq(mismatch, a, b) for a, b, fa, fb in
             zip(grid[:-1], grid[1:], values[:-1], values[1:]) if fa * fb < 0][:3]
    assert fe == pytest.approx(roots, rel=1e-6)
    one_pipe = c / (4 * sum(lengths))  # a uniform rod's first mode: the sections move it
    assert abs(fe[0] / one_pipe - 1) > 0.05


def test_a_composite_string_hangs_with_its_buoyed_weight_and_stretches_section_by_section():
    """Collar below drill pipe with tool joints, in a vertical hole in mud: the hook load is the sum of each
    section's buoyed weight (tool joints included, 1e-9), and in air, with linear strains, each section stretches
    under the weight below it, sum_k (T_k L_k + w_k L_k^2 / 2) / (E A_k) with T_k the weight hanging below
    section k, and carries the stress T(x) / A(x) in its body (1e-9: u is quadratic in each section, which the
    quadratic elements hold exactly).  The pipe's tool joints (OD 168 mm, 0.45 m every 9.4 m) stiffen it in series
    with its body: E A = E / ((1 - f) / A_body + f / A_joint), f = 0.45 / 9.4."""
    joint = dict(PIPE, tool_joint_outer_radius=0.084, tool_joint_length=0.45, tool_joint_spacing=9.4)
    for mud, strains in ((1200.0, "true"), (0.0, "false")):
        scene = sectioned([COLLAR, joint], "beam.elements=100", f"fluid.density={mud}",
                          f"model.geometric_nonlinearity={strains}",
                          well={"md": [0.0, 100.0], "inclination": [0.0, 0.0], "azimuth": [0.0, 0.0]})
        prepared = prepare(scene, dynamics=False)
        model = prepared.model
        sections = string_sections(scene)  # top down
        g = scene.environment.gravity
        weights = [s.buoyed_weight(g, mud, mud) for s in sections]
        lengths = [s.bottom - s.top for s in sections]
        assert prepared.static["hook_load"] == pytest.approx(sum(w * l for w, l in zip(weights, lengths)), rel=1e-9)
        assert model.disc.weight == pytest.approx(prepared.static["hook_load"], rel=1e-9)
    below, stretch = 0.0, 0.0
    for s, w, l in reversed(list(zip(sections, weights, lengths))):
        area = math.pi * (s.outer_radius**2 - s.inner_radius**2)
        if s.contact_radius > s.outer_radius:  # the jointed pipe: body and joint in series over the pitch
            f = 0.45 / 9.4
            area = 1.0 / ((1 - f) / area + f / (math.pi * (s.contact_radius**2 - s.inner_radius**2)))
        stretch += (below * l + w * l**2 / 2) / (s.young_modulus * area)
        below += w * l
    dofs = model.space.expand(prepared.equilibrium.q)
    assert dofs[model.disc.end_dof(U, 1)] == pytest.approx(stretch, rel=1e-9)
    # the stress each section carries, T(x) / A(x), read by the von Mises probe with each cell's radius and E
    probe = VonMisesProbe(model.disc, geometric_nonlinearity=False)
    x, stress = probe.x.ravel(), probe.stress(dofs).ravel()
    k = np.repeat(section_at(sections, probe.x.mean(axis=1)), probe.x.shape[1])  # each point's cell's section
    below = np.array([sum(w * l for w, l in zip(weights[j + 1:], lengths[j + 1:])) for j in range(len(sections))])
    tension = below[k] + np.array(weights)[k] * (np.array([s.bottom for s in sections])[k] - x)
    area = np.array([math.pi * (s.outer_radius**2 - s.inner_radius**2) for s in sections])[k]
    assert stress == pytest.approx(tension / area, rel=1e-9, abs=1e-9 * stress.max())


def test_each_section_rests_at_its_own_clearance():
    """A collar below drill pipe with tool joints in a horizontal hole: the pipe lies on the wall at the tool
    joints' clearance R_h - R_tj, the collar at its own R_h - R_c (within 1e-6 m: the wall springs' penetration,
    measured 7e-8 m),
    and the wall carries the lateral weight between the supports."""
    joint = dict(PIPE, tool_joint_outer_radius=0.084, tool_joint_length=0.45, tool_joint_spacing=9.4)
    scene = sectioned([COLLAR, joint], "beam.elements=200", "borehole.radius=0.108",
                      well={"md": [0.0, 100.0], "inclination": [90.0, 90.0], "azimuth": [0.0, 0.0]})
    prepared = prepare(scene, dynamics=False)
    model = prepared.model
    v, w = (rows @ prepared.equilibrium.q for rows in model.lateral_rows)
    x = model.disc.vertex_x
    for (a, b), clearance in (((15.0, 50.0), 0.108 - 0.084), ((70.0, 90.0), 0.108 - 0.0857)):
        on = (x > a) & (x < b)
        assert np.all(np.abs(np.hypot(v[on], w[on]) - clearance) < 1e-6), (a, b)
    assert prepared.static["contact_force_total"] < model.disc.weight


def test_fe_hook_load_of_a_real_string_in_a_3d_well_is_the_soft_strings():
    """Collar, stabiliser, heavy-weight and drill pipe with tool joints, in mud, in a well that builds and turns
    through a cased and an open hole: the FE static hook load against the soft string off bottom, within 1e-3 (the
    stiff string's bending where it crosses the hole and at the stabiliser; measured 1.1e-4)."""
    sections = [COLLAR, {"name": "stabiliser", "length": 1.5, "outer_radius": 0.0857, "inner_radius": 0.0357,
                         "tool_joint_outer_radius": 0.105, "tool_joint_length": 1.5, "tool_joint_spacing": 1.5},
                dict(PIPE, name="heavy-weight", inner_radius=0.0381),
                dict(PIPE, length=198.5, tool_joint_outer_radius=0.084, tool_joint_length=0.45,
                     tool_joint_spacing=9.4)]
    scene = sectioned(sections, "beam.elements=300", "fluid.density=1200.0", "torque_drag.element_length=0.5",
                      well={"md": [0.0, 100.0, 200.0, 300.0], "inclination": [0.0, 0.0, 30.0, 30.0],
                            "azimuth": [0.0, 0.0, 45.0, 45.0], "hole_bottom": [150.0, 300.0],
                            "hole_radius": [0.112, 0.108], "hole_cased": [True, False]})
    prepared = prepare(scene, dynamics=False)
    hook = torque_drag_study(scene)["report"]["operations"]["rotating_off_bottom"]["hook_load_N"]
    assert prepared.static["hook_load"] == pytest.approx(hook, rel=1e-3)
