"""``python -m navlib`` and the installed ``navlib`` command.

Numerical libraries run on one thread unless the caller's environment says otherwise: the workbench's
linear algebra is tall and skinny (100k x 20 products, QR factors of 100k x 10), where a second BLAS thread
costs more than it gives (the 100k-row compass loop of ``benchmarks/bench_workbench_loop.py``: 10.3 s with
OpenBLAS's two threads, 9.1 s with one, on 2 cores), and the Monte Carlo commands get their parallelism from
worker processes.  The variables must be set before numpy loads, hence here and not in :mod:`navlib.cli`.
"""

import os
import sys

from . import ONE_THREAD


def run() -> int:
    """Entry point: one-thread defaults (a value already in the environment wins), then the CLI."""
    for name, value in ONE_THREAD.items():
        os.environ.setdefault(name, value)
    from .cli import main  # noqa: PLC0415  # lazy: the thread variables must be set before numpy loads

    return main()


if __name__ == "__main__":
    sys.exit(run())
