"""The main job's demo scripts run: `make demo` ends with the modal distributions and Table 4, which must regenerate
the manual's table (the reduced sizes the paper keeps, 37 / 49 / 60, against ours)."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[1]


def test_modal_distributions_regenerate_table_4(tmp_path):
    """The script of `make demo` runs to its end and writes the Table 4 that docs/table4.md holds (the rows are
    counts of modes: equal, not close)."""
    done = subprocess.run([sys.executable, str(ROOT / "demos" / "modal_distributions.py"), "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    table = (tmp_path / "table4.md").read_text()
    assert table.strip() in (ROOT / "docs" / "table4.md").read_text()
    for name in ("fig10_flexural_modes.png", "fig11_torsional_modes.png", "fig12_axial_modes.png"):
        assert (tmp_path / name).stat().st_size > 10_000


DEMO_SCENES = sorted((ROOT / "demos" / "scenes").glob("*.toml"))
#: The demo scenes that are not for `static` and `run` (their comments say which command they are for).
CAMPBELL_ONLY = ("campbell_paper.toml",)


def test_every_demo_scene_passes_the_checks_of_its_mesh_and_step():
    """The mesh and step checks ``static`` and ``run`` apply to a user's scene (8 nodes per flexural wavelength at the
    band's top, the step against f_max) pass on every demo scene as it is shipped."""
    from fenics_drill.scene import load_scene
    from fenics_drill.studies.run import discretisation_reasons

    failing = {f"{scene.name} ({command})": reasons for scene in DEMO_SCENES if scene.name not in CAMPBELL_ONLY
               for command in ("static", "run")
               if (reasons := discretisation_reasons(load_scene(scene), {"command": command}))}
    assert not failing, failing


def test_the_demo_wells_static_and_run_end_finished(tmp_path):
    """``static`` and a 2 ms ``run`` of the VBH demo well (on bottom, its velocity drive pressing the bit at 25 kN) and
    of the paper's scene end ``finished``, with no suspect reason.  2 ms: what the checks judge is the scene's
    discretisation and its start, not the run's length."""
    import json

    failures = []
    for scene in ("well_vbh.toml", "paper.toml"):
        for command, extra in (("static", []), ("run", ["--set", "time.t_end=0.002", "--set", "output.field_interval=0",
                                                        "--quiet"])):
            out = tmp_path / f"{scene}-{command}"
            done = subprocess.run([sys.executable, "-m", "fenics_drill.cli", command,
                                   str(ROOT / "demos" / "scenes" / scene), *extra, "--out", str(out)],
                                  capture_output=True, text=True, timeout=600)
            summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else {}
            if done.returncode != 0 or summary.get("status") != "finished":
                failures.append(f"{command} {scene}: {summary.get('status')} "
                                f"{summary.get('suspect_reasons') or summary.get('message') or done.stderr[-300:]}")
    assert not failures, "\n".join(failures)


STUDY_TARGETS = {"mc": "mc", "optimize": "window-rop", "stick-slip": "stick-slip-stiff"}


def test_the_study_targets_start_a_fresh_directory_and_continue_an_interrupted_one(tmp_path):
    """`make mc`, `make optimize` and `make stick-slip` pass --resume only to a study directory an earlier run left
    its summary in: the commands refuse --resume of a directory that holds no study, so a first run on a fresh
    machine would otherwise end at its first line (`make -n` prints the commands without running them)."""
    for target, directory in STUDY_TARGETS.items():
        def commands():
            done = subprocess.run(["make", "-n", target, f"OUT={tmp_path}"], cwd=ROOT, capture_output=True,
                                  text=True, timeout=60)
            assert done.returncode == 0, done.stderr
            return [line for line in done.stdout.splitlines() if f"--out {tmp_path}/{directory} " in line + " "]

        fresh = commands()
        assert fresh and not any("--resume" in line for line in fresh), (target, fresh)
        (tmp_path / directory).mkdir()
        (tmp_path / directory / "summary.json").write_text("{}")
        assert all("--resume" in line for line in commands()), target
