"""Command-line interface: ``fenics-drill <command> SCENE [--set section.key=value ...] --out DIR``.

Every ordinary error (a bad scene, an unusable output directory, a scene too large for the
machine, an unreadable file) ends the command with a one-line message naming the key, the path
or the file, and exit code 2; Ctrl-C or SIGTERM with 130.  Under ``mpiexec`` an error on one rank
ends the whole job (``MPI_Abort``) with that rank's message.  ``run``, ``static`` and ``modal``
run in a worker process (:mod:`fenics_drill.supervisor`) so that a signal stops them within
seconds even inside a long C call.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np

from fenics_drill import __version__
from fenics_drill.scene import SceneError, load_scene, section_keys, unused_keys

#: Commands run in a supervised worker process (single-process commands that can run long).
SUPERVISED = ("run", "static", "modal", "campbell")
#: Commands that run on one process: under ``mpiexec -n N`` the first rank runs them and the others end at once.
SINGLE_PROCESS = ("scene", "modal", "static", "campbell", "plot", "forms", "torque-drag", "broomstick", "calibrate")




def _scene_args(parser: argparse.ArgumentParser, out: bool = True) -> None:
    parser.add_argument("scene", nargs="?", help="TOML scene file (default: the paper's nominal scene)")
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
        help="override one scene key; the value is read as TOML (repeatable)",
    )
    if out:
        parser.add_argument("--out", default="out", help="output directory (created if missing; it must be new "
                            "or empty, or hold this command's earlier output with --overwrite)")
        parser.add_argument("--overwrite", action="store_true",
                            help="replace this command's earlier output in --out (and nothing else there)")


def cmd_scene(args) -> int:
    """Print the validated scene with every default filled in, as TOML; a well's survey and sections are read and
    related to the string as every command does (a missing or unsorted survey file is refused here too)."""
    from fenics_drill.model.well import well_notes

    scene = load_scene(args.scene, args.overrides)
    for note in well_notes(scene):  # the checks of the string in its well, every command's first
        print(f"# note: {note}")
    written = getattr(scene, "written", {})
    unused = unused_keys(scene)
    for section, entries in scene.to_dict().items():
        print(f"[{section}]")
        keys = section_keys(section)
        for key, value in entries.items():
            given = f" (written {written[f'{section}.{key}']!r})" if f"{section}.{key}" in written else ""
            note = "  [not used: the well's keys rule]" if f"{section}.{key}" in unused else ""
            print(f"{key} = {json.dumps(value)}  # {keys[key].metadata['doc']}{given}{note}")
        print()
    sections_written = {k: v for k, v in written.items() if k.startswith("string.sections[")}
    if sections_written:
        print("# written with units in string.sections (shown above in SI): "
              + ", ".join(f"{k} = {v!r}" for k, v in sections_written.items()))
    return 0


def cmd_modal(args) -> int:
    """Modal analysis (62) and reduced-basis selection; writes DIR/modes.json."""
    from fenics_drill.plots.modal import spectra_figure
    from fenics_drill.studies.modal_report import write_modal_report

    scene = load_scene(args.scene, args.overrides)
    report = write_modal_report(scene, args.out, overwrite=args.overwrite)
    spectra_figure(report, Path(args.out) / "modes.png")
    red = report["reduced_basis"]
    chosen = (f"reduced basis ({scene.reduction.rule}): {red['size']} = {red['counts']}" if red["counts"] else
              f"full order ({scene.reduction.rule}{': ' + red['guard']['full_order']['why'] if 'guard' in red else ''})")
    about = report["linearised_about"]
    state = "the unloaded string" if about["state"] == "unloaded" else \
        f"the static state (weight on bit {about['weight_on_bit_N'] / 1e3:.4g} kN)"
    print(f"{report['full_dofs']} dofs, {len(report['modes'])} free-free modes with f* <= {scene.modal.f_star_max} "
          f"about {state}, {chosen} [{report['wall_time_s']:.1f} s] -> {Path(args.out) / 'modes.json'}")
    if report["first_torsional_period_s"]:
        print(f"drive-held, bit off bottom: first torsional mode {report['first_torsional_frequency_hz']:.4g} Hz "
              f"(period {report['first_torsional_period_s']:.4g} s)")
    if report.get("buckled"):
        print(f"BUCKLED: {report['buckled']['message']}")
    if report["lateral_critical_speeds_rpm"]:
        print("lateral critical speeds (order 1, not spinning; `fenics-drill campbell` for the spinning string): "
              + ", ".join(f"{r:.4g}" for r in report["lateral_critical_speeds_rpm"]) + " rpm")
    return 0


def cmd_static(args) -> int:
    """Static equilibrium under gravity with wall contact (Section 6.4): DIR/static.json, DIR/static.xdmf; on a well
    DIR/static_profiles.h5 and static_loads.png."""
    from fenics_drill.studies.run import run_static

    scene = load_scene(args.scene, args.overrides)
    report = run_static(scene, args.out, overwrite=args.overwrite)
    if (Path(args.out) / "static_profiles.h5").exists():  # a well: its loads along it
        from fenics_drill.plots.directory import plot_directory

        _drawn(lambda: plot_directory(Path(args.out)))
    if scene.well.survey or scene.well.md:  # in a well the lateral displacement is off the axis, any way
        shape = f"largest lateral displacement {report['max_lateral_displacement'] * 1e3:.3f} mm"
    else:
        shape = f"max sag {report['max_sag'] * 1e3:.3f} mm at x = {report['max_sag_position']:.1f} m"
    pressed = f", the bit pressed at {report['weight_on_bit'] / 1e3:.4g} kN" if report.get("weight_on_bit") else ""
    hook = report["hook_load"]
    top = f"hook load {hook / 1e3:.2f} kN" if hook >= 0 else f"the top pushes with {-hook / 1e3:.2f} kN (a hook load of " \
        f"{hook / 1e3:.2f} kN: the weight on bit asks more than the string weighs along its axis)"
    print(f"{shape}, {len(report['contact_vertices'])} vertices on the wall, {top}{pressed} -> "
          f"{Path(args.out) / 'static.json'}")
    buckling = report.get("buckling") or {}
    if buckling.get("message") and not buckling.get("unstable"):
        print(f"buckled: {buckling['message']}")
    for reason in report.get("suspect_reasons", []):
        print(f"suspect: {reason}")
    return 0


def cmd_campbell(args) -> int:
    """Critical speeds: the modes of the spinning string over campbell.rotation_speed (DIR/campbell.json, .png)."""
    from fenics_drill.plots.campbell import campbell_figure, crossing_text
    from fenics_drill.studies.campbell import write_campbell

    scene = load_scene(args.scene, args.overrides)
    report = write_campbell(scene, args.out, overwrite=args.overwrite)
    campbell_figure(report, Path(args.out) / "campbell.png")
    speeds = report["rotation_speed_rpm"]
    print(f"{len(report['branches'])} branches at {len(speeds)} speeds {speeds[0]:.4g}-{speeds[-1]:.4g} rpm, axial "
          f"compression {report['axial_force_N']:.4g} N [{report['wall_time_s']:.1f} s] -> "
          f"{Path(args.out) / 'campbell.json'}")
    for c in report["critical_speeds"]:
        print(f"  critical speed {c['speed_rpm']:8.2f} rpm: {crossing_text(c)} at {c['frequency_hz']:.3f} Hz")
    return 0


def cmd_run(args) -> int:
    """Drilling dynamics from the static equilibrium: summary.json, timeseries.h5, fields.xdmf."""
    from fenics_drill.studies.run import run_scene

    from mpi4py import MPI

    scene = load_scene(args.scene, args.overrides)
    summary = run_scene(scene, args.out, progress=not args.quiet, overwrite=args.overwrite)
    if MPI.COMM_WORLD.rank > 0:  # the second rank of a shared run: the first reports
        return {"finished": 0, "interrupted": 130}.get(summary["status"], 1)
    print(
        f"{summary['status']}: {summary['message']}; t = {summary['t_end']:.4g} s in {summary['steps']} steps, "
        f"wall {summary['wall_time_s']:.1f} s -> {Path(args.out) / 'summary.json'}"
    )
    if "mean_bit_velocity" in summary and "rop" in summary:
        print(
            f"mean bit velocity {summary['mean_bit_velocity'] * 3600:.2f} m/h, rop {summary['rop'] * 3600:.2f} m/h, "
            f"impacts {summary['impacts_total']}, energy balance error {summary['energy']['balance_error']:.2e}"
        )
    loads = summary.get("torque_and_drag")
    if loads:
        print(f"hook load {loads['hook_load']['mean_second_half'] / 1e3:.2f} kN, surface torque "
              f"{loads['surface_torque']['mean_second_half'] / 1e3:.3f} kN m (means over the run's second half)")
    for reason in summary.get("suspect_reasons", []):
        print(f"SUSPECT: {reason}")
    for advice in summary.get("advice", []):
        print(f"note: {advice}")
    return {"finished": 0, "suspect": 0, "interrupted": 130}.get(summary["status"], 1)


def cmd_mc(args) -> int:
    """Monte Carlo over the random bit-rock laws; with mpiexec -n P, realisations spread over P ranks."""
    from fenics_drill.studies.monte_carlo import monte_carlo

    scene = load_scene(args.scene, args.overrides)
    summary = monte_carlo(scene, args.samples, args.out, resume=args.resume, progress=not args.quiet,
                          overwrite=args.overwrite)
    if summary is not None:
        rop, eff = summary["rop"], summary["efficiency"]
        print(f"{summary['realisations']} realisations ({summary['failed']} failed), conv_MC "
              f"{summary['convergence_metric']:.6e}; rop {rop['mean'] * 3600:.2f} m/h "
              f"[{rop['p2.5'] * 3600:.2f}, {rop['p97.5'] * 3600:.2f}], efficiency {eff['mean']:.1%} "
              f"[{eff['p2.5']:.1%}, {eff['p97.5']:.1%}] -> {Path(args.out) / 'summary.json'}")
    return 0


def cmd_optimize(args) -> int:
    """The operating window: deterministic or robust optimum of rop or efficiency under the von Mises limit."""
    from fenics_drill.studies.operating_window import run_optimize

    scene = load_scene(args.scene, args.overrides)
    report = run_optimize(scene, args.out, resume=args.resume, progress=not args.quiet, overwrite=args.overwrite)
    if report is not None:
        if report["feasible"]:
            o = report["optimum"]
            print(f"{report['mode']} optimum of {report['objective']}: V0 = {o['axial_velocity'] * 3600:.2f} m/h, "
                  f"Omega = {o['rotation_speed'] * 30 / 3.141592653589793:.1f} rpm, objective {o['objective']:.6g} "
                  f"-> {Path(args.out) / 'optimize.json'}")
        else:
            print(f"infeasible: {report['message']} -> {Path(args.out) / 'optimize.json'}")
    return 0


def _drawn(draw):
    """``draw()``, with a line on stderr every 10 s after 5 s while the figures are drawn."""
    from fenics_drill.studies.run import SetupProgress

    progress = SetupProgress(True, prefix="figures")
    progress("drawing")
    try:
        return draw()
    finally:
        progress.close()


def cmd_plot(args) -> int:
    """Figures of a saved run (Figs. 13-23), Monte Carlo study (Figs. 28-35) or operating window (24-27, 36)."""
    from fenics_drill.io.files import read_json
    from fenics_drill.io.output_directory import FIGURE_RECORD
    from fenics_drill.plots.directory import plot_directory

    directory = Path(args.run_dir)
    paths = _drawn(lambda: plot_directory(directory, gif=not args.no_gif))
    print(f"{len(paths)} files in {directory}: " + ", ".join(p.name for p in paths))
    banner = read_json(directory / FIGURE_RECORD)["drawn_from"].get("banner")
    if banner:
        print(f"note: {banner[len('PARTIAL: '):]}; the figures say so in red, and the next command that writes "
              f"{directory} removes them")
    return 0


def cmd_forms(args) -> int:
    """List the forms, print one, or check the printed operators against the energies."""
    from fenics_drill.model.discretization import BeamDiscretization

    scene = load_scene(args.scene, args.overrides)
    if args.action == "check":
        from fenics_drill.studies.form_check import compare_printed_forms

        disc = BeamDiscretization(scene.beam_properties, 6, scene.beam.element_degree, "paper")
        rows = compare_printed_forms(disc)
        for row in rows:
            print(f"{row.term:22s} relative L2 difference {row.relative_difference:9.2e}  {row.status}")
        return 1 if any(r.status == "UNRECORDED MISMATCH" for r in rows) else 0
    from fenics_drill.studies.form_catalog import form_catalog

    catalog = form_catalog(BeamDiscretization(scene.beam_properties, 2, scene.beam.element_degree, "paper"))
    if args.action == "list":
        for name, (doc, _) in catalog.items():
            print(f"{name:16s} {doc}")
        return 0
    if args.name not in catalog:
        print(f"fenics-drill: unknown form {args.name!r}; 'fenics-drill forms list' names them", file=sys.stderr)
        return 2
    from ufl.algorithms.apply_derivatives import apply_derivatives

    doc, form = catalog[args.name]
    print(f"# {args.name}: {doc}\n{apply_derivatives(form)}")
    return 0


def cmd_torque_drag(args) -> int:
    """Soft-string torque and drag along the scene's well: DIR/torque_drag.json, torque_drag.h5, well.vtu, figures;
    with --samples N, under uncertainty over MPI ranks: DIR/risk.json, risk.nc, risk.png."""
    from fenics_drill.plots.directory import plot_directory
    from fenics_drill.studies.torque_drag import write_torque_drag

    scene = load_scene(args.scene, args.overrides)
    if args.samples is not None:
        return _risk(scene, args)
    report = write_torque_drag(scene, args.out, overwrite=args.overwrite)["report"]
    _drawn(lambda: plot_directory(Path(args.out)))
    well = report["well"]
    print(f"{well['measured_depth_m']:.0f} m well (TVD {well['true_vertical_depth_m']:.0f} m, max dogleg "
          f"{well['max_dogleg_deg_per_30m']:.2f} deg/30 m), {report['string']['length_m']:.0f} m string, "
          f"{report['elements']} elements [{report['wall_time_s']:.2f} s] -> {Path(args.out) / 'torque_drag.json'}")
    for name, op in report["operations"].items():
        buckled = (f", buckled from md {op['first_buckled_md_m']:.0f} m (sinusoidal "
                   f"{op['sinusoidally_buckled_length_m']:.0f} m, helical {op['helically_buckled_length_m']:.0f} m)"
                   if op["first_buckled_md_m"] is not None else "")
        locked = ", LOCKED UP: the surface would have to push" if op["locked_up"] else ""
        print(f"  {name:<20s} hook load {op['hook_load_N'] / 1e3:9.1f} kN, surface torque "
              f"{op['surface_torque_Nm'] / 1e3:7.2f} kN m{buckled}{locked}")
    return 0


def _risk(scene, args) -> int:
    """``torque-drag --samples N``: the study over the ranks, then (first rank) its figure and its summary."""
    from mpi4py import MPI

    from fenics_drill.plots.directory import plot_directory
    from fenics_drill.studies.risk import write_risk

    study = write_risk(scene, args.samples, args.out, resume=args.resume, overwrite=args.overwrite,
                       progress=not args.quiet)
    if MPI.COMM_WORLD.rank > 0 or study is None:
        return 0
    _drawn(lambda: plot_directory(Path(args.out)))
    report = study["report"]
    print(f"{report['samples']} realisations on {report['ranks']} rank(s), {report['depths']} bit depths "
          f"[{report['wall_time_s']:.1f} s] -> {Path(args.out) / 'risk.json'}")
    for key, what in (("max_probability_over_hook_load_limit", "the hook-load limit"),
                      ("max_probability_over_torque_limit", "the torque limit")):
        if report[key] is not None:
            print(f"  probability of exceeding {what}: up to {report[key]:.3f}")
    print(f"  probability of helical buckling slacking off at the bottom: "
          f"{report['probability_helical_slack_off_at_bottom']:.3f}")
    lock = report["lock_up_depth_sliding_m"]
    print(f"  sliding reaches the bottom in {report['probability_sliding_to_bottom']:.1%} of the realisations"
          + (f"; lock-up depth P10/P50/P90 {lock['p10']:.0f} / {lock['p50']:.0f} / {lock['p90']:.0f} m" if lock
             else ""))
    return 0


def cmd_stick_slip_map(args) -> int:
    """Stick-slip over weight on bit x rotation speed on the scene's axial-torsional string (MPI-parallel,
    resumable): DIR/map.nc, map.csv, map.json, stick_slip_map.png."""
    from mpi4py import MPI

    from fenics_drill.plots.directory import plot_directory
    from fenics_drill.studies.stick_slip_map import write_stick_slip_map

    scene = load_scene(args.scene, args.overrides)
    study = write_stick_slip_map(scene, args.out, resume=args.resume, overwrite=args.overwrite,
                                 progress=not args.quiet)
    if MPI.COMM_WORLD.rank > 0 or study is None:
        return 0
    _drawn(lambda: plot_directory(Path(args.out)))
    report, grid = study["report"], study["map"]
    print(f"{report['points']} points on {report['ranks']} rank(s), {report['settled_points']} settled "
          f"[{report['wall_time_s']:.1f} s] -> {Path(args.out) / 'map.json'}")
    for controller in grid.controller.values:
        at = grid.sel(controller=controller)
        print(f"  {controller}: stick-slip severity by weight on bit (rows, kN) and rotation speed (columns, rpm)")
        print("           " + "".join(f"{o * 30 / np.pi:8.0f}" for o in at.rotation_speed.values))
        moved = at.step_moved.values if "step_moved" in at else np.zeros(at.settled.shape, bool)
        for i, w in enumerate(at.weight_on_bit.values):
            cells = [("   fail " if not np.isfinite(v) else f"{v:7.2f}" + ("!" if f else "*" if not s else "~" if m
                                                                          else " "))
                     for v, s, f, m in zip(at.severity.values[i], at.settled.values[i], at.failed.values[i], moved[i])]
            print(f"  {w / 1e3:8.1f} " + "".join(cells))
    if report["settled_points"] < report["points"]:
        print(f"  *: not settled within stick_slip_map.time_limit = {grid.attrs['time_limit_s']:g} s (its last "
              "windows reported)")
    if report["failed_points"]:
        print("  !: a step's Newton failed there even in halves (map.csv says when); the windows before it reported")
    if report.get("step_moved_points"):
        print("  ~: settled, but its cycle moved at half the step (map.csv's step_moved; unsettled points may have too)")
    for advice in report.get("advice", []):
        print(f"  advice: {advice}")
    return 0


def cmd_broomstick(args) -> int:
    """The broomstick chart of the scene's well: DIR/broomstick.nc, broomstick.csv, broomstick.json, broomstick.png."""
    from fenics_drill.plots.directory import plot_directory
    from fenics_drill.studies.broomstick import write_broomstick

    scene = load_scene(args.scene, args.overrides)
    report = write_broomstick(scene, args.out, overwrite=args.overwrite)["report"]
    _drawn(lambda: plot_directory(Path(args.out)))
    pairs = report["friction_pairs"]
    print(f"{report['depths']} bit depths to {report['well_depth_m']:.0f} m every {report['depth_step_m']:g} m, "
          f"{len(report['operations'])} operations, {len(pairs)} friction pairs [{report['wall_time_s']:.2f} s] -> "
          f"{Path(args.out) / 'broomstick.png'}")
    for name, at in report["at_bottom"].items():
        loads = np.array(at["hook_load_N"]) / 1e3
        torques = np.array(at["surface_torque_Nm"]) / 1e3
        print(f"  at the bottom, {name:<20s} hook load {loads.min():8.1f} to {loads.max():8.1f} kN, torque "
              f"{torques.min():6.2f} to {torques.max():6.2f} kN m")
    return 0


def cmd_calibrate(args) -> int:
    """Friction factors fitted to a measured file: DIR/calibration.json, calibration.png, friction_track.png."""
    from fenics_drill.plots.directory import plot_directory
    from fenics_drill.studies.calibration import write_calibration

    scene = load_scene(args.scene, args.overrides)
    report = write_calibration(scene, args.measured, args.out, overwrite=args.overwrite,
                               fit_block=args.fit_block_weight)
    _drawn(lambda: plot_directory(Path(args.out)))
    print(f"{report['points']} measured points ({report['points_in_casing']} with the bit in casing, shoe at "
          f"{report['casing_shoe_m']:.0f} m) [{report['wall_time_s']:.2f} s] -> {Path(args.out) / 'calibration.json'}")
    for name in ("friction_cased", "friction_open"):
        entry = report[name]
        if entry["value"] is None:
            print(f"  {name}: {entry['message']}")
        else:
            interval = entry["interval"]
            shown = f"[{interval[0]:.4f}, {interval[1]:.4f}]" if interval else f"({entry['message']})"
            print(f"  {name}: {entry['value']:.4f} {shown} (95 %)")
    block = report["block_weight_N"]
    if block["fitted"]:
        print(f"  block weight: {block['value'] / 1e3:.1f} kN")
    for warning in report["warnings"]:
        print(f"warning: {warning}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="fenics-drill",
        description="Nonlinear dynamics of horizontal drillstrings (Cunha Jr, Soize, Sampaio 2015) on FEniCSx.",
    )
    parser.add_argument("--version", action="version", version=f"fenics-drill {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("scene", help="validate a scene and print it with all defaults")
    _scene_args(p, out=False)
    p.set_defaults(func=cmd_scene)
    p = sub.add_parser("modal", help="modal analysis (Eq. 62) about the unloaded string or the static state, the spectra "
                       "of the run's end conditions and the reduced basis (Section 6.3): DIR/modes.json, modes.png")
    _scene_args(p)
    p.set_defaults(func=cmd_modal)
    p = sub.add_parser("static", help="static equilibrium under gravity (Section 6.4): DIR/static.json")
    _scene_args(p)
    p.set_defaults(func=cmd_static)
    p = sub.add_parser("campbell", help="critical speeds: Campbell diagram of the spinning string, whirl, "
                                        "weight on bit: DIR/campbell.json, campbell.png")
    _scene_args(p)
    p.set_defaults(func=cmd_campbell)
    p = sub.add_parser("run", help="drilling dynamics: DIR/summary.json, timeseries.h5, fields.xdmf")
    _scene_args(p)
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("mc", help="Monte Carlo over the random bit-rock laws (MPI-parallel, resumable)")
    _scene_args(p)
    p.add_argument("--samples", type=int, required=True, help="number of realisations N")
    p.add_argument("--resume", action="store_true", help="continue the study in --out, skipping what is done")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(func=cmd_mc)
    p = sub.add_parser("optimize", help="efficiency / rop over the operating window, deterministic or robust "
                                        "(MPI-parallel, resumable): DIR/optimize.json")
    _scene_args(p)
    p.add_argument("--resume", action="store_true", help="continue in --out, skipping the points done")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(func=cmd_optimize)
    p = sub.add_parser("torque-drag", help="soft-string torque and drag along the scene's well (survey, string "
                                           "sections, mud): DIR/torque_drag.json, torque_drag.h5, well.vtu")
    _scene_args(p)
    p.add_argument("--samples", type=int, default=None,
                   help="under uncertainty: N realisations of the [risk] laws (MPI-parallel, resumable)")
    p.add_argument("--resume", action="store_true", help="with --samples: continue the study in --out")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(func=cmd_torque_drag)
    p = sub.add_parser("stick-slip-map", help="stick-slip severity, period (between rises and dominant), stuck share, "
                                              "fastest and median cycle's bit spin, rop and specific energy "
                                              "over weight on bit x rotation speed on the axial-torsional string "
                                              "(MPI-parallel, resumable): DIR/map.nc, map.csv, map.json")
    _scene_args(p)
    p.add_argument("--resume", action="store_true", help="continue in --out, skipping the points done")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.set_defaults(func=cmd_stick_slip_map)
    p = sub.add_parser("broomstick", help="hook load and surface torque against bit depth for the chart's operations "
                                          "and friction factors, with the rig's limits: DIR/broomstick.nc, .csv, .png")
    _scene_args(p)
    p.set_defaults(func=cmd_broomstick)
    p = sub.add_parser("calibrate", help="cased and open-hole friction factors fitted to the rig's measured hook "
                                         "loads and torques: DIR/calibration.json, calibration.png")
    p.add_argument("scene", help="TOML scene file of the well")
    p.add_argument("measured", help="CSV of bit_depth and any of pick_up, slack_off, rotating_off_bottom, "
                                    "torque_off_bottom, torque_on_bottom, units in brackets in the header")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one scene key; the value is read as TOML (repeatable)")
    p.add_argument("--out", default="out", help="output directory")
    p.add_argument("--overwrite", action="store_true", help="replace this command's earlier output in --out")
    p.add_argument("--fit-block-weight", action="store_true",
                   help="fit the travelling equipment's weight too (else broomstick.block_weight)")
    p.set_defaults(func=cmd_calibrate)
    p = sub.add_parser("plot", help="figures of a run (Figs. 13-23, spectra.json, animation.gif), a Monte Carlo "
                                    "study (Figs. 28-35), an operating window or a Campbell diagram")
    p.add_argument("run_dir", help="the --out directory of 'fenics-drill run', 'mc', 'optimize' or 'campbell'")
    p.add_argument("--no-gif", action="store_true", help="skip the animation (the slowest part)")
    p.set_defaults(func=cmd_plot)
    p = sub.add_parser("forms", help="list/show the weak forms, or check the printed ones against the energies")
    p.add_argument("action", choices=("list", "show", "check"))
    p.add_argument("name", nargs="?", help="with 'show': the form to print (see 'forms list')")
    p.add_argument("--scene", dest="scene", default=None, help="scene whose parameters the forms use")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE")
    p.set_defaults(func=cmd_forms)
    return parser


def _user_errors() -> tuple[type, ...]:
    """The ordinary errors: each ends a command with its message (exit 2), never a traceback."""
    from fenics_drill.io.files import UnreadableFile
    from fenics_drill.io.output_directory import OutputError
    from fenics_drill.model.resources import ResourceError
    from fenics_drill.model.reduction.spaces import BasisError
    from fenics_drill.plots.directory import NothingToPlot
    from fenics_drill.model.rotating_modes import Divergence, TooFewModes
    from fenics_drill.studies.campbell import CampbellError
    from fenics_drill.studies.shared_run import RankCountError
    from fenics_drill.studies.uncertainty import InadmissibleLaw

    return (SceneError, OutputError, ResourceError, UnreadableFile, InadmissibleLaw, NothingToPlot, BasisError,
            CampbellError, Divergence, TooFewModes, RankCountError)


def _collective_errors() -> tuple[type, ...]:
    """Errors every MPI rank meets alike (scene checks, laws, the study directory's verdict broadcast by
    rank 0): each rank can return its code.  Any other error on one rank ends the job with MPI_Abort."""
    from fenics_drill.io.output_directory import OutputError
    from fenics_drill.studies.shared_run import RankCountError
    from fenics_drill.studies.uncertainty import InadmissibleLaw

    return SceneError, OutputError, InadmissibleLaw, RankCountError


def _say_notes(args) -> None:
    """The notes a command's summary.json holds of its scene (where the bit is, what the survey's reader left out),
    one line each on stdout, after its results."""
    from fenics_drill.io.files import UnreadableFile, read_json

    out = getattr(args, "out", None)
    summary = Path(out) / "summary.json" if out else None
    if summary is None or not summary.is_file() or args.command == "plot":
        return
    try:
        notes = read_json(summary).get("notes", [])
    except UnreadableFile:
        return
    for note in notes if isinstance(notes, list) else []:
        print(f"note: {note}")


def _execute(args) -> int:
    """Run a command in this process; ordinary errors become messages, other errors under MPI end the job."""
    from mpi4py import MPI

    from fenics_drill.io.files import no_room_message
    from fenics_drill.io.study_directory import RankStopped
    from fenics_drill.solvers.static import StaticFailure

    comm = MPI.COMM_WORLD
    where = f" (rank {comm.rank} of {comm.size})" if comm.size > 1 else ""
    try:
        code = args.func(args)
        _say_notes(args)
        return code
    except _user_errors() as err:
        kind = "scene error: " if isinstance(err, SceneError) else ""
        _say(f"fenics-drill{where}: {kind}{err}")
        if comm.size > 1 and not isinstance(err, _collective_errors()):
            comm.Abort(2)
        return 2
    except StaticFailure as err:  # no equilibrium: the study says so and ends, no traceback
        _say(f"fenics-drill{where}: {err}")
        if comm.size > 1:
            comm.Abort(1)
        return 1
    except KeyboardInterrupt:
        _say(f"fenics-drill{where}: interrupted")
        return 130
    except RankStopped as stop:
        _say(f"fenics-drill{where}: stopped: {stop}")
        return 130 if stop.status == "interrupted" else 1
    except Exception as err:
        room = no_room_message(err)
        if room is not None:
            _say(f"fenics-drill{where}: cannot write to {getattr(args, 'out', 'the output directory')}: {room}")
            if comm.size == 1:  # HDF5 would close the files it could not extend once more at exit, and crash
                sys.stdout.flush()
                os._exit(1)
        elif comm.size == 1:
            raise
        else:
            import traceback

            # the line that names the rank first: MPI_Abort can end the job before the launcher has passed on the
            # last of a rank's output, and then only the traceback's tail is lost
            _say(f"fenics-drill{where}: failed ({type(err).__name__}); ending every rank")
            traceback.print_exc()
            sys.stderr.flush()
        if comm.size > 1:
            comm.Abort(1)
        return 1


def _say(line: str) -> None:
    """One line on stderr, flushed at once (a rank about to be aborted must not lose it in a buffer)."""
    sys.stderr.write(line + "\n")
    sys.stderr.flush()


def main(argv: list[str] | None = None) -> int:
    """The ``fenics-drill`` tool.  Called without ``argv`` (the console script), ``run``, ``static`` and
    ``modal`` go to a supervised worker process; with ``argv`` (tests, scripts) everything runs here.  A Ctrl-C
    anywhere, even while the libraries load, ends it with one line and exit code 130."""
    try:
        return _main(argv)
    except KeyboardInterrupt:
        _say("fenics-drill: interrupted")
        return 130


def _quiet_about_full_disks(unraisable, default=sys.unraisablehook) -> None:
    """HDF5 objects that could not be closed on a full disk complain again as they are collected (h5py reports
    them through both hooks); the command says once why it failed."""
    from fenics_drill.io.files import no_room_message

    if no_room_message(unraisable.exc_value) is None:
        default(unraisable)


def _quiet_excepthook(kind, value, trace, default=sys.excepthook) -> None:
    from fenics_drill.io.files import no_room_message

    if no_room_message(value) is None:
        default(kind, value, trace)


def _under_mpiexec() -> bool:
    """Started by an MPI process manager (MPICH's hydra, Open MPI, PMIx): the manager delivers the signals to
    every rank, and a worker process of the supervisor could not join the job's MPI world."""
    return any(name in os.environ for name in ("PMI_RANK", "PMI_SIZE", "PMIX_RANK", "OMPI_COMM_WORLD_SIZE"))


def _main(argv: list[str] | None) -> int:
    sys.unraisablehook, sys.excepthook = _quiet_about_full_disks, _quiet_excepthook
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "out", None) is not None and not str(args.out).strip():
        _say("fenics-drill: --out '' names no directory (it would write into the current one): give one, e.g. "
             "--out out/run1")
        return 2
    if args.command in SINGLE_PROCESS and _under_mpiexec() and getattr(args, "samples", None) is None:
        from mpi4py import MPI

        if MPI.COMM_WORLD.size > 1:
            if MPI.COMM_WORLD.rank > 0:
                return 0  # the first rank runs the command; this one has nothing to do
            import petsc4py

            petsc4py.init(comm=MPI.COMM_SELF)  # PETSc's start and end are collective: this rank's alone
            _say(f"fenics-drill: '{args.command}' runs on one process: rank 0 runs it, the other "
                 f"{MPI.COMM_WORLD.size - 1} end")
    if argv is None and args.command in SUPERVISED and not _under_mpiexec():
        from fenics_drill import supervisor

        if not supervisor.is_worker():
            try:
                load_scene(args.scene, args.overrides)  # bad input is refused here, before any worker starts
            except SceneError as err:
                print(f"fenics-drill: scene error: {err}", file=sys.stderr)
                return 2
            return supervisor.supervise(sys.argv[1:], args.command, Path(args.out))
    return _execute(args)


if __name__ == "__main__":
    sys.exit(main())
