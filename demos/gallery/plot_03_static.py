"""
The string at rest on the wall
==============================

Under its own weight the paper's string sags onto the low side of the hole (Section 6.4). The static
equilibrium is solved in the full order with the wall's Hunt-Crossley springs (17), and is the initial
state of every drilling run.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import meshio

import fenics_drill as fd

scene = fd.load_scene(Path(fd.__file__).parents[1] / "demos" / "scenes" / "paper.toml")
out = Path(tempfile.mkdtemp()) / "static"
rest = fd.static_state(scene, out=out)
print(f"max sag {rest['max_sag'] * 1e3:.3f} mm (gap {rest['gap'] * 1e3:.0f} mm), "
      f"{len(rest['contact_vertices'])} vertices on the wall")

# %%
# Sag along the string
# --------------------
# ``static.xdmf`` holds the six fields at the mesh's vertices; ParaView opens it, and so does meshio.

with meshio.xdmf.TimeSeriesReader(str(out / "static.xdmf")) as reader:
    points, _ = reader.read_points_cells()
    _, fields, _ = reader.read_data(0)
x, w = points[:, 0], fields["w"][:, 0]
fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(x, w * 1e3, lw=1.2, label="string axis")
ax.axhline(-rest["gap"] * 1e3, color="0.3", lw=0.8, ls="--", label="borehole wall (low side)")
ax.set(xlabel="x [m]", ylabel="vertical displacement w [mm]")
ax.legend(loc="upper right")
fig.tight_layout()
