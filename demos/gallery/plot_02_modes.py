"""
Modes and the reduced basis
===========================

The modal problem (62) of the paper's string, solved with SLEPc, each mode classified as flexural,
torsional, axial or rigid by its kinetic-energy fractions; and the reduced basis the default rule keeps
(Section 6.3, Table 4). Frequencies are shown against the dimensionless f* = f L / c_L of Eq. (95).

The scene takes the paper's wall friction (18)-(19): with the default Coulomb force at the contact point the
spinning string climbs the wall, and the 'auto' rule takes the full order instead of a modal basis.
"""

# %%
from pathlib import Path

import matplotlib.pyplot as plt

import fenics_drill as fd

scene = fd.load_scene(Path(fd.__file__).parents[1] / "demos" / "scenes" / "paper.toml",
                      ["contact.friction_model='paper'", "contact.sliding_velocity_scale=1e-3"])
report = fd.modal_analysis(scene)
basis = report["reduced_basis"]
print(f"{report['full_dofs']} unknowns, {len(report['modes'])} modes with f* <= {scene.modal.f_star_max}")
print(f"reduced basis ('{basis['rule']}'): {basis['size']} modes {basis['counts']}, {basis['unknowns']} unknowns")

# %%
# The spectrum by kind
# --------------------
# Flexural modes crowd the low frequencies of a long string; torsional and axial ones are spaced
# evenly, at n c / 2L.

fig, ax = plt.subplots(figsize=(7, 3.2))
kept = set(basis["mode_indices"])
markers = {"flexural": "o", "torsional": "s", "axial": "^", "rigid": "x"}
for kind, marker in markers.items():
    modes = [(i, m) for i, m in enumerate(report["modes"]) if m["kind"] == kind]
    if not modes:
        continue
    ax.scatter([m["f_star"] for _, m in modes], [m["frequency_hz"] for _, m in modes], marker=marker,
               s=[28 if i in kept else 8 for i, _ in modes], label=f"{kind} ({len(modes)})")
ax.set(xlabel="f* = f L / c_L [-]", ylabel="frequency [Hz]", yscale="symlog",
       title="large markers: modes in the reduced basis")
ax.legend(loc="upper left", fontsize=8)
fig.tight_layout()
