"""navlib.studies.gyro.diagnosis: Table 1 against the error model (C17) and the cold-start diagnosis on the
printed Tables 3-5 (C19, C20, C21)."""

import numpy as np
import pandas as pd
import pytest

from navlib import claims as reg
from navlib.data.gyro_tables import load_cold_test, load_cold_train, load_hot_test
from navlib.studies import gyro
from navlib.studies.gyro import diagnosis

P = gyro.StudyParams()


@pytest.fixture(scope="module")
def cold():
    return {c.key: c for c in gyro.cold_diagnosis_claims(P)}


def _rms(e):
    return float(np.sqrt(np.mean(np.square(e))))


# ---------------------------------------------------------------------------------------------------- C17
def test_table1_gaps_by_hand():
    g = gyro.table1_gaps().set_index("source")
    c = gyro.table1_vs_simulator().curves
    w = c[(c["case"] == "azimuth error 60 arcsec") & (c["t_h"] <= 12.0)]
    d = np.abs(w["simulator_arcsec"] - w["table1_arcsec"]).max()
    row = g.loc[gyro.TABLE1_SOURCES["azimuth error 60 arcsec"]]
    assert row["relative gap"] == pytest.approx(d / np.abs(w["simulator_arcsec"]).max())
    assert row["largest gap (arcsec)"] == pytest.approx(d)
    # the drift term is Table 1's own closed form of the same linear equations: it must overlay
    assert g.loc["axial gyro drift", "relative gap"] < reg.entry("C17").boundary


def test_table1_claims_primary_is_the_worst_of_four():
    cl = {c.key: c for c in gyro.table1_claims()}
    four = [
        cl[f"gyro_table1_{k}"].estimate.value for k in ("drift", "azimuth", "velocity", "accel")
    ]
    assert cl["gyro_table1"].estimate.value == pytest.approx(max(four))
    assert all(c.rule == "exact" and c.holds_when == "below" for c in cl.values())
    assert cl["gyro_table1_drift"].reproduced is True


def _fake_runs(scale):
    """Table 1 runs where Table 1 is the simulator times ``scale``."""
    t = np.linspace(0.0, 48.0, 97)
    curves = pd.concat(
        [
            pd.DataFrame(
                {
                    "case": case,
                    "t_h": t,
                    "simulator_arcsec": np.sin(t / 3.0) + 0.5,
                    "table1_arcsec": scale * (np.sin(t / 3.0) + 0.5),
                }
            )
            for case in gyro.TABLE1_SOURCES
        ],
        ignore_index=True,
    )
    return gyro.Table1Comparison(pd.DataFrame(), curves, pd.DataFrame())


@pytest.mark.parametrize("scale, verdict", [(1.0, "reproduced"), (1.2, "not reproduced")])
def test_table1_claims_follow_a_constructed_table(monkeypatch, scale, verdict):
    monkeypatch.setattr(diagnosis, "_table1_runs", lambda: _fake_runs(scale))
    cl = {c.key: c for c in gyro.table1_claims()}
    assert cl["gyro_table1"].estimate.value == pytest.approx(abs(scale - 1.0))
    assert cl["gyro_table1"].verdict == verdict


# ---------------------------------------------------------------------------------------------------- C19
def test_cold_worse_by_hand(cold):
    p5 = load_cold_test()["paper_pos_error_hot_net_nmi_72h"].to_numpy()
    p3 = load_hot_test()["paper_pos_error_after_nmi_72h"].to_numpy()
    c = cold["gyro_cold_worse"]
    assert c.estimate.value == pytest.approx(p5.mean() - p3.mean())
    assert c.holds_when == "above" and c.boundary == 0.0 and c.estimate.n == p5.size + p3.size
    # unpaired: each table resampled on its own, so the interval stays within the extreme means
    assert p5.min() - p3.max() <= c.interval[0] and c.interval[1] <= p5.max() - p3.min()


@pytest.mark.parametrize("shift, verdict", [(0.0, "cannot be judged"), (-0.5, "not reproduced")])
def test_cold_worse_follows_a_constructed_table5(monkeypatch, shift, verdict):
    t3 = load_hot_test()
    t5 = load_cold_test().copy()
    # Table 5's hot-net errors made equal to (or below) Table 3's 'after' errors
    t5["paper_pos_error_hot_net_nmi_72h"] = t3["paper_pos_error_after_nmi_72h"].to_numpy() + shift
    monkeypatch.setattr(diagnosis, "load_cold_test", lambda: t5)
    c = {k.key: k for k in gyro.cold_diagnosis_claims(P)}["gyro_cold_worse"]
    assert c.verdict == verdict


# ---------------------------------------------------------------------------------------------------- C20
def test_corr_of_a_constant_column_is_zero():
    assert diagnosis._corr([1.0, 1.0, 1.0], [1.0, 2.0, 3.0]) == 0.0
    assert diagnosis._corr([1.0, 2.0, 3.0], [2.0, 4.0, 6.5]) == pytest.approx(
        np.corrcoef([1.0, 2.0, 3.0], [2.0, 4.0, 6.5])[0, 1]
    )


def test_cold_cause_by_hand(cold):
    t4 = load_cold_train()
    e = np.abs(t4["true_drift_deg_h"] - t4["paper_hot_rbf_drift_deg_h"]).to_numpy()
    c = cold["gyro_cold_cause"]
    assert c.estimate.value == pytest.approx(np.corrcoef(t4["align_temp_change_c"], e)[0, 1])
    assert c.holds_when == "above" and c.rule == "bootstrap over rows" and c.estimate.n == 6
    # the chapter's k_R correlation (our hot net, signed, calibration rate) is one of the readings
    q = gyro.cold_leave_one_out(P).quantities
    ref = q.loc["correlation of hot-net error with rate", "value"]
    assert cold["gyro_cold_cause_ours_signed"].estimate.value == pytest.approx(ref)


@pytest.mark.parametrize("sign, verdict", [(1.0, "reproduced"), (-1.0, "not reproduced")])
def test_cold_cause_follows_a_constructed_table4(monkeypatch, sign, verdict):
    t4 = load_cold_train().copy()
    dt = t4["align_temp_change_c"].to_numpy(float)
    # |error| exactly linear in the alignment change (rising or falling with it)
    size = 1e-4 * (dt if sign > 0 else dt.max() + 1.0 - dt)
    t4["paper_hot_rbf_drift_deg_h"] = t4["true_drift_deg_h"] + size
    monkeypatch.setattr(diagnosis, "load_cold_train", lambda: t4)
    c = {k.key: k for k in gyro.cold_diagnosis_claims(P)}["gyro_cold_cause"]
    assert c.estimate.value == pytest.approx(sign)
    assert c.verdict == verdict


# ---------------------------------------------------------------------------------------------------- C21
def test_rate_corrected_loo_is_the_chapters_rate_baseline():
    t4 = load_cold_train()
    rows = gyro.cold_leave_one_out(P).rows
    ours = rows["hot net"].to_numpy()
    got = gyro.rate_corrected_loo(ours, t4["true_drift_deg_h"], t4["calib_temp_change_c"])
    assert got == pytest.approx(rows["hot + rate correction"].to_numpy())


def test_compensation_by_hand(cold):
    t4 = load_cold_train()
    y, h = t4["true_drift_deg_h"].to_numpy(), t4["paper_hot_rbf_drift_deg_h"].to_numpy()
    dt = t4["calib_temp_change_c"].to_numpy()
    pred = []
    for i in range(len(y)):
        k = np.arange(len(y)) != i
        kr = np.sum((h[k] - y[k]) * dt[k]) / np.sum(dt[k] ** 2)
        pred.append(h[i] - kr * dt[i])
    c = cold["gyro_cold_compensation"]
    assert c.estimate.value == pytest.approx(_rms(y - np.array(pred)) - _rms(y - h))
    assert c.holds_when == "above" and c.boundary == 0.0


def _table4_with_hot_error(err):
    t4 = load_cold_train().copy()
    t4["paper_hot_rbf_drift_deg_h"] = t4["true_drift_deg_h"] + err
    return t4


@pytest.mark.parametrize("case, verdict", [("rate", "not reproduced"), ("one row", "reproduced")])
def test_compensation_follows_a_constructed_table4(monkeypatch, case, verdict):
    dt = load_cold_train()["calib_temp_change_c"].to_numpy(float)
    if case == "rate":  # the error is exactly a rate term: the compensation removes it
        err = 1e-4 * dt
    else:  # a single row off: every other row's coefficient comes from it and only adds error
        err = np.zeros_like(dt)
        err[int(np.argmax(dt))] = 1e-3
    t4 = _table4_with_hot_error(err)
    monkeypatch.setattr(diagnosis, "load_cold_train", lambda: t4)
    c = {k.key: k for k in gyro.cold_diagnosis_claims(P)}["gyro_cold_compensation"]
    assert c.verdict == verdict


# ----------------------------------------------------------------------------------------- the register
def test_register_entries_name_the_rows_the_code_writes():
    cl = gyro.table1_claims() + gyro.cold_diagnosis_claims(P)
    recs = {r["id"]: r for r in reg.evaluate("gyro", [c.record() for c in cl])}
    entries = {e.id: e for e in reg.entries("gyro")}
    for i, key in (
        ("C17", "gyro_table1"),
        ("C19", "gyro_cold_worse"),
        ("C20", "gyro_cold_cause"),
        ("C21", "gyro_cold_compensation"),
    ):
        e = entries[i]
        assert e.status == "judged"
        written = {c.claim for c in cl}
        assert set(e.rows) <= written
        primary = next(c for c in cl if c.key == key)
        assert (e.primary_claim, e.primary_reading) == (primary.claim, primary.reading)
        assert recs[i]["reason"] != "not run"
        assert recs[i]["interval"] == pytest.approx(
            list(primary.interval), rel=1e-5
        )  # 6 digits stored
    assert entries["C31"].status == "noted" and entries["C31"].kind == "inconsistency"
