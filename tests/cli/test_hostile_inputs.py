"""Hostile inputs as a new user meets them (docs/reliability.md): each is refused in one line, answered correctly,
or said to be suspect, and none ends in a traceback, a hang or a lost file.  Commands run in this process where they
cannot block (``main(argv)`` returns the exit code), in a subprocess under a timeout where they could (pipes,
devices, MPI)."""

import dataclasses
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import fenics_drill as fd
from fenics_drill.cli import main
from fenics_drill.io.output_directory import LOCK_NAME, OutputError

ROOT = Path(__file__).parents[2]
PAPER = str(ROOT / "demos" / "scenes" / "paper.toml")
TOOL = [sys.executable, "-m", "fenics_drill.cli"]
MPIEXEC = str(Path(sys.executable).parent / "mpiexec")
#: A blocked read or a hung command shows up as this timeout instead of a blocked suite.
TIMEOUT = 120
SMALL = ["--set", "beam.length=20", "--set", "beam.elements=40"]

SECTIONS = """
[[string.sections]]
name = "collar"
length = 20.0
outer_radius = 0.0857
inner_radius = 0.0357
{collar}
[[string.sections]]
name = "drill pipe"
length = 100.0
outer_radius = 0.0635
inner_radius = 0.0543
tool_joint_outer_radius = 0.084
tool_joint_length = 0.45
tool_joint_spacing = 9.4
"""


def well_scene(tmp_path, survey: str | None = "md,inclination,azimuth\n0,0,0\n40,0,0\n120,45,30\n",
               collar: str = "", extra: str = "", name: str = "well.toml") -> Path:
    """A 120 m string of collar and drill pipe in mud along ``survey`` (a CSV beside the scene; None: none)."""
    well = '[well]\nsurvey = "survey.csv"\n' if survey is not None else ""
    if survey is not None:
        (tmp_path / "survey.csv").write_text(survey)
    path = tmp_path / name
    path.write_text(f"[beam]\nelements = 60\n\n{well}\n[fluid]\ndensity = 1200.0\n{extra}\n"
                    + SECTIONS.format(collar=collar))
    return path


def refused(capsys, argv, words) -> str:
    """The command is refused with exit code 2 and one line naming ``words``; no traceback."""
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in err, err
    return lines[0]


def tool(*args, timeout=TIMEOUT) -> subprocess.CompletedProcess:
    return subprocess.run([*TOOL, *args], capture_output=True, text=True, timeout=timeout, cwd=ROOT)


def refused_in_a_subprocess(args, words) -> None:
    result = tool(*args)
    assert result.returncode == 2 and words in result.stderr and "Traceback" not in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr


# Data loss: --overwrite removes what the command wrote, never a user's file because of its name


def test_overwrite_keeps_a_users_files_that_look_like_outputs(tmp_path, capsys):
    out = tmp_path / "static"
    assert main(["static", PAPER, *SMALL, "--out", str(out)]) == 0
    (out / ".notes.tmp.txt").write_text("the user's notes")  # hidden: never the command's
    assert main(["static", PAPER, *SMALL, "--overwrite", "--out", str(out)]) == 0
    assert (out / ".notes.tmp.txt").read_text() == "the user's notes"
    (out / "figure_from_colleague.png").write_bytes(b"a colleague's figure")  # named like a figure
    capsys.readouterr()
    refused(capsys, ["static", PAPER, *SMALL, "--overwrite", "--out", str(out)], "figure_from_colleague.png")
    assert (out / "figure_from_colleague.png").read_bytes() == b"a colleague's figure"
    assert not (out / LOCK_NAME).exists()  # the lock goes with the command, finished or refused


def test_overwrite_of_a_plotted_run_removes_its_figures_and_only_them(tmp_path):
    out = tmp_path / "run"
    args = ["run", PAPER, *SMALL, "--set", "time.t_end=0.01", "--set", "output.field_interval=0", "--quiet"]
    assert main([*args, "--out", str(out)]) == 0
    assert main(["plot", str(out), "--no-gif"]) == 0
    figures = sorted(p.name for p in out.glob("fig*.png"))
    assert figures
    assert main([*args, "--overwrite", "--out", str(out)]) == 0
    assert not list(out.glob("fig*.png")) and not (out / LOCK_NAME).exists()


# Inputs that could hang the reader


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_a_survey_that_is_a_pipe_or_a_device_is_refused_at_once(tmp_path, kind):
    """A FIFO would block the reader until a writer comes, /dev/zero would fill the memory: both refused in one
    line (a subprocess under a timeout, so that a hang fails the test)."""
    scene = well_scene(tmp_path)
    (tmp_path / "survey.csv").unlink()
    if kind == "fifo":
        os.mkfifo(tmp_path / "survey.csv")
    else:
        (tmp_path / "survey.csv").symlink_to("/dev/zero")
    refused_in_a_subprocess(["static", str(scene), "--out", str(tmp_path / "o")], "is not a regular file")


def test_static_on_a_dense_survey_finds_its_state(tmp_path):
    """30 000 stations (one every 4 mm): the static state is found (the elements take the curvature at their
    midpoints), and whatever the set-up said of its stages (after 5 s of silence: how long it takes depends on the
    machine, test_a_long_set_up_says_what_it_does) names a stage."""
    md = np.linspace(0.0, 120.0, 30001)
    inclination = np.clip((md - 40.0) * 45.0 / 80.0, 0.0, None)
    survey = "md,inclination,azimuth\n" + "\n".join(f"{a:.5f},{b:.6f},30" for a, b in zip(md, inclination)) + "\n"
    scene = well_scene(tmp_path, survey)
    result = tool("static", str(scene), "--out", str(tmp_path / "o"))
    assert result.returncode == 0 and "Traceback" not in result.stderr, result.stderr
    stages = [line for line in result.stderr.splitlines() if line.startswith("  set-up: ")]
    assert all(line.endswith(" s)") and len(line) > len("  set-up:  (5 s)") for line in stages), stages
    report = json.loads((tmp_path / "o" / "static.json").read_text())
    assert report["hook_load"] > 0


def test_a_soft_string_of_millions_of_elements_is_refused(tmp_path, capsys):
    scene = well_scene(tmp_path)
    refused(capsys, ["torque-drag", str(scene), "--set", "torque_drag.element_length=1e-5", "--out",
                     str(tmp_path / "o")], "torque_drag.element_length")


def test_a_run_of_days_is_refused_before_it_starts_and_allowed_when_asked(tmp_path, capsys):
    line = refused(capsys, ["run", PAPER, "--set", "time.dt=1e-9", "--set", "time.adaptive=false", "--out",
                            str(tmp_path / "o")], "time.max_steps")
    assert "1e+10 steps" in line
    assert not (tmp_path / "o").exists()
    scene = fd.load_scene(PAPER, ["time.dt=1e-9", "time.adaptive=false", "time.max_steps=1e11"])  # asked for
    assert scene.time.max_steps == 1e11


# Silent wrong answers


def test_inline_angles_without_depths_are_refused(tmp_path, capsys):
    scene = well_scene(tmp_path, None, extra="[well]\ninclination = [0.0, 30.0]\nazimuth = [0.0, 0.0]\n")
    refused(capsys, ["static", str(scene), "--out", str(tmp_path / "o")], "without well.md")


def test_the_api_checks_a_scene_changed_with_dataclasses_replace():
    scene = fd.load_scene(PAPER)
    cases = ((dataclasses.replace(scene, fluid=dataclasses.replace(scene.fluid, density=-1000.0)), "fluid.density"),
             (dataclasses.replace(scene, beam=dataclasses.replace(scene.beam, elements=-3)), "beam.elements"),
             (dataclasses.replace(scene, beam=dataclasses.replace(scene.beam, elements=0)), "beam.elements"),
             (dataclasses.replace(scene, fluid=dataclasses.replace(scene.fluid, density=math.nan)), "fluid.density"))
    for changed, key in cases:
        for call in (fd.static_state, fd.modal_analysis, fd.torque_drag, fd.campbell):
            with pytest.raises(fd.SceneError, match=key.replace(".", r"\.")):
                call(changed)


# Tracebacks that are now refusals or answers


@pytest.mark.parametrize("survey, words", [
    ("md,inclination,azimuth\n0,0,0\n40,0,0,7\n120,45,30\n", "line 3: 4 fields where the header names 3"),
    (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "is a binary file"),
    ("md,inclination,azimuth\n0,0,0\n", "at least two stations"),
    ("md,inclination,azimuth\n0,0,0\n40,0,0\n30,45,30\n", "does not exceed the station before"),
    ("MD (furlongz),Inc (deg),Azi (deg)\n0,0,0\n40,0,0\n", "unknown unit 'furlongz'"),
    ("MD (kg),Inc (deg),Azi (deg)\n0,0,0\n40,0,0\n", "is not a quantity in m"),
    ("md,inclination,azimuth\n0,0,0\n40,100,0\n120,150,0\n", "rises above the surface"),
])
def test_malformed_surveys_are_refused_naming_the_line(tmp_path, capsys, survey, words):
    scene = well_scene(tmp_path)
    path = tmp_path / "survey.csv"
    path.write_bytes(survey) if isinstance(survey, bytes) else path.write_text(survey)
    refused(capsys, ["torque-drag", str(scene), "--out", str(tmp_path / "o")], words)
    refused(capsys, ["scene", str(scene)], words)  # `scene` reads the survey as every command does


@pytest.mark.parametrize("header, encoding, factor", [
    ("# exported by the survey tool\n# units: SI\nmd,inclination,azimuth\n", "utf-8", 1.0),
    ("md,inclination,azimuth\n", "utf-8-sig", 1.0),  # Excel's "CSV UTF-8": a byte order mark
    ("MD (m),Inc (°),Azi (°)\n", "latin-1", 1.0),  # an older exporter's degree sign
    ("MD (m),Inc (deg),Azi (deg)\n", "utf-8", 1.0),
    ("MD (ft);Inc (deg);Azi (deg)\n", "utf-8", 0.3048),  # feet, semicolons
])
def test_surveys_as_exported_are_read_as_the_plain_one(tmp_path, header, encoding, factor):
    """Each survey gives the well of the plain file in metres: the same stations, to round-off."""
    from fenics_drill.model.well import read_survey_csv

    rows = [(0.0, 0.0, 0.0), (40.0, 0.0, 0.0), (120.0, 45.0, 30.0)]
    sep = ";" if ";" in header else ","
    text = header + "".join(f"{md / factor!r}{sep}{inc}{sep}{azi}\n" for md, inc, azi in rows)
    path = tmp_path / "survey.csv"
    path.write_bytes(text.encode(encoding))
    survey = read_survey_csv(path)
    # the depths went through repr() of md / factor and back times factor, the angles through degrees and radians:
    # a few ulps of round-off, so 1e-12
    np.testing.assert_allclose(survey.md, [r[0] for r in rows], rtol=1e-12)
    np.testing.assert_allclose(np.degrees(survey.inclination), [r[1] for r in rows], rtol=1e-12)


@pytest.mark.parametrize("collar, command, words", [
    ("density = 0.0", "static", "string.sections[1].density = 0.0"),
    ("density = 0.0", "torque-drag", "string.sections[1].density = 0.0"),
    ("young_modulus = 0.0", "static", "young_modulus = 0.0"),
    ("poisson_ratio = 0.5", "static", "poisson_ratio = 0.5"),
    ("poisson_ratio = 0.9", "torque-drag", "poisson_ratio = 0.9"),
    ("tool_joint_outer_radius = 0.1\ntool_joint_length = 20.0\ntool_joint_spacing = 9.4", "static",
     "tool_joint_length = 20.0"),
])
def test_impossible_sections_are_refused(tmp_path, capsys, collar, command, words):
    scene = well_scene(tmp_path, collar=collar)
    refused(capsys, [command, str(scene), "--out", str(tmp_path / "o")], words)


@pytest.mark.parametrize("overrides, words", [
    (["torque_drag.operations=[]"], "torque_drag.operations = []"),
    (["fluid.density=50000.0"], "fluid.density = 50000.0"),
])
def test_scene_keys_that_made_tracebacks_or_vague_failures_are_refused(tmp_path, capsys, overrides, words):
    scene = well_scene(tmp_path)
    argv = [a for o in overrides for a in ("--set", o)]
    refused(capsys, ["static", str(scene), *argv, "--out", str(tmp_path / "o")], words)


def test_a_floating_string_is_refused_naming_the_mud(tmp_path, capsys):
    scene = well_scene(tmp_path, collar="density = 2700.0")  # aluminium in 2900 kg/m^3 brine
    refused(capsys, ["static", str(scene), "--set", "fluid.density=2900.0", "--out", str(tmp_path / "o")],
            "floats in the mud")


def test_api_arguments_of_the_wrong_kind_are_refused_in_one_sentence():
    with pytest.raises(fd.SceneError, match="each override is a 'section.key=value' string"):
        fd.load_scene(PAPER, [None])
    with pytest.raises(fd.SceneError, match=r"give a list .* e\.g\. \['time\.t_end=1'\]"):
        fd.load_scene(PAPER, "time.t_end=1")
    with pytest.raises(fd.SceneError, match=r"give the keys of \[time\] as a dict"):
        fd.load_scene(PAPER).with_changes(time=5)
    with pytest.raises(fd.SceneError, match="expected a Scene"):
        fd.static_state("demos/scenes/paper.toml")


def test_the_api_refuses_a_bad_run_before_writing_anything(tmp_path):
    scene = fd.load_scene(PAPER)
    for changed in (dataclasses.replace(scene, time=dataclasses.replace(scene.time, t_end=-1.0)),
                    dataclasses.replace(scene, time=dataclasses.replace(scene.time, dt=math.nan))):
        with pytest.raises(fd.SceneError, match="time"):
            fd.run(changed, out=tmp_path / "o")
        assert not (tmp_path / "o").exists()


def test_the_api_names_its_own_arguments_in_an_output_directorys_message(tmp_path):
    scene = fd.load_scene(PAPER, ["beam.length=20", "beam.elements=40"])
    fd.static_state(scene, out=tmp_path / "o")
    with pytest.raises(OutputError, match=r"pass overwrite=True") as refusal:
        fd.static_state(scene, out=tmp_path / "o")
    assert "--overwrite" not in str(refusal.value)


# Bad input accepted, good input refused


def test_an_empty_out_is_refused(tmp_path, capsys):
    refused(capsys, ["static", PAPER, "--out", ""], "--out '' names no directory")


def test_a_monte_carlo_of_no_realisation_is_refused_from_python_too(tmp_path, capsys):
    refused(capsys, ["mc", PAPER, "--samples", "0", "--out", str(tmp_path / "o")], "(--samples) 0")
    with pytest.raises(fd.SceneError, match=r"\(--samples\) 0 is not admissible"):
        fd.monte_carlo(fd.load_scene(PAPER), samples=0, out=tmp_path / "o")
    assert not (tmp_path / "o").exists()


def test_the_scene_command_reads_the_survey_file(tmp_path, capsys):
    scene = well_scene(tmp_path)
    (tmp_path / "survey.csv").unlink()
    refused(capsys, ["scene", str(scene)], "does not exist")


def test_positions_on_a_string_of_sections_are_checked_against_its_own_length(tmp_path, capsys):
    """A 120 m string with beam.length left at 100: a watched section and a stabiliser at 110 m are on it."""
    scene = fd.load_scene(well_scene(tmp_path), ["output.section=110.0", "supports.stabilisers=[110.0]"])
    assert scene.output.section == 110.0 and scene.string_length == 120.0
    refused(capsys, ["scene", str(well_scene(tmp_path)), "--set", "output.section=130.0"], "the string's length")


# MPI: a single-process command under mpiexec


def test_a_single_process_command_under_mpiexec_runs_once_and_every_rank_ends_cleanly(tmp_path):
    scene = well_scene(tmp_path)
    result = subprocess.run([MPIEXEC, "-n", "2", *TOOL, "torque-drag", str(scene), "--out", str(tmp_path / "o")],
                            capture_output=True, text=True, timeout=TIMEOUT, cwd=ROOT)
    assert result.returncode == 0 and "Traceback" not in result.stderr, result.stderr
    assert "runs on one process" in result.stderr and "in use by another" not in result.stderr
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["status"] == "finished"


# Left behind or misleading on an ordinary run


def test_the_first_progress_line_gives_no_estimate_from_the_start_up(capsys):
    from fenics_drill.studies.run import Progress

    progress = Progress(True, every_s=0.0)
    progress(2e-6, 10.0, {"steps": 1}, 1e-6, 0.2)  # one start-up step: 0.2 s for 2e-7 of the run
    progress(0.5, 10.0, {"steps": 800}, 6e-4, 4.0)
    first, second = capsys.readouterr().err.strip().splitlines()
    assert first.endswith("eta     ...") and second.endswith("eta    76.0 s")


def test_a_long_set_up_says_what_it_does(capsys):
    """A set-up that lasts past its quiet time says, on stderr, the stage under way and how long it has run, again
    every period; a set-up that ends within its quiet time says nothing.  The quiet time and period here are 0.05 s
    and the waits 20 times longer, so that a loaded machine's scheduling cannot make the lines miss."""
    from fenics_drill.studies.run import SetupProgress

    quick = SetupProgress(True, quiet_s=1.0, every_s=1.0)
    quick("meshing")
    quick.close()
    time.sleep(1.2)
    assert capsys.readouterr().err == ""
    slow = SetupProgress(True, quiet_s=0.05, every_s=0.05)
    slow("the static equilibrium on the wall")
    time.sleep(1.0)
    slow.close()
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) >= 2 and all(line.startswith("  set-up: the static equilibrium on the wall (") for line in lines)


def test_the_manual_speaks_of_the_software_not_of_one_days_circumstances():
    # phrases the manual once used for the conditions of one measurement or for how it was written; a table states
    # its machine and command
    words = ("shared machine", "this project's machine", "the machine, not the code", "running on the other core",
             "session", "sitting")
    for page in [*(ROOT / "docs").rglob("*.md"), *(ROOT / "benchmarks" / "results").rglob("*.md"), ROOT / "README.md"]:
        if "_build" in page.parts:
            continue
        text = page.read_text().lower()
        for phrase in words:
            assert phrase not in text, f"{page.relative_to(ROOT)} speaks of '{phrase}'"
