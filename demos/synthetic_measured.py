"""Write a synthetic measured file for the VBH demo well (``demos/scenes/well_vbh_measured.csv``): the soft string's
indicated pick-up, slack-off and rotating hook loads and off- and on-bottom torques every three stands, from known
friction factors (cased 0.22, open hole 0.28) and the scene's 40 t block, with 1.5 % Gaussian noise (seeded) and
rounded as a rig's sensors print them (0.1 klbf, 0.1 kft lbf).  It is synthetic, and says so in its header: a
calibration of it (``fenics-drill calibrate``) should find the factors it was made from, within its interval.

    python demos/synthetic_measured.py [--out demos/scenes/well_vbh_measured.csv]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import fenics_drill as fd
from fenics_drill.studies.calibration import Calibration

ROOT = Path(__file__).parents[1]
TRUE_CASED, TRUE_OPEN, NOISE, SEED = 0.22, 0.28, 0.015, 20261202
KLBF, KFT_LBF = 4448.2216152605, 1355.8179483314004


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "demos" / "scenes" / "well_vbh_measured.csv")
    args = parser.parse_args()
    scene = fd.load_scene(ROOT / "demos" / "scenes" / "well_vbh.toml")
    depths = np.arange(3, 106, 3) * scene.broomstick.depth_step  # every three stands to the bottom
    depths = np.append(depths[depths < 3000.0], 3000.0)
    empty = {"bit_depth": depths, **{c: np.zeros_like(depths) for c in ("pick_up", "slack_off", "rotating_off_bottom",
                                                                      "torque_off_bottom", "torque_on_bottom")}}
    model = Calibration(scene, empty).loads(np.array([[TRUE_CASED, TRUE_OPEN]]), scene.broomstick.block_weight)
    rng = np.random.default_rng(SEED)
    lines = [f"# SYNTHETIC measured loads of the VBH demo well, made by demos/synthetic_measured.py from the soft string",
             f"# with friction factors {TRUE_CASED} (cased) and {TRUE_OPEN} (open hole), a 40 t block, and "
             f"{NOISE:.1%} Gaussian noise (seed {SEED}).",
             "bit_depth (m),pick_up (klbf),slack_off (klbf),rotating_off_bottom (klbf),torque_off_bottom (kft*lbf),"
             "torque_on_bottom (kft*lbf)"]
    for k, depth in enumerate(depths):
        noisy = {c: v[k, 0] * (1.0 + NOISE * rng.standard_normal()) for c, v in model.items()}
        lines.append(f"{depth:.1f},{noisy['pick_up'] / KLBF:.1f},{noisy['slack_off'] / KLBF:.1f},"
                     f"{noisy['rotating_off_bottom'] / KLBF:.1f},{noisy['torque_off_bottom'] / KFT_LBF:.1f},"
                     f"{noisy['torque_on_bottom'] / KFT_LBF:.1f}")
    args.out.write_text("\n".join(lines) + "\n")
    print(f"{len(depths)} points -> {args.out}")


if __name__ == "__main__":
    main()
