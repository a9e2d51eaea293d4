"""Compiled kernels stop like the rest of the code when a run is interrupted (fenics_drill/model/kernels/compiled.py)."""

import os
import signal
import threading

import numpy as np
import pytest

from fenics_drill.model.forces.wall.vertex_passes import _vertex_loads


def interrupt(signum, frame):
    raise KeyboardInterrupt


def test_an_interrupt_that_arrives_inside_a_kernel_is_a_keyboard_interrupt():
    """The signal handler of a run raises KeyboardInterrupt (studies/lifecycle.py).  Raised while a Numba
    kernel is called, Numba turned it into a SystemError, and the run ended "failed" with exit code 1
    instead of "interrupted" with 130 (seen in tests/cli/test_run_outputs.py under load).  Five signals
    into a loop of wall-law kernels, each must come out as KeyboardInterrupt (before the fix about
    three in four came out as SystemError).  A loop that no signal reaches ends after 200000 calls (a few
    seconds) and fails: nothing here can hang."""
    positions, rates = np.ones((3000, 4)), np.ones((3000, 4))
    gap, arm = np.full(3000, 0.5), np.full(3000, 0.1)  # the clearance and the torque arm at each vertex
    previous = signal.signal(signal.SIGUSR1, interrupt)
    try:
        for _ in range(5):
            timer = threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGUSR1))
            timer.start()
            with pytest.raises(KeyboardInterrupt):
                for _ in range(200000):
                    _vertex_loads(positions, rates, gap, 1.0, 1.0, 1.0, False, 0.2, 0.2, arm, 1e-4, True, 1e10,
                                  positions, np.zeros((3000, 2)), True)
            timer.join()
    finally:
        signal.signal(signal.SIGUSR1, previous)
