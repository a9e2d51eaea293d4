"""Independent references for stick-slip: the string as torsional (and axial) wave guides, solved along their
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
grid's points; the damping's step is explicit, with c dt of order 1e-6.  :func:`axial_torsional_stick_slip` adds
the axial guide and the cutting law at the bit (below).

Neither integration uses the finite-element model or its laws: only each section's length, stiffnesses and inertias,
the drive and the bit law's constants (the case builders read them from a scene; the statistics of a cycle use the
product's definition of a cycle, the same for both series compared).
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
def _wall_friction(f, g, friction, sliding):
    """The wall's Coulomb friction along the string over one step, cell by cell (:func:`torsional_stick_slip`):
    ``friction[k]`` = (the static and the kinetic impulse per step, as the spin they take from the cell, and the
    spin below which a sliding cell is held at the static one); ``sliding[k]``: (1 if it slid at the last step, its
    spin there).  A cell whose spin the step's impulse can take away stops; another loses that spin.  The impulse
    changes f and g alike, so the torque Z (g - f) is untouched."""
    for k in range(f.size):
        static, kinetic, slow = friction[k, 0], friction[k, 1], friction[k, 2]
        if static == 0.0:
            continue
        cap = kinetic if sliding[k, 0] > 0.5 and abs(sliding[k, 1]) >= slow else static
        spin = f[k] + g[k]
        taken = spin if abs(spin) <= cap else math.copysign(cap, spin)
        f[k] -= 0.5 * taken
        g[k] -= 0.5 * taken
        sliding[k, 0] = 1.0 if abs(spin) > cap else 0.0
        sliding[k, 1] = spin - taken


@njit(cache=True)
def _march(impedance, omega_top, damping, dt, steps, stride, torque_scale, drive, friction):
    n = impedance.size
    sliding = np.zeros((n, 2))  # at rest on the wall: stuck, held at the static factor
    f = np.full(n, 0.5 * omega_top)  # the string turning at Omega, untwisted: f = g = Omega / 2 in every cell
    g = np.full(n, 0.5 * omega_top)
    f_next, g_next = np.empty(n), np.empty(n)
    out = np.empty((steps // stride + 1, 3))
    out[0, 0], out[0, 1], out[0, 2] = 0.0, omega_top, 0.0
    decay = 0.5 * damping * dt
    spin, row = omega_top, 1
    inertia, k_p, k_i, t_max = drive
    top, integral, load = omega_top, 0.0, 0.0  # a top drive's speed, speed error's integral z, and J d(top)/dt
    for step in range(1, steps + 1):
        for k in range(n):
            loss = decay * (f[k] + g[k])
            f[k] -= loss
            g[k] -= loss
        g_top = g[0]
        if inertia == 0.0:
            f_next[0] = omega_top - g_top  # the held top
            top_torque = -impedance[0] * (2.0 * g_top - omega_top)  # what holding it takes: -M(0)
        else:  # J top' = T_m + M(0), M(0) = Z (2 g - top), by the trapezoidal rule with z of the same rule
            z0 = impedance[0]
            base = k_p * omega_top + k_i * (integral + dt * omega_top - 0.5 * dt * top)
            motor_rate = k_p + 0.5 * k_i * dt
            new_top = ((inertia / dt) * top + 0.5 * (base + 2.0 * z0 * g_top) + 0.5 * load) / (
                inertia / dt + 0.5 * motor_rate + 0.5 * z0)
            motor = base - motor_rate * new_top
            if abs(motor) > t_max:  # at the motor's limit, z frozen
                motor = math.copysign(t_max, motor)
                new_top = ((inertia / dt) * top + 0.5 * (motor + 2.0 * z0 * g_top) + 0.5 * load) / (
                    inertia / dt + 0.5 * z0)
            else:
                integral += dt * (omega_top - 0.5 * (top + new_top))
            load = motor + z0 * (2.0 * g_top - new_top)
            top = new_top
            f_next[0] = top - g_top
            top_torque = motor
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
        for k in range(n):
            f[k], g[k] = f_next[k], g_next[k]
        _wall_friction(f, g, friction, sliding)
        if step % stride == 0:
            out[row, 0], out[row, 1], out[row, 2] = step * dt, spin, top_torque
            row += 1
    return out[:row]


def torsional_stick_slip(sections, rotation_speed: float, damping: float, torque_scale: float, duration: float,
                         cell: float = 1.0, stride: int = 10, top_drive: tuple = (0.0, 0.0, 0.0, math.inf),
                         wall: tuple | None = None) -> dict:
    """The bit's spin and the drive's torque over ``duration`` [s] from the string turning untwisted at
    ``rotation_speed`` [rad/s], every ``stride`` steps: {"time", "bit_angular_velocity", "top_torque"}.

    ``sections``: (length [m], G J [N m^2], rho I_p [kg m]) from the top down, one wave speed; ``damping``: c [1/s];
    the bit's torque -``torque_scale`` xi(omega) [N m]; ``cell``: the grid's dx [m], which divides every length;
    ``top_drive``: (J [kg m^2], k_p [N m s/rad], k_i [N m/rad], T_max [N m]) of a top drive turned by the motor torque
    T_m = k_p (Omega - top) + k_i z, z the speed error's integral, frozen while |T_m| is at T_max (J = 0: the top
    held at Omega); the top torque is then T_m.

    ``wall``: (static factor, kinetic factor, static slip speed [m/s], and per section the wall's normal force per
    length [N/m] and the contact radius R [m]): Coulomb friction along the string, the torque per length mu N' R
    acting on each cell's spin, the kinetic factor where the cell slid at the last step at a surface speed R |omega|
    of at least the static slip speed, the static one elsewhere (the wall law of Aarsnes & Shor, J. Pet. Sci. Eng.
    163, 2018, with its threshold on the surface speed): a cell stops when the step's impulse of friction can take
    its spin away (:func:`_wall_friction`)."""
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
    friction = np.zeros((len(impedance), 3))
    if wall is not None:
        static, kinetic, slow_speed, per_section = wall
        k = 0
        for (length, _, inertia), (normal, radius) in zip(sections, per_section):
            cells = round(length / cell)
            per_step = normal * radius * dt / inertia  # the spin mu = 1 takes per step: N' R dt / (rho I_p)
            friction[k:k + cells] = (static * per_step, kinetic * per_step, slow_speed / radius)
            k += cells
    rows = _march(np.array(impedance), rotation_speed, damping, dt, int(round(duration / dt)), stride, torque_scale,
                  np.array(top_drive, dtype=float), friction)
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


def vertical_paper_law_case(elements: int = 200, controller: str = "stiff"):
    """(scene, reference): demos/scenes/vertical_2000m.toml (1800 m of 5 in drill pipe over 200 m of 6 3/4 in collars,
    ``elements`` over its length) drilling with the paper's bit law at its held V0 = 20 m/h and 60 rpm, where the bit
    force settles at F = Gamma (exp(-alpha V0) - 1) (the axial and torsional fields meet only in the bit torque
    without a wall), turned by ``controller`` (``drive.controller``), and ``reference(duration, cell)``:
    :func:`torsional_stick_slip` of its sections (G J and rho I_p of St-Venant's round tubes, G = E / (2 (1 + nu)))
    under the torque mu |F| R_bh xi(omega), R_bh the hole at the bit, with the scene's top drive: its J_td, T_max and
    gains, or for 'soft_torque' k_p = rho I_p c_T of the top section and k_i = (2 pi c_T / 4 L)^2 J_td (Kyllingstad &
    Nessjoen 2009)."""
    import fenics_drill as fd

    scene = fd.load_scene("demos/scenes/vertical_2000m.toml", [
        "bit_rock.law='paper'", "drive.mode='velocity'", "drive.weight_on_bit='26 kN'", f"beam.elements={elements}",
        f"drive.controller='{controller}'"])
    beam, bit, drive = scene.beam, scene.bit_rock, scene.drive
    shear = beam.young_modulus / (2.0 * (1.0 + beam.poisson_ratio))
    sections = []
    for section in reversed(scene.string.sections):  # the scene lists them from the bit up
        polar = math.pi / 2.0 * (section["outer_radius"] ** 4 - section["inner_radius"] ** 4)
        sections.append((section["length"], shear * polar, beam.density * polar))
    force = bit.limit_force * math.expm1(-bit.rate * drive.axial_velocity)
    scale = bit.friction * abs(force) * scene.hole_at_bit[0]
    top_drive = (0.0, 0.0, 0.0, math.inf)
    if controller == "pi":
        top_drive = (drive.top_drive_inertia, drive.proportional_gain, drive.integral_gain, drive.torque_limit)
    elif controller == "soft_torque":
        speed = math.sqrt(sections[0][1] / sections[0][2])
        quarter_wave = 2.0 * math.pi * speed / (4.0 * sum(length for length, _, _ in sections))
        top_drive = (drive.top_drive_inertia, sections[0][2] * speed, quarter_wave**2 * drive.top_drive_inertia,
                     drive.torque_limit)

    def reference(duration: float, cell: float = 1.0) -> dict:
        return torsional_stick_slip(sections, drive.rotation_speed, beam.damping, scale, duration, cell,
                                    max(1, round(10 / cell)), top_drive)

    return scene, reference


# The axial and torsional wave guides of one string, meeting at the bit in the cutting law of Richard, Germay &
# Detournay (2007) with its regenerative delay: the distributed axial-torsional model of Germay, Denoel & Detournay
# (J. Sound Vib. 325, 2009) and of Aarsnes & Aamo (J. Sound Vib. 360, 2016), solved along its characteristics.  The
# axial waves (speed c_A = sqrt(E / rho)) carry v = f + g and N = E A u_x = Z_A (g - f), Z_A = A sqrt(E rho), with the
# weight rho A g as a source: df/dt = dg/dt = (g_n - c v) / 2.  Both guides share the step; each section's length is
# a whole number of cells of both (the string's c_A / c_T is rational: a Poisson ratio of 0.28 gives 1.6).


@njit(cache=True)
def _clip_ramp(x, low):
    """(clip(x, low, 1), its slope): written here again, not imported from the model's law, so that the reference
    shares no code with what it checks."""
    if x <= low:
        return low, 0.0
    if x >= 1.0:
        return 1.0, 0.0
    return x, 1.0


@njit(cache=True)
def _surface_at(angles, surfaces, count, feed, angle):
    """S(angle) and its slope: linear between the recorded (angle, surface), steady drilling at ``feed`` before."""
    if angle <= angles[0]:
        return surfaces[0] - (angles[0] - angle) * feed, feed
    if angle >= angles[count - 1]:
        return surfaces[count - 1], 0.0
    lo, hi = 0, count - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if angles[mid] <= angle:
            lo = mid
        else:
            hi = mid
    slope = (surfaces[hi] - surfaces[lo]) / (angles[hi] - angles[lo])
    return surfaces[lo] + slope * (angle - angles[lo]), slope


@njit(cache=True)
def _cutting(u, v, phi, w, angles, surfaces, count, law):
    """(W, T) of the cutting law at the bit and their derivatives by (u, v, phi, w)."""
    blades, zeta_eps_a, eps_a2_half, contact_force, torque_arm, v_c, d_c, spin_scale, held, feed = law
    passage = 2.0 * math.pi / blades
    cut, slope = _surface_at(angles, surfaces, count, feed, phi - passage)
    d, dd_u, dd_phi = 0.0, 0.0, 0.0
    if u > cut:
        d, dd_u, dd_phi = blades * (u - cut), blades, -blades * slope
    g_v, dg_v = _clip_ramp(v / v_c, 0.0)
    g_d, dg_d = _clip_ramp(d / d_c, 0.0)
    contact = contact_force * g_v * g_d
    dc_d, dc_v = contact_force * g_v * dg_d / d_c, contact_force * dg_v / v_c * g_d
    s, ds = _clip_ramp(w / spin_scale, -1.0)
    magnitude = eps_a2_half * d + torque_arm * contact
    weight = zeta_eps_a * d + contact
    dw_d, dm_d = zeta_eps_a + dc_d, eps_a2_half + torque_arm * dc_d
    hold = held if w < 0.0 else 0.0  # a bit held against turning backwards: a damper on its backward spin
    return (weight, magnitude * s + hold * w, dw_d * dd_u, dc_v, dw_d * dd_phi, dm_d * dd_u * s,
            torque_arm * dc_v * s, dm_d * dd_phi * s, magnitude * ds / spin_scale + hold)


@njit(cache=True)
def _bit_residual(which, v_new, w_new, u, phi, v, w, dt, za, zt, inc_a, inc_t, angles, surfaces, count, law):
    """Z_A (v - 2 f_A) + W (which = 0) or Z_T (w - 2 f_T) + T (1) at the step's end, and its derivative by v (0)
    or w (1); u and phi advanced by the trapezoidal rule."""
    u_new, phi_new = u + 0.5 * dt * (v + v_new), phi + 0.5 * dt * (w + w_new)
    weight, torque, w_u, w_v, w_phi, t_u, t_v, t_phi, t_w = _cutting(u_new, v_new, phi_new, w_new, angles, surfaces,
                                                                     count, law)
    if which == 0:
        return za * (v_new - 2.0 * inc_a) + weight, za + w_v + 0.5 * dt * w_u
    return zt * (w_new - 2.0 * inc_t) + torque, zt + t_w + 0.5 * dt * t_phi


@njit(cache=True)
def _bit_root(which, v_new, w_new, u, phi, v, w, dt, za, zt, inc_a, inc_t, angles, surfaces, count, law):
    """The root of one bit equation in its own unknown, the other held: the residual rises with it (the impedance
    and the law's resistance), so Newton is kept inside the bracket its signs give, and bisects where it leaves it."""
    x = v_new if which == 0 else w_new
    low, high = -math.inf, math.inf
    for _ in range(200):
        r, slope = _bit_residual(which, x if which == 0 else v_new, x if which == 1 else w_new, u, phi, v, w, dt, za,
                                 zt, inc_a, inc_t, angles, surfaces, count, law)
        if r == 0.0:
            return x
        if r > 0.0:
            high = x
        else:
            low = x
        step = -r / slope if slope > 0.0 else (-1.0 if r > 0.0 else 1.0) * (1.0 + abs(x))
        trial = x + step
        if not (low < trial < high):
            trial = 0.5 * (low + high) if math.isfinite(low) and math.isfinite(high) else x + 2.0 * step
        if abs(trial - x) <= 1e-15 * (1.0 + abs(x)):
            return trial
        x = trial
    return x


@njit(cache=True)
def _march_coupled(axial_z, torsion_z, weight_source, axial_n0, omega_top, v0, hook_load, damping, dt,
                   steps, stride, law):
    na, nt = axial_z.size, torsion_z.size
    fa, ga = np.empty(na), np.empty(na)
    for k in range(na):  # moving at V0 in the static state: v = V0, N = Z (g - f) the static force
        fa[k] = 0.5 * (v0 - axial_n0[k] / axial_z[k])
        ga[k] = 0.5 * (v0 + axial_n0[k] / axial_z[k])
    ft, gt = np.full(nt, 0.5 * omega_top), np.full(nt, 0.5 * omega_top)
    fa_next, ga_next, ft_next, gt_next = np.empty(na), np.empty(na), np.empty(nt), np.empty(nt)
    capacity = steps + 2
    angles, surfaces = np.empty(capacity), np.empty(capacity)
    angles[0], surfaces[0], count = 0.0, 0.0, 1
    u, phi, v, w = 0.0, 0.0, v0, omega_top
    out = np.empty((steps // stride + 1, 4))
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = 0.0, w, 0.0, v
    half = 0.5 * damping * dt
    for step in range(1, steps + 1):
        for k in range(na):
            change = weight_source[k] * 0.5 * dt - half * (fa[k] + ga[k])
            fa[k] += change
            ga[k] += change
        for k in range(nt):
            loss = half * (ft[k] + gt[k])
            ft[k] -= loss
            gt[k] -= loss
        ga_top, gt_top = ga[0], gt[0]
        if math.isnan(hook_load):  # the top held moving at V0: v(0) = V0
            fa_next[0] = v0 - ga_top
        else:  # the hook's pull: N(0) = hook load
            fa_next[0] = ga_top - hook_load / axial_z[0]
        ft_next[0] = omega_top - gt_top  # the held top
        for j in range(1, na):
            above, below = axial_z[j - 1], axial_z[j]
            reflected = ((above - below) * fa[j - 1] + 2.0 * below * ga[j]) / (above + below)
            ga_next[j - 1] = reflected
            fa_next[j] = fa[j - 1] + reflected - ga[j]
        for j in range(1, nt):
            above, below = torsion_z[j - 1], torsion_z[j]
            reflected = ((above - below) * ft[j - 1] + 2.0 * below * gt[j]) / (above + below)
            gt_next[j - 1] = reflected
            ft_next[j] = ft[j - 1] + reflected - gt[j]
        za, zt, inc_a, inc_t = axial_z[na - 1], torsion_z[nt - 1], fa[na - 1], ft[nt - 1]
        v_new, w_new = v, w
        for _ in range(100):  # Gauss-Seidel over the two monotone equations, each solved bracketed
            v_old, w_old = v_new, w_new
            v_new = _bit_root(0, v_new, w_new, u, phi, v, w, dt, za, zt, inc_a, inc_t, angles, surfaces, count, law)
            w_new = _bit_root(1, v_new, w_new, u, phi, v, w, dt, za, zt, inc_a, inc_t, angles, surfaces, count, law)
            if abs(v_new - v_old) <= 1e-13 * (1.0 + abs(v_new)) and abs(w_new - w_old) <= 1e-13 * (1.0 + abs(w_new)):
                break
        u, phi = u + 0.5 * dt * (v + v_new), phi + 0.5 * dt * (w + w_new)
        v, w = v_new, w_new
        ga_next[na - 1], gt_next[nt - 1] = v - inc_a, w - inc_t
        if phi > angles[count - 1]:  # the blade at phi leaves what it met, or deeper
            met, _ = _surface_at(angles, surfaces, count, law[9], phi - 2.0 * math.pi / law[0])
            angles[count], surfaces[count] = phi, max(u, met)
            count += 1
        top_torque = -torsion_z[0] * (gt_top - ft_next[0])
        for k in range(na):
            fa[k], ga[k] = fa_next[k], ga_next[k]
        for k in range(nt):
            ft[k], gt[k] = ft_next[k], gt_next[k]
        if step % stride == 0:
            row = step // stride
            out[row, 0], out[row, 1], out[row, 2], out[row, 3] = step * dt, w, top_torque, v
    return out


def axial_torsional_stick_slip(sections, rotation_speed: float, axial_velocity: float, hook_load: float | None,
                               weight_on_bit: float, damping: float, gravity: float, law: tuple, duration: float,
                               cell: float = 1.0, stride: int = 10) -> dict:
    """The bit's spin and velocity and the drive's torque over ``duration`` [s], every ``stride`` steps, from the
    string's static state under ``weight_on_bit`` [N] moving at (``axial_velocity``, ``rotation_speed``), its top
    pulled with ``hook_load`` [N] (None: held moving at ``axial_velocity``) and turned at the held speed, the bit in the cutting law ``law`` = (n, zeta eps a,
    eps a^2 / 2, sigma a l, mu gamma a / 2, v_c, d_c, v_c / a, the damping c_h that holds a backward spin: the torque
    gains -c_h omega while omega < 0) over a bottom drilled steadily before t = 0.
    ``sections``: (length, E A, rho A, G J, rho I_p) from the top down, one ratio c_A / c_T that makes every length a
    whole number of both guides' cells (``cell`` [m] the torsional one)."""
    torsional_speed = math.sqrt(sections[0][3] / sections[0][4])
    dt = cell / torsional_speed
    axial_z, torsion_z, source, static = [], [], [], []
    tension = -weight_on_bit  # N at the bit, growing with the weight of each section above it
    axial_cell = math.sqrt(sections[0][1] / sections[0][2]) * dt
    layout = []
    for length, axial, axial_mass, torsion, torsion_inertia in sections:
        cells_a, cells_t = round(length / axial_cell), round(length / cell)
        if abs(cells_a * axial_cell - length) > 1e-6 * length or abs(cells_t * cell - length) > 1e-6 * length:
            raise ValueError(f"a section of {length} m is not a whole number of cells ({axial_cell} m, {cell} m)")
        layout.append((cells_a, axial, axial_mass))
        torsion_z += [math.sqrt(torsion * torsion_inertia)] * cells_t
    for cells_a, axial, axial_mass in reversed(layout):  # the static force from the bit up, at each cell's middle
        for k in range(cells_a):
            static.append(tension + axial_mass * gravity * (k + 0.5) * axial_cell)
        tension += axial_mass * gravity * cells_a * axial_cell
    static.reverse()
    for cells_a, axial, axial_mass in layout:
        axial_z += [math.sqrt(axial * axial_mass)] * cells_a
        source += [gravity] * cells_a
    feed = axial_velocity / rotation_speed
    rows = _march_coupled(np.array(axial_z), np.array(torsion_z), np.array(source), np.array(static),
                          rotation_speed, axial_velocity, math.nan if hook_load is None else hook_load, damping, dt,
                          int(round(duration / dt)), stride,
                          np.array([*law, feed]))
    return {"time": rows[:, 0], "bit_angular_velocity": rows[:, 1], "top_torque": rows[:, 2],
            "bit_velocity": rows[:, 3]}


def _cutting_law(bit) -> tuple:
    """:func:`axial_torsional_stick_slip`'s ``law`` of a scene's ``bit_rock`` section: its bit held against turning
    backwards by a damper of 1e6 N m s where ``bit_rock.backward_spin = 'held'``."""
    a = bit.bit_radius
    return (float(bit.blades), bit.cutting_orientation * bit.specific_energy * a, bit.specific_energy * a * a / 2.0,
            bit.contact_strength * a * bit.wear_flat_length, bit.friction * bit.geometry_factor * a / 2.0,
            bit.contact_velocity, bit.contact_depth, bit.contact_velocity / a,
            1e6 if bit.backward_spin == "held" else 0.0)


def vertical_cutting_law_case(elements: int = 200, weight_on_bit: float = 60e3, rotation_speed: float = 4.0 * math.pi,
                              backward_spin: str = "free"):
    """(scene, reference): demos/scenes/vertical_2000m.toml with the cutting law under its hook-load drive, in air, of a
    steel whose Poisson ratio 0.28 makes c_A / c_T = 1.6 (the guides' cells 1.6 m and 1 m fit every section), and
    ``reference(duration, cell)``: :func:`axial_torsional_stick_slip` of its sections, the hook load the string's weight
    less ``weight_on_bit`` [N], turned at ``rotation_speed`` [rad/s], its bit's ``backward_spin`` free or held (by a
    damper of 1e6 N m s on a backward spin, ``bit_rock.backward_spin``'s)."""
    import fenics_drill as fd

    scene = fd.load_scene("demos/scenes/vertical_2000m.toml", [
        "beam.poisson_ratio=0.28", "fluid.density=0", f"beam.elements={elements}",
        f"drive.weight_on_bit={weight_on_bit}", f"drive.rotation_speed={rotation_speed}",
        f"bit_rock.backward_spin='{backward_spin}'"])

    def reference(duration: float, cell: float = 1.0) -> dict:
        return hook_load_reference(scene, duration, cell)

    return scene, reference


def hook_load_reference(scene, duration: float, cell: float = 1.0) -> dict:
    """:func:`axial_torsional_stick_slip` of a scene's string in air under its hook-load drive: its sections (from the
    top down, St-Venant's round tubes, G = E / (2 (1 + nu))), the hook load its weight less the drive's weight on
    bit, the drive's speeds, the scene's cutting law, ``cell`` [m] torsional cells."""
    beam, drive = scene.beam, scene.drive
    shear = beam.young_modulus / (2.0 * (1.0 + beam.poisson_ratio))
    sections, weight = [], 0.0
    for section in reversed(scene.string.sections):
        outer, inner = section["outer_radius"], section["inner_radius"]
        area, polar = math.pi * (outer**2 - inner**2), math.pi / 2.0 * (outer**4 - inner**4)
        sections.append((section["length"], beam.young_modulus * area, beam.density * area, shear * polar,
                         beam.density * polar))
        weight += beam.density * area * section["length"] * scene.environment.gravity
    return axial_torsional_stick_slip(sections, drive.rotation_speed, drive.axial_velocity,
                                      weight - drive.weight_on_bit, drive.weight_on_bit, beam.damping,
                                      scene.environment.gravity, _cutting_law(scene.bit_rock), duration, cell,
                                      max(1, round(10 / cell)))


#: Aarsnes & van de Wouw's published axial-torsional model (github.com/ulfjakob/AxialTorsionalDrillString, "Coupled -
#: nondim"), the case of its MAIN.m: the cutting weight per depth, damping per time unit, contact torque arm, contact
#: weight, v0.
K_A, ETA, BETA, WEAR_FLAT, V0 = 20.0, 0.7, 0.1, 200.0, 2.0
#: The string their case is stated for (:func:`moving_top_cutting_law_case`).
LENGTH, OUTER, INNER, YOUNG, POISSON, DENSITY = 2000.0, 0.127, 0.1086, 210e9, 0.28, 7850.0
BLADES, RADIUS, ZETA, FLAT_LENGTH, MU = 4, 0.108, 1.0, 1.2e-3, 0.5


def published_scales() -> dict:
    """The dimensional scales of their nondimensional groups for this string: time L / c_t, velocity U* / t*, spin
    (2 pi / n) / t*, depth U* = 2 G J (2 pi / n) / (L eps a^2 n) (their cutting torque d), weight E A U* / L, torque
    G J (2 pi / n) / L, and the specific energy eps their K_a = zeta eps a n L / (E A) asks."""
    shear = YOUNG / (2.0 * (1.0 + POISSON))
    speed = math.sqrt(shear / DENSITY)
    polar = math.pi / 32.0 * (OUTER**4 - INNER**4)
    area = math.pi / 4.0 * (OUTER**2 - INNER**2)
    passage = 2.0 * math.pi / BLADES
    energy = K_A * YOUNG * area / (ZETA * RADIUS * BLADES * LENGTH)  # eps from K_a = zeta eps a n L / (E A)
    depth = 2.0 * shear * polar * passage / (LENGTH * energy * RADIUS**2 * BLADES)
    weight, torque = YOUNG * area * depth / LENGTH, shear * polar * passage / LENGTH
    t_star = LENGTH / speed
    return {"time": t_star, "velocity": depth / t_star, "spin": passage / t_star, "depth": depth, "weight": weight,
            "torque": torque, "specific_energy": energy}


def moving_top_cutting_law_case(omega0: float, elements: int = 200, v0: float = V0):
    """(scene, reference): their case at the set spin ``omega0`` and top velocity ``v0`` (their units) stated for
    2000 m of 5 in pipe without gravity, its top held moving at v0 and turning at omega0, the cutting law scaled by
    :func:`published_scales` (zeta = 1, l = 1.2 mm, mu = 0.5, a 4-blade bit of 0.108 m held against turning
    backwards, as theirs sticks), damped at their -ln(eta) per time unit; and ``reference(duration, cell)``:
    :func:`axial_torsional_stick_slip` of that string and law, the top held moving."""
    import tempfile
    from pathlib import Path

    import fenics_drill as fd

    s = published_scales()
    contact = WEAR_FLAT * s["weight"]  # sigma a l
    text = f"""
[well]
md = [0.0, {LENGTH}]
inclination = [0.0, 0.0]
azimuth = [0.0, 0.0]
hole_bottom = [{LENGTH}]
hole_radius = [{RADIUS}]
hole_cased = [false]
[[string.sections]]
name = "drill pipe 5 in"
length = {LENGTH}
outer_diameter = {OUTER}
inner_diameter = {INNER}
[beam]
elements = {elements}
young_modulus = {YOUNG}
poisson_ratio = {POISSON}
density = {DENSITY}
damping = {-math.log(ETA) / s["time"]!r}
[model]
gravity = false
lateral_length = 0.0
[contact]
friction = 0.0
[drive]
mode = "velocity"
axial_velocity = {v0 * s["velocity"]!r}
rotation_speed = {omega0 * s["spin"]!r}
weight_on_bit = {(K_A * v0 / omega0 + WEAR_FLAT) * s["weight"]!r}
start = "on_bottom"
[bit_rock]
law = "detournay"
bit_radius = {RADIUS}
blades = {BLADES}
specific_energy = {s["specific_energy"]!r}
cutting_orientation = {ZETA}
contact_strength = {contact / (RADIUS * FLAT_LENGTH)!r}
wear_flat_length = {FLAT_LENGTH}
friction = {MU}
geometry_factor = {2.0 * BETA * s["torque"] / (RADIUS * s["weight"]) / MU!r}
contact_velocity = {0.01 * s["velocity"]!r}
backward_spin = "held"
"""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "scene.toml"
        path.write_text(text)
        scene = fd.load_scene(path)
    beam = scene.beam
    shear = beam.young_modulus / (2.0 * (1.0 + beam.poisson_ratio))
    polar, area = math.pi / 32.0 * (OUTER**4 - INNER**4), math.pi / 4.0 * (OUTER**2 - INNER**2)
    sections = [(LENGTH, beam.young_modulus * area, beam.density * area, shear * polar, beam.density * polar)]
    drive = scene.drive

    def reference(duration: float, cell: float = 1.25) -> dict:
        return axial_torsional_stick_slip(sections, drive.rotation_speed, drive.axial_velocity, None,
                                          drive.weight_on_bit, beam.damping, 0.0, _cutting_law(scene.bit_rock),
                                          duration, cell, max(1, round(10 / cell)))

    return scene, reference


def inclined_wall_friction_case(elements: int = 200, inclination: float = 60.0, controller: str = "stiff"):
    """(scene, reference, static torque): the 2000 m string of demos/scenes/vertical_2000m.toml (``elements`` over
    its length) in a straight hole inclined ``inclination`` degrees, in air, rotating off bottom at 40 rpm with the
    wall's static factor 0.3, kinetic 0.195 and static slip speed 0.11 m/s (the ratio 0.65 and the threshold, 1.5
    rad/s on a 5 3/4 in pipe, of Aarsnes & Shor 2018), and ``reference(duration, cell)``: :func:`torsional_stick_slip`
    of its sections with the wall's normal force per length rho g A sin(inclination) (a straight hole: the string's
    weight across it) at the outer radius; the static torque is sum mu_s N' R L over the sections."""
    import fenics_drill as fd

    scene = fd.load_scene("demos/scenes/vertical_2000m.toml", [
        f"well.inclination=[{inclination}, {inclination}]", "fluid.density=0.0", "model.bit_rock=false",
        "drive.mode='velocity'", "drive.axial_velocity=0.0", "drive.start='off_bottom'", "drive.rotation_speed='40 rpm'",
        "model.lateral_length=0", "contact.friction=0.195", "contact.static_friction=0.3",
        "contact.static_slip_speed=0.11", f"beam.elements={elements}", f"drive.controller='{controller}'",
        "drive.top_drive_inertia=2900.0", "drive.proportional_gain=38e3", "drive.integral_gain=100e3",
        "drive.torque_limit=100e3"])
    beam, drive, contact = scene.beam, scene.drive, scene.contact
    shear = beam.young_modulus / (2.0 * (1.0 + beam.poisson_ratio))
    sections, wall = [], []
    for section in reversed(scene.string.sections):  # the scene lists them from the bit up
        outer, inner = section["outer_radius"], section["inner_radius"]
        polar = math.pi / 2.0 * (outer**4 - inner**4)
        sections.append((section["length"], shear * polar, beam.density * polar))
        weight = beam.density * scene.environment.gravity * math.pi * (outer**2 - inner**2)
        wall.append((weight * math.sin(math.radians(inclination)), outer))
    top_drive = (0.0, 0.0, 0.0, math.inf)
    if controller == "pi":
        top_drive = (drive.top_drive_inertia, drive.proportional_gain, drive.integral_gain, drive.torque_limit)
    law = (contact.static_friction, contact.friction, contact.static_slip_speed, wall)
    static_torque = sum(contact.static_friction * normal * radius * length
                        for (length, _, _), (normal, radius) in zip(sections, wall))

    def reference(duration: float, cell: float = 1.0) -> dict:
        return torsional_stick_slip(sections, drive.rotation_speed, beam.damping, 0.0, duration, cell,
                                    max(1, round(10 / cell)), top_drive, law)

    return scene, reference, static_torque
