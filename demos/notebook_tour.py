# # fenics-drill from Python: a tour
#
# This file is a notebook in jupytext's "light" format: open it in Jupyter (with the
# jupytext extension) as a notebook, or run it as a plain script:
#
#     .venv/bin/python demos/notebook_tour.py --out out/tour
#
# It walks through the public API, `import fenics_drill as fd`, on the paper's nominal
# scene (Cunha Jr, Soize & Sampaio 2015, Section 6), with short simulated times so that
# the whole tour takes a minute or two on a laptop.

# +
import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fenics_drill as fd  # noqa: E402

parser = argparse.ArgumentParser(description="the API tour as a script")
parser.add_argument("--out", type=Path, default=Path("out/tour"))
args, _ = parser.parse_known_args()
out = args.out
out.mkdir(parents=True, exist_ok=True)
# -

# ## A scene
#
# A scene is a TOML file in SI units, validated into a typed, immutable object. Overrides
# use the command line's `section.key=value` form; `with_changes` derives a new scene.

scene = fd.load_scene(Path(__file__).parent / "scenes" / "paper.toml", ["time.t_end=0.5"])
print(f"{scene.beam.length:g} m string, {scene.beam.elements} elements, "
      f"{scene.drive.rotation_speed * 30 / 3.141592653589793:.0f} rpm")

# ## Modes (Eq. 62) and the reduced basis (Section 6.3)

modes = fd.modal_analysis(scene)
flexural = [m["frequency_hz"] for m in modes["modes"] if m["kind"] == "flexural"]
print(f"{len(modes['modes'])} modes in the band, reduced basis of {modes['reduced_basis']['size']}:",
      modes["reduced_basis"]["counts"])
print("lowest flexural frequencies [Hz]:", [round(f, 2) for f in flexural[:4]])

# ## The string at rest on the borehole wall (Section 6.4)

rest = fd.static_state(scene)
print(f"max sag {rest['max_sag'] * 1e3:.2f} mm of a {rest['gap'] * 1e3:.0f} mm gap")

# ## Drilling (Sections 6.5-6.8)
#
# `fd.run` writes the run's files (summary, time series, ParaView fields) into a directory
# and returns the summary and the time series as an `xarray.Dataset`.

run = fd.run(scene, out=out / "run", overwrite=True)  # overwrite: replace the run of an earlier tour
print(f"{run.summary['status']}: rop {run.summary['rop'] * 3600:.2f} m/h, "
      f"efficiency {run.summary['efficiency']:.1%}, max von Mises {run.summary['max_von_mises']['value'] / 1e6:.1f} MPa")
series = run.series
fig, ax = plt.subplots(figsize=(7, 3))
(series["bit_angular_velocity"] * 30 / 3.141592653589793).plot(ax=ax)
ax.set(ylabel="bit speed [rpm]", title="stick-slip seen at the bit")
fig.tight_layout()
fig.savefig(out / "bit_speed.png")

# The paper's figures of the run come from its files:

print([p.name for p in fd.plot(out / "run")][:6], "...")

# ## Uncertain bit-rock law: Monte Carlo (Section 6.11)
#
# Realisations are spread over MPI ranks when the script runs under `mpiexec`.

# (0.2 s are dominated by the start-up from rest: the paper's study runs 10 s.)
short = scene.with_changes(time={"t_end": 0.2})
mc = fd.monte_carlo(short, samples=4, out=out / "mc", resume=True)
print(f"rop over 4 realisations: {mc['rop']['mean'] * 3600:.2f} m/h "
      f"[{mc['rop']['p2.5'] * 3600:.2f}, {mc['rop']['p97.5'] * 3600:.2f}]")

# ## The operating window (Sections 6.9-6.10)

window = fd.operating_window(short.with_changes(optimize={"axial_velocity": [1 / 360, 1 / 180, 2],
                                                          "rotation_speed": [4.0, 6.0, 2]}),
                             out=out / "window", resume=True)
best = window["optimum"]
print(f"best rop {best['objective'] * 3600:.2f} m/h at V0 = {best['axial_velocity'] * 3600:.1f} m/h, "
      f"{best['rotation_speed'] * 30 / 3.141592653589793:.0f} rpm")
