"""Differential evolution DE/rand/1/bin and paper A's adaptive variant (ADE), population at once.

Storn & Price (1997), as used by paper A (Yue et al.):

    mutation   v_i = x_r1 + F (x_r2 - x_r3),       r1, r2, r3 distinct and != i
    crossover  u_ij = v_ij if rand_ij < CR_i or j == j_rand(i) else x_ij
    selection  x_i <- u_i if J(u_i) <= J(x_i)

DE (paper's DE-BP): fixed F = 0.5, CR = 0.6.
ADE (paper's ADE-BP): F falls from F_max = 0.9 to F_min = 0.3 over the generations and each individual gets
its own CR from its fitness rank, CR_min = 0.1 .. CR_max = 0.9, worse individuals getting larger CR.
The OCR lost the F equation; we use the linear schedule

    F(t) = F_max - (F_max - F_min) t / (G_max - 1),      t = 0 .. G_max - 1           (:func:`ade_f`)

and the CR equation as printed in the digest (min-max scaled fitness; lower fitness = better)

    CR_i = CR_min + (CR_max - CR_min) (f_i - f_min) / (f_max - f_min)                  (:func:`ade_cr`)

(all individuals get CR_min when f_max == f_min).  Out-of-bounds genes of a trial are re-drawn uniformly
within the bounds, as scipy does.  The objective receives the whole trial population ``(NP, D)`` and returns
``(NP,)`` fitness values: one vectorised call per generation.

Implementation (speed, :mod:`navlib.methods.jit`): mutation, crossover and selection of all runs are one
compiled loop each per generation.  Each run draws its random numbers from its own xoshiro256** stream,
seeded from the run's numpy Generator (the initial population comes from the Generator itself);
``rand_ij`` are uniforms at 16-bit resolution (``k / 2^16``: a crossover probability is CR rounded up to
the next multiple of 2^-16, within 1.6e-5 of it).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import InputError, check_param
from .jit import de_select, de_trials, xoshiro_states
from .seeding import generators


@dataclass(frozen=True)
class DEParams:
    """Settings of DE/rand/1/bin; ``adaptive=True`` gives paper A's ADE. Defaults are paper A's.

    ``seed`` is the run index of :mod:`navlib.methods.seeding` used by :func:`evolve` (``evolve_many``
    takes one generator per run instead)."""

    pop_size: int = 95
    max_generations: int = 3000
    target_fitness: float = 0.2
    f: float = 0.5
    cr: float = 0.6
    adaptive: bool = False
    f_min: float = 0.3
    f_max: float = 0.9
    cr_min: float = 0.1
    cr_max: float = 0.9
    bound: float = 10.0          # search box [-bound, bound] for every gene (initial population and trials)
    seed: int = 0

    def __post_init__(self):
        check_param("NP (pop_size)", self.pop_size, lo=4, integer=True)
        check_param("max_generations", self.max_generations, lo=1, integer=True)
        check_param("bound", self.bound, lo=0, lo_open=True)
        check_param("target_fitness", self.target_fitness)
        check_param("seed", self.seed, lo=0, integer=True)
        for name in ("f", "f_min", "f_max"):
            check_param(f"F ({name})", getattr(self, name), lo=0, lo_open=True, hi=2)
        for name in ("cr", "cr_min", "cr_max"):
            check_param(f"CR ({name})", getattr(self, name), lo=0, hi=1)
        if self.f_min > self.f_max:
            raise InputError(f"parameter f_min={self.f_min} is above f_max={self.f_max}")
        if self.cr_min > self.cr_max:
            raise InputError(f"parameter cr_min={self.cr_min} is above cr_max={self.cr_max}")


def ade_f(generation, max_generations: int, f_min: float = 0.3, f_max: float = 0.9):
    """Paper A's mutation factor at 0-based ``generation``: linear from ``f_max`` down to ``f_min``."""
    g = np.asarray(generation, dtype=float)
    frac = g / max(max_generations - 1, 1)
    return f_max - (f_max - f_min) * np.clip(frac, 0.0, 1.0)


def ade_cr(fitness, cr_min: float = 0.1, cr_max: float = 0.9) -> np.ndarray:
    """Per-individual crossover rate from fitness (lower is better): the best gets ``cr_min``, the worst
    ``cr_max``, linear in between."""
    f = np.asarray(fitness, dtype=float)
    lo, hi = f.min(), f.max()
    if hi <= lo:
        return np.full(f.shape, cr_min)
    return cr_min + (cr_max - cr_min) * (f - lo) / (hi - lo)


@dataclass
class DEResult:
    x: np.ndarray                  # best individual
    fitness: float                 # its fitness
    generations: int               # generations run
    n_evaluations: int
    history: np.ndarray            # best fitness after each generation
    elapsed_s: float
    reached_target: bool
    population: np.ndarray = field(repr=False, default=None)


def evolve(objective: Callable[[np.ndarray], np.ndarray], dim: int, params: DEParams = DEParams(),
           initial: np.ndarray | None = None) -> DEResult:
    """Minimise ``objective`` over the box ``[-bound, bound]^dim`` with DE/rand/1/bin (or ADE): one run,
    seeded by ``params.seed`` (:mod:`navlib.methods.seeding`); :func:`evolve_many` with one generator.

    Stops after ``max_generations`` or as soon as the best fitness is <= ``target_fitness``."""
    init = None if initial is None else np.asarray(initial, dtype=float)[None]
    return evolve_many(objective, dim, params, generators([params.seed]), init)[0]


def evolve_many(objective: Callable[[np.ndarray], np.ndarray], dim: int, params: DEParams,
                rngs: list, initial: np.ndarray | None = None) -> list[DEResult]:
    """Several independent DE runs at once, one per generator in ``rngs``: every run's population lives in
    one ``(S, NP, D)`` array and each generation makes one ``objective`` call on all ``S NP`` trials.

    ``objective`` maps ``(K, D)`` to ``(K,)``.  Run ``s`` draws its random numbers from ``rngs[s]`` only (its
    initial population, then the seed of its xoshiro256** stream), so its result does not depend on which
    other runs share the batch.
    A run stops at ``max_generations`` or when its best fitness is <= ``target_fitness``; stopped runs
    leave the batch.  ``initial``: optional ``(S, NP, D)`` starting populations."""
    check_param("dim", dim, lo=1, integer=True)
    rngs = list(rngs)
    if not rngs:
        raise InputError("evolve_many: need at least one generator")
    n_runs, n, b, gmax = len(rngs), int(params.pop_size), float(params.bound), int(params.max_generations)
    t0 = time.perf_counter()
    if initial is None:
        pop = np.stack([g.uniform(-b, b, (n, dim)) for g in rngs])
    else:
        pop = np.array(initial, dtype=float)
        if pop.shape != (n_runs, n, dim):
            raise InputError(f"initial population has shape {pop.shape}, expected {(n_runs, n, dim)}")
    fit = np.ascontiguousarray(np.asarray(objective(pop.reshape(-1, dim)), dtype=float).reshape(n_runs, n))
    f_schedule = (ade_f(np.arange(gmax), gmax, params.f_min, params.f_max) if params.adaptive else None)
    history = np.full((n_runs, gmax), np.nan)
    results: list = [None] * n_runs
    ids = np.arange(n_runs)                 # run index of each row still in the batch

    def finish(mask, g):
        for j in np.flatnonzero(mask):
            s, best = ids[j], int(np.argmin(fit[j]))
            results[s] = DEResult(x=pop[j, best].copy(), fitness=float(fit[j, best]), generations=g,
                                  n_evaluations=n * (g + 1), history=history[s, :g].copy(),
                                  elapsed_s=time.perf_counter() - t0,
                                  reached_target=bool(fit[j, best] <= params.target_fitness),
                                  population=pop[j].copy())

    trial = np.empty_like(pop)
    best = np.empty(n_runs)
    state = xoshiro_states(rngs)        # each run's own stream for mutation, crossover and re-draws
    g = 0
    while True:
        done = fit.min(axis=1) <= params.target_fitness
        if g >= gmax:
            done[:] = True
        if done.any():
            finish(done, g)
            keep = ~done
            if not keep.any():
                break
            ids, pop, fit = ids[keep], np.ascontiguousarray(pop[keep]), np.ascontiguousarray(fit[keep])
            state = np.ascontiguousarray(state[keep])
            trial, best = trial[:keep.sum()], best[:keep.sum()]
        f = f_schedule[g] if params.adaptive else params.f
        de_trials(pop, fit, state, float(f), float(params.cr), bool(params.adaptive), float(params.cr_min),
                  float(params.cr_max), b, trial)
        tfit = np.asarray(objective(trial.reshape(-1, dim)), dtype=float).reshape(ids.size, n)
        de_select(pop, fit, trial, tfit, best)                             # greedy selection, in place
        history[ids, g] = best
        g += 1
    return results
