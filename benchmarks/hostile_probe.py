"""A corpus of hostile inputs over every command and the Python API, each tried as a new user would: the installed
tool (or a Python snippet) in its own process under a timeout.  Every case ends in one class:

* ``refused``: exit code 2 (or a SceneError / OutputError from the API) with a one-line message;
* ``correct``: the command finished (exit 0, summary "finished"), where the input is admissible;
* ``suspect``: it finished and said why its answer is doubtful (summary "suspect");
* ``failed (stated)``: it ended "failed" with its reason in one line;
* ``bad input accepted``: an input the case marks inadmissible ran without a word;
* ``silent answer``: it finished, but what it printed or wrote is not what the input means (a value misread, a
  buckled string given a critical speed, a note missing): the case's ``check`` says what is wrong;
* ``unclear``: refused, but in more than one line;
* ``traceback``, ``hang`` (past the timeout), ``data loss`` (a user's file gone or changed).

    python benchmarks/hostile_probe.py [--table benchmarks/results/hostile_probe.md] [--workers 2] [--match TEXT]

The counts go to the table's head, every case below it (docs/reliability.md).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).parents[1]
PYTHON = sys.executable
TOOL = [PYTHON, "-m", "fenics_drill.cli"]
MPIEXEC = str(Path(PYTHON).parent / "mpiexec")
PAPER = str(ROOT / "demos" / "scenes" / "paper.toml")
#: A case still running after this long is a hang.
TIMEOUT = 120
SMALL = ["--set", "beam.length=20", "--set", "beam.elements=40"]
CLASSES = ("refused", "correct", "suspect", "failed (stated)", "bad input accepted", "silent answer", "unclear",
           "traceback", "hang", "data loss")

# the 120 m string of collar and drill pipe in mud that the hostile-input tests use
sys.path.insert(0, str(ROOT / "tests" / "cli"))
from test_hostile_inputs import SECTIONS  # noqa: E402

SURVEY = "md,inclination,azimuth\n0,0,0\n40,0,0\n120,45,30\n"


@dataclass
class Case:
    """One hostile input: ``argv`` for the tool (``mpi`` ranks under mpiexec), or a Python ``snippet``; the files
    ``setup(workdir)`` lays out first; ``admissible`` whether the input should run; ``keep`` the user's files that
    must survive (name -> content); ``check(stdout, workdir)`` what is wrong with a finished case's answer (None:
    nothing); ``cwd`` the working directory (WORK/... or the repository)."""

    name: str
    argv: list = field(default_factory=list)
    snippet: str = ""
    setup: object = None
    admissible: bool = False
    keep: dict = field(default_factory=dict)
    mpi: int = 0
    check: object = None
    cwd: str = ""


def well_files(workdir: Path, survey: str | bytes | None = SURVEY, collar: str = "", extra: str = "") -> Path:
    """A 120 m string of collar and drill pipe in mud along ``survey`` (survey.csv beside well.toml)."""
    if isinstance(survey, bytes):
        (workdir / "survey.csv").write_bytes(survey)
    elif survey is not None:
        (workdir / "survey.csv").write_text(survey)
    well = '[well]\nsurvey = "survey.csv"\n' if survey is not None else ""
    path = workdir / "well.toml"
    path.write_text(f"[beam]\nelements = 60\n\n{well}\n[fluid]\ndensity = 1200.0\n{extra}\n"
                    + SECTIONS.format(collar=collar))
    return path


def key_cases() -> list[Case]:
    """Every scene key given a value of the wrong kind, and NaN, through ``fenics-drill scene``."""
    from fenics_drill.scene import describe_keys

    cases = []
    for row in describe_keys():
        dotted = f"{row.section}.{row.name}"
        wrong = {"a number": '"ten"', "an integer": "2.5", "true or false": '"maybe"', "a string": '"no-such-choice"',
                 "an array": "7"}.get(row.kind, '"x"')
        if dotted == "well.survey":
            wrong = '"/no/such/survey.csv"'
        cases.append(Case(f"{dotted} = {wrong}", ["scene", "--set", f"{dotted}={wrong}"]))
        cases.append(Case(f"{dotted} = nan", ["scene", "--set", f"{dotted}=nan"]))
    return cases


def survey_cases() -> list[Case]:
    def fifo(w):
        well_files(w, None).write_text(well_files(w).read_text())
        (w / "survey.csv").unlink()
        os.mkfifo(w / "survey.csv")

    def device(w):
        well_files(w)
        (w / "survey.csv").unlink()
        (w / "survey.csv").symlink_to("/dev/zero")

    def directory(w):
        well_files(w)
        (w / "survey.csv").unlink()
        (w / "survey.csv").mkdir()

    texts = {
        "survey: more fields than the header": ("md,inclination,azimuth\n0,0,0\n40,0,0,9\n120,45,30\n", False),
        "survey: fewer fields than the header": ("md,inclination,azimuth\n0,0,0\n40,0\n120,45,30\n", False),
        "survey: a comment before the header": ("# from the rig\n" + SURVEY, True),
        "survey: blank lines and comments between stations": ("md,inclination,azimuth\n\n0,0,0\n# hold\n40,0,0\n\n120,45,30\n", True),
        "survey: UTF-8 with a byte order mark": ("\ufeff" + SURVEY, True),
        "survey: Latin-1 degree signs in the header": ("MD (m),Inc (\u00b0),Azi (\u00b0)\n0,0,0\n40,0,0\n120,45,30\n".encode("latin-1"), True),
        "survey: header with units, metres": ("MD (m),Inc (deg),Azi (deg)\n0,0,0\n40,0,0\n120,45,30\n", True),
        "survey: header with units, feet": ("MD (ft),Inc (deg),Azi (deg)\n0,0,0\n131.2,0,0\n393.7,45,30\n", True),
        "survey: semicolons": ("md;inclination;azimuth\n0;0;0\n40;0;0\n120;45;30\n", True),
        "survey: tabs": ("md\tinclination\tazimuth\n0\t0\t0\n40\t0\t0\n120\t45\t30\n", True),
        "survey: an unknown unit": ("MD (furlongz),Inc (deg),Azi (deg)\n0,0,0\n40,0,0\n120,45,30\n", False),
        "survey: a unit of mass for the depth": ("MD (kg),Inc (deg),Azi (deg)\n0,0,0\n40,0,0\n120,45,30\n", False),
        "survey: depths in yards": ("MD (yd),Inc (deg),Azi (deg)\n0,0,0\n43.74,0,0\n131.24,45,30\n", True),
        "survey: a binary file": (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00", False),
        "survey: empty": ("", False),
        "survey: a header only": ("md,inclination,azimuth\n", False),
        "survey: one station": ("md,inclination,azimuth\n0,0,0\n", False),
        "survey: unsorted depths": ("md,inclination,azimuth\n0,0,0\n40,0,0\n30,45,30\n", False),
        "survey: a repeated depth": ("md,inclination,azimuth\n0,0,0\n40,0,0\n40,45,30\n", False),
        "survey: a word for a number": ("md,inclination,azimuth\n0,0,0\n40,x,0\n120,45,30\n", False),
        "survey: nan inclination": ("md,inclination,azimuth\n0,0,0\n40,nan,0\n120,45,30\n", False),
        "survey: inclination 200 deg": ("md,inclination,azimuth\n0,0,0\n40,0,0\n120,200,30\n", False),
        "survey: a dogleg no pipe passes": ("md,inclination,azimuth\n0,0,0\n40,0,0\n41,90,0\n120,90,0\n", False),
        "survey: rises above the ground": ("md,inclination,azimuth\n0,0,0\n40,100,0\n120,150,0\n", False),
        "survey: no inclination column": ("md,dip,azimuth\n0,0,0\n40,0,0\n120,45,30\n", False),
        "survey: shorter than the string": ("md,inclination,azimuth\n0,0,0\n40,0,0\n100,45,30\n", False),
        "survey: negative first depth": ("md,inclination,azimuth\n-10,0,0\n40,0,0\n120,45,30\n", False),
    }
    cases = []
    for name, (text, ok) in texts.items():
        cases.append(Case(name, ["torque-drag", "WORK/well.toml", "--out", "WORK/o"],
                          setup=lambda w, t=text: well_files(w, t), admissible=ok))
    for name, setup in (("survey: a FIFO", fifo), ("survey: a link to /dev/zero", device),
                        ("survey: a directory", directory)):
        cases.append(Case(name, ["static", "WORK/well.toml", "--out", "WORK/o"], setup=setup))
    cases.append(Case("survey: missing, seen by `scene`", ["scene", "WORK/well.toml"],
                      setup=lambda w: (well_files(w), (w / "survey.csv").unlink())))
    cases.append(Case("survey: unsorted, seen by `scene`", ["scene", "WORK/well.toml"],
                      setup=lambda w: well_files(w, "md,inclination,azimuth\n0,0,0\n50,0,0\n40,45,0\n")))
    dense = "md,inclination,azimuth\n" + "".join(f"{k * 0.004:.4f},{max(0.0, (k * 0.004 - 40) * 0.5625):.5f},30\n"
                                                 for k in range(30001))
    cases.append(Case("survey: 30 000 stations, static", ["static", "WORK/well.toml", "--out", "WORK/o"],
                      setup=lambda w: well_files(w, dense), admissible=True))
    return cases


def section_cases() -> list[Case]:
    entries = {
        "section: density 0": ("density = 0.0", False), "section: Young's modulus 0": ("young_modulus = 0.0", False),
        "section: Poisson ratio 0.5": ("poisson_ratio = 0.5", False),
        "section: Poisson ratio 0.9": ("poisson_ratio = 0.9", False),
        "section: tool joint 20 m every 9.4 m": ("tool_joint_outer_radius = 0.1\ntool_joint_length = 20.0\n"
                                                  "tool_joint_spacing = 9.4", False),
        "section: tool joint narrower than the body": ("tool_joint_outer_radius = 0.05\ntool_joint_length = 0.5\n"
                                                       "tool_joint_spacing = 9.4", False),
        "section: joint bore wider than the joint": ("tool_joint_outer_radius = 0.1\ntool_joint_inner_radius = 0.2\n"
                                                     "tool_joint_length = 0.5\ntool_joint_spacing = 9.4", False),
        "section: an unknown key": ("colour = 3.0", False),
        "section: a string for a number": ('density = "heavy"', False),
        "section: a steel density, given": ("density = 7850.0", True),
    }
    cases = []
    for command in ("static", "torque-drag"):
        for name, (collar, ok) in entries.items():
            cases.append(Case(f"{name} ({command})", [command, "WORK/well.toml", "--out", "WORK/o"],
                              setup=lambda w, c=collar: well_files(w, collar=c), admissible=ok))
    cases.append(Case("section: a floating string (static)", ["static", "WORK/well.toml", "--set",
                                                                 "fluid.density=2900.0", "--out", "WORK/o"],
                      setup=lambda w: well_files(w, collar="density = 2700.0")))
    cases.append(Case("well: angles without depths", ["static", "WORK/well.toml", "--out", "WORK/o"],
                      setup=lambda w: well_files(w, None, extra="[well]\ninclination = [0.0, 30.0]\n"
                                                                "azimuth = [0.0, 0.0]\n")))
    cases.append(Case("fluid: 50 SG mud", ["static", "WORK/well.toml", "--set", "fluid.density=50000.0", "--out",
                                          "WORK/o"], setup=lambda w: well_files(w)))
    cases.append(Case("torque_drag.operations = []", ["torque-drag", "WORK/well.toml", "--set",
                                                      "torque_drag.operations=[]", "--out", "WORK/o"],
                      setup=lambda w: well_files(w)))
    cases.append(Case("torque_drag.element_length = 1e-4", ["torque-drag", "WORK/well.toml", "--set",
                                                            "torque_drag.element_length=1e-5", "--out", "WORK/o"],
                      setup=lambda w: well_files(w)))
    cases.append(Case("output.section = 110 on a 120 m string", ["scene", "WORK/well.toml", "--set",
                                                                 "output.section=110.0", "--set",
                                                                 "supports.stabilisers=[110.0]"],
                      setup=lambda w: well_files(w), admissible=True))
    return cases


def output_cases() -> list[Case]:
    def run_dir_with_user_file(name):
        def setup(w):
            subprocess.run([*TOOL, "static", PAPER, *SMALL, "--out", str(w / "o")], capture_output=True,
                           timeout=TIMEOUT, cwd=ROOT)
            (w / "o" / name).write_text("the user's")
        return setup

    cases = [Case("--out ''", ["static", PAPER, *SMALL, "--out", ""]),
             Case("--out a file", ["static", PAPER, *SMALL, "--out", "WORK/file"],
                  setup=lambda w: (w / "file").write_text("x"), keep={"file": "x"}),
             Case("--out under /proc", ["static", PAPER, *SMALL, "--out", "/proc/fenics-drill-probe"]),
             Case("--out a directory of the user's files", ["static", PAPER, *SMALL, "--out", "WORK/mine"],
                  setup=lambda w: ((w / "mine").mkdir(), (w / "mine" / "notes.txt").write_text("n")),
                  keep={"mine/notes.txt": "n"}),
             Case("--resume of nothing", ["mc", PAPER, "--samples", "2", "--resume", "--out", "WORK/none"]),
             Case("static twice without --overwrite", ["static", PAPER, *SMALL, "--out", "WORK/o"],
                  setup=lambda w: subprocess.run([*TOOL, "static", PAPER, *SMALL, "--out", str(w / "o")],
                                                 capture_output=True, timeout=TIMEOUT, cwd=ROOT))]
    for name in ("figure_from_colleague.png", ".notes.tmp.txt", "summary.json.bak", "fig01.png", ".hidden"):
        cases.append(Case(f"--overwrite beside a user's {name}", ["static", PAPER, *SMALL, "--overwrite", "--out",
                                                                  "WORK/o"],
                          setup=run_dir_with_user_file(name), keep={f"o/{name}": "the user's"},
                          admissible=name.startswith(".")))
    return cases


API_HEAD = """
import dataclasses, math, sys
import fenics_drill as fd
from fenics_drill.io.output_directory import OutputError
scene = fd.load_scene({paper!r}, ["beam.length=20", "beam.elements=40", "time.t_end=0.01"])
try:
{body}
    print("ANSWERED")
except (fd.SceneError, OutputError) as err:
    print("REFUSED:", err, file=sys.stderr)
    sys.exit(2)
"""


def api_case(name: str, body: str, admissible: bool = False) -> Case:
    indented = "\n".join("    " + line for line in body.strip().splitlines())
    return Case(f"API: {name}", snippet=API_HEAD.format(paper=PAPER, body=indented), admissible=admissible)


def api_cases() -> list[Case]:
    replace = "dataclasses.replace(scene, {section}=dataclasses.replace(scene.{section}, {key}={value}))"
    bad = (("fluid", "density", "-1000.0"), ("beam", "elements", "-3"), ("beam", "elements", "0"),
           ("fluid", "density", "math.nan"), ("time", "t_end", "-1.0"), ("time", "dt", "math.nan"),
           ("beam", "young_modulus", "0.0"), ("contact", "friction", "math.inf"))
    cases = []
    for call in ("fd.static_state", "fd.modal_analysis", "fd.run", "fd.torque_drag", "fd.campbell"):
        for section, key, value in bad:
            changed = replace.format(section=section, key=key, value=value)
            cases.append(api_case(f"{call} with {section}.{key} = {value}", f"{call}({changed})"))
    cases += [
        api_case("load_scene(path, [None])", f"fd.load_scene({PAPER!r}, [None])"),
        api_case("load_scene(path, 'time.t_end=1')", f"fd.load_scene({PAPER!r}, 'time.t_end=1')"),
        api_case("load_scene(42)", "fd.load_scene(42)"),
        api_case("with_changes(time=5)", "scene.with_changes(time=5)"),
        api_case("with_changes(nosuch={'a': 1})", "scene.with_changes(nosuch={'a': 1})"),
        api_case("with_changes(time={'t_end': 'soon'})", "scene.with_changes(time={'t_end': 'soon'})"),
        api_case("static_state of a path", f"fd.static_state({PAPER!r})"),
        api_case("replace with a section that is not one", "fd.run(dataclasses.replace(scene, time=5))"),
        api_case("monte_carlo with 0 samples", "fd.monte_carlo(scene, samples=0, out=__import__('tempfile').mkdtemp())"),
        api_case("run twice into one directory", "import tempfile\nd = tempfile.mkdtemp()\nfd.run(scene, out=d)\n"
                                                 "fd.run(scene, out=d)"),
        api_case("run with out=''", "fd.run(scene, out='')"),
        api_case("a modal analysis", "fd.modal_analysis(scene)", admissible=True),
        api_case("a static state", "fd.static_state(scene)", admissible=True),
    ]
    return cases


def mpi_cases() -> list[Case]:
    return [Case(f"mpiexec -n 2 {command}", [command, *args, "--out", "WORK/o"] if command not in ("scene",) else
                 [command, *args], setup=setup, admissible=True, mpi=2)
            for command, args, setup in (
                ("scene", [PAPER], None), ("static", [PAPER, *SMALL], None),
                ("modal", [PAPER, *SMALL], None), ("torque-drag", ["WORK/well.toml"], lambda w: well_files(w)),
                ("campbell", [PAPER, *SMALL, "--set", "campbell.modes=4", "--set",
                              "campbell.rotation_speed=[0.0, 6.0, 3]"], None))]


def compute_cases() -> list[Case]:
    """Admissible inputs at their edges that compute: each must answer, or say it is suspect."""
    return [
        Case("run of 1e-6 s", ["run", PAPER, *SMALL, "--set", "time.t_end=1e-6", "--quiet", "--out", "WORK/o"],
             admissible=True),
        Case("static on 2 elements", ["static", PAPER, "--set", "beam.elements=2", "--set", "beam.length=5",
                                      "--out", "WORK/o"], admissible=True),
        Case("modal with f*_max 64 on a short beam", ["modal", PAPER, *SMALL, "--set", "modal.f_star_max=64",
                                                     "--out", "WORK/o"], admissible=True),
        Case("campbell with one mode", ["campbell", PAPER, *SMALL, "--set", "campbell.modes=1", "--set",
                                        "campbell.rotation_speed=[0.0, 6.0, 2]", "--out", "WORK/o"], admissible=True),
        Case("a run of days", ["run", PAPER, "--set", "time.dt=1e-9", "--set", "time.adaptive=false", "--out",
                               "WORK/o"]),
        Case("plot of an empty directory", ["plot", "WORK/empty"], setup=lambda w: (w / "empty").mkdir()),
        Case("plot of a missing directory", ["plot", "WORK/none"]),
        Case("a scene that is a directory", ["scene", "WORK"]),
        Case("a scene that is /dev/zero", ["scene", "/dev/zero"]),
        Case("a scene in UTF-16", ["scene", "WORK/s.toml"],
             setup=lambda w: (w / "s.toml").write_bytes("[beam]\nelements = 40\n".encode("utf-16"))),
        Case("an override without '='", ["scene", "--set", "beam.elements"]),
        Case("an override of an unknown key", ["scene", "--set", "beam.colour=3"]),
        Case("forms show of an unknown form", ["forms", "show", "no_such_form"]),
        Case("mc with 0 samples", ["mc", PAPER, "--samples", "0", "--out", "WORK/o"]),
    ]


def printed_value(stdout: str, section: str, key: str) -> float | None:
    """The value ``fenics-drill scene`` printed for ``section.key`` (None where it printed none)."""
    current = None
    for line in stdout.splitlines():
        if line.startswith("[") and line.endswith("]"):
            current = line[1:-1]
        elif current == section and line.startswith(f"{key} = "):
            return json.loads(line.split(" = ", 1)[1].split("  #", 1)[0])
    return None


def reads_as(dotted: str, expected: float):
    """A check that ``scene`` printed ``expected`` [SI] for ``dotted`` (a list: its first entry), to round-off."""
    section, key = dotted.split(".")

    def check(stdout, work):
        value = printed_value(stdout, section, key)
        value = value[0] if isinstance(value, list) else value
        if value is None or abs(value - expected) > 1e-12 * max(abs(expected), 1.0):
            return f"{dotted} read as {value!r}, which is not {expected!r}"
        return None

    return check


#: Drilling spellings (key, as written, its SI value by the definitions of NIST SP 811).
SPELLINGS = [
    ("beam.outer_radius", '"3 1/4 in"', 3.25 * 0.0254), ("beam.outer_radius", '"3-1/4 in"', 3.25 * 0.0254),
    ("beam.outer_radius", '"3\u00bc in"', 3.25 * 0.0254), ("beam.outer_radius", "'3 1/4\"'", 3.25 * 0.0254),
    ("beam.outer_radius", "'3.25\"'", 3.25 * 0.0254), ("beam.outer_radius", "\"3.25''\"", 3.25 * 0.0254),
    ("beam.outer_radius", '"3 IN"', 3 * 0.0254), ("well.hole_radius", '["4 13/16 in"]', 4.8125 * 0.0254),
    ("torque_drag.torque_on_bit", '"5 000 N m"', 5000.0), ("torque_drag.torque_on_bit", '"5 kN.m"', 5000.0),
    ("torque_drag.torque_on_bit", '"5 kft-lbf"', 5000 * 0.3048 * 4.4482216152605),
    ("torque_drag.torque_on_bit", '"3700 ft-lbf"', 3700 * 0.3048 * 4.4482216152605),
    ("torque_drag.torque_on_bit", '"5000 Nm"', 5000.0), ("fluid.density", '"1 200 kg/m^3"', 1200.0),
    ("fluid.density", '"78 pcf"', 78 * 0.45359237 / 0.3048**3), ("fluid.density", '"1.25 g/cm3"', 1250.0),
    ("contact.friction", "0,3", 0.3), ("drive.weight_on_bit", '"40 000 N"', 40e3),
    ("drive.weight_on_bit", '"5 klb"', 5e3 * 4.4482216152605), ("drive.weight_on_bit", '"2 tf"', 2000 * 9.80665),
    ("drive.rotation_speed", '"120 1/min"', 4 * 3.141592653589793),
    ("drive.rotation_speed", '"120 min^-1"', 4 * 3.141592653589793),
    ("drive.rotation_speed", '"2 Hz"', 4 * 3.141592653589793), ("drive.rotation_speed", '"120 RPM"', 4 * 3.141592653589793),
    ("drive.rotation_speed", '"120 rev/min"', 4 * 3.141592653589793),
    ("drive.rotation_speed", '"120 r/min"', 4 * 3.141592653589793),
    ("drive.axial_velocity", '"50 fph"', 50 * 0.3048 / 3600), ("drive.rotation_speed", '"\u221260 rpm"', -2 * 3.141592653589793),
]


def unit_cases() -> list[Case]:
    """Drilling spellings read to their SI values (a misread is a silent answer); ambiguous spellings refused."""
    cases = [Case(f"units: {dotted} = {written}", ["scene", "--set", f"{dotted}={written}"], admissible=True,
                  check=reads_as(dotted, si)) for dotted, written, si in SPELLINGS]
    for dotted, written in (("contact.friction", '"1,200"'), ("drive.weight_on_bit", '"4 tonf"'),
                            ("contact.friction", '"17 deg"'), ("drive.weight_on_bit", '"5 00 N"'),
                            ("beam.outer_radius", '"4 5/4 in"'), ("fluid.density", '"1,200 kg/m^3"'),
                            ("drive.weight_on_bit", '"2 ton"')):
        cases.append(Case(f"units: {dotted} = {written} (ambiguous)", ["scene", "--set", f"{dotted}={written}"]))
    return cases


def says(*words):
    """A check that the finished case's output holds ``words`` (its report of the input's meaning)."""
    def check(stdout, work):
        missing = [w for w in words if w not in stdout]
        return f"it did not say {missing[0]!r}" if missing else None

    return check


def well_reading_cases() -> list[Case]:
    """A well as a new user describes it: a survey beside the scene read from elsewhere, feet and their round-off,
    vendors' azimuth columns, a bit smaller than its BHA, a string shorter than its well, weights that the string
    cannot give or carry, a user's file saved while a command runs."""
    vertical = "md,inclination,azimuth\n0,0,0\n120,0,0\n"

    def elsewhere(w):
        well_files(w, vertical)
        (w / "elsewhere").mkdir()
        (w / "elsewhere" / "survey.csv").write_text(SURVEY)

    def tvd_is(expected):
        def check(stdout, work):
            tvd = json.loads((work / "o" / "torque_drag.json").read_text())["well"]["true_vertical_depth_m"]
            return None if abs(tvd - expected) < 1e-6 else f"TVD {tvd:.6g} m, the well's is {expected:g} m"
        return check

    feet = "MD (ft),Inc (deg),Azi (deg)\n0,0,0\n131.23,0,0\n393.70,45,30\n"  # 120.0006 m
    both = "MD (m),Inc (deg),Azi (grid),Azim True (deg)\n0,0,0,0\n40,0,0,0\n120,45,32,30\n"
    grid = "MD (m),Inc (deg),Azi (grid)\n0,0,0\n40,0,0\n120,45,32\n"
    users_file = ("import pathlib, sys\nimport fenics_drill.studies.run as run\nfrom fenics_drill.cli import main\n"
                  "out = pathlib.Path('WORK/o')\nprepare = run.prepare\n"
                  "def meanwhile(*a, **k):\n    (out / 'field_notes.txt').write_text('notes')\n"
                  "    return prepare(*a, **k)\nrun.prepare = meanwhile\n"
                  f"small = {SMALL!r}\nassert main(['static', {PAPER!r}, *small, '--out', str(out)]) == 0\n"
                  "run.prepare = prepare\n"
                  f"sys.exit(main(['static', {PAPER!r}, *small, '--overwrite', '--out', str(out)]))\n")
    bha = ('\n[bit_rock]\nlaw = "detournay"\nbit_radius = "1 1/2 in"\n')
    hook = '\n[drive]\nmode = "hook_load"\n[bit_rock]\nlaw = "detournay"\nbit_radius = 0.09\n'
    return [
        Case("well: a survey beside the scene, read from another folder", ["torque-drag", "../well.toml", "--out",
             "WORK/o"], setup=elsewhere, cwd="WORK/elsewhere", admissible=True, check=tvd_is(120.0)),
        Case("well: a survey in feet ending 0.6 mm past the string", ["scene", "WORK/well.toml"],
             setup=lambda w: well_files(w, feet), admissible=True),
        Case("well: a grid azimuth beside the true one", ["scene", "WORK/well.toml"], setup=lambda w: well_files(w, both),
             admissible=True, check=says("'Azim True (deg)' read as the azimuth")),
        Case("well: a grid azimuth alone", ["scene", "WORK/well.toml"], setup=lambda w: well_files(w, grid)),
        Case("well: a bit smaller than its collars", ["scene", "WORK/well.toml"],
             setup=lambda w: well_files(w, extra=bha)),
        Case("well: a string 20 m shorter than its well", ["torque-drag", "WORK/well.toml", "--out", "WORK/o"],
             setup=lambda w: well_files(w, "md,inclination,azimuth\n0,0,0\n40,0,0\n140,45,30\n"), admissible=True,
             check=says("the bit is 20 m above the well's bottom")),
        Case("well: 1e6 kN on the bit of a hook-load drive, seen by `scene`", ["scene", "WORK/well.toml", "--set",
             'drive.weight_on_bit="1e6 kN"'], setup=lambda w: well_files(w, extra=hook)),
        Case("well: modal.weight_on_bit above the string's weight, hook-load drive", ["modal", "WORK/well.toml", "--set",
             'modal.weight_on_bit="1e3 kN"', "--out", "WORK/o"], setup=lambda w: well_files(w, extra=hook)),
        Case("well: a velocity drive in a well starts on bottom", ["static", "WORK/well.toml", "--out", "WORK/o"],
             setup=lambda w: well_files(w), admissible=True, check=says("the bit pressed at 25 kN")),
        Case("modal: a weightless 50 m pipe pressed beyond its Euler load", ["modal", "--set", "beam.length=50.0",
             "--set", "beam.elements=40", "--set", "well.md=[0.0, 50.0]", "--set", "well.inclination=[0.0, 0.0]",
             "--set", "well.azimuth=[0.0, 0.0]", "--set", "model.gravity=false", "--set", "modal.state='static'",
             "--set", "modal.weight_on_bit=60e3", "--set", "reduction.rule='none'", "--out", "WORK/o"],
             admissible=True, check=says("BUCKLED: the string is buckled at 60 kN")),
        Case("static: a weightless 2000 m string pressed at 168.48 kN", ["static", "--set", "beam.length=2000.0",
             "--set", "beam.elements=100", "--set", "well.md=[0.0, 2000.0]", "--set", "well.inclination=[0.0, 0.0]",
             "--set", "well.azimuth=[0.0, 0.0]", "--set", "model.gravity=false", "--set", "drive.weight_on_bit=168.48e3",
             "--set", "reduction.rule='none'", "--out", "WORK/o"], admissible=True,
             check=says("the top pushes with 168.48 kN", "does not stand")),
        Case("output: a user's file saved while `static` runs, then --overwrite", snippet=users_file,
             keep={"o/field_notes.txt": "notes"}),
    ]


def run_case(case: Case, root: Path) -> dict:
    """Lay out the case's files in a fresh folder, run it, and classify what happened."""
    work = root / f"case{abs(hash(case.name)) % 10**10}"
    work.mkdir()
    if case.setup is not None:
        case.setup(work)
    clock = time.perf_counter()
    if case.snippet:
        command = [PYTHON, "-c", case.snippet.replace("WORK", str(work))]
    else:
        argv = [a.replace("WORK", str(work)) for a in case.argv]
        command = ([MPIEXEC, "-n", str(case.mpi)] if case.mpi else []) + [*TOOL, *argv]
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT,
                                cwd=case.cwd.replace("WORK", str(work)) if case.cwd else ROOT, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return {"name": case.name, "class": "hang", "message": f"still running after {TIMEOUT} s",
                "seconds": TIMEOUT}
    seconds = time.perf_counter() - clock
    err = result.stderr.strip()
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith("  ")
             and "runs on one process" not in line]
    lost = [name for name, text in case.keep.items() if not (work / name).exists() or (work / name).read_text() != text]
    status = None
    summary = work / "o" / "summary.json"
    if summary.exists():
        try:
            status = json.loads(summary.read_text()).get("status")
        except ValueError:
            status = "unreadable"
    if "Traceback (most recent call last)" in result.stderr:
        kind = "traceback"
    elif lost:
        kind = "data loss"
    elif result.returncode == 2:
        kind = "refused" if len(lines) == 1 else "unclear"
    elif result.returncode == 0:
        kind = ("suspect" if status == "suspect" else "correct") if case.admissible else "bad input accepted"
        if not case.admissible and status == "suspect":
            kind = "suspect"
        wrong = case.check(result.stdout, work) if case.check is not None else None
        if wrong:
            kind, lines = "silent answer", [wrong]
    elif status == "failed" and len(lines) <= 2:
        kind = "failed (stated)"
    else:
        kind = "unclear"
    message = lines[-1] if lines else (result.stdout.strip().splitlines() or [""])[-1]
    return {"name": case.name, "class": kind, "message": message[:160], "seconds": round(seconds, 1)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=ROOT / "benchmarks" / "results" / "hostile_probe.md")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--match", default="", help="run only the cases whose name holds this text (a table of them)")
    args = parser.parse_args()
    cases = [*key_cases(), *survey_cases(), *section_cases(), *output_cases(), *api_cases(), *mpi_cases(),
             *compute_cases(), *unit_cases(), *well_reading_cases()]
    cases = [case for case in cases if args.match in case.name]
    root = Path(tempfile.mkdtemp(prefix="fenics-drill-probe-"))
    clock = time.perf_counter()
    try:
        with ThreadPoolExecutor(args.workers) as pool:
            results = list(pool.map(lambda case: run_case(case, root), cases))
    finally:
        shutil.rmtree(root, ignore_errors=True)
    counts = {kind: sum(r["class"] == kind for r in results) for kind in CLASSES}
    lines = ["# Hostile inputs: what each ends in", "",
             f"Command: `python benchmarks/hostile_probe.py`. Machine: {os.cpu_count()} cores, "
             f"{platform.processor() or platform.machine()}, Python {platform.python_version()}. {len(cases)} cases, "
             f"{time.perf_counter() - clock:.0f} s on {args.workers} workers; each case in its own process under a "
             f"{TIMEOUT} s timeout.", "",
             "| " + " | ".join(CLASSES) + " |", "|" + "---|" * len(CLASSES),
             "| " + " | ".join(str(counts[k]) for k in CLASSES) + " |", "",
             "| case | class | what it said | s |", "|---|---|---|---|"]
    for r in results:
        said = r["message"].replace("|", "\\|").replace("\n", " ")
        lines.append(f"| {r['name'].replace('|', chr(92) + '|')} | {r['class']} | {said} | {r['seconds']} |")
    args.table.write_text("\n".join(lines) + "\n")
    print("\n".join(lines[:8]))
    bad = [r for r in results if r["class"] in ("traceback", "hang", "data loss", "unclear", "bad input accepted",
                                                "silent answer")]
    for r in bad:
        print(f"  {r['class']}: {r['name']}: {r['message']}")


if __name__ == "__main__":
    main()
