"""Generic MLP and paper D's study pieces (physical baseline, metrics, parameter validation)."""
import numpy as np
import pytest
import torch

from navlib.errors import InputError
from navlib.methods.mlp import MLPParams, train_mlp as train
from navlib.sensors.accelerometer import AccelCoefficients, TumbleExperiment, simulate_tumble
from navlib.studies import paper_d as D

torch.set_num_threads(1)


@pytest.mark.slow
@pytest.mark.parametrize("hidden", ["tansig", "logsig"])
def test_mlp_fits_a_smooth_map_and_is_seeded(hidden):
    rng = np.random.default_rng(0)
    X = rng.uniform(-1, 1, (200, 2))
    Y = np.c_[np.sin(2 * X[:, 0]) + X[:, 1], X[:, 0] * X[:, 1], X[:, 1] ** 2]
    p = MLPParams(n_in=2, n_hidden=10, n_out=3, hidden=hidden, epochs=40)
    a, b = train(X, Y, p, seed=1), train(X, Y, p, seed=1)
    np.testing.assert_array_equal(a.predict(X), b.predict(X))
    assert np.sqrt(np.mean((a.predict(X) - Y) ** 2)) < 0.02
    assert a.loss_history[-1] < a.loss_history[0]


@pytest.mark.parametrize("kw, word", [(dict(n_hidden=0), "n_hidden"), (dict(hidden="relu"), "hidden"),
                                      (dict(trainer="sgd"), "trainer"), (dict(epochs=0), "epochs")])
def test_mlp_bad_params(kw, word):
    with pytest.raises(InputError, match=word):
        MLPParams(**kw)


def test_mlp_shape_checks():
    with pytest.raises(InputError, match="inputs have 3 columns"):
        train(np.zeros((5, 3)), np.zeros(5), MLPParams(n_in=2))
    with pytest.raises(InputError, match="do not match the targets"):
        train(np.zeros((5, 2)), np.zeros(4), MLPParams(n_in=2))


def test_physical_baseline_exact_on_a_polynomial_noise_free_sensor():
    coef = AccelCoefficients(bias_step_mg=0.0, sf_quad_per_c2=0.0)
    exp = TumbleExperiment(noise_ug=0.0, lag_tau_min=0.0)
    df = simulate_tumble(coef, exp, seed=0)
    s = D.samples(df, "A")
    model = D.fit_physical(df, degree=3)
    pred = model(s[["temperature_c", "output_mg"]].to_numpy())
    assert np.max(np.abs(pred - s["target_mg"])) < 1e-3      # < 1 ug; only the small cross terms remain
    orc = D.oracle(coef)(s[["temperature_c", "output_mg"]].to_numpy())
    assert np.max(np.abs(orc - s["target_mg"])) < 1e-3


def test_metrics():
    m = D.metrics([1.0, -2.0, 1.0], [10.0, 20.0, -5.0])
    assert m["ME_mg"] == 2.0 and m["AE_mg"] == 0.0
    assert m["MAXE"] == pytest.approx(0.2) and m["MARE"] == pytest.approx((0.1 + 0.1 + 0.2) / 3)
    assert m["RMSE_mg"] == pytest.approx(np.sqrt(2.0))


def test_split_is_by_whole_temperatures():
    p = D.PaperDParams()
    s = D.samples(D.simulate(p, 0), "A")
    lab = D.split(s, p)
    for t, g in s.groupby("set_point_c"):
        assert lab[g.index].nunique() == 1
    assert set(s.loc[lab == "test", "set_point_c"]) == set(p.held_out_c)
    assert (lab[s["set_point_c"] == 55.0] == "train").all()


@pytest.mark.parametrize("kw, word", [
    (dict(held_out_c=(-32.0,)), "not a set point"), (dict(held_out_c=(55.0,)), "reference"),
    (dict(held_out_c=(0.0,), check_c=(0.0,)), "share"), (dict(radius_bounds=(0.5, 0.2)), "radius_bounds"),
    (dict(squash_bounds=(0.5, 2.0)), "squash"), (dict(seeds=()), "seeds"), (dict(fis_radius=0), "fis_radius"),
    (dict(max_rules=0), "max_rules"), (dict(mlp=MLPParams(n_in=3)), "mlp")])
def test_study_bad_params(kw, word):
    with pytest.raises(InputError, match=word):
        D.PaperDParams(**kw)
