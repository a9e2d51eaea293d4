"""``fenics-drill broomstick``: the soft string's hook load and surface torque against bit depth, for the chart's
operations and a grid of (cased, open-hole) friction factors, as the rig's weight indicator reads them.

At each bit depth (every ``broomstick.depth_step`` to the well's bottom) the string is the scene's, made up from the
bit as a rig runs it (:func:`~fenics_drill.model.string_sections.string_at_bit_depth`), and every operation with
every friction pair is one pass of the compiled soft string (:func:`~fenics_drill.model.soft_string.
soft_string_batch`).  The rig's side:

* the weight indicator reads the hook load plus the travelling equipment's weight (``block_weight``), times the
  deadline sensor's factor with ``lines`` strung lines and sheave efficiency e: n e^n (1 - e) / (1 - e^n) while
  hoisting (tripping out), the same with 1/e for e while lowering (tripping in, drilling), 1 at rest (rotating off
  bottom), from the line tensions that fall by e over each of the n + 1 sheaves between the fast line and the
  deadline in the direction the line runs;
* the minimum weight to helical buckling: the indicated hook load, sliding on bottom, at the weight on bit at which
  the string first buckles helically somewhere (its compression reaches the helical load of
  :mod:`~fenics_drill.observables.buckling`), found by bisection on the weight on bit;
* the maximum weight for yield: the indicated hook load, tripping out, at which the pipe body first yields in
  tension somewhere (an overpull adds to the tension all along a string free at the bit).

Files: ``broomstick.nc`` (an xarray dataset over ``depth``, ``operation`` and ``pair``), ``broomstick.csv`` (one row
per depth, operation and friction pair, with units in the header), ``broomstick.json``, and the chart.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from fenics_drill.forms import section_constants
from fenics_drill.io.files import write_atomic, write_json
from fenics_drill.model.soft_string import Operation, operations, soft_string_batch, string_mesh
from fenics_drill.model.string_sections import string_at_bit_depth
from fenics_drill.model.well import string_in_well
from fenics_drill.observables.buckling import helical_load
from fenics_drill.scene import SceneError
from fenics_drill.studies.lifecycle import command_output

#: Whether the block hoists (+1), lowers (-1) or rests (0) in each operation, for the weight indicator's factor.
BLOCK_MOTION = {"tripping_out": 1, "tripping_in": -1, "sliding": -1, "rotating_on_bottom": -1,
                "rotating_off_bottom": 0}
#: Bisection steps on the weight on bit for the helical buckling limit (its resolution: the string's weight / 2^n).
BUCKLING_BISECTIONS = 30
#: Most bit depths a chart takes (one soft string per depth and operation).
MAX_DEPTHS = 20_000


def indicator_factor(lines: int, efficiency: float, motion: int) -> float:
    """What the deadline sensor reads over the hook load: n e^n (1 - e) / (1 - e^n), e the sheave efficiency while
    hoisting (``motion`` 1), 1/e while lowering (-1); 1 at rest, without lines or without losses."""
    if lines == 0 or motion == 0 or efficiency == 1.0:
        return 1.0
    e = efficiency if motion > 0 else 1.0 / efficiency
    return lines * e**lines * (1.0 - e) / (1.0 - e**lines)


def friction_pairs(scene) -> np.ndarray:
    """The chart's (cased, open-hole) friction factors, (P, 2): ``broomstick.friction_pairs``, or every cased factor
    with every open one."""
    bs = scene.broomstick
    if bs.friction_pairs:
        return np.array(bs.friction_pairs, dtype=float)
    return np.array([(c, o) for c in bs.friction_cased for o in bs.friction_open], dtype=float)


def chart_depths(scene, well_depth: float) -> np.ndarray:
    """Every ``broomstick.depth_step`` from the first to the well's bottom, the bottom itself the last."""
    step = scene.broomstick.depth_step
    count = int(np.floor(well_depth / step * (1 + 1e-12)))
    if count + 1 > MAX_DEPTHS:
        raise SceneError(f"broomstick.depth_step = {step:g} m is not admissible for this {well_depth:g} m well: "
                         f"{count + 1} bit depths, more than {MAX_DEPTHS}")
    depths = step * np.arange(1, count + 1)
    return depths if depths.size and depths[-1] >= well_depth - 1e-9 else np.append(depths, well_depth)


def _string_in_well(scene, sections, well, depth: float):
    """(soft-string mesh, its sections, the cased elements) of the string with its bit at ``depth``: the mesh's
    friction row is 0 in cased hole and 1 in open hole, to be replaced by a pair's factors."""
    at_depth = string_at_bit_depth(sections, depth)
    g, outer, inner = scene.environment.gravity, scene.fluid.density, scene.inner_fluid_density
    weights = np.array([s.buoyed_weight(g, outer, inner) for s in at_depth])
    mesh = string_mesh(well, at_depth, scene.torque_drag.element_length, weights, 0.0, 1.0)
    return mesh, at_depth, mesh.friction == 0.0


def _frictions(cased: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Each pair's friction coefficient on every element (P, elements): its cased factor in cased hole."""
    return np.where(cased[None, :], pairs[:, :1], pairs[:, 1:])


def _helical_limit(scene, well, mesh, sections, frictions: np.ndarray) -> np.ndarray:
    """For each friction row: the weight on bit [N] at which the string, sliding on bottom, first buckles helically
    somewhere (bisection; NaN where it does not before its hook load falls to zero), and the hook load there."""
    middle = 0.5 * (mesh.md[1:] + mesh.md[:-1])
    stiffness = np.array([sections[k].bending_stiffness for k in mesh.section])
    clearance = well.hole.radius(middle) - mesh.contact_radius
    f_hel = helical_load(stiffness, mesh.weight, well.trajectory.inclination(middle), clearance,
                         well.trajectory.curvature(middle))
    sliding = operations(scene, ["sliding"])[0]
    rows = frictions.shape[0]

    def evaluate(weights_on_bit):
        batch = [Operation("sliding", sliding.axial_velocity, 0.0, -w, sliding.bit_torque) for w in weights_on_bit]
        tension = soft_string_batch(mesh, batch, frictions)["tension"]
        compression = -0.5 * (tension[:, 1:] + tension[:, :-1])
        return np.min(f_hel[None, :] - compression, axis=1), tension[:, 0]

    heaviest = float(np.sum(mesh.weight * np.diff(mesh.md)))  # no weight on bit beyond the string's weight
    low, high = np.zeros(rows), np.full(rows, heaviest)
    margin_low, _ = evaluate(low)
    margin_high, _ = evaluate(high)
    for _ in range(BUCKLING_BISECTIONS):
        halfway = 0.5 * (low + high)
        buckled = evaluate(halfway)[0] <= 0.0
        high, low = np.where(buckled, halfway, high), np.where(buckled, low, halfway)
    limit = np.where(margin_low <= 0.0, 0.0, high)  # buckled by the drag alone, or at the bisection's bound
    _, hook = evaluate(limit)
    # none where the string's whole weight does not buckle it, or where it locks up (the hook would push) first
    none = (margin_high > 0.0) | (hook <= 0.0)
    return np.where(none, np.nan, limit), np.where(none, np.nan, hook)


def _yield_limit(scene, mesh, sections, tension: np.ndarray) -> np.ndarray:
    """For each row of tripping-out tensions (B, nodes): the hook load [N] at which the pipe body first yields in
    tension somewhere, an overpull adding to the tension all along a string free at the bit."""
    area = np.array([section_constants(sections[k].outer_radius, sections[k].inner_radius).area
                     for k in mesh.section])
    top = np.maximum(tension[:, :-1], tension[:, 1:])
    return tension[:, 0] + np.min(scene.broomstick.yield_strength * area[None, :] - top, axis=1)


class ChartString:
    """The scene's string and well, made up at any bit depth: the soft string's surface loads of operations over
    friction pairs, what a chart, a calibration and a Monte Carlo of friction factors ask at many depths."""

    def __init__(self, scene, well=None):
        if not (scene.well.survey or scene.well.md):
            raise SceneError("a broomstick chart needs a well: give its survey in [well] (survey or md, inclination, "
                             "azimuth) and its string in [[string.sections]]")
        self.scene = scene
        resolved = string_in_well(scene)
        self.sections = list(resolved.sections)
        self.well = well if well is not None else resolved.well
        self._made_up = {}

    def made_up(self, depth: float):
        """(mesh, sections, cased elements) of the string with its bit at ``depth`` (:func:`_string_in_well`), made
        once per depth."""
        if depth not in self._made_up:
            self._made_up[depth] = _string_in_well(self.scene, self.sections, self.well, depth)
        return self._made_up[depth]

    def surface_loads(self, depth: float, names: list[str], pairs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(hook load, surface torque) [N, N m] at the hook, each (operations, pairs), with the bit at ``depth``."""
        mesh, _, cased = self.made_up(depth)
        frictions = _frictions(cased, pairs)
        batch = [op for op in operations(self.scene, names) for _ in range(pairs.shape[0])]
        loads = soft_string_batch(mesh, batch, np.tile(frictions, (len(names), 1)))
        return loads["tension"][:, 0].reshape(len(names), -1), loads["torque"][:, 0].reshape(len(names), -1)

    def limits(self, depth: float, pairs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(weight on bit at helical buckling, hook load there, hook load that yields the pipe) [N] per pair, with
        the bit at ``depth`` (:func:`_helical_limit`, :func:`_yield_limit`), at the hook."""
        mesh, at_depth, cased = self.made_up(depth)
        frictions = _frictions(cased, pairs)
        wob, hook = _helical_limit(self.scene, self.well, mesh, at_depth, frictions)
        out = soft_string_batch(mesh, [operations(self.scene, ["tripping_out"])[0]] * pairs.shape[0], frictions)
        return wob, hook, _yield_limit(self.scene, mesh, at_depth, out["tension"])


def broomstick_study(scene) -> dict:
    """The chart of a scene: ``report`` (JSON-ready) and ``chart`` (an ``xarray.Dataset`` over ``depth``,
    ``operation``, ``pair``: the indicated hook load and the surface torque of every operation and friction pair, the
    minimum weight to helical buckling and the maximum weight for yield per pair)."""
    import xarray

    clock = time.perf_counter()
    string = ChartString(scene)
    bs = scene.broomstick
    depths = chart_depths(scene, string.well.depth)
    pairs = friction_pairs(scene)
    names = list(bs.operations)
    shape = (depths.size, len(names), pairs.shape[0])
    hook, torque = np.empty(shape), np.empty(shape)
    helical_wob, helical_hook, yield_hook = (np.empty((depths.size, pairs.shape[0])) for _ in range(3))
    for i, depth in enumerate(depths):
        hook[i], torque[i] = string.surface_loads(depth, names, pairs)
        helical_wob[i], helical_hook[i], yield_hook[i] = string.limits(depth, pairs)
    factors = np.array([indicator_factor(bs.lines, bs.sheave_efficiency, BLOCK_MOTION[n]) for n in names])
    indicated = factors[None, :, None] * (hook + bs.block_weight)
    lowering = indicator_factor(bs.lines, bs.sheave_efficiency, -1)
    hoisting = indicator_factor(bs.lines, bs.sheave_efficiency, 1)
    chart = xarray.Dataset(
        {"hook_load": (("depth", "operation", "pair"), indicated, {"units": "N", "long_name": "indicated hook load"}),
         "hook_load_at_the_hook": (("depth", "operation", "pair"), hook, {"units": "N"}),
         "surface_torque": (("depth", "operation", "pair"), torque, {"units": "N m"}),
         "helical_buckling_hook_load": (("depth", "pair"), lowering * (helical_hook + bs.block_weight),
                                        {"units": "N", "long_name": "minimum weight to helical buckling"}),
         "helical_buckling_weight_on_bit": (("depth", "pair"), helical_wob, {"units": "N"}),
         "yield_hook_load": (("depth", "pair"), hoisting * (yield_hook + bs.block_weight),
                             {"units": "N", "long_name": "maximum weight for yield"}),
         "friction_cased": ("pair", pairs[:, 0]), "friction_open": ("pair", pairs[:, 1])},
        coords={"depth": ("depth", depths, {"units": "m", "long_name": "bit depth (measured)"}),
                "operation": names, "pair": np.arange(pairs.shape[0])},
        attrs={"block_weight_N": bs.block_weight, "lines": bs.lines, "sheave_efficiency": bs.sheave_efficiency,
               "hook_load_limit_N": bs.hook_load_limit, "torque_limit_Nm": bs.torque_limit})
    report = {"depths": depths.size, "depth_step_m": bs.depth_step, "well_depth_m": string.well.depth,
              "operations": names, "friction_pairs": pairs.tolist(), "block_weight_N": bs.block_weight,
              "indicator_factors": dict(zip(names, factors.tolist())),
              "at_bottom": {name: {"hook_load_N": [float(v) for v in indicated[-1, j]],
                                   "surface_torque_Nm": [float(v) for v in torque[-1, j]]}
                            for j, name in enumerate(names)},
              "wall_time_s": time.perf_counter() - clock}
    return {"report": report, "chart": chart}


def chart_table(chart) -> str:
    """The chart as CSV text, one row per depth, operation and friction pair, the units in the header."""
    rows = ["bit_depth (m),operation,friction_cased (-),friction_open (-),hook_load (N),surface_torque (N*m)"]
    cased, open_hole = chart["friction_cased"].values, chart["friction_open"].values
    hook, torque = chart["hook_load"].values, chart["surface_torque"].values
    for i, depth in enumerate(chart["depth"].values):
        for j, name in enumerate(chart["operation"].values):
            rows += [f"{depth:.6g},{name},{cased[p]:.6g},{open_hole[p]:.6g},{hook[i, j, p]:.9g},{torque[i, j, p]:.9g}"
                     for p in range(cased.size)]
    return "\n".join(rows) + "\n"


def write_broomstick(scene, out: str | Path, overwrite: bool = False) -> dict:
    """``fenics-drill broomstick``: DIR/broomstick.nc, broomstick.csv, broomstick.json and summary.json."""
    out = Path(out)
    with command_output(out, "broomstick", scene, overwrite) as summary:
        study = broomstick_study(scene)
        write_atomic(out / "broomstick.nc", lambda tmp: study["chart"].to_netcdf(tmp, engine="h5netcdf"))
        write_atomic(out / "broomstick.csv", lambda tmp: Path(tmp).write_text(chart_table(study["chart"])))
        write_json(out / "broomstick.json", study["report"])
        summary["message"] = "broomstick.json"
    return study
