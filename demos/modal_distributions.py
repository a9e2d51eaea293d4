"""Figs. 10-12 (mode distributions versus f* for several slenderness ratios) and Table 4.

    python demos/modal_distributions.py --out out/modal-distributions [--docs docs]

Figures use 5 elements per metre for every length (mesh-converged up to f* = 4);
Table 4 uses the paper's meshes (L = 50, 100, 150 m on 50, 500, 750 elements,
i.e. the paper's 306, 3006, 4506 DoFs with 6 DoFs per node).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from fenics_drill.studies.modal_report import modal_report  # noqa: E402
from fenics_drill.scene import load_scene  # noqa: E402

SCENE = Path(__file__).parent / "scenes" / "paper.toml"
FIGURE_LENGTHS = (50.0, 100.0, 150.0, 200.0)
TABLE4 = ((50.0, 50, 306, 37), (100.0, 500, 3006, 49), (150.0, 750, 4506, 60))  # L, elements, paper DoFs, paper reduced
FIGURES = (("flexural", "fig10_flexural_modes.png"), ("torsional", "fig11_torsional_modes.png"),
           ("axial", "fig12_axial_modes.png"))


def report_for(length: float, elements: int) -> dict:
    """The modal report of the paper's string at this length and mesh, with the paper's wall friction: the modes do
    not depend on it, but Table 4 is the reduced basis the paper keeps, which the 'auto' rule chooses under that law
    (under the default Coulomb force the spinning string climbs the wall and the rule takes the full order)."""
    scene = load_scene(SCENE, [f"beam.length={length}", f"beam.elements={elements}", "contact.friction_model='paper'",
                                "model.torsion='printed'"])
    return modal_report(scene)


def plot_distribution(reports: dict[float, dict], kind: str, path: Path, diameter: float) -> None:
    """Top: one tick per mode at the height of its slenderness ratio. Bottom: cumulative count N(f*)."""
    figure_number = 10 + [k for k, _ in FIGURES].index(kind)
    fig, (strip, cumulative) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, height_ratios=(1, 1.3))
    styles = ("-", "--", "-.", ":")
    for (length, rep), style in zip(reports.items(), styles):
        f_star = np.sort([m["f_star"] for m in rep["modes"] if m["kind"] == kind])
        slenderness = length / diameter
        strip.plot(f_star, np.full_like(f_star, slenderness), "|", markersize=12)
        cumulative.step(np.concatenate([[0.0], f_star, [4.0]]), np.arange(len(f_star) + 2).clip(max=len(f_star)),
                        where="post", linestyle=style, lw=1.6, label=f"L/D = {slenderness:.0f} (L = {length:.0f} m)")
    strip.set_ylabel("slenderness L/D  [-]")
    strip.set_title(f"{kind.capitalize()} modes versus dimensionless frequency (cf. paper Fig. {figure_number})")
    strip.grid(alpha=0.3)
    cumulative.set_xlabel("dimensionless frequency f* = f L / c_L  [-]")
    cumulative.set_ylabel(f"number of {kind} modes below f*  [-]")
    cumulative.set_xlim(0, 4)
    cumulative.grid(alpha=0.3)
    cumulative.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def table4_markdown(rows: list[dict]) -> str:
    lines = [
        "| L (m) | elements | paper full DoFs | our full DoFs (P2/P1) | paper reduced | our reduced | rigid | flexural | torsional | axial |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        c = r["counts"]
        lines.append(
            f"| {r['length']:.0f} | {r['elements']} | {r['paper_full_dofs']} | {r['full_dofs']} | "
            f"{r['paper_reduced']} | {r['reduced']} | {c['rigid']} | {c['flexural']} | {c['torsional']} | {c['axial']} |"
        )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/modal-distributions")
    parser.add_argument("--docs", default=None, help="also write table4.md and the figures into this folder")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    diameter = 2 * load_scene(SCENE).beam.outer_radius

    reports = {}
    for length in FIGURE_LENGTHS:
        reports[length] = report_for(length, int(5 * length))
        print(f"L = {length:.0f} m: {len(reports[length]['modes'])} modes with f* <= 4", flush=True)
    for kind, name in FIGURES:
        plot_distribution(reports, kind, out / name, diameter)

    rows = []
    for length, elements, paper_dofs, paper_reduced in TABLE4:
        rep = report_for(length, elements)
        red = rep["reduced_basis"]
        rows.append({"length": length, "elements": elements, "paper_full_dofs": paper_dofs,
                     "full_dofs": rep["full_dofs"], "paper_reduced": paper_reduced,
                     "reduced": red["size"], "counts": red["counts"]})
    (out / "table4.json").write_text(json.dumps(rows, indent=1))
    table = table4_markdown(rows)
    (out / "table4.md").write_text(table)
    print(table)
    if args.docs:
        docs = Path(args.docs)
        (docs / "figures").mkdir(parents=True, exist_ok=True)
        (docs / "table4.md").write_text(
            "# Table 4: full and reduced model sizes\n\nGenerated by `python demos/modal_distributions.py "
            "--docs docs`; see `docs/errata.md` (Table 4) for why the counts differ from the paper.\n\n" + table
        )
        for _, name in FIGURES:
            (docs / "figures" / name).write_bytes((out / name).read_bytes())
    return 0


if __name__ == "__main__":
    sys.exit(main())
