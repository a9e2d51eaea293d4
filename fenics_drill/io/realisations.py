"""Monte Carlo realisation files: ``DIR/realisations/NNNNNN.h5`` and ``DIR/nominal.h5``.

A realisation file holds, on the common grid of ``uncertainty.output_interval``, the
histories of :data:`fenics_drill.studies.prepare.HISTORIES`; and as attributes its
bit-rock parameters, status, rop, efficiency, mean bit velocity, max von Mises stress
and int ||q||^2 dt (for (101)).  Each is written through a temporary file renamed into
place (:func:`fenics_drill.io.files.write_atomic`), so a killed study leaves no
half-written result; a file broken otherwise is named by :func:`read_realisation`.
"""

from __future__ import annotations

from pathlib import Path

import h5py

from fenics_drill.io.files import UnreadableFile, write_atomic

#: Scalars kept per realisation.
SCALARS = ("rop", "efficiency", "efficiency_torque_magnitude", "signed_rop", "mean_bit_velocity", "max_von_mises",
           "q_norm_integral")
#: The realisation with the nominal bit-rock law.
NOMINAL = "nominal.h5"


def realisation_path(out: Path, k: int) -> Path:
    return out / "realisations" / f"{k:06d}.h5"


def write_realisation(path: Path, result: dict) -> None:
    """Write a realisation's result atomically: a temporary file renamed into place."""

    def write(tmp: Path) -> None:
        with h5py.File(tmp, "w") as f:
            f["time"] = result["time"]
            f["time"].attrs["units"] = "s"
            for name, values in result["histories"].items():
                f[name] = values
            for key in ("status", "message", "wall_time_s", "steps", *SCALARS):
                f.attrs[key] = result[key]
            for key, value in result["bit_rock"].items():
                f.attrs[f"bit_rock.{key}"] = value

    write_atomic(path, write)


def read_realisation(path: Path, histories: bool = True) -> dict:
    """A realisation's attributes, and with ``histories`` its time grid and histories; UnreadableFile
    naming the file if it is not a whole realisation."""
    try:
        with h5py.File(path, "r") as f:
            out = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
            if histories:
                out["time"] = f["time"][()]
                out["histories"] = {name: f[name][()] for name in f if name != "time"}
            missing = {"status", "q_norm_integral"} - set(out)
    except (OSError, KeyError) as err:
        raise UnreadableFile(f"{path} is not a readable realisation file (truncated or corrupt?): {err}") from err
    if missing:
        raise UnreadableFile(f"{path} is not a whole realisation file: {', '.join(sorted(missing))} missing")
    return out
