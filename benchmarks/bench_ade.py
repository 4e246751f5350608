"""ADE-BP with paper A's budget against scipy's differential_evolution, in one run.

Both train the same 1-6-1 network on the same 121-point training sweep with the same vectorised fitness
function, population (NP = 95) and number of generations (3000), polish off. Ours runs paper A's adaptive
schedules (ADE); scipy runs DE/rand/1/bin with F = 0.5, CR = 0.6 (its closest built-in; it has no ADE), so
the fitness comparison is between the paper's method and its baseline at equal cost. Prints both times,
both final fitness values (float64), and as its last line ``ade_vs_scipy_speedup=<ratio>``.

Run: ``.venv/bin/python benchmarks/bench_ade.py [--repeats 3] [--seeds 20]`` (the best of the repeats is
reported, to damp noise from other processes).

The chapter trains every seed's population in one array per generation
(:func:`navlib.methods.de.evolve_many`); the benchmark times that batch too and prints, as its
second-to-last line, ``ade_overhead_ratio=<batch time / time of the fitness evaluations alone>`` (the
fitness of all seeds' populations in one call per generation, as the batch makes it): how much the
optimiser's own work adds to the network evaluations it must pay.

It also times the network fitness alone and both optimisers on a trivial fitness (sum of squares), so the
output shows where the time goes. Both runs pay the same fitness cost every generation, so even an
optimiser with no overhead at all could be at most (scipy's time) / (generations x fitness cost) faster.
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # "on one core"

import numpy as np  # noqa: E402
from scipy.optimize import differential_evolution  # noqa: E402

from navlib.methods.bpnet import sse_objective, n_params  # noqa: E402
from navlib.data.compass_sweeps import load_sweeps, split_sweeps  # noqa: E402
from navlib.studies.compass import Sweeps  # noqa: E402
from navlib.methods.de import DEParams, evolve, evolve_many  # noqa: E402
from navlib.methods.seeding import generators  # noqa: E402
from navlib.paths import data_path  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--generations", type=int, default=3000)
    ap.add_argument("--seeds", type=int, default=20)
    args = ap.parse_args()
    sw = Sweeps(*split_sweeps(load_sweeps(data_path("compass_sweeps.csv"))))
    objective, _, _ = sse_objective(sw.x_train, sw.t_train, 6)
    exact, _, _ = sse_objective(sw.x_train, sw.t_train, 6, np.float64)
    dim, gens = n_params(6), args.generations
    params = DEParams(
        pop_size=95, max_generations=gens, target_fitness=0.2, adaptive=True, bound=10.0, seed=0
    )
    ours_t, scipy_t = [], []
    for rep in range(args.repeats):
        t0 = time.perf_counter()
        res = evolve(objective, dim, params)
        ours_t.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        ref = differential_evolution(
            lambda x: objective(x.T),
            [(-10.0, 10.0)] * dim,
            strategy="rand1bin",
            popsize=95 // dim,
            maxiter=gens - 1,
            mutation=0.5,
            recombination=0.6,
            updating="deferred",
            init="random",
            polish=False,
            tol=0,
            atol=0,
            vectorized=True,
            seed=0,
        )
        scipy_t.append(time.perf_counter() - t0)
    trivial = lambda pop: np.einsum("ij,ij->i", pop, pop)  # noqa: E731
    t0 = time.perf_counter()
    evolve(trivial, dim, replace(params, target_fitness=-1.0))
    ours_ovh = (time.perf_counter() - t0) / gens
    t0 = time.perf_counter()
    differential_evolution(
        lambda x: trivial(x.T),
        [(-10.0, 10.0)] * dim,
        strategy="rand1bin",
        popsize=95 // dim,
        maxiter=gens - 1,
        mutation=0.5,
        recombination=0.6,
        updating="deferred",
        init="random",
        polish=False,
        tol=0,
        atol=0,
        vectorized=True,
        seed=0,
    )
    scipy_ovh = (time.perf_counter() - t0) / gens
    pop = np.random.default_rng(0).uniform(-10, 10, (95, dim))
    t0 = time.perf_counter()
    for _ in range(500):
        objective(pop)
    fit_cost = (time.perf_counter() - t0) / 500
    batch_t = []
    for rep in range(args.repeats):
        t0 = time.perf_counter()
        evolve_many(objective, dim, params, generators(range(args.seeds)))
        batch_t.append(time.perf_counter() - t0)
    big = np.random.default_rng(1).uniform(-10, 10, (95 * args.seeds, dim))
    fit_batch = []
    for rep in range(args.repeats):
        t0 = time.perf_counter()
        for _ in range(200):
            objective(big)
        fit_batch.append((time.perf_counter() - t0) / 200)
    fitness_only = gens * min(fit_batch)
    ours_fit = float(exact(res.x[None, :])[0])
    scipy_fit = float(exact(ref.x[None, :])[0])
    print(f"budget: NP 95, {gens} generations, D {dim}, 121 points; best of {args.repeats} repeats")
    print(
        f"ours  ADE (navlib.methods.de.evolve):        {min(ours_t):7.3f} s   fitness J = {ours_fit:.2f} deg^2  "
        f"({res.generations} generations, {res.n_evaluations} evaluations)"
    )
    print(
        f"scipy differential_evolution DE:    {min(scipy_t):7.3f} s   fitness J = {scipy_fit:.2f} deg^2  "
        f"({ref.nit} iterations, nfev {ref.nfev} as scipy counts vectorised calls)"
    )
    print(
        f"per generation: fitness of 95 networks {fit_cost * 1e6:.0f} us (paid by both); optimiser overhead "
        f"on a trivial fitness ours {ours_ovh * 1e6:.0f} us, scipy {scipy_ovh * 1e6:.0f} us"
    )
    print(
        f"bound: an optimiser with zero overhead would be {min(scipy_t) / (gens * fit_cost):.1f}x faster than "
        f"scipy here (the fitness alone takes {gens * fit_cost:.3f} s)"
    )
    print(f"equal or better fitness: {ours_fit <= scipy_fit}")
    print(f"single run: ours / fitness-only = {min(ours_t) / (gens * fit_cost):.2f}")
    print(
        f"{args.seeds} seeds in one batch (evolve_many): {min(batch_t):7.3f} s = {min(batch_t) / args.seeds:.3f} s "
        f"per run; fitness of all {95 * args.seeds} networks per generation alone: {fitness_only:.3f} s; "
        f"per-run speedup over scipy {min(scipy_t) * args.seeds / min(batch_t):.2f}"
    )
    print(f"ade_overhead_ratio={min(batch_t) / fitness_only:.2f}")
    print(f"ade_vs_scipy_speedup={min(scipy_t) / min(ours_t):.2f}")


if __name__ == "__main__":
    main()
