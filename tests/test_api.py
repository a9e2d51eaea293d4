"""The public API a notebook user calls (``import fenics_drill as fd``), checked against closed forms."""

import math

import numpy as np
import pytest
from conftest import PAPER, expected_status

import fenics_drill as fd

#: A 10 m pinned-pinned string with only gravity and the linear beam: closed forms hold.
LINEAR = ["beam.length=10", "beam.elements=20", "model.supports='pinned'", "model.contact=false",
          "model.bit_rock=false", "model.geometric_nonlinearity=false", "model.inertial_nonlinearity=false",
          "reduction.rule='none'"]


def test_modal_analysis_gives_the_pinned_pinned_bending_frequency():
    scene = fd.load_scene(PAPER, LINEAR)
    modes = fd.modal_analysis(scene)
    p = scene.beam_properties
    first = min(m["frequency_hz"] for m in modes["modes"] if m["kind"] == "flexural")
    euler = (math.pi / p.length) ** 2 * math.sqrt(p.young_modulus * p.section.I4 / (p.density * p.section.area))
    # L / r_g = 210: shear and rotary inertia lower the Euler-Bernoulli value by ~(pi r_g / L)^2 = 2e-4
    assert first == pytest.approx(euler / (2 * math.pi), rel=1e-3)


def test_static_state_gives_the_timoshenko_sag_of_a_pinned_beam():
    scene = fd.load_scene(PAPER, [*LINEAR, "beam.elements=80"])
    p = scene.beam_properties
    q, L = p.density * p.section.area * p.gravity, p.length
    exact = 5 * q * L**4 / (384 * p.young_modulus * p.section.I4) \
        + q * L**2 / (8 * p.shear_factor * p.shear_modulus * p.section.area)
    # the sag converges at rate h^2 (tests/solvers): 2.0e-3 off at 20 elements, so ~1.3e-4 at 80
    assert fd.static_state(scene)["max_sag"] == pytest.approx(exact, rel=3e-4)


def test_run_returns_its_summary_and_its_time_series_as_xarray(tmp_path):
    scene = fd.load_scene(PAPER, [*LINEAR, "time.t_end=0.02"]).with_changes(drive={"rotation_speed": 3.0})
    assert scene.drive.rotation_speed == 3.0 and scene.beam.length == 10.0
    run = fd.run(scene, out=tmp_path)
    series = run.series
    assert run.summary["status"] == expected_status(scene)
    assert series["bit_displacement"].attrs["units"] == "m"
    # the drive holds u(0) = V0 t and the string is stiff axially: the bit follows at V0 on average
    travel = float(series["bit_displacement"][-1] - series["bit_displacement"][0])
    assert travel / float(series["time"][-1]) == pytest.approx(run.summary["mean_bit_velocity"], rel=1e-12)
    assert np.isclose(run.summary["mean_bit_velocity"], scene.drive.axial_velocity, rtol=0.05)


@pytest.mark.parametrize("first", ["fenics_drill.studies.prepare", "fenics_drill.model.internal_force"])
def test_any_module_imported_first_leaves_h5py_able_to_write(first, tmp_path):
    """A notebook may import any module first.  dolfinx.fem.petsc loads its own HDF5; h5py imported after
    it failed at import ("Not a datatype") until the package loaded h5py first.  A fresh interpreter
    (the import order is per process) writes and reads back a dataset; 300 s bounds a hung import."""
    import subprocess
    import sys

    script = (f"import {first}\nimport h5py\nwith h5py.File({str(tmp_path / 'x.h5')!r}, 'w') as f: f['a'] = [1.5]\n"
              f"print(h5py.File({str(tmp_path / 'x.h5')!r})['a'][0])")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert float(done.stdout.split()[-1]) == 1.5
