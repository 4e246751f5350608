import numpy as np
import pytest
from scipy.optimize import differential_evolution

from dataclasses import replace

from navlib.methods.de import DEParams, ade_cr, ade_f, ade_rates, evolve, evolve_many
from navlib.methods.jit import (
    ade_rates_into,
    de_trials,
    sample_parents,
    sample_uniform,
    xoshiro_states,
)
from navlib.methods.seeding import generators
from navlib.errors import InputError


def shifted_sphere(pop):
    return np.sum((pop - 1.5) ** 2, axis=1)


def rastrigin(pop):
    return 10 * pop.shape[1] + np.sum(pop**2 - 10 * np.cos(2 * np.pi * pop), axis=1)


@pytest.mark.parametrize("adaptive", [False, True])
def test_de_finds_known_optimum(adaptive):
    res = evolve(
        shifted_sphere,
        5,
        DEParams(
            pop_size=40,
            max_generations=400,
            target_fitness=1e-12,
            bound=5,
            adaptive=adaptive,
            seed=1,
        ),
    )
    assert np.allclose(res.x, 1.5, atol=1e-4)
    assert res.fitness < 1e-8


def test_de_on_multimodal_function_reaches_global_optimum():
    res = evolve(
        rastrigin,
        3,
        DEParams(
            pop_size=40,
            max_generations=600,
            target_fitness=1e-10,
            bound=5.12,
            f=0.5,
            cr=0.9,
            seed=0,
        ),
    )
    assert np.allclose(res.x, 0.0, atol=1e-3)


def test_de_stops_at_target_and_history_never_rises():
    res = evolve(
        shifted_sphere,
        4,
        DEParams(pop_size=20, max_generations=2000, target_fitness=1e-3, bound=5, seed=2),
    )
    assert res.reached_target and res.fitness <= 1e-3 and res.generations < 2000
    assert np.all(np.diff(res.history) <= 0)
    assert res.n_evaluations == 20 * (res.generations + 1)


def test_de_is_deterministic_with_seed_and_respects_bounds():
    p = DEParams(pop_size=12, max_generations=50, bound=2.0, seed=5)
    a, b = evolve(shifted_sphere, 3, p), evolve(shifted_sphere, 3, p)
    assert np.array_equal(a.x, b.x)
    assert np.all(np.abs(a.population) <= 2.0)


def test_de_matches_scipy_on_the_same_budget():
    """Ours and scipy run the same DE/rand/1/bin (deferred updating): on a budget where neither converges,
    their final fitness over 40 seeds has the same distribution (medians within a factor 1.3; a broken
    mutation, crossover or selection moves ours by orders of magnitude).  Both evaluate the initial
    population and 59 generations."""

    def sphere(pop):
        return np.sum((pop - 1.5) ** 2, axis=1)

    ours = [
        r.fitness
        for r in evolve_many(
            sphere,
            10,
            DEParams(pop_size=30, max_generations=59, f=0.5, cr=0.6, bound=5, target_fitness=-1),
            generators(range(40)),
        )
    ]
    ref = [
        differential_evolution(
            lambda x: sphere(x.T),
            [(-5, 5)] * 10,
            strategy="rand1bin",
            popsize=3,
            maxiter=59,
            mutation=0.5,
            recombination=0.6,
            tol=0,
            atol=0,
            polish=False,
            init="random",
            updating="deferred",
            vectorized=True,
            seed=s,
        ).fun
        for s in range(40)
    ]
    ratio = np.median(ours) / np.median(ref)
    assert 1 / 1.3 < ratio < 1.3, (np.median(ours), np.median(ref))


def test_seed_batched_runs_equal_runs_alone():
    p = DEParams(pop_size=12, max_generations=80, bound=5, adaptive=True, target_fitness=0.5)
    batch = evolve_many(shifted_sphere, 4, p, generators([0, 1, 2]))
    for k in range(3):
        alone = evolve_many(shifted_sphere, 4, p, generators([k]))[0]
        np.testing.assert_array_equal(batch[k].x, alone.x)
        assert batch[k].generations == alone.generations
    assert len({r.generations for r in batch}) > 1 or all(r.generations == 80 for r in batch)
    assert evolve(shifted_sphere, 4, replace(p, seed=2)).fitness == batch[2].fitness


def test_ade_f_schedule():
    g = np.arange(3000)
    f = ade_f(g, 3000, 0.3, 0.9)
    assert f[0] == pytest.approx(0.9) and f[-1] == pytest.approx(0.3)
    assert np.all(np.diff(f) < 0)
    assert f[1500] == pytest.approx(0.9 - 0.6 * 1500 / 2999)


def test_ade_cr_from_fitness_value():
    fit = np.array([5.0, 1.0, 3.0, 9.0])
    cr = ade_cr(fit, 0.1, 0.9)
    assert cr[1] == pytest.approx(0.1)  # best -> CR_min
    assert cr[3] == pytest.approx(0.9)  # worst -> CR_max
    assert cr[2] == pytest.approx(0.1 + 0.8 * 2 / 8)
    assert np.allclose(ade_cr(np.ones(4)), 0.1)  # no spread -> CR_min


def test_parent_and_jrand_draws_are_distinct_and_uniform():
    state = xoshiro_states(generators([0]))
    r = sample_parents(state, 6, 6000)
    assert np.all(r[:, :3] != 0)  # never the individual itself (i = 0)
    assert np.all(r[:, 0] != r[:, 1]) and np.all(r[:, 0] != r[:, 2]) and np.all(r[:, 1] != r[:, 2])
    for col in range(3):  # each uniform over the 5 others
        counts = np.bincount(r[:, col], minlength=6) / 6000
        assert np.allclose(counts[1:], 0.2, atol=0.025), counts
    assert np.allclose(
        np.bincount(r[:, 3], minlength=7) / 6000, 1 / 7, atol=0.025
    )  # j_rand over 7 genes
    u = sample_uniform(xoshiro_states(generators([1])), 20000)
    assert (
        u.min() >= 0
        and u.max() < 1
        and abs(u.mean() - 0.5) < 0.01
        and abs(u.var() - 1 / 12) < 0.003
    )


def _trials(pop, cr, bound=1e9, f=1.0, seed=0):
    pop = np.ascontiguousarray(pop[None], dtype=float)
    trial = np.empty_like(pop)
    n = pop.shape[1]
    de_trials(
        pop,
        xoshiro_states(generators([seed])),
        np.full((1, n), float(f)),
        np.full((1, n), float(cr)),
        bound,
        trial,
    )
    return trial[0]


def test_trial_is_the_rand1_mutant_of_three_distinct_others_with_full_crossover():
    n, dim = 10, 5
    pop = np.tile(2.0 ** np.arange(n)[:, None], (1, dim))  # individual i = 2^i in every gene
    trial = _trials(pop, cr=1.0)  # F = 1: u = 2^r1 + 2^r2 - 2^r3
    for i in range(n):
        assert np.all(trial[i] == trial[i, 0])  # one triple per individual
        v = int(trial[i, 0])
        found = [
            (a, b, c)
            for a in range(n)
            for b in range(n)
            for c in range(n)
            if len({a, b, c, i}) == 4 and 2**a + 2**b - 2**c == v
        ]
        assert found, (i, v)


def test_zero_crossover_changes_exactly_the_forced_gene_and_out_of_box_genes_are_redrawn():
    rng = np.random.default_rng(3)
    pop = rng.uniform(-1, 1, (20, 8))
    trial = _trials(pop, cr=0.0, f=0.5)
    assert np.all((trial != pop).sum(axis=1) == 1)  # j_rand only
    unbounded = _trials(pop, cr=1.0, f=2.0)
    wide = _trials(pop, cr=1.0, f=2.0, bound=1.0)  # the same draws, now inside [-1, 1]
    out = np.abs(unbounded) > 1.0
    assert out.mean() > 0.2
    first = int(np.flatnonzero(out.any(axis=1))[0])  # re-draws shift the stream after it
    same = np.zeros_like(out)
    same[: first + 1] = ~out[: first + 1]
    assert same.sum() > 0
    np.testing.assert_array_equal(wide[same], unbounded[same])  # in-box genes untouched
    assert np.all(np.abs(wide) <= 1.0)
    assert not np.any(np.abs(wide) == 1.0)  # re-drawn uniformly, not clipped


@pytest.mark.parametrize(
    "field,value,msg",
    [
        ("pop_size", 3, "NP"),
        ("f", 0.0, "F"),
        ("f", 2.5, "F"),
        ("cr", 1.5, "CR"),
        ("bound", -1, "bound"),
        ("max_generations", 0, "max_generations"),
        ("f_rule", "rank", "f_rule"),
        ("cr_rule", "generation", "cr_rule"),
    ],
)
def test_bad_de_parameters(field, value, msg):
    with pytest.raises(InputError, match=msg):
        DEParams(**{field: value})


# ---------------------------------------------------------------------------------------- ADE's readings
FIT = np.array([5.0, 1.0, 3.0, 9.0])  # q = (f - 1) / 8 = [1/2, 0, 1/4, 1]; ranks [2, 0, 1, 3]


@pytest.mark.parametrize(
    "f_rule,cr_rule,f_expected,cr_expected",
    [
        ("generation", "value", [0.6, 0.6, 0.6, 0.6], [0.5, 0.1, 0.3, 0.9]),
        ("individual", "value", [0.6, 0.3, 0.45, 0.9], [0.5, 0.1, 0.3, 0.9]),
        ("combined", "value", [0.45, 0.3, 0.375, 0.6], [0.5, 0.1, 0.3, 0.9]),
        ("generation", "rank", [0.6, 0.6, 0.6, 0.6], [0.1 + 0.8 * 2 / 3, 0.1, 0.1 + 0.8 / 3, 0.9]),
        ("combined", "rank", [0.45, 0.3, 0.375, 0.6], [0.1 + 0.8 * 2 / 3, 0.1, 0.1 + 0.8 / 3, 0.9]),
    ],
)
def test_ade_rules_on_a_population_with_known_fitness(f_rule, cr_rule, f_expected, cr_expected):
    """At generation 1500 of 3001 the schedule gives F(t) = 0.9 - 0.6 / 2 = 0.6; every reading's F_i and
    CR_i from the equations of navlib.methods.de, each population of a batch on its own."""
    p = DEParams(max_generations=3001, adaptive=True, f_rule=f_rule, cr_rule=cr_rule)
    batch = np.stack([FIT, 10 * FIT + 7])  # an affine copy: the same q and ranks
    f, cr = ade_rates(batch, 1500, p)
    assert f.shape == cr.shape == batch.shape
    for row in range(2):
        np.testing.assert_allclose(f[row], f_expected, rtol=1e-12)
        np.testing.assert_allclose(cr[row], cr_expected, rtol=1e-12)
    f0, cr0 = ade_rates(batch, 1500, replace(p, adaptive=False))  # DE: fixed F and CR
    assert np.all(f0 == p.f) and np.all(cr0 == p.cr)


def test_cr_by_value_and_by_rank_differ_when_fitness_spans_decades():
    """Fitness over four decades: by value all but the worst sit near CR_min, by rank they are evenly
    spread; equal fitness gives CR_min by value."""
    fit = np.array([1.0, 10.0, 100.0, 1e4])
    by_value, by_rank = ade_cr(fit, 0.1, 0.9, "value"), ade_cr(fit, 0.1, 0.9, "rank")
    assert np.all(by_value[:3] < 0.11) and by_value[3] == pytest.approx(0.9)
    np.testing.assert_allclose(by_rank, [0.1, 0.1 + 0.8 / 3, 0.1 + 1.6 / 3, 0.9])
    np.testing.assert_allclose(ade_cr(np.full(5, 2.0), 0.1, 0.9, "value"), 0.1)
    ties = ade_cr(np.array([3.0, 3.0, 1.0]), 0.1, 0.9, "rank")
    np.testing.assert_allclose(ties, [0.5, 0.9, 0.1])  # ties ranked by index


def test_kernel_uses_each_individuals_own_f_and_cr():
    """Per-individual F_i and CR_i reach the compiled generation: with individual i = 2^i in every gene and
    full crossover, u_i = 2^r1 + F_i (2^r2 - 2^r3) for some distinct r1, r2, r3 != i (the numpy
    statement of the mutation); with CR_i = 0 exactly one gene (j_rand) comes from the mutant."""
    n, dim = 10, 5
    pop = np.ascontiguousarray(np.tile(2.0 ** np.arange(n)[:, None], (1, dim))[None])
    f = np.where(np.arange(n) % 2 == 0, 1.0, 0.5)[None]
    cr = np.ones((1, n))
    trial = np.empty_like(pop)
    de_trials(pop, xoshiro_states(generators([4])), f, cr, 1e9, trial)
    for i in range(n):
        v = trial[0, i, 0]
        assert np.all(trial[0, i] == v)
        assert any(
            len({a, b, c, i}) == 4 and 2.0**a + f[0, i] * (2.0**b - 2.0**c) == v
            for a in range(n)
            for b in range(n)
            for c in range(n)
        ), (i, v)
    rng = np.random.default_rng(5)
    pop = np.ascontiguousarray(rng.uniform(-1, 1, (1, 20, 8)))
    cr = np.where(np.arange(20) < 10, 0.0, 1.0)[None]
    de_trials(
        pop,
        xoshiro_states(generators([6])),
        np.full((1, 20), 0.5),
        cr,
        1e9,
        trial := np.empty_like(pop),
    )
    changed = (trial[0] != pop[0]).sum(axis=1)
    assert np.all(changed[:10] == 1) and np.all(changed[10:] == 8)


@pytest.mark.parametrize(
    "f_rule,cr_rule", [("individual", "value"), ("combined", "rank"), ("generation", "rank")]
)
def test_every_ade_reading_optimises_and_batches_equal_runs_alone(f_rule, cr_rule):
    p = DEParams(
        pop_size=30,
        max_generations=300,
        target_fitness=1e-10,
        bound=5,
        adaptive=True,
        f_rule=f_rule,
        cr_rule=cr_rule,
    )
    batch = evolve_many(shifted_sphere, 4, p, generators([0, 1]))
    assert all(r.fitness < 1e-6 for r in batch)
    alone = evolve_many(shifted_sphere, 4, p, generators([1]))[0]
    np.testing.assert_array_equal(batch[1].x, alone.x)


@pytest.mark.parametrize("f_rule", ["generation", "individual", "combined"])
@pytest.mark.parametrize("cr_rule", ["value", "rank"])
def test_compiled_rates_equal_the_numpy_reference(f_rule, cr_rule):
    """The compiled ADE rates used by evolve_many equal ade_rates (numpy) exactly, ties and flat runs
    included."""
    rng = np.random.default_rng(7)
    fit = np.exp(rng.normal(0, 4, (3, 30)))
    fit[1, :5] = fit[1, 5]  # ties
    fit[2] = 2.5  # a flat run
    p = DEParams(max_generations=500, adaptive=True, f_rule=f_rule, cr_rule=cr_rule)
    f_ref, cr_ref = ade_rates(fit, 123, p)
    f, cr = np.empty_like(fit), np.empty_like(fit)
    ade_rates_into(
        fit,
        float(ade_f(123, 500, p.f_min, p.f_max)),
        p.f_min,
        p.f_max,
        p.cr_min,
        p.cr_max,
        ("generation", "individual", "combined").index(f_rule),
        cr_rule == "rank",
        f,
        cr,
    )
    np.testing.assert_array_equal(f, f_ref)
    np.testing.assert_array_equal(cr, cr_ref)
