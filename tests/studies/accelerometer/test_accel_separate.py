"""Paper D's register entry D11 ("an integrated model beats separate bias and scale-factor models"): the
separate K0, K1 compensator (its bias points, its inversion, no test reading reaching it) and the paired
claim against the integrated ANFIS."""

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from navbook.results_check import claim_problems
from navlib.errors import InputError
from navlib.studies import accelerometer as D

T55 = 55.3


def _k0(T):
    T = np.asarray(T, float)[:, 0]
    return 0.4 + 0.01 * (T - 55) + 2e-4 * (T - 55) ** 2


def _k1(X):
    T, a = X[:, 0], X[:, 1]
    return 1000.0 * (1 + 3e-5 * (T - 55)) + 0.3 * a + 0.2 * a**2


def _output(T, a):
    return _k0(T[:, None]) + _k1(np.column_stack([T, a])) * a


def test_inversion_recovers_the_input_and_the_reference_output_of_known_models():
    rng = np.random.default_rng(0)
    T = rng.uniform(-40, 70, 200)
    a = rng.uniform(-1, 1, 200)
    comp = D.SeparateCompensator(_k0, _k1, T55)
    X = np.column_stack([T, _output(T, a)])
    assert np.max(np.abs(comp.input_g(X) - a)) < 1e-12
    want = _output(np.full_like(a, T55), a)
    assert np.max(np.abs(comp(X) - want)) < 1e-9
    # without the fixed-point steps the scale factor's input dependence is left in: a test that can fail
    rough = replace(comp, steps=0)
    assert np.max(np.abs(rough(X) - want)) > 1e-4


def _samples(sets: dict):
    """Two set points x the four quadrant positions; ``sets`` maps (set point, position) to a label."""
    rows = []
    for sp in (0.0, 55.0):
        for q in (0.0, 90.0, 180.0, 270.0):
            rows.append(
                {
                    "set_point_c": sp,
                    "temperature_c": sp + 0.5,
                    "position_deg": q,
                    "output_mg": 1.0 + sp + np.cos(np.deg2rad(q)),
                    "set": sets.get((sp, q), "train"),
                }
            )
    return pd.DataFrame(rows)


def test_bias_points_need_both_0_and_180_deg_readings_in_one_set():
    bp = D.bias_points(_samples({(0.0, 180.0): "test"}))
    assert list(bp["set_point_c"]) == [55.0]  # 0 degC lost its 180 deg reading to the test set
    assert bp["bias_mg"].iloc[0] == pytest.approx(56.0)
    assert bp["temperature_c"].iloc[0] == pytest.approx(55.5)
    both = D.bias_points(_samples({(0.0, 0.0): "check", (0.0, 180.0): "check"}))
    assert list(both["set"]) == ["check", "train"]


def _run_frame(split_mode="temperatures", noise_ug=3.0, seed=0):
    p = D.PaperDParams(split_mode=split_mode)
    p = replace(p, experiment=replace(p.experiment, noise_ug=noise_ug))
    df = D.simulate(p, seed)
    a = D.samples(df, "A", p.experiment.reference_c)
    a["set"] = D.split(a, p) if split_mode == "temperatures" else D.random_split(a, p, seed)
    return p, a


@pytest.mark.parametrize("split_mode", ["temperatures", "random"])
def test_no_test_reading_reaches_the_separate_models(split_mode):
    p, a = _run_frame(split_mode)
    X = a[["temperature_c", "output_mg"]].to_numpy()
    before = D.fit_separate(a, p)(X)
    spoiled = a.copy()
    test = spoiled["set"] == "test"
    spoiled.loc[test, "output_mg"] += 1e3  # every test reading wildly wrong
    after = D.fit_separate(spoiled, p)(X)
    assert np.array_equal(before, after)
    # the control: spoiling training readings does change the models
    spoiled = a.copy()
    spoiled.loc[spoiled["set"] == "train", "output_mg"] += 0.5
    assert not np.allclose(D.fit_separate(spoiled, p)(X), before)


def test_separate_compensator_removes_most_of_the_drift_on_held_out_temperatures():
    p, a = _run_frame(noise_ug=0.0)
    test = (a["set"] == "test").to_numpy()
    pred = D.fit_separate(a, p)(a[["temperature_c", "output_mg"]].to_numpy())
    before = np.sqrt(np.mean((a["output_mg"] - a["target_true_mg"])[test] ** 2))
    after = np.sqrt(np.mean((pred - a["target_true_mg"].to_numpy())[test] ** 2))
    assert after < 0.05 * before


def test_fit_separate_refuses_too_few_bias_points_and_a_missing_reference():
    p, a = _run_frame()
    no_ref = a[~np.isclose(a["set_point_c"], 55.0)]
    with pytest.raises(InputError, match="reference 55"):
        D.fit_separate(no_ref, p)
    few = a.copy()
    few.loc[np.isclose(few["position_deg"], 180.0), "set"] = "test"
    with pytest.raises(InputError, match="0 set points with both 0 and 180 deg"):
        D.fit_separate(few, p)


def test_run_seed_predicts_with_the_separate_model_and_errors_long_reports_it():
    p = replace(D.PaperDParams(seeds=(0,)), swarm=replace(D.PaperDParams().swarm, generations=1))
    run = D.run_seed(p, 0)
    assert f"pred_{D.SEPARATE}" in run.a.columns and f"pred_{D.SEPARATE}" in run.b.columns
    err = D.errors_long([run])
    assert set(err.loc[err["method"] == D.SEPARATE, "set"]) == {"train", "check", "test", "unit B"}


def _err(sep_ug, n=8):
    rows = []
    for s in range(n):
        for m, v in (("ANFIS", 30.0 + s), (D.SEPARATE, 30.0 + s + sep_ug[s])):
            rows.append({"seed": s, "method": m, "set": "test", "RMSE_mg": v / 1000.0})
    return pd.DataFrame(rows)


def test_separate_claim_is_the_paired_difference_and_can_fail():
    p = D.PaperDParams(split_mode="random")
    worse = D.separate_claims(_err(np.full(8, 5.0)), p, "random split of the readings", "k")[0]
    assert worse.key == "k" and (worse.boundary, worse.holds_when) == (0.0, "above")
    assert worse.estimate.value == pytest.approx(5.0) and worse.verdict == "reproduced"
    assert claim_problems(worse.record()) == []
    better = D.separate_claims(_err(np.full(8, -5.0)), p, "random split of the readings")[0]
    assert better.verdict == "not reproduced"
    mixed = np.array([3.0, -3.0, 2.0, -2.0, 1.0, -1.0, 4.0, -4.0])
    assert D.separate_claims(_err(mixed), p, "x")[0].verdict == "cannot be judged"


def test_separate_claims_need_enough_paired_seeds():
    p = D.PaperDParams()
    with pytest.raises(InputError, match="at least"):
        D.separate_claims(_err(np.ones(3), n=3), p, "x")
    e = _err(np.ones(8))
    with pytest.raises(InputError, match="lacks"):
        D.separate_claims(e[~((e["method"] == D.SEPARATE) & (e["seed"] == 2))], p, "x")


def test_separate_noise_claims_one_row_per_noise_level():
    e = pd.concat(
        [_err(np.full(8, 2.0)).assign(noise_ug=v) for v in (1.0, 10.0)], ignore_index=True
    )
    cl = D.separate_noise_claims(e, D.PaperDParams())
    assert [c.reading for c in cl] == [
        "held-out temperatures, noise 1 ug",
        "held-out temperatures, noise 10 ug",
    ]
    assert "sensor noise 10 ug per reading" in cl[1].decided_by


def test_a_scale_factor_model_off_between_its_points_gives_finite_outputs_inside_its_range():
    def spiky(X):  # K1 as a fitted model can be: zero (no rule fires) on a narrow band of inputs
        k = _k1(X)
        return np.where(np.abs(X[:, 1] - 0.3) < 0.02, 0.0, k)

    T = np.full(5, 20.0)
    a = np.array([0.25, 0.29, 0.3, 0.31, 0.9])
    X = np.column_stack([T, _output(T, a)])
    want = _output(np.full_like(a, T55), a)
    band = np.abs(a - 0.3) < 0.02
    with np.errstate(divide="ignore", invalid="ignore"):
        unbounded = D.SeparateCompensator(_k0, spiky, T55)(X)
    # the failure the range prevents: infinite, or the input lost (the output collapses to K0)
    lost = ~np.isfinite(unbounded) | (np.abs(unbounded - want) > 0.5 * np.abs(want))
    assert lost[band].all()
    bounded = D.SeparateCompensator(_k0, spiky, T55, (990.0, 1010.0))(X)
    assert np.isfinite(bounded).all()
    assert (np.abs(bounded - want)[band] < 0.02 * np.abs(want)[band]).all()
    assert np.max(np.abs(bounded - want)[~band]) < 1e-9  # away from the band nothing changes


def test_scale_factor_range_must_not_contain_zero():
    with pytest.raises(InputError, match="k1_range_mg_g"):
        D.SeparateCompensator(_k0, _k1, T55, (-5.0, 1000.0))


def test_register_entry_d11_names_the_rows_the_chapter_writes():
    from navlib import claims as register

    d11 = next(e for e in register.load_register("paper_d") if e.id == "D11")
    c = D.separate_claims(_err(np.full(8, 5.0)), D.PaperDParams(), "random split of the readings")[
        0
    ]
    assert d11.status == "judged" and d11.rows == (c.claim,) and d11.primary_claim == c.claim
    assert d11.primary_reading == c.reading
    assert (d11.boundary, d11.holds_when, d11.unit, d11.statistic) == (
        c.boundary,
        c.holds_when,
        c.unit,
        c.statistic,
    )
    assert d11.margin == 1.0
