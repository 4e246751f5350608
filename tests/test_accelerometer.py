"""Tumble-test simulator (IEEE Std 1293), its Fourier analysis, the stored data set and the tumble loader."""
import numpy as np
import pandas as pd
import pytest

from navlib.data.tumble import TUMBLE_FILE, read_tumble, require_levels
from navlib.errors import InputError
from navlib.sensors.accelerometer import (AccelCoefficients, TumbleExperiment, bias_test, coefficients_from_fourier,
                                          paper_units, sensor_temperatures_c, simulate_tumble, tumble_coefficients,
                                          tumble_fourier)


def test_fourier_fit_recovers_the_simulator_coefficients():
    coef = AccelCoefficients()
    exp = TumbleExperiment(noise_ug=0.0, lag_tau_min=0.0)
    df = simulate_tumble(coef, exp, seed=0)
    got = tumble_coefficients(df)
    t = got["temperature_c"].to_numpy()
    np.testing.assert_allclose(t, exp.set_points_c)
    np.testing.assert_allclose(got["k0_mg"], coef.bias_mg(t), atol=1e-9)
    np.testing.assert_allclose(got["k1"], coef.scale_factor(t), rtol=1e-12)
    np.testing.assert_allclose(got["k2_mg_g2"], coef.second_order_mg_g2(t), atol=1e-9)
    np.testing.assert_allclose(got["kip_mg_g2"], coef.kip_mg_g2, atol=1e-9)
    np.testing.assert_allclose(got["delta_o_mg"], coef.delta_o_mg, atol=1e-9)


def test_fourier_terms_of_one_tumble():
    q = np.arange(24) * 15.0
    u = 0.5 + 1000 * np.cos(np.deg2rad(q)) + 0.3 * np.sin(np.deg2rad(2 * q)) + 0.01 * np.cos(np.deg2rad(3 * q))
    f = tumble_fourier(q, u)
    assert f["A0"] == pytest.approx(0.5) and f["A1"] == pytest.approx(1000)
    assert f["B2"] == pytest.approx(0.3) and f["A3"] == pytest.approx(0.01)
    c = coefficients_from_fourier(f)
    assert c["k0_mg"] == pytest.approx(0.5) and c["kip_mg_g2"] == pytest.approx(0.6)
    with pytest.raises(InputError, match="positions"):
        tumble_fourier(q[:6], u[:6])


def test_paper_experiment_size_and_default_drifts():
    exp = TumbleExperiment()
    assert exp.set_points_c.size == 23 and exp.positions_deg.size == 24
    df = simulate_tumble(AccelCoefficients(), exp, seed=1)
    assert len(df) == 552
    c = AccelCoefficients()
    t = exp.set_points_c
    bt = bias_test(c, TumbleExperiment(lag_tau_min=0.0), seed=0)["true_bias_mg"].to_numpy()
    assert 1.5 < np.abs(bt - bt[t == 55.0]).max() < 1.9   # paper: about 1.7 mg
    out = c.output_mg(t[:, None], exp.positions_deg[None]) - c.output_mg(55.0, exp.positions_deg)[None]
    assert 4.0 < np.abs(out).max() < 6.0              # paper: about 5 mg
    bt_noisy = bias_test(c, TumbleExperiment(lag_tau_min=0.0, noise_ug=0.0), seed=0)
    np.testing.assert_allclose(bt_noisy["true_bias_mg"],
                               c.bias_mg(t) + c.scale_factor(t) * c.second_order_mg_g2(t))


def test_noise_level_and_seeding():
    exp = TumbleExperiment(noise_ug=50.0)
    a = simulate_tumble(AccelCoefficients(), exp, seed=3)
    b = simulate_tumble(AccelCoefficients(), exp, seed=3)
    c = simulate_tumble(AccelCoefficients(), exp, seed=4)
    pd.testing.assert_frame_equal(a, b)
    assert not np.allclose(a["output_mg"], c["output_mg"])
    resid_ug = 1000 * (a["output_mg"] - a["true_output_mg"])
    assert 40 < resid_ug.std() < 60


def test_thermal_lag_settles_within_the_papers_stability():
    exp = TumbleExperiment()
    dt = sensor_temperatures_c(exp) - exp.set_points_c[:, None]
    assert np.abs(dt[1:]).max() < 0.5                 # paper: 0.1..0.5 degC after a 30 min soak
    assert np.all(np.abs(dt[1:, -1]) <= np.abs(dt[1:, 0]))
    still = sensor_temperatures_c(TumbleExperiment(lag_tau_min=0.0))
    np.testing.assert_allclose(still, np.broadcast_to(exp.set_points_c[:, None], still.shape))


def test_batch_member_within_spread():
    a = AccelCoefficients()
    b = a.batch_member(0.25, seed=2)
    assert b != a and b.bias_step_c == a.bias_step_c
    assert a.batch_member(0.0, seed=2) == a


def test_stored_data_equals_regeneration():
    stored = read_tumble(TUMBLE_FILE)
    fresh = paper_units()
    np.testing.assert_allclose(stored["output_mg"], fresh["output_mg"], atol=1e-8)
    np.testing.assert_allclose(stored["temperature_c"], fresh["temperature_c"], atol=1e-8)
    assert list(stored["unit"]) == list(fresh["unit"])


@pytest.mark.parametrize("kw, word", [
    (dict(t_step_c=0), "t_step_c"), (dict(t_start_c=-80), "t_start_c"), (dict(n_positions=7), "n_positions"),
    (dict(noise_ug=-1), "noise_ug"), (dict(reference_c=52), "reference_c"), (dict(t_stop_c=-45), "t_stop_c"),
    (dict(t_start_c=50, t_stop_c=55, t_step_c=5), "fewer than 3")])
def test_bad_experiment(kw, word):
    with pytest.raises(InputError, match=word):
        TumbleExperiment(**kw)


def test_bad_coefficients():
    with pytest.raises(InputError, match="bias_step_width_c"):
        AccelCoefficients(bias_step_width_c=0)
    with pytest.raises(InputError, match="k0c_mg"):
        AccelCoefficients(k0c_mg=float("nan"))


# ------------------------------------------------------------------------------------------- loader
def _write(tmp_path, rows, name="t.csv"):
    p = tmp_path / name
    pd.DataFrame(rows).to_csv(p, index=False)
    return p


def _good():
    return [{"temperature_c": t, "position_deg": q, "output_mg": 1000 * np.cos(np.deg2rad(q)), "unit": "A"}
            for t in (-10.0, 20.0, 55.0) for q in (0.0, 90.0, 180.0, 270.0)]


def test_reader_accepts_a_good_file_and_adds_set_points(tmp_path):
    df = read_tumble(_write(tmp_path, _good()))
    assert len(df) == 12 and set(df["set_point_c"]) == {-10.0, 20.0, 55.0}
    require_levels(df, temperatures=3, positions=4)


@pytest.mark.parametrize("mutate, message", [
    (lambda r: r[4].update(temperature_c=140.0), "t.csv: column 'temperature_c', row 5 (file line 6): 140.0 is outside -60..130 degC"),
    (lambda r: r[2].update(position_deg=100.0), "t.csv: column 'position_deg', row 3 (file line 4): 100 is not on the dividing head's 15 deg grid"),
    (lambda r: r[2].update(position_deg=360.0), "t.csv: column 'position_deg', row 3 (file line 4): 360 is not on the dividing head's 15 deg grid"),
    (lambda r: r[7].update(output_mg=float("nan")), "t.csv: column 'output_mg', row 8 (file line 9): is empty"),
    (lambda r: r[1].update(unit=" "), "t.csv: column 'unit', row 2 (file line 3): is empty"),
    (lambda r: r[0].update(output_mg="abc"), "t.csv: column 'output_mg', row 1 (file line 2): 'abc' is not a number"),
])
def test_reader_bad_input(tmp_path, mutate, message):
    rows = _good()
    mutate(rows)
    with pytest.raises(InputError) as err:
        read_tumble(_write(tmp_path, rows))
    assert str(err.value).startswith(message) and "\n" not in str(err.value)


def test_reader_missing_unit_column_and_too_few_levels(tmp_path):
    rows = [{k: v for k, v in r.items() if k != "unit"} for r in _good()]
    with pytest.raises(InputError, match="missing column 'unit'"):
        read_tumble(_write(tmp_path, rows))
    df = read_tumble(_write(tmp_path, [r for r in _good() if r["temperature_c"] != 20.0], "two.csv"))
    with pytest.raises(InputError, match="unit A has 2 temperatures; the K0\\(T\\) fit needs at least 3"):
        require_levels(df, temperatures=3, what="the K0(T) fit", name="two.csv")
    with pytest.raises(InputError, match="4 positions; the tumble Fourier fit needs at least 7"):
        require_levels(df, positions=7, what="the tumble Fourier fit", name="two.csv")


# ------------------------------------------------------------------------------- paper D's claims
from navlib import verdicts  # noqa: E402
from navbook.results_check import claim_problems  # noqa: E402
from navlib.studies import paper_d as D  # noqa: E402

BEST = "IAFSA-SCM-ANFIS"
PHYS = "physical (poly K0, K1, K2)"


def _err(test, train=None, unit_b=None, seeds=None):
    """A synthetic errors table (ug in, mg stored) for :func:`paper_d.claims`: ``test`` maps every method of
    ``paper_d.METHODS`` and "oracle" to per-seed held-out RMSE; ``train`` and ``unit_b`` (largest error) map
    IAFSA-SCM-ANFIS and "oracle"."""
    n = len(test[BEST])
    seeds = list(range(n)) if seeds is None else list(seeds)
    train = train or {BEST: np.full(n, 3.6), "oracle": np.full(n, 4.2)}
    unit_b = unit_b or {BEST: np.full(n, 1300.0), "oracle": np.full(n, 1300.0)}
    rows = []
    for s, table, col in (("test", test, "RMSE_mg"), ("train", train, "RMSE_mg"), ("unit B", unit_b, "ME_mg")):
        for m, v in table.items():
            for seed, x in zip(seeds, v):
                rows.append({"seed": seed, "method": m, "set": s, "RMSE_mg": x / 1000, "ME_mg": x / 1000})
    return pd.DataFrame(rows)


def _test_rmse(n=6, best=None, **over):
    base = {"ANN": 240.0, "FIS": 37.9, "ANFIS": 35.7, BEST: 5.4, PHYS: 28.3, "oracle": 4.3}
    base.update(over)
    out = {m: np.full(n, v) + 0.01 * np.arange(n) for m, v in base.items()}
    if best is not None:
        out[BEST] = np.asarray(best, float)
    return out


_DRIFT = pd.DataFrame({"quantity": ["max |output drift|, unit A", "max |bias drift|", "max |scale-factor drift|",
                                    "max |output drift|, unit B"], "unit": ["mg", "mg", "mg/g", "mg"],
                       "ours": [5.8, 1.68, 5.0, 6.7], "paper": [5.0, 1.7, 6.0, 7.21]})


def _claims(err, noise_ug=3.0):
    p = D.PaperDParams(experiment=TumbleExperiment(noise_ug=noise_ug))
    return {(c.key): c for c in D.claims(err, _DRIFT, D.paper_numbers(), p)}


def test_every_claim_is_built_by_the_rule_and_stored_verdicts_rederive():
    cl = _claims(_err(_test_rmse()))
    assert len(cl) == 12 and all(cl)                      # every claim has a key for the prose
    for c in cl.values():
        assert claim_problems(c.record()) == [], c.claim
        assert c.estimate is not None or c.by_construction
    book = [c for c in cl.values() if c.source == "book"]
    assert [c.key for c in book] == ["accel_vs_poly"] and book[0].paper == "(not in the paper)"
    # the paper's numbers are the boundaries, not our tolerances
    assert cl["accel_rmse_test"].boundary == pytest.approx(4.0) and cl["accel_unit_b"].boundary == pytest.approx(9.3)
    assert cl["accel_orders_ann"].boundary == cl["accel_orders_fis"].boundary == 10.0
    for k in ("accel_rmse_train", "accel_rmse_test", "accel_unit_b"):
        assert cl[k].holds_when == "below" and cl[k].floor is not None
    for k in ("accel_order_ann", "accel_order_fis", "accel_order_anfis", "accel_vs_poly"):
        assert cl[k].holds_when == "above" and cl[k].boundary == 0.0 and cl[k].rule == "paired difference"
    for k in ("accel_orders_ann", "accel_orders_fis"):
        assert cl[k].holds_when == "above" and cl[k].rule == "paired ratio" and cl[k].floor is not None
    assert cl["accel_drifts"].by_construction and cl["accel_drifts"].verdict == "cannot be judged"


def test_comparisons_are_paired_over_the_same_seeds():
    best = np.array([5.0, 50.0, 8.0, 30.0, 12.0, 20.0])          # wide spread over seeds
    t = _test_rmse(best=best)
    t["ANN"] = 20.0 * best                                       # 20x on every seed
    t["ANFIS"] = best + 1.0                                      # 1 ug worse on every seed
    err = _err(t).sample(frac=1.0, random_state=0)               # row order must not matter
    cl = _claims(err, noise_ug=0.1)
    r, d = cl["accel_orders_ann"].estimate, cl["accel_order_anfis"].estimate
    assert (r.lo, r.hi, r.n) == pytest.approx((20.0, 20.0, 6)) and cl["accel_orders_ann"].verdict == "reproduced"
    assert (d.lo, d.hi) == pytest.approx((1.0, 1.0)) and cl["accel_order_anfis"].verdict == "reproduced"
    # unpaired, the same numbers would overlap: ANFIS's values lie among IAFSA-SCM-ANFIS's
    assert verdicts.median_ci(t["ANFIS"]).lo < verdicts.median_ci(best).hi
    # a seed that lacks a method is an error, not a silently shorter pairing
    with pytest.raises(InputError, match="lacks"):
        _claims(err[~((err["seed"] == 3) & (err["method"] == "FIS") & (err["set"] == "test"))])


@pytest.mark.parametrize("best, noise, verdict, basis", [
    ([3.0, 3.1, 3.2, 3.3, 3.4, 3.5], 1.0, "reproduced", "interval"),
    ([6.0, 6.1, 6.2, 6.3, 6.4, 6.5], 1.0, "not reproduced", "interval"),
    ([3.0, 3.5, 3.9, 4.1, 4.5, 5.0], 1.0, "cannot be judged", "straddles"),
    # sqrt(2) x 3 = 4.24 ug > 4 ug: between the two, the noise excuses it; below 4, the data crossed the
    # floor estimate; beyond 4.24, it failed whatever the noise
    ([4.05, 4.08, 4.1, 4.12, 4.15, 4.2], 3.0, "cannot be judged", "noise floor"),
    ([3.0, 3.1, 3.2, 3.3, 3.4, 3.5], 3.0, "reproduced", "interval"),
    ([6.0, 6.1, 6.2, 6.3, 6.4, 6.5], 3.0, "not reproduced", "interval")])
def test_the_4ug_claim_lands_on_each_side(best, noise, verdict, basis):
    c = _claims(_err(_test_rmse(best=best)), noise_ug=noise)["accel_rmse_test"]
    assert (c.verdict, c.basis) == (verdict, basis)
    if noise == 3.0:
        assert c.floor.value == pytest.approx(np.sqrt(2) * 3.0)
        assert "2.83 ug" in c.floor.needs and "3 ug per reading" in c.floor.assumption


def test_training_floor_is_the_exact_models_on_training_readings():
    c = _claims(_err(_test_rmse()))["accel_rmse_train"]
    n_train = 23 - 3 - 3                                          # set points - held out - checking
    assert c.floor.value == pytest.approx(np.sqrt(2) * 3.0 * np.sqrt(1 - 1 / n_train))
    assert c.floor.value > 4.0                                    # the floor lies beyond the 4 ug boundary
    lo, hi = c.interval                                           # so the floor decides unless the data cross it
    assert (c.verdict, c.basis) == (("reproduced", "interval") if hi < 4.0 else
                                    ("not reproduced", "interval") if lo > c.floor.value else
                                    ("cannot be judged", "noise floor"))


def test_ratio_against_fis_needs_a_floor_below_our_fis():
    cl = _claims(_err(_test_rmse()))
    fis = cl["accel_orders_fis"]
    assert fis.floor.value < 10                                    # 37.9 / 4.24 < 10: our FIS caps the ratio
    # the ratio lies below even that cap: worse than anything the noise excuses
    assert fis.interval[1] < fis.floor.value and (fis.verdict, fis.basis) == ("not reproduced", "interval")
    assert cl["accel_orders_ann"].basis == "interval"              # 240 / 4.24 > 10
    better = _claims(_err(_test_rmse(FIS=101.0)))["accel_orders_fis"]
    assert better.basis == "interval" and better.verdict == "reproduced"


def test_unit_b_claim_sides_and_floor():
    t = _test_rmse()
    far = _claims(_err(t), noise_ug=0.5)["accel_unit_b"]
    assert far.verdict == "not reproduced"
    near = _claims(_err(t, unit_b={BEST: np.linspace(4, 5, 6), "oracle": np.full(6, 3.0)}), noise_ug=0.5)
    assert near["accel_unit_b"].verdict == "reproduced"
    # with 3 ug noise the floor (13 ug) lies beyond 9.3 ug: a unit B between the two is excused ...
    floored = _claims(_err(t, unit_b={BEST: np.linspace(10, 12, 6), "oracle": np.full(6, 3.0)}))["accel_unit_b"]
    assert floored.basis == "noise floor" and floored.floor.value > 9.3
    # ... one inside 9.3 ug crossed the floor estimate, one beyond the floor failed
    crossed = _claims(_err(t, unit_b={BEST: np.linspace(4, 5, 6), "oracle": np.full(6, 3.0)}))["accel_unit_b"]
    assert crossed.verdict == "reproduced"
    beyond = _claims(_err(t, unit_b={BEST: np.linspace(20, 25, 6), "oracle": np.full(6, 3.0)}))["accel_unit_b"]
    assert beyond.verdict == "not reproduced"


def test_claims_need_six_seeds():
    with pytest.raises(InputError, match="at least 6 seeds, got 4"):
        _claims(_err(_test_rmse(n=4)))


def test_floors_match_the_simulated_exact_model():
    coef = AccelCoefficients(kip_mg_g2=0.0, delta_o_mg=0.0)
    exp = TumbleExperiment(noise_ug=3.0, lag_tau_min=0.0)
    orc = D.oracle(coef)
    sq_all, sq_new, maxima = [], [], []
    for seed in range(150):
        s = D.samples(simulate_tumble(coef, exp, seed=seed), "A")
        e = 1000 * (orc(s[["temperature_c", "output_mg"]].to_numpy()) - s["target_mg"].to_numpy())
        new = ~np.isclose(s["set_point_c"], 55.0)
        sq_all.append(np.mean(e ** 2))
        sq_new.append(np.mean(e[new] ** 2))
        maxima.append(np.abs(e[new]).max())
    assert np.sqrt(np.mean(sq_new)) == pytest.approx(D.rmse_floor_ug(3.0), rel=0.03)
    assert np.sqrt(np.mean(sq_all)) == pytest.approx(D.rmse_floor_ug(3.0, 1 / 23), rel=0.03)
    assert np.median(maxima) == pytest.approx(D.max_error_floor_ug(3.0, 22, 24), rel=0.05)
    assert D.max_error_floor_ug(6.0, 22, 24) == pytest.approx(2 * D.max_error_floor_ug(3.0, 22, 24))
    with pytest.raises(InputError, match="reference_share"):
        D.rmse_floor_ug(3.0, 1.5)
