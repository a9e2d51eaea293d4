"""``fenics-drill modal``: the modal analysis of a scene as a JSON-ready report (DIR/modes.json)."""

from __future__ import annotations

import time
from pathlib import Path

from fenics_drill.forms import FIELD_NAMES
from fenics_drill.io.files import write_json
from fenics_drill.model.discretization import BeamDiscretization
from fenics_drill.model.reduction.modes import family_counts, select_modes
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.reduction.spaces import solution_space
from fenics_drill.studies.lifecycle import command_output


def modal_report(scene) -> dict:
    """full_dofs, every mode (frequency_hz, f_star, kind, energy fractions), the reduced basis (the modes
    the rule keeps, Table 4, the 'auto' rule's stuck-bit torsional modes, and the vectors the guard
    adds) and the guard's report."""
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    space, _, basis, guard, stuck = solution_space(scene, disc, operators)
    kept = [int(i) for i in select_modes(basis, scene)]
    modes = [
        {
            "frequency_hz": float(f),
            "f_star": float(fs),
            "kind": kind,
            "energy_fractions": dict(zip(FIELD_NAMES, map(float, fr))),
        }
        for f, fs, kind, fr in zip(basis.frequencies_hz, basis.f_star, basis.kinds, basis.energy_fractions)
    ]
    reduced = {
        "rule": scene.reduction.rule,
        "size": len(kept),
        "counts": family_counts(basis.kinds[i] for i in kept),
        "mode_indices": kept,
        "stuck_bit_modes_hz": [] if stuck is None else [float(f) for f in stuck.frequencies_hz],
        "enrichment_vectors": space.size - len(kept) - (0 if stuck is None else len(stuck)),
        "unknowns": space.size,
        "guard": guard,
    }
    if scene.reduction.rule == "none":  # full order: the FE space itself, no modal basis
        reduced = {"rule": "none", "size": disc.ndofs, "counts": None, "mode_indices": None}
    elif "full_order" in guard:  # the 'auto' rule chose the full order (the guard says why)
        reduced = {"rule": scene.reduction.rule, "size": disc.ndofs, "counts": None, "mode_indices": None,
                   "unknowns": disc.ndofs, "guard": guard}
    return {
        "full_dofs": disc.ndofs,
        "element_degree": disc.element_degree,
        "elements": disc.elements,
        "supports": disc.supports,
        "longitudinal_wave_speed": disc.properties.longitudinal_wave_speed,
        "modes": modes,
        "reduced_basis": reduced,
    }


def write_modal_report(scene, out: str | Path, overwrite: bool = False) -> dict:
    """``fenics-drill modal``: DIR/modes.json (the report) and DIR/summary.json (status, wall time)."""
    with command_output(out, "modal", scene, overwrite) as summary:
        start = time.perf_counter()
        report = modal_report(scene)
        report["wall_time_s"] = time.perf_counter() - start
        write_json(Path(out) / "modes.json", report)
        summary["message"] = "modes.json"
    return report
