import numpy as np
import pytest

from navlib.angles import wrap_deg
from navlib.errors import InputError
from navlib.methods.smith import design, eight_position_indices, fit_smith


def smith_curve(h, coef):
    return design(h) @ np.asarray(coef)


def test_smith_exact_on_noiseless_smith_data():
    coef = [1.2, 8.0, -3.0, 1.5, -0.7]
    m = np.arange(0, 360, 45.0)  # the 8 positions, in compass (measured) heading
    t = m - smith_curve(m, coef)  # deviation = measured - true
    model = fit_smith(m, t)
    assert np.allclose(model.coef, coef, atol=1e-10)
    assert np.allclose(wrap_deg(model.correct(m) - t), 0, atol=1e-10)


def test_smith_is_least_squares_with_noise():
    rng = np.random.default_rng(0)
    m = np.arange(0, 360, 5.0)
    coef = [0.5, 3.0, 1.0, -0.5, 0.2]
    t = m - smith_curve(m, coef) + 0.05 * rng.standard_normal(len(m))
    model = fit_smith(m, t)
    assert np.allclose(model.coef, coef, atol=0.03)
    assert set(model.as_dict()) == {"A", "B", "C", "D", "E"}


def test_eight_positions():
    t = np.arange(0, 361, 3.0)
    idx = eight_position_indices(t)
    assert list(t[idx]) == [0, 45, 90, 135, 180, 225, 270, 315]
    with pytest.raises(InputError, match="no reading at true heading 45"):
        eight_position_indices(np.arange(0, 360, 10.0))


def test_smith_needs_five_headings():
    with pytest.raises(InputError, match="at least 5"):
        fit_smith([0, 90, 180, 270], [0, 90, 180, 270])
