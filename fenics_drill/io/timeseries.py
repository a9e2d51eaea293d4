"""Time series of a run in HDF5, readable with h5py and xarray (netCDF-4 dimension scales): the one
writer and the one reader of ``timeseries.h5``.

Each variable (:data:`fenics_drill.observables.step_rows.VARIABLES`) is a resizable
dataset along the ``time`` dimension with ``units`` and ``long_name`` attributes; rows
are buffered and written every few seconds of wall time, so a run keeps everything up
to its last write, whatever ends it.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import h5py
import numpy as np

from fenics_drill.io.files import FlushClock, UnreadableFile, update_hdf5, write_atomic
from fenics_drill.observables.step_rows import VARIABLES
from fenics_drill.scene import validate

class TimeSeriesWriter:
    """Appends one row per accepted step to ``path`` (HDF5); the group ``modes`` holds the natural
    frequencies and families of the band B, to name spectral peaks.

    The file is whole at every moment: it is created complete (with no rows) before the first
    step, and the buffered rows are appended every few seconds of wall time (:class:`FlushClock`) to
    a copy renamed into place (:func:`update_hdf5`).  A kill (SIGKILL, the out-of-memory killer)
    loses only the rows since the last write."""

    def __init__(self, path: str | Path, vertex_x: np.ndarray, attributes: dict, modes=None,
                 clock: FlushClock | None = None, held_modes=None):
        """``modes``: the band B of the free string; ``held_modes``: of the string held by the drive."""
        self.path = Path(path)
        self.clock = clock or FlushClock()
        self.buffer: dict[str, list] = {name: [] for name in VARIABLES}
        self.rows_written = 0  # rows in the file: the initial state and the accepted steps
        write_atomic(self.path, lambda tmp: self._create(tmp, vertex_x, attributes, modes, held_modes))

    @staticmethod
    def _create(path: Path, vertex_x: np.ndarray, attributes: dict, modes, held_modes) -> None:
        with h5py.File(path, "w") as f:
            for key, value in attributes.items():
                f.attrs[key] = value
            for name, (units, long_name) in VARIABLES.items():
                ds = f.create_dataset(name, shape=(0,), maxshape=(None,), dtype="f8", chunks=(512,))
                ds.attrs["units"], ds.attrs["long_name"] = units, long_name
            f["time"].make_scale("time")
            for name in VARIABLES:
                if name != "time":
                    f[name].dims[0].attach_scale(f["time"])
            x = f.create_dataset("vertex_x", data=vertex_x)
            x.attrs["units"], x.attrs["long_name"] = "m", "x of the mesh vertices"
            x.make_scale("vertex_x")
            counts = f.create_dataset("impacts_per_vertex", data=np.zeros(len(vertex_x)))
            counts.attrs["units"] = "1"
            counts.attrs["long_name"] = "wall impacts per vertex (contact after moving clear of the wall)"
            counts.dims[0].attach_scale(x)
            for name, basis, what in (("modes", modes, "natural frequencies of the band B (Eq. 62)"),
                                      ("modes_drive_held", held_modes, "natural frequencies of the band B with "
                                       "u and theta_x held at x = 0, as the drive holds them in a run")):
                if basis is not None:
                    group = f.create_group(name)
                    group["frequency"] = basis.frequencies_hz
                    group["frequency"].attrs["units"] = "Hz"
                    group["frequency"].attrs["long_name"] = what
                    group["kind"] = np.array(basis.kinds, dtype="S")

    def append(self, row: dict) -> bool:
        """Buffer one row; write the buffer when the clock says so.  True if it was written."""
        for name in VARIABLES:
            self.buffer[name].append(row[name])
        if self.clock.due():
            self.flush()
            return True
        return False

    def flush(self, impacts_per_vertex: np.ndarray | None = None) -> None:
        """Append the whole buffered rows (and the impact counts) to the file."""
        # an interrupt (Ctrl-C, SIGTERM) inside append() can leave a row half-buffered: keep whole rows only
        n = min(len(values) for values in self.buffer.values())
        if not n and impacts_per_vertex is None:
            return
        started = time.monotonic()

        def update(f) -> None:
            for name, values in self.buffer.items():
                ds = f[name]
                ds.resize((ds.shape[0] + n,))
                ds[ds.shape[0] - n:] = values[:n]
            if impacts_per_vertex is not None:
                f["impacts_per_vertex"][:] = impacts_per_vertex

        update_hdf5(self.path, update)
        self.rows_written += n
        for values in self.buffer.values():
            del values[:n]
        self.clock.wrote(time.monotonic() - started)

    def close(self, impacts_per_vertex: np.ndarray | None = None) -> None:
        self.flush(impacts_per_vertex)


def read_series(path: str | Path) -> tuple[dict, dict]:
    """(variables, attributes) of a saved ``timeseries.h5``; the attribute ``scene`` is the run's Scene.
    UnreadableFile naming the file if it is not a whole time series."""
    try:
        with h5py.File(path, "r") as f:
            data = {k: f[k][()] for k in f.keys() if isinstance(f[k], h5py.Dataset)}
            attrs = dict(f.attrs)
        attrs["scene"] = validate(json.loads(attrs["scene"]))
    except (OSError, KeyError, ValueError) as err:
        raise UnreadableFile(f"{path} is not a readable time series (truncated or corrupt?): {err}") from err
    return data, attrs


def read_modes(path: str | Path, group: str = "modes") -> tuple[np.ndarray, list[str]] | None:
    """(natural frequencies [Hz], kinds) of the band B stored with a run (``group`` "modes": the free
    string; "modes_drive_held": held by the drive), or None if the run stored no such group."""
    with h5py.File(path, "r") as f:
        if group not in f:
            return None
        return f[f"{group}/frequency"][()], [k.decode() for k in f[f"{group}/kind"][()]]


def open_dataset(path: str | Path):
    """The time series as an ``xarray.Dataset`` loaded into memory (the file is closed again)."""
    import xarray

    return xarray.load_dataset(path, engine="h5netcdf")
