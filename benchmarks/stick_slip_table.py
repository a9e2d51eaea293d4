"""The stick-slip maps of ``make stick-slip`` as Markdown tables (docs/guide/drilling_control.md).

    .venv/bin/python benchmarks/stick_slip_table.py out/stick-slip-stiff out/stick-slip-soft

Each cell: stick-slip severity (max - min) omega_bit / 2 Omega over the second half of the run; in bold with
the time stuck (omega_bit < 0.1 Omega) and off bottom where the bit sticks or bounces off.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path


def table(directory: Path) -> str:
    report = json.loads((directory / "optimize.json").read_text())
    rpm = [w * 60 / (2 * math.pi) for w in report["rotation_speed"]]
    lines = [f"{directory}: t_end = {report['t_end']:g} s", "",
             "| V0 \\ Omega | " + " | ".join(f"{x:.1f} rpm" for x in rpm) + " |", "|---|" + "---|" * len(rpm)]
    for i, v0 in enumerate(report["axial_velocity"]):
        cells = []
        for j in range(len(rpm)):
            severity = report["stick_slip_severity"][i][j]
            stuck, off = report["stick_fraction"][i][j], report["off_bottom_fraction"][i][j]
            if severity is None or not math.isfinite(severity):
                cells.append("failed")
            elif stuck > 0 or off > 0:
                cells.append(f"**{severity:.2f}** ({100 * stuck:.1f} % stuck, {100 * off:.1f} % off)")
            else:
                cells.append(f"{severity:.2f}")
        lines.append(f"| {v0 * 3600:.0f} m/h | " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    print("\n\n".join(table(Path(d)) for d in sys.argv[1:]))
