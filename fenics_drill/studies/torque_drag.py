"""``fenics-drill torque-drag``: hook load, surface torque and the profiles along a well of the soft-string model
(:mod:`fenics_drill.model.soft_string`) for each operation, with the buckling loads of the pipe in its hole
(:mod:`fenics_drill.observables.buckling`).

Files: ``torque_drag.json`` (the well, the string, and per operation the surface loads and where the string buckles),
``torque_drag.h5`` (the profiles, an xarray/netCDF-4 dataset over the nodes' measured depth) and ``well.vtu`` (the
string's axis with its profiles, for ParaView).  On a well, ``fenics-drill static`` writes the FE static state's
profiles beside the soft string's (:func:`fe_static_profiles`, ``static_profiles.h5``).
"""

from __future__ import annotations

import time
from pathlib import Path

import meshio
import numpy as np

from fenics_drill.io.files import write_atomic, write_json
from fenics_drill.model.discretization import THETA_X, THETA_Y, THETA_Z, U, V, W
from fenics_drill.model.soft_string import operations, soft_string, stretch, string_mesh
from fenics_drill.model.well import dogleg_severity_deg_per_30m, string_in_well
from fenics_drill.observables.buckling import buckled_spans, helical_load, sinusoidal_load
from fenics_drill.observables.torque_drag import string_profiles
from fenics_drill.scene import SceneError
from fenics_drill.studies.lifecycle import command_output


def _fluids(scene) -> tuple[float, float]:
    outer = scene.fluid.density
    return outer, outer if scene.fluid.inner_density == -1.0 else scene.fluid.inner_density


#: The most elements of the soft string a study takes (1 cm elements along 10 km; its loads converge at 10 m).
MAX_SOFT_STRING_ELEMENTS = 1e6


def torque_drag_study(scene) -> dict:
    """The soft-string study of a scene: ``report`` (JSON-ready) and ``profiles`` (an ``xarray.Dataset``: node values
    over ``md``, element values over ``md_element``)."""
    clock = time.perf_counter()
    resolved = string_in_well(scene)
    sections, well = resolved.sections, resolved.well
    g = scene.environment.gravity
    outer, inner = _fluids(scene)
    weights = np.array([s.buoyed_weight(g, outer, inner) for s in sections])
    td = scene.torque_drag
    elements = sections[-1].bottom / td.element_length
    if elements > MAX_SOFT_STRING_ELEMENTS:
        raise SceneError(f"torque_drag.element_length = {td.element_length:g} m is not admissible for this "
                         f"{sections[-1].bottom:g} m string: {elements:.3g} elements, more than "
                         f"{MAX_SOFT_STRING_ELEMENTS:g} (the soft string converges at 10 m elements: "
                         "docs/wells.md)")
    mesh = string_mesh(well, sections, td.element_length, weights, td.friction_cased, td.friction_open)
    middle = 0.5 * (mesh.md[1:] + mesh.md[:-1])
    clearance = well.hole.radius(middle) - mesh.contact_radius
    if np.any(clearance <= 0):
        k = int(np.argmin(clearance))
        name = sections[mesh.section[k]].name
        raise SceneError(f"string section '{name}' (contact radius {mesh.contact_radius[k]:g} m) does not fit the hole "
                         f"of radius {well.hole.radius(middle[k])[0]:g} m at md = {middle[k]:.1f} m")
    trajectory = well.trajectory
    inclination = trajectory.inclination(middle)
    stiffness = np.array([sections[k].bending_stiffness for k in mesh.section])
    curvature = trajectory.curvature(middle)
    f_sin = sinusoidal_load(stiffness, mesh.weight, inclination, clearance, curvature)
    f_hel = helical_load(stiffness, mesh.weight, inclination, clearance, curvature)
    position = trajectory.positions(mesh.md)
    profiles = {"md": mesh.md, "north": position[:, 0], "east": position[:, 1], "tvd": -position[:, 2],
                "md_element": middle, "inclination_deg": np.degrees(inclination),
                "sinusoidal_buckling_load": f_sin, "helical_buckling_load": f_hel}
    results = {}
    for operation in operations(scene):
        loads = soft_string(mesh, operation)
        compression = -0.5 * (loads["tension"][1:] + loads["tension"][:-1])
        ds = np.diff(mesh.md)
        sinusoidal = (compression > f_sin) & (compression <= f_hel)
        helical = compression > f_hel
        for name in ("tension", "torque", "wall_force_per_length"):
            profiles[f"{name}_{operation.name}"] = loads[name]
        profiles[f"buckling_{operation.name}"] = np.where(helical, 2, np.where(sinusoidal, 1, 0))
        spans = buckled_spans(middle, ds, compression, f_sin, f_hel)
        results[operation.name] = {
            "hook_load_N": float(loads["tension"][0]),
            "surface_torque_Nm": float(loads["torque"][0]),
            "axial_velocity_m_s": operation.axial_velocity, "rotation_speed_rad_s": operation.rotation_speed,
            "bit_force_N": operation.bit_force, "bit_torque_Nm": operation.bit_torque,
            **{k: spans[k] for k in ("max_compression_N", "sinusoidally_buckled_length_m",
                                     "helically_buckled_length_m", "first_buckled_md_m")},
            "max_wall_force_per_length_N_m": float(loads["wall_force_per_length"].max()),
            "stretch_m": stretch(mesh, sections, loads["tension"], -0.5 * (position[1:, 2] + position[:-1, 2]), g,
                                 outer, inner),
            # the hook cannot push: a string that needs a negative hook load does not go down (lock-up)
            "locked_up": bool(loads["tension"][0] < 0.0),
        }
    survey = trajectory.survey
    report = {
        "well": {"measured_depth_m": well.depth, "true_vertical_depth_m": float(-trajectory.stations[-1, 2]),
                 "horizontal_displacement_m": float(np.hypot(*trajectory.stations[-1, :2])),
                 "max_inclination_deg": float(np.degrees(survey.inclination.max())),
                 "max_dogleg_deg_per_30m": float(dogleg_severity_deg_per_30m(survey).max()),
                 "hole_sections": [{"bottom_m": float(b), "radius_m": float(r), "cased": bool(c)}
                                   for b, r, c in zip(well.hole.bottoms, well.hole.radii, well.hole.cased)]},
        "string": {"length_m": sections[-1].bottom, "bit_md_m": sections[-1].bottom,
                   "weight_in_air_N": float(sum(g * s.mass_per_length * (s.bottom - s.top) for s in sections)),
                   "buoyed_weight_N": float(sum(w * (s.bottom - s.top) for s, w in zip(sections, weights))),
                   "sections": [{"name": s.name, "top_m": s.top, "bottom_m": s.bottom,
                                 "buoyed_weight_N_m": float(w), "contact_radius_m": s.contact_radius}
                                for s, w in zip(sections, weights)]},
        "fluid": {"density_kg_m3": outer, "inner_density_kg_m3": inner},
        "elements": int(mesh.md.size - 1),
        "operations": results,
        "wall_time_s": time.perf_counter() - clock,
    }
    return {"report": report, "profiles": _dataset(profiles)}


def _dataset(profiles: dict):
    """The profiles as an ``xarray.Dataset``: node values over ``md``, element values over ``md_element``."""
    import xarray

    nodes = profiles["md"].size
    variables = {name: (("md" if values.size == nodes else "md_element"), values)
                 for name, values in profiles.items() if name not in ("md", "md_element")}
    return xarray.Dataset(variables, coords={"md": profiles["md"], "md_element": profiles["md_element"]})


def write_path_vtu(path: Path, profiles) -> None:
    """The string as a polyline through its nodes (x north, y east, z up) with its node profiles, for ParaView."""
    points = np.column_stack([profiles["north"].values, profiles["east"].values, -profiles["tvd"].values])
    cells = [("line", np.column_stack([np.arange(points.shape[0] - 1), np.arange(1, points.shape[0])]))]
    data = {name: values.values for name, values in profiles.data_vars.items() if values.dims == ("md",)}
    write_atomic(path, lambda tmp: meshio.write_points_cells(str(tmp), points, cells, point_data=data,
                                                             file_format="vtu"))


def fe_static_profiles(scene, model, q):
    """The FE static state ``q`` of a string in its well along measured depth, as an ``xarray.Dataset``: its axial
    force (the effective tension: the FE weighs the pipe in the mud) and torque on each element (``md_element``)
    with the sinusoidal and helical buckling loads there, its wall force per length at the vertices (``md``), and the
    soft string's effective tension in the same operation (off bottom, or rotating on bottom for a state on bottom)
    for comparison; where each vertex lies (north,
    east, true vertical depth: the axis plus the lateral displacement) and how far it is off the axis."""
    import xarray

    disc = model.disc
    dofs = model.space.expand(q)
    fields = [dofs[disc.vertex_dofs(f)] for f in (U, V, W, THETA_X, THETA_Y, THETA_Z)]
    contact = scene.contact
    on = scene.model.contact
    loads = string_profiles(disc.vertex_x, *fields[:4], disc.element_properties, model.vertex_gap,
                            contact.stiffness_linear if on else 0.0, contact.stiffness_cubic if on else 0.0,
                            *fields[4:], disc.element_curvature)
    x = disc.vertex_x
    middle = 0.5 * (x[1:] + x[:-1])
    p = disc.element_properties
    stiffness, weight = p.young_modulus * p.section.I4, p.density * p.section.area * p.gravity
    clearance = np.minimum(model.vertex_gap[1:], model.vertex_gap[:-1])
    trajectory = disc.trajectory if disc.trajectory is not None else string_in_well(scene).well.trajectory
    inclination, curvature = trajectory.inclination(middle), trajectory.curvature(middle)
    operation = "rotating_on_bottom" if scene.starts_on_bottom else "rotating_off_bottom"  # what the state carries
    soft = torque_drag_study(scene.with_changes(torque_drag={"operations": [operation]}))["profiles"]
    frames = trajectory.bishop_frames(x)
    lateral = fields[1][:, None] * frames.d2 + fields[2][:, None] * frames.d3
    position = trajectory.positions(x) + lateral  # where the string's axis lies in the hole
    return xarray.Dataset(
        {"axial_force": ("md_element", loads["axial_force"]), "torque": ("md_element", loads["torque"]),
         "wall_force_per_length": ("md", loads["wall_normal_force_per_length"]),
         "wall_force_per_length_smoothed": ("md", smoothed_per_length(x, loads["wall_normal_force_per_length"],
                                                                      WALL_FORCE_WINDOW)),
         "sinusoidal_buckling_load": ("md_element", sinusoidal_load(stiffness, weight, inclination, clearance,
                                                                    curvature)),
         "helical_buckling_load": ("md_element", helical_load(stiffness, weight, inclination, clearance, curvature)),
         "soft_string_tension": ("md", np.interp(x, soft["md"].values, soft[f"tension_{operation}"].values)),
         "north": ("md", position[:, 0]), "east": ("md", position[:, 1]), "tvd": ("md", -position[:, 2]),
         "lateral_displacement": ("md", np.hypot(fields[1], fields[2]))},
        coords={"md": x, "md_element": middle}, attrs={"soft_string_operation": operation})


#: The length over which the FE wall force is averaged for reading [m]: about a joint of pipe, over which a stiff
#: string touches at its tool joints and spans between them (the soft string spreads the same force evenly).
WALL_FORCE_WINDOW = 10.0


def smoothed_per_length(x: np.ndarray, per_length: np.ndarray, window: float) -> np.ndarray:
    """A force per length read at the vertices ``x`` (each standing for half its two elements), averaged over
    ``window`` centred on each vertex (shortened at the ends): the force on the window over its length."""
    h = np.diff(x)
    nodal = per_length * np.concatenate([[h[0] / 2], 0.5 * (h[1:] + h[:-1]), [h[-1] / 2]])
    cumulative = np.concatenate([[0.0], np.cumsum(nodal)])
    low = np.searchsorted(x, x - window / 2, side="left")
    high = np.searchsorted(x, x + window / 2, side="right")
    span = np.minimum(x + window / 2, x[-1]) - np.maximum(x - window / 2, x[0])
    return (cumulative[high] - cumulative[low]) / np.maximum(span, 1e-12)


def write_torque_drag(scene, out: str | Path, overwrite: bool = False) -> dict:
    """``fenics-drill torque-drag``: DIR/torque_drag.json, torque_drag.h5, well.vtu and summary.json."""
    out = Path(out)
    with command_output(out, "torque-drag", scene, overwrite) as summary:
        study = torque_drag_study(scene)
        write_json(out / "torque_drag.json", study["report"])
        write_atomic(out / "torque_drag.h5", lambda tmp: study["profiles"].to_netcdf(tmp, engine="h5netcdf"))
        write_path_vtu(out / "well.vtu", study["profiles"])
        summary["message"] = "torque_drag.json"
        summary["hook_load_N"] = {k: v["hook_load_N"] for k, v in study["report"]["operations"].items()}
        summary["surface_torque_Nm"] = {k: v["surface_torque_Nm"] for k, v in study["report"]["operations"].items()}
    return study


def buckling_on_bottom(scene, weight_on_bit: float) -> str:
    """What the soft string says of the scene's string rotating on bottom with ``weight_on_bit`` [N]: where it is
    buckled, a sentence (what a static solve that cannot carry that weight is told)."""
    study = torque_drag_study(scene.with_changes(torque_drag={"operations": ["rotating_on_bottom"],
                                                              "weight_on_bit": weight_on_bit}))
    op = study["report"]["operations"]["rotating_on_bottom"]
    if op["first_buckled_md_m"] is None:
        return f"the soft string at {weight_on_bit / 1e3:.4g} kN on bottom is not buckled"
    return (f"the soft string at {weight_on_bit / 1e3:.4g} kN on bottom is buckled from md {op['first_buckled_md_m']:.0f}"
            f" m, helically over {op['helically_buckled_length_m']:.0f} m and sinusoidally over "
            f"{op['sinusoidally_buckled_length_m']:.0f} m (compression up to {op['max_compression_N'] / 1e3:.4g} kN): "
            "a string snapping into a helix in its hole, which a static solve does not follow; lower the weight on bit")
