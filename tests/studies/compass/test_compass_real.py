"""navlib.studies.compass.real: the papers' methods on BROAD's real level compass sweeps.

The study runs on the real files (skipped where ``../shared/realdata`` is absent) with the cheap methods
(uncompensated, the exact planar fit and the two ELMs; the networks of paper A cost a minute and add
nothing to what is checked here).  That the numbers do not depend on the workers is
``tests/workbench/test_compare.py::test_a_local_cluster_gives_the_numbers_of_one_process`` (the study only calls
:func:`navlib.workbench.compare.compare`)."""

import numpy as np
import pandas as pd
import pytest

from navlib import claims as registry
from navlib import verdicts
from navlib.errors import InputError
from navlib.paths import DATA_DIR
from navlib.studies.compass import real as cr

CHEAP = ("uncompensated", "physical", "elm", "elm_backtuned")
needs_data = pytest.mark.skipif(
    not cr.available(), reason="BROAD's level sweeps are not in ../shared/realdata"
)


@pytest.fixture(scope="module")
def real():
    if not cr.available():
        pytest.skip("BROAD's level sweeps are not in ../shared/realdata")
    return cr.real_compass_study(seeds=6, methods=CHEAP, workers=1)


@pytest.fixture(scope="module")
def paper():
    return pd.read_csv(DATA_DIR / "paper_a_error_ranges.csv")


def test_absent_data_give_none_and_every_glue_text_says_so(tmp_path):
    assert cr.real_compass_study(folder=tmp_path) is None
    assert cr.answer(None, []) == dict.fromkeys(cr.ANSWER_KEYS, cr.ABSENT)
    with pytest.raises(InputError, match="ls_tolerance_deg"):
        cr.real_compass_study(ls_tolerance_deg=30.0, folder=tmp_path)


@needs_data
def test_both_recordings_split_by_sweep_every_row_held_out_once(real):
    t05, sessions = real.results["trial05"], real.results["sessions"]
    assert t05.rule == sessions.rule == "sweep"
    assert [f.test_what for f in t05.folds] == ["sweep 1", "sweep 2"]
    assert len(sessions.folds) == sessions.frame["sweep"].nunique() == 4  # one fold per session
    for res in (t05, sessions):
        held = np.sort(np.concatenate([f.test for f in res.folds]))
        assert np.array_equal(held, np.arange(len(res.frame)))
        assert set(res.methods) == set(CHEAP)
    folds = cr.folds_table(real)
    assert len(folds) == 6 and list(folds.columns) == [
        "recording",
        "fold",
        "fitted on",
        "scored on",
    ]


@needs_data
def test_tables_are_complete_and_their_verdicts_come_from_the_one_rule(real):
    for key in ("trial05", "sessions"):
        res, tab = real.results[key], cr.method_table(real, key)
        assert list(tab.columns) == [
            "method",
            "held-out RMS (deg)",
            "minus best (deg)",
            "against the best",
        ]
        assert len(tab) == len(CHEAP) and tab["against the best"].iloc[0] == "best"
        best = res.best
        for mid, row in zip(res.table().method, tab.itertuples()):
            r = res.rms(mid)
            assert row._2.startswith(f"{np.median(r):.3f}")
            if mid == best:
                continue
            a, b = np.broadcast_arrays(r, res.rms(best))
            est = verdicts.exact(a[0] - b[0]) if a.size == 1 else verdicts.paired_difference(a, b)
            rep, _ = verdicts.decide(est.interval, 0.0, "above")
            assert row._4 == {True: "worse", None: "not told apart"}[rep]
            assert row._3.startswith(f"{est.value:+.3f}")


@needs_data
def test_real_claims_carry_data_real_the_simulated_wording_and_the_primary_reading(real, paper):
    cs = cr.real_claims(real, paper)
    entries = {t: e for e in registry.entries("compass") for t in e.rows}
    assert cs and all(c.data == "real" and c.source == entries[c.claim].origin for c in cs)
    assert all(c.claim in entries for c in cs)  # the simulated rows' own words
    primary = [c for c in cs if "; " not in c.reading]
    assert {c.claim for c in primary} == {
        "the back-tuned ELM improves the uncompensated heading",
        "ELM back-tuned beats the explicit (ellipse) model fitted on its training readings",
        "back-tuning beats a plain ELM of 19 nodes",
    }
    assert all(c.reading == entries[c.claim].primary_reading for c in primary)
    assert all(c.reading.endswith("; BROAD trials 2, 3, 5, 7") for c in cs if c not in primary)
    phys = next(c for c in primary if "explicit" in c.claim)
    runs = cr.runs_frame(real.results["trial05"])
    want = verdicts.paired_difference(
        runs[runs.method == "physical"].rms_deg.repeat(6).to_numpy(),
        runs[runs.method == "elm_backtuned"].rms_deg.to_numpy(),
    )
    assert phys.estimate == want and not phys.by_construction  # real data: nothing by construction
    assert phys.verdict == verdicts.verdict_name(*verdicts.decide(want.interval, 0.0, "above"))
    recs = [
        r for r in registry.evaluate("compass", [c.record() for c in cs]) if r["data"] == "real"
    ]
    assert {r["id"] for r in recs} == {"B01", "B14", "B09"}  # B08's real row is B14's
    by_id = {e.id: e for e in registry.entries("compass")}
    assert all(
        r["primary_reading"] == by_id[r["id"]].primary_reading and r["row_claim"] for r in recs
    )
    assert next(r for r in recs if r["id"] == "B14")["source"] == "paper"


@needs_data
def test_a_method_left_out_for_its_headings_makes_its_claims_not_run(real, paper):
    res = real.results["trial05"]
    why = (
        "needs 8 headings (...) and the training part of fold 1 (sweep 2) has 7 (none near 135 deg)"
    )
    res.not_run.append({"method": "ls8", "label": "LS", "why": why})
    try:
        cs = [c for c in cr.real_claims(real, paper) if "; " not in c.reading]
    finally:
        res.not_run.pop()
    ls = [c for c in cs if "8-position LS" in c.claim]
    assert [c.claim for c in ls] == [
        "ELM back-tuned beats 8-position LS [Smith 5 terms]"
    ]  # one per entry
    c = ls[0]
    assert (
        c.estimate is None and c.verdict == "cannot be judged" and c.record()["reason"] == "not run"
    )
    assert "none near 135 deg" in c.reason and c.data == "real"


@needs_data
def test_answer_and_verdict_changes(real, paper):
    cs = cr.real_claims(real, paper)
    a = cr.answer(real, cs)
    assert (
        set(a) == set(cr.ANSWER_KEYS)
        and a["best"] == real.results["trial05"].labels[real.results["trial05"].best]
    )
    assert a["ranking_holds"] == "does not hold"  # no comparison of paper A was run here
    sim = [c.__class__(**{**c.__dict__, "data": "simulated"}) for c in cs[:1]]
    ch = cr.verdict_changes(cs, sim)
    same = ch.claim == cs[0].claim  # on both recordings, against the one row
    assert (
        len(ch) == len(cs) and set(ch.differs[same]) == {"no"} and set(ch.differs[~same]) == {"–"}
    )
    assert list(ch.recording[same]) == ["BROAD trial 05", "BROAD trials 2, 3, 5, 7"]


@needs_data
def test_the_figure_draws_each_method_and_the_papers_range_where_it_has_one(real, paper):
    import matplotlib.pyplot as plt

    fig = cr.real_figure(real, paper)
    try:
        panels = [ax for ax in fig.axes if ax.get_title()]
        assert len(panels) == len(CHEAP)
        assert not any(ax.patches for ax in panels)  # uncompensated and the ELMs: no printed range
        assert fig.axes[-1].get_legend() is not None or any(ax.get_legend() for ax in fig.axes)
    finally:
        plt.close(fig)
