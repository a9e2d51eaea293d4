"""Cost and result of one run of the paper scene, or of a scene file: wall and CPU time, steps, Newton iterations,
rop, efficiency, peak von Mises stress (for before/after comparisons of the solver on a noisy machine).

    python benchmarks/run_cost.py ELEMENTS T_END RULE [SECTION.KEY=VALUE ...]
    python benchmarks/run_cost.py --scene FILE T_END [SECTION.KEY=VALUE ...]

e.g. ``python benchmarks/run_cost.py 1000 0.2 none time.dt=0.000616475`` for the full-order reference.
Run it with ``PYTHONPATH=<a checkout of another revision>`` to measure that revision instead (with a link
``fenics_drill/forms`` to its ``forms`` folder).
"""

from __future__ import annotations

import sys
import tempfile
import time

import dolfinx_solver  # noqa: F401  (before dolfinx: real PETSc/SLEPc)

from fenics_drill.scene import load_scene
from fenics_drill.studies.run import run_scene


def main() -> None:
    if sys.argv[1] == "--scene":
        path, t_end, *overrides = sys.argv[2:]
        scene = load_scene(path, [f"time.t_end={t_end}", "output.field_interval=0", *overrides])
    else:
        elements, t_end, rule, *overrides = sys.argv[1:]
        scene = load_scene("demos/scenes/paper.toml", [f"time.t_end={t_end}", "output.field_interval=0",
                                                       f"reduction.rule='{rule}'", f"beam.elements={elements}",
                                                       *overrides])
    with tempfile.TemporaryDirectory() as out:
        wall, cpu = time.perf_counter(), time.process_time()
        s = run_scene(scene, out, progress=False, overwrite=True)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(f"wall {wall:.1f} s, cpu {cpu:.1f} s, steps {s['steps']} ({s.get('compiled_steps', 0)} compiled, "
          f"{s.get('rejected_steps', 0)} rejected), Newton iterations {s['newton_iterations']}, "
          f"factorisations {s.get('factorisations', 0)}, "
          f"rop {s['rop'] * 3600:.4f} m/h, efficiency {s['efficiency']:.5f}, "
          f"max von Mises {s.get('max_von_mises', {'value': float('nan')})['value'] / 1e6:.3f} MPa")


if __name__ == "__main__":
    main()
