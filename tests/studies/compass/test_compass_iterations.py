"""Tests for document B's iteration claims (B10 pruning, B11 against Huang's point-incremental ELM):
:mod:`navlib.studies.compass.elm_iterations`."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from navlib.claims import load_register
from navlib.data.compass_sweeps import load_sweeps, split_sweeps
from navlib.methods.ielm import IELMParams, fit_ielm
from navlib.methods.scaling import MinMax
from navlib.methods.seeding import generators
from navlib.paths import data_path
from navlib.studies.compass import StudyParams, Sweeps, fit_method
from navlib.studies.compass import elm_iterations as it
from navlib.studies.compass.elm_patent import claims as patent_b_claims


@pytest.fixture(scope="module")
def sw():
    return Sweeps(*split_sweeps(load_sweeps(data_path("compass_sweeps.csv"))))


@pytest.fixture(scope="module")
def runs(sw):
    return it.iteration_study(sw, StudyParams(), seeds=range(2))


def test_the_back_tuned_runs_are_the_chapters_and_count_elm_solves(sw, runs):
    p = StudyParams()
    bt = runs[runs.run == it.BT].set_index("seed")
    for seed, comp in enumerate(fit_method("elm_backtuned", sw.x_train, sw.t_train, p, range(2))):
        hist = comp.info["history"]
        assert bt.loc[seed, "n_nodes"] == comp.info["n_nodes"]
        assert bt.loc[seed, "iterations"] == (hist.stage == "elm").sum()  # one ELM + tune pair each
        assert bt.loc[seed, "iterations"] == int(np.ceil(hist.iteration.max() / 2))
        assert bt.loc[seed, "cap"] == p.elm_max_iter // 2
        assert bool(bt.loc[seed, "reached"]) == (
            hist.loss.iloc[-1]
            <= p.incremental_params(
                float(np.ptp(p.target.target(sw.x_train, sw.t_train)))
            ).loss_goal
        )
    assert set(runs.run) == set(it.RUNS) and len(runs) == 2 * len(it.RUNS)


def test_the_ielm_rows_are_its_run_cut_at_each_cap(sw, runs):
    # the I-ELM's own run on the normalised sweep, seed 1, to 10 k: its loss at k and at 10 k
    p = StudyParams()
    k = it.iteration_cap(p)
    target = p.target.target(sw.x_train, sw.t_train)
    xs, ts = MinMax.fit(sw.x_train), MinMax.fit(target)
    ip = IELMParams(
        max_nodes=10 * k,
        loss_goal=p.incremental_params(float(np.ptp(target))).loss_goal,
        weight_range=p.elm_range,
        bias_range=p.elm_range,
    )
    _, hist = fit_ielm(xs.transform(sw.x_train), ts.transform(target), ip, rng=generators([1])[0])
    span = float(ts.span[0])
    for run, cap in ((it.IELM_K, k), (it.IELM_10K, 10 * k)):
        row = runs[(runs.run == run) & (runs.seed == 1)].iloc[0]
        n = min(cap, len(hist))
        assert row.iterations == n and row.cap == cap
        assert row.reached == (hist.loss.iloc[n - 1] <= ip.loss_goal)
        # the heading target: the wrapped training error is the network's error in degrees
        assert row.train_rms_deg == pytest.approx(span * np.sqrt(hist.loss.iloc[n - 1]), rel=1e-6)
        assert row.prune_stages == 0


def test_a_loose_goal_is_reached_by_the_ielm_before_its_cap(sw):
    # 30 deg training RMS: a handful of nodes; the row counts the iteration of the first loss at the goal
    p = replace(StudyParams(), elm_goal_deg=30.0)
    r = it.iteration_study(sw, p, seeds=[0])
    row = r[r.run == it.IELM_K].iloc[0]
    assert row.reached and row.iterations < it.iteration_cap(p)
    assert row.train_rms_deg <= 30.0
    target = p.target.target(sw.x_train, sw.t_train)
    xs, ts = MinMax.fit(sw.x_train), MinMax.fit(target)
    goal = p.incremental_params(float(np.ptp(target))).loss_goal
    ip = IELMParams(max_nodes=1000, weight_range=p.elm_range, bias_range=p.elm_range)
    _, hist = fit_ielm(xs.transform(sw.x_train), ts.transform(target), ip, rng=generators([0])[0])
    assert row.iterations == int(np.argmax(hist.loss.to_numpy() <= goal)) + 1


def test_a_huge_tolerance_prunes_and_none_does_not(sw):
    p = replace(StudyParams(), elm_prune_tol=1e12)  # every ELM stage keeps one node
    r = it.iteration_study(sw, p, seeds=[0])
    assert r[r.run == it.BT].prune_stages.iloc[0] > 0
    assert r[r.run == it.BT].n_nodes.iloc[0] == 1
    assert r[r.run == it.BT_NO_PRUNE].prune_stages.iloc[0] == 0
    assert it.prune_tolerances(p, 360.0) == {
        it.BT: 1e12,
        it.BT_NO_PRUNE: 0.0,
        it.BT_GOAL_PRUNE: pytest.approx(p.elm_goal_deg / 360.0),
    }


def _frame(iters: dict, reached: dict, test_rms: dict | None = None, prune=None) -> pd.DataFrame:
    """A runs frame of 6 seeds: ``iters[run]`` and ``reached[run]`` per seed (lists)."""
    rows = []
    for run in it.RUNS:
        for s in range(6):
            rows.append(
                {
                    "run": run,
                    "seed": s,
                    "prune_tol": 0.0 if run == it.BT_NO_PRUNE else 1e-4,
                    "iterations": iters[run][s],
                    "cap": 100 if run != it.IELM_10K else 1000,
                    "reached": reached[run][s],
                    "train_rms_deg": 0.09,
                    "test_rms_deg": (test_rms or {}).get(run, [0.1] * 6)[s],
                    "n_nodes": 10,
                    "prune_stages": (prune or {}).get(run, [0] * 6)[s],
                    "min_abs_beta": 1.0,
                }
            )
    return pd.DataFrame(rows)


def _by_key(claims):
    return {c.key: c for c in claims}


def test_claims_paired_by_seed_with_censoring_and_the_registers_margin():
    bt = [10, 12, 14, 11, 13, 15]
    iters = {
        it.BT: bt,
        it.BT_NO_PRUNE: bt,
        it.BT_GOAL_PRUNE: [b - 5 for b in bt],  # pruning at the goal saves 5 every seed
        it.IELM_K: [100] * 6,
        it.IELM_10K: [b + 7 for b in bt],  # reached 7 later than the back-tuned ELM
    }
    ok = [True] * 6
    reached = {r: ok for r in it.RUNS} | {it.IELM_K: [False] * 6}
    tr = {it.IELM_K: [3.0, 2.0, 4.0, 5.0, 2.5, 3.5]}
    c = _by_key(
        it.iteration_claims(_frame(iters, reached, tr, {it.BT_GOAL_PRUNE: [1] * 6}), StudyParams())
    )
    assert c["b_ielm"].estimate.value == pytest.approx(np.median([100 - b for b in bt]))
    assert c["b_ielm"].verdict == "reproduced"
    assert "6 of 6 pairs with only the I-ELM at its cap" in c["b_ielm"].why
    assert c["b_ielm_10k"].interval == (7.0, 7.0) and c["b_ielm_10k"].verdict == "reproduced"
    assert "every run reached the goal" in c["b_ielm_10k"].why
    assert c["b_ielm_accuracy"].unit == "deg" and c["b_ielm_accuracy"].verdict == "reproduced"
    margin = {e.id: e for e in load_register("patent_b")}["B10"].margin
    assert margin is not None and c["b_prune"].margin == margin
    assert c["b_prune"].interval == (0.0, 0.0) and c["b_prune"].verdict == "no difference"
    assert "fired in 0 of 6 runs" in c["b_prune"].why
    assert c["b_prune_goal"].estimate.value == 5 and c["b_prune_goal"].verdict == "reproduced"
    assert "fired in 6 of 6 runs" in c["b_prune_goal"].why


def test_claims_refute_when_the_back_tuned_elm_needs_more():
    bt = [30, 32, 34, 31, 33, 35]
    iters = {r: bt for r in it.RUNS} | {it.IELM_K: [5, 6, 4, 7, 5, 6], it.IELM_10K: [5] * 6}
    iters[it.BT_NO_PRUNE] = [b - 4 for b in bt]  # pruning costs iterations here
    reached = {r: [True] * 6 for r in it.RUNS} | {it.BT: [False, True, True, True, True, True]}
    tr = {it.IELM_K: [0.05] * 6}
    c = _by_key(it.iteration_claims(_frame(iters, reached, tr), StudyParams()))
    assert c["b_ielm"].verdict == "not reproduced"
    assert "1 with only the back-tuned ELM at its cap" in c["b_ielm"].why
    assert c["b_ielm_accuracy"].verdict == "not reproduced"
    assert c["b_prune"].verdict == "not reproduced"


def test_patent_b_claims_take_the_iteration_rows_and_the_register_owns_them():
    bt = [10, 12, 14, 11, 13, 15]
    iters = {r: bt for r in it.RUNS} | {it.IELM_K: [100] * 6, it.IELM_10K: [1000] * 6}
    rows = it.iteration_claims(_frame(iters, {r: [True] * 6 for r in it.RUNS}), StudyParams())
    es = {e.id: e for e in load_register("patent_b")}
    texts = {c.claim for c in rows}
    assert texts == set(es["B10"].rows) | set(es["B11"].rows)
    assert es["B10"].primary_claim in texts and es["B11"].primary_claim in texts


def test_patent_b_claims_append_the_iteration_rows(runs):
    """Document B's claims code takes the iteration study's rows (the notebook's one call)."""
    seeds = [0, 1]
    base = pd.DataFrame(
        [
            {"method": m, "seed": s, "rms_deg": r, "n_nodes": 12, "min_deg": -1, "max_deg": 1}
            for m, r in (("elm_backtuned", 0.12), ("elm", 0.13), ("ade_bp_pure", 3.0))
            for s in seeds
        ]
        + [
            {"method": m, "seed": -1, "rms_deg": r, "n_nodes": np.nan, "min_deg": -1, "max_deg": 1}
            for m, r in (("physical", 0.11),)
        ]
    )
    node_runs = pd.DataFrame({"method": "ELM", "seed": seeds, "n_nodes": 14, "reached": True})
    g_runs = pd.DataFrame(
        [
            {"variant": v, "seed": s, "test_rms_deg": 0.3}
            for v in ("median filter + screen (patent)", "no preparation")
            for s in seeds
        ]
    )
    small = pd.DataFrame(
        [
            {
                "n_train": 8,
                "method": "ELM back-tuned",
                "seed": s,
                "train_rms_deg": 0.0,
                "test_rms_deg": 0.1,
                "n_nodes": 1,
            }
            for s in seeds
        ]
    )
    without = patent_b_claims(base, node_runs, g_runs, small, StudyParams(), 50)
    with_it = patent_b_claims(base, node_runs, g_runs, small, StudyParams(), 50, iterations=runs)
    added = [c for c in with_it if c.claim not in {c.claim for c in without}]
    assert len(with_it) == len(without) + 5
    assert {c.key for c in added} == {
        "b_ielm",
        "b_ielm_10k",
        "b_ielm_accuracy",
        "b_prune",
        "b_prune_goal",
    }
