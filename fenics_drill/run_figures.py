"""``fenics-drill plot DIR``: everything a person looks at after a run, from its saved files.

timeseries.h5 -> Figs. 14-19, spectra (Figs. 21-23) and spectra.json (Section 6.8 peaks
with the nearest natural frequencies); fields.h5 -> Figs. 13 and 20 and animation.gif.
"""

from __future__ import annotations

from pathlib import Path

import h5py

from fenics_drill.drilling_quantities import read_series
from fenics_drill.pictures import make_pictures
from fenics_drill.plots import spectra_figures, spectra_json, time_series_figures, write_json
from fenics_drill.spectra import run_spectra


def run_spectra_of(run_dir: Path) -> dict:
    """Spectra of a saved run, peaks named by the modes stored with it."""
    data, _ = read_series(run_dir / "timeseries.h5")
    with h5py.File(run_dir / "timeseries.h5", "r") as f:
        frequencies = f["modes/frequency"][()]
        kinds = [k.decode() for k in f["modes/kind"][()]]
    return run_spectra(data, frequencies, kinds)


def plot_run(run_dir: Path, gif: bool = True) -> list[Path]:
    data, attrs = read_series(run_dir / "timeseries.h5")
    paths = time_series_figures(data, attrs, run_dir)
    spectra = run_spectra_of(run_dir)
    paths += spectra_figures(spectra, run_dir)
    write_json(run_dir / "spectra.json", spectra_json(spectra))
    paths.append(run_dir / "spectra.json")
    return paths + make_pictures(run_dir, gif)
