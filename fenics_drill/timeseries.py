"""Time series of a run in HDF5, readable with h5py and xarray (netCDF-4 dimension scales).

Each variable is a resizable dataset along the ``time`` dimension with ``units``
and ``long_name`` attributes; rows are buffered and flushed every few hundred
steps, so an interrupted run keeps everything up to its last flush.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

#: name: (units, long name) of every per-step variable.
VARIABLES = {
    "time": ("s", "simulated time"),
    "dt": ("s", "time step that reached this instant"),
    "newton_iterations": ("1", "Newton iterations of the step"),
    "bit_displacement": ("m", "axial displacement of the bit u(L)"),
    "bit_velocity": ("m/s", "axial velocity of the bit u_dot(L)"),
    "bit_rotation": ("rad", "rotation of the bit theta_x(L)"),
    "bit_angular_velocity": ("rad/s", "angular velocity of the bit theta_x_dot(L)"),
    "bit_force": ("N", "bit-rock force F_BR, Eq. (20)"),
    "bit_torque": ("N m", "bit-rock torque T_BR, Eq. (21)"),
    "lambda_1": ("N", "Lagrange multiplier lambda_1 of (74): -lambda_1 is the force the drive applies at x = 0"),
    "lambda_4": ("N m", "Lagrange multiplier lambda_4 of (74): -lambda_4 is the torque the drive applies at x = 0"),
    "impacts": ("1", "vertices whose wall contact began during the step"),
    "vertices_in_contact": ("1", "vertices in contact with the wall at the end of the step"),
    "section_v": ("m", "lateral displacement v at the recorded section"),
    "section_w": ("m", "lateral displacement w at the recorded section"),
    "section_v_velocity": ("m/s", "lateral velocity v_dot at the recorded section"),
    "section_w_velocity": ("m/s", "lateral velocity w_dot at the recorded section"),
    "section_theta_x_velocity": ("rad/s", "angular velocity theta_x_dot at the recorded section"),
    "max_von_mises": ("Pa", "maximum von Mises stress over the string (NaN if output.von_mises is off)"),
    "max_von_mises_x": ("m", "x where the maximum von Mises stress sits"),
    "kinetic_energy": ("J", "kinetic energy, Eq. (24)"),
    "strain_energy": ("J", "strain energy, Eq. (30)"),
    "input_work": ("J", "work of the drive since t = 0"),
    "dissipated_energy": ("J", "energy dissipated since t = 0"),
}

FLUSH_ROWS = 500


class TimeSeriesWriter:
    """Appends one row per accepted step to ``path`` (HDF5); the group ``modes`` holds
    the natural frequencies and families of the band B, to name spectral peaks."""

    def __init__(self, path: str | Path, vertex_x: np.ndarray, attributes: dict, modes=None):
        self.file = h5py.File(path, "w")
        for key, value in attributes.items():
            self.file.attrs[key] = value
        self.buffer: dict[str, list] = {name: [] for name in VARIABLES}
        for name, (units, long_name) in VARIABLES.items():
            ds = self.file.create_dataset(name, shape=(0,), maxshape=(None,), dtype="f8", chunks=(512,))
            ds.attrs["units"], ds.attrs["long_name"] = units, long_name
        self.file["time"].make_scale("time")
        for name in VARIABLES:
            if name != "time":
                self.file[name].dims[0].attach_scale(self.file["time"])
        x = self.file.create_dataset("vertex_x", data=vertex_x)
        x.attrs["units"], x.attrs["long_name"] = "m", "x of the mesh vertices"
        x.make_scale("vertex_x")
        counts = self.file.create_dataset("impacts_per_vertex", data=np.zeros(len(vertex_x)))
        counts.attrs["units"], counts.attrs["long_name"] = "1", "wall impacts (contact onsets) per vertex"
        counts.dims[0].attach_scale(x)
        if modes is not None:
            group = self.file.create_group("modes")
            group["frequency"] = modes.frequencies_hz
            group["frequency"].attrs["units"] = "Hz"
            group["frequency"].attrs["long_name"] = "natural frequencies of the band B (Eq. 62)"
            group["kind"] = np.array(modes.kinds, dtype="S")

    def append(self, row: dict) -> None:
        for name in VARIABLES:
            self.buffer[name].append(row[name])
        if len(self.buffer["time"]) >= FLUSH_ROWS:
            self.flush()

    def flush(self, impacts_per_vertex: np.ndarray | None = None) -> None:
        # an interrupt (Ctrl-C, SIGTERM) inside append() can leave a row half-buffered: keep whole rows only
        n = min(len(values) for values in self.buffer.values())
        if n:
            for name, values in self.buffer.items():
                ds = self.file[name]
                ds.resize((ds.shape[0] + n,))
                ds[-n:] = values[:n]
                values.clear()
        if impacts_per_vertex is not None:
            self.file["impacts_per_vertex"][:] = impacts_per_vertex
        self.file.flush()

    def close(self, impacts_per_vertex: np.ndarray | None = None) -> None:
        self.flush(impacts_per_vertex)
        self.file.close()
