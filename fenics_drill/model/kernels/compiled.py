"""Compiled kernels of the model (Numba) that Ctrl-C and SIGTERM still stop cleanly.

A run is stopped by a signal handler that raises KeyboardInterrupt
(:mod:`fenics_drill.studies.lifecycle`).  When the signal arrives while a Numba kernel is being
called, Numba reports that exception as a SystemError chained to it, and the run would end as
"failed" instead of "interrupted" (its summary, its exit code 130).  :func:`kernel` compiles a
function (cached on disk, so a process pays the compilation once per install) and calls it through a
wrapper that raises the interrupt as what it is.  Kernels called only from other kernels need
``numba.njit(cache=True)`` alone: the wrapper is for the ones Python calls.

Numba keeps a kernel's compiled code on disk (``__pycache__``) until its own file changes, not when a kernel it
calls from another file does: after editing a kernel that kernels of other files call (the laws and passes that
``solvers/compiled_residual.py`` and ``solvers/compiled_step.py`` call, ``cell_kernels.tabulate_at_cells``), touch
those files or delete their ``__pycache__`` directories, or they run the old code.
"""

from __future__ import annotations

import functools

from numba import njit


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

    @functools.wraps(function)
    def call(*args):
        try:
            return compiled(*args)
        except SystemError as error:
            if interrupt_in(error) is None:
                raise
            raise KeyboardInterrupt from error

    call.compiled = compiled
    return call
