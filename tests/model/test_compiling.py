"""Compiling is never cut short: a Ctrl-C during FFCx's compile of a form leaves its cache whole and still
stops the program once the compile is done; a cache entry left unfinished by a killed process is compiled
afresh (fenics_drill.model.kernels.compiled)."""

import os
import signal
import threading

import dolfinx_solver  # noqa: F401  (before dolfinx)
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_drill.model.kernels.compiled import compiling, form


def _mass_form():
    domain = mesh.create_unit_interval(MPI.COMM_SELF, 4)
    space = fem.functionspace(domain, ("Lagrange", 3))
    u, v = ufl.TrialFunction(space), ufl.TestFunction(space)
    return ufl.inner(u, v) * ufl.dx


def test_a_signal_inside_the_block_arrives_as_it_ends():
    reached_the_end = False
    with pytest.raises(KeyboardInterrupt):
        with compiling():
            signal.raise_signal(signal.SIGINT)
            reached_the_end = True
    assert reached_the_end


def test_a_ctrl_c_during_a_form_compile_leaves_the_cache_whole(tmp_path):
    timer = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))  # lands inside the C compiler's run
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        form(_mass_form(), jit_options={"cache_dir": tmp_path})
    timer.join()
    sources = {p.name for p in tmp_path.glob("libffcx_forms_*.c")}
    assert len(sources) == 1 and (tmp_path / (sources.pop() + ".cached")).exists()


def test_an_entry_left_unfinished_by_a_killed_process_is_compiled_afresh(tmp_path):
    compiled = form(_mass_form(), jit_options={"cache_dir": tmp_path})
    (source,) = tmp_path.glob("libffcx_forms_*.c")
    for done in tmp_path.glob(source.stem + ".*"):  # as a process killed after claiming the entry leaves it
        if done != source:
            done.unlink()
    again = form(_mass_form(), jit_options={"cache_dir": tmp_path, "timeout": 1})
    # the afresh compiled mass matrix integrates 1 over the unit interval: its entries sum to its length exactly
    # (the P3 basis sums to 1); 1e-12 is the round-off of the quadrature and the sum of its 169 entries
    assert fem.assemble_matrix(again).to_dense().sum() == pytest.approx(1.0, rel=1e-12)
    assert fem.assemble_matrix(compiled).to_dense().sum() == pytest.approx(1.0, rel=1e-12)
