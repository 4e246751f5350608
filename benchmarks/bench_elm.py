"""Patent B's back-tuned incremental ELM: the compiled back-tuning (numba) against the plain-numpy loop it
replaced (``tests/elm_reference.py``), in one run, on the chapter's data.

1. ``back-tuning``: one tuning stage (50 steps, first trial step 0.1) of ELMs with 3, 15 and 30 random nodes
   (U(-5, 5)) solved on the compass training sweep (normalised, as the chapter trains them): the numpy
   reference and ``navlib.methods.elm._back_tune`` on the same model; both losses are printed (they must
   agree) with the time ratio.
2. ``fit``: ``fit_incremental_elm`` with the chapter's settings (elm_range 5 and 1, 5 seeds), with the
   numpy reference kernels swapped in and with the compiled ones.
3. The chapter's ELM studies, timed with the compiled kernels and (unless ``--quick``) with the numpy
   reference kernels swapped in: ``elm_patent.glitch_study`` (glitch_prob 0.05, 15 uT, sim seed 2024),
   ``compass.seed_study`` with elm_range 1.0 (ELM methods) and ``elm_patent.node_count_curve`` for
   elm_range 5.0 and 1.0 (all 20 seeds, 40 nodes).  The reference runs keep the rest of today's
   ``fit_incremental_elm`` (e.g. reusing a stalled stage's solve), so their times are below those of the
   code before the kernels were compiled; the ratio is that of the kernels alone.

Every time is the best of ``--repeats`` runs (the machine is shared; the best run is the least disturbed).
The last line is ``elm_backtune_speedup=<reference / compiled, fit of part 2>``.

Run: ``.venv/bin/python benchmarks/bench_elm.py [--repeats 2] [--quick]``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # "on one core"
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))  # the numpy reference

import numpy as np  # noqa: E402

import elm_reference as reference  # noqa: E402
from navlib.data.compass_sweeps import load_sweeps, split_sweeps  # noqa: E402
from navlib.methods.elm import ELMParams, _back_tune, fit_elm, fit_incremental_elm  # noqa: E402
from navlib.methods.scaling import MinMax  # noqa: E402
from navlib.methods.seeding import generators  # noqa: E402
from navlib.paths import data_path  # noqa: E402
from navlib.sensors.compass import CompassErrors, SweepConfig, simulate_train_test  # noqa: E402
from navlib.studies import compass  # noqa: E402
from navlib.studies.compass import StudyParams, Sweeps, elm_patent  # noqa: E402


def best(fn, repeats: int, ref: bool = False) -> float:
    times = []
    for _ in range(repeats):
        with reference.numpy_reference() if ref else nullcontext():
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument(
        "--quick", action="store_true", help="time the studies with the compiled kernels only"
    )
    args = ap.parse_args()
    R = args.repeats
    sw = Sweeps(*split_sweeps(load_sweeps(data_path("compass_sweeps.csv"))))
    params = StudyParams()
    target = params.target.target(sw.x_train, sw.t_train)
    X = MinMax.fit(sw.x_train).transform(sw.x_train)[:, None]
    T = MinMax.fit(target).transform(target)[:, None]
    fit_incremental_elm(
        X, T, replace(params.incremental_params(float(np.ptp(target))), max_iter=2)
    )  # compile

    print(
        f"1. back-tuning, one stage of 50 steps on the training sweep ({X.shape[0]} readings), best of {R}"
    )
    for n in (3, 15, 30):
        model = fit_elm(X, T, ELMParams(n_hidden=n, weight_range=5.0, bias_range=5.0, seed=0))
        model.squeeze_output = False
        w, b, beta, ref_losses, _ = reference.back_tune(
            model.w, model.b, model.beta, X, T, "sigmoid", 50, 0.1
        )
        _, losses, _ = _back_tune(model, X, T, 50, 0.1)
        reps = max(R, 3) * (20 if n == 3 else 5)
        t_ref = best(
            lambda: reference.back_tune(model.w, model.b, model.beta, X, T, "sigmoid", 50, 0.1),
            reps,
        )
        t_ours = best(lambda: _back_tune(model, X, T, 50, 0.1), reps)
        print(
            f"   {n:2d} nodes: {len(losses) - 1:2d} accepted steps, final loss numpy {ref_losses[-1]:.12e} "
            f"compiled {losses[-1]:.12e}; numpy {t_ref * 1e3:7.2f} ms, compiled {t_ours * 1e3:6.2f} ms, "
            f"ratio {t_ref / t_ours:5.1f}"
        )

    print(f"2. fit_incremental_elm, chapter settings, seeds 0-4, best of {R}")
    fit_ratios = []
    for rng in (5.0, 1.0):
        ip = replace(params, elm_range=rng).incremental_params(float(np.ptp(target)))

        def fits():
            return [fit_incremental_elm(X, T, ip, rng=g)[1] for g in generators(range(5))]

        with reference.numpy_reference():
            ref_hist = fits()
        ours_hist = fits()
        same = all(a.equals(b) for a, b in zip(ref_hist, ours_hist))
        t_ref, t_ours = best(fits, R, ref=True), best(fits, R)
        fit_ratios.append(t_ref / t_ours)
        print(
            f"   elm_range {rng}: histories identical {same}; numpy {t_ref:6.2f} s, compiled {t_ours:5.2f} s, "
            f"ratio {t_ref / t_ours:5.1f}"
        )

    print(f"3. the chapter's ELM studies (20 seeds), wall time, best of {R}")
    g_train, g_test = split_sweeps(
        simulate_train_test(
            CompassErrors(), config=SweepConfig(glitch_prob=0.05, glitch_ut=15.0), seed=2024
        )
    )
    studies = {
        "elm_patent.glitch_study": lambda: elm_patent.glitch_study(
            g_train, g_test, params, seeds=range(20)
        ),
        "compass.seed_study elm_range=1.0": lambda: compass.seed_study(
            sw, replace(params, elm_range=1.0), seeds=range(20), methods=compass.ELM_METHODS
        ),
        "elm_patent.node_count_curve 5.0+1.0": lambda: [
            elm_patent.node_count_curve(
                sw, replace(params, elm_range=r), seeds=range(20), max_nodes=40
            )
            for r in (5.0, 1.0)
        ],
    }
    total = [0.0, 0.0]
    for name, fn in studies.items():
        t_ours = best(fn, R)
        total[1] += t_ours
        if args.quick:
            print(f"   {name:36s} compiled {t_ours:6.2f} s")
            continue
        t_ref = best(fn, R, ref=True)
        total[0] += t_ref
        print(
            f"   {name:36s} numpy kernels {t_ref:6.2f} s, compiled {t_ours:6.2f} s, ratio {t_ref / t_ours:5.1f}"
        )
    print(
        f"   total: compiled {total[1]:.2f} s"
        + ("" if args.quick else f", numpy kernels {total[0]:.2f} s")
    )
    print(f"elm_backtune_speedup={min(fit_ratios):.1f}")


if __name__ == "__main__":
    main()
