"""Tests for document B's data claims (B17 zero error with N nodes, B15 min-max normalisation, B19 the
sample size deep learning needs): :mod:`navlib.studies.compass.elm_data`."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from navlib.claims import load_register
from navlib.data.compass_sweeps import load_sweeps, split_sweeps
from navlib.errors import InputError
from navlib.paths import data_path
from navlib.studies.compass import StudyParams, Sweeps
from navlib.studies.compass import elm_data as ed
from navlib.studies.compass.elm_patent import big_net_labels

N_SEEDS = 20
ADAM, LM = big_net_labels(50)


def _by_claim(claims):
    return {c.claim: c for c in claims}


# ------------------------------------------------------------------------------------------- B17
def _interp(train, floor, readings=((121, 5.0), (30, 5.0), (8, 5.0), (121, 1.0))):
    rows = []
    for n, wr in readings:
        for s in range(N_SEEDS):
            tr = train[s] if np.ndim(train) else train
            fl = floor[s] if np.ndim(floor) else floor
            rows.append(
                {
                    "n_readings": n,
                    "weight_range": wr,
                    "seed": s,
                    "train_rms_deg": tr,
                    "cond": 1e3,
                    "rank": n,
                    "trunc_rms_deg": fl,
                    "round_rms_deg": 0.0,
                    "floor_rms_deg": fl,
                }
            )
    return pd.DataFrame(rows)


def _primary17(runs):
    return _by_claim(ed.interpolation_claims(runs))[
        "with as many hidden nodes as readings the ELM fits them with zero error [121 readings]"
    ]


def test_b17_each_branch_of_the_rule():
    # every run below the numerical zero
    row = _primary17(_interp(1e-9, 1e-10))
    assert row.verdict == "reproduced" and row.estimate.hi < ed.ZERO_DEG
    # far above zero where float64 could show zero: the error is not the solve's truncation
    row = _primary17(_interp(0.1, 1e-9))
    assert row.verdict == "not reproduced" and row.estimate.lo > ed.ZERO_DEG
    # above zero, but no more than float64 can show: the truncation, not the theorem
    row = _primary17(_interp(0.1, np.linspace(0.1, 0.12, N_SEEDS)))
    assert row.verdict == "cannot be judged" and row.basis == "noise floor"
    assert row.floor is not None and row.floor.interval[0] > ed.ZERO_DEG


def test_b17_one_bad_run_in_twenty_is_its_worst_case():
    train = np.full(N_SEEDS, 1e-9)
    train[5] = 1e-3
    row = _primary17(_interp(train, 1e-10))
    assert row.estimate.value == pytest.approx(1e-3)
    assert row.verdict != "reproduced"


def test_b17_refuses_a_repeated_seed():
    runs = _interp(1e-9, 1e-10)
    with pytest.raises(InputError, match="repeats a seed"):
        ed.interpolation_claims(pd.concat([runs, runs.iloc[:1]]))


def test_a_well_conditioned_square_elm_interpolates_and_its_floor_is_tiny():
    x = np.linspace(0.0, 350.0, 8)
    t = x + 5 * np.sin(np.radians(x))
    r = ed.interpolation_run(x, t, 5.0, seed=0)
    assert r["rank"] == 8 and r["train_rms_deg"] < ed.ZERO_DEG and r["floor_rms_deg"] < 1e-6


def test_the_floor_is_the_error_a_truncated_solve_leaves():
    # nearly straight nodes make H numerically singular: the solve drops directions, and what is
    # left of the target along them is the training error (up to rounding)
    x = np.linspace(0.0, 360.0, 60)
    t = x + 10 * np.sin(np.radians(3 * x))
    r = ed.interpolation_run(x, t, 0.05, seed=1)
    assert r["rank"] < 60 and r["cond"] > 1 / np.finfo(float).eps
    assert r["train_rms_deg"] > 1e-3
    assert r["train_rms_deg"] == pytest.approx(r["floor_rms_deg"], rel=0.05)


# ------------------------------------------------------------------------------------------- B15
def _norm(raw_fair, raw_same=None, norm=0.09):
    raw_same = raw_fair if raw_same is None else raw_same
    rows = []
    for run, v in ((ed.NORMALISED, norm), (ed.RAW_FAIR, raw_fair), (ed.RAW_SAME, raw_same)):
        for s in range(N_SEEDS):
            val = v[s] if np.ndim(v) else v
            rows.append(
                {
                    "run": run,
                    "seed": s,
                    "train_rms_deg": val,
                    "test_rms_deg": val,
                    "reached": val <= 0.1,
                    "iterations": 10,
                    "n_nodes": 10,
                }
            )
    return pd.DataFrame(rows)


def _primary15(runs):
    return _by_claim(ed.normalisation_claims(runs))[
        "min-max normalisation lowers the back-tuned ELM's training RMS [raw input weights scaled "
        "to the input span]"
    ]


def test_b15_each_branch_of_the_rule():
    assert _primary15(_norm(1.0)).verdict == "reproduced"
    assert _primary15(_norm(0.01)).verdict == "not reproduced"
    jitter = 0.09 + 0.001 * np.where(np.arange(N_SEEDS) % 2, 1.0, -1.0)
    row = _primary15(_norm(jitter))
    assert row.verdict == "cannot be judged" and row.estimate.lo < 0 < row.estimate.hi
    assert "reached in 20 of 20 raw runs" in _primary15(_norm(0.05)).why


def test_b15_refuses_a_missing_run():
    runs = _norm(1.0)
    with pytest.raises(InputError, match="no rows of run"):
        ed.normalisation_claims(runs[runs.run != ed.NORMALISED])


def test_raw_settings_carry_the_goal_and_the_draw_into_degrees():
    p = StudyParams()
    fair = ed.raw_params(p, 400.0, 360.0, scaled=True)
    same = ed.raw_params(p, 400.0, 360.0, scaled=False)
    assert fair.loss_goal == pytest.approx(p.elm_goal_deg**2)
    assert fair.prune_tol == pytest.approx(p.elm_prune_tol * 360.0)
    assert fair.weight_range == pytest.approx(p.elm_range / 400.0)
    assert same.weight_range == p.elm_range and fair.bias_range == same.bias_range == p.elm_range
    assert fair.max_nodes == p.elm_max_nodes and fair.max_iter == p.elm_max_iter
    with pytest.raises(InputError):
        ed.raw_params(p, 0.0, 360.0, scaled=True)


@pytest.fixture(scope="module")
def sw():
    return Sweeps(*split_sweeps(load_sweeps(data_path("compass_sweeps.csv"))))


def test_normalisation_study_rows_and_the_raw_runs_score_in_degrees(sw):
    runs = ed.normalisation_study(sw, StudyParams(), seeds=[0, 1])
    assert sorted(runs.run.unique()) == sorted(ed.NORMALISATION_RUNS)
    assert len(runs) == 6
    assert all(sorted(g.seed) == [0, 1] for _, g in runs.groupby("run"))
    # the raw networks are scored on the sweep in degrees, as the normalised one: same order of error
    # as the uncompensated compass or better, never a unit mismatch of a factor of hundreds
    assert (runs.train_rms_deg < 60).all() and (runs.test_rms_deg < 60).all()
    summ = ed.normalisation_summary(runs)
    assert list(summ.index) == list(ed.NORMALISATION_RUNS)


def test_interpolation_study_readings(sw):
    runs = ed.interpolation_study(sw, StudyParams(), seeds=[0, 1])
    got = sorted(set(zip(runs.n_readings, runs.weight_range)))
    assert got == sorted(ed.interpolation_readings(sw, StudyParams()))
    assert (runs["rank"] <= runs.n_readings).all() and (runs.floor_rms_deg >= 0).all()


# ------------------------------------------------------------------------------------------- B19
def _small(elm, net, sizes=(8, 15, 30, 60), net_train=0.0):
    """``elm``/``net``: the first size at which each seed's test RMS drops to 0.1 (None: never)."""
    rows = []
    for method, first in ((ed.ELM_LABEL, elm), (ADAM, net), (LM, net)):
        for s in range(N_SEEDS):
            f = first[s] if isinstance(first, (list, tuple)) else first
            for n in sizes:
                ok = f is not None and n >= f
                rows.append(
                    {
                        "n_train": n,
                        "method": method,
                        "seed": s,
                        "train_rms_deg": net_train if method != ed.ELM_LABEL else 0.0,
                        "test_rms_deg": 0.1 if ok else 5.0,
                        "n_nodes": 10,
                    }
                )
    return pd.DataFrame(rows)


def _runs(floor=0.1):
    return pd.DataFrame([{"method": "physical", "seed": -1, "rms_deg": floor}])


def _primary19(small):
    return _by_claim(ed.sample_claims(small, _runs(), 50, 121))[
        "the ELM reaches the test-RMS goal with fewer readings than an over-sized net [Adam from "
        "U(-1, 1), goal 2 x the floor]"
    ]


def test_readings_to_goal_and_censoring():
    small = _small(15, None)
    elm = ed.readings_to_goal(small, ed.ELM_LABEL, 0.2, 121)
    net = ed.readings_to_goal(small, ADAM, 0.2, 121)
    assert elm.readings.eq(15).all() and elm.reached.all()
    assert net.readings.eq(121).all() and not net.reached.any()
    with pytest.raises(InputError, match="cap"):
        ed.readings_to_goal(small, ADAM, 0.2, 60)
    with pytest.raises(InputError, match="lacks a size"):
        ed.readings_to_goal(small.drop(index=small.index[0]), ed.ELM_LABEL, 0.2, 121)
    with pytest.raises(InputError, match="no rows of method"):
        ed.readings_to_goal(small, "BP 1-9-1 (Adam)", 0.2, 121)


def test_b19_each_branch_of_the_rule():
    row = _primary19(_small(8, 60))
    assert row.verdict == "reproduced" and row.estimate.value == 52
    assert _primary19(_small(60, 8)).verdict == "not reproduced"
    mixed = [8 if s % 2 else 60 for s in range(N_SEEDS)]
    row = _primary19(_small(30, mixed))
    assert row.verdict == "cannot be judged"
    # the net never reaches the goal: counted at the full sweep (a lower bound), said in the reason
    row = _primary19(_small(30, None, net_train=5.0))
    assert row.estimate.value == 121 - 30 and "20 of 20 pairs with only the net short" in row.why
    assert "above the goal" in row.why and "more than 60" in row.ours


def test_the_register_names_the_rows_the_code_writes():
    written = {
        c.claim
        for c in ed.interpolation_claims(_interp(1e-9, 1e-10))
        + ed.normalisation_claims(_norm(1.0))
        + ed.sample_claims(_small(8, 60), _runs(), 50, 121)
    }
    reg = {e.id: e for e in load_register("patent_b")}
    for eid in ("B15", "B17", "B19"):
        e = reg[eid]
        assert e.status == "judged" and e.primary_claim in e.rows
        assert set(e.rows) <= written
    assert set(reg["B15"].rows) | set(reg["B17"].rows) | set(reg["B19"].rows) == written
    assert reg["B20"].status == "open"
