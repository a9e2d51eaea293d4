"""A reference shared by the tests of the axial-torsional string's two integrations (the finite-element model's run
and the compiled steps): steady rotation on bottom against the soft string."""

import math

import numpy as np

import fenics_drill as fd
from fenics_drill.forms.properties import section_constants
from fenics_drill.model.string_sections import string_sections


def steady_rotation_references(means_of, normal_force="static", pressed_for=None):
    """The build-and-hold demo well, axial-torsional (90 elements), drilled at 240 rpm and 15 m/h with the paper's bit
    law (no stick-slip at that speed), its wall pressed for the law's steady force at that rate,
    Gamma (1 - exp(-alpha V0)), and the damping (38) at c = 2 /s that settles the start's torsional waves within 6 s
    (a string sliding steadily on the wall is not damped by its Coulomb friction).  ``means_of(scene)`` gives the
    run's means over its last 2 s of 6 s: hook_load, surface_torque, weight_on_bit, bit_torque, rop, and the bit's
    spin there.  Returns (the scene, those means, (the soft string's hook load, its surface torque plus the viscous
    torque of the string turning at the drive's speed, c Omega sum(rho I_p L) over the sections)), the soft string
    (``torque-drag``) rotating on bottom at the run's mean bit loads and rop.  ``normal_force``: the wall's
    (``contact.normal_force``); ``pressed_for``: a weight on bit [N] to start from and press the static wall for,
    instead of the law's steady force."""
    scene = fd.load_scene("demos/scenes/well_build_hold.toml", [
        "model.lateral_length=0.0", "beam.elements=90", "time.t_end=6", "output.field_interval=0",
        "drive.rotation_speed='240 rpm'", "bit_rock.law='paper'", "drive.mode='velocity'", "beam.damping=2.0"])
    b = scene.bit_rock
    steady_force = b.limit_force * -math.expm1(-b.rate * scene.drive.axial_velocity)
    scene = scene.with_changes(drive={"weight_on_bit": steady_force if pressed_for is None else pressed_for},
                               contact={"normal_force": normal_force})
    means = means_of(scene)
    omega = scene.drive.rotation_speed
    assert np.all(np.abs(means["spin"] / omega - 1.0) < 0.05)  # steady rotation, no stick-slip
    soft = fd.torque_drag(scene.with_changes(torque_drag={
        "weight_on_bit": means["weight_on_bit"], "torque_on_bit": means["bit_torque"],
        "rate_of_penetration": means["rop"]})).report["operations"]["rotating_on_bottom"]
    viscous = sum(scene.beam.damping * omega * s.mass_per_length / (math.pi * (s.outer_radius**2 - s.inner_radius**2))
                  * 2.0 * section_constants(s.outer_radius, s.inner_radius).I4 * s.rotary_inertia_factor
                  * (s.bottom - s.top) for s in string_sections(scene))
    return scene, means, (soft["hook_load_N"], soft["surface_torque_Nm"] + viscous)
