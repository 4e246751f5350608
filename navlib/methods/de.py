"""Differential evolution DE/rand/1/bin and paper A's adaptive variant (ADE), population at once.

Storn & Price (1997), as used by paper A (Yue et al.):

    mutation   v_i = x_r1 + F (x_r2 - x_r3),       r1, r2, r3 distinct and != i
    crossover  u_ij = v_ij if rand_ij < CR_i or j == j_rand(i) else x_ij
    selection  x_i <- u_i if J(u_i) <= J(x_i)

DE (paper's DE-BP): fixed F = 0.5, CR = 0.6.
ADE (paper's ADE-BP), section 1.2 of the original: F and CR are printed per individual, ``F_i(t)`` and
``CR_i(t)``, next to the definitions of ``f_i(t)`` (the individual's fitness) and ``f_min(t)``, ``f_max(t)``
(the population's best and worst); the OCR kept only ``CR_i(t) = CR_min + (CR_max - CR_min) ...`` and lost
both fractions.  The prose: "early in the run F is large, which keeps the population diverse; as the
generations advance F falls, which speeds up late convergence; an individual of poor fitness gets a larger
CR so that it is replaced sooner, a good one a smaller CR so that it survives".  Every form consistent with
that text is a reading (``DEParams.f_rule``, ``DEParams.cr_rule``); with ``q_i`` the individual's scaled
fitness (lower fitness = better):

    q_i = (f_i - f_min) / (f_max - f_min)                         (0 for the best, 1 for the worst)

- F by generation (``f_rule='generation'``, the default, :func:`ade_f`)::

      F(t) = F_max - (F_max - F_min) t / (G_max - 1),      t = 0 .. G_max - 1

- F per individual (``'individual'``, :func:`ade_f_individual`; worse -> larger F, the form of the
  printed CR equation with the F bounds)::

      F_i(t) = F_min + (F_max - F_min) q_i

- F combining both (``'combined'``): the worst individual follows the generation schedule, the best keeps
  F_min::

      F_i(t) = F_min + (F(t) - F_min) q_i

- CR by value (``cr_rule='value'``, the default, :func:`ade_cr`)::

      CR_i = CR_min + (CR_max - CR_min) q_i

- CR by rank (``'rank'``)::

      CR_i = CR_min + (CR_max - CR_min) r_i / (NP - 1)

with ``r_i`` the individual's 0-based rank (0 = best; ties broken by index).  When ``f_max == f_min``,
``q_i = 0`` (F_min, CR_min).  Defaults: F by generation, because the only prose about F describes a fall
with the generations (and the digest reads it so); CR by value, because the printed fragment is
``(CR_max - CR_min)`` times a fraction next to the definitions of ``f_i``, ``f_min`` and ``f_max``, which
is the min-max scaling of the values.  Out-of-bounds genes of a trial are re-drawn uniformly
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
from typing import Callable, Literal

import numpy as np

from ..errors import InputError, check_choice, check_param
from .jit import ade_rates_into, de_select, de_trials, xoshiro_states
from .seeding import generators


#: ADE's readings of the adaptive mutation factor and crossover rate (module docstring).
F_RULES = ("generation", "individual", "combined")
CR_RULES = ("value", "rank")


@dataclass(frozen=True)
class DEParams:
    """Settings of DE/rand/1/bin; ``adaptive=True`` gives paper A's ADE. Defaults are paper A's.

    ``f_rule`` and ``cr_rule`` choose the reading of ADE's adaptive F and CR (module docstring; ignored
    unless ``adaptive``): F ``'generation'`` (default), ``'individual'`` or ``'combined'``; CR ``'value'``
    (default) or ``'rank'``.

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
    bound: float = 10.0  # search box [-bound, bound] for every gene (initial population and trials)
    seed: int = 0
    f_rule: Literal["generation", "individual", "combined"] = "generation"
    cr_rule: Literal["value", "rank"] = "value"

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
        check_choice("f_rule", self.f_rule, F_RULES)
        check_choice("cr_rule", self.cr_rule, CR_RULES)


def ade_f(generation, max_generations: int, f_min: float = 0.3, f_max: float = 0.9):
    """Paper A's mutation factor at 0-based ``generation``: linear from ``f_max`` down to ``f_min``."""
    g = np.asarray(generation, dtype=float)
    frac = g / max(max_generations - 1, 1)
    return f_max - (f_max - f_min) * np.clip(frac, 0.0, 1.0)


def scaled_fitness(fitness) -> np.ndarray:
    """``q_i = (f_i - f_min) / (f_max - f_min)`` along the last axis (each population on its own): 0 for the
    best individual, 1 for the worst, 0 for all when every fitness is equal."""
    f = np.asarray(fitness, dtype=float)
    lo, hi = f.min(axis=-1, keepdims=True), f.max(axis=-1, keepdims=True)
    spread = hi - lo
    return np.where(spread > 0, (f - lo) / np.where(spread > 0, spread, 1.0), 0.0)


def fitness_rank(fitness) -> np.ndarray:
    """0-based rank of every individual along the last axis (0 = lowest fitness = best; ties by index)."""
    f = np.asarray(fitness, dtype=float)
    order = np.argsort(f, axis=-1, kind="stable")
    rank = np.empty(f.shape, dtype=float)
    np.put_along_axis(
        rank, order, np.broadcast_to(np.arange(f.shape[-1], dtype=float), f.shape), axis=-1
    )
    return rank


def ade_cr(fitness, cr_min: float = 0.1, cr_max: float = 0.9, rule: str = "value") -> np.ndarray:
    """Per-individual crossover rate from fitness (lower is better), the best getting ``cr_min``, the worst
    ``cr_max``: ``rule='value'`` linear in the fitness value, ``CR_min + (CR_max - CR_min) q_i``
    (:func:`scaled_fitness`; ``cr_min`` for all when every fitness is equal), ``rule='rank'`` linear in the
    rank, ``CR_min + (CR_max - CR_min) r_i / (NP - 1)`` (:func:`fitness_rank`).  Along the last axis."""
    check_choice("cr_rule", rule, CR_RULES)
    f = np.asarray(fitness, dtype=float)
    if rule == "rank":
        return cr_min + (cr_max - cr_min) * fitness_rank(f) / (f.shape[-1] - 1)
    lo, hi = f.min(axis=-1, keepdims=True), f.max(axis=-1, keepdims=True)
    # the same operations, in the same order, as the former compiled rule (bit-identical numbers)
    return np.where(
        hi > lo, cr_min + (cr_max - cr_min) * (f - lo) / np.where(hi > lo, hi - lo, 1.0), cr_min
    )


def ade_f_individual(fitness, f_min: float = 0.3, f_max: float = 0.9, f_top=None) -> np.ndarray:
    """Per-individual mutation factor ``F_i = F_min + (F_top - F_min) q_i`` (:func:`scaled_fitness`): the
    best individual gets ``f_min``, the worst ``f_top`` (``f_max`` by default: the reading "F per
    individual"; the generation schedule :func:`ade_f` for "combined")."""
    top = f_max if f_top is None else f_top
    return f_min + (np.asarray(top, dtype=float) - f_min) * scaled_fitness(fitness)


def ade_rates(fitness, generation: int, params: DEParams) -> tuple[np.ndarray, np.ndarray]:
    """``(F_i, CR_i)`` of every individual of populations ``fitness (..., NP)`` at 0-based ``generation``
    under ``params`` (fixed F and CR unless ``adaptive``; then the readings ``f_rule``, ``cr_rule``).  The
    numpy reference of the compiled :func:`navlib.methods.jit.ade_rates_into`, which :func:`evolve_many`
    calls every generation."""
    f = np.asarray(fitness, dtype=float)
    if not params.adaptive:
        return np.full(f.shape, float(params.f)), np.full(f.shape, float(params.cr))
    f_gen = float(ade_f(generation, params.max_generations, params.f_min, params.f_max))
    if params.f_rule == "generation":
        big_f = np.full(f.shape, f_gen)
    else:
        big_f = ade_f_individual(
            f, params.f_min, params.f_max, params.f_max if params.f_rule == "individual" else f_gen
        )
    return big_f, ade_cr(f, params.cr_min, params.cr_max, params.cr_rule)


@dataclass
class DEResult:
    x: np.ndarray  # best individual
    fitness: float  # its fitness
    generations: int  # generations run
    n_evaluations: int
    history: np.ndarray  # best fitness after each generation
    elapsed_s: float
    reached_target: bool
    population: np.ndarray = field(repr=False, default=None)


def evolve(
    objective: Callable[[np.ndarray], np.ndarray],
    dim: int,
    params: DEParams = DEParams(),
    initial: np.ndarray | None = None,
) -> DEResult:
    """Minimise ``objective`` over the box ``[-bound, bound]^dim`` with DE/rand/1/bin (or ADE): one run,
    seeded by ``params.seed`` (:mod:`navlib.methods.seeding`); :func:`evolve_many` with one generator.

    Stops after ``max_generations`` or as soon as the best fitness is <= ``target_fitness``."""
    init = None if initial is None else np.asarray(initial, dtype=float)[None]
    return evolve_many(objective, dim, params, generators([params.seed]), init)[0]


def evolve_many(
    objective: Callable[[np.ndarray], np.ndarray],
    dim: int,
    params: DEParams,
    rngs: list,
    initial: np.ndarray | None = None,
) -> list[DEResult]:
    """Several independent DE runs at once, one per generator in ``rngs``: every run's population lives in
    one ``(S, NP, D)`` array and each generation makes one ``objective`` call on all ``S NP`` trials.

    ``objective`` maps ``(K, D)`` to ``(K,)``.  Run ``s`` draws its random numbers from ``rngs[s]`` only (its
    initial population, then the seed of its xoshiro256** stream), so its result does not depend on which
    other runs share the batch.
    A run stops at ``max_generations`` or when its best fitness is <= ``target_fitness``; stopped runs
    leave the batch.  ``initial``: optional ``(S, NP, D)`` starting populations.

    Parent cache (optional): an ``objective`` that also has ``start(pop)`` (fitness of the initial
    population, remembering what it needs), ``trials(trial, pop)`` (fitness of trial ``k``, made from
    individual ``k`` of ``pop``), ``accept(mask)`` (the trials that replaced their parents) and
    ``keep(rows)`` (the individuals of runs still in the batch) is evaluated through them: a trial keeps
    part of its parent's genes, and the objective may reuse the parent's partial results for them
    (:class:`navlib.methods.bpnet.LogsigSSE` does).  It must return exactly what calling it returns."""
    check_param("dim", dim, lo=1, integer=True)
    rngs = list(rngs)
    if not rngs:
        raise InputError("evolve_many: need at least one generator")
    n_runs, n, b, gmax = (
        len(rngs),
        int(params.pop_size),
        float(params.bound),
        int(params.max_generations),
    )
    t0 = time.perf_counter()
    if initial is None:
        pop = np.stack([g.uniform(-b, b, (n, dim)) for g in rngs])
    else:
        pop = np.array(initial, dtype=float)
        if pop.shape != (n_runs, n, dim):
            raise InputError(
                f"initial population has shape {pop.shape}, expected {(n_runs, n, dim)}"
            )
    cached = all(
        callable(getattr(objective, a, None)) for a in ("start", "trials", "accept", "keep")
    )
    first = objective.start if cached else objective
    fit = np.ascontiguousarray(
        np.asarray(first(pop.reshape(-1, dim)), dtype=float).reshape(n_runs, n)
    )
    history = np.full((n_runs, gmax), np.nan)
    results: list = [None] * n_runs
    ids = np.arange(n_runs)  # run index of each row still in the batch

    def finish(mask, g):
        for j in np.flatnonzero(mask):
            s, best = ids[j], int(np.argmin(fit[j]))
            results[s] = DEResult(
                x=pop[j, best].copy(),
                fitness=float(fit[j, best]),
                generations=g,
                n_evaluations=n * (g + 1),
                history=history[s, :g].copy(),
                elapsed_s=time.perf_counter() - t0,
                reached_target=bool(fit[j, best] <= params.target_fitness),
                population=pop[j].copy(),
            )

    trial = np.empty_like(pop)
    best = np.empty(n_runs)
    accepted = np.empty((n_runs, n), np.bool_)
    # every individual's F and CR (:func:`ade_rates`, compiled as :func:`navlib.methods.jit.ade_rates_into`)
    f_all, cr_all = np.full((n_runs, n), float(params.f)), np.full((n_runs, n), float(params.cr))
    f_schedule = (
        ade_f(np.arange(gmax), gmax, params.f_min, params.f_max) if params.adaptive else None
    )
    state = xoshiro_states(rngs)  # each run's own stream for mutation, crossover and re-draws
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
            if cached:
                objective.keep(np.repeat(keep, n))
            ids, pop, fit = (
                ids[keep],
                np.ascontiguousarray(pop[keep]),
                np.ascontiguousarray(fit[keep]),
            )
            state = np.ascontiguousarray(state[keep])
            trial, best, accepted = trial[: keep.sum()], best[: keep.sum()], accepted[: keep.sum()]
        f_i, cr_i = f_all[: ids.size], cr_all[: ids.size]
        if params.adaptive:
            ade_rates_into(
                fit,
                float(f_schedule[g]),
                float(params.f_min),
                float(params.f_max),
                float(params.cr_min),
                float(params.cr_max),
                F_RULES.index(params.f_rule),
                params.cr_rule == "rank",
                f_i,
                cr_i,
            )
        de_trials(pop, state, f_i, cr_i, b, trial)
        if cached:
            tfit = objective.trials(trial.reshape(-1, dim), pop.reshape(-1, dim))
        else:
            tfit = objective(trial.reshape(-1, dim))
        tfit = np.asarray(tfit, dtype=float).reshape(ids.size, n)
        de_select(pop, fit, trial, tfit, best, accepted)  # greedy selection, in place
        if cached:
            objective.accept(accepted.ravel())
        history[ids, g] = best
        g += 1
    return results
