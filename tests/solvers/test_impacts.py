"""Wall impacts: contact onsets of vertices that had moved clear of the wall (solvers/impacts.py)."""

from types import SimpleNamespace

import numpy as np
from fenics_drill.solvers.impacts import IMPACT_CLEARANCE, ImpactCounter
from tests.conftest import scene_with

GAP = 0.015


def wall_at(delta, vertices):
    """What the counter reads of a wall evaluation: the evaluated vertices and their indentations."""
    return SimpleNamespace(vertices=np.asarray(vertices), delta=np.asarray(delta, dtype=float))


def test_a_contact_counts_as_an_impact_only_after_the_vertex_moved_clear_of_the_wall():
    clearance = IMPACT_CLEARANCE * GAP
    counter = ImpactCounter(4, GAP)
    # vertex 0 rests on the wall, 1 is near it, 2 is clear of it, 3 is far (left out of the evaluation)
    every = np.arange(3)
    counter.start(wall_at([1e-8, -0.5 * clearance, -0.01], every))
    # 0 flickers off by nanometres and back, 1 touches from within the clearance, 2 lands: one impact
    counter.step(wall_at([-2e-9, -0.5 * clearance, -0.001], every))
    landed = counter.step(wall_at([1e-8, 1e-8, 1e-8], every))
    assert landed.tolist() == [2]
    # 2 bounces by more than the clearance and lands again: a second impact; 0 flickers again: none
    counter.step(wall_at([-2e-9, 1e-8, -2 * clearance], every))
    again = counter.step(wall_at([1e-8, 1e-8, 1e-8], every))
    assert again.tolist() == [2]
    # the wall's culled set changes: 3 comes in from far away and lands, an impact
    near = np.arange(4)
    counter.step(wall_at([1e-8, 1e-8, 1e-8, -0.004], near))
    arrived = counter.step(wall_at([1e-8, 1e-8, 1e-8, 1e-9], near))
    assert arrived.tolist() == [3]
    assert counter.per_vertex.tolist() == [0, 0, 2, 1]


def test_a_vertex_left_out_by_the_culling_has_moved_clear_and_its_next_contact_is_an_impact():
    """The wall leaves out the vertices farther than half the gap (WallContact.NEAR): one that drops out of the
    evaluated set after a contact has left the wall by far more than the clearance."""
    counter = ImpactCounter(2, GAP)
    counter.start(wall_at([1e-8, 1e-8], [0, 1]))
    counter.step(wall_at([1e-8], [0]))  # vertex 1 flew off and is left out
    back = counter.step(wall_at([1e-8, 1e-8], [0, 1]))
    assert back.tolist() == [1]


def test_a_thin_string_resting_on_the_wall_flickers_at_its_contact_edges_without_impacts():
    """A 20 m string of thin pipe (60/45 mm in an 80 mm borehole) lies on the wall at a few vertices. As it
    starts drilling, the edges of its contact zones leave the wall and touch it again: 8 contact onsets in
    0.6 s (measured; 10 in 0.3 s before the start-up was resolved, time.start_up_share, and 80 before the basis
    carried the wall friction's static response, docs/verification.md). The vertices lift by less than 0.1 um, the scale of the wall springs' indentation
    (k_FS1 = 1e10 N/m under hundreds of newtons), far below the clearance of 1e-3 of the gap (20 um): no impacts."""
    from fenics_drill.solvers.time_loop import Simulation
    from fenics_drill.studies.prepare import prepare

    scene = scene_with("beam.length=20.0", "beam.elements=40", "beam.outer_radius=0.06", "beam.inner_radius=0.045",
                       "borehole.radius=0.08")
    prepared = prepare(scene)
    model = prepared.model
    simulation = Simulation(model, scene, energy_budget=False)
    v_rows, w_rows = model.lateral_rows
    onsets, lifts = [0], []
    separation = {}

    def on_step(record):
        radius = np.hypot(v_rows @ record.state.q, w_rows @ record.state.q)
        clear = model.gap - radius  # > 0: away from the wall
        if separation:
            started = record.in_contact & ~separation["contact"]
            onsets[0] += int(np.count_nonzero(started))
            lifts.extend(separation["largest"][started].tolist())
            largest = np.maximum(separation["largest"], clear)
        else:
            largest = clear
        separation["largest"] = np.where(record.in_contact, 0.0, largest)
        separation["contact"] = record.in_contact.copy()

    simulation.run(simulation.initial_state(prepared.equilibrium.q), 0.6, on_step=on_step)
    assert onsets[0] > 4  # the flicker is there (measured 8), or this tests nothing
    # how far the flickering vertices left the wall: measured at most 6.6e-8 m; 5e-7 m bounds it with room and
    # stays forty times below the clearance
    assert max(lifts) < 5e-7 < IMPACT_CLEARANCE * model.gap / 40
    assert simulation.impacts_per_vertex.sum() == 0


def test_a_full_order_string_resting_on_the_wall_is_not_lifted_off_it_by_newtons_stopping_test():
    """A 193 m string of light pipe (107/79 mm, 130 N per vertex) in a 153 mm hole lies on the wall over 444
    vertices and drills at 36 m/h and 69 rpm.  Its full order (4347 unknowns) stays on the wall, as does the
    same run with a tenfold tighter time.error_tolerance, and the reduced model (docs/verification.md,
    "Newton's stopping test and the wall").  When Newton took iterates whose next update moved the surface by
    up to 1e-8 m (the modal spaces' SETTLED_SHARE, solvers/newmark.py) or 1e-9 m, each vertex on the wall
    springs (1e10 N/m) kept a force error of up to 100 N or 10 N: the string lifted off the wall from 0.14 s on
    (866 impacts in 0.25 s at 1e-9 m, 33410 in 1 s at 1e-8 m).  The full space stops at 1e-10 m
    (SETTLED_SHARE_FULL)."""
    from fenics_drill.solvers.time_loop import Simulation
    from fenics_drill.studies.prepare import prepare

    scene = scene_with("beam.length=193.19", "beam.elements=483", "beam.outer_radius=0.0536598",
                       "beam.inner_radius=0.0394553", "borehole.radius=0.0764319", "drive.axial_velocity=0.0100389393",
                       "drive.rotation_speed=7.21530891", "bit_rock.limit_force=32945.5", "bit_rock.rate=223.701",
                       "bit_rock.friction=0.3469", "reduction.rule='none'")
    prepared = prepare(scene)
    simulation = Simulation(prepared.model, scene, energy_budget=False)
    contact = []
    simulation.run(simulation.initial_state(prepared.equilibrium.q), 0.25,
                   on_step=lambda record: contact.append(int(record.in_contact.sum())))
    assert contact[0] > 400  # it starts on the wall
    # it stays there: the edges of the contact zones may flicker by a few vertices, the string does not lift
    # (with the stop at 1e-9 m the contact fell to 291 vertices within 0.25 s)
    assert min(contact) >= contact[0] - 5
    assert simulation.impacts_per_vertex.sum() == 0
