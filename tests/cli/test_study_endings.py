"""How every command ends, tried as a user meets it: Ctrl-C on an MPI study, kills, a full disk, values the
scene accepts at their edges, and figures drawn from a directory that changes.  Each test runs the installed
command in subprocesses under a timeout, so that a hang fails the test instead of blocking the suite
(docs/reliability.md)."""

import json
import os
import resource
import signal
import subprocess
import time
from pathlib import Path

import pytest

from fenics_drill.io.output_directory import LOCK_NAME, summary_of

from test_reliability import MPIEXEC, PAPER, ROOT, TOOL  # noqa: E402  (the same command, the same scene)

SMALL = ["--set", "beam.length=20", "--set", "beam.elements=40", "--set", "output.field_interval=0"]
#: A hang shows up as a timeout of this many seconds.
TIMEOUT = 180
#: The longest a study may take to end after one Ctrl-C (the issue's promise).
STOP_WITHIN_S = 10.0


def tool(*args, timeout=TIMEOUT, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([*TOOL, *args], capture_output=True, text=True, timeout=timeout, cwd=ROOT, **kwargs)


def start_mpi(*args) -> subprocess.Popen:
    return subprocess.Popen([MPIEXEC, "-n", "2", *TOOL, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=ROOT, start_new_session=True)


def wait_for(condition, timeout=TIMEOUT, what="the condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.05)
    raise AssertionError(f"{what} never happened within {timeout} s")


def realisations(out: Path) -> int:
    return len(list((out / "realisations").glob("*.h5"))) if (out / "realisations").is_dir() else 0


def stop_and_time(process: subprocess.Popen, signum=signal.SIGINT) -> tuple[float, str]:
    """Send ``signum`` to mpiexec (as a terminal's Ctrl-C does); the seconds until the job ended, and stderr."""
    sent = time.monotonic()
    process.send_signal(signum)
    try:
        _, err = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise AssertionError("the study did not end within 60 s of one signal")
    return time.monotonic() - sent, err


#: A short study; the paper's wall friction keeps its realisations reduced and quick (these tests are about how a
#: study ends, not about its physics).
MC = ["mc", PAPER, *SMALL, "--set", "time.t_end=0.3", "--samples", "8", "--quiet", "--set",
      "contact.friction_model='paper'", "--set", "contact.sliding_velocity_scale=1e-3"]


@pytest.fixture(scope="module")
def compiled_study(tmp_path_factory):
    """The study's forms and kernels compiled once before a signal is timed: a signal that arrives while a compiler
    runs waits until it is done (docs/reliability.md), which on a fresh install can take longer than the promise."""
    out = tmp_path_factory.mktemp("warm") / "mc"
    done = tool("mc", PAPER, *SMALL, "--set", "time.t_end=0.01", "--samples", "1", "--quiet", "--set",
                "contact.friction_model='paper'", "--set", "contact.sliding_velocity_scale=1e-3", "--out", str(out))
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("moment", ["during the set-up", "once two realisations are written"])
def test_one_ctrl_c_ends_an_mpi_monte_carlo_within_10_s_as_interrupted(compiled_study, tmp_path, moment):
    out = tmp_path / "mc"
    process = start_mpi(*MC, "--out", str(out))
    if moment == "during the set-up":
        wait_for(lambda: (out / "summary.json").exists(), what="the study's start")
        time.sleep(0.5)
    else:
        wait_for(lambda: realisations(out) >= 2, what="two realisations")
    took, err = stop_and_time(process)
    assert took < STOP_WITHIN_S, err
    assert process.returncode == 130, err
    assert "Traceback" not in err
    summary = summary_of(out)
    assert summary["status"] == "interrupted" and summary["samples"] == 8
    assert summary["realisations_done"] == realisations(out) < 8


def test_sigterm_ends_an_operating_window_as_interrupted_and_resume_finishes_it(tmp_path):
    out = tmp_path / "window"
    args = ["optimize", PAPER, *SMALL, "--set", "time.t_end=0.2", "--set", "optimize.axial_velocity=[0.003, 0.006, 3]",
            "--set", "optimize.rotation_speed=[4.0, 6.0, 3]", "--quiet", "--out", str(out)]
    process = start_mpi(*args)
    wait_for(lambda: len(list((out / "points").glob("*.json"))) >= 2 if (out / "points").is_dir() else False,
             what="two window points")
    took, err = stop_and_time(process, signal.SIGTERM)
    assert took < STOP_WITHIN_S and process.returncode == 130, err
    assert summary_of(out)["status"] == "interrupted"
    finished = subprocess.run([MPIEXEC, "-n", "2", *TOOL, *args, "--resume"], capture_output=True, text=True,
                              cwd=ROOT, timeout=TIMEOUT)
    assert finished.returncode == 0, finished.stderr
    assert summary_of(out)["status"] == "finished"


def test_a_study_killed_without_a_word_reads_as_killed(tmp_path):
    """SIGKILL to every process (the out-of-memory killer, a node lost): nothing can write the summary, and the
    next command that reads the directory sees the dead process."""
    out = tmp_path / "mc"
    process = start_mpi(*MC, "--out", str(out))
    wait_for(lambda: realisations(out) >= 1, what="a realisation")
    os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)
    wait_for(lambda: summary_of(out)["status"] == "killed", timeout=10, what="the dead pid being seen")
    plotted = tool("plot", str(out))
    assert plotted.returncode == 2 and "killed" in plotted.stderr and "Traceback" not in plotted.stderr
    resumed = subprocess.run([MPIEXEC, "-n", "2", *TOOL, *MC, "--out", str(out), "--resume"], capture_output=True,
                             text=True, cwd=ROOT, timeout=TIMEOUT)
    assert resumed.returncode == 0 and summary_of(out)["status"] == "finished"


def test_a_failing_rank_leaves_a_failed_summary_with_its_message(tmp_path):
    """Rank 0 alone runs the nominal realisation: its file made a directory that cannot be moved aside."""
    out = tmp_path / "mc"
    args = [*MC, "--set", "time.t_end=0.02", "--samples", "2"]
    assert subprocess.run([MPIEXEC, "-n", "2", *TOOL, *args, "--out", str(out)], capture_output=True,
                          timeout=TIMEOUT, cwd=ROOT).returncode == 0
    (out / "nominal.h5").unlink()
    for blocker in ("nominal.h5", "nominal.h5.corrupt"):
        (out / blocker).mkdir()
        (out / blocker / "x").write_text("")
    result = subprocess.run([MPIEXEC, "-n", "2", *TOOL, *args, "--out", str(out), "--resume"], capture_output=True,
                            text=True, timeout=TIMEOUT, cwd=ROOT)
    assert result.returncode != 0
    summary = summary_of(out)
    # written by the failing rank ("rank 0: ...") or by the other, which stopped on its marker ("rank 0 failed: ...")
    assert summary["status"] == "failed" and summary["message"].startswith("rank 0")
    assert "Directory not empty" in summary["message"]


# A full disk: every write beyond a size limit fails (RLIMIT_FSIZE, the per-file quota of ulimit -f)


def _file_size_limit(limit: int):
    def apply():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit then fails with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def test_a_full_disk_fails_a_run_in_one_line_with_a_final_summary(tmp_path):
    out = tmp_path / "run"
    # 6 MB: MPI's own shared-memory files (4.3 MB) must still fit, the time series of 5 s (9 MB) does not
    result = subprocess.run([*TOOL, "run", PAPER, *SMALL, "--set", "time.t_end=5", "--set",
                             "contact.friction_model='paper'", "--quiet", "--out", str(out)],  # reduced: quick
                            capture_output=True, text=True, cwd=ROOT, timeout=TIMEOUT,
                            preexec_fn=_file_size_limit(6_000_000))
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [f"fenics-drill: cannot write to {out}: a file reached the size "
                                                  "limit (ulimit -f)"]
    summary = summary_of(out)
    assert summary["status"] == "failed" and "size limit" in summary["message"]
    assert 0 < summary["t_end"] < 5 and summary["steps"] > 0


@pytest.fixture
def small_disk(tmp_path):
    """A 300 kB file system (tmpfs): where this machine lets the tests mount one (root), a disk that fills up."""
    mount = tmp_path / "small"
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", str(mount)],
                      capture_output=True).returncode != 0:
        pytest.skip("no tmpfs can be mounted here")
    yield mount
    subprocess.run(["umount", str(mount)], capture_output=True)


def test_a_full_disk_ends_an_mpi_study_in_one_line_per_rank_with_a_failed_summary(small_disk):
    out = small_disk / "mc"
    result = subprocess.run([MPIEXEC, "-n", "2", *TOOL, *MC, "--samples", "40", "--out", str(out)],
                            capture_output=True, text=True, cwd=ROOT, timeout=TIMEOUT)
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    ours = [line for line in result.stderr.splitlines() if line.startswith("fenics-drill")]
    assert ours and all("no space left on the device" in line for line in ours), result.stderr
    summary = summary_of(out)
    assert summary["status"] == "failed" and "no space left" in summary["message"]


# Values the scene accepts at their edges, and resources: one line each, before any computation


@pytest.mark.parametrize("command, overrides, words", [
    ("run", ["beam.elements=1"], "beam.elements = 1 is not admissible"),
    ("campbell", ["beam.elements=1"], "beam.elements = 1 is not admissible"),
    ("run", ["time.t_end=1e-300"], "time.t_end = 1e-300 is not admissible"),
    ("run", ["beam.length=1e-9"], "beam.length = 1e-09 is not admissible"),
    ("run", ["beam.length=1e308"], "beam.length = 1e+308 is not admissible"),
    ("run", ["beam.length=0.01"], "beam.length = 0.01 is not admissible"),
    ("run", ["beam.density=1e-300"], "beam.density = 1e-300 is not admissible"),
    ("modal", ["modal.f_star_max=1e-9"], "modal.f_star_max = 1e-09 is not admissible"),
    ("mc", ["uncertainty.output_interval=1e-12"], "uncertainty.output_interval = 1e-12 is not admissible"),
    ("run", ["supports.stabilisers=[0.01]"], "snaps onto the end vertex"),
])
def test_values_at_the_edges_are_refused_in_one_line(tmp_path, command, overrides, words):
    extra = ["--samples", "2"] if command == "mc" else []
    result = tool(command, PAPER, *[a for o in overrides for a in ("--set", o)], *extra, "--out", str(tmp_path / "o"),
                  timeout=60)
    assert result.returncode == 2 and words in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not (tmp_path / "o").exists()


def test_scenes_that_are_not_regular_files_or_are_empty_are_refused(tmp_path):
    fifo, empty = tmp_path / "scene.fifo", tmp_path / "empty.toml"
    os.mkfifo(fifo)
    empty.write_text("\n")
    for scene, words in (("/dev/zero", "is not a regular file"), (fifo, "is not a regular file"), (empty, "is empty")):
        result = tool("run", str(scene), "--out", str(tmp_path / "o"), timeout=30)
        assert result.returncode == 2 and words in result.stderr, result.stderr


def test_a_refused_command_leaves_nothing_behind_and_resume_of_nothing_is_refused(tmp_path):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("the user's")
    assert tool("static", PAPER, "--out", str(mine)).returncode == 2
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]  # no lock file left
    result = tool("mc", PAPER, "--samples", "2", "--resume", "--out", str(tmp_path / "none"))
    assert result.returncode == 2 and "holds no 'fenics-drill mc' study to continue" in result.stderr
    assert not (tmp_path / "none").exists() and not (mine / LOCK_NAME).exists()


def test_campbell_overwrites_its_own_output(tmp_path):
    args = ["campbell", PAPER, "--set", "beam.length=10", "--set", "beam.elements=20", "--set", "campbell.modes=4",
            "--set", "campbell.rotation_speed=[0.0, 10.0, 3]", "--out", str(tmp_path)]
    assert tool(*args).returncode == 0
    second = tool(*args, "--overwrite")
    assert second.returncode == 0, second.stderr


# Figures know what they show


def test_figures_of_a_killed_run_say_so_and_a_new_run_removes_them(tmp_path):
    out = tmp_path / "run"
    process = subprocess.Popen([*TOOL, "run", PAPER, *SMALL, "--set", "time.t_end=1000", "--quiet", "--out",
                                str(out)], cwd=ROOT, start_new_session=True, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    wait_for(lambda: (out / "summary.json").exists() and summary_of(out).get("t_end", 0) > 0, what="progress")
    running = summary_of(out)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)
    import h5py

    with h5py.File(out / "timeseries.h5") as f:
        rows = len(f["time"])
    assert running["steps"] + 1 <= rows  # the summary's steps are rows the file held when it was written
    plotted = tool("plot", str(out), "--no-gif")
    assert plotted.returncode == 0 and "the run is killed" in plotted.stdout
    record = json.loads((out / "figures.json").read_text())
    assert record["drawn_from"]["status"] == "killed" and record["drawn_from"]["rows"] == rows
    assert "fig14_bit_axial.png" in record["figures"] and (out / "fig14_bit_axial.png").exists()
    again = tool("run", PAPER, *SMALL, "--set", "time.t_end=0.05", "--quiet", "--overwrite", "--out", str(out))
    assert again.returncode == 0
    assert not (out / "fig14_bit_axial.png").exists() and not (out / "figures.json").exists()
