"""The modes of strings hanging in a vertical well against exact references (docs/verification.md, "Modes in the
well"): transfer-matrix roots of a composite rod (axial, St-Venant torsion; with discrete tool joints) and the
tensioned-beam equation solved by Chebyshev collocation (tests/model/string_references.py, shared with the tests).

    python benchmarks/modes_in_the_well.py [--table benchmarks/results/modes_in_the_well.md]
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).parents[1]
sys.path[:0] = [str(ROOT / "tests" / "model"), str(ROOT / "tests")]

from string_references import rod_frequencies, tensioned_beam_frequencies  # noqa: E402
from test_modes_in_the_well import (COLLAR, E, HEAVY_WEIGHT, JOINTED, PIPE, RHO, G, fe_family,  # noqa: E402
                                    lateral_modes, segments, vertical_string)

from fenics_drill.forms.properties import section_constants  # noqa: E402
from fenics_drill.model.discretization import DRIVE, BeamDiscretization  # noqa: E402
from fenics_drill.model.operators import assemble_linear  # noqa: E402
from fenics_drill.model.reduction.modes import solve_modes  # noqa: E402


def rows(name, fe, exact) -> list[str]:
    return [f"| {name} | {k + 1} | {f:.6g} | {x:.6g} | {abs(f / x - 1):.1e} |" for k, (f, x) in enumerate(zip(fe, exact))]


def composite_rows() -> list[str]:
    sections = [COLLAR, HEAVY_WEIGHT, PIPE]
    disc = BeamDiscretization.from_scene(vertical_string(sections, 1000))
    mass = assemble_linear(disc).mass
    out = []
    for held in (False, True):
        basis = solve_modes(disc, 2.0, mass, held=DRIVE if held else (), vectors=False)
        for kind in ("axial", "torsional"):
            fe = fe_family(basis, kind, 3)
            exact = rod_frequencies(segments(sections, kind), "held" if held else "free", "free", 3, 1.2 * fe[-1])
            out += rows(f"{kind}, {'drive-held' if held else 'free-free'}", fe, exact)
    return out


def joint_rows() -> list[str]:
    disc = BeamDiscretization.from_scene(vertical_string([JOINTED], 470))
    basis = solve_modes(disc, 1.5, assemble_linear(disc).mass, held=DRIVE, vectors=False)
    body = section_constants(JOINTED["outer_radius"], JOINTED["inner_radius"])
    joint = section_constants(JOINTED["tool_joint_outer_radius"], JOINTED["tool_joint_inner_radius"])
    out = []
    for kind in ("axial", "torsional"):
        fe = fe_family(basis, kind, 3)
        pitch = [(l, E * c.area, RHO * c.area) if kind == "axial" else (l, G * 2 * c.I4, RHO * 2 * c.I4)
                 for c, l in ((body, 8.9), (joint, 0.5))]
        exact = rod_frequencies(pitch * 50, "held", "free", 3, 1.2 * fe[-1])
        mass_only = rod_frequencies([(l, pitch[0][1], m) for l, _, m in pitch] * 50, "held", "free", 3, 1.2 * fe[-1])
        out += [f"| {kind} | {k + 1} | {f:.6g} | {x:.6g} | {f / x - 1:+.2%} | {m / x - 1:+.2%} |"
                for k, (f, x, m) in enumerate(zip(fe, exact, mass_only))]
    return out


def lateral_rows() -> list[str]:
    out = []
    cases = (("drill pipe, 500 m hanging", dict(PIPE, length=500.0), 250, 0.0),
             ("drill pipe, 1500 m hanging", dict(PIPE, length=1500.0), 750, 0.0),
             ("collars, 120 m, 30 kN on the bit", dict(COLLAR, length=120.0), 240, 30e3))
    for name, section, elements, wob in cases:
        fe, _, disc = lateral_modes(vertical_string([section], elements), wob)
        c = section_constants(section["outer_radius"], section["inner_radius"])
        m = RHO * c.area
        exact = tensioned_beam_frequencies(section["length"], E * c.I4, m, m * 9.81, wob, 5)
        unloaded = fe_family(solve_modes(disc, 0.05, assemble_linear(disc).mass, held=DRIVE, vectors=False),
                             "flexural", 10)[::2]
        out += [f"| {name} | {k + 1} | {f:.5g} | {x:.5g} | {abs(f / x - 1):.1e} | {u:.3g} |"
                for k, (f, x, u) in enumerate(zip(fe[:5], exact, unloaded))]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "modes_in_the_well.md")
    args = parser.parse_args()
    start = time.perf_counter()
    lines = ["# Modes in the well against exact references", "",
             f"Command: `python benchmarks/modes_in_the_well.py`. Machine: {os.cpu_count()} cores, "
             f"{platform.processor() or platform.machine()}, Python {platform.python_version()}. Steel: E = {E:.3g} Pa, "
             f"rho = {RHO:g} kg/m^3, nu = 0.3; strings hang in air in a vertical hole, full order, quadratic "
             "displacements and linear rotations.", "",
             "## Axial and torsional waves of a composite string", "",
             "Collars (60 m, 6.75 x 2.81 in), heavy-weight (90 m, 5 x 3 in), drill pipe (350 m, 5 x 4.276 in); "
             "1000 elements.  Reference: the roots of the transfer matrix of the three sections.", "",
             "| waves, ends | mode | FE [Hz] | transfer matrix [Hz] | relative error |", "|---|---|---|---|---|",
             *composite_rows(), "",
             "## Tool joints: homogenised against discrete", "",
             "470 m of 5 in drill pipe with 6 5/8 x 3 1/4 in tool joints, 0.5 m every 9.4 m, held by the drive; "
             "470 elements.  FE: the joints homogenised over the pitch (series stiffness, mean inertia).  Reference: "
             "the transfer matrix with each of the 50 joints its own segment.  Last column: the same reference with "
             "the joints' steel as mass alone (their stiffness left out).", "",
             "| waves | mode | FE [Hz] | discrete joints [Hz] | FE error | mass alone |", "|---|---|---|---|---|---|",
             *joint_rows(), "",
             "## Lateral modes about the static state", "",
             "Held by the drive at the top (clamped), pinned at the bit; linearised about the static state (its "
             "tension and weight on bit).  Reference: (EI y'')'' - (T y')' + m y_tt = 0 with T(s) = w (L - s) - P, "
             "Chebyshev collocation converged to 1e-6.  Last column: the unloaded string's mode (the stiffness (46) "
             "alone), what `modal` reported before it knew the tension.", "",
             "| string | mode | FE [Hz] | tensioned beam [Hz] | relative error | unloaded [Hz] |",
             "|---|---|---|---|---|---|", *lateral_rows(), "",
             f"Wall time {time.perf_counter() - start:.0f} s."]
    args.table.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
