"""MATLAB's trainlm (navlib.methods.lm), Nguyen-Widrow initialisation, the validation stop and the DE -> LM
hand-over of paper A's second reading."""

import numpy as np
import pytest
from scipy.optimize import least_squares

from navlib.errors import InputError
from navlib.methods.bpnet import (
    TANSIG_ACTIVE,
    matlab_initial_weights,
    nguyen_widrow,
    output_jacobian,
    train_hybrid_many,
    train_lm_many,
    train_matlab_bp_many,
)
from navlib.methods.de import DEParams
from navlib.methods.lm import LMParams, dividerand, levenberg_marquardt
from navlib.methods.scaling import MinMax
from navlib.methods.seeding import generators


def small_problem(noise=0.01, n=40, seed=0):
    """A 1-3-1 logsig net's outputs plus noise: a least-squares problem with a known neighbourhood."""
    rng = np.random.default_rng(seed)
    xn = np.linspace(0, 1, n)
    true = np.array([6.0, -4.0, 3.0, -3.0, 1.0, -1.5, 0.8, -0.6, 0.5, 0.2])
    y = output_jacobian(true[None], xn, 3)[0][0] + noise * rng.standard_normal(n)
    return xn, y, true


def _against_least_squares(res, jac, start):
    """Our LM from ``start`` against scipy's MINPACK LM on the same residuals: the same minimum (SSE and
    weights), well below the start's; returns our result."""
    ours = levenberg_marquardt(res, jac, start[None], LMParams(epochs=500, min_grad=0.0))
    ref = least_squares(
        lambda th: res(th[None])[0],
        start,
        jac=lambda th: jac(th[None])[0],
        method="lm",
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
        max_nfev=10000,
    )
    sse_ours = float(np.sum(res(ours.theta) ** 2))
    assert sse_ours == pytest.approx(2 * ref.cost, rel=1e-8)
    np.testing.assert_allclose(ours.theta[0], ref.x, atol=1e-5)
    assert sse_ours < float(np.sum(res(start[None]) ** 2)) / 10  # it did train
    return ours


def test_lm_matches_scipy_least_squares_on_a_small_net():
    xn, y, true = small_problem()
    start = true + 0.3 * np.random.default_rng(1).standard_normal(true.size)

    def res(th):
        return output_jacobian(th, xn, 3)[0] - y

    def jac(th):
        return output_jacobian(th, xn, 3)[1]

    ours = _against_least_squares(res, jac, start)
    h = ours.perf[0][np.isfinite(ours.perf[0])]
    assert np.all(np.diff(h) <= 0) and np.sum(np.diff(h) < 0) > 5  # accepted steps lower the MSE
    assert ours.stop[0] in ("maximum mu", "maximum epoch")


def test_batched_lm_equals_one_net_at_a_time():
    xn, y, true = small_problem()
    starts = true + 0.5 * np.random.default_rng(2).standard_normal((3, true.size))

    def res(th):
        return output_jacobian(th, xn, 3)[0] - y

    def jac(th):
        return output_jacobian(th, xn, 3)[1]

    p = LMParams(epochs=60)
    both = levenberg_marquardt(res, jac, starts, p)
    for i in range(3):
        one = levenberg_marquardt(res, jac, starts[i : i + 1], p)
        np.testing.assert_allclose(both.theta[i], one.theta[0], rtol=1e-10, atol=1e-12)
        assert both.epochs[i] == one.epochs[0] and both.stop[i] == one.stop[0]


def test_validation_stop_returns_best_validation_weights():
    rng = np.random.default_rng(3)
    x = np.linspace(0, 360, 60)
    t = x + 5 * np.sin(np.radians(2 * x)) + 2.0 * rng.standard_normal(x.size)  # noisy: overfits
    xs, ts = MinMax.fit(x, out=(-1, 1)), MinMax.fit(t, out=(-1, 1))
    g = generators([1])[0]
    split = dividerand(x.size, g)
    theta0 = matlab_initial_weights(10, g)[None]
    p = LMParams(max_fail=6)
    net = train_lm_many(x, t, 10, theta0, xs, ts, "tansig", p, [split])[0]
    assert net.info["stop"] == "validation stop"
    vh = net.info["val_history"]
    best = int(np.argmin(vh))
    assert net.info["best_epoch"] == best
    assert net.info["epochs"] == best + p.max_fail  # six failures after the best epoch
    assert np.all(vh[best + 1 :] > vh[best])
    val = split[1]
    mse_val = np.mean((net.predict(x[val]) - t[val]) ** 2)
    assert mse_val == pytest.approx(vh[best], rel=1e-9)  # the returned net is the best one
    no_stop = train_lm_many(x, t, 10, theta0, xs, ts, "tansig", p)[0]
    assert no_stop.info["stop"] != "validation stop" and no_stop.info["epochs"] > net.info["epochs"]


def test_dividerand_is_matlabs_70_15_15():
    tr, va, te = dividerand(121, np.random.default_rng(0))
    assert (tr.size, va.size, te.size) == (85, 18, 18)
    assert np.array_equal(np.sort(np.concatenate([tr, va, te])), np.arange(121))
    with pytest.raises(InputError, match="ratios"):
        dividerand(10, np.random.default_rng(0), ratios=(1, -1, 0))


@pytest.mark.parametrize(
    "n_hidden", [4, 6, 10]
)  # below 4 units the regions leave gaps (0.7 factor)
def test_nguyen_widrow_active_regions_span_the_input_range(n_hidden):
    for g in generators(range(5)):
        w, b = nguyen_widrow(n_hidden, g)
        w, b = w[:, 0], b
        assert np.allclose(np.abs(w), 0.7 * n_hidden * 2.0)  # 0.7 H^(1/n), stretched to [-2, 2]
        lo = (TANSIG_ACTIVE[0] - b) / w
        hi = (TANSIG_ACTIVE[1] - b) / w
        a, z = np.minimum(lo, hi), np.maximum(lo, hi)
        order = np.argsort(a)
        a, z = a[order], z[order]
        assert a[0] <= -1.0 and z[-1] >= 1.0  # the ends of [-1, 1] are covered
        assert np.all(a[1:] <= np.maximum.accumulate(z)[:-1] + 1e-12)  # and no gap in between
        centres = np.sort(-b / w)
        np.testing.assert_allclose(centres, np.linspace(-1, 1, n_hidden), atol=1e-12)


def test_matlab_bp_trains_the_compass_map_to_the_noise_level():
    rng = np.random.default_rng(4)
    x = np.linspace(-15, 375, 121)
    t = np.linspace(0, 360, 121)
    t = t + 3 * np.sin(np.radians(2 * t)) + 0.1 * rng.standard_normal(121)
    nets = train_matlab_bp_many(x, t, 6, generators(range(3)), LMParams(epochs=300))
    rms = [np.sqrt(np.mean((n.predict(x) - t) ** 2)) for n in nets]
    assert np.median(rms) < 0.2  # noise 0.1 deg; a line leaves 2.1
    assert all(n.activation == "tansig" for n in nets)
    assert nets[0].x_scale.transform(x).min() == -1.0


def test_de_to_lm_hand_over():
    x = np.linspace(0, 360, 61)
    t = x + 4 * np.sin(np.radians(x))
    de = DEParams(pop_size=30, max_generations=400, adaptive=True, target_fitness=0.2)
    span = np.ptp(t)
    stage_only = train_hybrid_many(x, t, 3, de, generators([0, 1]), LMParams(epochs=0))
    for net in stage_only:
        np.testing.assert_array_equal(net.theta, net.info["de_theta"])  # zero epochs: the DE result
        assert net.info["de_fitness"] <= 0.2 * span**2  # normalised target 0.2 reached
        assert net.info["de_generations"] < 400
    full = train_hybrid_many(x, t, 3, de, generators([0, 1]), LMParams(epochs=200))
    for a, b in zip(stage_only, full):
        np.testing.assert_array_equal(a.info["de_theta"], b.info["de_theta"])
        assert b.history[0] == pytest.approx(
            b.info["de_fitness"] / x.size, rel=1e-9
        )  # LM starts there
        assert b.history[-1] < b.history[0] / 100
    deg2 = train_hybrid_many(x, t, 3, de, generators([0]), LMParams(epochs=0), target="deg2")[0]
    assert deg2.info["de_generations"] == 400  # 0.2 deg^2 is never reached


@pytest.mark.parametrize(
    "activation,validation",
    [("tansig", False), ("tansig", True), ("logsig", False), ("logsig", True)],
)
def test_compiled_trainlm_equals_the_generic_numpy_trainlm(activation, validation):
    """The compiled kernel (default) and levenberg_marquardt: the same epochs, stop reasons and best epochs;
    the same initial MSE to 1e-13 and the MSE history to 1e-3 over the first 20 epochs (J'J + mu I has
    condition numbers near 1e10: BLAS and the kernel sum J'J in different orders, and the 1e-16
    difference becomes 1e-6 in the first step and up to 5e-4 after 20 epochs), the same final MSE and
    outputs, with and without the validation stop, for both networks of the chapter."""
    rng = np.random.default_rng(8)
    x = np.linspace(-10, 370, 80)
    t = np.linspace(0, 360, 80) + 4 * np.sin(np.radians(2 * x)) + 0.5 * rng.standard_normal(80)
    out = (-1, 1) if activation == "tansig" else (0, 1)
    xs, ts = MinMax.fit(x, out=out), MinMax.fit(t, out=out)
    gens = generators(range(4))
    theta0 = np.stack([matlab_initial_weights(5, g) for g in gens])
    splits = [dividerand(x.size, g) for g in gens] if validation else None
    p = LMParams(epochs=150)
    fast = train_lm_many(x, t, 5, theta0, xs, ts, activation, p, splits)
    ref = train_lm_many(x, t, 5, theta0, xs, ts, activation, p, splits, compiled=False)
    for a, b in zip(fast, ref):
        assert a.info["epochs"] == b.info["epochs"] and a.info["stop"] == b.info["stop"]
        assert a.info["best_epoch"] == b.info["best_epoch"]
        assert a.history[0] == pytest.approx(b.history[0], rel=1e-13)  # the same network and data
        np.testing.assert_allclose(a.history[:20], b.history[:20], rtol=1e-3)
        np.testing.assert_allclose(a.history[-1], b.history[-1], rtol=1e-2)
        np.testing.assert_allclose(a.predict(x), b.predict(x), atol=1e-2)  # deg, on a 360 deg span
    assert {n.info["stop"] for n in fast} <= {
        "maximum epoch",
        "validation stop",
        "minimum gradient",
        "maximum mu",
    }
    if validation:
        assert any(n.info["stop"] == "validation stop" for n in fast)


# ------------------------------------------------------------------ multi-input, multi-output nets (paper E)
def _ff_problem(n=60, seed=5):
    """A 3-4-2 net's outputs plus noise.  The seed gives an isolated minimum near the true weights (with
    some draws a saturated unit leaves a flat valley along which both solvers drift without end)."""
    from navlib.methods import feedforward as ff

    rng = np.random.default_rng(seed)
    xn = rng.uniform(-1, 1, (n, 3))
    true = rng.normal(0, 1.5, ff.n_weights(3, 4, 2))
    y = ff.forward(true[None], xn, 3, 4, 2)[0] + 0.01 * rng.standard_normal((n, 2))
    return ff, xn, y, true


def test_multi_output_jacobian_matches_finite_differences():
    ff, xn, _, true = _ff_problem()
    j = ff.jacobian(true[None], xn, 3, 4, 2)[0].reshape(-1, true.size)
    eps = 1e-6
    num = np.stack(
        [
            (
                ff.forward((true + eps * e)[None], xn, 3, 4, 2)[0]
                - ff.forward((true - eps * e)[None], xn, 3, 4, 2)[0]
            ).ravel()
            / (2 * eps)
            for e in np.eye(true.size)
        ],
        axis=1,
    )
    np.testing.assert_allclose(j, num, atol=1e-7)


def test_lm_matches_scipy_least_squares_on_a_multi_output_net():
    ff, xn, y, true = _ff_problem()
    start = true + 0.3 * np.random.default_rng(4).standard_normal(true.size)

    def res(th):
        return (ff.forward(th, xn, 3, 4, 2) - y[None]).reshape(th.shape[0], -1)

    def jac(th):
        return ff.jacobian(th, xn, 3, 4, 2).reshape(th.shape[0], y.size, -1)

    _against_least_squares(res, jac, start)  # asserts inside


def test_train_feedforward_learns_and_stops_on_validation():
    from navlib.methods.feedforward import train_feedforward

    ff, xn, y, _ = _ff_problem(n=200)
    x = 5.0 + 3.0 * xn  # raw units: mapminmax must undo them
    x = np.column_stack([x, np.full(len(x), 2.0)])  # a constant column: removeconstantrows drops it
    net = train_feedforward(x, 100.0 * y, 4, np.random.default_rng(0), activation="logsig")
    assert net.info["n_weights"] == ff.n_weights(3, 4, 2) and net.keep.tolist() == [True] * 3 + [
        False
    ]
    assert net.info["stop"] in ("validation stop", "minimum gradient", "maximum mu")
    rms = float(np.sqrt(np.mean((net.predict(x) - 100.0 * y) ** 2)))
    assert rms < 0.1 * float(np.std(100.0 * y))
    with pytest.raises(InputError, match="activation"):
        train_feedforward(x, y, 4, np.random.default_rng(0), activation="relu")
