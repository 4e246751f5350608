"""navlib.sensors.thermal_gyro: the cold-start thermal gyro model and the exact 12 h latitude-error map."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from navlib.errors import InputError
from navlib.sensors import ins
from navlib.sensors import thermal_gyro as tg

G = tg.ThermalGyro(temp_coeff_deg_h_per_c=2e-4, gradient_coeff_deg_h_per_c=3e-3, lag_h=1.5)


def test_step_closed_form_steady_state_and_time_constant():
    # case soaked at 10 C, then held at 40 C from t = 0 with the sensor still at 10 C
    knots, case = [0.0, 100.0], [40.0, 40.0]
    ts = G.sensor_temperature_c([0.0, G.lag_h, 3 * G.lag_h, 60.0], knots, case, start_c=10.0)
    assert ts[0] == pytest.approx(10.0)
    assert ts[1] == pytest.approx(40.0 - 30.0 / math.e, rel=1e-12)  # 63 % of the step after one tau
    assert ts[2] == pytest.approx(40.0 - 30.0 * math.exp(-3), rel=1e-12)
    assert ts[3] == pytest.approx(40.0, abs=1e-9)
    steady = G.steady_state_drift_deg_h(40.0, 0.001, end_c=35.0)
    assert steady == pytest.approx(0.001 + 2e-4 * 5.0)
    d = G.axial_drift_deg_h([60.0], knots, case, 0.001, end_c=35.0)
    assert d[0] == pytest.approx(steady, abs=1e-12)


def test_piecewise_ramp_matches_numerical_integration_and_rate_limit():
    knots, case = np.array([0.0, 4.0, 16.0]), np.array([12.0, 25.0, 35.0])
    t = np.linspace(0.0, 20.0, 81)
    sol = solve_ivp(
        lambda s, y: (np.interp(s, knots, case) - y) / G.lag_h,
        (0.0, 20.0),
        [12.0],
        t_eval=t,
        rtol=1e-10,
        atol=1e-10,
        max_step=0.01,
    )
    assert np.allclose(G.sensor_temperature_c(t, knots, case), sol.y[0], atol=1e-6)
    # on a long ramp the gradient settles to r tau: the rate term k_G tau dT/dt
    r = 2.0
    ramp = G.sensor_temperature_c([50.0], [0.0, 100.0], [0.0, 200.0])
    assert (2.0 * 50.0 - ramp[0]) == pytest.approx(r * G.lag_h, rel=1e-9)
    fast = tg.ThermalGyro(gradient_coeff_deg_h_per_c=1e-3 / 0.001, lag_h=0.001)
    cold = ins.ColdStart(
        align_temp_min_c=12, calib_temp_min_c=25, calib_temp_max_c=35, drift_per_c_h_deg_h=1e-3
    )
    th = np.linspace(5.0, 15.0, 11)
    kt, kc = tg.cold_start_knots(cold)
    assert np.allclose(
        fast.axial_drift_deg_h(th, kt, kc, 0.002), cold.axial_drift_deg_h(th, 0.002), atol=1e-8
    )


def test_identification_map_equals_the_simulator():
    m = tg.identification_map(ins.Earth())
    imu, init = ins.random_test(
        np.random.default_rng(7), axial_drift_deg_h=0.0, gyro_arw_deg_rt_h=0.0
    )
    kt, kc = tg.cold_start_knots(ins.ColdStart(12, 25, 35))
    ax = G.axial_drift_deg_h(m.t_mid_h, kt, kc, 0.001)
    run = ins.simulate(
        12.0, imu=imu, initial=init, axial_drift_deg_h=ax, t0_s=4 * 3600.0, seed=None
    )
    assert m.latitude_error_deg(ax, imu, init)[0] == pytest.approx(
        run.latitude_error_deg[-1], rel=1e-9
    )
    # a constant drift: the Table 1 gain
    assert m.axial.sum() == pytest.approx(ins.latitude_error_per_drift(12.0), rel=1e-3)
    assert m.noise_per_arw > 0


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"lag_h": 0.0}, "lag_h"),
        ({"temp_coeff_deg_h_per_c": float("nan")}, "temp_coeff_deg_h_per_c"),
        ({"gradient_coeff_deg_h_per_c": 5.0}, "gradient_coeff_deg_h_per_c"),
    ],
)
def test_bad_parameters_name_the_parameter(kwargs, name):
    with pytest.raises(InputError, match=name):
        tg.ThermalGyro(**kwargs)
    with pytest.raises(InputError, match="knots_h"):
        G.sensor_temperature_c([1.0], [0.0, 0.0], [1.0, 2.0])
