"""Tests for navlib.compass_study's patent-B additions: the ELM methods, the patent's data preparation,
the glitch, node-count and small-sample studies."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from navlib.data.compass_sweeps import split_sweeps

from navlib.sensors.compass import SweepConfig, simulate_train_test
from navlib.studies.paper_a import (ALL_METHODS, STOCHASTIC, StudyParams, Sweeps, compensate, seed_study,
    summarize, test_errors as heading_errors)
from navlib.studies.patent_b import (GLITCH_VARIANTS, even_indices, glitch_run, glitch_study,
    node_count_curve, prepare_patent_data, small_sample_study)
from navlib.errors import InputError


@pytest.fixture(scope="module")
def frames():
    return split_sweeps(simulate_train_test(seed=2024))


@pytest.fixture(scope="module")
def sw(frames):
    return Sweeps(*frames)


def test_elm_methods_registered():
    for m in ("ELM", "ELM back-tuned"):
        assert m in ALL_METHODS and m in STOCHASTIC


def test_elm_in_seed_study_with_node_count(sw):
    runs = seed_study(sw, seeds=range(3), methods=("uncompensated", "LS 8-position", "ELM", "ELM back-tuned"))
    assert set(runs.method) == {"uncompensated", "LS 8-position", "ELM", "ELM back-tuned"}
    assert (runs.method == "ELM back-tuned").sum() == 3
    assert runs.loc[runs.method == "ELM", "n_nodes"].eq(StudyParams().elm_nodes).all()
    bt = runs.loc[runs.method == "ELM back-tuned", "n_nodes"]
    assert bt.notna().all() and (bt >= 1).all() and (bt <= StudyParams().elm_max_nodes).all()
    assert runs.loc[runs.method.isin(["uncompensated", "LS 8-position"]), "n_nodes"].isna().all()
    s = summarize(runs)
    for col in ("runs", "median_rms_deg", "rms_p10_deg", "rms_p90_deg", "median_time_s"):
        assert col in s
    assert s.loc["ELM back-tuned", "min_nodes"] <= s.loc["ELM back-tuned", "median_nodes"] \
        <= s.loc["ELM back-tuned", "max_nodes"]
    assert np.isnan(s.loc["uncompensated", "median_nodes"])
    # summarize still works on runs without the column (older tables)
    assert "median_nodes" not in summarize(runs.drop(columns="n_nodes"))


@pytest.mark.parametrize("method", ["ELM", "ELM back-tuned"])
def test_elm_is_deterministic_for_a_seed(sw, method):
    a, ia = compensate(method, sw, seed=3)
    b, ib = compensate(method, sw, seed=3)
    c, _ = compensate(method, sw, seed=4)
    np.testing.assert_array_equal(a, b)
    assert ia["n_nodes"] == ib["n_nodes"]
    assert not np.array_equal(a, c)


@pytest.mark.parametrize("method", ["ELM", "ELM back-tuned"])
@pytest.mark.parametrize("target", ["heading", "error"])
def test_elm_beats_uncompensated_by_far(sw, method, target):
    p = StudyParams(network_target=target)
    before = np.sqrt(np.mean(heading_errors(sw.m_test, sw) ** 2))
    for seed in range(3):
        corrected, info = compensate(method, sw, p, seed=seed)
        rms = np.sqrt(np.mean(heading_errors(corrected, sw) ** 2))
        assert before > 10.0
        assert rms < 0.5, (method, target, seed, rms)     # 16 deg -> a few tenths at most
        assert np.all(np.abs(heading_errors(corrected, sw)) < 1.0)


def test_back_tuned_elm_stops_at_goal(sw):
    _, info = compensate("ELM back-tuned", sw, seed=0)
    hist = info["history"]
    goal = (StudyParams().elm_goal_deg / 360.0) ** 2
    assert hist.loss.iloc[-1] <= goal < hist.loss.iloc[-2]
    assert info["n_nodes"] == hist.n_nodes.iloc[-1] < StudyParams().elm_max_nodes
    # a narrow weight range does not reach the goal and hits the node cap (the chapter's scale argument)
    _, info1 = compensate("ELM back-tuned", sw, replace(StudyParams(), elm_range=1.0), seed=0)
    assert info1["n_nodes"] == StudyParams().elm_max_nodes


def test_bad_elm_study_params():
    for kw, word in ((dict(elm_nodes=0), "elm_nodes"), (dict(elm_range=0.0), "elm_range"),
                     (dict(elm_goal_deg=-1.0), "elm_goal_deg"), (dict(elm_max_iter=0), "elm_max_iter"),
                     (dict(elm_max_nodes=1.5), "elm_max_nodes")):
        with pytest.raises(InputError, match=word) as err:
            StudyParams(**kw).validate()
        assert "\n" not in str(err.value)


def _spiked(frame: pd.DataFrame, rows, ut=8.0) -> pd.DataFrame:
    f = frame.copy()
    for r in rows:                      # a spike along the vertical axis: changes m . g, barely the heading
        f.loc[r, "mag_z_ut"] += ut
    return f


def test_prepare_patent_data_rejects_injected_glitches_and_keeps_clean(frames):
    train, _ = frames
    clean = prepare_patent_data(train, rng=0, median=False)
    assert clean.n_rejected == 0 and clean.keep.all()
    spiked = _spiked(train, [20, 64, 99])
    d = prepare_patent_data(spiked, rng=0, median=False)
    assert np.flatnonzero(~d.keep).tolist() == [20, 64, 99]
    assert d.true_deg.size == len(train) - 3
    lo, hi = d.screen.band
    assert not (lo <= d.screen.dot[20] <= hi)
    # split 90/10 of the kept readings, normalisation of the kept readings
    assert d.train_idx.size == round(0.9 * d.true_deg.size)
    assert np.intersect1d(d.train_idx, d.test_idx).size == 0
    assert d.x_scale.transform(d.x).min() == 0.0 and d.x_scale.transform(d.x).max() == 1.0
    # the median filter (window 3) removes an isolated spike before the screen sees it
    filtered = prepare_patent_data(spiked, rng=0)
    assert filtered.n_rejected == 0
    # no preparation keeps everything
    assert prepare_patent_data(spiked, rng=0, median=False, screen=False).keep.all()


def test_prepare_patent_data_bad_input(frames):
    train, test = frames
    with pytest.raises(InputError, match="acc_x_ms2"):
        prepare_patent_data(train.drop(columns="acc_x_ms2"))
    with pytest.raises(InputError, match="window"):
        prepare_patent_data(train, window=4)
    with pytest.raises(InputError, match="unknown preparation"):
        glitch_run(train, test, "magic")


def test_glitch_study_preparation_helps():
    train, test = split_sweeps(simulate_train_test(config=SweepConfig(glitch_prob=0.05), seed=7))
    assert train.glitch.sum() >= 3
    runs = glitch_study(train, test, seeds=range(2), method="ELM")
    assert set(runs.variant) == set(GLITCH_VARIANTS) and len(runs) == 2 * len(GLITCH_VARIANTS)
    med = runs.groupby("variant").test_rms_deg.median()
    assert med["median filter + screen (patent)"] < med["no preparation"]
    scr = runs[runs.variant == "dot-product screen"]
    assert (scr.glitches_rejected > 0).all() and (scr.glitches_rejected <= scr.n_rejected).all()
    assert runs.loc[runs.variant == "no preparation", "n_rejected"].eq(0).all()
    err, clean, d, info = glitch_run(train, test, "no preparation", seed=0, method="ELM")
    assert err.shape == (len(test),) and clean.sum() == len(test) - test.glitch.sum()


def test_node_count_curve(sw):
    c = node_count_curve(sw, seeds=range(2), max_nodes=12)
    assert set(c.method) == {"ELM", "ELM back-tuned"}
    elm = c[c.method == "ELM"]
    assert sorted(elm.n_nodes.unique()) == list(range(1, 13))
    bt = c[c.method == "ELM back-tuned"]
    assert bt.n_nodes.max() == 12 and (bt.groupby("seed").size() >= 10).all()
    med = c.groupby(["method", "n_nodes"]).test_rms_deg.median()
    # one node cannot follow the map, twelve can (to well under a degree)
    for m in ("ELM", "ELM back-tuned"):
        assert med[m, 1] > 10 * med[m, 12] and med[m, 12] < 1.0


def test_even_indices_and_subset(sw):
    idx = even_indices(121, 8)
    assert idx[0] == 0 and idx[-1] == 120 and idx.size == 8
    sub = sw.subset(idx)
    np.testing.assert_array_equal(sub.t_train, sw.t_train[idx])
    np.testing.assert_array_equal(sub.x_test, sw.x_test)
    assert sw.t_train.size == 121                      # the original is unchanged
    with pytest.raises(InputError, match="subset"):
        sw.subset([5, 3])
    with pytest.raises(InputError, match="n="):
        even_indices(121, 1)


def test_small_sample_study(sw):
    p = StudyParams(bp_epochs=300)
    runs = small_sample_study(sw, sizes=(15,), params=p, seeds=range(2), big_hidden=10,
                              second_order_seeds=range(1))
    assert set(runs.method) == {"ELM back-tuned", "ELM", "BP 1-10-1 (Adam)", "BP 1-10-1 (LM/TRF)",
                                "physical model"}
    assert runs.n_train.eq(15).all()
    assert len(runs) == 2 * 3 + 1 + 1
    converged = runs[runs.method == "BP 1-10-1 (LM/TRF)"].iloc[0]
    assert converged.train_rms_deg < 0.1               # a second-order method fits the readings
    assert runs.loc[runs.method == "BP 1-10-1 (Adam)", "n_nodes"].eq(10).all()
    phys = runs[runs.method == "physical model"].iloc[0]
    assert phys.test_rms_deg < 0.3                     # five parameters from 15 readings: near the floor
    # with 15 nodes or fewer (back-tuned ELM's goal) the training readings are fitted closely
    bt = runs[runs.method == "ELM back-tuned"]
    assert (bt.train_rms_deg <= StudyParams().elm_goal_deg + 1e-9).all()
