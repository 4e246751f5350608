"""Issue 34: the vectorised REML likelihood of the AR noise model and its analytic gradient
(navlib.workbench.reml), against the direct likelihood and finite differences."""

import numpy as np
import pandas as pd
import pytest

from navlib.workbench import reml, serial


def _series(seed=4, rows=200, axes=3, drop=0.03):
    """Three axes of ``rows`` samples with gaps (new segments) and a few samples left out."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.choice([0.1, 0.1, 0.1, 0.6], rows))
    n = rows * axes
    return serial.series_of(pd.DataFrame({"time_s": t}), n, "magnetometer").without(
        rng.random(n) < drop
    ), n


def _basis(ser, n, k, seed=5):
    return (
        serial.basis_on(np.random.default_rng(seed).standard_normal((n, k)), ser, n)
        if k
        else np.zeros((n, 0))
    )


KAPPAS = [(0.6,), (0.8, -0.3), (0.2, 0.3, -0.4), (-0.7,), (0.95, 0.5, 0.1)]


@pytest.mark.parametrize("kappa", [(0.5,), (0.5, -0.3), (0.5, -0.3, 0.7), (0.9, 0.8, -0.9, 0.4)])
def test_levinson_derivatives_are_those_of_the_recursion(kappa):
    phi, v, dphi, dv = reml.levinson_derivatives(kappa)
    assert np.array_equal(phi, reml.levinson(kappa)[0]) and np.array_equal(
        v, reml.levinson(kappa)[1]
    )
    h = 1e-6
    for j in range(len(kappa)):
        up, down = (
            reml.levinson(np.add(kappa, h * np.eye(len(kappa))[j])),
            reml.levinson(np.subtract(kappa, h * np.eye(len(kappa))[j])),
        )
        assert np.allclose(dphi[j], (up[0] - down[0]) / (2 * h), atol=1e-8)
        assert np.allclose(dv[j], (up[1] - down[1]) / (2 * h), atol=1e-8)


@pytest.mark.parametrize("k", [0, 1, 7])
@pytest.mark.parametrize("order", [1, 2, 3])
def test_the_vectorised_likelihood_equals_the_direct_one(k, order):
    """Every order up to the parts' (``P``), with and without regressors, on segments of every length."""
    ser, n = _series()
    Q = _basis(ser, n, k)
    r = serial.colour(np.random.default_rng(6).standard_normal(len(ser.order)), (0.7, 0.2), ser, n)
    lik = reml._Restricted(r, Q, ser, order)
    for kappa in [()] + [kp for kp in KAPPAS if len(kp) <= order]:
        direct = serial._restricted_loglik(kappa, r, Q, ser)
        assert lik(kappa) == pytest.approx(direct, rel=1e-10)
        assert lik.value_and_gradient(kappa)[0] == pytest.approx(direct, rel=1e-10)


@pytest.mark.parametrize("k", [0, 7])
@pytest.mark.parametrize("order", [1, 2, 3])
def test_the_gradient_equals_finite_differences_of_the_likelihood(k, order):
    """``value_and_gradient`` against central differences of ``l_R`` in each ``kappa_l``, at orders below
    the parts' too (a bootstrap's parts serve every order up to theirs)."""
    ser, n = _series(seed=8)
    Q = _basis(ser, n, k, seed=9)
    r = serial.colour(
        np.random.default_rng(10).standard_normal(len(ser.order)), (0.6, 0.3), ser, n
    ) + Q @ np.ones(k)
    lik = reml._Restricted(r, Q, ser, 3)
    h = 1e-6
    for kappa in [kp for kp in KAPPAS if len(kp) == order]:
        _, grad = lik.value_and_gradient(kappa)
        fd = [
            (lik(np.add(kappa, h * e)) - lik(np.subtract(kappa, h * e))) / (2 * h)
            for e in np.eye(order)
        ]
        assert np.allclose(grad, fd, rtol=1e-5, atol=1e-4 * max(1.0, np.max(np.abs(fd)))), (
            kappa,
            grad,
            fd,
        )


def test_the_optimisers_objective_is_in_atanh_kappa():
    """What L-BFGS-B minimises: ``-l_R(tanh a)`` and its gradient in ``a``."""
    ser, n = _series(seed=11)
    Q = _basis(ser, n, 5, seed=12)
    r = serial.colour(
        np.random.default_rng(13).standard_normal(len(ser.order)), (0.8, -0.2, 0.1), ser, n
    )
    fun, jac = serial._objective(reml._Restricted(r, Q, ser, 3))
    assert jac is True
    a = np.arctanh([0.7, -0.1, 0.2])
    value, grad = fun(a)
    h = 1e-6
    fd = [(fun(a + h * e)[0] - fun(a - h * e)[0]) / (2 * h) for e in np.eye(3)]
    assert value == pytest.approx(-serial._restricted_loglik(np.tanh(a), r, Q, ser), rel=1e-10)
    assert np.allclose(grad, fd, rtol=1e-5, atol=1e-4)


def test_the_estimate_with_the_analytic_gradient_is_the_maximum():
    """The fixed-order estimate from a start (a bootstrap replicate) lands where the likelihood is highest:
    no direction of ``kappa`` raises it by more than the optimiser's tolerance."""
    ser, n = _series(seed=14, rows=400)
    X = np.random.default_rng(15).standard_normal((n, 4))
    r = serial.colour(
        np.random.default_rng(16).standard_normal(len(ser.order)), (0.6, 0.3, 0.2), ser, n
    )
    nm = serial.estimate(r, X, ser, order=3, interval=False, start_at=(0.5, 0.2, 0.1))
    lik = reml._Restricted(r, serial.basis_on(X, ser, n), ser, 3)
    best = lik(nm.kappa)
    for e in np.r_[np.eye(3), -np.eye(3)]:
        assert lik(np.add(nm.kappa, 1e-3 * e)) <= best + 1e-6


@pytest.mark.parametrize("kappa", [(), (0.7,), (0.8, -0.3), (0.5, 0.2, 0.4)])
def test_whiten_transpose_is_the_adjoint_of_whitening(kappa):
    """``whiten_transpose`` is ``W'`` (the matrix of ``whiten`` in series order, columns of the identity), so
    ``W' W`` is the inverse AR correlation."""
    ser, n = _series(seed=17, rows=40)
    N = len(ser.order)
    W = serial.whiten(np.eye(N), kappa, ser, ordered=True)
    y = np.random.default_rng(18).standard_normal((N, 2))
    assert np.allclose(serial.whiten_transpose(y, kappa, ser), W.T @ y)
    assert np.allclose(serial.whiten_transpose(y[:, 0], kappa, ser), W.T @ y[:, 0])
