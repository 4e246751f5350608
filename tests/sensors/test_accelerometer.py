"""Tumble-test simulator (IEEE Std 1293), its Fourier analysis, the stored data set and the tumble loader."""

import numpy as np
import pandas as pd
import pytest

from navlib.data.tumble import TUMBLE_FILE, read_tumble, require_levels
from navlib.errors import InputError
from navlib.sensors.accelerometer import (
    AccelCoefficients,
    TumbleExperiment,
    bias_test,
    coefficients_from_fourier,
    paper_units,
    sensor_temperatures_c,
    simulate_tumble,
    tumble_coefficients,
    tumble_fourier,
)


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
    u = (
        0.5
        + 1000 * np.cos(np.deg2rad(q))
        + 0.3 * np.sin(np.deg2rad(2 * q))
        + 0.01 * np.cos(np.deg2rad(3 * q))
    )
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
    assert 1.5 < np.abs(bt - bt[t == 55.0]).max() < 1.9  # paper: about 1.7 mg
    out = (
        c.output_mg(t[:, None], exp.positions_deg[None])
        - c.output_mg(55.0, exp.positions_deg)[None]
    )
    assert 4.0 < np.abs(out).max() < 6.0  # paper: about 5 mg
    bt_noisy = bias_test(c, TumbleExperiment(lag_tau_min=0.0, noise_ug=0.0), seed=0)
    np.testing.assert_allclose(
        bt_noisy["true_bias_mg"], c.bias_mg(t) + c.scale_factor(t) * c.second_order_mg_g2(t)
    )


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
    assert np.abs(dt[1:]).max() < 0.5  # paper: 0.1..0.5 degC after a 30 min soak
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


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(t_step_c=0), "t_step_c"),
        (dict(t_start_c=-80), "t_start_c"),
        (dict(n_positions=7), "n_positions"),
        (dict(noise_ug=-1), "noise_ug"),
        (dict(reference_c=52), "reference_c"),
        (dict(t_stop_c=-45), "t_stop_c"),
        (dict(t_start_c=50, t_stop_c=55, t_step_c=5), "fewer than 3"),
    ],
)
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
    return [
        {
            "temperature_c": t,
            "position_deg": q,
            "output_mg": 1000 * np.cos(np.deg2rad(q)),
            "unit": "A",
        }
        for t in (-10.0, 20.0, 55.0)
        for q in (0.0, 90.0, 180.0, 270.0)
    ]


def test_reader_accepts_a_good_file_and_adds_set_points(tmp_path):
    df = read_tumble(_write(tmp_path, _good()))
    assert len(df) == 12 and set(df["set_point_c"]) == {-10.0, 20.0, 55.0}
    require_levels(df, temperatures=3, positions=4)


@pytest.mark.parametrize(
    "mutate, message",
    [
        (
            lambda r: r[4].update(temperature_c=140.0),
            "t.csv: column 'temperature_c', row 5 (file line 6): 140.0 is outside -60..130 degC",
        ),
        (
            lambda r: r[2].update(position_deg=100.0),
            "t.csv: column 'position_deg', row 3 (file line 4): 100 is not on the dividing head's 15 deg grid",
        ),
        (
            lambda r: r[2].update(position_deg=360.0),
            "t.csv: column 'position_deg', row 3 (file line 4): 360 is not on the dividing head's 15 deg grid",
        ),
        (
            lambda r: r[7].update(output_mg=float("nan")),
            "t.csv: column 'output_mg', row 8 (file line 9): is empty",
        ),
        (lambda r: r[1].update(unit=" "), "t.csv: column 'unit', row 2 (file line 3): is empty"),
        (
            lambda r: r[0].update(output_mg="abc"),
            "t.csv: column 'output_mg', row 1 (file line 2): 'abc' is not a number",
        ),
    ],
)
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
    df = read_tumble(
        _write(tmp_path, [r for r in _good() if r["temperature_c"] != 20.0], "two.csv")
    )
    with pytest.raises(
        InputError, match="unit A has 2 temperatures; the K0\\(T\\) fit needs at least 3"
    ):
        require_levels(df, temperatures=3, what="the K0(T) fit", name="two.csv")
    with pytest.raises(InputError, match="4 positions; the tumble Fourier fit needs at least 7"):
        require_levels(df, positions=7, what="the tumble Fourier fit", name="two.csv")
