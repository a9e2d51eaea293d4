"""One row of observables per accepted step: what ``timeseries.h5`` stores (names and units in
:data:`fenics_drill.timeseries.VARIABLES`) and what a Monte Carlo realisation keeps."""

from __future__ import annotations

import numpy as np

from fenics_drill.drillstring_model import DrillstringModel
from fenics_drill.simulation import StepRecord
from fenics_drill.von_mises import VonMisesProbe

TX_FIELD = 3


class StepRows:
    """Turns a :class:`StepRecord` into a dict of scalars (the bit, the section, the stress, energies)."""

    def __init__(self, model: DrillstringModel, scene: dict):
        self.model = model
        disc = model.disc
        section = int(np.argmin(np.abs(disc.vertex_x - scene["output"]["section"])))
        self.section_x = float(disc.vertex_x[section])
        v_rows, w_rows = model.lateral_rows
        tx_rows = model.space.rows(disc.vertex_dofs(TX_FIELD))
        self.section_rows = (v_rows[[section]], w_rows[[section]], tx_rows[[section]])
        flags = scene["model"]
        self.stress = VonMisesProbe(disc, flags["geometric_nonlinearity"], flags["kinematics"]) \
            if scene["output"]["von_mises"] else None

    def __call__(self, record: StepRecord, dofs: np.ndarray) -> dict:
        """The row of one step; ``dofs`` is the full-space displacement Phi q of the step."""
        s = record.state
        u, du, tx, dtx = self.model.bit_state(s.q, s.qd)
        bit = record.evaluation.bit
        v, w, _ = (float((rows @ s.q)[0]) for rows in self.section_rows)
        dv, dw, dsx = (float((rows @ s.qd)[0]) for rows in self.section_rows)
        stress, stress_x = self.stress.maximum(dofs) if self.stress is not None else (np.nan, np.nan)
        budget = record.budget
        return {
            "time": s.t, "dt": record.dt, "newton_iterations": record.newton_iterations,
            "bit_displacement": u, "bit_velocity": du, "bit_rotation": tx, "bit_angular_velocity": dtx,
            "bit_force": 0.0 if bit is None else bit.force, "bit_torque": 0.0 if bit is None else bit.torque,
            "lambda_1": s.mu[0], "lambda_4": s.mu[1],
            "impacts": int(record.onsets.sum()), "vertices_in_contact": int(record.in_contact.sum()),
            "section_v": v, "section_w": w, "section_v_velocity": dv, "section_w_velocity": dw,
            "section_theta_x_velocity": dsx, "max_von_mises": stress, "max_von_mises_x": stress_x,
            "kinetic_energy": budget.kinetic, "strain_energy": budget.strain,
            "input_work": budget.input_work, "dissipated_energy": budget.total_dissipated,
        }
