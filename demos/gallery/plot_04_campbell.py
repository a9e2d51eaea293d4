"""
Critical speeds of a spinning string
====================================

The Campbell diagram of a 10 m length of the paper's pipe, pinned at both ends: the whirl frequencies of
the string linearised about a steady spin, with the gyroscopic coupling that splits each bending pair into a
forward and a backward whirl. Critical speeds are where a branch meets an excitation line n Omega.
"""

# %%
import tempfile
from pathlib import Path

import fenics_drill as fd

scene = fd.load_scene(Path(fd.__file__).parents[1] / "demos" / "scenes" / "campbell_paper.toml", [
    "beam.length=10.0", "beam.elements=40", "model.supports='pinned'", "campbell.state='straight'", "campbell.modes=6",
    "campbell.rotation_speed=[0.0, 300.0, 13]", "campbell.excitation_orders=[1.0]"])
out = Path(tempfile.mkdtemp()) / "campbell"
report = fd.campbell(scene, out=out)
for crossing in report["critical_speeds"][:4]:
    print(crossing)

# %%
# The diagram, as ``fenics-drill plot`` draws it
# ----------------------------------------------

import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

figure = fd.plot(out)[0]
fig, ax = plt.subplots(figsize=(8, 5))
ax.imshow(mpimg.imread(figure))
ax.set_axis_off()
fig.tight_layout()
