"""
A first drilling run
====================

The paper's nominal scene (a 100 m string of steel pipe on the low side of a horizontal hole, pushed at
20 m/h and turned at 60 rpm) for half a second: the static equilibrium on the wall, then the drilling
dynamics. ``fd.run`` writes the run's files into a directory and returns its summary and its time series as an
``xarray.Dataset``.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import fenics_drill as fd

scenes = Path(fd.__file__).parents[1] / "demos" / "scenes"
scene = fd.load_scene(scenes / "paper.toml", ["time.t_end=0.5", "output.field_interval=0"])
run = fd.run(scene, out=Path(tempfile.mkdtemp()) / "run")
s = run.summary
print(f"{s['status']}: {s['steps']} steps, reduced model of {s['reduced_size']} unknowns")
print(f"rop {s['rop'] * 3600:.2f} m/h, efficiency {s['efficiency']:.1%}, "
      f"peak von Mises {s['max_von_mises']['value'] / 1e6:.1f} MPa")

# %%
# The bit: axial velocity and spin
# ---------------------------------
# At t = 0 the string moves at the drive's speed against the rock, which brakes the bit within
# microseconds; the spin then sticks and slips (torsional stick-slip) about the drive's 60 rpm.

series = run.series
t = series["time"].values
fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
top.plot(t, series["bit_velocity"].values * 3600, lw=0.8)
top.axhline(scene.drive.axial_velocity * 3600, color="0.5", ls="--", lw=0.8, label="feed V0")
top.set_ylabel("bit axial velocity [m/h]")
top.legend(loc="lower right")
bottom.plot(t, series["bit_angular_velocity"].values * 30 / np.pi, lw=0.8)
bottom.axhline(scene.drive.rotation_speed * 30 / np.pi, color="0.5", ls="--", lw=0.8, label="drive speed")
bottom.set(xlabel="time [s]", ylabel="bit speed [rpm]")
bottom.legend(loc="lower right")
fig.tight_layout()

# %%
# Where the energy went
# ---------------------
# The energy budget books the drive's work, what each force dissipated and the change of the string's
# energy; it closes to the ``balance_error`` below.

energy = s["energy"]
print({name: f"{value / 1e3:.2f} kJ" for name, value in energy["dissipated_by"].items()})
print(f"balance error {energy['balance_error']:.1e}")
