import scipy.special
import numpy as np
import pytest
import torch

from navlib.methods.bpnet import (
    AdamParams,
    forward_population,
    n_params,
    output_jacobian,
    sse_objective,
    train_adam_many,
    train_de_many,
    train_least_squares,
    unpack,
)
from navlib.methods.seeding import generators
from navlib.methods.de import DEParams
from navlib.errors import InputError
from peers import autograd_adam


def reference_forward(theta, xn, m):
    w, b, v, c = unpack(theta, m)
    return (1 / (1 + np.exp(-(np.outer(xn, w) + b)))) @ v + c


def test_forward_population_matches_per_network_loop():
    rng = np.random.default_rng(0)
    pop = rng.uniform(-5, 5, (7, n_params(6)))
    xn = np.linspace(0, 1, 31)
    out = forward_population(pop, xn, 6)
    ref = np.stack([reference_forward(p, xn, 6) for p in pop])
    assert np.allclose(out, ref, atol=1e-12)
    assert np.allclose(forward_population(pop, xn, 6, np.float32), ref, atol=1e-4)


def test_sse_objective_in_degrees():
    x = np.linspace(0, 360, 121)
    t = x + 5 * np.sin(np.radians(x))
    obj64, xs, ts = sse_objective(x, t, 6, np.float64)
    rng = np.random.default_rng(1)
    pop = rng.uniform(-3, 3, (5, 19))
    ref = [np.sum((t - ts.inverse(reference_forward(p, xs.transform(x), 6))) ** 2) for p in pop]
    assert np.allclose(obj64(pop), ref, rtol=1e-10)
    obj32, _, _ = sse_objective(x, t, 6)
    assert np.allclose(obj32(pop), ref, rtol=1e-4)


def test_output_jacobian_matches_finite_differences():
    rng = np.random.default_rng(5)
    xn = np.linspace(-1, 1, 9)
    for act in ("logsig", "tansig"):
        th = rng.uniform(-2, 2, (2, n_params(4)))
        out, jac = output_jacobian(th, xn, 4, act)
        np.testing.assert_allclose(out, forward_population(th, xn, 4, activation=act), atol=1e-12)
        eps = 1e-6
        for d in range(th.shape[1]):
            e = np.zeros_like(th)
            e[:, d] = eps
            fd = (
                forward_population(th + e, xn, 4, activation=act)
                - forward_population(th - e, xn, 4, activation=act)
            ) / (2 * eps)
            np.testing.assert_allclose(jac[:, :, d], fd, atol=1e-7)


@pytest.mark.slow
def test_second_order_and_adam_fit_a_smooth_map():
    """LM reaches the exact map from most starts.  Adam from U(-1, 1) in 3000 epochs learns the trend but
    hardly the two-cycle wiggle (a straight line leaves 1.95 deg RMS; Adam's median is just under it, its
    normalised MSE falls by more than two orders of magnitude from the start) -- the chapter's finding
    that Adam with this budget stays degrees away from the floor."""
    torch.set_num_threads(1)
    x = np.linspace(-10, 350, 121)
    t = np.linspace(0, 360, 121)
    t = t + 3 * np.sin(np.radians(2 * t))
    line = np.polyval(np.polyfit(x, t, 1), x)
    line_rms = np.sqrt(np.mean((line - t) ** 2))
    lm = [
        np.sqrt(np.mean((train_least_squares(x, t, 6, g).predict(x) - t) ** 2))
        for g in generators(range(5))
    ]
    nets = train_adam_many(x, t, 6, AdamParams(), generators(range(5)))
    adam = [np.sqrt(np.mean((n.predict(x) - t) ** 2)) for n in nets]
    assert line_rms > 1.9
    assert sum(r < 0.01 for r in lm) >= 3
    assert np.median(adam) < line_rms
    assert all(n.history[-1] < n.history[0] / 100 for n in nets)


def test_adam_training_is_reproducible():
    torch.set_num_threads(1)
    x = np.linspace(0, 1, 20)
    a = train_adam_many(x, x**2, 3, AdamParams(epochs=50), generators([4]))[0]
    b = train_adam_many(x, x**2, 3, AdamParams(epochs=50), generators([4]))[0]
    assert np.array_equal(a.theta, b.theta)


def test_de_bp_beats_random_search_and_reports_float64_fitness():
    """The evolved net is far better than the best of as many random nets as DE evaluated (a DE whose
    mutation, crossover or selection were broken would not be)."""
    x = np.linspace(0, 360, 61)
    t = x + 4 * np.sin(np.radians(x))
    p = DEParams(pop_size=30, max_generations=200, adaptive=True, target_fitness=-1)
    nets, res = train_de_many(x, t, 3, p, generators([0]))
    net = nets[0]
    objective, _, _ = sse_objective(x, t, 3, np.float64)
    random_best = objective(
        np.random.default_rng(0).uniform(-10, 10, (res[0].n_evaluations, n_params(3)))
    ).min()
    assert net.info["fitness"] < random_best / 4
    assert net.info["fitness"] == pytest.approx(np.sum((net.predict(x) - t) ** 2), rel=1e-9)
    assert net.method == "ADE-BP"


def test_bad_network_inputs():
    g = generators([0])
    with pytest.raises(InputError, match="n_hidden"):
        train_adam_many([0, 1, 2], [0, 1, 2], 0, AdamParams(), g)
    with pytest.raises(InputError, match="equal length"):
        train_adam_many([0, 1, 2], [0, 1], 2, AdamParams(), g)
    with pytest.raises(InputError, match="constant"):
        train_adam_many([1, 1, 1], [0, 1, 2], 2, AdamParams(), g)
    with pytest.raises(InputError, match="rngs"):
        train_adam_many([0, 1, 2], [0, 1, 2], 2, AdamParams(), [3])


def test_train_adam_many_matches_one_at_a_time():
    torch.set_num_threads(1)
    x = np.linspace(0, 360, 15)
    t = x + 10 * np.sin(np.radians(x))
    ap = AdamParams(epochs=200, lr=0.01)
    nets = train_adam_many(x, t, 5, ap, generators([0, 3, 7]))
    xt = np.linspace(0, 360, 121)
    for s, net in zip([0, 3, 7], nets):
        ref = train_adam_many(x, t, 5, ap, generators([s]))[0]
        np.testing.assert_allclose(net.predict(xt), ref.predict(xt), atol=1e-6)
        np.testing.assert_allclose(net.history, ref.history, rtol=1e-9)
    assert not np.allclose(nets[0].theta, nets[1].theta)


@pytest.mark.parametrize("m, n", [(5, 15), (50, 8)])
def test_analytic_adam_follows_the_autograd_trajectory(m, n):
    """The hand-written gradient and the fused Adam step reproduce autograd + default Adam up to rounding
    over 200 epochs (a wrong term of the gradient, e.g. a missing x' in dL/dw, moves the weights by far
    more than 1e-8 relative).  The nets' own U(-1, 1) draws and the normalisation are those of
    train_adam_many."""
    x = np.linspace(0, 360, n)
    t = x + 10 * np.sin(np.radians(2 * x))
    ap = AdamParams(epochs=200, lr=0.01)
    seeds = [0, 3, 7]
    nets = train_adam_many(x, t, m, ap, generators(seeds))
    theta0 = np.stack([g.uniform(-1, 1, n_params(m)) for g in generators(seeds)])
    xn, tn = nets[0].x_scale.transform(x), nets[0].t_scale.transform(t)
    theta, history = autograd_adam(theta0, xn, tn, m, ap.epochs, ap.lr)
    assert history[:, -1].max() < history[:, 0].min() / 2  # the nets did train
    for i, net in enumerate(nets):
        np.testing.assert_allclose(net.history, history[i], rtol=1e-8)
        np.testing.assert_allclose(net.theta, theta[i], rtol=1e-8, atol=1e-10)


def test_adam_result_does_not_depend_on_the_thread_count():
    x = np.linspace(0, 360, 60)
    t = x + 10 * np.sin(np.radians(x))
    threads = torch.get_num_threads()
    try:
        runs = []
        for k in (1, 2):
            torch.set_num_threads(k)
            runs.append(train_adam_many(x, t, 50, AdamParams(epochs=100), generators(range(20))))
            assert torch.get_num_threads() == k  # the caller's setting is restored
    finally:
        torch.set_num_threads(threads)
    for a, b in zip(*runs):
        assert np.array_equal(a.theta, b.theta)


def test_second_order_training_of_an_oversized_net_falls_back_to_trf_and_fits():
    """MINPACK's LM needs at least as many readings as weights; with fewer, TRF solves the same problem."""
    x = np.linspace(0, 360, 8)
    t = x + 5 * np.sin(np.radians(x))
    net = train_least_squares(x, t, 20, generators([0])[0])
    assert net.method == "BP (TRF)"
    assert np.max(np.abs(net.predict(x) - t)) < 1e-3
    small = train_least_squares(
        np.linspace(0, 360, 121), np.linspace(0, 360, 121), 2, generators([0])[0]
    )
    assert small.method == "BP (LM)"


def test_compiled_sigmoid_is_float32_accurate_everywhere():
    from navlib.methods.jit import logsig_vec

    z = np.concatenate(
        [np.linspace(-200, 200, 200001), [0.0, -1e-8, 1e-8, 88.7, -88.7, 1e30, -1e30]]
    )
    exact = scipy.special.expit(z)
    got = logsig_vec(z.astype(np.float32)).astype(float)
    assert np.max(np.abs(got - exact)) < 2e-7
    assert np.all(
        np.diff(logsig_vec(np.linspace(-30, 30, 10001, dtype=np.float32))) >= 0
    )  # monotone


def test_compiled_fitness_matches_double_precision_on_evolved_like_nets():
    x = np.linspace(0, 360, 121)
    t = x + 15 * np.sin(np.radians(x)) + 3 * np.cos(2 * np.radians(x))
    obj64, _, _ = sse_objective(x, t, 6, np.float64)
    obj32, _, _ = sse_objective(x, t, 6)
    pop = np.random.default_rng(7).uniform(-10, 10, (500, 19))
    np.testing.assert_allclose(obj32(pop), obj64(pop), rtol=2e-5)
    np.testing.assert_allclose(obj32(pop[:1]), obj64(pop[:1]), rtol=2e-5)  # any population size


def test_parent_cached_fitness_equals_the_full_evaluation_bit_for_bit():
    """LogsigSSE.trials reuses a parent's hidden units whose weights a trial kept; every fitness equals the
    plain call's exactly, whichever units were changed (none, some, all, the output weights only)."""
    x = np.linspace(0, 360, 121)
    t = x + 15 * np.sin(np.radians(x)) + 3 * np.cos(2 * np.radians(x))
    obj, _, _ = sse_objective(x, t, 6)
    rng = np.random.default_rng(3)
    pop = rng.uniform(-10, 10, (200, 19))
    np.testing.assert_array_equal(obj.start(pop), obj(pop))
    trial = pop.copy()
    mask = rng.random(pop.shape) < rng.uniform(
        0, 1, (200, 1)
    )  # each trial changes its own share of genes
    mask[:20] = False  # identical to the parent
    mask[20:40] = False
    mask[20:40, 12:] = True  # only the output layer changed
    trial[mask] = rng.uniform(-10, 10, mask.sum())
    np.testing.assert_array_equal(obj.trials(trial, pop), obj(trial))
    kept_unit = ~(mask[:, :6] | mask[:, 6:12])
    assert kept_unit.any() and (~kept_unit).any()
    # accept every other trial: the kept hidden layers follow, and a next generation still matches
    accepted = np.arange(200) % 2 == 0
    obj.accept(accepted)
    pop[accepted] = trial[accepted]
    trial2 = pop.copy()
    trial2[:, 3] += 0.5  # unit 3's input weight: every trial
    np.testing.assert_array_equal(obj.trials(trial2, pop), obj(trial2))
    rows = np.arange(200) < 95  # a finished run leaves the batch
    obj.keep(rows)
    np.testing.assert_array_equal(obj.trials(trial2[rows], pop[rows]), obj(trial2[rows]))


@pytest.mark.parametrize(
    "adaptive,cr_rule,target",
    [(False, "value", 0.0), (True, "value", 0.0), (True, "rank", 0.0), (False, "value", 2e5)],
)
def test_evolution_with_the_parent_cache_equals_plain_evaluation(adaptive, cr_rule, target):
    """evolve_many through the cache protocol gives the runs a plain callable gives, bit for bit (also when
    runs reach the target at different generations and leave the batch)."""
    from navlib.methods.de import DEParams, evolve_many
    from navlib.methods.seeding import generators

    x = np.linspace(0, 360, 121)
    t = x + 15 * np.sin(np.radians(x)) + 3 * np.cos(2 * np.radians(x))
    obj, _, _ = sse_objective(x, t, 6)
    p = DEParams(
        pop_size=20, max_generations=300, target_fitness=target, adaptive=adaptive, cr_rule=cr_rule
    )
    cached = evolve_many(obj, 19, p, generators([0, 1, 2]))
    plain = evolve_many(lambda th: obj(th), 19, p, generators([0, 1, 2]))
    if target:
        assert len({r.generations for r in plain}) > 1  # runs left the batch at different times
    for a, b in zip(cached, plain):
        assert a.generations == b.generations and a.fitness == b.fitness
        np.testing.assert_array_equal(a.population, b.population)
        np.testing.assert_array_equal(a.history, b.history)
