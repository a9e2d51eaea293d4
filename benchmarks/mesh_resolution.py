"""How well a mesh carries the band of analysis: the paper scene's flexural frequencies against a 1000-element
reference, per mesh, with the nodes per flexural wavelength at f_max (fenics_drill/model/resolution.py).

    python benchmarks/mesh_resolution.py [--table benchmarks/results/mesh_resolution.md]

The modes are solved by field groups, so each bending plane's flexural frequencies come in order and the k-th of
one mesh is compared with the k-th of the reference.
"""

from __future__ import annotations

import argparse
import platform
from pathlib import Path

import numpy as np

import fenics_drill as fd
from fenics_drill.model.resolution import band_frequency, nodes_per_wavelength

ROOT = Path(__file__).parents[1]
SCENE = ROOT / "demos" / "scenes" / "paper.toml"


def flexural_by_plane(scene) -> dict[str, np.ndarray]:
    planes: dict[str, list] = {}
    for mode in fd.modal_analysis(scene)["modes"]:
        if mode["kind"] == "flexural":
            fractions = mode["energy_fractions"]
            planes.setdefault("v" if fractions.get("v", 0) > fractions.get("w", 0) else "w", []).append(
                mode["frequency_hz"])
    return {plane: np.sort(values) for plane, values in planes.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "mesh_resolution.md")
    args = parser.parse_args()
    reference = flexural_by_plane(fd.load_scene(SCENE, ["beam.elements=1000"]))
    top = band_frequency(fd.load_scene(SCENE))
    lines = ["# Flexural frequencies against the mesh: the paper scene", "",
             f"Command: `python benchmarks/mesh_resolution.py`. Machine: {platform.machine()}, Python "
             f"{platform.python_version()}. Reference: 1000 elements of degree 2. f_max = {top:.1f} Hz.", "",
             "| elements | nodes per wavelength at f_max | largest error above 0.75 f_max | largest error below 0.25 f_max |",
             "|---|---|---|---|"]
    for elements in (500, 250, 150, 100):
        scene = fd.load_scene(SCENE, [f"beam.elements={elements}"])
        got = flexural_by_plane(scene)
        high, low = [], []
        for plane, ref in reference.items():
            k = min(len(ref), len(got.get(plane, [])))
            error = np.abs(got[plane][:k] - ref[:k]) / ref[:k]
            high += list(error[ref[:k] > 0.75 * top])
            low += list(error[ref[:k] < 0.25 * top])
        lines.append(f"| {elements} | {nodes_per_wavelength(scene):.1f} | {max(high):.2%} | {max(low):.2%} |")
    args.table.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
