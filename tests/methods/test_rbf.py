"""navlib.methods.rbf: MATLAB newrb / newrbe semantics."""

import math

import numpy as np
import pytest

from navlib.errors import InputError
from navlib.methods.rbf import InputScaler, newrb, newrbe, radbas, width_from_spread


def test_spread_to_width_relation():
    for spread in (0.1, 1.0, 2.0, 7.5):
        b = width_from_spread(spread)
        assert b == pytest.approx(math.sqrt(math.log(2.0)) / spread, rel=1e-14)
        assert b * spread == pytest.approx(0.8325546111576977, rel=1e-14)
    # a trained neuron outputs exactly 0.5 at distance SPREAD from its centre
    net = newrbe([0.0, 100.0], [1.0, 0.0], spread=3.0)
    h = net.hidden(np.array([3.0, -3.0, 0.0]))
    assert h[:, 0] == pytest.approx([0.5, 0.5, 1.0], abs=1e-12)


def test_newrb_reproduces_known_target_exactly_with_enough_neurons():
    x = np.linspace(-2, 2, 9)
    t = np.sin(1.3 * x) + 0.2 * x**2
    net = newrb(x, t, goal=0.0, spread=1.0)  # goal 0 is never met strictly: all 9 neurons
    assert net.n_neurons == 9
    assert np.max(np.abs(net.predict(x) - t)) < 1e-9
    assert net.perf_mse[-1] < 1e-18
    # training error never increases as neurons are added (nested least squares)
    assert np.all(np.diff(net.perf_mse) <= 1e-15)
    exact = newrbe(x, t, spread=1.0)
    assert np.max(np.abs(exact.predict(x) - t)) < 1e-9


def test_neuron_order_isolated_neurons_follow_target_energy():
    # centres 5 apart with SPREAD 1: P is the identity to 3e-8, so score_j = t_j^2 / sum t^2 = 0.9, 0.1, 0
    x, t = np.array([0.0, 5.0, 10.0]), np.array([0.0, 1.0, 3.0])
    net = newrb(x, t, goal=0.0, spread=1.0)
    assert net.center_index.tolist() == [2, 1, 0]
    # one neuron on x=10 plus bias: bias = mean(0, 1) = 0.5, MSE = (0.25 + 0.25) / 3
    assert net.perf_mse[1] == pytest.approx(1 / 6, rel=1e-6)
    assert net.perf_mse[0] == pytest.approx(np.var(t), rel=1e-12)


def test_neuron_order_overlapping_gram_schmidt_by_hand():
    # x = 0, 1, 2 with SPREAD 1: neighbours 0.5, next 0.0625.  t = (1, 0, 0).
    # first scores: p0 1/1.2539 = 0.797, p1 0.25/1.5 = 0.167, p2 0.0039/1.2539 -> pick 0
    # after Gram-Schmidt on p0: p1' = (-0.3224, 0.5888, 0.4486) score 0.1595,
    #                           p2' = (-0.2366, 0.3505, 0.9813) score 0.0490 -> pick 1, then 2
    net = newrb([0.0, 1.0, 2.0], [1.0, 0.0, 0.0], goal=0.0, spread=1.0)
    assert net.center_index.tolist() == [0, 1, 2]
    # reversing the target reverses the order
    net = newrb([0.0, 1.0, 2.0], [0.0, 0.0, 1.0], goal=0.0, spread=1.0)
    assert net.center_index.tolist() == [2, 1, 0]


def test_goal_not_checked_after_first_neuron_and_strict():
    x, t = np.array([0.0, 5.0, 10.0]), np.array([0.0, 1.0, 3.0])
    # after one neuron the MSE is 1/6 < 0.2, but MATLAB only tests from the second neuron on
    assert newrb(x, t, goal=0.2, spread=1.0).n_neurons == 2
    # strict inequality: an exact fit with goal 0 keeps going to the maximum
    net = newrb(x, t, goal=0.0, spread=1.0)
    assert net.n_neurons == 3 and net.stop_reason == "max_neurons reached"
    assert newrb(x, t, goal=1e-6, spread=1.0, max_neurons=2).stop_reason == "goal met"


def test_sse_goal_is_stricter_than_mse_for_the_same_number():
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0, 10, 30))
    t = np.sin(x) + 0.05 * rng.standard_normal(30)
    m = newrb(x, t, goal=0.05, spread=1.5, goal_kind="mse")
    s = newrb(x, t, goal=0.05, spread=1.5, goal_kind="sse")
    assert s.n_neurons > m.n_neurons
    assert m.perf_mse[-1] < 0.05 and s.perf_sse[-1] < 0.05 and s.stop_reason == "goal met"
    np.testing.assert_allclose(s.perf_sse, s.perf_mse * 30, rtol=1e-12)


def test_explicit_scaler_equals_prescaled_inputs():
    x = np.array([-0.025, -0.01, 0.0, 0.004, 0.013, 0.025])
    t = 0.13 * x + 0.002 * np.sin(200 * x)
    a = newrb(x, t, goal=1e-12, spread=2.0, scaler=InputScaler.affine(0.0, 1 / 60.0))
    b = newrb(x * 60.0, t, goal=1e-12, spread=2.0)
    assert a.center_index.tolist() == b.center_index.tolist()
    xt = np.array([-0.02, 0.011])
    np.testing.assert_allclose(a.predict(xt), b.predict(xt * 60.0), rtol=1e-8, atol=1e-14)
    z = InputScaler.standardize(np.c_[x, 10 * x + 3])
    np.testing.assert_allclose(z.transform(np.c_[x, 10 * x + 3]).std(axis=0), [1, 1])


def test_duplicated_inputs_do_not_crash_or_nan():
    x = np.array([0.0, 0.0, 1.0, 2.0, 2.0, 2.0])
    t = np.array([1.0, 1.2, 0.0, 3.0, 3.1, 2.9])
    net = newrb(x, t, goal=0.0, spread=1.0)
    assert net.n_neurons == 3 and net.stop_reason == "no independent candidate"
    assert sorted(set(x[net.center_index])) == [0.0, 1.0, 2.0]
    y = net.predict(np.linspace(-1, 3, 21))
    assert np.all(np.isfinite(y))
    # best possible fit: the mean of each duplicated group
    np.testing.assert_allclose(net.predict([0.0, 1.0, 2.0]), [1.1, 0.0, 3.0], atol=1e-9)
    e = newrbe(x, t, spread=1.0)
    assert np.all(np.isfinite(e.predict(np.linspace(-1, 3, 21))))
    # all inputs identical
    same = newrb(np.ones(4), [1.0, 2.0, 3.0, 4.0], goal=0.0, spread=1.0)
    assert same.n_neurons == 1 and np.all(np.isfinite(same.predict([1.0, 5.0])))


def test_multi_input_and_multi_output():
    rng = np.random.default_rng(0)
    x = rng.uniform(-1, 1, (20, 2))
    t = np.c_[x[:, 0] * x[:, 1], np.cos(x[:, 0])]
    net = newrb(x, t, goal=0.0, spread=0.8)
    assert net.predict(x).shape == (20, 2)
    assert np.max(np.abs(net.predict(x) - t)) < 1e-6


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(spread=0.0), "SPREAD"),
        (dict(spread=-1.0), "SPREAD"),
        (dict(spread=float("nan")), "SPREAD"),
        (dict(goal=-1e-9), "goal"),
        (dict(goal_kind="rms"), "goal_kind"),
        (dict(max_neurons=0), "max_neurons"),
    ],
)
def test_bad_parameters(kwargs, fragment):
    with pytest.raises(InputError, match=fragment):
        newrb([0.0, 1.0, 2.0], [0.0, 1.0, 0.0], **kwargs)


def test_bad_shapes():
    with pytest.raises(InputError, match="2 training row.*3 inputs"):
        newrb(np.zeros((2, 3)), np.zeros(2), spread=1.0)
    with pytest.raises(InputError, match="2 training row.*3 inputs"):
        newrbe(np.zeros((2, 3)), np.zeros(2), spread=1.0)
    with pytest.raises(InputError, match="one target row per input row"):
        newrb([0.0, 1.0, 2.0], [0.0, 1.0], spread=1.0)
    with pytest.raises(InputError, match="row 2, column 1"):
        newrb([0.0, np.nan, 2.0], [0.0, 1.0, 2.0], spread=1.0)
    with pytest.raises(InputError, match="SPREAD"):
        newrbe([0.0, 1.0], [0.0, 1.0], spread=0)


def test_radbas():
    assert radbas(np.array([0.0, 1.0]))[1] == pytest.approx(math.exp(-1))


def test_gaussian_width_conversion_matches_matlab_radbas():
    from navlib.methods.rbf import LN2_SQRT, radbas, spread_from_gaussian_width, width_from_spread

    delta = 2.0
    sp = spread_from_gaussian_width(delta)
    assert sp == pytest.approx(0.8326 * delta, rel=1e-4)
    b = width_from_spread(sp)  # newrb's bias 0.8326 / SPREAD
    assert b == pytest.approx(1.0 / delta)
    u = np.linspace(-5, 5, 11)
    assert np.allclose(radbas(b * u), np.exp(-(u**2) / delta**2))
    assert radbas(np.array(1.0)) == pytest.approx(math.exp(-1.0))  # radbas(n) = exp(-n^2)
    assert radbas(LN2_SQRT / 3.0 * np.array(3.0)) == pytest.approx(
        0.5
    )  # MATLAB: 0.5 at distance SPREAD
    with pytest.raises(InputError, match="delta"):
        spread_from_gaussian_width(0.0)
