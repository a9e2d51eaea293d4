"""A new force law added by the three steps of docs/architecture.md (here: a linear spring on u at the
bit) is taken by the model, its tangent and the energy budget without any other change."""

from typing import ClassVar

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import scene_with

from fenics_drill.model import forces
from fenics_drill.model.discretization import U
from fenics_drill.model.drillstring import build_model
from fenics_drill.model.forces.protocol import ForceEvaluation
from fenics_drill.solvers.time_loop import Simulation


class TipSpring:
    """f = -k u(L) on the axial dof at the bit; potential k u(L)^2 / 2."""

    name: ClassVar[str] = "tip_spring"
    switch: ClassVar[str] = "bit_rock"  # reuses an existing [model] switch: the test adds no scene section
    conservative: ClassVar[bool] = True
    recorded: ClassVar[dict] = {}

    def __init__(self, row, stiffness):
        self.row, self.k = row, stiffness

    @classmethod
    def from_scene(cls, scene, disc, space, operators):
        p = scene.beam_properties
        return cls(space.point_rows([disc.end_dof(U, 1)]), p.young_modulus * p.section.area / p.length)

    def evaluate(self, q, qd, with_tangent=False):
        u = self.row.values(q)
        return ForceEvaluation(self.row.spread(-self.k * u), 0.5 * self.k * float(u @ u), {})

    def tangent(self, evaluation, c_u, c_v):
        return self.row.block(np.array([[-c_u * self.k]]))

    def record(self, evaluation):
        return {}


@pytest.fixture
def spring_model(monkeypatch):
    monkeypatch.setattr(forces, "FORCES", (forces.Gravity, forces.WallContact, TipSpring))
    scene = scene_with("beam.length=10.0", "beam.elements=40", "reduction.rule='none'", "model.gravity=false",
                       "model.contact=false", "model.bit_rock=true", "model.geometric_nonlinearity=false",
                       "model.inertial_nonlinearity=false", "beam.damping=0.0", "time.newmark_alpha=0.0",
                       "time.adaptive=false", "drive.axial_velocity=0.0", "drive.rotation_speed=0.0")
    return scene, build_model(scene)


def test_the_spring_sets_the_axial_frequency_of_a_bar_fixed_at_one_end(spring_model):
    """Bar held at x = 0 (the drive), spring k = EA/L at x = L: tan(beta L) = -beta L, beta L = 2.02876;
    f = beta L c_L / (2 pi L).  The tangent of the model (stiffness + spring) and its mass give it."""
    scene, model = spring_model
    assert [f.name for f in model.forces] == ["tip_spring"]
    zero = np.zeros(model.size)
    K = model.evaluate(zero, zero, zero, np.zeros(2), (1.0, 0.0, 0.0)).tangent.toarray()
    M = model.mass.toarray()
    null = sla.null_space(model.constraints)  # u(0) = theta_x(0) = 0
    eigenvalues, vectors = sla.eigh(null.T @ K @ null, null.T @ M @ null)
    modes = null @ vectors
    axial_dofs = model.space.project(np.isin(np.arange(model.disc.ndofs), model.disc.field_dofs[U]).astype(float))
    share = np.einsum("ij,ij->j", modes * axial_dofs[:, None], M @ modes) / np.einsum("ij,ij->j", modes, M @ modes)
    omega = np.sqrt(eigenvalues[share > 0.99].min())
    p = model.disc.properties
    exact = 2.028757838110434 * p.longitudinal_wave_speed / p.length
    # P1 bar on 40 elements: the discrete frequency is high by ~(beta h)^2 / 24 = 1e-4
    assert omega == pytest.approx(exact, rel=5e-4)


def test_the_budget_books_the_spring_potential_and_the_energy_is_conserved(spring_model):
    """No damping, alpha = 0 (energy-conserving average acceleration), linear: E(t) = E(0), where E
    holds the spring's potential; the tangent is exact, so Newton converges in one iteration."""
    scene, model = spring_model
    simulation = Simulation(model, scene)
    q0 = np.zeros(model.size)
    start = simulation.initial_state(q0)
    tip = model.space.rows([model.disc.end_dof(U, 1)])
    start.qd = 0.1 * tip.toarray().ravel()  # the bit moves at 0.1 m/s (the full space's rows are sparse)
    start.qdd, start.mu = simulation.stepper.initial_acceleration(q0, start.qd)
    simulation.run(start, 5e-3)
    budget = simulation.budget
    assert budget.potential > 0  # the spring was stretched and its energy is in the budget
    # the average-acceleration rule conserves the quadratic energy of a linear system exactly, and the
    # trapezoidal work of the budget is exact for it: only round-off remains (3e-16 measured)
    assert budget.balance_error < 1e-12, budget.summary()
    assert simulation.stats["newton_iterations"] <= 2 * simulation.stats["steps"]
