"""Time series of a run in HDF5, readable with h5py and xarray (netCDF-4 dimension scales): the one
writer and the one reader of ``timeseries.h5``.

Each variable (:data:`fenics_drill.observables.step_rows.VARIABLES`) is a resizable
dataset along the ``time`` dimension with ``units`` and ``long_name`` attributes; rows
are buffered and flushed every few hundred steps, so an interrupted run keeps
everything up to its last flush.
"""

from __future__ import annotations

from pathlib import Path

import json

import h5py
import numpy as np

from fenics_drill.observables.step_rows import VARIABLES
from fenics_drill.scene import validate

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


def read_series(path: str | Path) -> tuple[dict, dict]:
    """(variables, attributes) of a saved ``timeseries.h5``; the attribute ``scene`` is the run's Scene."""
    with h5py.File(path, "r") as f:
        data = {k: f[k][()] for k in f.keys() if isinstance(f[k], h5py.Dataset)}
        attrs = dict(f.attrs)
    attrs["scene"] = validate(json.loads(attrs["scene"]))
    return data, attrs


def read_modes(path: str | Path) -> tuple[np.ndarray, list[str]]:
    """(natural frequencies [Hz], kinds) of the band B stored with a run."""
    with h5py.File(path, "r") as f:
        return f["modes/frequency"][()], [k.decode() for k in f["modes/kind"][()]]


def open_dataset(path: str | Path):
    """The time series as an ``xarray.Dataset`` loaded into memory (the file is closed again)."""
    import xarray

    return xarray.load_dataset(path, engine="h5netcdf")
