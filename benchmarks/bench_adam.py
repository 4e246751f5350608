"""Adam-trained BP nets: our analytic-gradient trainer against the autograd path it replaced, in one run.

:func:`navlib.methods.bpnet.train_adam_many` trains many 1-M-1 logsig nets by full-batch Adam with the
gradient written out in torch operations and torch's fused Adam step (bit-identical to
``torch.optim.Adam(fused=True)``); the former implementation
built an autograd graph every epoch and stepped torch's default Adam (kept here as ``autograd_trajectories``,
the same as the reference in ``tests/methods/test_bpnet.py``).  Ours runs single-threaded; the autograd path runs
both on torch's default thread count (as the former code did: on a shared machine its threads wait for
each other) and single-threaded (the part of the gain that is the gradient and the step alone).

For each shape the chapter trains (20 or 4 nets of 1-6-1 on the 121-reading sweep; 20 nets of 1-50-1 on 8
and 60 readings, patent B's small-sample study) it prints the time per epoch of each and the ratios, with
``--study`` the time of ``compass.seed_study(..., methods=("bp_adam",))`` over 20 and 4 seeds with each
trainer, and as its last line ``adam_speedup=<geometric mean of the per-epoch ratios against the former code>``.

Run: ``.venv/bin/python benchmarks/bench_adam.py [--repeats 3] [--epochs 300] [--study]`` (best of the
repeats).
"""

from __future__ import annotations

import argparse
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np
import torch

import navlib.methods.bpnet as bpnet
from navlib.data.compass_sweeps import load_sweeps, split_sweeps
from navlib.methods.bpnet import AdamParams, train_adam_many
from navlib.methods.seeding import generators
from navlib.paths import data_path
from navlib.studies import compass
from navlib.studies.compass import StudyParams, Sweeps

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))  # the peer adapters
from peers import autograd_adam  # noqa: E402


def autograd_trajectories(theta0, xn, tn, n_hidden, params, threads=None):
    """The former trainer: autograd back-propagation and torch's default Adam (same signature as
    ``navlib.methods.bpnet._adam_trajectories``), on ``threads`` torch threads (None: torch's default, as
    the former code ran)."""
    caller = torch.get_num_threads()
    torch.set_num_threads(threads or caller)
    try:
        return autograd_adam(theta0, xn, tn, n_hidden, params.epochs, params.lr)
    finally:
        torch.set_num_threads(caller)


OURS = bpnet._adam_trajectories
TRAINERS = {
    "ours": OURS,
    "autograd 1 thread": partial(autograd_trajectories, threads=1),
    "autograd (former)": autograd_trajectories,
}


def best_time(fn, repeats):
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--epochs", type=int, default=300)
    ap.add_argument(
        "--study",
        action="store_true",
        help="also time the seed study (slow: the former code takes about a minute per run)",
    )
    a = ap.parse_args(argv)
    sw = Sweeps(*split_sweeps(load_sweeps(data_path("compass_sweeps.csv"))))
    params = AdamParams(epochs=a.epochs)
    ratios = []
    print(
        f"ms per epoch, best of {a.repeats} runs of {a.epochs} epochs; torch default threads "
        f"{torch.get_num_threads()}"
    )
    for nets, m, n in ((20, 6, 121), (4, 6, 121), (20, 50, 8), (20, 50, 60)):
        idx = np.unique(np.round(np.linspace(0, sw.x_train.size - 1, n)).astype(int))
        x, t = sw.x_train[idx], sw.t_train[idx]
        times = {}
        for name, fn in TRAINERS.items():
            bpnet._adam_trajectories = fn
            try:
                train_adam_many(x, t, m, AdamParams(epochs=5), generators(range(nets)))  # warm-up
                times[name] = (
                    best_time(
                        lambda: train_adam_many(x, t, m, params, generators(range(nets))), a.repeats
                    )
                    / a.epochs
                    * 1e3
                )
            finally:
                bpnet._adam_trajectories = OURS
        ratios.append(times["autograd (former)"] / times["ours"])
        print(
            f"{nets:3d} nets 1-{m}-1 on {n:3d} readings: "
            + "  ".join(f"{k} {v:.3f}" for k, v in times.items())
            + f"  ratio {ratios[-1]:.1f} (1 thread: {times['autograd 1 thread'] / times['ours']:.1f})"
        )
    if a.study:
        for seeds in (range(20), range(4)):
            times = {}
            for name, fn in TRAINERS.items():
                bpnet._adam_trajectories = fn
                try:
                    times[name] = best_time(
                        lambda: compass.seed_study(
                            sw, StudyParams(), seeds=seeds, methods=("bp_adam",)
                        ),
                        a.repeats,
                    )
                finally:
                    bpnet._adam_trajectories = OURS
            print(
                f"seed_study bp_adam, {len(seeds)} seeds, 3000 epochs (s): "
                + "  ".join(f"{k} {v:.2f}" for k, v in times.items())
                + f"  ratio {times['autograd (former)'] / times['ours']:.1f}"
            )
    print(f"adam_speedup={float(np.exp(np.mean(np.log(ratios)))):.2f}")


if __name__ == "__main__":
    main()
