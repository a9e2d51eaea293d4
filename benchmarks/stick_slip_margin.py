"""How much damping the VBH well's stick-slip survives: benchmarks/results/stick_slip_margin.md.

    python benchmarks/stick_slip_margin.py

One point of the VBH well's map (demos/scenes/well_vbh.toml with the settings of ``make well-maps``, the stiff drive,
20 kN and 120 rpm) run to its limit cycle or 200 s by :func:`~fenics_drill.studies.stick_slip.limit_cycle`: at the
default step and at half of it, on 10 m and 5 m elements, with ``stick_slip_map.mesh_viscosity`` = zeta (damping
ratio zeta h omega / (4 c_T)) and with the string's own damping c of (38) (``beam.damping``, mass-proportional:
c / (2 omega)) raised.  Each row states the damping ratio of both at the string's first torsional mode (held at the
top, free at the bit) and at RIPPLE, the frequency of the small cycle the viscous runs settle on.  Then the string
is stepped 120 s with one zeta and 150 s more from that state with the other, both ways: whether the cycle each
zeta reaches depends on where it starts (two attractors) or not (the steady rotation's stability changes).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.linalg import eigh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

from speed import machine, write_result  # noqa: E402

import fenics_drill as fd  # noqa: E402
from fenics_drill.model.axial_torsional_string import axial_torsional_string, pressed_for  # noqa: E402
from fenics_drill.studies.stick_slip import limit_cycle, start  # noqa: E402
from fenics_drill.studies.stick_slip_map import map_scene, point_scene  # noqa: E402

SCENE = "demos/scenes/well_vbh.toml"
SETTINGS = ["drive.mode='hook_load'", "bit_rock.law='detournay'", "bit_rock.bit_radius='4.25 in'"]
WEIGHT, RPM = 20e3, 120.0
#: (zeta, element length [m], share of the default step, c of (38) [1/s]) of each run to the limit cycle.
RUNS = ((0.0, 10.0, 1.0, 0.01), (0.0, 10.0, 0.5, 0.01), (0.0, 5.0, 1.0, 0.01), (0.0, 10.0, 1.0, 0.03),
        (0.25, 10.0, 1.0, 0.01), (1.0, 10.0, 1.0, 0.01))
#: The small cycle's frequency with the viscosity, 1 / 0.175 s [Hz].
RIPPLE = 5.72
#: Spin below which the bit counts as stuck in the switched runs [rad/s] (the map's own threshold is its cycle's).
STUCK_SPIN = 0.1


def point(zeta: float, element_length: float = 10.0, damping: float = 0.01):
    scene = map_scene(fd.load_scene(ROOT / SCENE, [*SETTINGS, f"stick_slip_map.mesh_viscosity={zeta}",
                                                   f"stick_slip_map.element_length={element_length}",
                                                   f"beam.damping={damping}"]))
    at = point_scene(scene, "stiff", WEIGHT, RPM * math.pi / 30.0)
    return at, pressed_for(axial_torsional_string(scene), at)


def first_torsional_damping_ratio(string) -> tuple[float, float]:
    """(omega_1 [rad/s], the damping ratio of (38) there): the torsional block held at the top, free at the bit."""
    kept = np.flatnonzero(string.angle)
    kept = kept[kept != string.top[1]]
    block = np.ix_(kept, kept)
    mass, damping = string.dense(string.mass)[block], string.dense(string.damping)[block]
    values, vectors = eigh(string.dense(string.stiffness)[block], mass, subset_by_index=(0, 0))
    mode, omega = vectors[:, 0], math.sqrt(values[0])
    return omega, float(mode @ damping @ mode / (2.0 * omega * (mode @ mass @ mode)))


def last_spins(series: dict, span: float = 30.0) -> str:
    t, spin = series["time"], series["bit_angular_velocity"]
    last = t > t[-1] - span
    return (f"{spin[last].min():.2f} | {spin[last].max():.2f} | "
            f"{np.mean(np.abs(spin[last]) < STUCK_SPIN):.3f}")


def main() -> None:
    rows, switched = [], []
    omega_1, _ = first_torsional_damping_ratio(point(0.0)[1])
    for zeta, length, share, damping in RUNS:
        at, string = point(zeta, length, damping)
        simulation = start(at, string=string)
        if share != 1.0:
            simulation = start(at, string=string, dt=share * simulation.dt)
        clock = time.perf_counter()
        c = limit_cycle(at, 200.0, simulation=simulation)
        period = "-" if c["period_s"] is None else f"{c['period_s']:.3f}"
        ratios = [100 * (damping / (2.0 * omega) + zeta * length * omega / (4.0 * string.torsional_wave_speed_at_top))
                  for omega in (omega_1, 2.0 * math.pi * RIPPLE)]
        rows.append(f"| {zeta:g} | {damping:g} | {ratios[0]:.3f} | {ratios[1]:.3f} | {length:g} | {share:g} | "
                    f"{c['settled']} | {period} | "
                    f"{c['min_bit_spin_rad_s']:.2f} | {c['max_bit_spin_rad_s']:.2f} | {c['stuck_share']:.3f} | "
                    f"{time.perf_counter() - clock:.1f} |")
        print(rows[-1], flush=True)
    for first, then in ((0.0, 0.25), (0.25, 0.0)):
        at, string = point(first)
        before = start(at, string=string)
        spins_before = last_spins(before.run(120.0))
        at, string = point(then)
        after = start(at, string=string)
        after.state, after.drive = before.state, before.drive
        switched.append(f"| {first:g} | {spins_before} | {then:g} | {last_spins(after.run(150.0))} |")
        print(switched[-1], flush=True)
    omega, ratio = first_torsional_damping_ratio(point(0.0)[1])
    assert abs(omega - omega_1) < 1e-12 * omega  # the same string
    lines = ["# How much damping the VBH well's stick-slip survives", "",
             f"Command: `python benchmarks/stick_slip_margin.py`. Machine: {machine()}; one process. {SCENE} with the "
             f"settings of `make well-maps`, the stiff drive, {WEIGHT / 1e3:g} kN and {RPM:g} rpm; each run to its "
             "limit cycle or 200 s. zeta: `stick_slip_map.mesh_viscosity`; c: `beam.damping`, (38); the damping "
             "ratio of both together at the first torsional mode (held at the top, free at the bit: "
             f"{omega:.3f} rad/s, where (38) alone gives {100 * ratio:.3f} % of critical from the string's matrices) "
             f"and at {RIPPLE:g} Hz, the small cycle the viscous runs settle on; step: the share of the default step.",
             "",
             "| zeta | c [1/s] | damping at the first mode [%] | at the small cycle [%] | element [m] | step | "
             "settled | cycle [s] | slowest spin [rad/s] | fastest spin [rad/s] | stuck share | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|", *rows, "",
             f"Stepped 120 s with one zeta, then 150 s more from that state with the other (the bit's spin over the "
             f"last 30 s of each; stuck: below {STUCK_SPIN:g} rad/s):", "",
             "| zeta first | slowest spin [rad/s] | fastest spin [rad/s] | stuck share | zeta then | slowest spin "
             "[rad/s] | fastest spin [rad/s] | stuck share |", "|---|---|---|---|---|---|---|---|", *switched]
    write_result("stick_slip_margin.md", lines)


if __name__ == "__main__":
    main()
