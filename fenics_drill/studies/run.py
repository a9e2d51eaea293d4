"""``fenics-drill run`` and ``fenics-drill static``: a scene in, files out.

run: DIR/summary.json, DIR/timeseries.h5 (see :mod:`fenics_drill.io.timeseries`),
DIR/fields.xdmf (u, v, w, theta_x, theta_y, theta_z on P1 every
``output.field_interval`` seconds).  The summary is written however the run
ends (finished, failed with the reason, or interrupted with Ctrl-C) and says which.
"""

from __future__ import annotations

import functools
import json
import os
import socket
import sys
import threading
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from fenics_drill.io.fields import FieldWriter
from fenics_drill.io.files import no_room_message, write_atomic, write_final_json, write_json
from fenics_drill.io.output_directory import claim_output, remove_figures
from fenics_drill.io.timeseries import TimeSeriesWriter, read_series
from fenics_drill.model.discretization import THETA_X, THETA_Y, THETA_Z, U, V, W
from fenics_drill.model.drillstring import DrillstringModel
from fenics_drill.model.reduction.modes import drive_held_modes
from fenics_drill.model.resources import check_disk, check_memory
from fenics_drill.observables.buckling import buckled_spans
from fenics_drill.observables.drilling_quantities import drilling_quantities, spin_variation_ratio
from fenics_drill.observables.step_rows import StepRows
from fenics_drill.observables.torque_drag import string_profiles, top_loads
from fenics_drill.observables.whirl import whirl
from fenics_drill.scene import Time
from fenics_drill.solvers.static import StaticFailure, static_report
from fenics_drill.model.resolution import band_frequency, mesh_advice
from fenics_drill.solvers.step_control import (RunFailure, breaks_loose_in_waves, check_run_length, least_steps,
                                              nominal_step, steps_per_band_period, torsional_transit)
from fenics_drill.solvers.time_loop import Simulation, StepRecord
from fenics_drill.studies.lifecycle import (StopOnSignal, agree_to_stop, command_output, scene_record, stop_if_requested,
                                            uninterrupted)
from fenics_drill.studies.operating_state import REPORTED_MODES, state_of, unstable_modes
from fenics_drill.studies.prepare import prepare
from fenics_drill.studies.shared_run import check_ranks, check_same_state, second_rank_run, shared_model
from fenics_drill.studies.torque_drag import fe_static_profiles, write_path_vtu


#: A nominal step that resolves the band's highest frequency f_max with fewer steps per period than the
#: default time.band_steps is told that its efficiency (96) is not resolved: 4-7 % high at the paper's 2
#: (docs/verification.md).
RESOLVING_BAND_STEPS = Time.band_steps

#: Fewest steps per period of the band's f_max a step may take (Nyquist); a run at fewer is "suspect".
NYQUIST_STEPS = 2.0

#: A run whose string went deeper into the wall than this share of the gap is reported "suspect": the
#: Hunt-Crossley law (17) models a stiff wall, so a deep penetration means the time step or the contact
#: stiffness does not resolve the impacts.
PENETRATION_LIMIT = 0.1

#: A run with wall impacts, or with the printed kinematics, whose energy budget closes only to worse than this share
#: of the energy exchanged is told that the time integration took that share: Newmark's numerical damping, which no
#: physical term of the budget books.  A thin pipe's wider-band reduced model, which bounces on the wall where
#: the full order rests, closed to 1.02 %, and to 0.04 % with time.newmark_alpha = 0 (bouncing harder: 9.11
#: against 8.54 m/h); resting runs close within 0.25 %, the paper scene to 0.21 % (docs/verification.md).  Without impacts the damping takes the string's own
#: stiff modes, and what it takes does not matter: a 20 m string in stick-slip closes to 0.6 %, and half the step
#: (0.3 %) moves its rop by 0.3 % and its efficiency by 0.1 %.
BALANCE_ADVICE = 5e-3

#: A run whose bit's angular velocity varies over the second half of the run by more than this many times what
#: a stick-slip at the string's first torsional frequency can (observables.drilling_quantities.
#: spin_variation_ratio) is told that its bit rings.  Measured (docs/verification.md, 2026-11-24): 0.1-2.8 for
#: every full order and every reduced model that matched it, 8.1 for the printed kinematics' chaotic reduced
#: model, 9.7 for a 20 m string at a quarter of the default step; 40-380 for the reduced models whose bit rang
#: (efficiency up to 2.3 % and peak stress up to 7 % off their full order).
RINGING_RATIO = 20.0

#: A run whose bit advanced by less than this many times time.error_tolerance is told that its rop and efficiency
#: measure a motion of the size of a few steps' admissible error.  Measured with the start-up resolved
#: (docs/verification.md, random scenes over 1 s, the reduced model against its full order): rop off by 28 % and
#: 5 % at advances of 0.2 and 0.4 tolerances (strings of 490-520 m, whose bit has barely started), by 0.8 % at 7,
#: by 0.34 % at 24, and by at most 0.13 % beyond 80.
SMALL_ADVANCE = 20.0


def run_static(scene, out: str | Path, overwrite: bool = False, progress: bool = True) -> dict:
    """Static equilibrium of the scene (Section 6.4): DIR/static.json, DIR/static.xdmf, DIR/summary.json; on a well
    DIR/static_profiles.h5 (:func:`~fenics_drill.studies.torque_drag.fe_static_profiles`) and static_path.vtu (the
    string where it lies in the hole, for ParaView)."""
    out = Path(out)
    with command_output(out, "static", scene, overwrite) as summary:
        setup = SetupProgress(progress)
        try:
            prepared = prepare(scene, dynamics=False, stage=setup)
        finally:
            setup.close()
        model, equilibrium = prepared.model, prepared.equilibrium
        report = {**static_report(model, equilibrium), "hook_load": prepared.static["hook_load"],
                  "weight_on_bit": prepared.static["weight_on_bit"]}
        report["reduced_size"] = model.size
        report["basis_guard"] = model.guard
        reasons = discretisation_reasons(scene, {"command": "static"})
        if reasons:
            report["suspect_reasons"] = reasons
            summary.update(status="suspect", suspect_reasons=reasons)
        writer = FieldWriter(model.disc, out / "static.xdmf")
        writer.write(model.space.expand(equilibrium.q), 0.0)
        writer.close()
        if model.disc.trajectory is not None or model.disc.sections is not None:  # a well: its loads along it
            profiles = fe_static_profiles(scene, model, equilibrium.q)
            write_atomic(out / "static_profiles.h5", lambda tmp: profiles.to_netcdf(tmp, engine="h5netcdf"))
            write_path_vtu(out / "static_path.vtu", profiles)
            report["buckling"] = static_buckling(profiles, model.vertex_gap,
                                                 lambda: unstable_modes(scene, model.disc, model.operators,
                                                                        state_of(model, equilibrium.q)))
            if report["buckling"]["unstable"]:
                reasons = [*reasons, report["buckling"]["message"]]
                report["suspect_reasons"] = reasons
                summary.update(status="suspect", suspect_reasons=reasons)
        write_json(out / "static.json", report)
        summary["message"] = "static.json"
    return report


#: A buckled span of a static state whose largest lateral displacement is below this share of the clearance lies
#: off the wall: the straight state of a compressed string, an equilibrium that is not stable.
OFF_THE_WALL = 0.5


def static_buckling(profiles, gap: np.ndarray, unstable_modes) -> dict:
    """Where the FE static state of a string in its well is compressed beyond its sinusoidal or helical buckling
    loads in the hole (:func:`~fenics_drill.observables.buckling.buckled_spans` of its axial force), with a sentence
    that says so.  Those loads are a long string's: where the buckled span lies off the wall (:data:`OFF_THE_WALL`),
    ``unstable_modes()`` (the drive-held modes without stiffness about the state) says whether the straight state
    found stands (a short span's own Euler load can carry the compression) or not (``unstable``)."""
    md, middle = profiles["md"].values, profiles["md_element"].values
    spans = buckled_spans(middle, np.diff(md), -profiles["axial_force"].values,
                          profiles["sinusoidal_buckling_load"].values, profiles["helical_buckling_load"].values)
    spans["unstable"], spans["message"] = False, None
    if spans["first_buckled_md_m"] is None:
        return spans
    inside = (md >= spans["first_buckled_md_m"]) & (md <= spans["last_buckled_md_m"])
    share = float(np.max(profiles["lateral_displacement"].values[inside] / gap[inside])) if inside.any() else 0.0
    sinusoidal, helical = spans["buckling_loads_at_max_compression_N"]
    modes = unstable_modes() if share < OFF_THE_WALL else []
    spans["unstable"], spans["unstable_mode_count"] = bool(modes), len(modes)
    spans["unstable_modes"] = modes[:REPORTED_MODES]
    where = ("lies buckled on the wall" if share >= OFF_THE_WALL else
             f"the state found lies off the wall there, straight, and does not stand: {len(modes)} mode(s) of the "
             f"drive-held string have no positive stiffness about it (the first bends most at md "
             f"{modes[0]['largest_lateral_displacement_at_m']:.0f} m)" if modes else
             "stands straight off the wall there (stable over its length: those loads are a long string's)")
    spans["message"] = (
        f"the string is compressed beyond its buckling load in the hole from md {spans['first_buckled_md_m']:.0f} m to "
        f"{spans['last_buckled_md_m']:.0f} m (helically over {spans['helically_buckled_length_m']:.0f} m, "
        f"sinusoidally over {spans['sinusoidally_buckled_length_m']:.0f} m; up to {spans['max_compression_N'] / 1e3:.4g} "
        f"kN against {sinusoidal / 1e3:.4g} kN sinusoidal and {helical / 1e3:.4g} kN helical there) and {where}")
    return spans


#: The share of the run after which the progress line gives an estimate of the time left.
ETA_AFTER = 0.01


class Progress:
    """A progress report on stderr: simulated time, steps, step size, wall time, ETA.  On a terminal one
    line rewritten every 2 s; in a log file (a batch job) one line every 30 s."""

    def __init__(self, enabled: bool, every_s: float | None = None):
        self.terminal = sys.stderr.isatty()
        self.every_s = every_s if every_s is not None else (2.0 if self.terminal else 30.0)
        self.enabled, self.last = enabled, -np.inf

    def __call__(self, t, t_end, stats, dt, wall):
        if not self.enabled or (wall - self.last < self.every_s and t < t_end):
            return
        self.last = wall
        # the first steps (the start-up from rest, at a fraction of the nominal step) say nothing of the rest
        eta = f"{wall * (t_end - t) / t:7.1f} s" if t >= ETA_AFTER * t_end else "    ..."
        line = (f"  t = {t:8.4f} / {t_end:g} s ({100 * t / t_end:5.1f}%)  steps {stats['steps']:7d}  "
                f"dt {dt:.2e} s  wall {wall:7.1f} s  eta {eta}")
        done = t >= t_end * (1 - 1e-12)
        sys.stderr.write(f"\r{line}" + ("\n" if done else "") if self.terminal else f"{line}\n")
        sys.stderr.flush()


class SetupProgress:
    """Progress of a stage that lasts (a set-up, the drawing of figures): after ``quiet_s`` seconds, a line on stderr
    every ``every_s`` seconds naming the part under way, after ``prefix`` (a background thread, so that a long part
    is reported while it runs)."""

    def __init__(self, enabled: bool, quiet_s: float = 5.0, every_s: float = 10.0, prefix: str = "set-up"):
        self.enabled, self.quiet_s, self.every_s, self.prefix = enabled, quiet_s, every_s, prefix
        self.current, self.started = "", time.perf_counter()
        self.done = threading.Event()
        if enabled:
            threading.Thread(target=self._report, daemon=True).start()

    def __call__(self, name: str) -> None:
        self.current = name

    def _report(self) -> None:
        if self.done.wait(self.quiet_s):
            return
        while True:
            sys.stderr.write(f"  {self.prefix}: {self.current} ({time.perf_counter() - self.started:.0f} s)\n")
            sys.stderr.flush()
            if self.done.wait(self.every_s):
                return

    def close(self) -> None:
        self.done.set()


class RunRecorder:
    """Turns accepted steps (and the initial state) into time-series rows and XDMF snapshots."""

    def __init__(self, model: DrillstringModel, scene, out: Path, on_write=None):
        """``on_write(t)`` is called after each write of the files, with the time of the last row written
        (the running summary)."""
        self.model = model
        self.on_write = on_write
        self.rows = StepRows(model, scene)
        self.section_x = self.rows.section_x
        held = drive_held_modes(model.disc, model.modes, scene.modal.f_star_max, model.operators.mass,
                                model.operators.stiffness)
        self.series = TimeSeriesWriter(out / "timeseries.h5", model.disc.vertex_x, {
            "section_x": self.section_x, "gap": self.rows.section_gap, "section_radius": self.rows.outer_radius,
            "scene": json.dumps(scene.to_dict()), "reduced_size": model.size,
        }, model.modes, held_modes=held)
        self.field_interval = scene.output.field_interval
        self.fields = FieldWriter(model.disc, out / "fields.xdmf", with_stress=self.rows.stress is not None,
                                  with_profiles=True) if self.field_interval > 0 else None
        contact = scene.contact
        self.profile_law = (model.vertex_gap, contact.stiffness_linear if scene.model.contact else 0.0,
                            contact.stiffness_cubic if scene.model.contact else 0.0)
        self.next_field_time = 0.0
        # the latest state taken (what an interrupted run reports): its row is in the series at the latest when
        # the recorder closes
        self.last_state = None

    def _write_fields(self, state) -> None:
        if self.fields is not None and state.t >= self.next_field_time - 1e-12:
            dofs = self.model.space.expand(state.q)
            stress = self.rows.stress.cell_stress(dofs) if self.rows.stress is not None else None
            disc = self.model.disc
            u, v, w, tx, ty, tz = (dofs[disc.vertex_dofs(f)] for f in (U, V, W, THETA_X, THETA_Y, THETA_Z))
            profiles = string_profiles(disc.vertex_x, u, v, w, tx, disc.element_properties, *self.profile_law, ty, tz,
                                       disc.element_curvature)
            self.fields.write(dofs, state.t, stress, profiles)
            self.next_field_time = self.field_interval * (np.floor(state.t / self.field_interval + 1e-9) + 1)

    def __call__(self, record: StepRecord) -> None:
        with uninterrupted():  # the files, their rows and last_state stay the same step
            self._write_fields(record.state)
            completed = self.rows.add(record)
            self.last_state = record.state
            self._append(completed)

    def _append(self, rows: list[dict]) -> None:
        written = None  # the time of the last row written to the file
        for row in rows:
            if self.series.append(row):
                written = row["time"]
        if written is not None:
            if self.fields is not None:
                self.fields.flush()
            if self.on_write is not None:
                self.on_write(written)

    def close(self, impacts_per_vertex: np.ndarray) -> None:
        """The rows still pending (:class:`StepRows` completes them in batches) and the impact counts
        written; the files closed."""
        self._append(self.rows.complete())
        self.series.close(impacts_per_vertex)
        if self.fields is not None:
            self.fields.close()


def run_scene(scene, out: str | Path, progress: bool = True, overwrite: bool = False, comm=None) -> dict:
    """Static equilibrium, then the drilling dynamics to time.t_end; returns the summary.

    The output directory is taken under the policy of :mod:`fenics_drill.io.output_directory`
    (OutputError before any computation).  While the run runs, ``summary.json`` says "running"
    and how far it got at the last write of the files; at the end it holds the whole summary,
    however the run ended: finished, suspect (finished, but physically doubtful: see
    ``suspect_reasons``), failed (with when and why) or interrupted (Ctrl-C, SIGTERM).

    On the two ranks of ``comm`` (default: MPI's world; ``mpiexec -n 2``) a full-order string is split between
    them and the first writes the files (:mod:`fenics_drill.studies.shared_run`); the second returns what it
    did, without files."""
    out = Path(out)
    comm = MPI.COMM_WORLD if comm is None else comm
    check_ranks(comm)
    if comm.rank > 0:  # the second rank of a run shared by two (studies/shared_run.py): it writes nothing
        return second_rank_run(scene, comm, comm.bcast(None, root=0))
    try:
        check_memory(scene.beam.elements, scene.beam.element_degree)
        check_run_length(scene)
        _check_disk_for_run(scene, out)
        claim = claim_output(out, "run", overwrite)
    except Exception as err:
        if comm.size > 1:
            comm.bcast(str(err), root=0)
        raise
    if comm.size > 1:
        comm.bcast(None, root=0)
    clock = time.perf_counter()
    summary: dict = {"command": "run", "status": "failed", "message": "", "t_end": 0.0, "steps": 0,
                     **scene_record(scene)}
    recorder = simulation = None
    host = socket.gethostname()

    def running(t: float) -> None:
        # what the files hold: the rows written are the initial state and the steps taken to t
        rows = recorder.series.rows_written
        write_json(out / "summary.json", {**summary, "status": "running", "pid": os.getpid(), "host": host,
                                          "t_end": t, "steps": max(rows - 1, 0), "rows": rows,
                                          "wall_time_s": time.perf_counter() - clock})

    with StopOnSignal(collective=comm.size > 1) as stop:
        try:
            setup = SetupProgress(progress)
            try:
                prepared = prepare(scene, stage=setup)
            finally:
                setup.close()
            if comm.size > 1:
                agree_to_stop(comm)
            model, equilibrium = prepared.model, prepared.equilibrium
            summary["reduced_size"], summary["full_dofs"] = model.size, model.disc.ndofs
            summary["basis_guard"] = model.guard
            summary["discretisation"] = _discretisation(model, scene)
            summary["setup_time_s"], summary["static"] = prepared.setup_time_s, prepared.static
            atomic = uninterrupted
            if comm.size > 1:
                model, summary["ranks"] = shared_model(model, comm)
                if summary["ranks"]["split"]:
                    atomic = functools.partial(uninterrupted, comm=comm)
                else:  # the second rank has left: this one runs alone, and a signal stops it at once
                    stop.collective = False
                    stop_if_requested()
            simulation = Simulation(model, scene)
            start = simulation.initial_state(equilibrium.q)
            if atomic is not uninterrupted:
                check_same_state(comm, start.q)
            recorder = RunRecorder(model, scene, out, on_write=running)
            u0 = model.bit_state(start.q, start.qd)[0]
            summary["nominal_dt"] = nominal_step(scene)
            capped = scene.time.dt <= 0 and summary["nominal_dt"] == torsional_transit(scene)
            if capped:
                summary["nominal_dt_reason"] = ("an element's torsional transit: the wall's static friction makes the "
                                                "string break loose in torsional waves")
            if progress:  # the space it runs in and its length before it starts (the progress line's estimate follows)
                space = "the full order" if model.space.sparse else "a reduced model"
                why = f" ({summary['nominal_dt_reason']})" if capped else ""
                scope = summary["discretisation"].get("lateral")
                split = f" ({scope['said']})" if scope else ""
                sys.stderr.write(f"  {space}, {model.size} unknowns{split}; {scene.time.t_end:g} s at a step of at "
                                 f"most {summary['nominal_dt']:.3g} s{why}: at least {least_steps(scene):.0f} "
                                 "steps\n")
                sys.stderr.flush()
            loop_clock = time.perf_counter()
            try:
                final = simulation.run(start, scene.time.t_end, recorder, Progress(progress), atomic=atomic)
                summary["status"], summary["message"] = "finished", "reached time.t_end"
            except RunFailure as failure:
                final = None
                summary["message"] = str(failure)
            summary["integration_time_s"] = time.perf_counter() - loop_clock
            last = final if final is not None else simulation.last_state
            summary.update(_dynamics_summary(model, simulation, recorder, last, u0))
        except KeyboardInterrupt:
            summary["status"], summary["message"] = "interrupted", "stopped by Ctrl-C or SIGTERM"
            if recorder is not None and recorder.last_state is not None:
                summary.update(_dynamics_summary(model, simulation, recorder, recorder.last_state, u0))
        except StaticFailure as failure:
            summary["message"] = f"at t = 0 s: {failure}"
        except Exception as err:
            reached = recorder.last_state.t if recorder is not None and recorder.last_state is not None else 0.0
            if recorder is not None and recorder.last_state is not None:
                summary.update(_dynamics_summary(model, simulation, recorder, recorder.last_state, u0))
            room = no_room_message(err)
            summary["status"] = "failed"
            summary["message"] = (f"at t = {reached:.6g} s: cannot write the run's files: {room}" if room else
                                  f"at t = {reached:.6g} s: {type(err).__name__}: {err}")
            raise
        finally:
            with uninterrupted(stop_after=False):  # the summary is written whatever comes
                _close_run(summary, out, recorder, simulation, scene)
                summary["wall_time_s"] = time.perf_counter() - clock
                _write_final_summary(out, summary)
                remove_figures(out)
                claim.release()
    return summary


def _discretisation(model, scene) -> dict:
    """Which space the run took and why: the modal basis of ``reduction.rule``, or the full order (asked for, or
    chosen by the 'auto' rule where no modal basis can be trusted); where the lateral fields are not solved along the
    whole string, what the run solves, what it leaves out and what 'auto' chose (:func:`lateral_scope`)."""
    full = model.space.sparse  # the full space's [Phi] is a sparse selection of the free dofs
    why = model.guard.get("full_order", {}).get("why") if full else None
    scope = lateral_scope(scene)
    return {"space": "full order" if full else "modal", "unknowns": model.size, "rule": scene.reduction.rule,
            **({"why": why} if why else {}), **({"lateral": scope} if scope else {})}


def lateral_scope(scene) -> dict | None:
    """``model.lateral_length``'s split as a run states it (None for the whole string's lateral fields): the length
    whose lateral fields are solved [m], the elements' length above it [m] and who chose it, the wall's normal force
    there, what the run leaves out above it, and a one-line ``said`` for the run's first line."""
    lateral = scene.model.lateral_length
    if lateral < 0:
        return None
    chosen = scene.axial_torsional_element_length
    element = chosen if chosen > 0 else scene.string_length / scene.beam.elements
    by = "auto" if scene.model.axial_torsional_element_length == 0 else "scene"
    pressed = ("the string's own tension" if scene.contact.normal_force == "dynamic"
               else "the soft string's normal force")
    solved = f"lateral fields over the bottom {lateral:g} m" if lateral > 0 else "no lateral fields"
    above = "above it" if lateral > 0 else "along the string"
    return {"lateral_length_m": lateral, "axial_torsional_element_length_m": element, "element_length_by": by,
            "wall_normal_force": scene.contact.normal_force,
            "left_out": f"whirl, lateral shocks and bending {above}: u and theta_x alone on the well's axis",
            "said": f"{solved}; u and theta_x {above} on {element:.3g} m elements ({by}), the wall pressed by "
                    f"{pressed}"}


def _check_disk_for_run(scene, out: Path) -> None:
    """The files a run will write, at least: a time-series row per nominal step (steps refined for impacts or the
    bit add to it) and the field snapshots, twice over while a file is updated through its copy."""
    from fenics_drill.io.timeseries import VARIABLES
    from fenics_drill.model.resources import dof_count

    rows = scene.time.t_end / nominal_step(scene) + 1
    series = rows * len(VARIABLES) * 8.0
    snapshots = scene.time.t_end / scene.output.field_interval + 1 if scene.output.field_interval > 0 else 0
    fields = snapshots * (dof_count(scene.beam.elements, 1) + 4 * scene.beam.elements) * 8.0
    check_disk(out, 2.0 * (series + fields), f"the run's files ({rows:.3g} time-series rows for time.t_end = "
               f"{scene.time.t_end:g} s at the nominal step, {snapshots:.3g} field snapshots at output.field_interval "
               f"= {scene.output.field_interval:g} s)")


def _close_run(summary: dict, out: Path, recorder, simulation, scene) -> None:
    """The last rows written and the summary completed from the files.  A disk that is full now fails the run
    with that reason, but what the files already hold is still summarised."""
    if recorder is not None:
        try:
            recorder.close(simulation.impacts_per_vertex)
        except Exception as err:
            room = no_room_message(err)
            if room is None:
                raise
            if summary["status"] != "failed":  # the first failure is the one to report
                reached = "reached time.t_end, but " if summary["status"] == "finished" else ""
                summary["status"] = "failed"
                summary["message"] = f"{reached}the last rows of timeseries.h5 could not be written: {room}"
        quantities = quantities_of_run(out / "timeseries.h5")
        if summary["status"] == "failed":  # a run that failed is no answer: what it did is kept apart
            summary["until_failure"] = quantities
        else:
            summary.update(quantities)
    if simulation is not None and simulation.model.hyper_reduction is not None:
        stats = simulation.stats
        summary["hyper_reduction"] = {**simulation.model.hyper_reduction, "checks": stats["sampling_checks"],
                                      "max_error_found": stats["max_sampling_error"]}
    if simulation is not None:
        _judge_admissibility(summary, simulation, scene)
        _advise_on_energy_budget(summary, scene)


def _write_final_summary(out: Path, summary: dict) -> None:
    """``summary.json`` with the final status, whatever the disk (:func:`write_final_json`); the reason on stderr
    if not even the status fits."""
    try:
        write_json(out / "summary.json", summary)
        return
    except Exception as err:
        room = no_room_message(err)
        if room is None:
            raise
        if summary["status"] != "failed":
            summary["status"], summary["message"] = "failed", f"summary.json could not be written: {room}"
    if not write_final_json(out / "summary.json", summary, keep=("command", "status", "message", "t_end", "steps")):
        sys.stderr.write(f"fenics-drill: {out / 'summary.json'} could not be written ({summary['message']})\n")


def _judge_admissibility(summary: dict, simulation: Simulation, scene) -> None:
    """A finished run whose numbers cannot be trusted becomes "suspect", with its reasons."""
    stats = simulation.stats
    gap = simulation.model.gap  # the smallest clearance
    summary["max_penetration"] = stats["max_penetration"]
    summary["forced_steps"] = stats["forced_steps"]
    reasons = []
    if stats["max_penetration"] > PENETRATION_LIMIT * gap:
        reasons.append(f"the string went {stats['max_penetration'] * 1e3:.3g} mm into the wall, more than "
                       f"{PENETRATION_LIMIT:.0%} of the {gap * 1e3:.3g} mm gap: the contact stiffness or the "
                       "time step does not resolve the impacts")
    if stats["forced_steps"]:
        reasons.append(f"{stats['forced_steps']} steps were accepted at the minimum step size with a local "
                       f"error up to {simulation.controller.worst_forced_ratio:.3g} times time.error_tolerance: "
                       "raise time.max_step_cuts or time.error_tolerance")
    reasons += discretisation_reasons(scene, summary)
    if summary["status"] == "finished":
        energy = summary.get("energy") or {}
        released, work = max(0.0, -energy.get("energy_change", 0.0)), energy.get("input_work", 0.0)
        # the bit can take what the drive put in and what the string released of the energy it started with (a
        # string pressed on bottom, a few steps into its run): beyond that, no resolved run goes
        allowed = 1.0 + released / work if work > 0 else np.inf
        if summary.get("efficiency", 0.0) > allowed:
            reasons.append(f"the efficiency is {summary['efficiency']:.3g} > {allowed:.3g}: the run put out more work "
                           "at the bit than the drive put in and the string released, which no resolved run does")
        backward = -summary.get("mean_bit_velocity", 0.0) * summary.get("t_end", 0.0)  # beyond a start-up recoil
        if scene.drive.axial_velocity > 0 and backward > SMALL_ADVANCE * scene.time.error_tolerance:
            reasons.append(f"the bit moved backwards on average ({summary['mean_bit_velocity'] * 3600:.3g} m/h) "
                           f"while pushed at {scene.drive.axial_velocity * 3600:.3g} m/h")
    if reasons and summary["status"] == "finished":
        summary["status"] = "suspect"
    if reasons:
        summary["suspect_reasons"] = reasons


def discretisation_reasons(scene, summary: dict) -> list[str]:
    """Why the mesh or the step the scene chose cannot carry its band of analysis (the reasons a run or a static
    state is "suspect"); advice on a step that resolves the band less finely than the default."""
    reasons = []
    mesh = mesh_advice(scene)
    if mesh is not None:
        reasons.append(mesh)
    if summary.get("command") == "static":
        return reasons
    band_steps = steps_per_band_period(scene)
    largest = 1.0 / (NYQUIST_STEPS * band_frequency(scene))
    if band_steps < NYQUIST_STEPS:
        reasons.append(f"time.dt = {nominal_step(scene):.3g} s resolves the band's f_max = {band_frequency(scene):.4g} "
                       f"Hz with {band_steps:.2g} steps per period, fewer than {NYQUIST_STEPS:g}: the band is not "
                       f"resolved; use time.dt <= {largest:.3g} s, or -1 for the nominal step")
    elif not scene.time.adaptive and band_steps < RESOLVING_BAND_STEPS * (1.0 - 1e-9):
        reasons.append(f"a fixed step (time.adaptive = false) of {band_steps:.2g} steps per period of f_max resolves "
                       "neither the band nor the bit's transients: use the adaptive step")
    elif band_steps < RESOLVING_BAND_STEPS * (1.0 - 1e-9):
        summary.setdefault("advice", []).append(
            f"the nominal step resolves the band's f_max with {band_steps:.3g} steps per period (the default "
            f"{RESOLVING_BAND_STEPS:g}): the efficiency (96) came out 4-7 % high at the paper's 2 on the paper scene "
            "(docs/verification.md); compare with a run at time.dt = -1")
    elif not scene.time.adaptive and scene.model.bit_rock:
        summary.setdefault("advice", []).append(
            "a fixed step (time.adaptive = false) does not resolve the bit's start-up: on the paper scene over 0.5 s "
            "rop was 1.8 % and the efficiency 1.0 % off the converged model at the nominal step (docs/performance.md)")
    return reasons


def _advise_on_energy_budget(summary: dict, scene) -> None:
    """Advice for a run with impacts, or with the printed kinematics, whose energy budget does not close to
    BALANCE_ADVICE: the share it misses was taken by Newmark's numerical damping, so the motion carries energy
    the step does not resolve, and its drilling quantities may move with the step, the mesh or
    time.newmark_alpha, up to another regime (docs/verification.md)."""
    energy = summary.get("energy")
    if energy is None or not energy["balance_error"] > BALANCE_ADVICE:
        return
    if scene.model.kinematics == "printed":
        cause = "the printed kinematics' spin pumps energy into the highest modes"
    elif summary.get("impacts_total"):
        cause = f"the string hit the wall {summary['impacts_total']} times"
    else:
        return  # the damping of the string's own stiff modes (see BALANCE_ADVICE)
    summary.setdefault("advice", []).append(
        f"the energy budget closes only to {energy['balance_error']:.1%} of the energy exchanged "
        f"(energy.balance_error): that share was taken by no physical law but by the time integration, Newmark's "
        f"numerical damping (time.newmark_alpha = {scene.time.newmark_alpha:g}), because {cause}; rop and the "
        "efficiency may then change with the step, the mesh or the basis, up to a string that rests on the wall "
        "instead of bouncing: compare with a run at a tenth of time.error_tolerance, or with the full order "
        "(reduction.rule = 'none') over a short horizon (docs/verification.md)")


def _dynamics_summary(model, simulation: Simulation, recorder: RunRecorder, state, u0: float) -> dict:
    t = state.t
    u = model.bit_state(state.q, state.qd)[0]
    stats = simulation.stats
    return {
        "t_end": t,
        "steps": stats["steps"],
        "rejected_steps": stats["rejected_steps"],
        "newton_failures": stats["newton_failures"],
        "newton_iterations": stats["newton_iterations"],
        "factorisations": simulation.factorisations,
        "compiled_steps": simulation.stepper.compiled_steps,
        "min_dt": stats["min_dt"], "max_dt": stats["max_dt"],
        "mean_bit_velocity": (u - u0) / t if t > 0 else 0.0,
        "impacts_total": int(simulation.impacts_per_vertex.sum()),
        "section_x": recorder.section_x,
        "energy": simulation.budget.summary(),
    }


def quantities_of_run(series_path: Path) -> dict:
    """Drilling quantities (96)-(99), indicators and the von Mises maximum (100) of the saved series,
    and ``advice`` on physics the scene paid for without needing it."""
    data, attrs = read_series(series_path)
    if len(data["time"]) < 2:
        return {}
    scene = attrs["scene"]
    out = drilling_quantities(data, scene.drive.axial_velocity, scene.drive.rotation_speed)
    out["torque_and_drag"] = top_loads(data["time"], data["lambda_1"], data["lambda_4"])
    if "section_orbit_angle" in data:  # series written before the whirl was recorded have none
        out["whirl"] = {"section": {"x": float(attrs["section_x"]), **whirl(
            data["time"], data["section_v"], data["section_w"], data["section_v_velocity"], data["section_w_velocity"],
            data["section_theta_x_velocity"], float(attrs["gap"]),
            float(attrs.get("section_radius", scene.beam.outer_radius)))},
            "bit": {"direction": "none", "held": True, "why": "model.supports holds v and w at the bit"}}
    stress = data["max_von_mises"]
    if np.isfinite(stress).any():
        k = int(np.nanargmax(stress))
        out["max_von_mises"] = {"value": float(stress[k]), "x": float(data["max_von_mises_x"][k]),
                                "t": float(data["time"][k])}
    advice = []
    p = scene.beam_properties
    ringing = spin_variation_ratio(data["time"], data["bit_angular_velocity"], scene.drive.rotation_speed,
                                   p.torsional_wave_speed / (4.0 * p.length))
    if np.isfinite(ringing):
        out["bit_spin_variation_ratio"] = ringing
    if ringing > RINGING_RATIO:
        basis = "the model's basis" if scene.reduction.rule != "none" else "the model"
        advice.append(f"the bit's angular velocity varies {ringing:.0f} times more over the second half of the run "
                      "than a stick-slip at the string's first torsional frequency can: it zig-zags from step to "
                      f"step, a stiff bit-local direction of {basis} ringing against the bit law's torque, which "
                      "falls with the spin rate; the peak stress at the bit and the efficiency may be several % "
                      "off: compare with the full order (reduction.rule = 'none') over a short horizon "
                      "(docs/verification.md)")
    advance = float(data["bit_displacement"][-1] - data["bit_displacement"][0])
    if scene.drive.axial_velocity > 0 and advance < SMALL_ADVANCE * scene.time.error_tolerance:
        advice.append(f"the bit advanced {advance * 1e6:.3g} um, {advance / scene.time.error_tolerance:.2g} times "
                      "time.error_tolerance, the local error a step may make: rop and efficiency measure a motion of "
                      "the size of a few steps' errors (on a long string, the bit has barely started moving) and "
                      "may be off by several %: run longer, or at a tighter time.error_tolerance "
                      "(docs/verification.md)")
    transit = torsional_transit(scene)
    longest = float(np.diff(data["time"]).max(initial=0.0))
    if breaks_loose_in_waves(scene) and longest > transit * (1.0 + 1e-6):  # a time.dt the scene chose
        advice.append(f"the wall's static friction makes the string break loose in torsional waves, which steps "
                      f"longer than an element's torsional transit ({1e3 * transit:.3g} ms) smooth away, and this "
                      f"run's steps reached {1e3 * longest:.3g} ms: run it with time.dt = {transit:.2g} or less, or "
                      "-1, whose nominal step is capped there (docs/guide/stick_slip_maps.md)")
    if scene.model.contact and scene.model.lateral_length < 0 and not data["vertices_in_contact"].any():
        advice.append("the string never touched the wall: model.contact = false gives the same answer "
                      "without paying for contact")
    if advice:
        out["advice"] = advice
    return out
