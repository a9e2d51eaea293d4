"""Static equilibrium under gravity with wall contact (Section 6.4).

The paper reaches it by integrating the dynamics from rest with V0 = Omega = 0;
here Newton solves  f_int(q, 0, 0) = f_G + f_FS(q, 0)  with u(0) = theta_x(0) = 0
directly, in the same solution space as the dynamics so that the drilling run
starts from an equilibrium of its own model.  Each Newton update is limited so
that no vertex moves laterally by more than a quarter of the gap: from the
straight string the linear sag is orders of magnitude larger than the gap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fenics_drill.model.discretization import U, V, W
from fenics_drill.model.drillstring import DrillstringModel
from fenics_drill.model.soft_string import Operation, soft_string, string_mesh
from fenics_drill.model.well import string_in_well
from fenics_drill.solvers.newton import saddle_newton

#: Contact stiffness continuation: the wall springs are scaled by 10^s, s rising from FIRST_STAGE to 0 in steps
#: of STAGE_STEP decades, each stage starting from the previous equilibrium.  A soft wall lets the string
#: settle onto it smoothly; stiffening then moves it by amounts Newton handles well.  A stage whose Newton does
#: not converge within STAGE_ITERATIONS (the last, with the real wall: the solve's ``max_iterations``) is
#: tried again from the last equilibrium with half the step, down to SMALLEST_STAGE_STEP (a long string on a
#: stiff wall); after a success the step doubles again, up to STAGE_STEP.
FIRST_STAGE = -4.0
STAGE_STEP = 1.0
SMALLEST_STAGE_STEP = 1.0 / 64
STAGE_ITERATIONS = 40

#: Largest lateral move of any vertex per Newton update, as a fraction of the gap.
STEP_LIMIT = 0.25

#: Newton on the kink of the wall law (17) at zero indentation can cycle between contact sets
#: when hundreds of vertices rest on the wall (a 1000 m string).  If the relative residual has
#: not halved for STALL_ITERATIONS iterations and is below STALL_TOLERANCE (1e-6 of the weight:
#: about 1 N for a 1000 m string), the best iterate is taken; the report gives its residual.
STALL_TOLERANCE = 1e-6
STALL_ITERATIONS = 20


class StaticFailure(RuntimeError):
    """Newton found no equilibrium within the allowed iterations."""


@dataclass
class StaticEquilibrium:
    q: np.ndarray
    mu: np.ndarray
    iterations: int
    residual: float  # relative


def solve_static(model: DrillstringModel, tolerance: float = 1e-8, max_iterations: int = 200,
                 initial: np.ndarray | None = None) -> StaticEquilibrium:
    """Equilibrium of the string at rest (velocities zero, so no friction and no bit-rock force).

    From the straight string with wall contact, the wall springs are stiffened stage by stage
    (:data:`FIRST_STAGE`, :data:`STAGE_STEP`) on copies of the model; the model itself is left as it was.  On a
    well, first one Newton solve with the real wall from :func:`resting_guess`; where that fails for a string whose bit
    is pressed (an axial tip load), the load raised in steps from the string resting off bottom
    (:func:`_pressed_by_steps`).  From an ``initial`` guess near the equilibrium (the full-order state projected on a
    reduced basis), one Newton solve with the real wall."""
    model = model.at_rest()  # both drive dofs held, whatever drives the run
    wall = model.force("wall")
    q, mu = (np.zeros(model.size) if initial is None else initial), np.zeros(2)
    if wall is None or initial is not None:
        return _newton(model, q, mu, tolerance, max_iterations)
    resting = resting_guess(model)
    if resting is not None:  # a well: from the string the soft-string model lays on the wall, the real wall at once
        try:
            return _newton(model, resting, mu, tolerance, max_iterations)
        except StaticFailure:  # (a string the soft string leaves near the axis): the stages from the straight one
            pass
    pressed = model.force("axial_tip_load")
    if pressed is not None and pressed.force != 0.0:  # on bottom: from the string resting off bottom, pressed in steps
        return _pressed_by_steps(model, pressed, tolerance, max_iterations)
    return _staged(model, wall, q, mu, tolerance, max_iterations)


#: The weight on bit of a string on bottom is raised in steps of at most this share of it from the string resting off
#: bottom when the solve at the whole weight fails; a step whose Newton fails within LOAD_STEP_ITERATIONS is halved,
#: down to SMALLEST_LOAD_STEP of the weight.
LOAD_STEP, SMALLEST_LOAD_STEP, LOAD_STEP_ITERATIONS = 1.0 / 8, 1.0 / 1024, 60


class LoadNotCarried(StaticFailure):
    """The weight on bit raised in steps found equilibria up to ``reached`` [N] of ``force`` [N], and none beyond: a
    limit of the static path (a string that snaps into a helix in its hole)."""

    def __init__(self, message: str, reached: float, force: float):
        super().__init__(message)
        self.reached, self.force = reached, force


def _pressed_by_steps(model: DrillstringModel, pressed, tolerance: float, max_iterations: int) -> StaticEquilibrium:
    """The equilibrium with the bit pressed by ``pressed.force``, reached from the string resting off bottom by
    raising the load in steps (:data:`LOAD_STEP`), each from the last equilibrium; LoadNotCarried names the largest
    load carried where the steps stall."""
    def at(force: float) -> DrillstringModel:
        return model.with_force(type(pressed)(model.disc, model.space, force))

    eq = solve_static(at(0.0))
    reached, step, total = 0.0, LOAD_STEP * pressed.force, eq.iterations
    while reached < pressed.force:
        trial = min(reached + step, pressed.force)
        try:
            eq = _newton(at(trial), eq.q, eq.mu, tolerance,
                         max_iterations if trial == pressed.force else LOAD_STEP_ITERATIONS)
        except StaticFailure:
            step *= 0.5
            if step < SMALLEST_LOAD_STEP * pressed.force:
                raise LoadNotCarried(f"static equilibrium not found with the bit pressed at {pressed.force / 1e3:.4g} "
                                     f"kN: raised in steps from off bottom, the string rests in equilibrium up to "
                                     f"{reached / 1e3:.4g} kN and none is found beyond", reached, pressed.force) from None
            continue
        reached, total, step = trial, total + eq.iterations, min(2.0 * step, LOAD_STEP * pressed.force)
    return StaticEquilibrium(eq.q, eq.mu, total, eq.residual)


def resting_guess(model: DrillstringModel) -> np.ndarray | None:
    """Where the full-order Newton starts on a well: the string laid against the wall where the soft-string model
    at rest (:func:`~fenics_drill.model.soft_string.soft_string`, no friction) says the wall carries it, on the
    side its wall force comes from, RESTING_PENETRATION of the clearance into the wall (its springs act from the
    first iterate); stretched by that model's tension.  From the straight string a long well's first updates sag
    it by kilometres and the move limit lets it creep.  Between the pressed lengths it runs straight from one to the
    next.  None for the straight horizontal hole or a modal space."""
    disc, scene = model.disc, model.scene
    if disc.trajectory is None or not model.space.sparse:
        return None
    resolved = string_in_well(scene)
    sections, well = resolved.sections, resolved.well
    g = scene.environment.gravity if scene.model.gravity else 0.0
    weights = [s.buoyed_weight(g, scene.fluid.density, scene.inner_fluid_density) for s in sections]
    mesh = string_mesh(well, sections, float(np.diff(disc.vertex_x).min()), weights, 0.0, 0.0)
    pressed = model.force("axial_tip_load")  # a string on bottom: the bit pressed with the weight on bit
    rest = soft_string(mesh, Operation("at rest", 0.0, 0.0, -pressed.force if pressed is not None else 0.0, 0.0))
    dofs = np.zeros(disc.ndofs)
    element = lambda x: np.clip(np.searchsorted(mesh.md, x) - 1, 0, mesh.md.size - 2)  # noqa: E731
    for field, axis in ((V, "d2"), (W, "d3")):
        at = disc.field_dofs[field]
        x = disc.dof_coordinates[at]
        k = element(x)
        pressed = rest["wall_force_per_length"][k] > RESTING_SHARE * mesh.weight[k]
        toward = -np.einsum("ij,ij->i", rest["wall_force_direction"][k], getattr(disc.trajectory.bishop_frames(x), axis))
        gap = (1.0 + RESTING_PENETRATION) * np.interp(x, disc.vertex_x, model.vertex_gap)
        # between the pressed lengths (and from the top, held on the axis) the string runs straight from one to the
        # next: a step from the axis onto the wall within one element would be a shear strain of gap / element
        order = np.argsort(x)
        on_wall = order[pressed[order]]
        dofs[at] = np.interp(x, np.concatenate([[0.0], x[on_wall]]), np.concatenate([[0.0], (gap * toward)[on_wall]]))
    at = disc.field_dofs[U]
    x = disc.dof_coordinates[at]
    p = disc.element_properties
    strain = 0.5 * (rest["tension"][1:] + rest["tension"][:-1]) / np.interp(
        0.5 * (mesh.md[1:] + mesh.md[:-1]), 0.5 * (disc.vertex_x[1:] + disc.vertex_x[:-1]),
        np.broadcast_to(p.young_modulus * p.section.area, (disc.vertex_x.size - 1,)))
    dofs[at] = np.interp(x, mesh.md, np.concatenate([[0.0], np.cumsum(strain * np.diff(mesh.md))]))
    return model.space.project(dofs)


#: :func:`resting_guess` lays the string on the wall where the wall carries more than this share of its weight per
#: length, that share of the clearance into the wall.
RESTING_SHARE, RESTING_PENETRATION = 0.05, 1e-4


def _staged(model: DrillstringModel, wall, q, mu, tolerance: float, max_iterations: int) -> StaticEquilibrium:
    """The wall springs stiffened stage by stage from 10^FIRST_STAGE (:data:`STAGE_STEP`) to the real wall."""
    exponent, step, iterations = FIRST_STAGE, STAGE_STEP, 0
    # the first stage may take all the iterations it is allowed
    eq = _newton(model.with_force(wall.with_stiffness_scale(10.0 ** exponent)), q, mu, 1e-6, max_iterations)
    while True:
        q, mu, iterations = eq.q, eq.mu, iterations + eq.iterations
        if exponent == 0.0:
            return StaticEquilibrium(q, mu, iterations, eq.residual)
        while True:
            trial = min(exponent + step, 0.0)
            stage = model.with_force(wall.with_stiffness_scale(10.0 ** trial))
            try:
                eq = _newton(stage, q, mu, 1e-6, STAGE_ITERATIONS) if trial < 0.0 else \
                    _newton(stage, q, mu, tolerance, max_iterations)
                break
            except StaticFailure:
                step *= 0.5
                if step < SMALLEST_STAGE_STEP:
                    raise
        exponent, step = trial, min(2.0 * step, STAGE_STEP)

def _newton(model: DrillstringModel, q, mu, tolerance: float, max_iterations: int) -> StaticEquilibrium:
    zero = np.zeros(model.size)
    lateral_v, lateral_w = model.lateral_rows
    step_limit = STEP_LIMIT * model.gap if model.force("wall") is not None else np.inf

    def evaluate(q, mu):
        return model.evaluate(q, zero, zero, mu, tangent_coefficients=(1.0, 0.0, 0.0))

    best = [np.inf, q, mu, 0]  # relative residual, q, mu, iteration of the last halving
    last = [np.inf]

    def check(iteration, q, mu, ev, norm, gap):
        scale = max(np.linalg.norm(ev.internal), np.linalg.norm(ev.external), 1e-30)
        relative = last[0] = norm / scale
        if relative <= tolerance and np.all(np.abs(gap) <= tolerance):
            return StaticEquilibrium(q, mu, iteration, relative)
        if relative <= 0.5 * best[0]:
            best[:] = [relative, q, mu, iteration]
        elif iteration - best[3] >= STALL_ITERATIONS and best[0] <= STALL_TOLERANCE:
            return StaticEquilibrium(best[1], best[2], iteration, best[0])
        return None

    def first_step(dq):
        move = max(np.max(np.abs(lateral_v @ dq)), np.max(np.abs(lateral_w @ dq)))
        return min(1.0, step_limit / move) if move > 0 else 1.0

    result = saddle_newton(evaluate, model.space, model.constraints, np.zeros(2), q, mu, evaluate(q, mu), check,
                           max_iterations, first_step)
    if result is None:
        raise StaticFailure(f"static equilibrium not found in {max_iterations} Newton iterations "
                            f"(relative residual {last[0]:.2e})")
    return result


def static_report(model: DrillstringModel, eq: StaticEquilibrium) -> dict:
    """max_sag [m], the hook load [N], contact vertices and forces: what ``fenics-drill static`` writes to
    static.json."""
    v, w = (rows @ eq.q for rows in model.lateral_rows)
    x = model.disc.vertex_x
    report = {
        "max_sag": float(np.max(-w)),
        "max_sag_position": float(x[np.argmax(-w)]),
        "max_lateral_displacement": float(np.max(np.hypot(v, w))),
        "gap": model.gap,
        "weight": model.disc.weight,
        # the top holds the string (both drive dofs, :func:`solve_static`): the load it applies along the axis,
        # down-hole > 0, is minus the hook load
        "hook_load": -model.at_rest().drive.applied(eq.mu, None)[0],
        "newton_iterations": eq.iterations,
        "relative_residual": eq.residual,
        "contact_vertices": [],
    }
    wall = model.force("wall")
    if wall is not None:
        forces = wall.evaluate(eq.q, np.zeros_like(eq.q))
        active = forces.in_contact
        report["contact_vertices"] = [float(xi) for xi in x[active]]
        report["contact_force_total"] = float(-np.sum(forces.normal))
        report["max_penetration"] = float(np.max(forces.indentation[active])) if active.any() else 0.0
    return report
