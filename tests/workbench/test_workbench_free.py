"""The reference-free magnetometer system (issue 23): fits, hidden effects named and quiet without one
(independent and AR(1) noise), calibrate -> apply round trip, a cross-check against an independent
ellipsoid fit, bad input, and the IGRF field at two sites against published values."""

import json

import numpy as np
import pandas as pd
import pytest

from navlib import commands
from navlib.cli import main
from navlib.errors import InputError
from navlib.sensors.earth_field import Site, igrf_field
from navlib.workbench import get_system
from navlib.workbench import free_simulation as FS
from navlib.workbench import magnetometer_free as MF
from navlib.workbench.local_field import field_check
from navlib.workbench.diagnose import diagnose
from navlib.workbench.fit import fit_model

TRUE = {
    "hard_x_ut": 6.0,
    "hard_y_ut": -4.0,
    "hard_z_ut": 2.5,
    "scale_x": 0.03,
    "scale_y": -0.02,
    "soft_xy": 0.015,
    "soft_xz": -0.02,
    "soft_yz": 0.01,
}
NOISE = 0.3


@pytest.fixture(scope="module")
def sim():
    """A 30 s hand-turned recording with hard iron and the full ellipsoid, no misalignment/temperature."""
    return FS.simulate_free(TRUE, duration_s=30.0, noise_ut=NOISE, seed=np.random.SeedSequence(23))


@pytest.fixture(scope="module")
def sim_file(sim, tmp_path_factory):
    p = tmp_path_factory.mktemp("free") / "sim.csv"
    sim.drop(columns=list(MF.DERIVED)).to_csv(p, index=False)
    return p


def test_registered_and_fits_the_truth(sim):
    assert get_system("magnetometer_free").catalogue is MF.FREE_EFFECTS
    f = fit_model("magnetometer_free", sim, ["hard_iron", "scale", "soft_iron"])
    assert f.n == 2 * len(sim)  # magnitude and dip residual per row
    assert f.rms == pytest.approx(NOISE, rel=0.1)
    for k, v in TRUE.items():
        assert f.params[k] == pytest.approx(v, abs=0.2 if k.startswith("hard") else 3e-3), k
    assert f.params["field_ut"] == pytest.approx(MF.SIM_FIELD_UT, abs=0.1)
    assert MF.field_summary(f)["dip (deg)"] == pytest.approx(MF.SIM_DIP_DEG, abs=0.2)
    # without the accelerometer: one residual per row, misalignment cannot be tested
    noacc = sim.drop(columns=list(MF.ACC) + ["field_gravity_ut"])
    d = diagnose(fit_model("magnetometer_free", noacc, ["hard_iron", "scale", "soft_iron"]))
    assert d.n == len(sim) and "misalignment" in d.untestable and d.consistent_with_noise


def _trials(rho, seeds, nulls):
    st = FS.hidden_effect_study(
        ratios=(3.0,),
        noises=(NOISE,),
        seeds=range(seeds),
        none_seeds=range(nulls),
        correlation=rho,
        duration_s=20.0,
    )
    named = st[st.hidden != "(none)"]
    quiet = st[st.hidden == "(none)"]
    return named, quiet


@pytest.mark.slow
def test_each_hidden_effect_named_and_quiet_without_one():
    named, quiet = _trials(0.0, 2, 3)
    assert set(named.hidden) == set(MF.FREE_EFFECTS)
    assert named.correct.astype(bool).all(), named[~named.correct.astype(bool)][["hidden", "named"]]
    assert quiet.correct.astype(bool).sum() >= len(quiet) - 1


@pytest.mark.slow
def test_hidden_effects_with_ar1_noise_of_correlation_09():
    # a few trials only; the full run is benchmarks/workbench_free_rates.py (rates in its docstring)
    named, quiet = _trials(0.9, 1, 2)
    assert named.correct.astype(bool).all(), named[["hidden", "named"]]
    assert quiet.correct.astype(bool).sum() >= len(quiet) - 1


@pytest.mark.slow
@pytest.mark.parametrize("seed", [5, 10])
def test_noise_model_on_the_sensor_axes_not_on_the_invariants(seed):
    """AR(1) noise of 0.9 on the axes, seen through the turning field direction: an AR model of the
    invariants' residuals runs to its bound (0.995) on these seeds -- the cause of the false alarms --
    while the projected model (the system's noise_directions hook) recovers the axes' correlation."""
    from navlib.workbench.screen import screen
    from navlib.workbench.serial import KAPPA_MAX, select, series_of

    d = FS.simulate_free(
        {"hard_x_ut": 5.0},
        duration_s=20.0,
        noise_ut=NOISE,
        noise_correlation=0.9,
        seed=np.random.SeedSequence(seed),
    )
    sc = screen(fit_model("magnetometer_free", d, ["hard_iron"]))
    ser = sc.noise.series
    assert ser.projection is not None and sc.noise.order == 1
    assert 0.85 < sc.noise.lag1 < 0.96
    # the AR model of each invariant in time (the series axis-major, as without a projection; the projected
    # series is time-major), on the same observations
    axis_major = series_of(sc.rich.data, sc.rich.n, sc.rich.system).without(
        ~np.isin(np.arange(sc.rich.n), ser.order)
    )
    ar = select(sc.rich.residuals, *sc.regressors, axis_major)
    assert ar.lag1 > KAPPA_MAX - 1e-3


def test_projected_whitening_is_the_inverse_of_colouring():
    from navlib.workbench.serial import Projection, Series, colour, whiten

    rng = np.random.default_rng(3)
    n = 40
    d = rng.standard_normal((2 * n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    order = np.arange(2 * n)  # a projected series is time-major (serial.with_projection)
    ser = Series(order, order, "time_s", Projection(d, np.repeat(np.arange(n, dtype=float), 2)))
    u = rng.standard_normal((2 * n, 5))
    x = colour(u, (0.8,), ser, 2 * n)
    assert np.allclose(whiten(x, (0.8,), ser), u)
    # the covariance it colours with: 0.8^|t_i - t_j| (d_i . d_j), e.g. observations 0 and 3 (rows 0, 1)
    cov = colour(np.eye(2 * n), (0.8,), ser, 2 * n)
    K = cov @ cov.T
    assert K[0, 3] == pytest.approx(0.8 * d[0] @ d[3]) and K[0, 0] == pytest.approx(1.0)
    # an irregular clock (block times with jitter): only kappa >= 0 is a valid correlation
    from dataclasses import replace
    from navlib.workbench.serial import regular_clock

    jittered = replace(
        ser, projection=Projection(d, np.repeat(np.arange(n) + 0.1 * rng.random(n), 2))
    )
    assert regular_clock(ser) and not regular_clock(jittered)
    assert np.allclose(whiten(colour(u, (0.8,), jittered, 2 * n), (0.8,), jittered), u)
    with pytest.raises(ValueError, match="regular clock"):
        colour(u, (-0.5,), jittered, 2 * n)


def _with_site(frame, **cols):
    out = frame.drop(columns=list(MF.DERIVED)).copy()
    for k, v in cols.items():
        out[k] = v
    return out


def test_site_and_date_from_the_data_columns(sim, tmp_path, capsys):
    site = MF.site_of(
        _with_site(sim, lat_deg=52.5, lon_deg=13.4, height_m=50.0, date="2021-01-01T10:00:00Z")
    )
    assert (site.lat_deg, site.lon_deg, site.height_m, site.date) == (
        52.5,
        13.4,
        50.0,
        "2021-01-01",
    )
    over = MF.site_of(
        _with_site(sim, lat_deg=52.5, lon_deg=13.4), site=(10.0, 20.0), date="2020-06-01"
    )
    assert (over.lat_deg, over.lon_deg, over.height_m, over.date) == (10.0, 20.0, 0.0, "2020-06-01")
    assert MF.site_of(_with_site(sim)) is None
    p = tmp_path / "site.csv"
    _with_site(sim, lat_deg=52.5, lon_deg=13.4, height_m=50.0, date="2021-01-01").to_csv(
        p, index=False
    )
    out = tmp_path / "cal.json"
    assert main(["calibrate", "magnetometer", str(p), "--out", str(out)]) == 0
    field = json.loads(out.read_text())["field"]
    assert field["model"]["lat_deg"] == 52.5 and field["model"]["date"] == "2021-01-01"
    assert field["model"]["intensity_ut"] == pytest.approx(
        igrf_field(Site(52.5, 13.4, 50.0, "2021-01-01")).intensity_ut
    )
    assert "model (IGRF-14" in capsys.readouterr().out
    # inconsistent or impossible values: one line, exit 2, naming the column
    lat = np.full(len(sim), 52.5)
    lat[7] = 52.9
    for cols, says in (
        (dict(lat_deg=lat, lon_deg=13.4), "'lat_deg' varies by 0.4 deg"),
        (dict(lat_deg=95.0, lon_deg=13.4), "'lat_deg', row 1"),
        (dict(lat_deg=52.5), "'lat_deg' without 'lon_deg'"),
        (dict(lat_deg=52.5, lon_deg=13.4, date="today"), "column 'date', row 1"),
        (
            dict(lat_deg=52.5, lon_deg=13.4, date=np.where(lat > 52.6, "2023-05-01", "2021-01-01")),
            "'date' spans 850 days",
        ),
    ):
        _with_site(sim, **cols).to_csv(p, index=False)
        assert main(["calibrate", "magnetometer", str(p), "--out", str(tmp_path / "no.json")]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and says in err, err


def test_the_cli_loop_has_no_per_system_branch(monkeypatch, sim, tmp_path, capsys):
    """The end-of-loop field report is the system's ``final_check`` hook; a system without one refuses
    --site in one line."""
    import inspect

    assert "magnetometer_free" not in inspect.getsource(commands._loop)
    assert get_system("magnetometer_free").final_check is MF.loop_field_check
    assert get_system("compass").final_check is None
    assert main(["loop", "compass", "whatever.csv", "--site", "50,10"]) == 2
    assert "makes no field check" in capsys.readouterr().err


def test_calibrate_apply_round_trip_and_uncertainties(sim, sim_file, tmp_path, capsys):
    cal_path, out = tmp_path / "cal.json", tmp_path / "corrected.csv"
    assert main(["calibrate", "magnetometer", str(sim_file), "--out", str(cal_path)]) == 0
    cal = json.loads(cal_path.read_text())
    mc = cal["magcal"]
    b, A = np.array(mc["b_ut"]), np.array(mc["A"])
    # the truth within 4 of the reported standard errors
    b_true = np.array([TRUE["hard_x_ut"], TRUE["hard_y_ut"], TRUE["hard_z_ut"]])
    assert np.all(np.abs(b - b_true) < 4 * np.array(mc["b_std_ut"]))
    A_true = MF.correction_matrix(TRUE)
    assert np.all(np.abs(A - A_true) < 4 * np.array(mc["A_std"]) + 1e-12)
    assert main(["apply", str(cal_path), str(sim_file), "--out", str(out)]) == 0
    corr = pd.read_csv(out)
    u = corr[list(MF.MAG)].to_numpy()
    assert (
        np.sqrt(np.mean((np.linalg.norm(u, axis=1) - mc["expected_field_strength_ut"]) ** 2))
        < 1.2 * NOISE
    )
    # the corrected field is the true body field to the noise (no misalignment simulated)
    true_u = (sim[list(MF.MAG)].to_numpy() - b_true) @ A_true.T
    noise_free = FS.simulate_free(
        TRUE, duration_s=30.0, noise_ut=0.0, seed=np.random.SeedSequence(23)
    )
    v = (noise_free[list(MF.MAG)].to_numpy() - b_true) @ A_true.T
    assert np.sqrt(np.mean((u - v) ** 2)) < 1.2 * np.sqrt(np.mean((true_u - v) ** 2))
    assert (
        main(["apply", str(cal_path), str(sim_file), "--out", str(out)]) == 2
    )  # never overwritten
    assert "already exists" in capsys.readouterr().err


def _algebraic_ellipsoid(m):
    """Independent peer: the quadric x'Qx + 2 p'x = 1 by plain least squares; centre c = -Q^-1 p; the
    symmetric correction mapping the ellipsoid onto the unit sphere is sqrtm(Q / (1 + c'Qc))."""
    x, y, z = m.T
    D = np.column_stack([x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z, 2 * x, 2 * y, 2 * z])
    v = np.linalg.lstsq(D, np.ones(len(m)), rcond=None)[0]
    Q = np.array([[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]])
    c = -np.linalg.solve(Q, v[6:])
    Q = Q / (1 + c @ Q @ c)
    w, U = np.linalg.eigh(Q)
    return c, U @ np.diag(np.sqrt(w)) @ U.T


def test_agrees_with_an_independent_ellipsoid_fit(sim):
    from navlib.workbench.calibration import calibrate

    mc = calibrate(sim.drop(columns=list(MF.ACC) + ["field_gravity_ut"]))["magcal"]
    c, W = _algebraic_ellipsoid(sim[list(MF.MAG)].to_numpy())
    assert np.allclose(mc["b_ut"], c, atol=0.15)
    assert np.allclose(
        np.array(mc["A"]) / mc["expected_field_strength_ut"], W, atol=3e-3 / MF.SIM_FIELD_UT * 10
    )


def test_bad_input_one_line_exit_2(sim, tmp_path, capsys):
    raw = sim.drop(columns=list(MF.DERIVED))

    def run(frame, *extra):
        p = tmp_path / "bad.csv"
        frame.to_csv(p, index=False)
        rc = main(
            ["calibrate", "magnetometer", str(p), "--out", str(tmp_path / "never.json"), *extra]
        )
        err = capsys.readouterr().err.strip()
        assert rc == 2 and len(err.splitlines()) == 1, err
        p.unlink()
        return err

    nt = raw.copy()
    nt[list(MF.MAG)] *= 1000.0
    assert "look like nT" in run(nt)
    gauss = raw.copy()
    gauss[list(MF.MAG)] /= 100.0
    assert "gauss" in run(gauss)
    g = raw.copy()
    g[list(MF.ACC)] /= MF.G0
    assert "look like g" in run(g)
    flat = raw.copy()
    t = np.linspace(0, 2 * np.pi, len(flat))
    flat["mag_x_ut"], flat["mag_y_ut"], flat["mag_z_ut"] = (
        40 * np.cos(t),
        40 * np.sin(t),
        5 + 0.01 * t,
    )
    # a circle of directions: enough 30-deg cells, no spread out of its plane; only what failed is named
    assert MF.orientation_cells(flat) >= MF.MIN_ORIENTATIONS
    said = run(flat)
    assert (
        "smallest spread of the field's directions" in said and "distinct orientations" not in said
    )
    assert "unknown magnetometer_free effect" in run(raw, "--model", "hard_iron,wobble")
    few = raw.iloc[::12]  # 25 rows: too few for the loader
    assert "rows" in run(few)
    # a calibration of another system
    other = tmp_path / "other.json"
    other.write_text(
        json.dumps({"format": "navlib calibration", "version": 1, "system": "compass"})
    )
    src = tmp_path / "ok.csv"
    raw.to_csv(src, index=False)
    assert main(["apply", str(other), str(src), "--out", str(tmp_path / "x.csv")]) == 2
    assert "a calibration of the system 'compass'" in capsys.readouterr().err
    # too few distinct orientations for a model with more parameters than cells
    part = sim.iloc[:40]
    with pytest.raises(InputError, match="distinct orientations") as err:
        MF.check_orientations(part, "part", needed=MF.orientation_cells(part) + 1)
    assert (MF.orientation_spread(part) >= MF.MIN_SPREAD) == ("spread" not in str(err.value))


# IGRF: published values of the NOAA/NCEI geomagnetic calculator (model IGRF2020, calculator 0.5.1.11) at
# 2020-01-01, 5 km above the WGS84 ellipsoid, as stored in ppigrf's test data
# (github.com/klaundal/ppigrf, test/data/2020-01-01/b_n.csv, b_e.csv, b_z.csv), nT: north, east, down.
PUBLISHED = {(60.0, 10.0): (15063.0, 920.3, 48911.3), (-30.0, 150.0): (26417.7, 5070.0, -47914.2)}


@pytest.mark.parametrize("lat, lon", list(PUBLISHED))
def test_igrf_at_two_sites_against_published_values(lat, lon):
    f = igrf_field(Site(lat, lon, 5000.0, "2020-01-01"))
    n, e, d = (v / 1000.0 for v in PUBLISHED[(lat, lon)])
    assert abs(f.north_ut - n) < 0.1 and abs(f.east_ut - e) < 0.1 and abs(f.down_ut - d) < 0.1
    assert f.intensity_ut == pytest.approx(np.sqrt(n * n + e * e + d * d), abs=0.1)


def test_igrf_ships_offline_and_bad_site():
    import importlib.resources

    assert importlib.resources.files("ppigrf").joinpath("IGRF14.shc").is_file()
    with pytest.raises(InputError, match="lat_deg"):
        Site(91.0, 0.0)
    with pytest.raises(InputError, match="date"):
        Site(50.0, 0.0, 0.0, "2040-01-01")


def test_field_check_flags_an_anomaly_and_not_the_model_field(sim):
    site = Site(52.5, 13.4, 50.0, "2021-01-01")
    model = igrf_field(site)
    same = FS.simulate_free(
        TRUE,
        duration_s=20.0,
        noise_ut=NOISE,
        field_ut=model.intensity_ut,
        dip_deg=model.dip_deg,
        seed=np.random.SeedSequence(231),
    )
    ok = field_check(
        fit_model("magnetometer_free", same, ["hard_iron", "scale", "soft_iron"]), site
    )
    assert not ok["local_anomaly"] and "agrees" in ok["message"]
    assert abs(ok["intensity_difference_ut"]) < 3 * ok["intensity_std_ut"] + 0.05
    assert abs(ok["dip_difference_deg"]) < 3 * ok["dip_std_deg"] + 0.05
    # BROAD's room field (43.5 uT, dip 69.6 deg) is not the IGRF field there: flagged
    far = field_check(
        fit_model("magnetometer_free", sim, ["hard_iron", "scale", "soft_iron"]), site
    )
    assert far["local_anomaly"] and "local anomaly" in far["message"]


def test_an_accelerated_sensor_is_warned_about(sim, tmp_path, capsys):
    """The dip constraint takes a/|a| for the vertical: a recording whose accelerometer saw more than gravity
    (fast hand motion) gets a warning in the calibration and on stderr; a still or slowly turned one none."""
    assert MF.accelerometer_motion(sim) is None
    moved = sim.copy()
    rng = np.random.default_rng(3)
    jolt = rng.random(len(moved)) < 0.3
    moved.loc[jolt, list(MF.ACC)] += rng.normal(0, 4.0, (int(jolt.sum()), 3))
    said = MF.accelerometer_motion(moved)
    assert said is not None and "accelerated" in said and "acc_x_ms2" in said
    src = tmp_path / "moved.csv"
    moved.drop(columns=list(MF.DERIVED)).to_csv(src, index=False)
    capsys.readouterr()
    assert main(["calibrate", "magnetometer", str(src), "--out", str(tmp_path / "cal.json")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("navlib calibrate: warning: columns acc_x_ms2")
    assert json.loads((tmp_path / "cal.json").read_text())["warnings"] == [said]
