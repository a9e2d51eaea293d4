"""The paper's Section 6, as printed and consistent, side by side (docs/reproduction.md).

    python benchmarks/reproduction.py [--t-end 3] [--samples 32] [--ranks 2] [--runs out/reproduction]
                                      [--table docs/reproduction_numbers.md] [--figures docs/figures/reproduction]

Two models: ``consistent`` (demos/scenes/paper.toml, the defaults) and ``as_printed``
(demos/scenes/paper_as_printed.toml: kinematics (14), angular velocity (13), laws (18), (19), (21) as
printed, Table 4's basis).  For each: the nominal run (10 s; the as-printed one runs away after
about 8 s: docs/reproduction.md), the three operating windows of
demos/scenes/window_{efficiency,rop,robust}.toml and a Monte Carlo of --samples realisations, the
windows and the Monte Carlo over --t-end seconds, on --ranks MPI processes.  Every study resumes
where it stopped; a finished one is not run again.  Writes the numbers of the report into --table
and copies the figures, named ``<figure>_<model>.png``, into --figures.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from fenics_drill.io.timeseries import read_series
from fenics_drill.observables.drilling_quantities import drilling_quantities
from fenics_drill.plots.common import panels, save_figure

MODELS = {"consistent": "demos/scenes/paper.toml", "as_printed": "demos/scenes/paper_as_printed.toml"}
#: The consistent model takes the paper's friction laws (18)-(19) with consistent signs, so that the two models
#: differ by the printed signs alone (today's default friction, one Coulomb force at the contact point, is
#: compared with it in docs/reproduction.md, "The nominal scene with the Coulomb friction").
#: Both models keep the paper's torsional stiffness kappa_s G J (as_printed in its scene), so that they differ by the
#: laws this comparison is about; St-Venant's G J, the default, is in docs/verification.md.
MODEL_SETS = {"consistent": ["--set", "contact.friction_model=paper", "--set", "contact.sliding_velocity_scale=1e-3",
                             "--set", "model.torsion=printed"],
              "as_printed": []}
#: Nominal 10 s runs: the two models, and the as-printed one with one law changed (why it runs away).
NOMINALS = {
    "consistent": ("the paper's laws with consistent signs", MODELS["consistent"], []),
    "as_printed": ("every law as printed", MODELS["as_printed"], []),
    "as_printed_bit_torque_consistent": ("as printed, but the bit torque (21) consistent", MODELS["as_printed"],
                                         ["bit_rock.torque_law=consistent"]),
    "as_printed_damper_printed": ("as printed, and the damper (17) as printed", MODELS["as_printed"],
                                  ["contact.damper_law=printed"]),
}
WINDOWS = ("efficiency", "rop", "robust")
M_PER_H = 3600.0


def _command(*args: str, ranks: int = 1) -> list[str]:
    launcher = [str(Path(sys.executable).parent / "mpiexec"), "-n", str(ranks)] if ranks > 1 else []
    return [*launcher, sys.executable, "-m", "fenics_drill.cli", *args]


def _run(label: str, command: list[str], done: Path) -> float:
    """Runs ``command`` unless ``done`` exists; returns its wall time (0 when skipped)."""
    if done.exists():
        return 0.0
    print(f"[reproduction] {label}: {' '.join(command)}", flush=True)
    start = time.perf_counter()
    subprocess.run(command, check=False)
    return time.perf_counter() - start


def _resume(out: Path) -> list[str]:
    """--resume for a study an earlier run left its summary in (the commands refuse it for a directory without)."""
    return ["--resume"] if (out / "summary.json").exists() else []


def _window_overrides(window: str, t_end: float) -> list[str]:
    """The [optimize] keys of demos/scenes/window_<window>.toml as --set overrides, over t_end."""
    scene = tomllib.loads(Path(f"demos/scenes/window_{window}.toml").read_text())
    sets = [f"optimize.{key}={json.dumps(value)}" for key, value in scene["optimize"].items()]
    return [a for s in [*sets, f"time.t_end={t_end}"] for a in ("--set", s)]


def studies(args) -> dict:
    """Runs what is missing; returns {study: wall time [s]} of what ran now."""
    costs = {}
    for name, (_, scene, overrides) in NOMINALS.items():
        nominal = args.runs / f"nominal-{name}"
        sets = [*MODEL_SETS["consistent" if name == "consistent" else "as_printed"],
                *[a for o in ["time.t_end=10", *overrides] for a in ("--set", o)]]
        costs[nominal.name] = _run(f"nominal {name}", _command(
            "run", scene, *sets, "--quiet", "--overwrite", "--out", str(nominal)), nominal / "fig14_bit_axial.png")
        if not (nominal / "fig14_bit_axial.png").exists():
            subprocess.run(_command("plot", str(nominal), "--no-gif"), check=False)
    for model, scene in MODELS.items():
        for window in WINDOWS:
            out = args.runs / f"window-{window}-{model}"
            costs[out.name] = _run(f"{window} window {model}", _command(
                "optimize", scene, *MODEL_SETS[model], *_window_overrides(window, args.t_end), "--quiet", *_resume(out),
                "--out", str(out), ranks=args.ranks), out / "optimize.json")
            subprocess.run(_command("plot", str(out)), check=False)
        out = args.runs / f"mc-{model}"
        costs[out.name] = _run(f"Monte Carlo {model}", _command(
            "mc", scene, *MODEL_SETS[model], "--samples", str(args.samples), "--set", f"time.t_end={args.t_end}",
            "--quiet", *_resume(out),
            "--out", str(out), ranks=args.ranks), out / "statistics.h5")
        subprocess.run(_command("plot", str(out)), check=False)
    return costs


def _first_seconds(data: dict, drive, t_first: float) -> dict:
    """Mean bit velocity, rop, efficiencies and the bit's swings over [0, t_first] of a run."""
    kept = data["time"] <= t_first * (1 + 1e-9)
    part = {k: v[kept] for k, v in data.items() if np.shape(v) == np.shape(data["time"])}
    q = drilling_quantities(part, drive.axial_velocity, drive.rotation_speed)
    t, u = part["time"], part["bit_displacement"]
    label = f"first {t_first:g} s:"
    return {f"{label} mean bit velocity [m/h]": f"{(u[-1] - u[0]) / (t[-1] - t[0]) * M_PER_H:.2f}",
            f"{label} rop [m/h]": f"{q['rop'] * M_PER_H:.2f}",
            f"{label} u̇_bit / V0": (f"{q['bit_bounce']['velocity_min_ratio']:.1f} … "
                                   f"{q['bit_bounce']['velocity_max_ratio']:.1f}"),
            f"{label} ω_bit / Ω": (f"{q['stick_slip']['omega_min_ratio']:.1f} … "
                                  f"{q['stick_slip']['omega_max_ratio']:.1f}"),
            f"{label} efficiency (96)-(98)": f"{q['efficiency']:.1%}",
            f"{label} efficiency, bit torque by its magnitude": f"{q['efficiency_torque_magnitude']:.1%}",
            f"{label} largest kinetic energy [kJ]": f"{part['kinetic_energy'].max() / 1e3:.1f}"}


def _nominal_row(directory: Path, t_first: float) -> dict:
    summary = json.loads((directory / "summary.json").read_text())
    data, attrs = read_series(directory / "timeseries.h5")
    drive = attrs["scene"].drive
    quantities = drilling_quantities(data, drive.axial_velocity, drive.rotation_speed)
    bounce, slip = summary["bit_bounce"], summary["stick_slip"]
    return {"mean bit velocity [m/h]": f"{summary['mean_bit_velocity'] * M_PER_H:.2f}",
            "rop [m/h]": f"{summary['rop'] * M_PER_H:.2f}",
            "bit off bottom": f"{bounce['off_bottom_fraction']:.1%}",
            "u̇_bit / V0": f"{bounce['velocity_min_ratio']:.1f} … {bounce['velocity_max_ratio']:.1f}",
            "bit angular velocity / Ω": f"{slip['omega_min_ratio']:.1f} … {slip['omega_max_ratio']:.1f}",
            "efficiency (96)-(98)": f"{summary['efficiency']:.1%}",
            "efficiency, bit torque by its magnitude": f"{quantities['efficiency_torque_magnitude']:.1%}",
            "impacts": f"{summary['impacts_total']}", "shock packages": f"{summary['shock_packages']}",
            "max σ_VM [MPa]": f"{summary['max_von_mises']['value'] / 1e6:.0f}",
            "work of the printed laws [kJ]": ", ".join(
                f"{k} {v / 1e3:.1f}" for k, v in summary["energy"]["injected_by"].items()) or "—",
            "largest kinetic energy [kJ]": f"{data['kinetic_energy'].max() / 1e3:.3g}",
            "status": summary["status"], "steps": f"{summary['steps']}",
            "wall time [s]": f"{summary['wall_time_s']:.0f}", **_first_seconds(data, drive, t_first)}


def _realisation_spread(points: Path) -> str:
    """Across the realisations of each point of a robust window: the widest range of rop [m/h]."""
    by_point: dict[str, list[float]] = {}
    for path in sorted(points.glob("*_[0-9]*.json")):
        result = json.loads(path.read_text())
        if result["status"] == "finished":
            by_point.setdefault(path.name[:4], []).append(result["rop"] * M_PER_H)
    widest = max(by_point.values(), key=lambda r: max(r) - min(r))
    return f"{min(widest):.1f} … {max(widest):.1f}"


def _window_row(directory: Path) -> dict:
    report = json.loads((directory / "optimize.json").read_text())
    v0, omega = np.asarray(report["axial_velocity"]), np.asarray(report["rotation_speed"])
    best = report.get("optimum")
    row = {"grid": f"{len(v0)} × {len(omega)}", "feasible": str(report.get("feasible"))}
    if best:
        row["grid optimum (V0 [m/h], Ω [rpm])"] = (f"({best['axial_velocity'] * M_PER_H:.0f}, "
                                                  f"{best['rotation_speed'] * 30 / np.pi:.0f})")
        row["objective at optimum"] = (f"{best['objective'] * M_PER_H:.1f} m/h" if report["objective"] == "rop"
                                       else f"{best['objective']:.1%}")
    for name, scale, unit in (("rop", M_PER_H, "m/h"), ("signed_rop", M_PER_H, "m/h"), ("efficiency", 100, "%"),
                              ("efficiency_torque_magnitude", 100, "%"), ("max_von_mises", 1e-6, "MPa")):
        values = np.asarray(report.get(name, np.nan), dtype=float) * scale
        if np.isfinite(values).any():
            row[f"{name} range [{unit}]"] = f"{np.nanmin(values):.1f} … {np.nanmax(values):.1f}"
    row["admissible points"] = f"{int(np.sum(report['admissible']))} of {np.size(report['admissible'])}"
    row["failed runs"] = f"{report['failed_runs']}"
    if report["mode"].startswith("robust"):
        row["widest rop range over one point's realisations [m/h]"] = _realisation_spread(directory / "points")
    return row


def _mc_row(summary: dict) -> dict:
    row = {"realisations": f"{summary.get('realisations')}", "failed": f"{summary.get('failed')}",
           "wall time per realisation [s]": f"{summary.get('wall_time_per_realisation_s', float('nan')):.0f}"}
    for name, scale, unit in (("rop", M_PER_H, "m/h"), ("efficiency", 100, "%"), ("efficiency_torque_magnitude", 100, "%"),
                              ("max_von_mises", 1e-6, "MPa")):
        stats = summary.get(name)
        if stats:
            row[f"{name} [{unit}] mean (2.5 … 97.5 %)"] = (
                f"{stats['mean'] * scale:.1f} ({stats['p2.5'] * scale:.1f} … {stats['p97.5'] * scale:.1f})")
    return row


def _table(title: str, rows: dict[str, dict]) -> list[str]:
    keys = list(dict.fromkeys(k for row in rows.values() for k in row))
    lines = [f"## {title}", "", "| | " + " | ".join(rows) + " |", "|---|" + "---|" * len(rows)]
    lines += [f"| {k} | " + " | ".join(row.get(k, "—") for row in rows.values()) + " |" for k in keys]
    return [*lines, ""]


def _spectra_lines(args) -> list[str]:
    """The two highest peaks of every Section 6.8 signal, named against the free modes of the band and
    against the modes with u and theta_x held at x = 0 by the drive (spectra.json of each nominal run)."""
    lines = ["## Spectral peaks (Figs. 21-23): peak [Hz] → nearest free mode / nearest mode held by the drive",
             "", "| signal | " + " | ".join(label for label, _, _ in NOMINALS.values()) + " |",
             "|---|" + "---|" * len(NOMINALS)]
    spectra = {name: json.loads(p.read_text()) if (p := args.runs / f"nominal-{name}" / "spectra.json").exists()
               else {} for name in NOMINALS}
    signals = dict.fromkeys(k for s in spectra.values() for k in s)
    for signal in signals:
        cells = []
        for name in NOMINALS:
            peaks = spectra[name].get(signal, {}).get("peaks", [])
            cells.append("<br>".join(
                f"{pk['frequency_hz']:.2f} → {pk['mode_frequency_hz']:.2f} {pk['mode_kind']} / "
                f"{pk['held_mode_frequency_hz']:.2f} {pk['held_mode_kind']}" for pk in peaks[:2]) or "—")
        lines.append(f"| {signal} (Fig. {next(s[signal]['figure'] for s in spectra.values() if signal in s)}) | "
                     + " | ".join(cells) + " |")
    return [*lines, ""]


def write_report(args, costs: dict) -> None:
    lines = ["# Section 6 reproduced: numbers (generated)", "",
             f"Command: `python benchmarks/reproduction.py --t-end {args.t_end} --samples {args.samples} "
             f"--ranks {args.ranks}` (both models with the paper's torsional stiffness κs G J). Nominal runs 10 s; windows and Monte Carlo {args.t_end} s per run. Read with docs/reproduction.md.", ""]
    nominal = {label: _nominal_row(args.runs / f"nominal-{name}", args.t_end) for name, (label, _, _) in NOMINALS.items()}
    lines += _table("Nominal run, 10 s", nominal)
    lines += _spectra_lines(args)
    for window in WINDOWS:
        rows = {m: _window_row(d) for m in MODELS
                if ((d := args.runs / f"window-{window}-{m}") / "optimize.json").exists()}
        lines += _table(f"{window} window", rows)
    rows = {m: _mc_row(json.loads(p.read_text())) for m in MODELS
            if (p := args.runs / f"mc-{m}" / "summary.json").exists()}
    lines += _table("Monte Carlo", rows)
    ran = {k: v for k, v in costs.items() if v > 0}
    if ran:
        lines += ["## Wall time of the studies run by this invocation (2-core machine)", ""]
        lines += [f"- {k}: {v:.0f} s" for k, v in ran.items()] + [""]
    args.table.write_text("\n".join(lines))
    print("\n".join(lines))


def comparison_figure(args) -> Path:
    """Bit velocity / V0, bit angular velocity / Omega and impacts per step of the nominal runs, stacked
    (the as-printed run's runaway is clipped at the axes' limits)."""
    fig, axes = panels(3, 2.6)
    for order, (name, (label, _, _)) in enumerate(NOMINALS.items()):
        data, attrs = read_series(args.runs / f"nominal-{name}" / "timeseries.h5")
        drive, t = attrs["scene"].drive, data["time"]
        # the runaway of every law as printed behind the others
        style = {"lw": 0.5, "zorder": 1 if name == "as_printed" else len(NOMINALS) - order, "color": f"C{order}"}
        axes[0].plot(t, data["bit_velocity"] / drive.axial_velocity, label=label, **style)
        axes[1].plot(t, data["bit_angular_velocity"] / drive.rotation_speed, **style)
        axes[2].plot(t, np.cumsum(data["impacts"]), **{**style, "lw": 1.2})
    axes[0].set(ylabel="u̇_bit / V0", ylim=(-150, 150))
    axes[1].set(ylabel="ω_bit / Ω", ylim=(-30, 30))
    axes[2].set(ylabel="impacts (cumulative)", xlabel="time [s]", yscale="symlog", ylim=(0, None))
    axes[0].legend(fontsize=7, loc="upper left")
    axes[0].set_title("Nominal scene, 10 s: consistent, as printed, as printed with one law changed", fontsize=10)
    args.figures.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, args.figures / "nominal_comparison.png")


#: The figures the report shows: all of a model's, the time histories of a variant.
VARIANT_FIGURES = ("fig14_bit_axial", "fig15_bit_rotation", "fig18_impacts_time")


def copy_figures(args) -> None:
    """The studies' figures into --figures as <figure>[_<study>]_<model>.png."""
    args.figures.mkdir(parents=True, exist_ok=True)
    for model in NOMINALS:
        for study in args.runs.glob(f"*-{model}"):
            kind = study.name.removesuffix(f"-{model}")
            for png in study.glob("fig*.png"):
                if model not in MODELS and png.stem not in VARIANT_FIGURES:
                    continue
                name = png.stem if kind == "nominal" else f"{png.stem}_{kind}"
                shutil.copy(png, args.figures / f"{name}_{model}.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=3.0)
    parser.add_argument("--samples", type=int, default=32)
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--runs", type=Path, default=Path("out/reproduction"))
    parser.add_argument("--table", type=Path, default=Path("docs/reproduction_numbers.md"))
    parser.add_argument("--figures", type=Path, default=Path("docs/figures/reproduction"))
    args = parser.parse_args()
    costs = studies(args)
    write_report(args, costs)
    copy_figures(args)
    comparison_figure(args)


if __name__ == "__main__":
    main()
