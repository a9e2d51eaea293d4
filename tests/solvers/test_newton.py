"""Newton's line search across a kink of a force law (the bit-rock law (20) at u_dot_bit = 0)."""

import numpy as np
import pytest

from fenics_drill.model.forces.bit_rock import KINK_PAST, step_past_kink
from fenics_drill.model.reduction.spaces import ModalSpace
from fenics_drill.solvers.newton import saddle_newton

#: r(y) = y + K max(y, 0) - b: a unit spring, and a stiff one that acts only for y > 0 (as F_BR acts only
#: for u_dot_bit > 0); its root is y* = b / (1 + K).
STIFF, LOAD = 1e4, 1.0


class Kinked:
    def __init__(self, y):
        self.residual = np.array([y[0] + STIFF * max(y[0], 0.0) - LOAD])
        self.tangent = np.array([[1.0 + (STIFF if y[0] > 0 else 0.0)]])
        self.y = y[0]


def solve(with_kink: bool):
    evaluations = []

    def evaluate(y, mu):
        evaluations.append(y[0])
        return Kinked(y)

    def check(iteration, y, mu, ev, norm, gap):
        return (y[0], iteration) if norm <= 1e-12 * LOAD else None

    def kink_step(ev, dy):
        return step_past_kink(ev.y, dy[0])

    y0 = np.array([-1.0])
    result = saddle_newton(evaluate, ModalSpace(np.eye(1)), np.zeros((0, 1)), np.zeros(0), y0, np.zeros(0),
                           Kinked(y0), check, 40, kink_step=kink_step if with_kink else None)
    return result, len(evaluations)


def test_the_line_search_tries_the_step_just_past_a_kink_and_then_converges_on_the_new_branch():
    (root, updates), evaluations = solve(with_kink=True)
    # Newton stops at |r| <= 1e-12 b; on the stiff branch r' = 1 + K, so |y - y*| <= 1e-12 b / (1 + K),
    # i.e. 1e-12 of y* = b / (1 + K): the tolerance is the residual's own
    assert root == pytest.approx(LOAD / (1 + STIFF), rel=1e-12)
    # from y = -1 the unit spring's update overshoots to y = b, the kink trial lands just past y = 0, and
    # the next update on the stiff branch (linear) is exact: converged at the third check, after three trials
    assert updates == 3 and evaluations == 3
    # halving alone creeps towards the kink with the soft side's tangent: from y = 0 all six halvings fail
    # (the last lands at y = 1/32, on the stiff side), and only then does the stiff branch's tangent take it
    # to the root: three times the evaluations
    (plain_root, plain_updates), plain_evaluations = solve(with_kink=False)
    # the same stopping test |r| <= 1e-12 b on the stiff branch (r' = 1 + K): within 1e-12 of y*, as above
    assert plain_root == pytest.approx(LOAD / (1 + STIFF), rel=1e-12)
    assert plain_evaluations == 9 and plain_updates == 4


def test_when_every_halving_fails_newton_goes_on_from_the_last_point_it_evaluated():
    """After HALVINGS failed trials the iterate is the last trial's point, whose residual and tangent the next
    update uses (not a further halved point that was never evaluated)."""
    points = [0.0]  # the initial point, evaluated by the caller

    def evaluate(y, mu):
        points.append(y[0])
        return Kinked(y)

    def check(iteration, y, mu, ev, norm, gap):
        # each checked iterate is a point Newton evaluated, with that point's residual
        assert y[0] in points and ev.y == y[0]
        return (y[0], iteration) if norm <= 1e-12 * LOAD else None

    y0 = np.array([0.0])
    result = saddle_newton(evaluate, ModalSpace(np.eye(1)), np.zeros((0, 1)), np.zeros(0), y0, np.zeros(0),
                           Kinked(y0), check, 40)
    # from y = 0 the six halvings of the soft side's update all fail; the stiff side's tangent at the last
    # one (y = 1/32) then gives the root, which the consistent iterate reaches
    assert result is not None and 1.0 / 32.0 in points


@pytest.mark.parametrize("value, change", [(-1.0, 3.0), (2.0, -2.5), (1e-6, -1.0), (-6.5e-19, 2e-5), (0.0, 1.0)])
def test_the_kink_step_lands_just_past_zero_on_the_far_side(value, change):
    """Also from an iterate on the kink itself (the bit's velocity of a stalled start-up step, -6.5e-19 m/s
    after round-off, with an update of 2e-5 m/s; or exactly zero)."""
    s = step_past_kink(value, change)
    landed = value + s * change
    assert np.sign(landed) == np.sign(change)
    # landed = KINK_PAST change exactly in real arithmetic; value + s change cancels to 1e-6 of the change,
    # so the round-off of that sum (1e-16 of |value| <= |change|) is at most 1e-10 of the result: 1e-9
    # holds it with margin
    assert abs(landed) == pytest.approx(KINK_PAST * abs(change), rel=1e-9)


@pytest.mark.parametrize("value, change", [(1.0, 2.0), (-1.0, 0.5), (1.0, 0.0)])
def test_no_kink_step_where_the_update_does_not_cross_zero(value, change):
    assert step_past_kink(value, change) is None


def test_a_kept_tangent_starts_newton_and_one_that_contracts_too_slowly_is_replaced():
    """``kept`` (solvers/newton.py): the first update takes the tangent of an earlier solve, and the rate test
    judges it like any kept tangent.  On r(y) = y + y^3 - 1 (root y* = 0.6823278...), from y = 0.7: a tangent
    close to r'(y*) = 2.397 shrinks |r| by 0.014, then 0.0016, per update and is kept to the end; one of
    r'(0) = 1 (a different system) overshoots (|r| grows by 1.4), the line search halves the update, and a
    halved update has the fresh tangent taken at the next iterate.  Both converge to the same root."""
    from fenics_drill.solvers.newton import KeptTangent

    class Cubic:
        def __init__(self, y):
            self.residual = np.array([y[0] + y[0] ** 3 - 1.0])
            self.y = y[0]

        @property
        def tangent(self):
            fresh.append(self.y)
            return np.array([[1.0 + 3.0 * self.y**2]])

    def check(iteration, y, mu, ev, norm, gap):
        return y[0] if norm <= 1e-13 else None

    root = 0.6823278038280193  # the real root of y^3 + y - 1 (Cardano)
    for slope, replaced in ((2.4, False), (1.0, True)):
        fresh = []
        kept = KeptTangent(np.array([[slope]]))
        y0 = np.array([0.7])
        result = saddle_newton(lambda y, mu: Cubic(y), ModalSpace(np.eye(1)), np.zeros((0, 1)), np.zeros(0), y0,
                               np.zeros(0), Cubic(y0), check, 40, reuse_rate=0.1, kept=kept)
        # |r| <= 1e-13 with r' ~ 2.4 near the root: within 1e-13 of it
        assert result == pytest.approx(root, abs=1e-13)
        assert bool(fresh) == replaced
        # what the solve leaves for the next one: the tangent it used last
        assert kept.matrix[0, 0] == (1.0 + 3.0 * fresh[-1] ** 2 if replaced else slope)


def test_a_runs_summary_counts_every_banded_factorisation_of_its_steps(tmp_path, monkeypatch):
    """The summary's ``factorisations`` (the speed table's factorisations per simulated second) is the number of
    LAPACK banded LUs of the saddle matrix (76) the time loop made: each call counted where LAPACK is called."""
    import scipy.linalg.lapack as lapack

    import fenics_drill.model.kernels.banded_saddle as banded_saddle
    from fenics_drill.scene import load_scene
    from fenics_drill.solvers.time_loop import Simulation
    from fenics_drill.studies.run import run_scene

    calls, real_lu, real_run = [], lapack.dgbtrf, Simulation.run

    def counted_lu(*args, **kwargs):
        calls.append(1)
        return real_lu(*args, **kwargs)

    def counted_run(self, *args, **kwargs):
        calls.clear()  # the static state's factorisations are not the loop's
        return real_run(self, *args, **kwargs)

    monkeypatch.setattr(banded_saddle.lapack, "dgbtrf", counted_lu)
    monkeypatch.setattr(Simulation, "run", counted_run)
    scene = load_scene(None, ["reduction.rule=none", "beam.elements=60", "time.t_end=0.02",
                              "output.field_interval=0"])
    summary = run_scene(scene, tmp_path / "run", progress=False)
    assert summary["steps"] > 0
    assert summary["factorisations"] == len(calls) > 0
    # a kept tangent is solved again without a new LU: fewer factorisations than Newton iterations
    assert summary["factorisations"] < summary["newton_iterations"]


class CurvedValley:
    """r(y) = (S (y1 - y2^2), y2 - 1): a stiff row S along a curved valley, root (1, 1).  From (0, 0.1) the full
    Newton update lands on y2 = 1 exactly (the second row is linear) but raises |r| from 1e4 to 8.1e5: the
    residual's 2-norm, dominated by the stiff row, rejects the update that the Newton correction J(y0)^-1 r (the
    natural level, Deuflhard 2004, Sec. 3.3) measures as 0.88 of the update's."""

    STIFF = 1e6

    def __init__(self, y):
        self.y = y.copy()
        self.residual = np.array([self.STIFF * (y[0] - y[1] ** 2), y[1] - 1.0])
        self.tangent = np.array([[self.STIFF, -2.0 * self.STIFF * y[1]], [0.0, 1.0]])


def test_a_full_update_that_raises_the_residual_of_a_stiff_row_is_taken_by_its_natural_level():
    points = []

    def evaluate(y, mu):
        points.append(y.copy())
        return CurvedValley(y)

    def check(iteration, y, mu, ev, norm, gap):
        return (y.copy(), iteration) if norm <= 1e-9 else None

    y0 = np.array([0.0, 0.1])
    result = saddle_newton(evaluate, ModalSpace(np.eye(2)), np.zeros((0, 2)), np.zeros(0), y0, np.zeros(0),
                           CurvedValley(y0), check, 20)
    assert result is not None
    (y, iterations) = result
    # 1e-9: check() stops at |r| <= 1e-9, which bounds |y2 - 1| by 1e-9 (its row has unit slope) and |y1 - y2^2|
    # by 1e-15 (the stiff row)
    assert np.allclose(y, [1.0, 1.0], atol=1e-9)
    first = points[0]  # the first trial: the full update, to (0.19, 1) in exact arithmetic
    # 1e-12: the update is one 2 x 2 solve of entries up to 2e5; its round-off is ~1e-16 relative
    assert first == pytest.approx([0.19, 1.0], abs=1e-12)
    assert np.linalg.norm(CurvedValley(first).residual) > 50 * np.linalg.norm(CurvedValley(y0).residual)
    # taken: the next trial starts from it (the second row is linear, so every later update keeps y2 = 1 up to the
    # same round-off as above), and Newton ends in a few updates
    assert all(p[1] == pytest.approx(1.0, abs=1e-12) for p in points[1:])
    assert iterations <= 4
