"""The projected noise model's Kalman filter (issue 34, :mod:`navlib.workbench.innovations`): whitening,
colouring, ``log det R`` and the REML likelihood equal those of the dense Cholesky factor of the n x n
covariance on small problems (irregular clocks with repeated times and gaps, a negative correlation on a
regular clock, the bound KAPPA_MAX, several observations per time); the compiled kernels equal their
plain-Python selves; the series is time-major; and on 50,000 observations the memory stays far below an
n x n matrix's."""

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from scipy.linalg import solve_triangular

from navlib.workbench import innovations as inn
from navlib.workbench import serial


def _projected(times, axes, seed, drop=0.0, unit=False):
    """A projected series of ``axes`` observations per row at ``times`` (time_s, file order shuffled),
    random directions (unit or not), optionally with observations left out."""
    rng = np.random.default_rng(seed)
    rows = rng.permutation(len(times))
    data = pd.DataFrame({"time_s": np.asarray(times, float)[rows]})
    n_obs = axes * len(data)
    d = rng.standard_normal((n_obs, 3))
    if unit:
        d /= np.linalg.norm(d, axis=1, keepdims=True)
    ser = serial.with_projection(serial.series_of(data, n_obs, "magnetometer"), data, d)
    if drop:
        ser = ser.without(rng.random(n_obs) < drop)
    return ser, n_obs


def _dense_factor(kappa, ser):
    pr = ser.projection
    K = inn.dense_covariance(kappa, pr.clock[ser.order], pr.directions[ser.order])
    return np.linalg.cholesky(K)


rng0 = np.random.default_rng(34)
CASES = {
    # irregular clock: steps of 0.1 s with jitter, repeated times (one observation per row) and gaps
    "irregular, repeated times, gaps": (
        0.8,
        np.cumsum(rng0.choice([0.0, 0.1, 0.13, 0.1, 0.9], 70)),
        1,
        0.0,
    ),
    "irregular, two per row, left out": (0.9, np.cumsum(rng0.choice([0.1, 0.12, 0.5], 50)), 2, 0.1),
    "negative kappa, regular clock": (
        -0.6,
        0.1 * np.cumsum(rng0.choice([1, 1, 1, 2, 5], 60)),
        2,
        0.0,
    ),
    "kappa at the bound": (serial.KAPPA_MAX, 0.1 * np.arange(60), 2, 0.0),
    "negative kappa at the bound": (-serial.KAPPA_MAX, 0.1 * np.arange(50), 1, 0.05),
    "three per row": (0.7, np.cumsum(rng0.choice([0.1, 0.2, 3.0], 40)), 3, 0.0),
    "no correlation": (0.0, 0.1 * np.arange(40), 2, 0.0),
}


@pytest.mark.parametrize("case", list(CASES))
def test_the_filter_equals_the_dense_cholesky_factor(case):
    kappa, times, axes, drop = CASES[case]
    ser, n_obs = _projected(times, axes, seed=len(case), drop=drop)
    L = _dense_factor(kappa, ser)
    x = np.random.default_rng(1).standard_normal((n_obs, 4))
    xo = x[ser.order]
    w = serial.whiten(x, (kappa,), ser)
    ref = solve_triangular(L, xo, lower=True)
    assert np.max(np.abs(w - ref)) <= 1e-9 * max(1.0, np.max(np.abs(ref)))
    assert np.allclose(serial.whiten(x[:, 2], (kappa,), ser), w[:, 2], rtol=0, atol=1e-12)
    g = serial.projected_gains((kappa,), ser)
    assert g.logdet == pytest.approx(2 * np.sum(np.log(np.diag(L))), abs=1e-9)
    u = np.random.default_rng(2).standard_normal((len(ser.order), 3))
    c = serial.colour(u, (kappa,), ser, n_obs)
    assert np.max(np.abs(c[ser.order] - L @ u)) <= 1e-9 * max(1.0, np.max(np.abs(L @ u)))
    assert np.allclose(serial.whiten(c, (kappa,), ser), u, rtol=0, atol=1e-9)


@pytest.mark.parametrize("case", list(CASES))
def test_the_projected_likelihood_equals_the_dense_one(case):
    kappa, times, axes, drop = CASES[case]
    ser, n_obs = _projected(times, axes, seed=len(case) + 1, drop=drop, unit=True)
    rng = np.random.default_rng(3)
    Q = serial.basis_on(rng.standard_normal((n_obs, 3)), ser, n_obs)
    r = rng.standard_normal(n_obs)
    lik = serial._ProjectedLik(r, Q, ser)
    L = _dense_factor(kappa, ser)
    wq = solve_triangular(L, Q[ser.order], lower=True)
    wr = solve_triangular(L, r[ser.order], lower=True)
    b = np.linalg.lstsq(wq, wr, rcond=None)[0]
    rss = float(np.sum((wr - wq @ b) ** 2))
    n, k = len(ser.order), 3
    reml = -0.5 * (
        (n - k) * np.log(rss) + 2 * np.sum(np.log(np.diag(L))) + np.linalg.slogdet(wq.T @ wq)[1]
    )
    assert lik((kappa,)) == pytest.approx(reml, abs=1e-7)


def test_the_compiled_kernels_equal_their_python_reference():
    ser, n_obs = _projected(
        np.cumsum(np.random.default_rng(5).choice([0.0, 0.1, 0.3], 80)), 2, seed=6
    )
    pr = ser.projection
    phi = inn.propagation(0.93, pr.clock[ser.order])
    d = np.ascontiguousarray(pr.directions[ser.order])
    gain, sd = inn._gains(phi, d, 1e-10)
    gain_py, sd_py = inn._gains.py_func(phi, d, 1e-10)
    assert np.allclose(gain, gain_py, rtol=1e-13, atol=0) and np.allclose(
        sd, sd_py, rtol=1e-13, atol=0
    )
    x = np.random.default_rng(7).standard_normal((len(phi), 5))
    for kernel in (inn._whiten, inn._colour):
        assert np.allclose(
            kernel(phi, d, gain, sd, x), kernel.py_func(phi, d, gain, sd, x), rtol=1e-12, atol=1e-13
        )


@pytest.mark.parametrize("case", list(CASES))
def test_the_one_pass_filter_is_the_gains_and_the_whitening(case):
    """The likelihood's one-pass filter (issue 34: no gains kept) gives the numbers of the gains and the
    whitening computed apart, bit for bit, and its Python reference the same to rounding."""
    kappa, times, axes, drop = CASES[case]
    ser, n_obs = _projected(times, axes, seed=len(case) + 2, drop=drop)
    pr = ser.projection
    clock, d = pr.clock[ser.order], np.ascontiguousarray(pr.directions[ser.order])
    x = np.random.default_rng(8).standard_normal((len(clock), 4))
    g = inn.gains(kappa, clock, d)
    w, logdet = inn.whiten_direct(kappa, clock, d, inn.nugget_of(d), x)
    assert np.array_equal(w, inn.whiten_columns(g, x)) and logdet == g.logdet
    steps = inn.clock_steps(clock)
    w_py, sd_py = inn._filter_whiten_steps.py_func(kappa, *steps, d, inn.nugget_of(d), x)
    assert np.allclose(w, w_py, rtol=1e-12, atol=1e-13)
    assert np.allclose(g.sd, sd_py, rtol=1e-13, atol=0)


@pytest.mark.parametrize("case", list(CASES))
def test_the_filter_with_its_propagation_compiled_equals_the_numpy_reference(case):
    """The likelihood's compiled pass with the propagation inside (``whiten_steps``, issue 34) against
    its reference computed apart: ``propagation`` in numpy, the gains, and the Python reference of the
    whitening; the compiled kernel and its own Python self agree too.  A clock out of time order is refused."""
    kappa, times, axes, drop = CASES[case]
    ser, n_obs = _projected(times, axes, seed=len(case) + 5, drop=drop)
    pr = ser.projection
    clock, d = pr.clock[ser.order], np.ascontiguousarray(pr.directions[ser.order])
    x = np.random.default_rng(9).standard_normal((len(clock), 5))
    nugget = inn.nugget_of(d)
    steps = inn.clock_steps(clock)
    w, logdet = inn.whiten_steps(kappa, steps, d, nugget, x)
    g = inn.gains(
        kappa, clock, d, nugget
    )  # the numpy propagation, the gains and the whitening apart
    w_ref, sd_ref = inn._whiten.py_func(g.phi, d, g.gain, g.sd, x), g.sd
    assert np.allclose(w, w_ref, rtol=1e-12, atol=1e-13)
    assert logdet == pytest.approx(2.0 * np.sum(np.log(sd_ref)), rel=1e-13, abs=1e-12)
    w_py, sd_py = inn._filter_whiten_steps.py_func(kappa, *steps, d, nugget, x)
    assert np.allclose(w, w_py, rtol=1e-12, atol=1e-13)
    assert np.allclose(sd_py, sd_ref, rtol=1e-13, atol=0)
    with pytest.raises(ValueError, match="time order"):
        inn.clock_steps(np.array([0.0, 2.0, 1.0]))


def test_a_projected_series_is_time_major():
    """Rows in time order, each row's observations together; segments start where the rows' did; leaving
    observations out keeps the time order; a series out of time order is refused by the filter."""
    t = np.r_[0.1 * np.arange(5), 5.0 + 0.1 * np.arange(4)]
    data = pd.DataFrame({"time_s": t[::-1]})  # file order reversed
    ser = serial.with_projection(serial.series_of(data, 18, "magnetometer"), data, np.ones((18, 3)))
    rows = np.arange(9)[::-1]
    assert np.array_equal(ser.order, (rows[:, None] * 2 + np.arange(2)).ravel())
    assert np.array_equal(ser.pos, np.r_[np.arange(10), np.arange(8)]) and ser.segments == 2
    clock = ser.projection.clock[ser.order]
    assert np.all(np.diff(clock) >= 0)
    less = ser.without(np.isin(np.arange(18), [1, 6]))
    assert np.all(np.diff(ser.projection.clock[less.order]) >= 0)
    bad = serial.Series(ser.order[::-1], ser.pos, ser.source, ser.projection)
    with pytest.raises(ValueError, match="time order"):
        serial.whiten(np.ones(18), (0.5,), bad)


_MEMORY = r"""
import json, resource, sys
import numpy as np, pandas as pd
from navlib.workbench import serial

def run(rows):
    rng = np.random.default_rng(0)
    data = pd.DataFrame({"time_s": 0.1 * np.arange(rows)})
    n_obs = 2 * rows
    d = rng.standard_normal((n_obs, 3))
    ser = serial.with_projection(serial.series_of(data, n_obs, "magnetometer"), data, d)
    X = rng.standard_normal((n_obs, 10))
    e = serial.colour(rng.standard_normal(n_obs), (0.9,), ser, n_obs)
    w = serial.whiten(np.column_stack([X, e]), (0.9,), ser)
    m = serial.estimate(e, X, ser)
    return m

run(200)                                           # compile / load the kernels, import everything
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
m = run(int(sys.argv[1]))
grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
print(json.dumps({"kib": grown, "lag1": m.lag1, "order": m.order}))
"""


@pytest.mark.slow
def test_whitening_and_the_likelihood_of_50000_observations_stay_linear_in_memory():
    """50,000 observations (25,000 rows of two invariants): colouring, whitening 11 columns and the REML
    estimate together grow the process's peak memory by well under 200 MiB, where one n x n float matrix
    is 18.6 GiB (the dense factor's)."""
    out = subprocess.run(
        [sys.executable, "-c", _MEMORY, "25000"], capture_output=True, text=True, check=True
    )
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["kib"] < 200 * 1024, res
    assert res["order"] == 1 and res["lag1"] == pytest.approx(0.9, abs=0.02)


def test_the_likelihoods_cholesky_parts_are_the_eigendecompositions():
    """The RSS after the regressors and their log det from the Cholesky factor of the bordered Gram matrix
    (the projected likelihood's, issue 34) equal the eigendecomposition's; a Gram matrix that is not
    positive definite (the residual inside the regressors' span) falls back to it."""
    rng = np.random.default_rng(9)
    w = rng.standard_normal((400, 8))
    M = w.T @ w
    for k in (0, 1, 7):
        rss, lg = serial._rss_g_cholesky(M[: k + 1, : k + 1], k)
        ref = serial._rss_g(M[: k + 1, : k + 1], k)
        assert rss == pytest.approx(ref[0], rel=1e-12) and lg == pytest.approx(ref[1], rel=1e-12)
    w[:, -1] = w[:, :3] @ np.array([1.0, -2.0, 0.5])  # r in the span: RSS 0, not positive definite
    M = w.T @ w
    rss, lg = serial._rss_g_cholesky(M, 7)
    ref = serial._rss_g(M, 7)
    assert abs(rss) <= 1e-9 * M[-1, -1] and lg == pytest.approx(ref[1], rel=1e-12)
