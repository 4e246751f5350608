"""The calibration's faster paths (issue 34) against their references: the compiled neighbour median
against numpy's median, and the profile interval that does not evaluate a bound beyond a point the
estimate evaluated."""

import numpy as np
import pytest
import pandas as pd
from scipy.optimize import minimize_scalar

from navlib.workbench import serial
from navlib.workbench.screen import _neighbour_median, _neighbour_median_numpy


def test_the_compiled_neighbour_median_is_numpys_median():
    rng = np.random.default_rng(2)
    for t in range(300):
        m = int(rng.integers(1, 50))
        x = rng.normal(size=m) * 10.0 ** rng.uniform(-3, 3)
        if t % 3 == 0:
            x[rng.random(m) < 0.2] = np.nan
        seg = np.cumsum(rng.random(m) < 0.2)
        for width in (1, 2, 3):
            got = _neighbour_median(x, seg, width)
            assert np.array_equal(got, _neighbour_median_numpy(x, seg, width), equal_nan=True)


def _projected_ar1(kappa, rows=1500, seed=3):
    """Residuals of two observations per row, the projections of a 3-axis AR(1) noise of lag-1
    correlation ``kappa`` along turning unit directions, on a regular clock."""
    rng = np.random.default_rng(seed)
    t = 0.1 * np.arange(rows)
    noise = np.zeros((rows, 3))
    e = rng.normal(size=(rows, 3))
    noise[0] = e[0]
    for i in range(1, rows):
        noise[i] = kappa * noise[i - 1] + np.sqrt(1 - kappa**2) * e[i]
    ang = np.cumsum(rng.normal(0.05, 0.02, size=(rows, 2)), axis=0)
    d = np.stack(
        [
            np.column_stack([np.cos(ang[:, j]), np.sin(ang[:, j]), 0.3 * np.ones(rows)])
            for j in (0, 1)
        ],
        axis=1,
    ).reshape(2 * rows, 3)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    x = np.einsum("ij,ij->i", d, np.repeat(noise, 2, axis=0))
    data = pd.DataFrame({"time_s": t})
    ser = serial.with_projection(serial.series_of(data, 2 * rows, "magnetometer"), data, d)
    return x, ser


class _Counting:
    """A likelihood that counts where it is evaluated (and keeps ``values`` as the real ones do)."""

    def __init__(self, lik, keep=True):
        self.lik, self.calls, self.keep = lik, [], keep
        self.values = {}

    def __call__(self, kappa):
        self.calls.append(float(kappa[0]))
        v = self.lik(kappa)
        if self.keep:
            self.values[tuple(float(k) for k in kappa)] = v
        return v


def test_the_interval_does_not_evaluate_a_bound_beyond_an_evaluated_point():
    x, ser = _projected_ar1(0.6, rows=400)
    counted = _Counting(serial._ProjectedLik(x, np.zeros((len(x), 0)), ser))
    lim = np.arctanh(serial.KAPPA_MAX)
    sol = minimize_scalar(
        lambda a: -counted((np.tanh(a),)), bounds=(-lim, lim), method="bounded"
    )  # from the whole range: points beyond the drop on both sides
    kappa, ll = (float(np.tanh(sol.x)),), -float(sol.fun)
    counted.calls.clear()
    ends = serial._interval(counted, kappa, ll, -lim)
    assert not any(abs(c) >= serial.KAPPA_MAX - 1e-12 for c in counted.calls)
    # the same ends as from the estimate and the bounds alone (no evaluated points known)
    blind = _Counting(serial._ProjectedLik(x, np.zeros((len(x), 0)), ser), keep=False)
    ref = serial._interval(blind, kappa, ll, -lim)
    assert any(abs(c) >= serial.KAPPA_MAX - 1e-12 for c in blind.calls)
    np.testing.assert_allclose(np.arctanh(ends), np.arctanh(ref), atol=3 * serial.INTERVAL_XTOL)
    assert ends[0] < kappa[0] < ends[1]


def test_the_orientation_cells_are_the_distinct_cell_ids():
    """_cells counts the distinct 30-deg cells by a bincount where the ids are small non-negative
    integers (unit vectors), by np.unique otherwise: the same count as np.unique always."""
    from navlib.workbench.magnetometer_free import _cells

    rng = np.random.default_rng(4)
    for t in range(200):
        u = rng.normal(size=(int(rng.integers(1, 300)), 3))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        if t % 4 == 0:
            u *= 3.0  # not unit: ids outside 0..124, some negative
        ids = (np.round(u * 2).astype(np.int64) + 2) @ np.array([25, 5, 1])
        assert _cells(u) == np.unique(ids).size


def test_least_squares_by_the_normal_equations_is_lstsq():
    """Well-conditioned columns of very different scales: the Cholesky route's coefficients are lstsq's
    to 1e-9; a dependent column: lstsq's minimum-norm solution itself."""
    from navlib.workbench.linalg import least_squares_coef

    rng = np.random.default_rng(5)
    X = rng.normal(size=(1500, 20)) * 10.0 ** rng.uniform(-3, 3, 20)
    y = rng.normal(size=1500)
    ref = np.linalg.lstsq(X, y, rcond=1e-10)[0]
    np.testing.assert_allclose(least_squares_coef(X, y), ref, rtol=1e-9)
    X[:, 7] = 2.0 * X[:, 3] - X[:, 1]
    assert np.array_equal(least_squares_coef(X, y), np.linalg.lstsq(X, y, rcond=1e-10)[0])


def _lfilter_colour(u, kappa, starts):
    """The AR colouring as it was written with ``scipy.signal.lfilter``: start-up by the Durbin-Levinson
    coefficients of each order, then the order-p recursion with the start-up as the filter's state."""
    from scipy.signal import lfilter

    phi, v = serial.levinson(kappa)
    p = len(kappa)
    x = np.empty_like(u)
    a = np.r_[1.0, -phi[p, 1 : p + 1]]
    for a0, b0 in zip(starts[:-1], starts[1:]):
        for t in range(min(p, b0 - a0)):
            x[a0 + t] = np.sqrt(v[t]) * u[a0 + t]
            for j in range(1, t + 1):
                x[a0 + t] += phi[t, j] * x[a0 + t - j]
        if b0 - a0 > p:
            past = x[a0 : a0 + p][::-1]
            zi = np.array([-np.tensordot(a[k + 1 :], past[: p - k], axes=(0, 0)) for k in range(p)])
            x[a0 + p : b0], _ = lfilter([1.0], a, np.sqrt(v[p]) * u[a0 + p : b0], axis=0, zi=zi)
    return x


def test_the_compiled_ar_colouring_is_the_lfilter_recursion():
    rng = np.random.default_rng(5)
    for kappa in [(0.6,), (0.9, -0.3, 0.2), (-0.5, 0.4)]:
        u = rng.standard_normal((700, 4))
        starts = np.array([0, 1, 3, 250, 600, 700], dtype=np.int64)  # segments shorter than p too
        phi, v = serial.levinson(kappa)
        got = serial.ar_colour(u, phi, v, starts)
        assert np.allclose(got, _lfilter_colour(u, kappa, starts), rtol=1e-12, atol=1e-12)
        assert np.array_equal(got, serial.ar_colour.py_func(u, phi, v, starts))
    # a wrong coefficient shows: the check can fail
    bad = serial.ar_colour(u, phi * 1.001, v, starts)
    assert not np.allclose(bad, _lfilter_colour(u, kappa, starts), rtol=1e-9)


def test_noise_band_quantile_is_scipy_stats_chi2():
    from scipy.stats import chi2

    from navlib.workbench.loop import _chi2_ppf

    for q in (0.025, 0.5, 0.975):
        for dof in (1, 7, 1997, 250_000):
            assert _chi2_ppf(q, dof) == chi2.ppf(q, dof)


def test_the_grids_order_1_weights_are_the_prepared_weights():
    from navlib.workbench import noise_grid
    from navlib.workbench.reml import _Prepared

    rng = np.random.default_rng(8)
    t = np.cumsum(rng.choice([0.1, 0.1, 0.7], 300))
    ser = serial.series_of(pd.DataFrame({"time_s": t}), 300, "compass")
    pre = _Prepared(rng.standard_normal((300, 3)), ser, 1)
    w, ws, logdet = noise_grid._ar1_weights(pre, noise_grid.AR1_GRID)
    for g in (0, 17, 120, 240):
        w1, ws1, ld1 = pre.weights((noise_grid.AR1_GRID[g],))
        assert np.array_equal(w[g], w1) and np.array_equal(ws[g], ws1)
        assert logdet[g] == ld1


def test_the_compiled_restricted_likelihood_is_the_numpy_one():
    """``_Restricted``'s compiled parts against its numpy reference: value, gradient and parts, for
    regressor counts 0..40, AR orders up to the cache's, and a singular Gram matrix (eigenvalue path)."""
    from navlib.workbench.reml import _Restricted

    rng = np.random.default_rng(4)
    t = np.cumsum(rng.choice([0.1, 0.1, 0.1, 0.6], 400))
    ser = serial.series_of(pd.DataFrame({"time_s": t}), 800, "magnetometer").without(
        rng.random(800) < 0.03
    )
    e = serial.colour(rng.standard_normal(len(ser.order)), (0.7, 0.2), ser, 800)
    X1 = rng.standard_normal((800, 3))
    cases = [np.zeros((800, 0))] + [
        serial.basis_on(rng.standard_normal((800, k)), ser, 800) for k in (1, 4, 40)
    ]
    for Q in cases:
        for P in (1, 3):
            R = _Restricted(e, Q, ser, P)
            for p in range(P + 1):
                kap = np.tanh(rng.normal(size=p))
                v1, g1 = R.value_and_gradient(kap)
                v0, g0 = R._value_and_gradient_numpy(kap)
                assert v1 == pytest.approx(v0, rel=1e-10)
                assert np.allclose(g1, g0, rtol=1e-8, atol=1e-8 * abs(v0))
                assert np.allclose(R._parts(kap), R._parts_numpy(kap), rtol=1e-10)
    # two equal columns: G singular, the eigenvalue path (round-off decides the numbers: finite only)
    R = _Restricted(e, np.column_stack([X1, X1[:, :1]]), ser, 2)
    v1, g1 = R.value_and_gradient(np.array([0.5, 0.1]))
    assert np.isfinite(v1) and np.all(np.isfinite(g1))
