"""The dedicated calibrator's fit (navlib.methods.ellipsoid); the workbench chapter's comparison with it is
tested in tests/studies/workbench/test_wbstudy_peer.py."""

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from navlib.errors import InputError
from navlib.methods.ellipsoid import algebraic_ellipsoid, lm_ellipsoid
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
    assert F == pytest.approx(F0)  # the LM fit keeps its start's radius
    geo0 = np.sqrt(np.mean((np.linalg.norm((m - b) @ (S * F0), axis=1) - F0) ** 2))
    geo = np.sqrt(np.mean((np.linalg.norm((m - b2) @ S2, axis=1) - F) ** 2))
    assert geo <= geo0 + 1e-12 and geo < 1.5  # the geometric error, near the 1 uT noise


def test_the_workbench_fit_is_the_algebraic_fit_scaled():
    m = raw_field(noise=0.5)
    frame = pd.DataFrame(m, columns=["mag_x_ut", "mag_y_ut", "mag_z_ut"])
    W, c = ellipsoid_fit(frame)
    b, S = algebraic_ellipsoid(m)
    assert np.array_equal(c, b) and np.allclose(
        W, np.mean(np.linalg.norm(m - b, axis=1)) * S, rtol=0, atol=0
    )


@pytest.mark.parametrize(
    "m, says",
    [
        (np.ones((5, 3)), "n >= 9"),
        (np.c_[raw_field()[:, :2], np.full(600, np.nan)], "finite"),
        (np.c_[raw_field()[:, :2], np.zeros(600)], "3-D"),
    ],
)
def test_bad_fields_are_refused_in_one_line(m, says):
    with pytest.raises(InputError, match=says):
        lm_ellipsoid(m)
