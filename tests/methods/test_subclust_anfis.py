"""Subtractive clustering (MATLAB subclust) on hand-traced cases, genfis2, Sugeno inference against simpful,
and ANFIS's gradient and step-size rule."""

import math

import numpy as np
import pytest

from navlib.errors import InputError
from navlib.methods.anfis import AnfisOptions, anfis, premise_gradient, update_step
from navlib.methods.subclust import SubclustOptions, SugenoFIS, genfis2, subclust
from peers import simpful_system


def test_two_points_both_accepted_then_exhausted():
    # normalised 0 and 1, r = 0.5: equal potentials 1 + e^-16, the first wins; after the reduction the
    # other keeps (1 + e^-16)(1 - e^-10.24), ratio ~1 > 0.5: accepted; then every potential is 0.
    C, sig, trace = subclust(np.array([[0.0], [1.0]]), 0.5, return_trace=True)
    assert trace == ["accept", "accept", "exhausted"]
    np.testing.assert_allclose(C[:, 0], [0.0, 1.0])
    np.testing.assert_allclose(sig, [0.5 / math.sqrt(8)])


def test_grey_zone_accepted_by_distance():
    # 4 points at 0 and one at 1 (r = 0.5): after the first centre the far point keeps potential
    # 1 + 4e^-16 - (4 + e^-16) e^-10.24 ~ 0.9999, ratio ~ 0.25 (grey); d_min = 1/0.5 = 2, 0.25 + 2 >= 1.
    X = np.array([[0.0]] * 4 + [[1.0]])
    C, _, trace = subclust(X, 0.5, return_trace=True)
    assert trace == ["accept", "grey-accept", "exhausted"]
    np.testing.assert_allclose(C[:, 0], [0.0, 1.0])


def test_grey_zone_rejected_then_exhausted():
    # bounds [0, 1]; 4 points at 0, 2 at 0.3, r = 0.5: P(0) = 4 + 2e^-1.44 = 4.4738, P(0.3) = 2 + 4e^-1.44
    # = 2.9477; after the centre at 0: P(0.3) = 2.9477 - 4.4738 e^-0.9216 = 1.1677, ratio 0.261 (grey),
    # d_min = 0.6: 0.861 < 1, rejected (potential set to 0), twice; then all potentials are 0.
    X = np.array([[0.0]] * 4 + [[0.3]] * 2)
    C, _, trace = subclust(X, 0.5, bounds=[[0.0], [1.0]], return_trace=True)
    p0 = 4 + 2 * math.exp(-1.44)
    p3 = 2 + 4 * math.exp(-1.44) - p0 * math.exp(-4 * (0.3 / 0.625) ** 2)
    assert 0.15 < p3 / p0 < 0.5 and p3 / p0 + 0.6 < 1  # the hand trace itself
    assert trace == ["accept", "grey-reject", "grey-reject", "exhausted"]
    np.testing.assert_allclose(C[:, 0], [0.0])


def test_low_ratio_stops():
    # 4 points at 0 and one at 0.3 (bounds [0, 1]): ratio 0.062 <= 0.15: stop.
    X = np.array([[0.0]] * 4 + [[0.3]])
    C, _, trace = subclust(X, 0.5, bounds=[[0.0], [1.0]], return_trace=True)
    assert trace == ["accept", "stop"]
    assert C.shape == (1, 1)


def test_radius_per_dimension_and_data_units():
    X = np.array([[10.0, 100.0], [20.0, 300.0]])
    C, sig = subclust(X, [0.5, 0.25])
    np.testing.assert_allclose(sig, [0.5 * 10 / math.sqrt(8), 0.25 * 200 / math.sqrt(8)])
    np.testing.assert_allclose(np.sort(C[:, 0]), [10.0, 20.0])


@pytest.mark.parametrize(
    "kwargs, word",
    [(dict(radii=0.0), "radii"), (dict(radii=[0.5, 0.5, 0.5]), "radii"), (dict(radii=-1), "radii")],
)
def test_subclust_bad_radii(kwargs, word):
    with pytest.raises(InputError, match=word):
        subclust(np.random.default_rng(0).random((5, 2)), **kwargs)


def test_subclust_bad_data():
    with pytest.raises(InputError, match="no spread"):
        subclust(np.ones((4, 1)), 0.5)
    with pytest.raises(InputError, match="NaN"):
        subclust(np.array([[0.0], [np.nan]]), 0.5)
    with pytest.raises(InputError, match="reject"):
        SubclustOptions(accept=0.1, reject=0.2)


def _simpful(fis: SugenoFIS, X):
    fs, names = simpful_system(fis)
    out = []
    for x in X:
        for nm, v in zip(names, x):
            fs.set_variable(nm, float(v))
        out.append(fs.Sugeno_inference(["y"])["y"])
    return np.array(out)


def test_genfis2_inference_equals_simpful():
    rng = np.random.default_rng(3)
    X = rng.uniform(-1, 1, (60, 2))
    y = np.sin(2 * X[:, 0]) + X[:, 1] ** 2
    fis = genfis2(X, y, 0.4)
    assert fis.n_rules >= 3
    Xq = rng.uniform(-1, 1, (25, 2))
    np.testing.assert_allclose(fis(Xq), _simpful(fis, Xq), rtol=0, atol=1e-12)


def test_genfis2_consequents_are_the_least_squares_solution():
    rng = np.random.default_rng(4)
    X = rng.uniform(0, 1, (40, 2))
    y = 3 * X[:, 0] - 2 * X[:, 1] + 0.5  # linear: any rule base reproduces it exactly
    fis = genfis2(X, y, 0.6)
    np.testing.assert_allclose(fis(X), y, atol=1e-9)


def test_premise_gradient_matches_finite_differences():
    rng = np.random.default_rng(5)
    X = rng.uniform(0, 1, (30, 2))
    t = np.cos(3 * X[:, 0]) * X[:, 1]
    fis = genfis2(X, t, 0.5)
    gc, gs = premise_gradient(fis, X, t)

    def sse(c, s):
        return float(np.sum((SugenoFIS(c, s, fis.consequents)(X) - t) ** 2))

    h = 1e-6
    for r, i in [(0, 0), (fis.n_rules - 1, 1)]:
        dc = np.zeros_like(fis.centers)
        dc[r, i] = h
        num_c = (sse(fis.centers + dc, fis.sigmas) - sse(fis.centers - dc, fis.sigmas)) / (2 * h)
        num_s = (sse(fis.centers, fis.sigmas + dc) - sse(fis.centers, fis.sigmas - dc)) / (2 * h)
        assert gc[r, i] == pytest.approx(num_c, rel=1e-5, abs=1e-9)
        assert gs[r, i] == pytest.approx(num_s, rel=1e-5, abs=1e-9)


@pytest.mark.parametrize(
    "errors, factor",
    [
        ([5, 4, 3, 2, 1], 1.1),  # four consecutive decreases
        ([9, 5, 4, 3, 2, 1], 1.1),  # the window slides
        ([1, 2, 1, 2, 1], 0.9),  # up-down-up-down: two oscillations
        ([5, 4, 3, 2, 2.5], 1.0),  # neither
        ([2, 1, 2, 1, 0.5], 1.0),  # down-up-down-down: neither
        ([4, 3, 2, 1], 1.0),  # too short
    ],
)
def test_step_size_rule(errors, factor):
    assert update_step(errors, 0.01) == pytest.approx(0.01 * factor)


def test_anfis_applies_the_rule_and_returns_the_best_checking_epoch():
    rng = np.random.default_rng(6)
    X = rng.uniform(0, 1, (80, 2))
    t = np.sin(4 * X[:, 0]) + X[:, 1]
    Xc = rng.uniform(0, 1, (30, 2))
    tc = np.sin(4 * Xc[:, 0]) + Xc[:, 1]
    res = anfis(X, t, genfis2(X, t, 0.5), AnfisOptions(epochs=25), check=(Xc, tc))
    ss = 0.01
    for k in range(len(res.train_rmse)):
        assert res.step_sizes[k] == pytest.approx(ss)
        ss = update_step(res.train_rmse[: k + 1], ss)
    assert res.best_epoch == int(np.argmin(res.check_rmse))
    best = np.sqrt(np.mean((res.fis(Xc) - tc) ** 2))
    assert best == pytest.approx(res.check_rmse.min(), rel=1e-9)
    assert res.train_rmse[-1] < res.train_rmse[0]


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(epochs=0), "epochs"),
        (dict(epochs=2.5), "epochs"),
        (dict(initial_step=0), "initial_step"),
        (dict(step_decrease=1.5), "step_decrease"),
    ],
)
def test_anfis_bad_options(kw, word):
    with pytest.raises(InputError, match=word):
        AnfisOptions(**kw)
