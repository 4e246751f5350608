"""Physics of the compass simulator and the exact planar model."""

from dataclasses import replace

import numpy as np
import pytest

from navlib.angles import wrap_deg

from navlib.data.compass_sweeps import load_sweeps, unwrap_measured
from navlib.paths import data_path

from navlib.sensors.compass import (
    COMPASS_SITE,
    NO_ERRORS,
    PAPER_A_EARTH,
    CompassErrors,
    EarthField,
    SweepConfig,
    simulate_sweep,
    simulate_train_test,
)

from navlib.sensors.planar import PlanarModel, fit_planar_model


def harmonics(err_deg):
    """Amplitudes of the 0th, 1st, 2nd, 3rd harmonics of an error curve over one revolution (120 points)."""
    e = np.asarray(err_deg)[:120]
    c = np.fft.rfft(e) / len(e)
    return np.abs(c[:4]) * np.array([1, 2, 2, 2])


def test_wrap_deg_range():
    w = wrap_deg([-540, -180, -179.5, 0, 180, 181, 359, 720.25])
    assert np.allclose(w, [180, 180, -179.5, 0, 180, -179, -1, 0.25])
    assert np.all((w > -180) & (w <= 180))


def test_no_errors_no_heading_error():
    d = simulate_sweep(NO_ERRORS)
    assert len(d) == 121
    assert d.true_heading_deg.iloc[0] == 0 and d.true_heading_deg.iloc[-1] == 360
    assert np.max(np.abs(d.heading_error_deg)) < 1e-9


def test_pure_hard_iron_gives_one_cycle_error():
    err = replace(NO_ERRORS, hard_iron_ut=(1.5, -2.0, 5.0))
    a = harmonics(simulate_sweep(err).heading_error_deg)
    assert a[1] > 2.0  # ~ |h|/H = 2.5/27 rad = 5.3 deg
    assert a[1] > 20 * max(a[0], a[2], a[3])
    # first order: delta = asin(h_perp / H); its amplitude is |h_xy| / H radians
    H = EarthField().horizontal_ut
    assert a[1] == pytest.approx(np.degrees(2.5 / H), rel=0.02)


def test_pure_soft_iron_gives_two_cycle_error():
    err = replace(NO_ERRORS, soft_iron=((0.05, 0.0, 0.0), (0.0, -0.05, 0.0), (0.0, 0.0, 0.0)))
    a = harmonics(simulate_sweep(err).heading_error_deg)
    assert a[2] > 2.0
    assert a[1] < 1e-9 and a[0] < 1e-9 and a[3] < 1e-9


def test_yaw_misalignment_gives_constant_error():
    err = replace(NO_ERRORS, misalignment_deg=(0.0, 0.0, 2.0))
    e = simulate_sweep(err).heading_error_deg
    assert np.allclose(e, 2.0, atol=1e-9)  # sensor x axis turned 2 deg clockwise reads 2 deg more


def test_default_story_spans_paper_range():
    d = simulate_train_test(earth=PAPER_A_EARTH)
    for _, part in d.groupby("sweep"):
        assert -17.0 < part.heading_error_deg.min() < -15.0
        assert 29.5 < part.heading_error_deg.max() < 32.0


def test_sweeps_are_deterministic_and_independent():
    a, b = simulate_train_test(seed=7), simulate_train_test(seed=7)
    assert np.array_equal(a.to_numpy(), b.to_numpy())
    n1 = (
        a[a.sweep == 1].mag_x_ut.to_numpy()
        - simulate_sweep(replace(CompassErrors(), noise_ut=0)).mag_x_ut
    )
    n2 = (
        a[a.sweep == 2].mag_x_ut.to_numpy()
        - simulate_sweep(replace(CompassErrors(), noise_ut=0)).mag_x_ut
    )
    assert abs(np.corrcoef(n1, n2)[0, 1]) < 0.3  # independent noise
    assert 0.02 < np.std(n1) < 0.06


def test_temperature_drift_of_hard_iron_changes_error_along_sweep():
    err = replace(NO_ERRORS, hard_iron_tc_ut_per_c=(0.0, 0.2, 0.0))
    cfg = SweepConfig(temperature_rate_c_per_point=0.1)
    d = simulate_sweep(err, config=cfg)
    assert d.temperature_c.iloc[-1] == pytest.approx(20 + 12.0)
    assert np.abs(d.heading_error_deg).max() > 1.0
    assert np.abs(simulate_sweep(err).heading_error_deg).max() < 1e-9  # no warming, no error


def test_glitches_are_injected_and_flagged():
    d = simulate_sweep(config=SweepConfig(glitch_prob=0.1), seed=3)
    assert 3 <= d.glitch.sum() <= 25
    clean = simulate_sweep(seed=3)
    moved = np.linalg.norm(
        d[["mag_x_ut", "mag_y_ut", "mag_z_ut"]].to_numpy()
        - clean[["mag_x_ut", "mag_y_ut", "mag_z_ut"]].to_numpy(),
        axis=1,
    )
    assert np.all(moved[d.glitch == 1] > 10)


def test_gravity_is_in_sensor_frame():
    d = simulate_sweep(
        replace(NO_ERRORS, misalignment_deg=(2.0, 0.0, 0.0)),
        config=SweepConfig(gravity_noise_ms2=0.0),
    )
    g = d[["acc_x_ms2", "acc_y_ms2", "acc_z_ms2"]].to_numpy()
    assert np.allclose(np.linalg.norm(g, axis=1), 9.8)
    assert abs(g[0, 1]) == pytest.approx(9.8 * np.sin(np.radians(2.0)), rel=1e-6)


def test_planar_model_is_exact_for_the_3d_simulator():
    """On a level table the full 3-D error model collapses to the 5-parameter planar model: its fit to a
    noiseless sweep leaves no residual, and its inverse recovers the true heading."""
    d = simulate_sweep(replace(CompassErrors(), noise_ut=0.0))
    model = fit_planar_model(d.true_heading_deg, d.measured_heading_deg)
    assert np.max(np.abs(model.predict_error(d.true_heading_deg) - d.heading_error_deg)) < 1e-6
    back = wrap_deg(model.correct(d.measured_heading_deg) - d.true_heading_deg)
    assert np.max(np.abs(back)) < 1e-6


def test_planar_model_recovers_its_parameters_and_inverts():
    true = PlanarModel(
        params={"yaw_deg": 1.5, "hard_x": 0.2, "hard_y": -0.3, "soft_e": 0.04, "soft_f": -0.02}
    )
    psi = np.arange(0, 360, 3.0)
    fit = fit_planar_model(psi, true.predict_measured(psi))
    for k, v in true.params.items():
        assert fit.params[k] == pytest.approx(v, abs=1e-7)
    assert np.max(np.abs(wrap_deg(true.correct(true.predict_measured(psi)) - psi))) < 1e-9


def test_planar_model_subset_holds_others_at_zero():
    m = fit_planar_model(
        np.arange(0, 360, 10.0), np.arange(0, 360, 10.0) + 2.0, effects=("misalignment",)
    )
    assert m.full_params()["hard_x"] == 0.0
    assert m.params["yaw_deg"] == pytest.approx(
        2.0, abs=1e-6
    )  # a yaw misalignment is a constant offset


def test_unwrap_measured_is_continuous():
    d = simulate_sweep()
    x = unwrap_measured(d.true_heading_deg, d.measured_heading_deg)
    assert np.all(np.diff(x) > 0)
    assert abs(x[0] - d.true_heading_deg.iloc[0]) < 180
    assert x[-1] - x[0] == pytest.approx(360, abs=1)


def test_error_parameters_are_validated():
    from navlib.errors import InputError

    with pytest.raises(InputError, match="noise_ut"):
        simulate_sweep(replace(CompassErrors(), noise_ut=-1))
    with pytest.raises(InputError, match="hard_iron_ut"):
        simulate_sweep(replace(CompassErrors(), hard_iron_ut=(1, 2)))
    with pytest.raises(InputError, match="glitch_prob"):
        simulate_sweep(config=SweepConfig(glitch_prob=2))


def test_stored_sweeps_are_what_the_simulator_produces():
    """data/compass_sweeps.csv is regenerated by code (seed 2024, default compass), not pasted."""
    stored = load_sweeps(data_path("compass_sweeps.csv"))
    fresh = simulate_train_test(earth=PAPER_A_EARTH, seed=2024)
    assert list(stored.columns) == list(fresh.columns) and len(stored) == len(fresh)
    np.testing.assert_allclose(stored.to_numpy(float), fresh.to_numpy(float), rtol=0, atol=1e-6)
    other = simulate_train_test(earth=PAPER_A_EARTH, seed=2025)
    assert not np.allclose(stored.measured_heading_deg, other.measured_heading_deg, atol=1e-6)


def test_the_planar_jacobian_equals_central_differences():
    """``PlanarModel.jacobian`` (exact derivatives of the measured heading) against central differences of
    ``predict_measured``, every parameter, away from zero, with a temperature drift."""
    from navlib.sensors.planar import PLANAR_EFFECTS, PlanarModel

    rng = np.random.default_rng(np.random.SeedSequence(18, spawn_key=(7,)))
    effects = tuple(PLANAR_EFFECTS)
    names = [n for e in effects for n in PLANAR_EFFECTS[e]]
    p0 = dict(zip(names, [3.0, 0.3, -0.2, 0.1, -0.05, 0.01, -0.02]))
    true = rng.uniform(0, 360, 200)
    temp = rng.uniform(-10, 40, 200)
    J = PlanarModel(effects, p0, 15.0).jacobian(true, names, temp)
    for j, name in enumerate(names):
        h = 1e-6
        up = PlanarModel(effects, {**p0, name: p0[name] + h}, 15.0).predict_measured(true, temp)
        dn = PlanarModel(effects, {**p0, name: p0[name] - h}, 15.0).predict_measured(true, temp)
        fd = wrap_deg(up - dn) / (2 * h)
        np.testing.assert_allclose(J[:, j], fd, rtol=1e-5, atol=1e-7, err_msg=name)


def test_default_field_is_igrf_at_the_stated_site():
    """The simulator's default field is IGRF-14 at COMPASS_SITE (no typed numbers); paper A keeps its
    round 54 uT / 60 deg explicitly, and a sweep's field follows the EarthField it is given."""
    from navlib.sensors.earth_field import igrf_field

    model = igrf_field(COMPASS_SITE)
    e = EarthField()
    assert (e.total_ut, e.dip_deg) == (model.intensity_ut, model.dip_deg)
    assert 50.0 < e.total_ut < 60.0 and 55.0 < e.dip_deg < 65.0  # Shenyang, about 54 uT at 60 deg
    assert (PAPER_A_EARTH.total_ut, PAPER_A_EARTH.dip_deg) != (e.total_ut, e.dip_deg)
    z = simulate_sweep(NO_ERRORS).mag_z_ut.to_numpy()
    assert np.allclose(z, e.vertical_ut) and np.allclose(
        simulate_sweep(NO_ERRORS, PAPER_A_EARTH).mag_z_ut, PAPER_A_EARTH.vertical_ut
    )
