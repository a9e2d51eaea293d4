"""Linear stability of steady drilling with the cutting law: the two-mode delay model of Richard, Germay &
Detournay (2007), with the paper's string, against the stick-slip threshold the simulations find.

The string is reduced to its first axial and first torsional modes, each fixed at the (stiff) drive and free
at the bit, normalised to unit motion at the bit: m = rho A L / 2, J = rho I_xx L / 2, omega_a = pi c_L / 2L,
omega_t = pi c_T / 2L, and the damping (38) gives c m and c J.  About steady drilling (u_dot = V0 > v_c:
the contact part is constant) the perturbations x = du_bit, y = dphi_bit obey

    m x'' + c m x' + k x = -zeta eps a dd,       J y'' + c J y' + k_t y = -(eps a^2 / 2) dd,
    dd = n [(x - x(t - tau)) - (V0 / Omega)(y - y(t - tau))],   tau = 2 pi / (n Omega),

(the delay is the bit's own blade passage, so a twist dy changes it by (dy - dy(t - tau)) / Omega).  The
rightmost characteristic roots come from the pseudospectral collocation of Breda, Maset & Vermiglio
(SIAM J. Sci. Comput. 27, 2005) on N Chebyshev nodes of [-tau, 0].

    .venv/bin/python benchmarks/stick_slip_stability.py [--scene demos/scenes/stick_slip_map.toml]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from fenics_drill.scene import load_scene

ROOT = Path(__file__).parents[1]


def chebyshev(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev points x_j = cos(j pi / n) on [-1, 1] and their differentiation matrix (Trefethen 2000)."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.ones(n + 1)
    c[0] = c[-1] = 2.0
    c *= (-1.0) ** np.arange(n + 1)
    dx = x[:, None] - x[None, :]
    D = np.outer(c, 1.0 / c) / (dx + np.eye(n + 1))
    D -= np.diag(D.sum(axis=1))
    return x, D


def rightmost_roots(A0: np.ndarray, A1: np.ndarray, tau: float, nodes: int = 40) -> np.ndarray:
    """Approximate roots of det(s I - A0 - A1 exp(-s tau)) = 0, sorted by decreasing real part."""
    dim = A0.shape[0]
    _, D = chebyshev(nodes)
    D = D * (2.0 / tau)  # on [-tau, 0]: theta = tau (x - 1) / 2
    big = np.kron(D, np.eye(dim))
    big[:dim, :] = 0.0
    big[:dim, :dim] = A0  # theta = 0: the equation itself
    big[:dim, -dim:] = A1  # theta = -tau
    roots = np.linalg.eigvals(big)
    return roots[np.argsort(-roots.real)]


def two_mode_system(scene, axial_velocity: float, rotation_speed: float):
    """(A0, A1, tau) of the linearised two-mode model about steady drilling (module doc)."""
    p, b = scene.beam_properties, scene.bit_rock
    area, polar = p.section.area, 2.0 * p.section.I4
    m, J = p.density * area * p.length / 2, p.density * polar * p.length / 2
    k = m * (math.pi * p.longitudinal_wave_speed / (2 * p.length)) ** 2
    k_t = J * (math.pi * p.torsional_wave_speed / (2 * p.length)) ** 2
    n, zeta_eps_a, eps_a2 = b.blades, b.cutting_orientation * b.specific_energy * b.bit_radius, \
        b.specific_energy * b.bit_radius**2 / 2
    feed = axial_velocity / rotation_speed
    # dd = n (E x - feed E y) with E = 1 - delay: the generalised "cutting stiffness" on (x, y)
    cutting = n * np.array([[zeta_eps_a, -zeta_eps_a * feed], [eps_a2, -eps_a2 * feed]])
    mass, stiffness, damping = np.diag([m, J]), np.diag([k, k_t]), p.damping * np.diag([m, J])
    inv = np.linalg.inv(mass)
    A0 = np.block([[np.zeros((2, 2)), np.eye(2)], [-inv @ (stiffness + cutting), -inv @ damping]])
    A1 = np.block([[np.zeros((2, 2)), np.zeros((2, 2))], [inv @ cutting, np.zeros((2, 2))]])
    return A0, A1, 2 * math.pi / (n * rotation_speed)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(ROOT / "demos" / "scenes" / "stick_slip_map.toml"))
    parser.add_argument("--nodes", type=int, default=120)
    args = parser.parse_args()
    scene = load_scene(args.scene)
    v0 = scene.drive.axial_velocity
    print(f"| Omega [rpm] | tau [s] | rightmost root: growth rate [1/s] | its frequency [Hz] | "
          f"check N = {args.nodes // 2}: growth rate [1/s] |")
    print("|---|---|---|---|---|")
    for rpm in (15, 20, 30, 45, 60, 75, 90, 120):
        omega = rpm * 2 * math.pi / 60
        A0, A1, tau = two_mode_system(scene, v0, omega)
        root = rightmost_roots(A0, A1, tau, args.nodes)[0]
        coarse = rightmost_roots(A0, A1, tau, args.nodes // 2)[0]
        print(f"| {rpm} | {tau:.4f} | {root.real:.4g} | {abs(root.imag) / (2 * math.pi):.4g} | {coarse.real:.4g} |")


if __name__ == "__main__":
    main()
