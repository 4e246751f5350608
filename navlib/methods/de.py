"""Differential evolution DE/rand/1/bin and paper A's adaptive variant (ADE), population at once.

Storn & Price (1997), as used by paper A (Yue et al.):

    mutation   v_i = x_r1 + F (x_r2 - x_r3),       r1, r2, r3 distinct and != i
    crossover  u_ij = v_ij if rand_ij <= CR_i or j == j_rand(i) else x_ij
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
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import InputError, check_param


@dataclass(frozen=True)
class DEParams:
    """Settings of DE/rand/1/bin; ``adaptive=True`` gives paper A's ADE. Defaults are paper A's."""

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
    seed: int | None = 0

    def validate(self) -> "DEParams":
        check_param("NP (pop_size)", self.pop_size, lo=4, integer=True)
        check_param("max_generations", self.max_generations, lo=1, integer=True)
        check_param("bound", self.bound, lo=0, lo_open=True)
        for name in ("f", "f_min", "f_max"):
            check_param(f"F ({name})", getattr(self, name), lo=0, lo_open=True, hi=2)
        for name in ("cr", "cr_min", "cr_max"):
            check_param(f"CR ({name})", getattr(self, name), lo=0, hi=1)
        if self.f_min > self.f_max:
            raise InputError(f"parameter f_min={self.f_min} is above f_max={self.f_max}")
        if self.cr_min > self.cr_max:
            raise InputError(f"parameter cr_min={self.cr_min} is above cr_max={self.cr_max}")
        return self


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


def distinct_triples(rng: np.random.Generator, n: int, batch: int | None = None) -> np.ndarray:
    """For each i in 0..n-1, three indices distinct from each other and from i, uniformly at random.

    Draws three distinct offsets from 1..n-1 (the second skips the first, the third skips both) and
    returns ``(i + offset) mod n``; shape ``(n, 3)``, or ``(batch, n, 3)`` for several generations at once
    (one vectorised call instead of one per generation)."""
    if n < 4:
        raise InputError(f"parameter NP={n}: DE/rand/1 needs at least 4 individuals")
    shape = (1 if batch is None else batch, n)
    o1 = rng.integers(1, n, shape)
    o2 = rng.integers(1, n - 1, shape)
    o2 += o2 >= o1
    lo, hi = np.minimum(o1, o2), np.maximum(o1, o2)
    o3 = rng.integers(1, n - 2, shape)
    o3 += o3 >= lo
    o3 += o3 >= hi
    r = (np.arange(n)[None, :, None] + np.stack([o1, o2, o3], axis=-1)) % n
    return r[0] if batch is None else r


def evolve(objective: Callable[[np.ndarray], np.ndarray], dim: int, params: DEParams = DEParams(),
           initial: np.ndarray | None = None) -> DEResult:
    """Minimise ``objective`` over the box ``[-bound, bound]^dim`` with DE/rand/1/bin (or ADE).

    Stops after ``max_generations`` or as soon as the best fitness is <= ``target_fitness``."""
    params.validate()
    check_param("dim", dim, lo=1, integer=True)
    rng = np.random.default_rng(params.seed)
    n, b = int(params.pop_size), float(params.bound)
    t0 = time.perf_counter()
    pop = rng.uniform(-b, b, (n, dim)) if initial is None else np.array(initial, dtype=float)
    if pop.shape != (n, dim):
        raise InputError(f"initial population has shape {pop.shape}, expected {(n, dim)}")
    fit = np.asarray(objective(pop), dtype=float)
    n_eval = n
    history = np.empty(params.max_generations)
    rows = np.arange(n)
    f_schedule = (ade_f(np.arange(params.max_generations), params.max_generations, params.f_min,
                        params.f_max) if params.adaptive else None)
    trial = np.empty_like(pop)
    g = 0
    chunk = 256
    best = int(np.argmin(fit))
    reached = fit[best] <= params.target_fitness
    while g < params.max_generations and not reached:
        if g % chunk == 0:      # random numbers for the next `chunk` generations, one call each
            triples = distinct_triples(rng, n, chunk)
            uniforms = rng.random((chunk, n, dim))
            forced = rng.integers(0, dim, (chunk, n))
        if params.adaptive:
            f = f_schedule[g]
            cr = ade_cr(fit, params.cr_min, params.cr_max)[:, None]
        else:
            f, cr = params.f, params.cr
        k = g % chunk
        x1, x2, x3 = np.take(pop, triples[k].T, axis=0)           # (3, NP, D) in one gather
        np.subtract(x2, x3, out=trial)                            # mutation: x_r1 + F (x_r2 - x_r3)
        trial *= f
        trial += x1
        keep = uniforms[k] > cr                                   # binomial crossover, j_rand forced
        keep[rows, forced[k]] = False
        np.copyto(trial, pop, where=keep)
        out = np.abs(trial) > b
        if out.any():
            trial[out] = rng.uniform(-b, b, int(np.count_nonzero(out)))
        tfit = np.asarray(objective(trial), dtype=float)
        n_eval += n
        better = tfit <= fit                                      # greedy selection
        np.copyto(pop, trial, where=better[:, None])
        np.minimum(fit, tfit, out=fit)
        best = int(np.argmin(fit))
        history[g] = fit[best]
        g += 1
        reached = fit[best] <= params.target_fitness
    return DEResult(x=pop[best].copy(), fitness=float(fit[best]), generations=g, n_evaluations=n_eval,
                    history=history[:g].copy(), elapsed_s=time.perf_counter() - t0,
                    reached_target=bool(reached), population=pop)
