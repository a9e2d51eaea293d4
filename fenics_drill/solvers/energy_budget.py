"""Energy budget of a run: E(t) - E(0) = W_drive - D, term by term.

Mechanical energy E = T (24) (plus the top drive's J_td theta_x_dot(0)^2 / 2) + strain energy (30) +
the potentials of the point forces (gravity -F_G . U, wall springs k1 delta^2 / 2 + k2 delta^4 / 4).
The drive's work is int lambda . h_dot dt for what it holds, and the work of the weight on bit and
motor torque it applies otherwise; the viscous damping (38) dissipates; and every non-conservative law of
the point forces does its own work, booked under its name: ``wall_damper`` (17),
``wall_axial_friction`` (18), ``wall_friction_torque`` (19), ``bit_rock_force`` (20),
``bit_rock_torque`` (21).  A law that dissipates does negative work; one that injects energy
(the printed (18), (19), (21), docs/errata.md) shows as a positive term, not as a balance error:

    E(t) - E(0) = W_drive + sum_laws W_law - D_damping.

Work
increments use the trapezoidal rule  dW = (f_n + f_{n+1}) / 2 . (q_{n+1} - q_n),
which is exact for the average-acceleration Newmark rule (alpha = 0) on linear
terms; with alpha > 0 the budget also shows Newmark's numerical dissipation.

The kinetic and strain energies of the accepted states are computed for BATCH states at once
(:meth:`EnergyBudget.defer`), in one compiled call per energy: at every step they cost as much as a model
evaluation (docs/performance.md).  Whatever reads them settles the pending states first.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np


@dataclass
class PowerTerms:
    """The generalised forces of one state that enter the budget."""

    drive: np.ndarray  # lambda (force, torque applied by the drive at x = 0)
    drive_displacement: np.ndarray  # B q: the held ones of (u(0), theta_x(0))
    drive_loads: np.ndarray  # the generalised weight on bit and motor torque of a drive that applies them
    damping: np.ndarray  # C qd
    laws: dict[str, np.ndarray]  # the non-conservative generalised force of each law of the point forces


@dataclass
class EnergyBudget:
    initial_energy: float
    #: (rows of q, rows of qd) -> (kinetic, strain energies): what :meth:`defer` computes its states' energies with
    energies: Callable | None = None
    input_work: float = 0.0
    dissipated: dict = field(default_factory=lambda: {"damping": 0.0})
    work_by_law: dict = field(default_factory=dict)
    _energy: float = 0.0
    _kinetic: float = 0.0
    _strain: float = 0.0
    _potential: float = 0.0
    _scale: float = 0.0
    _pending: list = field(default_factory=list)  # (step, q, qd, potential) of deferred states, in order
    _by_step: dict = field(default_factory=dict)  # step -> (kinetic, strain) of the latest KEPT recorded steps

    #: States whose energies are computed together.
    BATCH: ClassVar[int] = 64
    #: Recorded steps whose energies stay readable by step (:meth:`energies_at`; a reader takes them every BATCH).
    KEPT: ClassVar[int] = 1024

    def __post_init__(self):
        self._energy = self.initial_energy

    def advance(self, old: PowerTerms, new: PowerTerms, dq: np.ndarray) -> None:
        """Add the work of one step."""
        self.input_work += 0.5 * float((old.drive + new.drive) @ (new.drive_displacement - old.drive_displacement))
        self.input_work += 0.5 * float((old.drive_loads + new.drive_loads) @ dq)
        self.dissipated["damping"] += 0.5 * float((old.damping + new.damping) @ dq)
        work = self.work_by_law
        for terms in (old.laws, new.laws):  # a law present at one end of the step only works from that end
            for name, law in terms.items():
                work[name] = work.get(name, 0.0) + 0.5 * float(law @ dq)

    def record(self, kinetic: float, strain: float, potential: float, step: int | None = None) -> None:
        """Set the mechanical energy of the current state (potential: of the point forces); ``step`` keeps its
        kinetic and strain energies readable by :meth:`energies_at`."""
        self._settle()
        self._set(kinetic, strain, potential, step)

    def defer(self, step: int, q: np.ndarray, qd: np.ndarray, potential: float) -> None:
        """:meth:`record` of the state (q, qd), its energies computed with the next BATCH - 1 ones (or when read)."""
        self._pending.append((step, q, qd, potential))
        if len(self._pending) >= self.BATCH:
            self._settle()

    def _settle(self) -> None:
        """Compute and record the energies of the deferred states, in their order."""
        if not self._pending:
            return
        steps, qs, qds, potentials = zip(*self._pending)
        self._pending.clear()
        kinetic, strain = self.energies(np.array(qs), np.array(qds))
        for k, s, p, step in zip(kinetic.tolist(), strain.tolist(), potentials, steps):
            self._set(k, s, p, step)

    def _set(self, kinetic: float, strain: float, potential: float, step: int | None) -> None:
        self._kinetic, self._strain, self._potential = kinetic, strain, potential
        self._energy = kinetic + strain + potential
        self._scale = max(self._scale, abs(self._energy - self.initial_energy), kinetic)
        if step is not None:
            self._by_step[step] = (kinetic, strain)
            if len(self._by_step) > self.KEPT:
                del self._by_step[next(iter(self._by_step))]

    def energies_at(self, step: int) -> tuple[float, float]:
        """(kinetic, strain) energy of a recorded step, one of the latest KEPT."""
        self._settle()
        return self._by_step[step]

    @property
    def energy(self) -> float:
        """Mechanical energy of the latest state."""
        self._settle()
        return self._energy

    @property
    def kinetic(self) -> float:
        self._settle()
        return self._kinetic

    @property
    def strain(self) -> float:
        self._settle()
        return self._strain

    @property
    def potential(self) -> float:
        self._settle()
        return self._potential

    @property
    def total_dissipated(self) -> float:
        """Energy taken out of the string: the damping's, minus the net work of the laws."""
        return self.dissipated["damping"] - sum(self.work_by_law.values())

    @property
    def balance_error(self) -> float:
        """|E - E0 - W + D| relative to the largest energy exchanged or held."""
        residual = self.energy - self.initial_energy - self.input_work + self.total_dissipated
        scale = max(abs(self.input_work), self.total_dissipated, self._scale, 1e-30)  # _scale is settled now
        return abs(residual) / scale

    def summary(self) -> dict:
        return {
            "input_work": self.input_work,
            "kinetic": self.kinetic,
            "strain": self.strain,
            "potential": self.potential,
            "energy_change": self.energy - self.initial_energy,
            "dissipated": self.total_dissipated,
            "dissipated_by": {"damping": self.dissipated["damping"], **{k: -w for k, w in self.work_by_law.items()}},
            "work_by_law": dict(self.work_by_law),
            "injected_by": {k: w for k, w in self.work_by_law.items() if w > 0},
            "balance_error": self.balance_error,
        }
