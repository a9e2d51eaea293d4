"""One row of observables per accepted step: what ``timeseries.h5`` stores and what a Monte Carlo
realisation keeps.  :data:`VARIABLES` names them with their units; the point forces add theirs
(:func:`fenics_drill.model.forces.recorded_variables`)."""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from fenics_drill.model.discretization import THETA_X
from fenics_drill.model.drillstring import DrillstringModel
from fenics_drill.model.forces import recorded_variables
from fenics_drill.observables.von_mises import VonMisesProbe
from fenics_drill.observables.whirl import slip_velocity
from fenics_drill.solvers.time_loop import StepRecord

#: name: (units, long name) of every per-step variable that does not belong to a point force.
STATE_VARIABLES = {
    "time": ("s", "simulated time"),
    "dt": ("s", "time step that reached this instant"),
    "newton_iterations": ("1", "Newton iterations of the step"),
    "bit_displacement": ("m", "axial displacement of the bit u(L)"),
    "bit_velocity": ("m/s", "axial velocity of the bit u_dot(L)"),
    "bit_rotation": ("rad", "rotation of the bit theta_x(L)"),
    "bit_angular_velocity": ("rad/s", "angular velocity of the bit theta_x_dot(L)"),
    "lambda_1": ("N", "Lagrange multiplier lambda_1 of (74): -lambda_1 is the force the drive applies at x = 0 "
                 "(minus the weight on bit of a hook-load drive)"),
    "lambda_4": ("N m", "Lagrange multiplier lambda_4 of (74): -lambda_4 is the torque the drive applies at x = 0 "
                 "(minus the motor torque of a top-drive controller)"),
    "top_velocity": ("m/s", "axial velocity of the top u_dot(0)"),
    "top_angular_velocity": ("rad/s", "angular velocity of the top theta_x_dot(0)"),
    "impacts": ("1", "vertices whose wall impact began during the step: contact after moving clear of the wall"),
    "section_v": ("m", "lateral displacement v at the recorded section"),
    "section_w": ("m", "lateral displacement w at the recorded section"),
    "section_v_velocity": ("m/s", "lateral velocity v_dot at the recorded section"),
    "section_w_velocity": ("m/s", "lateral velocity w_dot at the recorded section"),
    "section_theta_x_velocity": ("rad/s", "angular velocity theta_x_dot at the recorded section"),
    "section_orbit_angle": ("rad", "angle of the recorded section's centre in the hole, atan2(w, v)"),
    "section_slip_velocity": ("m/s", "slip of the section's surface facing the wall, t . (v_dot, w_dot) + R_ext "
                              "theta_x_dot with t = (-w, v) / r: zero when it rolls on the wall"),
    "max_von_mises": ("Pa", "maximum von Mises stress over the string (NaN if output.von_mises is off)"),
    "max_von_mises_x": ("m", "x where the maximum von Mises stress sits"),
    "kinetic_energy": ("J", "kinetic energy, Eq. (24)"),
    "strain_energy": ("J", "strain energy, Eq. (30)"),
    "input_work": ("J", "work of the drive since t = 0"),
    "dissipated_energy": ("J", "energy dissipated since t = 0"),
}

#: Every per-step variable of a run: the state's and the point forces'.
VARIABLES = {**STATE_VARIABLES, **recorded_variables()}


class StepRows:
    """Turns accepted steps (:class:`StepRecord`) into dicts of scalars: the bit, the section, the stress,
    energies, and what each point force records (zeros for the forces the scene leaves off).

    What a step's record alone knows (its time, multipliers, works, the forces' records) is read when
    the step is taken; what follows from its state (the bit and section values, the von Mises maximum
    over the string) is computed for BATCH steps together, with one product of [Phi] with all their
    states instead of one per step (docs/performance.md), and its kinetic and strain energies
    are read from the budget, which computes them in batches too."""

    #: Steps whose state observables are computed together.
    BATCH = 64

    def __init__(self, model: DrillstringModel, scene):
        self.model = model
        disc = model.disc
        section = int(np.argmin(np.abs(disc.vertex_x - scene.output.section)))
        self.section_x = float(disc.vertex_x[section])
        # the pipe's contact radius and its clearance at the section (one pipe: R_ext and R_bh - R_ext)
        self.outer_radius = float(disc.vertex_radii(scene.borehole.radius)[0][section])
        self.section_gap = float(model.vertex_gap[section])
        v_rows, w_rows = model.lateral_rows
        tx_rows = model.space.rows(disc.vertex_dofs(THETA_X))
        # u(L), theta_x(L), then v, w, theta_x at the section, then u(0), theta_x(0): one product gives them all
        parts = (model.bit_rows, v_rows[[section]], w_rows[[section]], tx_rows[[section]], model.drive.rows.dense())
        self.point_rows = sp.vstack(parts, format="csr") if sp.issparse(parts[0]) else np.vstack(parts)
        flags = scene.model
        self.stress = VonMisesProbe(disc, flags.geometric_nonlinearity, flags.kinematics) \
            if scene.output.von_mises else None
        self.absent = {name: 0.0 for name in recorded_variables()}
        self._pending: list[tuple[dict, object]] = []  # (what the record gave, state) of steps not yet returned

    def add(self, record: StepRecord) -> list[dict]:
        """Take an accepted step; returns the rows it completes: BATCH rows every BATCH steps, else none."""
        self._pending.append((self._record_scalars(record), record.state, record.budget, record.step_index))
        return self.complete() if len(self._pending) >= self.BATCH else []

    def complete(self) -> list[dict]:
        """The rows of the steps taken and not yet returned, in their order."""
        if not self._pending:
            return []
        scalars, states, budgets, steps = zip(*self._pending)
        q = np.array([s.q for s in states])
        values = np.asarray(self.point_rows @ q.T).T.tolist()  # (steps, 7)
        rates = np.asarray(self.point_rows @ np.array([s.qd for s in states]).T).T.tolist()
        if self.stress is not None:
            largest, where = self.stress.maxima(self.model.space.expand_rows(q))
            stresses = list(zip(largest.tolist(), where.tolist()))
        else:
            stresses = [(np.nan, np.nan)] * len(states)
        energies = [(np.nan, np.nan) if budget is None else budget.energies_at(step)
                    for budget, step in zip(budgets, steps)]
        rows = []
        for known, (u, tx, v, w, *_), (du, dtx, dv, dw, dsx, du_top, dtx_top), (stress, stress_x), (kinetic, strain) \
                in zip(scalars, values, rates, stresses, energies):
            rows.append({**known, "kinetic_energy": kinetic, "strain_energy": strain,
                         "bit_displacement": u, "bit_velocity": du, "bit_rotation": tx,
                         "bit_angular_velocity": dtx, "section_v": v, "section_w": w, "section_v_velocity": dv,
                         "section_w_velocity": dw, "section_theta_x_velocity": dsx, "top_velocity": du_top,
                         "top_angular_velocity": dtx_top, "max_von_mises": stress, "max_von_mises_x": stress_x,
                         "section_orbit_angle": math.atan2(w, v),
                         "section_slip_velocity": float(slip_velocity(v, w, dv, dw, dsx, self.outer_radius))})
        self._pending.clear()  # only now: a row interrupted while computed is still pending
        return rows

    def _record_scalars(self, record: StepRecord) -> dict:
        """The row's values that the step's record gives (all but those of its state's observables)."""
        s = record.state
        budget = record.budget
        work, dissipated = (np.nan,) * 2 if budget is None else (budget.input_work, budget.total_dissipated)
        force, torque = self.model.drive.applied(s.mu, record.evaluation.drive)
        row = {
            "time": s.t, "dt": record.dt, "newton_iterations": record.newton_iterations,
            "lambda_1": -force, "lambda_4": -torque, "impacts": len(record.impacts),
            "input_work": work, "dissipated_energy": dissipated,
            **self.absent,
        }
        for force in self.model.forces:
            row.update(force.record(record.evaluation.forces[force.name]))
        return row
