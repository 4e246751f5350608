"""The accelerometer chapter's pieces: the physical baseline and the exact model, the metrics, the split by
whole temperatures and the validation of its parameters."""

import numpy as np
import pytest

from navlib.errors import InputError
from navlib.methods.mlp import MLPParams
from navlib.sensors.accelerometer import AccelCoefficients, TumbleExperiment, simulate_tumble
from navlib.studies import accelerometer as D


def test_physical_baseline_exact_on_a_polynomial_noise_free_sensor():
    coef = AccelCoefficients(bias_step_mg=0.0, sf_quad_per_c2=0.0)
    exp = TumbleExperiment(noise_ug=0.0, lag_tau_min=0.0)
    df = simulate_tumble(coef, exp, seed=0)
    s = D.samples(df, "A")
    model = D.fit_physical(df, degree=3)
    pred = model(s[["temperature_c", "output_mg"]].to_numpy())
    assert np.max(np.abs(pred - s["target_mg"])) < 1e-3  # < 1 ug; only the small cross terms remain
    orc = D.oracle(coef)(s[["temperature_c", "output_mg"]].to_numpy())
    assert np.max(np.abs(orc - s["target_mg"])) < 1e-3


def test_metrics():
    m = D.metrics([1.0, -2.0, 1.0], [10.0, 20.0, -5.0])
    assert m["ME_mg"] == 2.0 and m["AE_mg"] == 0.0
    assert m["MAXE"] == pytest.approx(0.2) and m["MARE"] == pytest.approx((0.1 + 0.1 + 0.2) / 3)
    assert m["RMSE_mg"] == pytest.approx(np.sqrt(2.0))
    assert m["range_mg"] == 3.0  # largest minus smallest residual, signs kept: 1 - (-2)


def test_split_is_by_whole_temperatures():
    p = D.PaperDParams()
    s = D.samples(D.simulate(p, 0), "A")
    lab = D.split(s, p)
    for t, g in s.groupby("set_point_c"):
        assert lab[g.index].nunique() == 1
    assert set(s.loc[lab == "test", "set_point_c"]) == set(p.held_out_c)
    assert (lab[s["set_point_c"] == 55.0] == "train").all()


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(held_out_c=(-32.0,)), "not a set point"),
        (dict(held_out_c=(55.0,)), "reference"),
        (dict(held_out_c=(0.0,), check_c=(0.0,)), "share"),
        (dict(radius_bounds=(0.5, 0.2)), "radius_bounds"),
        (dict(squash_bounds=(0.5, 2.0)), "squash"),
        (dict(seeds=()), "seeds"),
        (dict(fis_radius=0), "fis_radius"),
        (dict(max_rules=0), "max_rules"),
        (dict(mlp=MLPParams(n_in=3)), "mlp"),
    ],
)
def test_study_bad_params(kw, word):
    with pytest.raises(InputError, match=word):
        D.PaperDParams(**kw)
