import numpy as np
import pytest
import torch

from navlib.methods.bpnet import (GradientParams, forward_population, n_params, sse_objective, train_de,

    train_gradient, unpack)
from navlib.methods.de import DEParams
from navlib.errors import InputError


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


def test_gradient_bp_fits_smooth_map():
    """LM reaches the exact map from most starts (a 1-6-1 net has local minima); Adam gets close."""
    x = np.linspace(-10, 350, 121)
    t = np.linspace(0, 360, 121)
    t = t + 3 * np.sin(np.radians(2 * t))
    rms = {m: [np.sqrt(np.mean((train_gradient(x, t, 6, GradientParams(method=m, seed=s)).predict(x) - t) ** 2))
               for s in range(5)] for m in ("lm", "adam")}
    assert sum(r < 0.01 for r in rms["lm"]) >= 3
    assert np.median(rms["adam"]) < 2.0          # a straight line leaves 2.1 deg RMS


def test_adam_training_is_reproducible():
    torch.set_num_threads(1)
    x = np.linspace(0, 1, 20)
    a = train_gradient(x, x ** 2, 3, GradientParams(epochs=50, seed=4))
    b = train_gradient(x, x ** 2, 3, GradientParams(epochs=50, seed=4))
    assert np.array_equal(a.theta, b.theta)


def test_de_bp_improves_over_generations_and_reports_float64_fitness():
    x = np.linspace(0, 360, 61)
    t = x + 4 * np.sin(np.radians(x))
    net, res = train_de(x, t, 3, DEParams(pop_size=30, max_generations=200, seed=0, adaptive=True))
    assert res.history[-1] < res.history[0]
    assert net.info["fitness"] == pytest.approx(np.sum((net.predict(x) - t) ** 2), rel=1e-9)
    assert net.method == "ADE-BP"


def test_bad_network_inputs():
    with pytest.raises(InputError, match="n_hidden"):
        train_gradient([0, 1, 2], [0, 1, 2], 0)
    with pytest.raises(InputError, match="equal length"):
        train_gradient([0, 1, 2], [0, 1], 2)
    with pytest.raises(InputError, match="constant"):
        train_gradient([1, 1, 1], [0, 1, 2], 2)
    with pytest.raises(InputError, match="method"):
        train_gradient([0, 1, 2], [0, 1, 2], 2, GradientParams(method="sgd"))


def test_train_adam_many_matches_one_at_a_time():
    from navlib.methods.bpnet import train_adam_many

    x = np.linspace(0, 360, 15)
    t = x + 10 * np.sin(np.radians(x))
    gp = GradientParams(epochs=200, lr=0.01)
    nets = train_adam_many(x, t, 5, gp, seeds=[0, 3, 7])
    xt = np.linspace(0, 360, 121)
    for s, net in zip([0, 3, 7], nets):
        ref = train_gradient(x, t, 5, GradientParams(epochs=200, lr=0.01, seed=s))
        np.testing.assert_allclose(net.predict(xt), ref.predict(xt), atol=1e-6)
        np.testing.assert_allclose(net.history, ref.history, rtol=1e-9)
    assert not np.allclose(nets[0].theta, nets[1].theta)
    with pytest.raises(InputError, match="adam"):
        train_adam_many(x, t, 5, GradientParams(method="lm"))


def test_second_order_training_of_an_oversized_net_falls_back_to_trf_and_fits():
    """LM needs at least as many readings as weights; with fewer, the same problem is solved by TRF."""
    x = np.linspace(0, 360, 8)
    t = x + 5 * np.sin(np.radians(x))
    net = train_gradient(x, t, 20, GradientParams(method="lm", seed=0))
    assert net.method == "BP (TRF)"
    assert np.max(np.abs(net.predict(x) - t)) < 1e-3
    small = train_gradient(np.linspace(0, 360, 121), np.linspace(0, 360, 121), 2, GradientParams(method="lm"))
    assert small.method == "BP (LM)"
