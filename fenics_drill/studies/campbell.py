"""``fenics-drill campbell``: the critical-speed analysis of a scene (DIR/campbell.json, DIR/campbell.png).

1. The steady state: the straight string, or its static equilibrium on the wall under gravity
   (Section 6.4), each under the axial compression of ``campbell.axial_force`` or the weight on bit
   (the bit force (20) at the drive's V0), solved in the full order.
2. One linearisation about it in spin (:mod:`fenics_drill.model.rotating_modes`): M, C, G, K with the
   geometric stiffness of the preload and the linearised wall springs; u(0) and theta_x(0) held by the drive.
3. The lowest ``campbell.modes`` modes at every speed of ``campbell.rotation_speed``, with whirl and kind.
4. The critical speeds: where a branch f_k(Omega) crosses an excitation line f = n Omega / 2 pi.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from fenics_drill.io.files import write_json
from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.forces.bit_rock import bit_rock_force
from fenics_drill.model.forces.wall_contact import WallContact
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.rotating_modes import held_space, linearise_about_spin, solve_whirl_modes
from fenics_drill.studies.lifecycle import command_output
from fenics_drill.studies.operating_state import operating_state, unstable_modes

RPM = 60.0 / (2.0 * math.pi)  # rad/s -> rev/min


class CampbellError(ValueError):
    """A scene the critical-speed analysis cannot linearise."""


def axial_preload(scene) -> float:
    """The compression at the bit [N]: the steady bit force -F_BR(V0) of Eq. (20) with
    ``campbell.weight_on_bit``, otherwise ``campbell.axial_force``."""
    if scene.campbell.weight_on_bit:
        bit = scene.bit_rock
        return -float(bit_rock_force(scene.drive.axial_velocity, bit.limit_force, bit.rate))
    return scene.campbell.axial_force


def critical_speeds(speeds: np.ndarray, frequencies: np.ndarray, whirl: list[list[str]], kinds: list[list[str]],
                    orders) -> list[dict]:
    """Crossings of each branch (column of ``frequencies`` [Hz], rows per speed [rad/s]) with each line
    f = n Omega / 2 pi, by linear interpolation between the speeds that bracket a sign change."""
    found = []
    for order in orders:
        line = order * speeds / (2.0 * math.pi)
        for branch in range(frequencies.shape[1]):
            gap = frequencies[:, branch] - line
            for i in np.flatnonzero(np.sign(gap[:-1]) * np.sign(gap[1:]) < 0):
                share = gap[i] / (gap[i] - gap[i + 1])
                speed = speeds[i] + share * (speeds[i + 1] - speeds[i])
                nearest = i if share < 0.5 else i + 1
                found.append({
                    "order": float(order), "speed_rad_s": float(speed), "speed_rpm": float(speed * RPM),
                    "frequency_hz": float(order * speed / (2.0 * math.pi)), "branch": int(branch),
                    "whirl": whirl[nearest][branch], "kind": kinds[nearest][branch],
                })
    return sorted(found, key=lambda c: c["speed_rad_s"])


def campbell_report(scene) -> dict:
    """The Campbell diagram of a scene as a JSON-ready dict (see the module docstring)."""
    if scene.model.kinematics != "objective":
        raise CampbellError("model.kinematics = 'printed' makes the strain energy change with the spin angle "
                            "(docs/errata.md): the linearised string has a periodic stiffness and no Campbell "
                            "diagram; use model.kinematics = 'objective'")
    start = time.perf_counter()
    cfg = scene.campbell
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    preload = axial_preload(scene)
    steady = operating_state(scene, disc, operators, preload, on_wall=scene.campbell.state == "static")
    buckled = unstable_modes(scene, disc, operators, steady)
    if buckled:  # a buckled string has no critical speed: said, never a diagram of its unstable modes
        first = buckled[0]
        raise CampbellError(f"the string is buckled under {preload / 1e3:.4g} kN of axial compression: {len(buckled)} "
                            f"mode(s) of the drive-held string have no positive stiffness (the first, {first['kind']}, "
                            f"bends most at x = {first['largest_lateral_displacement_at_m']:.4g} m), so it has no "
                            "critical speed; lower campbell.axial_force (or the weight on bit)")
    about = {k: v for k, v in steady.about.items() if k != "weight_on_bit_N"}
    space = held_space(disc)
    wall = [WallContact.from_scene(scene, disc, space, operators)] if steady.on_the_wall else []
    linearisation = linearise_about_spin(disc, operators, scene.model, steady.displacement, space, wall)
    setup = time.perf_counter() - start
    low, high, n = cfg.rotation_speed
    speeds = np.linspace(low, high, int(n))
    sweep = [solve_whirl_modes(disc, linearisation, s, cfg.modes, cfg.damping) for s in speeds]
    frequencies = np.array([m.frequencies_hz for m in sweep])
    whirl = [m.whirl for m in sweep]
    kinds = [m.kinds for m in sweep]
    branches = [
        {"frequency_hz": frequencies[:, k].tolist(), "whirl": [w[k] for w in whirl], "kind": [c[k] for c in kinds],
         "damping_ratio": [float(m.damping_ratios[k]) for m in sweep],
         "whirl_ratio": [float(m.whirl_ratios[k]) for m in sweep]}
        for k in range(cfg.modes)
    ]
    return {
        "rotation_speed_rad_s": speeds.tolist(),
        "rotation_speed_rpm": (speeds * RPM).tolist(),
        "branches": branches,
        "critical_speeds": critical_speeds(speeds, frequencies, whirl, kinds, cfg.excitation_orders),
        "excitation_orders": list(cfg.excitation_orders),
        "axial_force_N": preload,
        "steady_state": about,
        "stabilisers_m": disc.vertex_x[disc.stabiliser_vertices].tolist(),
        "supports": disc.supports,
        "linearisation": {
            "gyroscopic": scene.model.inertial_nonlinearity, "geometric_stiffness": scene.model.geometric_nonlinearity,
            "angular_velocity": scene.model.angular_velocity, "damping": cfg.damping,
            "wall_springs": bool(wall), "held": ["u(0)", "theta_x(0)"],
        },
        "operating_window_rpm": [scene.optimize.rotation_speed[0] * RPM, scene.optimize.rotation_speed[1] * RPM],
        "full_dofs": disc.ndofs,
        "max_relative_residual": max(m.relative_residual for m in sweep),
        "setup_time_s": setup,
        "wall_time_s": time.perf_counter() - start,
    }


def write_campbell(scene, out: str | Path, overwrite: bool = False) -> dict:
    """``fenics-drill campbell``: DIR/campbell.json and DIR/summary.json (the figure: ``fenics-drill plot DIR``)."""
    out = Path(out)
    with command_output(out, "campbell", scene, overwrite) as summary:
        report = campbell_report(scene)
        write_json(out / "campbell.json", report)
        summary["message"] = "campbell.json"
        summary["critical_speeds_rpm"] = [round(c["speed_rpm"], 3) for c in report["critical_speeds"]]
    return report
