"""Which printed law makes which published phenomenon: 3 s of the nominal scene with the
laws (18), (19), (21) as printed one at a time and together, with both kinematics.

    python benchmarks/printed_laws.py [--t-end 3] [--runs out/reproduction] [--table docs/printed_laws.md]

Reuses ``RUNS/<name>`` when its summary says the run finished.
"""

from __future__ import annotations

from scene_runs import run_once, study_arguments, write_table

#: The paper's friction laws (18)-(19), whose printed signs the cases switch on; the table compares laws one at a
#: time, so every case takes them (the default is the Coulomb force at the contact point).
PAPER_FRICTION = ["contact.friction_model=paper", "contact.sliding_velocity_scale=1e-3"]

CASES = {
    "consistent_objectivekin": ("consistent laws, objective kinematics", [*PAPER_FRICTION]),
    "all_objectivekin": ("all three laws printed, objective kinematics", [*PAPER_FRICTION, "model.laws=printed"]),
    "consistent_printedkin": ("consistent laws, printed kinematics (14)", [*PAPER_FRICTION, "model.kinematics=printed"]),
    "axial_printedkin": ("axial friction (18) printed, kinematics (14)",
                         [*PAPER_FRICTION, "model.kinematics=printed", "contact.axial_friction_law=printed"]),
    "torque_printedkin": ("friction torque (19) printed, kinematics (14)",
                          [*PAPER_FRICTION, "model.kinematics=printed", "contact.friction_torque_law=printed"]),
    "bit_printedkin": ("bit torque (21) printed, kinematics (14)",
                       [*PAPER_FRICTION, "model.kinematics=printed", "bit_rock.torque_law=printed"]),
    "all_printedkin": ("every law as printed (demos/scenes/paper_as_printed.toml)",
                       [*PAPER_FRICTION, "model.kinematics=printed", "model.laws=printed"]),
}


def main() -> None:
    args = study_arguments(__doc__, 3.0, "out/reproduction", "docs/printed_laws.md")
    lines = [f"# The printed laws one at a time: `demos/scenes/paper.toml`, {args.t_end} s", "",
             f"Command: `python benchmarks/printed_laws.py --t-end {args.t_end}` (reduced model, default basis). "
             "V0 = 20 m/h, Omega = 60 rpm. Work: what each printed law put into the string (kJ).", "",
             "| laws | rop [m/h] | bit off bottom | u̇_bit / V0 | ω_bit / Ω | stick-slip severity | efficiency "
             "| impacts | shock packages | max σ_VM [MPa] | work of the printed laws [kJ] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, (label, overrides) in CASES.items():
        s = run_once(args.runs / name, args.t_end, overrides)
        bounce, slip = s["bit_bounce"], s["stick_slip"]
        injected = ", ".join(f"{k} {v / 1e3:.2f}" for k, v in s["energy"]["injected_by"].items()) or "—"
        lines.append(f"| {label} | {s['rop'] * 3600:.2f} | {bounce['off_bottom_fraction']:.2%} | "
                     f"{bounce['velocity_min_ratio']:.1f} … {bounce['velocity_max_ratio']:.1f} | "
                     f"{slip['omega_min_ratio']:.2f} … {slip['omega_max_ratio']:.2f} | {slip['stick_slip_severity']:.2f} | "
                     f"{s['efficiency']:.1%} | {s['impacts_total']} | {s['shock_packages']} | "
                     f"{s['max_von_mises']['value'] / 1e6:.0f} | {injected} |")
    write_table(args.table, lines)


if __name__ == "__main__":
    main()
