"""Nothing lost, nothing stale, nothing hung (docs/reliability.md): each failure of a long-running solver
tried the way a user meets it - the installed command in a subprocess, real signals, real MPI - under
timeouts, so that a hang fails the test instead of blocking the suite."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

from fenics_drill.io.fields import FieldSnapshots

ROOT = Path(__file__).parents[2]
PAPER = str(ROOT / "demos" / "scenes" / "paper.toml")
TOOL = [sys.executable, "-m", "fenics_drill.cli"]
MPIEXEC = str(Path(sys.executable).parent / "mpiexec")
#: A short string: a few seconds of setup, then as long a run as asked for.
SMALL = ["--set", "beam.length=20", "--set", "beam.elements=40", "--set", "output.field_interval=0.01"]
#: A hang shows up as a timeout of this many seconds instead of a blocked suite.
TIMEOUT = 120


def tool(*args, timeout=TIMEOUT, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([*TOOL, *args], capture_output=True, text=True, timeout=timeout, cwd=ROOT, **kwargs)


def mpi(ranks, *args) -> subprocess.CompletedProcess:
    return subprocess.run([MPIEXEC, "-n", str(ranks), *TOOL, *args], capture_output=True, text=True,
                          timeout=TIMEOUT, cwd=ROOT)


def start(*args) -> subprocess.Popen:
    """The tool in the background, in its own session (so a test can signal its process group)."""
    return subprocess.Popen([*TOOL, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
                            start_new_session=True)


def summary_of(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def wait_until_running(out: Path, past: float = 0.0, timeout: float = TIMEOUT) -> dict:
    """Wait until the run's summary says "running" beyond simulated time ``past`` (it is rewritten at
    every write of the files, every ~2 s of wall time)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            summary = summary_of(out)
            if summary.get("status") == "running" and summary.get("t_end", 0.0) > past:
                return summary
        except (OSError, ValueError):
            pass
        time.sleep(0.1)
    raise AssertionError(f"the run in {out} never reported progress")


# 1. MPI: one rank's failure ends the job


def test_mpi_study_into_a_file_ends_every_rank_with_the_message(tmp_path):
    target = tmp_path / "f"
    target.write_text("x")
    result = mpi(2, "mc", PAPER, *SMALL, "--set", "time.t_end=0.05", "--samples", "4", "--out", str(target))
    assert result.returncode == 2
    assert f"--out {target} is a file" in result.stderr


def test_mpi_window_into_an_uncreatable_path_ends_every_rank(tmp_path):
    result = mpi(2, "optimize", PAPER, *SMALL, "--set", "time.t_end=0.05", "--out", "/proc/fenics-drill/out")
    assert result.returncode == 2
    assert "cannot create --out /proc/fenics-drill/out" in result.stderr


def test_mpi_study_with_a_corrupt_scene_record_is_refused_naming_it(tmp_path):
    args = ["mc", PAPER, *SMALL, "--set", "time.t_end=0.02", "--samples", "2", "--out", str(tmp_path)]
    assert mpi(2, *args).returncode == 0
    (tmp_path / "scene.json").write_text('{"beam": ')  # truncated
    result = mpi(2, *args, "--resume")
    assert result.returncode == 2
    assert "scene.json is not a readable JSON file" in result.stderr


def test_a_truncated_realisation_is_named_and_computed_again_on_resume(tmp_path):
    args = ["mc", PAPER, *SMALL, "--set", "time.t_end=0.02", "--samples", "4", "--out", str(tmp_path)]
    assert mpi(2, *args).returncode == 0
    with h5py.File(tmp_path / "statistics.h5") as f:
        reference = f["bit_velocity/mean"][()]
    broken = tmp_path / "realisations" / "000002.h5"
    broken.write_bytes(broken.read_bytes()[:300])
    result = mpi(2, *args, "--resume")
    assert result.returncode == 0, result.stderr
    assert "000002.h5" in result.stderr and (tmp_path / "realisations" / "000002.h5.corrupt").exists()
    with h5py.File(tmp_path / "statistics.h5") as f:  # the recomputed realisation is the same one
        np.testing.assert_array_equal(f["bit_velocity/mean"][()], reference)


def test_an_unexpected_error_on_one_rank_aborts_the_job_instead_of_hanging(tmp_path):
    """Rank 0 alone runs the nominal realisation: when it cannot (its file is a directory that cannot even
    be moved aside), rank 0 fails while rank 1 goes on to the final barrier; MPI_Abort ends both."""
    args = ["mc", PAPER, *SMALL, "--set", "time.t_end=0.02", "--samples", "2", "--out", str(tmp_path)]
    assert mpi(2, *args).returncode == 0
    (tmp_path / "nominal.h5").unlink()
    for blocker in ("nominal.h5", "nominal.h5.corrupt"):
        (tmp_path / blocker).mkdir()
        (tmp_path / blocker / "x").write_text("")
    result = mpi(2, *args, "--resume")
    assert result.returncode != 0
    # rank 0's failure is named by rank 0 itself or, when the job ends before rank 0 has written its line, by
    # rank 1, which read it from rank 0's marker: either way the user learns which rank failed and why
    assert "rank 0 of 2" in result.stderr or "rank 0 failed: OSError" in result.stderr, result.stderr


# 2. Stale output is never shown as current


def test_a_second_run_into_the_same_directory_needs_overwrite_and_then_leaves_nothing_stale(tmp_path):
    first = tool("run", PAPER, *SMALL, "--set", "time.t_end=0.05", "--quiet", "--out", str(tmp_path))
    assert first.returncode == 0, first.stderr
    assert tool("plot", str(tmp_path), "--no-gif").returncode == 0
    again = tool("run", PAPER, *SMALL, "--set", "time.t_end=0.02", "--quiet", "--out", str(tmp_path))
    assert again.returncode == 2 and "--overwrite" in again.stderr
    assert summary_of(tmp_path)["t_end"] == pytest.approx(0.05)  # the first run is untouched
    replaced = tool("run", PAPER, *SMALL, "--set", "time.t_end=0.02", "--quiet", "--overwrite", "--out",
                    str(tmp_path))
    assert replaced.returncode == 0
    assert not list(tmp_path.glob("fig*.png"))  # the first run's figures went with it
    snapshots = FieldSnapshots(tmp_path / "fields.h5")
    assert snapshots.times.max() == pytest.approx(0.02)


def test_a_run_that_fails_at_t0_is_not_plotted(tmp_path):
    result = tool("run", PAPER, *SMALL, "--set", "time.max_step_cuts=0", "--set", "solver.newton_max_iterations=1",
                  "--quiet", "--out", str(tmp_path))
    assert result.returncode == 1
    assert summary_of(tmp_path)["status"] == "failed"
    plotted = tool("plot", str(tmp_path))
    assert plotted.returncode == 2 and "nothing to draw" in plotted.stderr


def test_a_study_never_writes_into_a_run_directory(tmp_path):
    assert tool("run", PAPER, *SMALL, "--set", "time.t_end=0.02", "--quiet", "--out", str(tmp_path)).returncode == 0
    before = (tmp_path / "summary.json").read_text()
    result = tool("mc", PAPER, *SMALL, "--samples", "2", "--out", str(tmp_path), "--overwrite")
    assert result.returncode == 2 and "holds a drilling run" in result.stderr
    assert (tmp_path / "summary.json").read_text() == before


# 3. SIGKILL loses at most the last seconds


def test_sigkill_leaves_readable_series_fields_and_summary(tmp_path):
    process = start("run", PAPER, *SMALL, "--set", "time.t_end=1000", "--quiet", "--out", str(tmp_path))
    running = wait_until_running(tmp_path, past=0.0)
    os.killpg(process.pid, signal.SIGKILL)  # the whole process group, as the out-of-memory killer would
    process.wait(timeout=30)
    summary = summary_of(tmp_path)
    assert summary["status"] == "running" and summary["t_end"] >= running["t_end"] > 0
    with h5py.File(tmp_path / "timeseries.h5") as f:
        t = f["time"][()]
    assert t[-1] >= summary["t_end"] > 0  # every row up to the last write, and the summary says how far
    assert xr.load_dataset(tmp_path / "timeseries.h5", engine="h5netcdf").sizes["time"] == len(t)
    snapshots = FieldSnapshots(tmp_path / "fields.h5")
    assert len(snapshots.times) >= 2 and "w" in snapshots.fields


def test_sigkill_of_the_tool_alone_also_ends_its_worker(tmp_path):
    process = start("run", PAPER, *SMALL, "--set", "time.t_end=1000", "--quiet", "--out", str(tmp_path))
    wait_until_running(tmp_path)
    worker = summary_of(tmp_path)["pid"]
    process.kill()  # SIGKILL to the tool only
    process.wait(timeout=30)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and Path(f"/proc/{worker}").exists():
        time.sleep(0.1)
    assert not Path(f"/proc/{worker}").exists() or "zombie" in Path(f"/proc/{worker}/status").read_text()


# 4. Runs that can always be stopped, and sizes the machine can hold


def test_a_mesh_beyond_the_machine_is_refused_before_allocating(tmp_path):
    result = tool("run", PAPER, "--set", "beam.elements=10000000", "--out", str(tmp_path / "out"), timeout=30)
    assert result.returncode == 2
    assert "beam.elements = 10000000" in result.stderr and "fits" in result.stderr
    assert not (tmp_path / "out").exists()  # refused before even the output directory is made


def test_the_memory_check_counts_every_rank_on_the_machine(monkeypatch):
    """Each rank of a run, mc or optimize holds a model of its own: a mesh that one process can hold with room to
    spare is refused when as many ranks as the process manager says share the machine would need more than it has,
    and the size it offers fits that many."""
    from fenics_drill.model import resources

    one = resources.estimated_memory(2000, 2)
    monkeypatch.setattr(resources, "available_memory", lambda: 1.5 * one / resources.USABLE_SHARE)
    monkeypatch.delenv("MPI_LOCALNRANKS", raising=False)
    monkeypatch.delenv("OMPI_COMM_WORLD_LOCAL_SIZE", raising=False)
    resources.check_memory(2000, 2)  # 1.5 times what it needs
    monkeypatch.setenv("MPI_LOCALNRANKS", "2")
    with pytest.raises(resources.ResourceError, match="on each of 2 ranks") as refused:
        resources.check_memory(2000, 2)
    fits = int(str(refused.value).rsplit("beam.elements = ", 1)[1].split()[0])
    assert 2 * resources.estimated_memory(fits, 2) <= 1.5 * one < 2 * resources.estimated_memory(fits + 1, 2)


def test_sigterm_inside_a_long_c_call_stops_the_run_within_the_grace_time(tmp_path):
    """60 000 elements: the worker sits in mesh building and the modal factorisation (minutes), where Python
    cannot see the signal; the tool ends it after its 5 s of grace and says so in the summary."""
    process = start("run", PAPER, "--set", "beam.elements=60000", "--quiet", "--out", str(tmp_path))
    deadline = time.monotonic() + 60
    while not (tmp_path / "summary.json").exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)
    sent = time.monotonic()
    process.send_signal(signal.SIGTERM)
    assert process.wait(timeout=30) == 130
    assert time.monotonic() - sent < 15  # 5 s of grace, then SIGKILL
    summary = summary_of(tmp_path)
    assert summary["status"] == "interrupted" and "SIGTERM" in summary["message"]


def test_a_huge_window_is_refused_when_the_scene_is_read(tmp_path):
    result = tool("optimize", PAPER, "--set", "optimize.samples=100000000", "--out", str(tmp_path / "o"), timeout=30)
    assert result.returncode == 2 and "optimize.samples" in result.stderr and not (tmp_path / "o").exists()


# 5. Ordinary errors: a message naming the file, the key or the path, never a traceback


@pytest.mark.parametrize("content, words", [
    ("\ufeff[beam]\nlength = 3\n".encode("utf-16"), "not UTF-8 text"),
    (bytes(range(256)), "not UTF-8 text"),
    (b"[beam\nlength = ", "not valid TOML"),
])
def test_bad_scene_files_are_refused_with_the_file_named(tmp_path, content, words):
    scene = tmp_path / "scene.toml"
    scene.write_bytes(content)
    result = tool("run", str(scene), "--out", str(tmp_path / "out"), timeout=30)
    assert result.returncode == 2 and words in result.stderr and str(scene) in result.stderr
    assert "Traceback" not in result.stderr


def test_a_directory_or_an_unreadable_path_as_the_scene_is_said_so(tmp_path):
    result = tool("static", str(tmp_path), "--out", str(tmp_path / "out"), timeout=30)
    assert result.returncode == 2 and "is a directory" in result.stderr
    result = tool("static", "/proc/self/mem", "--out", str(tmp_path / "out"), timeout=30)
    assert result.returncode == 2 and "cannot be read" in result.stderr and "Traceback" not in result.stderr


def test_out_pointing_at_a_file_is_refused(tmp_path):
    target = tmp_path / "file"
    target.write_text("")
    result = tool("static", PAPER, *SMALL, "--out", str(target), timeout=60)
    assert result.returncode == 2 and "is a file" in result.stderr and "Traceback" not in result.stderr


def test_two_runs_on_one_directory_the_second_is_refused_and_the_first_goes_on(tmp_path):
    first = start("run", PAPER, *SMALL, "--set", "time.t_end=1000", "--quiet", "--out", str(tmp_path))
    pid = wait_until_running(tmp_path)["pid"]
    second = tool("run", PAPER, *SMALL, "--set", "time.t_end=0.01", "--overwrite", "--quiet", "--out", str(tmp_path))
    assert second.returncode == 2 and f"in use by another fenics-drill process (pid {pid})" in second.stderr
    assert summary_of(tmp_path)["pid"] == pid  # the first run's summary, still its own
    os.killpg(first.pid, signal.SIGTERM)
    assert first.wait(timeout=30) == 130
    assert summary_of(tmp_path)["status"] == "interrupted"


def test_plot_of_a_truncated_time_series_names_the_file(tmp_path):
    assert tool("run", PAPER, *SMALL, "--set", "time.t_end=0.02", "--quiet", "--out", str(tmp_path)).returncode == 0
    series = tmp_path / "timeseries.h5"
    series.write_bytes(series.read_bytes()[:2000])
    result = tool("plot", str(tmp_path), timeout=60)
    assert result.returncode == 2 and str(series) in result.stderr and "Traceback" not in result.stderr


# 6. Two quick Ctrl-C still leave the summary


def test_two_quick_ctrl_c_leave_an_interrupted_summary(tmp_path):
    process = start("run", PAPER, *SMALL, "--set", "time.t_end=1000", "--quiet", "--out", str(tmp_path))
    wait_until_running(tmp_path)
    os.killpg(process.pid, signal.SIGINT)  # Ctrl-C reaches the whole foreground group
    time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    assert process.wait(timeout=30) == 130
    summary = summary_of(tmp_path)
    assert summary["status"] == "interrupted" and summary["t_end"] > 0 and "energy" in summary


def test_a_signal_inside_the_recording_of_a_step_stops_the_run_only_after_it():
    """The CI once saw an interrupted run whose summary named a step before the last row of its series: SIGTERM
    had landed between the recorder's rows and its state (studies/run.py).  Inside ``uninterrupted`` a signal
    must wait: the block runs to its end, then KeyboardInterrupt comes, and later signals are ignored."""
    from fenics_drill.studies.lifecycle import StopOnSignal, uninterrupted

    done = []
    with pytest.raises(KeyboardInterrupt):
        with StopOnSignal():
            with uninterrupted():
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(0.05)  # the handler runs here, between two bytecodes
                done.append("rows")
                os.kill(os.getpid(), signal.SIGINT)  # a second signal: ignored
                time.sleep(0.05)
                done.append("state")
            done.append("after")  # not reached: the deferred interrupt comes as the block ends
    assert done == ["rows", "state"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # the handlers are given back


def test_an_interrupt_that_something_swallowed_still_stops_the_run_at_the_next_step():
    """A KeyboardInterrupt raised where Python only prints it (a destructor, a C library's callback) was lost:
    the signals were ignored from then on and the run went on until the supervisor killed it, without its
    summary.  The next step's recording must raise it again; the writing of the summary must not."""
    from fenics_drill.studies.lifecycle import StopOnSignal, uninterrupted

    with StopOnSignal():
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.05)
        except KeyboardInterrupt:
            pass  # swallowed
        with uninterrupted(stop_after=False):
            pass  # the summary's block: no interrupt
        with pytest.raises(KeyboardInterrupt):
            with uninterrupted():
                pass


def test_the_ranks_of_a_shared_run_stop_only_where_they_exchange_the_signal():
    """The CI saw a two-rank run crash in MPI ("Message truncated") after Ctrl-C: one rank got the signal between
    two steps, raised at once and left, while the other, which had not yet seen it, went on to the next step's
    exchange and met the first rank's exit in it.  Under a collective StopOnSignal a signal outside any block,
    and inside a block without ``comm``, must not raise; the next exchange with ``comm`` stops every rank."""
    from fenics_drill.studies.lifecycle import StopOnSignal, agree_to_stop, uninterrupted

    class OneRank:  # what an allreduce with MPI.LOR gives on one rank
        def allreduce(self, value, op):
            return value

    with StopOnSignal(collective=True):
        agree_to_stop(OneRank())  # no signal yet: nothing
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)  # between two steps: only noted
        with uninterrupted():  # a block that is not an exchange (the set-up's own runs)
            pass
        with pytest.raises(KeyboardInterrupt):
            with uninterrupted(comm=OneRank()):
                pass
        with pytest.raises(KeyboardInterrupt):
            agree_to_stop(OneRank())


# 7. Impossible states are not "finished"


def test_zero_contact_stiffness_with_contact_on_is_refused(tmp_path):
    result = tool("run", PAPER, "--set", "contact.stiffness_linear=0", "--out", str(tmp_path), timeout=30)
    assert result.returncode == 2 and "contact.stiffness_linear" in result.stderr


def test_a_wall_the_string_goes_through_makes_the_run_suspect(tmp_path):
    """k_FS1 = 1e5 N/m and no cubic spring: each vertex carries ~190 N of weight, so the string sinks ~2 mm
    into the wall, more than 10 % of the 15 mm gap.  (The paper's modal basis: with so soft a wall the
    static state is not found in the full order, docs/verification.md.)"""
    result = tool("run", PAPER, *SMALL, "--set", "contact.stiffness_linear=1e5", "--set", "contact.stiffness_cubic=0",
                  "--set", "reduction.enrich=false", "--set", "reduction.guard_tolerance=1",
                  "--set", "time.t_end=0.01", "--quiet", "--out", str(tmp_path))
    assert result.returncode == 0 and "SUSPECT" in result.stdout
    summary = summary_of(tmp_path)
    assert summary["status"] == "suspect" and summary["max_penetration"] > 0.1 * 0.015
    assert "into the wall" in summary["suspect_reasons"][0]


def test_steps_forced_at_the_minimum_size_make_the_run_suspect(tmp_path):
    result = tool("run", PAPER, *SMALL, "--set", "time.max_step_cuts=0", "--set", "time.error_tolerance=1e-15",
                  "--set", "time.t_end=0.01", "--quiet", "--out", str(tmp_path))
    assert result.returncode == 0
    summary = summary_of(tmp_path)
    assert summary["status"] == "suspect" and summary["forced_steps"] == summary["steps"]
    assert "minimum step size" in summary["suspect_reasons"][0]
