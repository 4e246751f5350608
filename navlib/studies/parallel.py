"""Independent tasks of a study in worker processes, so a chapter uses every core of the machine.

Every run of every method draws from its own generator (:mod:`navlib.methods.seeding`), so which process
runs a task, and in which order, never changes a number: ``workers=1`` and ``workers=2`` give identical
tables (tested).  ``workers`` counts this process: ``workers=2`` spawns one more.  Workers are spawned once
and reused by every study of the process (a chapter pays their start-up, 3-5 s of imports, once, and
:func:`start` lets it happen in the background); each runs torch and BLAS on one thread.

Processes rather than threads: on a machine whose cores are shared, a thread barrier waits for any
descheduled thread (numba's threads ran up to 15x slower under load), while independent processes only
slow down in proportion.
"""
from __future__ import annotations

import atexit
import os
import signal
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from typing import Callable, Sequence

import torch

from ..errors import check_param

_POOLS: dict[int, ProcessPoolExecutor] = {}


def _init_worker() -> None:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    torch.set_num_threads(1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)     # an interrupt stops the parent, which stops the pool


def executor(workers: int) -> ProcessPoolExecutor:
    """The pool of ``workers`` spawned processes (created on first use, shut down at exit)."""
    check_param("workers", workers, lo=1, integer=True)
    pool = _POOLS.get(int(workers))
    if pool is None:
        pool = ProcessPoolExecutor(max_workers=int(workers), mp_context=get_context("spawn"),
                                   initializer=_init_worker)
        _POOLS[int(workers)] = pool
    return pool


def shutdown() -> None:
    """Stop every worker pool."""
    for pool in _POOLS.values():
        pool.shutdown(cancel_futures=True)
    _POOLS.clear()


atexit.register(shutdown)


def run_tasks(fn: Callable, tasks: Sequence[tuple], workers: int = 1, cost: Sequence[float] | None = None) -> list:
    """``[fn(*task) for task in tasks]`` on ``workers`` processes: this one and ``workers - 1`` spawned
    ones (:func:`executor`).

    ``cost``: optional estimated cost per task; tasks start most expensive first (longest processing time
    first), which keeps every process busy until the end.  This process takes the next task that no worker
    has started, so it never idles while a worker imports.  Results come back in the order of ``tasks``."""
    check_param("workers", workers, lo=1, integer=True)
    tasks = list(tasks)
    if workers == 1 or len(tasks) <= 1:
        return [fn(*t) for t in tasks]
    order = sorted(range(len(tasks)), key=lambda i: -cost[i]) if cost is not None else list(range(len(tasks)))
    pool = executor(workers - 1)
    futures = {i: pool.submit(fn, *tasks[i]) for i in order}
    results: dict = {}
    for i in order:                       # take over every task no worker has picked up yet
        if futures[i].cancel():
            results[i] = fn(*tasks[i])
    return [results[i] if i in results else futures[i].result() for i in range(len(tasks))]


def start(workers: int) -> None:
    """Spawn the ``workers - 1`` worker processes now (they import navlib in the background while this
    process goes on), so the first parallel study does not wait for them."""
    check_param("workers", workers, lo=1, integer=True)
    if workers > 1:
        pool = executor(workers - 1)
        for _ in range(workers - 1):
            pool.submit(_ready)


def _ready() -> bool:
    return True
