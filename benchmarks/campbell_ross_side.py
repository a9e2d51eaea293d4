"""ROSS's half of benchmarks/campbell_ross.py: a pinned-pinned hollow shaft's Campbell diagram with
``ross.Rotor.run_campbell``, printed as JSON (run in a Python that has ross-rotordynamics; see the
Makefile's ``bench-ross`` target, which keeps it out of the project's .venv)."""

import json
import sys
import time

start = time.perf_counter()
import numpy as np  # noqa: E402
import ross as rs  # noqa: E402


def main(spec: dict) -> dict:
    n = spec["elements"]
    steel = rs.Material(name="steel", rho=spec["density"], E=spec["young_modulus"], Poisson=spec["poisson_ratio"])
    shaft = [rs.ShaftElement(L=spec["length"] / n, idl=2 * spec["inner_radius"], odl=2 * spec["outer_radius"],
                             material=steel, shear_effects=True, rotary_inertia=True, gyroscopic=True)
             for _ in range(n)]
    # pinned: a translational spring stiff enough to hold v = w = 0, no rotational stiffness
    bearings = [rs.BearingElement(n=node, kxx=spec["support_stiffness"], cxx=0.0) for node in (0, n)]
    rotor = rs.Rotor(shaft, bearing_elements=bearings)
    speeds = np.linspace(*spec["speeds_rad_s"])
    campbell = rotor.run_campbell(speeds, frequencies=spec["modes"])
    wd = np.asarray(campbell.wd)  # rad/s, (speeds, modes)
    whirl = np.asarray(campbell.whirl_values)
    return {"frequency_hz": (wd / (2 * np.pi)).tolist(), "whirl_values": whirl.tolist(),
            "shear_factor": float(shaft[0].kappa) if hasattr(shaft[0], "kappa") else None,
            "wall_time_s": time.perf_counter() - start}


if __name__ == "__main__":
    print(json.dumps(main(json.loads(sys.argv[1]))))
