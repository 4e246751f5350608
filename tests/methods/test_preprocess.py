"""Tests for navlib.methods.preprocess (patent B data preparation) and navlib.methods.scaling (min-max normalisation)."""

from __future__ import annotations

import numpy as np
import pytest

from navlib.errors import InputError
from navlib.methods.preprocess import (
    dot_product_screen,
    field_gravity_dot,
    median_filter,
    reject_dot_product_outliers,
    train_test_split,
)
from navlib.methods.scaling import MinMax


def sweep_readings(n: int = 121, seed: int = 0):
    """A level turntable sweep 0..360 deg: field (uT) and gravity (m/s^2) in the sensor frame, with hard
    and soft iron (which makes m . g vary with heading) and sensor noise."""
    rng = np.random.default_rng(seed)
    h = np.deg2rad(np.linspace(0.0, 360.0, n))
    dip = np.deg2rad(60.0)
    f = 50.0 * np.array([np.cos(dip), 0.0, np.sin(dip)])  # NED field, uT
    rot = np.zeros((n, 3, 3))  # sensor <- NED, yaw only
    rot[:, 0, 0], rot[:, 0, 1] = np.cos(h), np.sin(h)
    rot[:, 1, 0], rot[:, 1, 1] = -np.sin(h), np.cos(h)
    rot[:, 2, 2] = 1.0
    soft = np.array([[1.05, 0.03, 0.01], [0.02, 0.97, -0.02], [0.04, -0.05, 1.0]])
    mag = (rot @ f) @ soft.T + np.array([3.0, -2.0, 1.5]) + rng.normal(0, 0.1, (n, 3))
    grav = np.tile([0.0, 0.0, 9.81], (n, 1)) + rng.normal(0, 0.01, (n, 3))
    return mag, grav


def test_glitch_filter_rejects_injected_glitches_and_keeps_clean_readings():
    mag, grav = sweep_readings()
    clean = reject_dot_product_outliers(mag, grav)
    assert clean.all()  # the soft-iron variation is not "abnormal"
    mag[37, 2] += 15.0  # magnetometer spike
    grav[80] = [4.0, 0.0, 8.96]  # accelerometer shock (same |g|, tilted)
    mag[100] *= 0.6  # field magnitude dropout
    keep = reject_dot_product_outliers(mag, grav)
    assert np.flatnonzero(~keep).tolist() == [37, 80, 100]
    keep_cos = reject_dot_product_outliers(mag, grav, normalize=True)
    # the angle statistic ignores a pure magnitude change and barely sees a spike along the field's
    # main (vertical) component; it catches the tilt.  The patent's raw inner product catches all three.
    assert np.flatnonzero(~keep_cos).tolist() == [80]


def test_dot_product_screen_details():
    mag, grav = sweep_readings(seed=1)
    mag[5] = np.nan
    scr = dot_product_screen(mag, grav, threshold=4.0)
    assert not scr.keep[5] and scr.n_rejected == 1
    s = field_gravity_dot(mag, grav)
    assert np.isnan(s[5])
    np.testing.assert_allclose(s[0], mag[0] @ grav[0])
    lo, hi = scr.band
    assert lo < np.nanmin(s) and np.nanmax(s) < hi
    # the centre is the median, not the mean: one huge glitch does not move it
    mag[9, 2] += 1e6
    assert dot_product_screen(mag, grav).center == pytest.approx(scr.center, rel=1e-3)
    assert not dot_product_screen(mag, grav).keep[9]
    # the cosine statistic is (close to) sin(dip) for level readings
    cosang = field_gravity_dot(mag, grav, normalize=True)
    assert np.nanmedian(cosang) == pytest.approx(np.sin(np.deg2rad(60.0)), abs=0.03)


def test_dot_product_zero_mad_uses_min_scale():
    mag = np.tile([20.0, 0.0, 40.0], (10, 1))
    grav = np.tile([0.0, 0.0, 9.8], (10, 1))
    mag[4, 2] += 1e-3
    assert np.flatnonzero(~reject_dot_product_outliers(mag, grav)).tolist() == [4]
    assert reject_dot_product_outliers(mag, grav, min_scale=0.01).all()


def test_median_filter_removes_spike_and_keeps_ramp():
    ramp = np.linspace(0.0, 360.0, 121)
    np.testing.assert_array_equal(median_filter(ramp, 5), ramp)
    spiky = ramp.copy()
    spiky[50] += 30.0
    out = median_filter(spiky, 3)
    assert out[50] == pytest.approx(ramp[50], abs=3.0)
    np.testing.assert_array_equal(np.delete(out, [49, 50, 51]), np.delete(ramp, [49, 50, 51]))
    np.testing.assert_array_equal(median_filter(spiky, 1), spiky)


def test_median_filter_columns_and_edges():
    mag, _ = sweep_readings()
    out = median_filter(mag, 5)
    assert out.shape == mag.shape
    for j in range(3):
        np.testing.assert_array_equal(out[:, j], median_filter(mag[:, j], 5))
    # nearest: sample 0 sees [v0, v0, v0, v1, v2]
    v = np.array([10.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    assert median_filter(v, 5)[0] == 10.0
    assert median_filter(v, 5, mode="wrap")[0] == 5.0  # sees [5, 6, 10, 1, 2]


def test_median_filter_closed_sweep():
    # a full revolution sampled at both 0 and 360 deg: the ring has period n - 1
    h = np.linspace(0.0, 2 * np.pi, 121)
    v = np.cos(h)
    v[0] += 5.0  # glitch on the 0 deg reading
    out = median_filter(v, 5, mode="closed")
    ring = np.cos(h[:-1])
    ring[0] += 5.0
    ref = median_filter(ring, 5, mode="wrap")
    np.testing.assert_allclose(out[:-1], ref, atol=1e-15)
    assert abs(out[0] - 1.0) < 0.01  # glitch removed
    # the 360 deg reading's window is [v118, v119, v120, v1, v2]: it never sees its own glitch twin
    assert out[-1] == np.median(v[[118, 119, 120, 1, 2]])


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(window=4), "window"),
        (dict(window=0), "window"),
        (dict(window=2.5), "window"),
        (dict(window=3, mode="circular"), "mode"),
        (dict(window=121, mode="closed"), "window"),
    ],
)
def test_median_filter_bad_params(kwargs, word):
    with pytest.raises(InputError, match=word):
        median_filter(np.arange(121.0), **kwargs)


def test_bad_screen_params():
    mag, grav = sweep_readings()
    with pytest.raises(InputError, match="threshold"):
        reject_dot_product_outliers(mag, grav, threshold=0.0)
    with pytest.raises(InputError, match="N x 3"):
        reject_dot_product_outliers(mag[:, :2], grav[:, :2])
    with pytest.raises(InputError, match="differs"):
        reject_dot_product_outliers(mag, grav[:-1])


def test_train_test_split():
    tr, te = train_test_split(121, 0.9, rng=3)
    assert (tr.size, te.size) == (109, 12)
    assert np.intersect1d(tr, te).size == 0
    np.testing.assert_array_equal(np.sort(np.concatenate([tr, te])), np.arange(121))
    assert np.all(np.diff(tr) > 0) and np.all(np.diff(te) > 0)
    tr2, te2 = train_test_split(121, 0.9, rng=np.random.default_rng(3))
    np.testing.assert_array_equal(tr, tr2)
    np.testing.assert_array_equal(te, te2)
    assert not np.array_equal(te, train_test_split(121, 0.9, rng=4)[1])
    assert [a.size for a in train_test_split(2, 0.99, rng=0)] == [1, 1]
    for kwargs, word in (
        (dict(n=1), "n"),
        (dict(n=10, frac=1.0), "frac"),
        (dict(n=10, frac=0.0), "frac"),
        (dict(n=10, rng=-2), "seed"),
    ):
        with pytest.raises(InputError, match=word):
            train_test_split(**kwargs)


def test_minmax_roundtrip_and_errors():
    rng = np.random.default_rng(0)
    v = rng.uniform(-16, 391, (50, 2))
    sc = MinMax.fit(v)
    z = sc.transform(v)
    assert z.min(axis=0).tolist() == [0.0, 0.0] and z.max(axis=0).tolist() == [1.0, 1.0]
    np.testing.assert_allclose(sc.inverse(z), v, rtol=0, atol=1e-12)
    one = MinMax.fit(v[:, 0])
    assert one.transform(v[:, 0]).shape == (50,)
    np.testing.assert_allclose(one.transform(v[:, 0]), z[:, 0])
    assert one.transform(one.hi[0] + one.span[0]) == pytest.approx(2.0)  # no clipping
    np.testing.assert_allclose(one.inverse_scale(np.array([0.5])), 0.5 * one.span)
    with pytest.raises(InputError, match="column 1 is constant"):
        MinMax.fit(np.column_stack([v[:, 0], np.ones(50)]))
    with pytest.raises(InputError, match="NaN"):
        MinMax.fit(np.array([1.0, np.nan]))
    with pytest.raises(InputError, match="2 column"):
        sc.transform(v[:, 0])
