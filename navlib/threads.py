"""One BLAS thread inside navlib's numerical entry points, for library calls as for the command line.

The workbench's linear algebra is tall and skinny (QR factors of 100k x 10, 100k x 20 products, many small
solves): there a second BLAS thread costs more than it gives, and on a shared 2-core machine OpenBLAS's
threads stall for 50-400 ms on small solves (issue 34 measured ``calibrate()`` in a Python session at 8-20 s
with the default threads against 0.6-0.9 s with one).  The command line sets the thread variables before
numpy loads (``navlib.__main__``); a library call cannot, because numpy is already loaded.  So the entry
points (:func:`navlib.workbench.fit.fit_model`, :func:`~navlib.workbench.diagnose.diagnose`,
:func:`~navlib.workbench.loop.loop`, :func:`~navlib.workbench.calibration.calibrate`) run under
a ``threadpoolctl`` limit of one BLAS thread (:func:`one_blas_thread`).

A caller who set a thread count in the environment (``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS``,
``MKL_NUM_THREADS``) keeps it: the limit applies only where none is set.  Calls nested inside one entry point
pay for the limit once.
"""

from __future__ import annotations

import contextvars
import functools
import os

from threadpoolctl import ThreadpoolController

from . import ONE_THREAD

#: The variables that, set by the caller, mean "use this many threads" (then navlib sets no limit).
THREAD_VARIABLES = tuple(
    k for k in ONE_THREAD if k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
)
_INSIDE = contextvars.ContextVar("navlib_one_blas_thread", default=False)
#: The process's thread pools, found once, at the first limited call (``threadpoolctl.threadpool_limits``
#: looks for them at every call: about 1 ms, a twentieth of a calibration of 1,000 rows).  numpy's and
#: scipy's BLAS are loaded with navlib; a BLAS library loaded after the first call is not limited.
_CONTROLLER: list = []


def _controller() -> ThreadpoolController:
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0]


def caller_chose_threads() -> bool:
    """Whether the environment sets a BLAS thread count (the command line sets 1 before numpy loads)."""
    return any(os.environ.get(k) for k in THREAD_VARIABLES)


def one_blas_thread(func):
    """Decorator: run ``func`` with one BLAS thread (module docstring), unless the caller chose a count or an
    enclosing call already set the limit."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        if _INSIDE.get() or caller_chose_threads():
            return func(*args, **kwargs)
        token = _INSIDE.set(True)
        try:
            with _controller().limit(limits=1, user_api="blas"):
                return func(*args, **kwargs)
        finally:
            _INSIDE.reset(token)

    return wrapper
