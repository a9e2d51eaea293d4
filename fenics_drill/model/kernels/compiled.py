"""Compiled kernels of the model (Numba) that Ctrl-C and SIGTERM still stop cleanly.

A run is stopped by a signal handler that raises KeyboardInterrupt
(:mod:`fenics_drill.studies.lifecycle`).  When the signal arrives while a Numba kernel is being
called, Numba reports that exception as a SystemError chained to it, and the run would end as
"failed" instead of "interrupted" (its summary, its exit code 130).  :func:`kernel` compiles a
function (cached on disk, so a process pays the compilation once per install) and calls it through a
wrapper that raises the interrupt as what it is.  Kernels called only from other kernels need
``numba.njit(cache=True)`` alone: the wrapper is for the ones Python calls.

Compiling is never cut short.  A signal that arrives while FFCx compiles a form or Numba compiles a kernel
(:func:`compiling`) is held until the compiler is done and then delivered as it came: FFCx cut by
KeyboardInterrupt leaves its cache holding a form that never finishes compiling (every later process waits for
it and fails), and Numba cut inside its cache writer fails with an unrelated RuntimeError.  A form whose cache
entry was left so by a process killed outright (SIGKILL) is compiled afresh (:func:`form`).

Numba keeps a kernel's compiled code on disk (``__pycache__``) until its own file changes, not when a kernel it
calls from another file does: after editing a kernel that kernels of other files call (the laws and passes that
``solvers/compiled_residual.py`` and ``solvers/compiled_step.py`` call, ``cell_kernels.tabulate_at_cells``), touch
those files or delete their ``__pycache__`` directories, or they run the old code.
"""

from __future__ import annotations

import contextlib
import functools
import re
import signal
import threading
from pathlib import Path

from numba import njit

#: The signals a command stops on (Ctrl-C, a batch system's SIGTERM), held while compiling.
HELD_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def compiling():
    """A block in which SIGINT and SIGTERM are held: each arrives as it came, to the handler that was in place,
    once the block ends (a no-op outside the main thread, where Python runs no handlers)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    arrived: list[int] = []
    previous = {s: signal.signal(s, lambda signum, frame: arrived.append(signum)) for s in HELD_SIGNALS}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        for signum in dict.fromkeys(arrived):
            signal.raise_signal(signum)


#: FFCx's word for a form whose cache entry another process began and never finished.
_STALE_ENTRY = re.compile(r"remove (\S+\.c)\)")


def form(ufl_form, **options):
    """``dolfinx.fem.form`` compiled whole (:func:`compiling`); a cache entry left unfinished by a killed process
    is set aside (as FFCx sets aside a failed one) and the form compiled afresh."""
    from dolfinx import fem

    with compiling():
        try:
            return fem.form(ufl_form, **options)
        except TimeoutError as error:
            stale = _STALE_ENTRY.search(str(error))
            if stale is None or not Path(stale.group(1)).exists():
                raise
            path = Path(stale.group(1))
            path.replace(path.with_suffix(".c.failed"))
            return fem.form(ufl_form, **options)


def interrupt_in(error: BaseException) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt that ``error`` was chained from, if any."""
    seen = 0
    while error is not None and seen < 16:
        if isinstance(error, KeyboardInterrupt):
            return error
        error, seen = error.__cause__ or error.__context__, seen + 1
    return None


#: Numba's fastmath flags for kernels that sum long products: reassociated (vectorised) sums and fused
#: multiply-adds, which change results by round-off only; NaN and infinity keep their meaning.
REASSOCIATE = frozenset({"reassoc", "contract"})


def kernel(function=None, *, fastmath=False):
    """``function`` compiled by Numba (nopython, cached), called so that an interrupt is not a failure;
    ``fastmath``: Numba's flags (e.g. :data:`REASSOCIATE`).  The compiled function itself is the wrapper's
    ``compiled``: what another kernel calls."""
    if function is None:
        return functools.partial(kernel, fastmath=fastmath)
    compiled = njit(cache=True, fastmath=set(fastmath) if fastmath else False)(function)
    loaded = False  # whether this process has called it once (asking Numba for its signatures costs ~10 us a call)

    @functools.wraps(function)
    def call(*args):
        nonlocal loaded
        try:
            if not loaded:  # its first call in this process compiles it, or loads it from the cache
                with compiling():
                    out = compiled(*args)
                loaded = True
                return out
            return compiled(*args)
        except SystemError as error:
            if interrupt_in(error) is None:
                raise
            raise KeyboardInterrupt from error

    call.compiled = compiled
    return call
