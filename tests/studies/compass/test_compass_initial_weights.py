"""Tests for paper A's A15 ("ADE overcomes the difficulty of choosing BP's initial weights") and A20 ("the
ellipse-hypothesis model's accuracy is limited"): constructed seed-study runs where the answer is known, each
verdict branch, broken inputs, and the register naming the rows the code writes."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from navlib import claims as registry
from navlib.claims import load_register
from navlib.errors import InputError
from navlib.methods.compass_methods import R1, R2, R4, R4V
from navlib.studies.compass import ellipse, initial_weights
from navlib.studies.compass import real as cr
from navlib.studies.compass.initial_weights import (
    SHARE_TEXT,
    SPREAD_TEXT,
    far_share,
    initial_weight_claims,
    initial_weight_table,
    iqr,
)

N = 20
FLOOR = 0.1


def _runs(bp, ade, floor=FLOOR, extra=True):
    """Seed-study runs: ``physical`` (one row, seed -1) and every pair of PAIRS with the BP methods'
    RMS ``bp`` and the ADE-started methods' RMS ``ade`` (arrays over the seeds)."""
    rows = [{"method": "physical", "seed": -1, "rms_deg": floor, "min_deg": -1, "max_deg": 1}]
    bps = {b for _, _, b, _ in initial_weights.PAIRS}
    ades = {a for _, a, _, _ in initial_weights.PAIRS} if extra else {"ade_bp_full_trainlm"}
    for mids, vals in ((bps, bp), (ades, ade)):
        for m in sorted(mids):
            rows += [
                {"method": m, "seed": s, "rms_deg": float(v), "min_deg": -1, "max_deg": 1}
                for s, v in enumerate(vals)
            ]
    return pd.DataFrame(rows)


def _near(scale=0.01, n=N):
    """RMS values just above the floor with a small spread (all well below 2 x floor)."""
    return FLOOR * 1.05 + scale * np.linspace(0, 1, n)


def _by(cs):
    return {(c.claim, c.reading): c for c in cs}


def test_the_rows_are_the_registers():
    reg = {e.id: e for e in load_register("paper_a")}
    cs = initial_weight_claims(_runs(_near(), _near()))
    assert set(reg["A15"].rows) == {c.claim for c in cs} == {SHARE_TEXT, SPREAD_TEXT}
    assert reg["A15"].primary_claim == SHARE_TEXT and reg["A15"].primary_reading == R4
    assert (SHARE_TEXT, R4) in _by(cs)
    assert {c.reading for c in cs if c.claim == SPREAD_TEXT} == {R4, R2}
    e = ellipse.ellipse_claims(_runs(_near(), _near()))
    assert set(reg["A20"].rows) == {c.claim for c in e} == {ellipse.ELLIPSE_TEXT}
    assert reg["A20"].primary_claim == ellipse.ELLIPSE_TEXT and reg["A20"].primary_reading == R4
    recs = {r["id"]: r for r in registry.evaluate("compass", [c.record() for c in cs + e])}
    assert recs["A15"]["row_claim"] == SHARE_TEXT and recs["A15"]["primary_reading"] == R4
    assert recs["A20"]["basis"] == "by construction"


def test_bad_random_starts_that_ade_avoids_are_reproduced():
    """8 of 20 BP runs stuck at ten times the floor, none of ADE's: the share difference 0.4 lies above 0."""
    bp = _near()
    bp[::5] = 1.0
    bp[1::5] = 1.0
    c = _by(initial_weight_claims(_runs(bp, _near())))[(SHARE_TEXT, R4)]
    assert c.estimate.value == pytest.approx(0.4)
    assert c.estimate.lo > 0 and c.verdict == "reproduced"
    assert "8 of 20 BP runs vs 0 of 20 ADE-BP runs" in c.ours
    spread = _by(initial_weight_claims(_runs(bp, _near())))[(SPREAD_TEXT, R4)]
    assert spread.estimate.value > 1


def test_no_bad_start_on_either_side_cannot_be_judged():
    """No run of either start far from the floor: BP had no difficulty to overcome; the interval [0, 0]
    touches the boundary."""
    c = _by(initial_weight_claims(_runs(_near(), _near())))[(SHARE_TEXT, R4)]
    assert c.estimate.interval == (0.0, 0.0) and c.verdict == "cannot be judged"
    assert c.basis == "straddles"


def test_ade_starts_that_fail_more_often_are_not_reproduced():
    ade = _near()
    ade[: N // 2] = 1.0
    c = _by(initial_weight_claims(_runs(_near(), ade)))[(SHARE_TEXT, R4)]
    assert c.estimate.hi < 0 and c.verdict == "not reproduced"


def test_the_spread_ratio_reads_the_interquartile_ranges():
    bp, ade = _near(scale=0.05), _near(scale=0.005)
    c = _by(initial_weight_claims(_runs(bp, ade)))[(SPREAD_TEXT, R4)]
    assert c.estimate.value == pytest.approx(iqr(bp) / iqr(ade))
    assert c.estimate.lo > 1 and c.verdict == "reproduced"
    flat = np.full(N, 0.105)
    c = _by(initial_weight_claims(_runs(bp, flat)))[(SPREAD_TEXT, R4)]
    assert c.estimate is None and "no spread" in c.reason  # a deliberately broken input


def test_every_reading_is_a_row_and_missing_pairs_are_skipped():
    cs = initial_weight_claims(_runs(_near(), _near()))
    assert {c.reading for c in cs if c.claim == SHARE_TEXT} == {
        r for r, *_ in initial_weights.PAIRS
    }
    only4 = initial_weight_claims(_runs(_near(), _near(), extra=False))
    assert {(c.claim, c.reading) for c in only4} == {(SHARE_TEXT, R4), (SPREAD_TEXT, R4)}
    assert R1 not in {c.reading for c in only4} and R4V not in {c.reading for c in only4}
    tab = initial_weight_table(_runs(_near(), _near()))
    assert len(tab) == 2 * len(initial_weights.PAIRS)


def test_broken_inputs_are_refused():
    runs = _runs(_near(), _near())
    with pytest.raises(InputError, match="physical"):
        initial_weight_claims(runs[runs.method != "physical"])
    with pytest.raises(InputError, match="floor RMS"):
        initial_weight_claims(_runs(_near(), _near(), floor=0.0))
    assert far_share([0.1, 0.3, 0.25], 0.1) == pytest.approx(2 / 3)


def test_the_simulated_ellipse_row_is_by_construction_whatever_the_numbers():
    for ade in (_near() * 0.5, _near() * 3):
        (c,) = ellipse.ellipse_claims(_runs(_near(), ade))
        assert c.by_construction and c.verdict == "cannot be judged"
        assert c.estimate is not None and c.data == "simulated" and c.reading == R4


# ------------------------------------------------------------------------------ A20 on real data
class _FakeCompare:
    """The parts of a CompareResult that real_claims reads: held-out errors per method and seed."""

    def __init__(self, errors: dict, stochastic: dict):
        self.methods = list(errors)
        self.errors = {m: np.atleast_2d(e) for m, e in errors.items()}
        self.stochastic = stochastic
        self.not_run = []

    def rms(self, mid):
        return np.sqrt(np.mean(self.errors[mid] ** 2, axis=1))


def _fake_real(ade_scale: float):
    """Held-out errors: the ellipse model 0.5 x one noise curve, ADE-BP's six runs ``ade_scale`` x the
    same curve, each a hair apart."""
    rng = np.random.default_rng(0)
    base = rng.standard_normal(50)
    ade = ade_scale * base * (1 + 0.001 * np.arange(6))[:, None]
    res = _FakeCompare(
        {"physical": 0.5 * base, "ade_bp_full_trainlm": ade},
        {"physical": False, "ade_bp_full_trainlm": True},
    )
    return cr.RealCompass({"trial05": res, "sessions": res}, 6, 0, 22.5, cr.MethodParams())


@pytest.mark.parametrize(
    "ade_scale, verdict", [(0.2, "reproduced"), (1.5, "not reproduced"), (0.5, "no difference")]
)
def test_a20_on_real_sweeps_is_judged_on_data_real(ade_scale, verdict):
    paper = pd.DataFrame(
        [{"method": "ADE-BP", "error_min_deg": -0.22, "error_max_deg": 0.2}]
    )  # unused by A20's row
    cs = [
        c for c in cr.real_claims(_fake_real(ade_scale), paper) if c.claim == ellipse.ELLIPSE_TEXT
    ]
    assert [c.reading for c in cs] == [R4, f"{R4}; BROAD trials 2, 3, 5, 7"]
    c = cs[0]
    assert c.data == "real" and not c.by_construction and c.paper == ellipse.PAPER_TEXT
    rec = next(
        r
        for r in registry.evaluate("compass", [x.record() for x in cs])
        if r["id"] == "A20" and r["data"] == "real"
    )
    assert rec["verdict"] == verdict  # the register's 0.01 deg margin applies
