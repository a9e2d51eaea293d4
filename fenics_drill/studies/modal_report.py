"""``fenics-drill modal``: the modal analysis of a scene as a JSON-ready report (DIR/modes.json).

The modes of (62) about the state ``modal.state`` says: the stiffness (46) of the unloaded string, or the tangent
stiffness about the operation's static state (:mod:`fenics_drill.studies.operating_state`: the hanging tension,
the weight on bit of ``modal.weight_on_bit`` (-1: the run's start, on or off bottom) and the wall springs); 'auto' takes the static state in a well and the
unloaded string in the paper's straight hole.  Three spectra of the band B, one per set of end conditions a run
meets: free-free (Eq. 62 as the paper solves it), held by the drive at the top with the bit off bottom, and held
by the drive with the bit stuck (theta_x held at x = L).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from fenics_drill.forms import FIELD_NAMES
from fenics_drill.io.files import write_json
from fenics_drill.model.discretization import DRIVE, THETA_X, BeamDiscretization
from fenics_drill.model.operators import assemble_linear
from fenics_drill.model.reduction.modes import (ModalBasis, drive_held_modes, family_counts, select_modes,
                                                solve_modes, stuck_bit_modes)
from fenics_drill.model.reduction.spaces import solution_space
from fenics_drill.model.well import check_string_in_well
from fenics_drill.studies.lifecycle import command_output
from fenics_drill.studies.operating_state import (REPORTED_MODES, linearised_state, loaded_stiffness, operating_state,
                                                  unstable_modes)

#: The end conditions of each spectrum: the (field, end) pairs held besides the supports, and how they read.
SPECTRA = {
    "free_free": ((), []),
    "drive_held_bit_off_bottom": (DRIVE, ["u(0)", "theta_x(0)"]),
    "drive_held_bit_stuck": ((*DRIVE, (THETA_X, 1)), ["u(0)", "theta_x(0)", "theta_x(L)"]),
}
#: Lateral modes whose synchronous critical speeds (order 1: f = Omega / 2 pi) the report states.
CRITICAL_SPEEDS = 3


def _mode_rows(basis: ModalBasis) -> list[dict]:
    return [{"frequency_hz": float(f), "f_star": float(fs), "kind": kind,
             "energy_fractions": dict(zip(FIELD_NAMES, map(float, fr)))}
            for f, fs, kind, fr in zip(basis.frequencies_hz, basis.f_star, basis.kinds, basis.energy_fractions)]


def _spectra(scene, disc, operators, free: ModalBasis, loaded) -> dict:
    """The three spectra of :data:`SPECTRA` (ModalBasis each, no vectors): with the stiffness ``loaded`` (on every
    dof), or of the unloaded string (None), whose drive-held and stuck-bit spectra come from the free one and the
    axial and torsional blocks."""
    f_star_max = scene.modal.f_star_max
    if loaded is not None:
        return {name: solve_modes(disc, f_star_max, operators.mass, held=held, vectors=False, stiffness=loaded)
                for name, (held, _) in SPECTRA.items()}
    held = drive_held_modes(disc, free, f_star_max, operators.mass, operators.stiffness)
    stuck = stuck_bit_modes(disc, f_star_max, operators.mass, operators.stiffness)
    others = held.select(np.flatnonzero(np.array(held.kinds) != "torsional"))
    both = ModalBasis(*(np.concatenate([a, b]) for a, b in ((others.frequencies_hz, stuck.frequencies_hz),
                                                           (others.f_star, stuck.f_star))),
                      others.kinds + stuck.kinds, np.concatenate([others.energy_fractions, stuck.energy_fractions]),
                      None)
    return {"free_free": free, "drive_held_bit_off_bottom": held,
            "drive_held_bit_stuck": both.select(np.argsort(both.frequencies_hz, kind="stable"))}


def spectra_summary(spectra: dict, buckled: bool = False) -> dict:
    """The drilling engineer's reading of the spectra: the first torsional mode of the drive-held string with the
    bit off bottom (its period, the time scale of torsional stick-slip) and the synchronous critical speeds of its
    first lateral modes (rotation speed = lateral frequency, order 1); none for a ``buckled`` string, which has no
    critical speed."""
    held = spectra["drive_held_bit_off_bottom"]
    kinds = np.array(held.kinds)
    torsional = held.frequencies_hz[(kinds == "torsional") & (held.frequencies_hz > 0)]
    lateral = [] if buckled else held.frequencies_hz[kinds == "flexural"][:CRITICAL_SPEEDS]
    return {
        "first_torsional_frequency_hz": float(torsional[0]) if torsional.size else None,
        "first_torsional_period_s": float(1.0 / torsional[0]) if torsional.size else None,
        "lateral_critical_speeds_rpm": [float(60.0 * f) for f in lateral],
    }


def buckling_report(buckled: list[dict], weight_on_bit: float) -> dict | None:
    """What ``modal`` says of a buckled static state: the load, the modes without stiffness, where they bend."""
    if not buckled:
        return None
    first = buckled[0]
    return {"weight_on_bit_N": weight_on_bit, "mode_count": len(buckled), "modes": buckled[:REPORTED_MODES],
            "message": f"the string is buckled at {weight_on_bit / 1e3:.4g} kN on the bit: {len(buckled)} mode(s) of "
                       f"the drive-held string have no positive stiffness (the first, {first['kind']}, bends most "
                       f"at {first['largest_lateral_displacement_at_m']:.0f} m); its static state is not stable and "
                       "it has no critical speed: lower modal.weight_on_bit (the soft string's buckling loads: "
                       "fenics-drill torque-drag)"}


def modal_report(scene) -> dict:
    """full_dofs, every free-free mode (frequency_hz, f_star, kind, energy fractions), the spectra of the run's end
    conditions about the state ``modal.state`` chooses, the reduced basis (the modes the rule keeps of the same
    free-free spectrum, Table 4, the 'auto' rule's stuck-bit torsional modes, and the vectors the guard adds) and
    the guard's report."""
    check_string_in_well(scene)
    disc = BeamDiscretization.from_scene(scene)
    operators = assemble_linear(disc)
    loaded, about = None, {"state": "unloaded"}
    if linearised_state(scene) == "static":
        state = operating_state(scene, disc, operators, scene.modal_weight_on_bit, on_wall=True)
        loaded, about = loaded_stiffness(scene, disc, operators, state), state.about
    space, _, basis, guard, stuck = solution_space(scene, disc, operators,
                                                   None if loaded is None else lambda *_: loaded)
    kept = [int(i) for i in select_modes(basis, scene)]
    spectra = _spectra(scene, disc, operators, basis, loaded)
    reduced = {
        "rule": scene.reduction.rule,
        "size": len(kept),
        "counts": family_counts(basis.kinds[i] for i in kept),
        "mode_indices": kept,  # into "modes": the free-free spectrum the basis is chosen from
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
    free = spectra["free_free"]
    buckled = buckling_report(unstable_modes(scene, disc, operators, state), about.get("weight_on_bit_N", 0.0)) \
        if loaded is not None else None
    return {
        "full_dofs": disc.ndofs,
        "element_degree": disc.element_degree,
        "elements": disc.elements,
        "supports": disc.supports,
        "longitudinal_wave_speed": disc.properties.longitudinal_wave_speed,
        "torsion": disc.properties.torsion,
        "linearised_about": about,
        "modes": _mode_rows(free),
        "spectra": {name: {"held": SPECTRA[name][1], "modes": _mode_rows(spectrum)}
                    for name, spectrum in spectra.items()},
        **spectra_summary(spectra, buckled is not None),
        "buckled": buckled,
        "reduced_basis": reduced,
    }


def write_modal_report(scene, out: str | Path, overwrite: bool = False) -> dict:
    """``fenics-drill modal``: DIR/modes.json (the report) and DIR/summary.json (status, wall time); the figure of
    the spectra: ``fenics-drill plot DIR``."""
    with command_output(out, "modal", scene, overwrite) as summary:
        start = time.perf_counter()
        report = modal_report(scene)
        report["wall_time_s"] = time.perf_counter() - start
        write_json(Path(out) / "modes.json", report)
        summary["message"] = "modes.json"
    return report
