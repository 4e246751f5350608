"""navlib.sensors.ins: static-base error model of the single-axis rotation INS and Table 1 of paper C."""

import math

import numpy as np
import pytest

from navlib.errors import InputError
from navlib.angles import ARCSEC, DEG
from navlib.sensors.ins import (
    ColdStart,
    Earth,
    ImuErrors,
    InitialErrors,
    Procedure,
    Rotation,
    drift_from_latitude_error,
    latitude_error_per_drift,
    run_procedure,
    simulate,
    system_matrices,
    table1_latitude_error,
)

NO_ROT = Rotation(kind="none")


def _zero_crossing_period_min(t_h, y):
    s = np.signbit(y)
    idx = np.flatnonzero(s[1:] != s[:-1])
    # linear interpolation of each crossing time
    tc = t_h[idx] - y[idx] * (t_h[idx + 1] - t_h[idx]) / (y[idx + 1] - y[idx])
    return 2 * np.mean(np.diff(tc)) * 60.0


def test_schuler_period_from_the_model_and_from_a_run():
    e = Earth()
    assert e.schuler_period_min == pytest.approx(84.4, abs=0.3)
    A, _ = system_matrices(e)
    f = np.sort(np.abs(np.linalg.eigvals(A).imag))  # rad/s
    W = e.earth_rate_rad_s
    assert f[1] == pytest.approx(W, rel=1e-3)  # the 24 h Earth-rate mode
    # the Schuler pair is split by Foucault coupling: w_s -/+ W sin L
    assert f[3] == pytest.approx(e.schuler_rad_s - W * math.sin(e.lat_rad), rel=2e-3)
    assert f[5] == pytest.approx(e.schuler_rad_s + W * math.sin(e.lat_rad), rel=2e-3)
    # time domain: an initial north velocity error oscillates with the Schuler period
    r = simulate(6.0, initial=InitialErrors(vel_north_m_s=0.1), rotation=NO_ROT, step_s=10.0)
    assert _zero_crossing_period_min(r.t_h, r.states[:, 4]) == pytest.approx(84.4, abs=0.6)


def test_axial_drift_gives_24h_earth_rate_oscillation_matching_table1():
    eps = 0.001
    r = simulate(48.0, imu=ImuErrors(axial_drift_deg_h=eps), rotation=NO_ROT, step_s=60.0)
    lat = r.latitude_error_deg
    peak = np.argmax(lat[: len(lat) // 2])
    assert r.t_h[peak] == pytest.approx(12.0, abs=0.3)
    assert abs(r.at(24.0)[5] / DEG) < 0.01 * lat.max()
    assert r.at(36.0)[5] / DEG == pytest.approx(lat[peak], rel=0.01)
    cf = table1_latitude_error(r.t_h, axial_drift_deg_h=eps)
    assert np.max(np.abs(lat - cf)) < 0.01 * np.max(cf)
    # sanity value of the notes: 0.001 deg/h -> 0.0067 deg after 12 h, ~0.6 nmi per day
    assert r.at(12.0)[5] / DEG == pytest.approx(0.0067, abs=0.0001)
    assert r.position_error_nmi[-1] / 2.0 == pytest.approx(0.6, abs=0.05)


def test_table1_sine_terms_vanish_at_12h():
    e = Earth()
    for init in (InitialErrors(azimuth_arcsec=60.0), InitialErrors(vel_north_m_s=0.1)):
        r = simulate(24.0, initial=init, rotation=NO_ROT, step_s=30.0)
        assert abs(r.at(12.0)[5]) < 0.05 * np.max(np.abs(r.states[:, 5]))
    # the azimuth term's 24 h part: -phi_U cos L sin(W t), peak at 6 h
    r = simulate(24.0, initial=InitialErrors(azimuth_arcsec=60.0), rotation=NO_ROT, step_s=30.0)
    assert r.at(18.0)[5] / DEG == pytest.approx(
        float(table1_latitude_error(18.0, azimuth_error_arcsec=60.0)), rel=0.2
    )
    assert r.at(6.0)[5] / ARCSEC == pytest.approx(-60 * math.cos(e.lat_rad), rel=0.2)


def test_inverse_of_table1():
    k = latitude_error_per_drift(12.0)
    # 2 cos L / W up to 12 h not being exactly half a sidereal day
    assert k == pytest.approx(
        2 * math.cos(28.222 * DEG) / 7.2921151467e-5 * DEG / 3600 / DEG, rel=1e-4
    )
    assert k == pytest.approx(6.713, abs=0.001)
    eps = np.array([-0.0034, 0.0003, 0.0022])
    lat = table1_latitude_error(12.0, axial_drift_deg_h=eps[:, None])[:, 0]
    np.testing.assert_allclose(drift_from_latitude_error(lat), eps, rtol=1e-12)
    with pytest.raises(InputError, match="t_h"):
        drift_from_latitude_error(0.01, t_h=24.0)


def test_rotation_modulates_horizontal_gyro_bias_but_not_axial_drift():
    imu = ImuErrors(gyro_bias_x_deg_h=0.01)
    fixed = simulate(72.0, imu=imu, rotation=NO_ROT).position_error_nmi.max()
    rot = simulate(72.0, imu=imu, rotation=Rotation()).position_error_nmi.max()
    cont = simulate(
        72.0, imu=imu, rotation=Rotation(kind="continuous", rate_deg_s=0.5)
    ).position_error_nmi.max()
    assert fixed > 1.0
    assert rot < 0.05 * fixed and cont < 0.05 * fixed
    # the nav-frame forcing of a body-x bias averages to zero over one indexing cycle
    cs, sn = Rotation().mean_cos_sin(0.0, 20, 60.0)
    assert abs(cs.mean()) < 1e-12 and abs(sn.mean()) < 1e-12
    # same for an accelerometer bias
    acc = ImuErrors(accel_bias_x_ug=50.0)
    assert (
        simulate(72.0, imu=acc, rotation=Rotation()).position_error_nmi.max()
        < 0.2 * simulate(72.0, imu=acc, rotation=NO_ROT).position_error_nmi.max()
    )
    # the axial drift is not modulated: identical with and without rotation
    ax = ImuErrors(axial_drift_deg_h=0.002)
    np.testing.assert_allclose(
        simulate(72.0, imu=ax, rotation=Rotation()).states,
        simulate(72.0, imu=ax, rotation=NO_ROT).states,
        atol=1e-15,
    )


def test_angle_random_walk_grows_with_the_square_root_of_time():
    # white rate noise of N deg/sqrt(h) on every gyro: well inside a Schuler period each attitude error is a
    # random walk whose standard deviation over many seeds is N sqrt(t), whatever the simulator step
    # (over hours the Schuler loop bounds the level errors and feeds part of them into the azimuth)
    arw = 3e-4
    imu = ImuErrors(gyro_arw_deg_rt_h=arw)
    for step_s in (10.0, 60.0):
        runs = (
            np.array(
                [
                    simulate(1 / 3, imu=imu, rotation=NO_ROT, step_s=step_s, seed=s).states[:, :3]
                    for s in range(400)
                ]
            )
            / DEG
        )  # phi_E, phi_N, phi_U in deg
        t_h = np.arange(runs.shape[1]) * step_s / 3600.0
        sd = runs.std(axis=0)
        for t in (5 / 60, 10 / 60, 20 / 60):
            k = int(np.argmin(np.abs(t_h - t)))
            assert sd[k, 2] == pytest.approx(arw * math.sqrt(t), rel=0.1), (step_s, t)
        k5, k30 = int(np.argmin(np.abs(t_h - 5 / 60))), int(np.argmin(np.abs(t_h - 20 / 60)))
        np.testing.assert_allclose(
            sd[k5], arw * math.sqrt(5 / 60), rtol=0.1
        )  # all three axes at 5 min
        assert sd[k30, 2] / sd[k5, 2] == pytest.approx(2.0, rel=0.12)  # sqrt(20 min / 5 min)
        assert abs(runs[:, k30, 2].mean()) < 4 * sd[k30, 2] / math.sqrt(400)  # zero mean


def test_position_error_for_another_compensation_equals_a_rerun():
    # ProcedureResult.position_error_nmi_for (Fig 4, Table 5) against the simulator re-run with that compensation
    imu = ImuErrors(
        gyro_bias_x_deg_h=0.002,
        axial_drift_deg_h=0.0022,
        accel_bias_y_ug=15.0,
        gyro_arw_deg_rt_h=3e-4,
    )
    init = InitialErrors(tilt_east_arcsec=1.0, azimuth_arcsec=8.0, vel_north_m_s=0.01)
    cold = ColdStart(
        align_temp_min_c=25, calib_temp_min_c=40, calib_temp_max_c=57, drift_per_c_h_deg_h=0.001
    )
    base = run_procedure(None, imu=imu, initial=init, cold=cold, seed=5)
    for c in (0.0, 0.0015, 0.0022, -0.001):
        rerun = run_procedure(lambda lat, c=c: c, imu=imu, initial=init, cold=cold, seed=5)
        np.testing.assert_allclose(
            base.position_error_nmi_for(c), rerun.after.position_error_nmi, rtol=1e-9, atol=1e-9
        )
    # and it is not just the identified run: another compensation gives another history
    assert np.max(np.abs(base.position_error_nmi_for(0.0) - base.after.position_error_nmi)) > 0.5


def test_noise_is_seeded():
    imu = ImuErrors(axial_drift_deg_h=0.001, gyro_arw_deg_rt_h=3e-4)
    a, b, c = (simulate(12.0, imu=imu, seed=s).states for s in (1, 1, 2))
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_procedure_identifies_pure_axial_drift_and_true_drift_definition():
    imu = ImuErrors(axial_drift_deg_h=-0.0034)
    res = run_procedure(None, imu=imu)
    assert res.identified_drift_deg_h == pytest.approx(-0.0034, rel=0.01)
    assert res.max_error_after_nmi < 0.05
    assert res.max_error_before_nmi == pytest.approx(1.8 * 3.4, rel=0.1)
    assert res.best_drift_deg_h == pytest.approx(-0.0034, abs=1e-6)
    # a custom identification that is off by 0.0005 deg/h leaves ~0.9 nmi / 72 h
    off = run_procedure(lambda lat: -0.0029, imu=imu)
    assert off.max_error_after_nmi == pytest.approx(0.9, abs=0.1)


def test_cold_start_temperature_history_biases_the_identification():
    cold = ColdStart(
        align_temp_min_c=25, calib_temp_min_c=40, calib_temp_max_c=57, drift_per_c_h_deg_h=0.001
    )
    assert cold.temperature_c([0, 4, 16, 30]).tolist() == [25, 40, 57, 57]
    assert cold.rate_c_h([1, 10, 20]).tolist() == pytest.approx([15 / 4, 17 / 12, 0.0])
    imu = ImuErrors(axial_drift_deg_h=0.001)
    hot = run_procedure(None, imu=imu)
    res = run_procedure(None, imu=imu, cold=cold)
    # during the window the drift is 0.001 + 0.001 * 17/12 deg/h; the 12 h estimate sees that
    assert res.identified_drift_deg_h - hot.identified_drift_deg_h == pytest.approx(
        0.001 * 17 / 12, rel=0.02
    )
    assert res.max_error_after_nmi > 1.0 > hot.max_error_after_nmi


@pytest.mark.parametrize(
    "make, fragment",
    [
        (lambda: Rotation(kind="spin"), "rotation kind"),
        (lambda: simulate(12.0, rotation=Rotation(dwell_s=90.0)), "dwell_s"),
        (lambda: simulate(-1.0), "duration_h"),
        (lambda: ImuErrors(gyro_arw_deg_rt_h=-1.0), "gyro_arw_deg_rt_h"),
        (lambda: Earth(latitude_deg=95.0), "latitude_deg"),
        (lambda: Procedure(navigate_h=0.0), "navigate_h"),
        (
            lambda: ColdStart(
                align_temp_min_c=float("nan"), calib_temp_min_c=1, calib_temp_max_c=2
            ),
            "align_temp_min_c",
        ),
    ],
)
def test_bad_parameters(make, fragment):
    with pytest.raises(InputError, match=fragment):
        make()
