"""``fenics-drill calibrate``: the cased and open-hole friction factors fitted to the rig's measured hook loads and
torques (:mod:`fenics_drill.io.measured`), so that the next section's loads are predicted from this well's own
friction.

The soft string (:class:`~fenics_drill.studies.broomstick.ChartString`) gives, at each measured bit depth, the
indicated hook load of tripping out (pick-up), tripping in (slack-off) and rotating off bottom, and the surface torque
off and on bottom.  The residuals, each divided by its column's root-mean-square measured value (so that kN and
kN m weigh alike), are minimised by bounded least squares (``scipy.optimize.least_squares``, factors in [0, 1], the
block weight >= 0 when it is fitted): first the cased factor on the points with the bit inside the casing (the
open hole takes no part there), then the open-hole factor on the points below the shoe with the cased one fixed.
Each factor's interval is the 95 % one of the linearised fit: value -+ t(0.975, m - p) s sqrt((J^T J)^-1) with s^2
the residuals' sum of squares over m - p (Student's t; m points, p factors).  Also reported: the residual at every
point, a warning where pick-up and slack-off disagree by more than friction can explain (the frictionless hook load
must lie between them), and the friction factor back-calculated at each point alone (the one factor that makes the
model meet that measurement), a track against depth.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import t as student

from fenics_drill.io.files import write_atomic, write_json
from fenics_drill.io.measured import HOOK_LOADS, read_measured
from fenics_drill.studies.broomstick import BLOCK_MOTION, ChartString, broomstick_study, indicator_factor
from fenics_drill.studies.lifecycle import command_output

#: The operation whose hook load (or torque) each measured column is, and which: (operation, "hook"|"torque").
MODELLED = {"pick_up": ("tripping_out", "hook"), "slack_off": ("tripping_in", "hook"),
            "rotating_off_bottom": ("rotating_off_bottom", "hook"),
            "torque_off_bottom": ("rotating_off_bottom", "torque"), "torque_on_bottom": ("rotating_on_bottom", "torque")}
OPERATIONS = ("tripping_out", "tripping_in", "rotating_off_bottom", "rotating_on_bottom")
#: The friction factors at which each point's own factor is read off (then by linear interpolation).
TRACK_GRID = np.linspace(0.0, 1.0, 401)
#: Pick-up and slack-off whose frictionless hook load lies outside them by more than this share of it are flagged.
HYSTERESIS_SHARE = 0.01


class Calibration:
    """The model of the measured points: the indicated loads at their depths for friction factors and a block
    weight."""

    def __init__(self, scene, measured: dict):
        self.scene, self.measured = scene, measured
        self.string = ChartString(scene)
        self.depths = measured["bit_depth"]
        self.columns = [c for c in MODELLED if c in measured]
        bs = scene.broomstick
        self.factor = {op: indicator_factor(bs.lines, bs.sheave_efficiency, BLOCK_MOTION[op]) for op in OPERATIONS}
        cased = self.string.well.hole.cased
        self.shoe = float(self.string.well.hole.bottoms[cased].max()) if cased.any() else 0.0

    def loads(self, pairs: np.ndarray, block: float, at: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Each measured column's model (points, pairs) at the points ``at`` (default all) for friction ``pairs``."""
        index = np.arange(self.depths.size) if at is None else at
        out = {c: np.empty((index.size, pairs.shape[0])) for c in self.columns}
        for row, k in enumerate(index):
            hook, torque = self.string.surface_loads(self.depths[k], list(OPERATIONS), pairs)
            for c in self.columns:
                operation, kind = MODELLED[c]
                j = OPERATIONS.index(operation)
                out[c][row] = self.factor[operation] * (hook[j] + block) if kind == "hook" else torque[j]
        return out

    def residuals(self, pair, block: float, at: np.ndarray) -> np.ndarray:
        """The measured minus the model over the points ``at``, each column over its RMS measured value."""
        model = self.loads(np.array([pair], dtype=float), block, at)
        parts = []
        for c in self.columns:
            measured = self.measured[c][at]
            keep = np.isfinite(measured)
            parts.append((measured[keep] - model[c][keep, 0]) / self.scale(c))
        return np.concatenate(parts)

    def scale(self, column: str) -> float:
        """The column's RMS measured value: what its residuals are divided by."""
        values = self.measured[column][np.isfinite(self.measured[column])]
        return float(np.sqrt(np.mean(values**2))) if values.size and np.any(values) else 1.0


def _interval(result, count: int) -> np.ndarray | None:
    """The 95 % intervals' half-widths of a least-squares result over ``count`` points (None: undetermined)."""
    parameters = result.x.size
    if count <= parameters:
        return None
    jac = result.jac
    try:
        covariance = np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        return None
    s2 = float(result.fun @ result.fun) / (count - parameters)
    return student.ppf(0.975, count - parameters) * np.sqrt(np.maximum(np.diag(covariance) * s2, 0.0))


def _fit(calibration: Calibration, at: np.ndarray, fixed_cased: float | None, block: float, fit_block: bool):
    """Bounded least squares over the points ``at``: (cased, open) factors, or the open one with the cased one
    ``fixed_cased``; and the block weight where ``fit_block``.  (values, half-widths or None, points)."""
    if fixed_cased is not None:
        names = ["friction_open"]
    elif np.all(calibration.depths[at] <= calibration.shoe + 1e-9):
        names = ["friction_cased"]
    else:  # no point in casing: both factors from the points below the shoe
        names = ["friction_cased", "friction_open"]
    names += ["block_weight"] * fit_block
    start = {"friction_cased": 0.25, "friction_open": 0.25, "block_weight": max(block, 1.0)}
    upper = {"friction_cased": 1.0, "friction_open": 1.0, "block_weight": np.inf}

    def unpack(x):
        values = dict(zip(names, x))
        cased = values.get("friction_cased", fixed_cased if fixed_cased is not None else 0.0)
        return (cased, values.get("friction_open", cased)), values.get("block_weight", block)

    result = least_squares(lambda x: calibration.residuals(*unpack(x), at), [start[n] for n in names],
                           bounds=([0.0] * len(names), [upper[n] for n in names]), x_scale="jac")
    count = result.fun.size
    half = _interval(result, count)
    return dict(zip(names, result.x)), (None if half is None else dict(zip(names, half))), count


def calibrate(scene, measured: dict, fit_block: bool = False) -> dict:
    """The calibration of a scene's friction factors (and block weight) to ``measured`` (SI columns, as
    :func:`~fenics_drill.io.measured.read_measured` gives them): what ``calibration.json`` holds."""
    clock = time.perf_counter()
    calibration = Calibration(scene, measured)
    depths = calibration.depths
    in_casing = np.flatnonzero(depths <= calibration.shoe + 1e-9)
    below = np.flatnonzero(depths > calibration.shoe + 1e-9)
    block = scene.broomstick.block_weight
    report = {"casing_shoe_m": calibration.shoe, "points": int(depths.size), "points_in_casing": int(in_casing.size),
              "points_in_open_hole": int(below.size), "columns": calibration.columns, "warnings": []}
    fitted, halves = {}, {}
    if in_casing.size:
        values, half, count = _fit(calibration, in_casing, None, block, fit_block)
        fitted.update(values)
        halves.update(half or {name: None for name in values})
        block = fitted.get("block_weight", block)
    if below.size:
        values, half, count = _fit(calibration, below, fitted.get("friction_cased"), block,
                                   fit_block and "block_weight" not in fitted)
        fitted.update(values)
        halves.update(half or {name: None for name in values})
        block = fitted.get("block_weight", block)
    for name, where in (("friction_cased", "inside the casing"), ("friction_open", "in open hole")):
        value, half = fitted.get(name), halves.get(name)
        entry = {"value": None if value is None else float(value),
                 "interval": None if value is None or half is None else
                 [float(max(value - half, 0.0)), float(min(value + half, 1.0))]}
        if value is None:
            entry["message"] = f"undetermined: no measured point with the bit {where}"
            report["warnings"].append(f"{name} is undetermined: no measured point with the bit {where}")
        elif half is None:
            entry["message"] = "its interval is undetermined: as many factors as points"
        report[name] = entry
    report["block_weight_N"] = {"value": float(block), "fitted": bool(fit_block),
                                "interval": None if not fit_block or halves.get("block_weight") is None else
                                [float(max(block - halves["block_weight"], 0.0)),
                                 float(block + halves["block_weight"])]}
    pair = np.array([[fitted.get("friction_cased", fitted.get("friction_open", 0.0)),
                      fitted.get("friction_open", fitted.get("friction_cased", 0.0))]])
    model = calibration.loads(pair, block)
    report["measured"] = {name: [None if not np.isfinite(v) else float(v) for v in values]
                          for name, values in measured.items()}
    report["model"] = {c: [float(v) for v in model[c][:, 0]] for c in calibration.columns}
    report["residuals"] = {c: [None if not np.isfinite(m) else float(m - v) for m, v in
                               zip(measured[c], model[c][:, 0])] for c in calibration.columns}
    report["calibrated_pair"] = pair[0].tolist()
    report["warnings"] += _hysteresis(calibration, block)
    report["back_calculated"] = _track(calibration, float(pair[0, 0]), block)
    report["wall_time_s"] = time.perf_counter() - clock
    return report


def _hysteresis(calibration: Calibration, block: float) -> list[str]:
    """Where pick-up and slack-off are both measured, the frictionless model's indicated hook loads must lie
    between them: a warning for each point where they do not (by more than HYSTERESIS_SHARE)."""
    measured = calibration.measured
    if "pick_up" not in measured or "slack_off" not in measured:
        return []
    both = np.flatnonzero(np.isfinite(measured["pick_up"]) & np.isfinite(measured["slack_off"]))
    if not both.size:
        return []
    free = calibration.loads(np.zeros((1, 2)), block, both)
    warnings = []
    for row, k in enumerate(both):
        up, down = measured["pick_up"][k], measured["slack_off"][k]
        free_up, free_down = free["pick_up"][row, 0], free["slack_off"][row, 0]
        tolerance = HYSTERESIS_SHARE * free_up
        if up < free_up - tolerance or down > free_down + tolerance:
            warnings.append(f"at bit depth {calibration.depths[k]:.1f} m pick-up {up / 1e3:.1f} kN and slack-off "
                            f"{down / 1e3:.1f} kN disagree by more than friction can explain: without friction the "
                            f"indicator would read {free_up / 1e3:.1f} kN and {free_down / 1e3:.1f} kN, between them "
                            "(deadline hysteresis, or an indicator zeroed with another block weight)")
    return warnings


def _track(calibration: Calibration, cased: float, block: float) -> dict[str, list]:
    """The friction factor that makes the model meet each measured point alone: the cased one for a bit in casing,
    the open-hole one below (the cased one at its calibrated value); None where no factor in [0, 1] does."""
    track = {c: [] for c in calibration.columns}
    grid = TRACK_GRID
    for k, depth in enumerate(calibration.depths):
        in_casing = depth <= calibration.shoe + 1e-9
        pairs = np.column_stack([grid, grid]) if in_casing else np.column_stack([np.full_like(grid, cased), grid])
        model = calibration.loads(pairs, block, np.array([k]))
        for c in calibration.columns:
            value, curve = calibration.measured[c][k], model[c][0]
            track[c].append(_crossing(grid, curve, value) if np.isfinite(value) else None)
    return track


def _crossing(grid: np.ndarray, curve: np.ndarray, value: float) -> float | None:
    """The grid value at which the monotone ``curve`` meets ``value`` (linear between grid points), or None where
    it does not, or where the curve does not depend on the factor (a vertical hole: friction takes no part)."""
    if abs(curve[-1] - curve[0]) <= 1e-9 * np.max(np.abs(curve)):
        return None
    rising = curve[-1] >= curve[0]
    ordered = curve if rising else curve[::-1]
    abscissa = grid if rising else grid[::-1]
    if not ordered[0] <= value <= ordered[-1]:
        return None
    return float(np.interp(value, ordered, abscissa))


def write_calibration(scene, measured_path: str | Path, out: str | Path, overwrite: bool = False,
                      fit_block: bool = False) -> dict:
    """``fenics-drill calibrate``: DIR/calibration.json, the scene's chart (broomstick.nc) and the calibrated pair's
    (calibrated.nc), and summary.json."""
    out = Path(out)
    string = ChartString(scene)
    measured = read_measured(measured_path, string.well.depth)  # refused before the directory is taken
    with command_output(out, "calibrate", scene, overwrite) as summary:
        report = calibrate(scene, measured, fit_block)
        report["measured_file"] = str(Path(measured_path).resolve())
        chart = broomstick_study(scene)["chart"]
        calibrated = broomstick_study(scene.with_changes(broomstick={
            "friction_pairs": [report["calibrated_pair"]], "block_weight": report["block_weight_N"]["value"]}))["chart"]
        write_atomic(out / "broomstick.nc", lambda tmp: chart.to_netcdf(tmp, engine="h5netcdf"))
        write_atomic(out / "calibrated.nc", lambda tmp: calibrated.to_netcdf(tmp, engine="h5netcdf"))
        write_json(out / "calibration.json", report)
        summary["message"] = "calibration.json"
        summary["friction_cased"] = report["friction_cased"]
        summary["friction_open"] = report["friction_open"]
    return report
