"""The dedicated calibrator's fit (navlib.methods.ellipsoid) and the workbench chapter's comparison with it
(navlib.studies.workbench.calibration_beside_peer)."""
import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from navlib.errors import InputError
from navlib.methods.ellipsoid import algebraic_ellipsoid, lm_ellipsoid
from navlib.studies import workbench as wb
from navlib.workbench.magnetometer import ellipsoid_fit

B_TRUE = np.array([12.0, -5.0, 3.0])
W_TRUE = np.array([[1.05, 0.03, -0.02], [0.03, 0.97, 0.01], [-0.02, 0.01, 1.01]])
F_TRUE = 48.0


def raw_field(n=600, noise=0.0, seed=1):
    rng = np.random.default_rng(seed)
    u = Rotation.random(n, random_state=rng).apply([F_TRUE, 0, 0])
    return u @ W_TRUE.T + B_TRUE + noise * rng.standard_normal((n, 3))


def test_both_fits_recover_a_clean_ellipsoid():
    m = raw_field()
    b, S = algebraic_ellipsoid(m)
    assert np.allclose(b, B_TRUE, atol=1e-8)
    assert np.allclose(np.linalg.norm((m - b) @ S, axis=1), 1.0, atol=1e-8)
    b2, S2, F = lm_ellipsoid(m)
    assert np.allclose(b2, B_TRUE, atol=1e-6)
    assert np.allclose(np.linalg.norm((m - b2) @ S2, axis=1), F, atol=1e-6)
    # S (m - b) undoes W up to a rotation: S W / (F / F_TRUE) is orthogonal
    R = S2 @ W_TRUE * (F_TRUE / F)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-6)


def test_the_lm_fit_is_no_worse_than_its_algebraic_start_on_noisy_data():
    m = raw_field(noise=1.0, seed=4)
    b, S = algebraic_ellipsoid(m)
    F0 = np.mean(np.linalg.norm(m - b, axis=1))
    b2, S2, F = lm_ellipsoid(m)
    assert F == pytest.approx(F0)                     # the LM fit keeps its start's radius
    geo0 = np.sqrt(np.mean((np.linalg.norm((m - b) @ (S * F0), axis=1) - F0) ** 2))
    geo = np.sqrt(np.mean((np.linalg.norm((m - b2) @ S2, axis=1) - F) ** 2))
    assert geo <= geo0 + 1e-12 and geo < 1.5            # the geometric error, near the 1 uT noise


def test_the_workbench_fit_is_the_algebraic_fit_scaled():
    m = raw_field(noise=0.5)
    frame = pd.DataFrame(m, columns=["mag_x_ut", "mag_y_ut", "mag_z_ut"])
    W, c = ellipsoid_fit(frame)
    b, S = algebraic_ellipsoid(m)
    assert np.array_equal(c, b) and np.allclose(W, np.mean(np.linalg.norm(m - b, axis=1)) * S, rtol=0, atol=0)


@pytest.mark.parametrize("m, says", [
    (np.ones((5, 3)), "n >= 9"),
    (np.c_[raw_field()[:, :2], np.full(600, np.nan)], "finite"),
    (np.c_[raw_field()[:, :2], np.zeros(600)], "3-D"),
])
def test_bad_fields_are_refused_in_one_line(m, says):
    with pytest.raises(InputError, match=says):
        lm_ellipsoid(m)


def test_held_out_errors_are_zero_for_a_perfect_calibration():
    q = Rotation.random(50, random_state=2)
    world = np.array([20.0, 1.0, 40.0])
    body = q.inv().apply(world)                       # body frame readings of one world field
    ang, spread = wb.held_out_field_errors(body, q.as_quat()[:, [3, 0, 1, 2]])
    assert ang == pytest.approx(0.0, abs=1e-6) and spread == pytest.approx(0.0, abs=1e-9)


def test_the_summary_counts_what_the_table_says():
    acc = pd.DataFrame({"raw direction (deg)": [1.0, 1.0, 2.0], "peer direction (deg)": [0.9, 3.0, np.nan],
                        "navlib direction (deg)": [0.8, 4.0, np.nan], "peer": ["fitted", "fitted", "no ellipsoid"],
                        "navlib": ["calibrated", "warned", "refused"]}, index=["a", "b", "c"])
    times = pd.DataFrame({"navlib (s)": [1.0, 2.0, 0.5], "peer (s)": [0.01, 0.01, 0.01]}, index=acc.index)
    s = wb.PeerComparison(acc, times).summary()
    assert s == {"trials": 3, "calibrated": 2, "warned": 1, "peer_failed": 1, "refused": 1, "navlib_worse": 1,
                 "navlib_worse_warned": 1, "peer_worse": 1, "time_ratio": 100.0}


@pytest.mark.skipif(not wb.MAG_DIR.exists(), reason="BROAD 3-D recordings absent (../shared/realdata)")
def test_the_comparison_runs_on_a_real_recording():
    r = wb.calibration_beside_peer([wb.MAG_DIR / wb.CALIBRATION_TRIAL])
    a = r.accuracy.iloc[0]
    assert a["navlib"] == "calibrated" and a["peer"] == "fitted"
    assert a["navlib direction (deg)"] < a["raw direction (deg)"] + 0.5
    assert list(r.times.columns) == ["navlib (s)", "peer (s)"]
    with pytest.raises(InputError, match="train_share"):
        wb.calibration_beside_peer([wb.MAG_DIR / wb.CALIBRATION_TRIAL], train_share=1.5)
