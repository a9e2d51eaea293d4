"""
Drilling a well on bottom
=========================

The worked example of the manual's "Drilling your well" page, short: the build-and-hold well of
``demos/scenes/well_build_hold.toml`` (900 m, 10.4 ppg mud, an 8 1/2 in cutting bit at 40 kN and 60 rpm), its soft
string's torque and drag, the finite-element string at rest with the bit pressed at the set weight on bit, and
0.3 s of drilling on bottom with the hook-load drive holding it.
"""

# %%
from pathlib import Path
import tempfile

import matplotlib.pyplot as plt

import fenics_drill as fd

scene = fd.load_scene(Path(fd.__file__).parents[1] / "demos" / "scenes" / "well_build_hold.toml",
                      ["beam.elements=150"])
td = fd.torque_drag(scene)
on_bottom = td.report["operations"]["rotating_on_bottom"]
print(f"soft string, rotating on bottom: hook load {on_bottom['hook_load_N'] / 1e3:.1f} kN, "
      f"surface torque {on_bottom['surface_torque_Nm'] / 1e3:.2f} kN m")

# %%
# At rest on bottom
# -----------------
# The hook-load drive starts the string on bottom: the static state with 40 kN on the bit.

rest = fd.static_state(scene)
print(f"FE string at rest, the bit pressed at {rest['weight_on_bit'] / 1e3:.0f} kN: hook load "
      f"{rest['hook_load'] / 1e3:.1f} kN")

# %%
# Drilling on bottom
# ------------------
# 0.3 s with the drawworks holding the hook load that leaves 40 kN on the bit.

run = fd.run(scene.with_changes(time={"t_end": 0.3}, output={"field_interval": 0.0}),
             out=Path(tempfile.mkdtemp()) / "run")
series = run.series
fig, (top, bit) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
top.plot(series["time"], series["lambda_1"] / 1e3, label="hook load (drive)")
top.axhline(on_bottom["hook_load_N"] / 1e3, color="k", ls="--", lw=1, label="soft string, rotating on bottom")
top.set_ylabel("hook load [kN]")
top.legend(fontsize=8)
bit.plot(series["time"], -series["bit_force"] / 1e3)
bit.axhline(40.0, color="k", ls="--", lw=1)
bit.set_xlabel("time [s]")
bit.set_ylabel("weight on bit [kN]")
fig.tight_layout()
