"""navlib.engine (dask.distributed) against the scheduler it replaced, in one run.

The peer is a copy of the former ``navlib/studies/parallel.py``: a ``ProcessPoolExecutor`` of spawned
workers (torch imported and set to one thread in each) fed from done-callbacks, this process running tasks
too, a busy-wait for the last one; trial studies cut into ``8 x workers`` chunks.

Measured:

- start-up: a fresh local cluster of 2 single-threaded workers until a first task came back (ours), a
  fresh pool of 1 spawned worker plus this process until its first task came back (the peer);
- a workbench trial study of 400 trials (compass sweeps, every catalogued effect hidden at 3 and 10 x the
  noise at two noise levels, plus nothing-hidden trials) at 1 and 2 workers, on a started cluster / pool;
  the results of all four runs must be identical.

Prints the times and the ratios; the last lines are ``engine_speedup_2_vs_1=<ratio>`` (target >= 1.8 on
2 cores) and ``engine_vs_peer_2_workers=<peer time / our time>``.

    .venv/bin/python benchmarks/bench_engine.py [trials per case, default 20 (400 trials)] [repeats, default 2]

Each configuration runs ``repeats`` times, interleaved with the others; the best time of each counts (the
machine's other load only ever adds time).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import numpy as np
import pandas as pd

from navlib import engine
from navlib.workbench import trials as T


# ------------------------------------------------------------------- the peer: the former parallel.py
_POOLS: dict[int, ProcessPoolExecutor] = {}


def _peer_init_worker() -> None:
    import torch  # the former module imported torch at its top

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    torch.set_num_threads(1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def peer_executor(workers: int) -> ProcessPoolExecutor:
    pool = _POOLS.get(workers)
    if pool is None:
        pool = ProcessPoolExecutor(
            max_workers=workers, mp_context=get_context("spawn"), initializer=_peer_init_worker
        )
        _POOLS[workers] = pool
    return pool


def peer_run_tasks(fn, tasks, workers=1, cost=None) -> list:
    tasks = list(tasks)
    if workers == 1 or len(tasks) <= 1:
        return [fn(*t) for t in tasks]
    order = (
        sorted(range(len(tasks)), key=lambda i: -cost[i])
        if cost is not None
        else list(range(len(tasks)))
    )
    queue = iter(order)
    lock = threading.Lock()
    pool = peer_executor(workers - 1)
    futures: dict = {}
    results: dict = {}

    def take():
        with lock:
            return next(queue, None)

    def feed(_=None):
        i = take()
        if i is None:
            return
        futures[i] = pool.submit(fn, *tasks[i])
        futures[i].add_done_callback(feed)

    for _ in range(workers - 1):
        feed()
    while (i := take()) is not None:
        results[i] = fn(*tasks[i])
    for i, f in list(futures.items()):
        results[i] = f.result()
    while len(results) < len(tasks):
        for i, f in list(futures.items()):
            if i not in results:
                results[i] = f.result()
        time.sleep(0.001)
    return [results[i] for i in range(len(tasks))]


def _batch(fn, args):
    return [fn(*a) for a in args]


def peer_run_trials(fn, args, workers=1) -> list:
    if workers == 1 or len(args) < 2:
        return _batch(fn, args)
    chunks = [c for c in np.array_split(np.arange(len(args)), 8 * int(workers)) if len(c)]
    parts = peer_run_tasks(_batch, [(fn, [args[i] for i in c]) for c in chunks], int(workers))
    return [row for part in parts for row in part]


def _ready():
    return os.getpid()


# ------------------------------------------------------------------------------------------ the study
def study_args(per_case: int) -> list:
    """The trials of :func:`navlib.workbench.trials.hidden_effect_study` on the compass: 4 effects x 2 sizes
    x 2 noise levels x ``per_case`` hidden, 2 x ``2 per_case`` nothing hidden (400 for 20 per case)."""
    seen = []
    real = T.run_trials
    T.run_trials = lambda fn, args, *a, **k: seen.extend(args) or []
    try:
        T.hidden_effect_study(
            "compass",
            ratios=(3.0, 10.0),
            noises=(0.05, 0.2),
            seeds=range(per_case),
            none_seeds=range(2 * per_case),
        )
    finally:
        T.run_trials = real
    return seen


def timed(f):
    t0 = time.perf_counter()
    out = f()
    return time.perf_counter() - t0, out


def main() -> None:
    per_case = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    args = study_args(per_case)
    print(f"trial study: {len(args)} compass trials ({os.cpu_count()} cores)")

    # start-up, from nothing to the first task's result
    t_ours_start, _ = timed(lambda: engine.run(_ready, [()] * 2, workers=2))
    t_peer_start, _ = timed(lambda: peer_executor(1).submit(_ready).result())
    print(
        f"start-up: local dask cluster of 2 workers {t_ours_start:.2f} s; former pool "
        f"(1 spawned worker + this process) {t_peer_start:.2f} s"
    )

    fn = T.hidden_effect_trial
    T.hidden_effect_trial(*args[0])  # warm this process (numba caches, imports),
    engine.client(2).run(T.hidden_effect_trial, *args[0])  # every cluster worker
    peer_executor(1).submit(T.hidden_effect_trial, *args[0]).result()  # and the pool's worker

    runs = {
        "ours_1": lambda: engine.run_batches(fn, args, T.TRIAL_BATCH, workers=1),
        "peer_1": lambda: peer_run_trials(fn, args, workers=1),
        "ours_2": lambda: engine.run_batches(fn, args, T.TRIAL_BATCH, workers=2),
        "peer_2": lambda: peer_run_trials(fn, args, workers=2),
    }
    best, out = {}, {}
    for _ in range(repeats):  # interleaved; the best of each
        for name, f in runs.items():
            t, out[name] = timed(f)
            best[name] = min(best.get(name, np.inf), t)
    t_ours_1, t_peer_1, t_ours_2, t_peer_2 = (
        best[k] for k in ("ours_1", "peer_1", "ours_2", "peer_2")
    )
    frames = [pd.DataFrame(out[k]) for k in runs]
    for f in frames[1:]:
        pd.testing.assert_frame_equal(frames[0], f)
    print("results identical in all four runs")
    print(
        f"engine: 1 worker {t_ours_1:.1f} s, 2 workers {t_ours_2:.1f} s "
        f"({t_ours_start + t_ours_2:.1f} s with the cluster's start-up)"
    )
    print(f"former pool: 1 worker {t_peer_1:.1f} s, 2 workers {t_peer_2:.1f} s")
    print(f"peer_speedup_2_vs_1={t_peer_1 / t_peer_2:.2f}")
    print(f"startup_peer_vs_engine={t_peer_start / t_ours_start:.2f}")
    print(f"engine_speedup_2_vs_1={t_ours_1 / t_ours_2:.2f}")
    print(f"engine_vs_peer_2_workers={t_peer_2 / t_ours_2:.2f}")
    for pool in _POOLS.values():
        pool.shutdown()
    engine.shutdown()


if __name__ == "__main__":
    main()
