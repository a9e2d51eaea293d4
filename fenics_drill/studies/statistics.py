"""Statistics of a Monte Carlo study (Section 6.11): convergence metric (101), mean, nominal and
95 % envelope of the histories (Figs. 29, 31, 33), PDFs by kernel density estimation (Figs. 30,
32, 34, 35), written to ``DIR/statistics.h5`` and ``DIR/summary.json``.

The realisations are read in index order, so the statistics are the same whatever
the number of processes that computed them.  Failed realisations (the step control
gave up) are counted and left out.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
from scipy import stats

from fenics_drill.io.files import write_json
from fenics_drill.io.realisations import NOMINAL, read_realisation, realisation_path
from fenics_drill.studies.prepare import HISTORIES

#: Points of the KDE curves.
PDF_POINTS = 200
PERCENTILES = (2.5, 50.0, 97.5)


def convergence_metric(q_norm_integrals: np.ndarray) -> np.ndarray:
    """conv_MC(n) = sqrt(1/n sum_{k<=n} int ||q_k||^2 dt), Eq. (101), for n = 1..N."""
    n = np.arange(1, len(q_norm_integrals) + 1)
    return np.sqrt(np.cumsum(q_norm_integrals) / n)


def kde(values: np.ndarray, normalised: bool = False) -> tuple[np.ndarray, np.ndarray] | None:
    """(points, density) of a Gaussian KDE; standardised to zero mean, unit deviation if asked.
    None when the values do not spread (fewer than 2, or equal to round-off: zero dispersions)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if len(values) < 2 or np.std(values) <= 1e-12 * np.max(np.abs(values)):
        return None
    if normalised:
        values = (values - values.mean()) / values.std()
    spread = values.std()
    points = np.linspace(values.min() - 3 * spread, values.max() + 3 * spread, PDF_POINTS)
    return points, stats.gaussian_kde(values)(points)


def _scalar_summary(values: np.ndarray) -> dict:
    values = values[np.isfinite(values)]
    if values.size == 0:
        return {}
    p = np.percentile(values, PERCENTILES)
    return {"mean": float(values.mean()), "std": float(values.std(ddof=1)) if values.size > 1 else 0.0,
            "p2.5": float(p[0]), "p50": float(p[1]), "p97.5": float(p[2])}


def write_statistics(out: Path, samples: int) -> dict:
    """Read realisations 0..samples-1, write statistics.h5 and summary.json, return the summary."""
    results = [read_realisation(realisation_path(out, k)) for k in range(samples)]
    ok = [r for r in results if r["status"] == "finished"]
    if not ok:
        raise RuntimeError(f"none of the {samples} realisations finished; see their messages in {out}/realisations")
    nominal = read_realisation(out / NOMINAL)
    time = ok[0]["time"]
    # (realisations of earlier versions lack efficiency_torque_magnitude: NaN, left out of its summary)
    scalars = {key: np.array([r.get(key, np.nan) for r in ok], dtype=float)
               for key in ("rop", "efficiency", "efficiency_torque_magnitude", "signed_rop", "mean_bit_velocity",
                           "max_von_mises")}
    conv = convergence_metric(np.array([r["q_norm_integral"] for r in ok]))
    with h5py.File(out / "statistics.h5", "w") as f:
        f.attrs["realisations"] = len(ok)
        f.attrs["failed"] = len(results) - len(ok)
        f["time"] = time
        f["time"].attrs["units"] = "s"
        f["convergence_metric"] = conv
        f["convergence_metric"].attrs["long_name"] = "conv_MC(n_s), Eq. (101), for n_s = 1..N"
        for name in HISTORIES:
            stack = np.stack([r["histories"][name] for r in ok])
            g = f.create_group(name)
            g["mean"] = stack.mean(axis=0)
            g["nominal"] = nominal["histories"][name]
            low, high = np.percentile(stack, [2.5, 97.5], axis=0)
            g["p2.5"], g["p97.5"] = low, high
            g.attrs["long_name"] = f"{name}: mean, nominal and 95 % envelope over the realisations"
        pdfs = f.create_group("pdf")
        for name, values, normalised in (
            ("bit_velocity_at_t_end", [r["histories"]["bit_velocity"][-1] for r in ok], True),
            ("bit_angular_velocity_at_t_end", [r["histories"]["bit_angular_velocity"][-1] for r in ok], True),
            ("efficiency", scalars["efficiency"], False),
            ("rop", scalars["rop"], False),
        ):
            curve = kde(np.array(values), normalised)
            if curve is not None:
                g = pdfs.create_group(name)
                g["points"], g["density"] = curve
                g.attrs["normalised"] = normalised
        for key, values in scalars.items():
            f[f"scalars/{key}"] = values
    summary = {
        "realisations": len(ok), "failed": len(results) - len(ok), "convergence_metric": float(conv[-1]),
        "nominal": {key: float(nominal.get(key, np.nan)) for key in scalars},
        **{key: _scalar_summary(values) for key, values in scalars.items()},
        "wall_time_per_realisation_s": float(np.mean([r["wall_time_s"] for r in results])),
    }
    write_json(out / "summary.json", {"command": "mc", "status": "finished", **summary})
    return summary
