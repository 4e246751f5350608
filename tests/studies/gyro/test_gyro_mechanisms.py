"""navlib.studies.gyro.mechanisms: centres against basis functions (C14), the axial drift's share of the 12 h
latitude error (C16) and of the 72 h position error with rotation on (C18)."""

import math

import numpy as np
import pytest

from navlib import claims as reg
from navlib.claims import Claim
from navlib import verdicts
from navlib.errors import InputError
from navlib.sensors import ins
from navlib.studies import gyro
from navlib.studies.gyro import mechanisms as mech
from navlib.studies.gyro.networks import _hot_loo_errors

P = gyro.StudyParams()


@pytest.fixture(scope="module")
def written():
    return {c.key: c for c in mech.mechanism_claims(P)}


# ---------------------------------------------------------------------------------------------------- C14
def test_kmeans_finds_two_separated_clusters():
    x = np.r_[np.linspace(0.0, 1.0, 5), np.linspace(10.0, 11.0, 5)][:, None]
    c = np.sort(mech.kmeans_centres(x, 2)[:, 0])
    assert c == pytest.approx([0.5, 10.5])
    with pytest.raises(InputError):
        mech.kmeans_centres(x, 11)


def test_spread_difference_by_hand():
    # columns: 4 bases (RMS 1, 2, 1, 1), k-means (RMS 5), random (RMS 1 and 3: median 2)
    e = np.ones((4, 7)) * np.array([1.0, 2.0, 1.0, 1.0, 5.0, 1.0, 3.0])
    assert mech.spread_difference(e, 4, 5) == pytest.approx((5 - 1) - (2 - 1))
    assert mech.spread_difference(e[:, :5], 4, None) == pytest.approx(4 - 1)


@pytest.mark.parametrize(
    "centre_scale, basis_scale, verdict",
    [(3.0, 1.0, "reproduced"), (1.0, 3.0, "not reproduced"), (1.0, 1.0, "cannot be judged")],
)
def test_centre_claims_follow_constructed_errors(monkeypatch, centre_scale, basis_scale, verdict):
    rng = np.random.default_rng(1)
    base = rng.normal(0.0, 1e-4, 16)
    runs = mech.CentreBasisErrors(
        basis=np.c_[base, base, base, basis_scale * base],
        kmeans=centre_scale * base,
        random=np.c_[base, base, base],
        neurons=np.full(16, 2),
    )
    monkeypatch.setattr(
        mech, "_c14_runs", lambda params: dict.fromkeys(("primary", "deg", "rss"), runs)
    )
    c = {k.key: k for k in mech.centre_claims(P)}["gyro_centres"]
    assert c.verdict == verdict


def test_centre_basis_errors_gaussian_column_is_the_chapters_loo():
    r = mech.centre_basis_errors(P.hot, n_subsets=5, seed=0)
    assert r.basis[:, 0] == pytest.approx(_hot_loo_errors(P.hot), abs=1e-12)
    assert r.random.shape == (16, 5) and np.all(r.neurons >= 2)


# ---------------------------------------------------------------------------------------------------- C16
def test_latitude_share_by_hand():
    eps = np.array([0.001, -0.002, 0.003])
    assert mech.latitude_share(2.0 * eps, eps, 2.0) == pytest.approx(100.0)
    dl = 2.0 * eps + np.array([0.002, 0.0, 0.0])
    a2 = float(np.sum((2.0 * eps) ** 2))
    assert mech.latitude_share(dl, eps, 2.0) == pytest.approx(100 * a2 / (a2 + 0.002**2))
    with pytest.raises(InputError):
        mech.latitude_share([1.0, 2.0], [1.0], 2.0)
    with pytest.raises(InputError):
        mech.latitude_share([0.0], [0.0], 2.0)


@pytest.mark.parametrize("noise, verdict", [(0.0, "reproduced"), (1.0, "not reproduced")])
def test_latitude_share_follows_a_constructed_table2(monkeypatch, noise, verdict):
    x2, y2, x3, y3 = mech._hot_xy()
    k = ins.latitude_error_per_drift(12.0, P.earth)
    # latitude errors made exactly the drift's (share 100 %), or swamped by an unrelated error
    fake = k * y2 + noise * np.where(np.arange(16) % 2, 1.0, -1.0)
    monkeypatch.setattr(mech, "_hot_xy", lambda: (fake, y2, x3, y3))
    c = {k.key: k for k in mech.latitude_share_claims(P)}["gyro_latitude_share"]
    assert c.verdict == verdict


def test_simulated_latitude_share_is_by_construction(written):
    c = written["gyro_latitude_share_sim"]
    assert c.by_construction and c.verdict == "cannot be judged"


# ---------------------------------------------------------------------------------------------------- C18
@pytest.mark.parametrize("phase", [0, 7])
def test_rotation_responses_match_the_simulator(phase):
    rot = ins.Rotation()
    r = mech.rotation_responses(rot, duration_h=6.0, start_h=16.0)
    for j, imu in enumerate(
        (
            ins.ImuErrors(gyro_bias_x_deg_h=1.0),
            ins.ImuErrors(gyro_bias_y_deg_h=1.0),
            ins.ImuErrors(accel_bias_x_ug=1.0),
            ins.ImuErrors(accel_bias_y_ug=1.0),
        )
    ):
        run = ins.simulate(
            6.0, imu=imu, initial=np.zeros(7), rotation=rot, t0_s=16 * 3600.0 + 60.0 * phase
        )
        assert r.horizontal[phase, j, 0] == pytest.approx(
            run.north_m, abs=1e-9 * np.abs(run.north_m).max()
        )
        assert r.horizontal[phase, j, 1] == pytest.approx(
            run.east_m, abs=1e-9 * np.abs(run.east_m).max()
        )


def test_axial_response_is_table1s_closed_form():
    e = ins.Earth()
    r = mech.rotation_responses(ins.Rotation(), earth=e, duration_h=24.0)
    lat = r.axial[0] / e.radius_m / (math.pi / 180.0)
    cf = ins.table1_latitude_error(r.t_h, earth=e, axial_drift_deg_h=1.0)
    assert np.abs(lat - cf).max() < 0.01 * np.abs(cf).max()


@pytest.mark.parametrize("kind, verdict", [("indexing", "reproduced"), ("none", "not reproduced")])
def test_rotation_share_needs_the_rotation(kind, verdict):
    # without rotation the horizontal gyros' unmodulated drifts swamp the axial one
    r = mech.rotation_responses(ins.Rotation(kind=kind))
    df = mech.rotation_shares(r, 0.002, 20.0, 50, 3)
    c = Claim(
        "x",
        "x",
        statistic="share",
        estimate=verdicts.median_ci(df["axial share (%)"].to_numpy()),
        boundary=reg.entry("C18").boundary,
        holds_when="above",
        unit="%",
    )
    assert c.verdict == verdict


def test_rotation_shares_by_hand():
    r = mech.RotationResponses(
        axial=np.array([[0.0, 3.0 * ins.NMI], [0.0, 4.0 * ins.NMI]]),
        horizontal=np.zeros((1, 4, 2, 2)),
        t_h=np.array([0.0, 1.0]),
    )
    df = mech.rotation_shares(r, 2.0, 1.0, 3, 0)
    assert df["axial drift (nmi)"].tolist() == pytest.approx([10.0] * 3)
    assert df["axial share (%)"].tolist() == pytest.approx([100.0] * 3)
    with pytest.raises(InputError):
        mech.rotation_shares(r, 0.0, 1.0, 3, 0)


# ----------------------------------------------------------------------------------------- the register
def test_register_entries_name_the_rows_the_code_writes(written):
    cl = list(written.values())
    recs = {r["id"]: r for r in reg.evaluate("gyro", [c.record() for c in cl])}
    entries = {e.id: e for e in reg.entries("gyro")}
    for i, key in (
        ("C14", "gyro_centres"),
        ("C16", "gyro_latitude_share"),
        ("C18", "gyro_rotation_axial"),
    ):
        e = entries[i]
        assert e.status == "judged"
        assert set(e.rows) <= {c.claim for c in cl}
        primary = written[key]
        assert (e.primary_claim, e.primary_reading) == (primary.claim, primary.reading)
        assert recs[i]["reason"] != "not run"
        assert recs[i]["interval"] == pytest.approx(list(primary.interval), rel=1e-5)
