"""An independent reference for torsional stick-slip: the string as a torsional wave guide, solved along its
characteristics.

The distributed torsional model of a drill string (the drill pipe and collars as the wave equation
rho I_p theta_tt + c rho I_p theta_t = G J theta_xx, the top turned at a held speed Omega, the bit's torque at its
free end) is what the delay-equation models of the literature reduce to (Balanov et al., Chaos Solitons Fractals 15,
2003; Barton, Krauskopf & Wilson, 2007): on a piecewise-uniform string of one material the angular velocity is
omega = f + g, the internal torque M = G J theta_x = Z (g - f) with the impedance Z = I_p sqrt(G rho), and the
down-going wave f and the up-going g travel one cell of length dx = c_T dt per step dt without changing shape.  Where
two sections meet they split into the transmitted and reflected waves that keep omega and M continuous; the held top
reflects g as f = Omega - g; at the bit M = T_bit(omega), solved by Newton for the bit's spin; the mass-proportional
damping c acts along each characteristic as df/dt = dg/dt = -c (f + g) / 2.  Without damping this is exact at the
grid's points; the damping's step is explicit, with c dt of order 1e-6.

Nothing here uses the finite-element model: only each section's length, G J and rho I_p, the drive's speed and the
bit law's torque scale.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _regularisation(omega):
    """xi(omega) = tanh(omega) + 2 omega / (1 + omega^2), the paper's (22), and its derivative."""
    t = math.tanh(omega)
    return t + 2.0 * omega / (1.0 + omega * omega), 1.0 - t * t + 2.0 * (1.0 - omega * omega) / (1.0 + omega * omega) ** 2


@njit(cache=True)
def _march(impedance, omega_top, damping, dt, steps, stride, torque_scale):
    n = impedance.size
    f = np.full(n, 0.5 * omega_top)  # the string turning at Omega, untwisted: f = g = Omega / 2 in every cell
    g = np.full(n, 0.5 * omega_top)
    f_next, g_next = np.empty(n), np.empty(n)
    out = np.empty((steps // stride + 1, 3))
    out[0, 0], out[0, 1], out[0, 2] = 0.0, omega_top, 0.0
    decay = 0.5 * damping * dt
    spin, row = omega_top, 1
    for step in range(1, steps + 1):
        for k in range(n):
            loss = decay * (f[k] + g[k])
            f[k] -= loss
            g[k] -= loss
        g_top = g[0]
        f_next[0] = omega_top - g_top  # the held top
        for j in range(1, n):  # the node between cell j - 1 (above) and cell j (below)
            above, below = impedance[j - 1], impedance[j]
            reflected = ((above - below) * f[j - 1] + 2.0 * below * g[j]) / (above + below)
            g_next[j - 1] = reflected
            f_next[j] = f[j - 1] + reflected - g[j]
        z, incoming = impedance[n - 1], f[n - 1]
        for _ in range(60):  # Z (omega - 2 f) = T_bit(omega) = -scale xi(omega), monotone in omega
            xi, slope = _regularisation(spin)
            change = -(z * spin + torque_scale * xi - 2.0 * z * incoming) / (z + torque_scale * slope)
            spin += change
            if abs(change) <= 1e-13 * (1.0 + abs(spin)):
                break
        g_next[n - 1] = spin - incoming
        top_torque = -impedance[0] * (g_top - f_next[0])  # what the drive applies: -M(0)
        for k in range(n):
            f[k], g[k] = f_next[k], g_next[k]
        if step % stride == 0:
            out[row, 0], out[row, 1], out[row, 2] = step * dt, spin, top_torque
            row += 1
    return out[:row]


def torsional_stick_slip(sections, rotation_speed: float, damping: float, torque_scale: float, duration: float,
                         cell: float = 1.0, stride: int = 10) -> dict:
    """The bit's spin and the drive's torque over ``duration`` [s] from the string turning untwisted at
    ``rotation_speed`` [rad/s], every ``stride`` steps: {"time", "bit_angular_velocity", "top_torque"}.

    ``sections``: (length [m], G J [N m^2], rho I_p [kg m]) from the top down, one wave speed; ``damping``: c [1/s];
    the bit's torque -``torque_scale`` xi(omega) [N m]; ``cell``: the grid's dx [m], which divides every length."""
    speeds = [math.sqrt(rigidity / inertia) for _, rigidity, inertia in sections]
    if max(speeds) - min(speeds) > 1e-9 * max(speeds):
        raise ValueError("the sections' torsional wave speeds differ: the grid needs one")
    impedance = []
    for length, rigidity, inertia in sections:
        cells = round(length / cell)
        if abs(cells * cell - length) > 1e-9 * length:
            raise ValueError(f"a cell of {cell} m does not divide a section of {length} m")
        impedance += [math.sqrt(rigidity * inertia)] * cells
    dt = cell / speeds[0]
    rows = _march(np.array(impedance), rotation_speed, damping, dt, int(round(duration / dt)), stride, torque_scale)
    return {"time": rows[:, 0], "bit_angular_velocity": rows[:, 1], "top_torque": rows[:, 2]}


def limit_cycle_statistics(series: dict, rotation_speed: float, after: float) -> dict:
    """Over the whole cycles of ``series`` after ``after`` [s] (from one rise of the bit's spin through the drive's
    speed to the next, :func:`~fenics_drill.studies.stick_slip.cycles`): the mean cycle's duration, the bit's fastest
    and slowest spin, the share of time it turns slower than 1 % of the drive's speed, the mean surface torque."""
    from fenics_drill.studies.stick_slip import cycles

    late = series["time"] > after
    part = {name: series[name][late] for name in ("time", "bit_angular_velocity", "top_torque")}
    whole = cycles(part, rotation_speed)
    rows = slice(whole[0].start, whole[-1].stop)
    t, spin, torque = part["time"][rows], part["bit_angular_velocity"][rows], part["top_torque"][rows]
    span = t[-1] - t[0]
    return {"period": span / len(whole), "max_spin": float(spin.max()), "min_spin": float(spin.min()),
            "stuck_share": float(np.trapezoid((spin < 0.01 * rotation_speed).astype(float), t) / span),
            "surface_torque": float(np.trapezoid(torque, t) / span), "cycles": len(whole)}


def vertical_paper_law_case(elements: int = 200):
    """(scene, reference): demos/scenes/vertical_2000m.toml (1800 m of 5 in drill pipe over 200 m of 6 3/4 in collars,
    ``elements`` over its length) drilling with the paper's bit law at its held V0 = 20 m/h and 60 rpm, where the bit
    force settles at F = Gamma (exp(-alpha V0) - 1) (the axial and torsional fields meet only in the bit torque
    without a wall), and ``reference(duration)``: :func:`torsional_stick_slip` of its sections (G J and rho I_p of
    St-Venant's round tubes, G = E / (2 (1 + nu))) under the torque mu |F| R_bh xi(omega), R_bh the hole at the bit."""
    import fenics_drill as fd

    scene = fd.load_scene("demos/scenes/vertical_2000m.toml", [
        "bit_rock.law='paper'", "drive.mode='velocity'", "drive.weight_on_bit='26 kN'", f"beam.elements={elements}"])
    beam, bit = scene.beam, scene.bit_rock
    shear = beam.young_modulus / (2.0 * (1.0 + beam.poisson_ratio))
    sections = []
    for section in reversed(scene.string.sections):  # the scene lists them from the bit up
        polar = math.pi / 2.0 * (section["outer_radius"] ** 4 - section["inner_radius"] ** 4)
        sections.append((section["length"], shear * polar, beam.density * polar))
    force = bit.limit_force * math.expm1(-bit.rate * scene.drive.axial_velocity)
    scale = bit.friction * abs(force) * scene.hole_at_bit[0]

    def reference(duration: float) -> dict:
        return torsional_stick_slip(sections, scene.drive.rotation_speed, beam.damping, scale, duration)

    return scene, reference
