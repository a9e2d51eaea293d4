"""
Rotation takes the drag away
============================

A 20 m length of the paper's pipe lies on the low side of the hole and is pushed at 20 m/h, without a bit, at
several rotation speeds. The wall's friction is one Coulomb force at the contact point (the default): it opposes
the slip of the pipe's surface, whose axial share V0 / sqrt(V0^2 + (R_ext Omega)^2) is all that is left to drag
the string. The top's force, less the damping of the feed, against that closed form; and the string climbing the
wall while it spins.
"""

# %%
import math
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import fenics_drill as fd

feed = 20.0 / 3600.0
base = ["beam.length=20.0", "beam.elements=80", "model.bit_rock=false", "time.t_end=1.5",
        "output.field_interval=0", "beam.damping=20.0", f"drive.axial_velocity={feed}"]
scenes = Path(fd.__file__).parents[1] / "demos" / "scenes"
speeds = [0.0, 0.07, 0.15, 0.5]  # rad/s
shares, angles = [], []
for spin in speeds:
    scene = fd.load_scene(scenes / "paper.toml", [*base, f"drive.rotation_speed={spin}"])
    run = fd.run(scene, out=Path(tempfile.mkdtemp()) / "run")
    series = run.series
    late = series["time"].values > 1.0  # the climb has settled (the damping is raised for that)
    wall = run.summary["static"]["contact_force_total"]
    damping = scene.beam.damping * scene.beam_properties.mass_per_length * scene.beam.length * feed
    top = np.mean(-series["lambda_1"].values[late]) - damping
    shares.append(top / (scene.contact.friction * wall))
    angles.append((series["time"].values, np.degrees(np.arctan2(-series["section_v"].values,
                                                                -series["section_w"].values))))
print("drag / (mu N):", [f"{share:.3f}" for share in shares])

# %%
# The drag against the slip's direction
# -------------------------------------

radius = 0.08
ratio = np.linspace(0, 8, 200)
fig, ax = plt.subplots(figsize=(7, 3.6))
ax.plot(ratio, 1 / np.sqrt(1 + ratio**2), "k-", lw=1, label="V0 / |s|: one Coulomb force at the contact point")
ax.plot([radius * s / feed for s in speeds], shares, "o", color="tab:red", label="the runs (top force / mu N)")
ax.set(xlabel="surface speed over feed, R_ext Omega / V0 [-]", ylabel="drag / (mu N) [-]", ylim=(0, 1.05))
ax.grid(alpha=0.3)
ax.legend(loc="upper right", fontsize=8)
fig.tight_layout()

# %%
# The string climbs the wall while it spins
# -----------------------------------------
# The tangential friction pushes the string up the wall until gravity's share along it balances mu N:
# ``tan(phi) = mu s_t / |s|``.  Without spin it stays at the bottom.

fig, ax = plt.subplots(figsize=(7, 3.2))
for spin, (t, angle) in zip(speeds, angles):
    ax.plot(t, angle, lw=0.8, label=f"{spin * 30 / math.pi:.2g} rpm")
ax.set(xlabel="time [s]", ylabel="angle on the wall at mid-length [deg]")
ax.grid(alpha=0.3)
ax.legend(fontsize=8, ncol=3)
fig.tight_layout()
