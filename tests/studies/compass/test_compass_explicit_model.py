"""Tests for document B's B14 ("any explicit error model can hardly include all error factors"): the
AMR cross-axis effect (its formula, that no ellipse fits it and that it vanishes for a large field scale
constant), constructed runs for each verdict branch, broken inputs, and the register naming the rows the
code (this module and the real-data section) writes."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from navlib import claims as registry
from navlib import verdicts
from navlib.angles import wrap_deg
from navlib.errors import InputError
from navlib.sensors.compass import PAPER_A_EARTH, CompassErrors, simulate_train_test
from navlib.sensors.planar import fit_planar_model
from navlib.studies.compass import explicit_model as em
from navlib.studies.compass import real as cr

N = 20


def _runs(explicit_rms, elm_rms):
    """Seed-study runs: the ellipse model's one row (seed -1) and the ELM's ``elm_rms`` over the seeds."""
    rows = [{"method": em.EXPLICIT_ID, "seed": -1, "rms_deg": float(explicit_rms)}]
    rows += [
        {"method": em.IMPLICIT_ID, "seed": s, "rms_deg": float(v)} for s, v in enumerate(elm_rms)
    ]
    return pd.DataFrame(rows)


def _spread(centre, half=0.01, n=N):
    return centre + half * np.linspace(-1, 1, n)


# ------------------------------------------------------------------ the register
def test_the_register_names_the_rows_the_code_writes():
    reg = {e.id: e for e in registry.load_register("patent_b")}
    b14, b08 = reg["B14"], reg["B08"]
    assert b14.status == "judged" and b14.origin == "paper"
    assert set(b14.rows) == {em.EXPLICIT_TEXT} and b14.primary_claim == em.EXPLICIT_TEXT
    assert b14.primary_reading == em.EXPLICIT_READING
    # the simulated row (this module) and the real rows (real.py) carry the entry's text
    cs = em.explicit_model_claims(_runs(0.4, _spread(0.1)))
    assert [(c.claim, c.reading, c.data) for c in cs] == [
        (em.EXPLICIT_TEXT, em.EXPLICIT_READING, "simulated")
    ]
    spec = next(s for s in cr.real_claim_specs() if s.claim == em.EXPLICIT_TEXT)
    assert spec.methods == (em.IMPLICIT_ID, em.EXPLICIT_ID)  # better, worse: the same difference
    # B08 keeps only its simulated row: a results row belongs to one entry
    assert em.EXPLICIT_TEXT not in b08.rows
    assert all(s.claim not in b08.rows for s in cr.real_claim_specs())


def test_the_evaluator_files_both_rows_under_b14_with_the_real_record_apart():
    sim = em.explicit_model_claims(_runs(0.4, _spread(0.1)))[0]
    real = sim.__class__(**{**sim.__dict__, "data": "real", "key": ""})
    recs = [
        r for r in registry.evaluate("compass", [sim.record(), real.record()]) if r["id"] == "B14"
    ]
    assert [r["data"] for r in recs] == ["simulated", "real"]
    assert all(
        r["row_claim"] == em.EXPLICIT_TEXT and r["primary_reading"] == em.EXPLICIT_READING
        for r in recs
    )


# ------------------------------------------------------------------ each verdict branch
@pytest.mark.parametrize(
    "explicit,elm,want",
    [
        (0.40, _spread(0.10), "reproduced"),  # the ellipse misses: the ELM is better on every seed
        (0.10, _spread(0.40), "not reproduced"),  # the ELM worse on every seed
        (0.10, _spread(0.10, half=0.05), "cannot be judged"),  # straddles the boundary
    ],
)
def test_each_verdict_branch(explicit, elm, want):
    (c,) = em.explicit_model_claims(_runs(explicit, elm))
    want_est = verdicts.paired_difference(np.full(N, explicit), elm)
    assert c.estimate == want_est and c.boundary == 0.0 and c.holds_when == "above"
    assert c.verdict == want and not c.by_construction
    assert c.source == "paper" and c.key == "b_explicit_cross_axis"


def test_runs_without_a_method_are_refused():
    with pytest.raises(InputError, match="physical"):
        em.explicit_model_claims(_runs(0.4, _spread(0.1)).query("method != 'physical'"))
    with pytest.raises(InputError, match="elm_backtuned"):
        em.explicit_model_claims(_runs(0.4, _spread(0.1)).query("method != 'elm_backtuned'"))


# ------------------------------------------------------------------ the cross-axis effect
def test_the_cross_axis_formula():
    h0 = em.CROSS_AXIS_H0_UT
    out = em.CrossAxis().apply(np.array([[10.0, 0.0], [10.0, 20.0], [-30.0, 5.0]]))
    want = np.array([[10.0, 0.0], [10 * h0 / (h0 + 20), 20 * h0 / (h0 - 10)]])
    assert np.allclose(out[:2], want)
    assert np.allclose(out[2], [-30 * h0 / (h0 + 5), 5 * h0 / (h0 + 30)])


@pytest.mark.parametrize(
    "make,match",
    [
        (lambda: em.CrossAxis(h0_ut=0.0), "h0_ut"),
        (lambda: em.CrossAxis(h0_ut=-5.0), "h0_ut"),
        (lambda: em.CrossAxis().apply(np.ones((3, 3))), r"\(n, 2\)"),
        (lambda: em.CrossAxis(h0_ut=50.0).apply(np.array([[30.0, 0.0]])), "half of H_0"),
        (lambda: em.with_cross_axis(pd.DataFrame({"true_heading_deg": [0.0]})), "mag_x_ut"),
    ],
)
def test_broken_inputs_are_refused_in_one_line(make, match):
    with pytest.raises(InputError, match=match):
        make()


def _planar_residual_deg(frame):
    tr = frame[frame.sweep == 1]
    model = fit_planar_model(tr.true_heading_deg.to_numpy(), tr.measured_heading_deg.to_numpy())
    pred = model.correct(tr.measured_heading_deg.to_numpy())
    return float(np.sqrt(np.mean(wrap_deg(pred - tr.true_heading_deg.to_numpy()) ** 2)))


def test_no_ellipse_fits_the_cross_axis_effect_and_a_large_h0_removes_it():
    quiet = CompassErrors(noise_ut=0.0)
    frame = simulate_train_test(quiet, PAPER_A_EARTH, seed=1)
    assert _planar_residual_deg(frame) < 1e-4  # our compass: exactly the ellipse model
    assert _planar_residual_deg(em.with_cross_axis(frame)) > 0.05  # outside it
    huge = em.with_cross_axis(frame, em.CrossAxis(h0_ut=1e9))
    assert np.allclose(huge.measured_heading_deg, frame.measured_heading_deg, atol=1e-5)
    changed = em.with_cross_axis(frame)
    same = [
        c
        for c in frame.columns
        if c not in ("mag_x_ut", "mag_y_ut", "measured_heading_deg", "heading_error_deg")
    ]
    pd.testing.assert_frame_equal(changed[same], frame[same])


def test_the_study_fits_both_models_on_the_same_sweep_and_pairs_the_seeds():
    runs = em.explicit_model_study(seeds=range(6))
    assert set(runs.method) == {em.EXPLICIT_ID, em.IMPLICIT_ID}
    assert sorted(runs[runs.method == em.IMPLICIT_ID].seed) == list(range(6))
    (c,) = em.explicit_model_claims(runs)
    e = runs[runs.method == em.EXPLICIT_ID].rms_deg.to_numpy()
    b = runs[runs.method == em.IMPLICIT_ID].rms_deg.to_numpy()
    assert c.estimate == verdicts.paired_difference(np.repeat(e, 6), b)
    # the ellipse model's test RMS on the sweep pair, computed apart
    sw = em.cross_axis_sweeps()
    model = fit_planar_model(sw.t_train, np.mod(sw.m_train, 360.0))
    rms = np.sqrt(np.mean(wrap_deg(model.correct(np.mod(sw.m_test, 360.0)) - sw.t_test) ** 2))
    assert e[0] == pytest.approx(rms, rel=1e-9)


# ------------------------------------------------------------------ real sweeps: inside the coverage
def test_covered_marks_readings_between_close_training_headings_across_north():
    train = np.r_[np.arange(0.0, 100.0, 3.0), np.arange(200.0, 360.0, 3.0)]  # a gap 99..200
    got = em.covered(train, [50.0, 150.0, 358.5, 1.0, 99.5, 201.0])
    assert got.tolist() == [True, False, True, True, False, True]
    assert em.covered([350.0, 5.0], [358.0, 180.0], gap_deg=15.0).tolist() == [True, False]
    assert em.covered([350.0, 5.0], [358.0], gap_deg=14.0).tolist() == [False]


@pytest.mark.parametrize(
    "args,match",
    [(([0.0, 10.0], [5.0], 0.0), "gap_deg"), (([0.0], [5.0]), "2 training headings")],
)
def test_covered_refuses_broken_input(args, match):
    with pytest.raises(InputError, match=match):
        em.covered(*args)


def _fake_real(gap_error_deg, inside_elm_deg=0.5, inside_explicit_deg=0.6, seeds=10):
    """A real-data result over headings every 3 deg with two folds: fold 1 trains on 180..357 without
    243..297 plus 0..57 and scores 0..177; fold 2 trains on 0..177 and scores 180..357 without 243..297.
    Fold 1's held-out readings 60..177 lie in a gap of its training headings.  The ELM errs by
    ``gap_error_deg`` on the uncovered readings, by ``inside_elm_deg`` (plus 0.01 per seed) on the
    covered ones; the explicit model by ``inside_explicit_deg`` everywhere."""
    from types import SimpleNamespace

    from navlib.workbench.compare import Fold

    h = np.arange(0.0, 360.0, 3.0)
    first = np.where(h < 180)[0]
    second = np.where((h >= 180) & ~((h > 240) & (h < 300)))[0]
    folds = [
        Fold(np.r_[second, np.where(h < 60)[0]], first, "sweep 2 + 0..57", "sweep 1"),
        Fold(first, second, "sweep 1", "sweep 2"),
    ]
    n = h.size
    elm = np.full((seeds, n), inside_elm_deg) + 0.01 * np.arange(seeds)[:, None]
    phys = np.full((1, n), inside_explicit_deg)
    inside = np.zeros(n, dtype=bool)
    for f in folds:
        inside[f.test] = em.covered(h[f.train], h[f.test])
    elm[:, ~inside] = gap_error_deg
    res = SimpleNamespace(
        frame=pd.DataFrame({"true_heading_deg": h}),
        folds=folds,
        methods=["physical", "elm_backtuned"],
        errors={"physical": phys, "elm_backtuned": elm},
        stochastic={"physical": False, "elm_backtuned": True},
    )
    return SimpleNamespace(results={em.COVERAGE_RECORDING: res}), inside


def test_coverage_claims_score_only_the_covered_readings():
    real, inside = _fake_real(gap_error_deg=10.0)
    assert 2 <= inside.sum() < inside.size  # some readings in gaps, some covered
    (c,) = em.coverage_claims(real)
    assert c.claim == em.EXPLICIT_TEXT and c.data == "real" and c.source == "paper"
    assert c.reading.startswith(em.EXPLICIT_READING + "; BROAD trial 05")
    elm = np.array([0.5 + 0.01 * k for k in range(10)])
    want = verdicts.paired_difference(np.full(10, 0.6), elm)
    got = (c.estimate.value, c.estimate.lo, c.estimate.hi)
    assert got == pytest.approx((want.value, want.lo, want.hi), abs=1e-12)
    assert c.verdict == "reproduced"  # the gap rows' large errors are left out
    assert f"on {int(inside.sum())} of {inside.size} readings" in c.ours
    # the ELM worse inside the coverage too: the other branch
    (w,) = em.coverage_claims(_fake_real(10.0, inside_elm_deg=0.9)[0])
    assert w.verdict == "not reproduced"


def test_coverage_claims_without_the_methods_or_covered_readings():
    real, _ = _fake_real(10.0)
    res = real.results[em.COVERAGE_RECORDING]
    res.methods = ["physical"]
    assert em.coverage_claims(real) == []
    res.methods = ["physical", "elm_backtuned"]
    with pytest.raises(InputError, match="inside the coverage"):
        em.coverage_claims(real, gap_deg=1.0)  # 3-deg spacing: nothing is covered


def test_the_coverage_row_belongs_to_b14s_real_record():
    sim = em.explicit_model_claims(_runs(0.4, _spread(0.1)))[0]
    real = sim.__class__(**{**sim.__dict__, "data": "real", "key": ""})
    (cov,) = em.coverage_claims(_fake_real(10.0)[0])
    recs = registry.evaluate("compass", [sim.record(), real.record(), cov.record()])
    (r,) = [r for r in recs if r["id"] == "B14" and r["data"] == "real"]
    assert [s["reading"] for s in r["sensitivity"]] == [cov.reading]
