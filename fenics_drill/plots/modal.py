"""The spectra of ``fenics-drill modal`` (DIR/modes.png): each set of end conditions on its own row, one mark per
mode at its frequency, coloured by kind, with the first torsional period and the lateral critical speeds stated."""

from __future__ import annotations

from pathlib import Path

from fenics_drill.plots.common import plt, save_figure

#: How each spectrum of modes.json reads on the figure.
LABELS = {"free_free": "free-free", "drive_held_bit_off_bottom": "drive-held,\nbit off bottom",
          "drive_held_bit_stuck": "drive-held,\nbit stuck"}
COLOURS = {"flexural": "tab:blue", "torsional": "tab:red", "axial": "tab:green", "rigid": "tab:gray"}
#: Each kind on its own line within a spectrum's row, so that no kind hides another.
OFFSETS = {"flexural": 0.0, "torsional": -0.22, "axial": 0.22, "rigid": 0.0}


def spectra_figure(report: dict, path: Path) -> Path:
    """The modes of each spectrum of ``report`` (modes.json) against frequency (log scale)."""
    spectra = report["spectra"]
    fig, ax = plt.subplots(figsize=(8, 1.2 + 0.9 * len(spectra)))
    for row, (name, spectrum) in enumerate(spectra.items()):
        for kind, colour in COLOURS.items():
            f = [m["frequency_hz"] for m in spectrum["modes"] if m["kind"] == kind and m["frequency_hz"] > 0]
            if f:
                ax.scatter(f, [row + OFFSETS[kind]] * len(f), marker="|", s=150, color=colour,
                           label=kind if row == 0 or kind not in ax.get_legend_handles_labels()[1] else None)
    ax.set_yticks(range(len(spectra)), [LABELS.get(name, name) for name in spectra])
    ax.set_ylim(-0.6, len(spectra) - 0.4)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("frequency [Hz]")
    about = report["linearised_about"]
    state = "unloaded string" if about["state"] == "unloaded" else \
        f"static state, weight on bit {about.get('weight_on_bit_N', 0.0) / 1e3:.3g} kN"
    facts = []
    if report.get("first_torsional_period_s"):
        facts.append(f"first torsional period {report['first_torsional_period_s']:.3g} s")
    if report.get("lateral_critical_speeds_rpm"):
        facts.append("lateral critical speeds " + ", ".join(f"{r:.3g}" for r in report["lateral_critical_speeds_rpm"])
                     + " rpm")
    ax.set_title(f"Modes about the {state}\n" + "; ".join(facts), fontsize=10)
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax.legend(unique.values(), unique.keys(), loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    return save_figure(fig, path)
