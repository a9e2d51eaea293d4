"""The period of an irregular or multi-slip stick-slip cycle read two ways, on the cases of Aarsnes & van de Wouw's
published axial-torsional model (their MAIN.m's six (omega0, v0)): benchmarks/results/stick_slip_irregular_cycles.md.

    python benchmarks/stick_slip_irregular_cycles.py

For each case, the compiled steps on 10 m elements and the same string and law solved exactly along the
characteristics (1.25 m cells; tests/torsional_waves.py), over the whole cycles in [60, 120] of their time units:
the period between rises of the bit's spin through omega0 (``period_s`` of a map), the dominant period of the spin
(``dominant_period_s``), each cycle's fastest spin (median, 10th-90th percentile) and the stuck share.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from published_axial_torsional_model import AFTER, DURATION, peaks_cell, scaled_statistics  # noqa: E402
from speed import machine, write_result  # noqa: E402
from torsional_waves import moving_top_cutting_law_case, published_scales  # noqa: E402

from fenics_drill.studies.stick_slip import start  # noqa: E402

#: Their MAIN.m's cases: (omega0, v0) in their units.
CASES = ((1.0, 2.0), (1.8, 2.0), (3.2, 2.0), (2.2, 10.0), (3.5, 10.0), (6.3, 10.0))
CELL = 1.25


def row(label: str, series: dict, omega0: float, wall: float) -> str:
    m = scaled_statistics(series, omega0)
    line = (f"| {label} | {m['period']:.3f} | {m['dominant_period']:.3f} | {m['max_spin']:.3f} | {peaks_cell(m)} | "
            f"{m['stuck_share']:.3f} | {wall:.1f} |")
    print(line, flush=True)
    return line


def main() -> None:
    duration = DURATION * published_scales()["time"]
    rows = []
    for omega0, v0 in CASES:
        scene, exact_run = moving_top_cutting_law_case(omega0, 200, v0)
        clock = time.perf_counter()
        series = start(scene).run(duration)
        rows.append(row(f"{omega0:g}, {v0:g}, 10 m elements", series, omega0, time.perf_counter() - clock))
        clock = time.perf_counter()
        exact = exact_run(duration, CELL)
        rows.append(row(f"{omega0:g}, {v0:g}, exact characteristics", exact, omega0, time.perf_counter() - clock))
    lines = ["# The period of an irregular stick-slip cycle, read two ways", "",
             f"Command: `python benchmarks/stick_slip_irregular_cycles.py`. Machine: {machine()}; one process. "
             "Aarsnes & van de Wouw's cases (their MAIN.m; benchmarks/published_axial_torsional_model.py states them "
             f"for a 2000 m string), {DURATION:g} time units, statistics over the whole cycles in [{AFTER:g}, "
             f"{DURATION:g}] in their units; exact: the characteristics on {CELL:g} m cells. Rises: the mean time "
             "between rises of the bit's spin through omega0 (a map's period_s); dominant: the period of the largest "
             "peak of the spin's spectrum (dominant_period_s); per cycle: each cycle's fastest spin, the median "
             "(10th-90th percentile).", "",
             "| omega0, v0, model | period, rises | period, dominant | fastest spin | per cycle | stuck share | "
             "wall [s] |", "|---|---|---|---|---|---|---|", *rows]
    write_result("stick_slip_irregular_cycles.md", lines)


if __name__ == "__main__":
    main()
