"""What every drilling run of a scene shares, and one run of it kept in memory.

:func:`prepare` builds the model and solves its static equilibrium (Section 6.4) once;
neither depends on the drive speeds nor on the bit-rock parameters, so a Monte Carlo
study or an operating window runs every realisation from the same prepared scene
(:func:`run_realisation`) with its own drive and bit-rock law, on a model derived
from the shared one (the shared one is never changed).
"""

from __future__ import annotations

import dataclasses
import time
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from fenics_drill.model.drillstring import DrillstringModel, build_model
from fenics_drill.model.forces.axial_tip_load import AxialTipLoad
from fenics_drill.model.well import check_string_in_well
from fenics_drill.model.reduction.enrichment import (basis_error, bit_loads, missed_share, tangent_responses,
                                                     wall_friction_loads)
from fenics_drill.model.reduction.hyper_reduction import train_sample
from fenics_drill.model.internal_force import AssembledInternalForce
from fenics_drill.model.reduction.spaces import ModalSpace
from fenics_drill.observables.drilling_quantities import bit_bounce, drilling_quantities, stick_slip
from fenics_drill.observables.step_rows import StepRows
from fenics_drill.solvers.static import StaticEquilibrium, StaticFailure, solve_static, static_report
from fenics_drill.solvers.step_control import RunFailure
from fenics_drill.solvers.time_loop import Simulation
from fenics_drill.studies.lifecycle import uninterrupted
from fenics_drill.studies.operating_state import prestressed_modes, solve_pressed

#: Time histories kept per realisation (Figs. 29, 31, 33).
HISTORIES = ("bit_displacement", "bit_velocity", "bit_rotation", "bit_angular_velocity", "section_w",
             "section_w_velocity")


@dataclass
class PreparedScene:
    """The model of a scene and its static equilibrium (Section 6.4), shared by all its runs."""

    model: DrillstringModel
    equilibrium: StaticEquilibrium
    static: dict
    setup_time_s: float


def prepare(scene, dynamics: bool = True, stage=lambda name: None) -> PreparedScene:
    """Build the model and solve its static equilibrium (raises StaticFailure).

    A reduced model whose basis misses the string's state at rest beyond ``reduction.guard_tolerance``
    (a heavy string on the wall, a long one sagging far: large deflections that the modes and their
    companions carry only approximately) gets that state, solved once in the full order, as one more
    basis vector when ``reduction.enrich`` is on; the guard's report says so (``static_state``).
    The basis's directions above the band are damped as they are with the string resting at that equilibrium
    (:meth:`~fenics_drill.model.drillstring.DrillstringModel.resting_at`).
    With ``dynamics`` and ``reduction.hyper``, a modal model's nonlinear forces are then sampled
    (:func:`_with_element_sample`).  ``stage(name)`` is told each part as it starts (a progress report).
    A scene that starts on bottom (:attr:`~fenics_drill.scene.Scene.starts_on_bottom`) rests with the bit pressed at
    ``drive.weight_on_bit`` (an axial load at the bit in the static solve); its static report's hook load is then
    the on-bottom one."""
    check_string_in_well(scene)
    clock = time.perf_counter()
    stage("mesh, operators, modes and the solution space (a reduced basis or the full order)")
    model = build_model(scene, prestressed_modes(scene))
    initial = None
    if isinstance(model.space, ModalSpace) and scene.reduction.enrich and scene.model.gravity:
        stage("the static state in the full order, and the responses at rest")
        model, state = _with_static_state(model, scene.reduction.guard_tolerance,
                                          scene.reduction.rest_response_tolerance)
        if state is not None:
            initial = model.space.phi.T @ (model.operators.mass @ state)  # M-orthonormal basis: the projection
    setup = time.perf_counter() - clock
    on_bottom = scene.drive.weight_on_bit if scene.starts_on_bottom else 0.0
    stage("the static equilibrium on the wall" + (f", the bit pressed at {on_bottom / 1e3:.4g} kN" if on_bottom else ""))
    resting = model if not on_bottom else model.with_added_force(AxialTipLoad(model.disc, model.space, on_bottom))
    equilibrium = solve_pressed(resting, scene, on_bottom, initial=initial)
    model = model.resting_at(equilibrium.q)
    static = {k: v for k, v in static_report(resting, equilibrium).items() if k != "contact_vertices"}
    static["weight_on_bit"] = on_bottom
    if dynamics and scene.reduction.hyper and isinstance(model.space, ModalSpace) \
            and isinstance(model.internal, AssembledInternalForce):
        stage(f"the element sample of the nonlinear forces (training run of {scene.reduction.hyper_training:g} s)")
        model = _with_element_sample(model, scene, equilibrium)
    return PreparedScene(model, equilibrium, static, setup)


#: Training states kept from the training run (evenly spaced in its steps).
TRAINING_STATES = 12


def _with_element_sample(model: DrillstringModel, scene, equilibrium: StaticEquilibrium) -> DrillstringModel:
    """The model with its nonlinear internal forces on an ECSW element sample, trained on
    TRAINING_STATES states of the first ``reduction.hyper_training`` seconds from the static state.

    The training run itself is sampled: a first sample, trained on the initial state alone (turned
    through the spin like every training state), and checked and retrained by the run's error
    indicator, gives its states at a sampled model's cost (a quarter of the unsampled one's); the sample
    is then trained on them, each state's element forces exact.  The model is returned as it was if the
    run fails (said in its ``hyper_reduction`` report)."""
    clock = time.perf_counter()
    horizon = min(scene.reduction.hyper_training, scene.time.t_end)
    m = scene.model
    switches = (m.geometric_nonlinearity, m.inertial_nonlinearity, m.kinematics, m.angular_velocity)
    start = Simulation(model, scene, energy_budget=False).initial_state(equilibrium.q)
    first = [(start.q, start.qd, start.qdd)]
    sample, report = train_sample(model.disc, model.space, model.operators, switches, first,
                                  scene.reduction.hyper_tolerance)
    for trainer in (model.with_sample(sample, report, first), model):  # the unsampled run if the sampled fails
        simulation = Simulation(trainer, scene, energy_budget=False)
        states = []
        try:
            simulation.run(simulation.initial_state(equilibrium.q), horizon,
                           lambda r: states.append((r.state.q, r.state.qd, r.state.qdd)))
            break
        except RunFailure as failure:
            message = f"training run failed, all elements kept: {failure}"
    else:
        model.hyper_reduction = {"elements": None, "message": message}
        return model
    chosen = np.unique(np.linspace(0, len(states) - 1, TRAINING_STATES).round().astype(int))
    training = [states[i] for i in chosen]
    sample, report = train_sample(model.disc, model.space, model.operators, switches, training,
                                  scene.reduction.hyper_tolerance)
    report.update(training_time_s=time.perf_counter() - clock, training_horizon_s=horizon)
    return model.with_sample(sample, report, training)


def _with_static_state(model: DrillstringModel, tolerance: float,
                       rest_tolerance: float) -> tuple[DrillstringModel, np.ndarray]:
    """The model, with the full-order static state added to its basis if the basis misses more than
    ``tolerance`` of it, and the state's responses to the loads that change in a run if it misses more than
    ``rest_tolerance`` of them (:func:`_with_responses_at_rest`); and that state (full-space dofs), or None if
    the full order finds no static state (said in the guard)."""
    full = model.full_order()
    try:
        equilibrium = solve_static(full)
    except StaticFailure as failure:  # the reduced solve may still succeed: it is tried as it was
        model.guard = {**model.guard, "static_state": {"error": None, "added": False,
                                                       "message": f"full-order static state not found: {failure}"}}
        return model, None
    state = full.space.expand(equilibrium.q)
    stiffness, held = model.operators.stiffness, model.at_rest().constraints
    missed = missed_share(model.space.phi, stiffness, held, state)
    guard = {**model.guard, "static_state": {"error_modes": missed, "added": missed > tolerance}}
    if missed > tolerance:
        model = model.with_vectors(state[:, None], guard)
    guard["static_state"]["error"] = missed_share(model.space.phi, stiffness, model.at_rest().constraints, state)
    model.guard = guard
    return _with_responses_at_rest(model, full, equilibrium, rest_tolerance), state


def _with_responses_at_rest(model: DrillstringModel, full: DrillstringModel, equilibrium: StaticEquilibrium,
                            tolerance: float) -> DrillstringModel:
    """The model, with the responses of the string at rest to the loads that change in a run added to its basis
    where it misses more than ``tolerance`` of them (in the energy norm of the tangent at rest): a unit bit
    force and torque, and the wall's axial friction and friction torque driven by the full order's reaction at
    rest.  The tangent holds the wall's springs and the geometric stiffness, so these are the shapes the
    resting string takes as the bit load and the friction vary: the moment's kink at the touchdown where a
    pinned string sags onto the wall, which the modes of the free string carry poorly (the peak stress was
    0.6-2 % low; docs/verification.md).  Each one's share missed by the basis is in the guard (``*_at_rest``)."""
    at_rest, space = full.at_rest(), full.space
    zero = np.zeros(full.size)
    evaluation = at_rest.evaluate(equilibrium.q, zero, zero, equilibrium.mu, tangent_coefficients=(1.0, 0.0, 0.0))
    loads = bit_loads(model.disc) if model.force("bit_rock") is not None else {}
    wall = evaluation.forces.get("wall")
    if wall is not None and model.scene.contact.friction > 0 and wall.delta.max(initial=0.0) > 0:
        loads.update(wall_friction_loads(model.disc, space.expand(wall.generalised),
                                         model.scene.contact.friction_model == "coulomb"))
    if not loads:
        return model
    responses = {name: response for name, response in
                 tangent_responses(space, evaluation.tangent, at_rest.constraints, loads).items()
                 if np.all(np.isfinite(response))}  # a singular tangent at rest gives none
    loads = {name: loads[name] for name in responses}

    def missed(basis, name):
        return basis_error(basis.space.phi[space.free], evaluation.tangent, basis.at_rest().constraints,
                           space.project(loads[name]), space.project(responses[name]))

    report = {f"{name}_at_rest": {"error_modes": missed(model, name)} for name in loads}
    added = [name for name in loads if report[f"{name}_at_rest"]["error_modes"] > tolerance]
    guard = {**model.guard, **report}
    if added:
        model = model.with_vectors(np.column_stack([responses[name] for name in added]), guard)
    for name in loads:
        report[f"{name}_at_rest"].update(added=name in added, error=missed(model, name))
    model.guard = guard
    return model


class RealisationRecorder:
    """Keeps the rows of one realisation in memory and integrates ||q||^2 (Eq. 101)."""

    def __init__(self, model: DrillstringModel, scene):
        self.model = model
        self.rows = StepRows(model, scene)
        self._series: dict[str, list] = defaultdict(list)
        self.q_norm_integral = 0.0
        self._last: tuple[float, float] | None = None

    def __call__(self, record) -> None:
        s = record.state
        self._keep(self.rows.add(record))
        q2 = float(s.q @ s.q)
        if self._last is not None:
            t0, q20 = self._last
            self.q_norm_integral += 0.5 * (q20 + q2) * (s.t - t0)
        self._last = (s.t, q2)

    def _keep(self, rows: list[dict]) -> None:
        for row in rows:
            for key, value in row.items():
                self._series[key].append(value)

    @property
    def series(self) -> dict[str, list]:
        """Every variable's values at the steps taken so far."""
        self._keep(self.rows.complete())
        return self._series


def run_realisation(prepared: PreparedScene, scene) -> dict:
    """One drilling run from the shared static state with the drive speeds and bit-rock parameters of
    ``scene`` (a variant of the prepared one): histories on the grid of ``uncertainty.output_interval``
    and the scalars of a realisation."""
    model = prepared.model.with_drive(scene.drive.axial_velocity, scene.drive.rotation_speed) \
        .with_bit_rock(scene.bit_rock)
    simulation = Simulation(model, scene, energy_budget=False)  # no output of a realisation reads the budget
    start = simulation.initial_state(prepared.equilibrium.q)
    recorder = RealisationRecorder(model, scene)
    clock = time.perf_counter()
    status, message = "finished", "reached time.t_end"
    try:
        simulation.run(start, scene.time.t_end, recorder, atomic=uninterrupted)  # a signal stops it between steps
    except RunFailure as failure:
        status, message = "failed", str(failure)
    series = {k: np.asarray(v, dtype=float) for k, v in recorder.series.items()}
    t = series["time"]
    grid = np.arange(0.0, scene.time.t_end + 1e-9, scene.uncertainty.output_interval)
    drive = scene.drive
    result = {"status": status, "message": message, "wall_time_s": time.perf_counter() - clock,
              "steps": simulation.stats["steps"], "time": grid,
              "histories": {name: np.interp(grid, t, series[name]) for name in HISTORIES},
              "bit_rock": dataclasses.asdict(scene.bit_rock), "q_norm_integral": recorder.q_norm_integral}
    q = drilling_quantities(series, drive.axial_velocity, drive.rotation_speed) if len(t) > 1 else {}
    result["rop"], result["efficiency"] = q.get("rop", np.nan), q.get("efficiency", np.nan)
    result["signed_rop"] = q.get("signed_rop", np.nan)
    result["efficiency_torque_magnitude"] = q.get("efficiency_torque_magnitude", np.nan)
    result["mean_bit_velocity"] = (series["bit_displacement"][-1] - series["bit_displacement"][0]) / t[-1] \
        if t[-1] > 0 else np.nan
    result.update(_oscillation_indicators(series, drive.axial_velocity, drive.rotation_speed))
    stress = series["max_von_mises"]
    result["max_von_mises"] = float(np.nanmax(stress)) if np.isfinite(stress).any() else np.nan
    return result


def _oscillation_indicators(series: dict, axial_velocity: float, rotation_speed: float) -> dict:
    """Stick-slip severity, stuck fraction and off-bottom fraction over the second half of a run (the
    start-up from the static state left out): what a stick-slip map shows."""
    t = series["time"]
    late = t >= 0.5 * t[-1]
    if late.sum() < 2 or rotation_speed <= 0:
        return {"stick_slip_severity": np.nan, "stick_fraction": np.nan, "off_bottom_fraction": np.nan}
    spin = stick_slip(t[late], series["bit_angular_velocity"][late], rotation_speed)
    bounce = bit_bounce(t[late], series["bit_velocity"][late], axial_velocity)
    return {"stick_slip_severity": spin["stick_slip_severity"], "stick_fraction": spin["stick_fraction"],
            "off_bottom_fraction": bounce["off_bottom_fraction"]}
