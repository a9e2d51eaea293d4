"""The paper scene with the bit's rows of the step's error estimate F times tighter (docs/verification.md,
"What the efficiency converges to").

    python benchmarks/bit_rows.py F [SECTION.KEY=VALUE ...]

The step control measures its local error on the lateral displacements and, at the bit, on the axial
displacement and the arc r theta_x (solvers/step_control.py).  Scaling the bit's two rows by F refines the
steps at the bit's stick-slip and bounce transitions only (F = 1: the default run).  Prints wall time,
steps, Newton iterations, rop and efficiency.
"""

from __future__ import annotations

import sys
import tempfile
import time

import fenics_drill  # noqa: F401  (dolfinx_solver and h5py first)
import fenics_drill.model.drillstring as drillstring
from fenics_drill.scene import load_scene
from fenics_drill.studies.run import run_scene


def main() -> None:
    factor, overrides = float(sys.argv[1]), sys.argv[2:]
    build = drillstring.DrillstringModel.__init__

    def tighter_at_the_bit(self, *args, **kwargs):
        build(self, *args, **kwargs)
        lateral_v, lateral_w, bit_axial, bit_arc = self.error_rows
        self.error_rows = (lateral_v, lateral_w, factor * bit_axial, factor * bit_arc)

    drillstring.DrillstringModel.__init__ = tighter_at_the_bit
    scene = load_scene("demos/scenes/paper.toml", ["output.field_interval=0", *overrides])
    with tempfile.TemporaryDirectory() as out:
        clock = time.perf_counter()
        s = run_scene(scene, out, progress=False, overwrite=True)
    print(f"F = {factor:g} {' '.join(overrides)}: wall {time.perf_counter() - clock:.1f} s, {s['steps']} steps, "
          f"{s['newton_iterations']} Newton iterations, rop {s['rop'] * 3600:.4f} m/h, "
          f"efficiency {s['efficiency']:.5f}")


if __name__ == "__main__":
    main()
