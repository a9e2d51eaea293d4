"""fenics-drill run / static: the files a user opens, and what an interrupted or failed run keeps."""

import json

import h5py
import meshio
import numpy as np
import pytest
import xarray as xr

from fenics_drill.cli import main
from fenics_drill.scene import load_scene

from conftest import expected_status

SHORT = ["--set", "beam.length=10.0", "--set", "beam.elements=10", "--set", "time.t_end=0.05",
         "--set", "output.field_interval=0.01", "--set", "reduction.rule='count'",
         "--set", "reduction.flexural=6", "--set", "reduction.torsional=2", "--set", "reduction.axial=2"]


def test_run_writes_summary_timeseries_and_fields(tmp_path):
    assert main(["run", *SHORT, "--quiet", "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == expected_status(load_scene(None, SHORT[1::2]))
    assert summary["t_end"] == pytest.approx(0.05)
    for key in ("steps", "newton_iterations", "wall_time_s", "mean_bit_velocity", "rop", "impacts_total",
                "efficiency", "signed_rop", "stick_slip", "bit_bounce"):
        assert key in summary
    assert 0.0 <= summary["efficiency"] <= 1.0  # (96) with positive parts: output cannot exceed input
    assert 0.0 <= summary["max_von_mises"]["t"] <= 0.05 and 0.0 <= summary["max_von_mises"]["x"] <= 10.0
    assert set(summary["energy"]) >= {"input_work", "kinetic", "strain", "dissipated", "balance_error"}
    ds = xr.open_dataset(tmp_path / "timeseries.h5", engine="h5netcdf", phony_dims="sort")
    assert ds.sizes["time"] == summary["steps"] + 1  # the initial state and every accepted step
    assert ds["bit_velocity"].attrs["units"] == "m/s"
    assert ds["impacts_per_vertex"].dims == ("vertex_x",)
    # the bit displacement is the integral of the bit velocity (trapezoidal rule of Newmark, gamma ~ 1/2)
    t = ds["time"].values
    assert t[0] == 0.0
    with h5py.File(tmp_path / "timeseries.h5") as f:
        u, v = f["bit_displacement"][()], f["bit_velocity"][()]
        assert f["modes/frequency"].shape == f["modes/kind"].shape and f["modes/frequency"][-1] > 0
    travel = np.trapezoid(v, t)
    assert u[-1] - u[0] == pytest.approx(travel, rel=0.05)
    xdmf = (tmp_path / "fields.xdmf").read_text()
    with h5py.File(tmp_path / "fields.h5") as f:
        assert set(f["Function"]) == {"u", "v", "w", "theta_x", "theta_y", "theta_z", "displacement", "von_mises",
                                      "axial_force", "torque", "wall_normal_force_per_length"}
        snapshots = list(f["Function/w"])
        assert len(snapshots) == 6  # t = 0, 0.01, ..., 0.05
        assert f["Function/w"][snapshots[0]].shape[0] == 11  # P1: one value per vertex
    assert 'Name="w"' in xdmf and 'Name="theta_x"' in xdmf
    # the XDMF index opens as a time series (meshio reads it the way ParaView's XDMF reader does)
    reader = meshio.xdmf.TimeSeriesReader(tmp_path / "fields.xdmf")
    points, cells = reader.read_points_cells()
    assert points.shape == (11, 3) and cells[0].type == "line" and len(cells[0].data) == 10
    assert reader.num_steps == 6
    t_last, point_data, cell_data = reader.read_data(reader.num_steps - 1)
    assert t_last == pytest.approx(0.05) and point_data["displacement"].shape == (11, 3)
    assert cell_data["von_mises"][0].shape == (10, 1)
    # fenics-drill plot: every figure, the spectra and the animation from the saved files alone
    assert main(["plot", str(tmp_path)]) == 0
    for name in ("fig13_static_3d", "fig14_bit_axial", "fig17_section_radial", "fig19_impacts_position",
                 "surface_loads", "fig20_sections", "fig20_3d", "fig21_psd", "fig22_psd", "fig23_psd"):
        assert (tmp_path / f"{name}.png").stat().st_size > 10_000, name
    assert (tmp_path / "animation.gif").exists()
    spectra = json.loads((tmp_path / "spectra.json").read_text())
    assert set(spectra) == {"bit_velocity", "bit_angular_velocity", "section_w_velocity",
                            "section_theta_x_velocity", "impacts"}


def test_static_writes_sag_and_contact_positions(tmp_path):
    assert main(["static", *SHORT[:4], "--set", "model.supports='pinned'", "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "static.json").read_text())
    assert report["max_sag"] > 0
    assert isinstance(report["contact_vertices"], list)


def test_bad_scene_is_refused_before_computing(tmp_path, capsys):
    assert main(["run", "--set", "time.newmark_alpha=0.9", "--out", str(tmp_path)]) == 2
    assert "time.newmark_alpha" in capsys.readouterr().err
    assert not (tmp_path / "summary.json").exists()


def test_sigterm_ends_a_run_like_ctrl_c_and_keeps_its_results(tmp_path):
    """A batch system's time limit (SIGTERM) must not lose the run: summary and series are written."""
    import subprocess
    import sys
    import time

    # a run far longer than the test waits for (more steps than time.max_steps allows unasked: asked for here)
    long_run = ["time.t_end=1000" if a.startswith("time.t_end") else a for a in SHORT] + ["--set", "time.max_steps=1e12"]
    process = subprocess.Popen([sys.executable, "-m", "fenics_drill.cli", "run", *long_run, "--quiet",
                                "--out", str(tmp_path)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.time() + 120
    while not (tmp_path / "fields.h5").exists() and time.time() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)  # some steps into the dynamics
    process.terminate()
    assert process.wait(timeout=60) == 130
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "interrupted" and 0 < summary["t_end"] < 1000
    with h5py.File(tmp_path / "timeseries.h5") as f:
        assert f["time"][-1] == pytest.approx(summary["t_end"])
