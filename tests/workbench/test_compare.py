"""navlib.workbench.compare (issue 36): the split rules (disjoint training and test rows, every row a test
row once), the method list (paper A's primary reading from its claims register), the network input's branch,
the statistics and verdicts against the best method, the report folder, and the same numbers in this
process, on a local cluster of 2 workers and on a scheduler started here on 127.0.0.1."""

from __future__ import annotations

import csv
import inspect
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from navlib import names, verdicts
from navlib.angles import wrap_deg
from navlib.data.compass_sweeps import load_sweeps
from navlib.errors import InputError
from navlib.methods import compass_methods as cm
from navlib.methods.de import DEParams
from navlib.paths import data_path
from navlib.sensors.compass import PAPER_A_EARTH, CompassErrors, simulate_train_test
from navlib.sensors.planar import PlanarModel
from navlib.workbench import compare as C

ROOT = Path(__file__).resolve().parents[2]
#: Small training budgets: the tests check the bookkeeping, not the methods' accuracy.
FAST = replace(
    cm.MethodParams(),
    de=DEParams(max_generations=30),
    lm=replace(cm.MethodParams().lm, epochs=10),
    elm_max_iter=20,
)


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    """Paper A's two simulated sweeps (121 readings each, 0..360 deg every 3 deg) as a file."""
    path = tmp_path_factory.mktemp("compare") / "sweeps.csv"
    simulate_train_test(CompassErrors(), PAPER_A_EARTH, seed=7).to_csv(path, index=False)
    return path


def _assert_partition(folds, n):
    """Every fold's training and test rows are disjoint and cover the file; every row is a test row once."""
    for f in folds:
        assert np.intersect1d(f.train, f.test).size == 0
        assert np.array_equal(np.sort(np.concatenate([f.train, f.test])), np.arange(n))
    tested = np.sort(np.concatenate([f.test for f in folds]))
    assert np.array_equal(tested, np.arange(n))


# ------------------------------------------------------------------------------------------ splits
def test_sweep_split_tests_each_sweep_once_trained_on_the_others():
    frame = pd.DataFrame({"sweep": [1, 1, 2, 2, 2, 1, 3, 3]})
    folds = C.sweep_folds(frame.iloc[:6])
    _assert_partition(folds, 6)
    assert [f.test_what for f in folds] == ["sweep 1", "sweep 2"] and folds[
        0
    ].train_what == "sweep 2"
    assert list(folds[0].test) == [0, 1, 5] and list(folds[1].train) == [0, 1, 5]
    three = C.sweep_folds(frame)  # leave one sweep out
    _assert_partition(three, 8)
    assert [f.train_what for f in three] == ["sweeps 2, 3", "sweeps 1, 3", "sweeps 1, 2"]
    with pytest.raises(InputError, match="needs at least 2 sweeps.*has 1"):
        C.sweep_folds(pd.DataFrame({"sweep": [1, 1, 1]}), "f.csv")


def test_heading_split_alternates_bins_all_round_and_both_ways():
    t = np.arange(0.0, 360.0, 1.0)
    folds = C.bin_folds(t, 15.0)
    _assert_partition(folds, t.size)
    k = np.floor(t / 15.0).astype(int)
    assert np.all(k[folds[0].test] % 2 == 1) and np.all(k[folds[0].train] % 2 == 0)
    assert np.array_equal(folds[1].test, folds[0].train) and np.array_equal(
        folds[1].train, folds[0].test
    )
    # 360 closes onto bin 0 (even), 359 sits in the last bin (odd): neighbours across north alternate too
    f = C.bin_folds(np.array([359.0, 360.0, 0.5, 14.9, 15.0]), 15.0)
    assert list(f[0].test) == [0, 4] and list(f[0].train) == [1, 2, 3]
    for bad in (7.0, 0.0, 240.0, 120.0):  # 360/120 = 3 bins: odd, cannot alternate
        with pytest.raises(InputError, match="bin-deg"):
            C.check_bin_deg(bad)


def test_random_split_halves_by_the_seed():
    a = C.random_folds(11, seed=3)
    _assert_partition(a, 11)
    assert sorted([a[0].test.size, a[1].test.size]) == [5, 6]
    b = C.random_folds(11, seed=3)
    assert all(np.array_equal(x.test, y.test) for x, y in zip(a, b))
    assert not np.array_equal(C.random_folds(11, seed=4)[0].test, a[0].test)


@pytest.mark.parametrize("split", ["sweep", "heading", "random"])
def test_every_split_of_a_file_holds_each_row_out_once(sim, split):
    r = C.compare("compass", sim, methods="uncompensated,physical", split=split, seeds=1, seed=5)
    _assert_partition(r.folds, len(r.frame))
    assert r.rule == split and len(r.folds) == 2
    for f in r.folds:
        assert f.train.size >= C.MIN_TRAIN_ROWS
    # the uncompensated error of a row is measured - true, whichever fold held it out
    frame = load_sweeps(sim)
    want = wrap_deg(frame.measured_heading_deg.to_numpy() - frame.true_heading_deg.to_numpy())
    np.testing.assert_allclose(r.errors["uncompensated"][0], want, atol=1e-9)


def test_the_default_split_is_sweep_with_two_sweeps_else_heading(sim, tmp_path):
    assert C.compare("compass", sim, methods="uncompensated", seeds=1).rule == "sweep"
    one = tmp_path / "one.csv"
    pd.read_csv(sim).query("sweep == 1").drop(columns="sweep").to_csv(one, index=False)
    r = C.compare("compass", one, methods="uncompensated", seeds=1)
    assert r.rule == "heading" and r.folds[0].test_what == "odd 15-deg heading bins"
    with pytest.raises(InputError, match="one.csv: --split sweep needs at least 2 sweeps"):
        C.compare("compass", one, methods="uncompensated", split="sweep")
    with pytest.raises(InputError, match="--split='turns'"):
        C.compare("compass", sim, methods="uncompensated", split="turns")


# ------------------------------------------------------------------------------------------ methods
def _register_primary_reading(claim_id="A01"):
    with open(data_path("claims_paper_a.csv"), encoding="utf-8") as fh:
        return next(r for r in csv.DictReader(fh) if r["id"] == claim_id)["primary_reading"]


def test_the_default_methods_are_the_papers_in_the_primary_reading():
    primary = _register_primary_reading()
    assert primary == cm.R4 and _register_primary_reading("A03") == primary
    ls, bp, de, ade = cm.READINGS[primary]
    assert C.COMPASS_DEFAULT == (
        "uncompensated",
        *cm.LS_MODELS,
        "physical",
        bp,
        de,
        ade,
        *cm.ELM_METHODS,
    )
    assert (bp, de, ade) == ("bp_matlab", "de_bp_full_trainlm", "ade_bp_full_trainlm")
    assert set(C.COMPASS.methods) == set(cm.METHODS)
    assert all(cm.METHODS[m].stochastic == C.COMPASS.stochastic(m) for m in C.COMPASS.methods)
    # the command line's lists (stdlib only) equal the library's
    assert names.COMPARE_DEFAULT_METHODS == {"compass": C.COMPASS_DEFAULT}
    assert names.COMPARE_SYSTEM_NAMES == tuple(sorted(C.COMPARISONS))
    assert names.COMPARE_SPLITS == C.SPLITS == C.COMPASS.splits
    s = C.compass_settings()
    assert (s.params.ls_tol_deg, s.bin_deg) == (
        names.COMPARE_LS_TOLERANCE_DEG,
        names.COMPARE_BIN_DEG,
    )
    assert inspect.signature(C.compare).parameters["seeds"].default == names.COMPARE_SEEDS


def test_method_names_are_checked_and_listed():
    ids, explicit = C.resolve_methods(C.COMPASS, None)
    assert ids == list(C.COMPASS_DEFAULT) and not explicit
    assert C.resolve_methods(C.COMPASS, " elm,ls8 ,elm") == (["elm", "ls8"], True)
    with pytest.raises(InputError) as err:
        C.resolve_methods(C.COMPASS, "elm,ADE-BP")
    msg = str(err.value)
    assert (
        "unknown method 'ADE-BP'" in msg and "known: uncompensated, ls8," in msg and "\n" not in msg
    )
    assert all(m in msg for m in cm.METHODS)
    with pytest.raises(InputError, match="--methods: empty"):
        C.resolve_methods(C.COMPASS, " , ")
    with pytest.raises(InputError, match="unknown system 'gyro'"):
        C.compare("gyro", "x.csv")


def test_network_input_is_one_branch_cut_in_the_narrowest_gap():
    t = np.arange(0.0, 363.0, 3.0)  # paper A's sweep: 0 and 360 both read
    x = C.network_input(t, t)
    assert x[0] == x[-1] == 0.0 and np.all(np.diff(x[:-1]) > 0)  # the cut at north; 360 read as 0
    m = np.array([10.0, 20.0, 200.0, 205.0, 300.0, 330.0])  # narrowest gap 200..205: cut at 202.5
    xs = C.network_input(m, m)
    assert np.all((xs >= 202.5) & (xs < 562.5)) and np.allclose(np.mod(xs, 360.0), m)
    shuffled = np.random.default_rng(0).permutation(m)  # any order: the same branch
    np.testing.assert_allclose(C.network_input(shuffled, m), xs)
    # a test heading in the widest gap (205..300) lies inside the branch: interpolated, not extrapolated
    assert 205.0 < C.network_input(m, np.array([250.0]))[0] < 300.0


def test_the_exact_model_corrects_a_noiseless_planar_compass_on_every_fold():
    model = PlanarModel(
        params={"yaw_deg": 2.0, "hard_x": 0.2, "hard_y": -0.1, "soft_e": 0.05, "soft_f": 0.02}
    )
    t = np.arange(0.0, 360.0, 3.0)
    frame = pd.DataFrame({"true_heading_deg": t, "measured_heading_deg": model.predict_measured(t)})
    r = C.compare(
        "compass",
        "planar.csv",
        methods="physical,ls8_planar,uncompensated",
        split="heading",
        seeds=1,
        frame=frame,
    )
    assert (
        np.max(np.abs(r.errors["physical"])) < 1e-6
        and np.max(np.abs(r.errors["ls8_planar"])) < 1e-6
    )
    assert r.best in ("physical", "ls8_planar") and r.table().method.iloc[-1] == "uncompensated"


def test_eight_position_ls_refused_when_named_left_out_by_default():
    """The 8-position LS takes the training reading nearest to each of 0, 45, ..., 315 deg within the
    tolerance: a file without readings near 135 and 225 deg refuses it when it is named, leaves it out (with
    the reason) from the default list, and runs it with a tolerance that reaches them."""
    t = np.concatenate(
        [np.arange(0.0, 120.0, 3.0), np.arange(150.0, 210.0, 3.0), np.arange(240.0, 360.0, 3.0)]
    )
    frame = pd.DataFrame({"true_heading_deg": t, "measured_heading_deg": np.mod(t + 1.0, 360.0)})
    with pytest.raises(InputError) as err:
        C.compare(
            "compass", "gappy.csv", methods="elm,ls8", split="heading", frame=frame, params=FAST
        )
    msg = str(err.value)
    assert msg.startswith("gappy.csv: method ls8 (LS 8-position (Smith, 5 terms)) needs 8 headings")
    assert "has 6 (none near 135, 225 deg)" in msg and "\n" not in msg
    r = C.compare(
        "compass", "gappy.csv", methods=None, split="heading", seeds=2, frame=frame, params=FAST
    )
    assert [d["method"] for d in r.not_run] == list(cm.LS_MODELS) and set(r.methods) == set(
        C.COMPASS_DEFAULT
    ) - set(cm.LS_MODELS)
    assert r.not_run_lines() == [f"not run: ls8, ls8_planar, ls8_h3: {r.not_run[0]['why']}"]
    ok = C.compare(
        "compass",
        "gappy.csv",
        methods="ls8",
        split="sweep",
        frame=frame.assign(sweep=np.arange(t.size) % 2 + 1),
        ls_tolerance_deg=20.0,
    )
    assert (
        ok.methods == ["ls8"] and np.max(np.abs(ok.errors["ls8"])) < 1e-6
    )  # a constant 1 deg error
    with pytest.raises(InputError, match="--ls-tolerance"):
        C.compare("compass", "gappy.csv", methods="ls8", frame=frame, ls_tolerance_deg=23.0)


def test_too_few_training_rows_name_the_fold():
    frame = pd.DataFrame(
        {
            "true_heading_deg": [0.0, 10, 20, 30, 40, 50, 60, 70, 80, 90],
            "measured_heading_deg": [1.0, 11, 21, 31, 41, 51, 61, 71, 81, 91],
        }
    )
    with pytest.raises(
        InputError,
        match=r"few.csv: fold 1 \(train even 15-deg heading bins, test odd 15-deg "
        r"heading bins\) has \d training and \d test rows; at least 8 and 1",
    ):
        C.compare("compass", "few.csv", methods="uncompensated", frame=frame)


# ------------------------------------------------------------------------------------------ statistics
def _result(rms: dict, stochastic: dict, margin=None) -> C.CompareResult:
    """A result whose methods have the given RMS per run (one test row each run: error = the RMS)."""
    frame = pd.DataFrame({"true_heading_deg": [0.0], "measured_heading_deg": [0.0]})
    fold = C.Fold(np.array([], dtype=int), np.array([0]), "a", "b")
    errors = {m: np.asarray(v, dtype=float)[:, None] for m, v in rms.items()}
    return C.CompareResult(
        "compass",
        "deg",
        "x.csv",
        frame,
        "sweep",
        [fold],
        max(len(v) for v in rms.values()),
        0,
        list(rms),
        {m: m for m in rms},
        stochastic,
        errors,
        margin=margin,
    )


def test_statistics_and_verdicts_against_the_best():
    good = [0.50, 0.52, 0.49, 0.51, 0.55, 0.50, 0.48]
    close = [0.51, 0.50, 0.52, 0.50, 0.54, 0.52, 0.47]
    r = _result(
        {"det": [0.9], "good": good, "close": close, "worse": [v + 0.3 for v in good]},
        {"det": False, "good": True, "close": True, "worse": True},
    )
    assert r.best == "good"
    t = r.table().set_index("method")
    assert list(t.index) == ["good", "close", "worse", "det"]
    e = verdicts.median_ci(good)
    assert (t.loc["good", "rms"], t.loc["good", "rms_lo"], t.loc["good", "rms_hi"]) == (
        e.value,
        e.lo,
        e.hi,
    )
    assert r.estimate("det")[0] == verdicts.exact(0.9)
    vs = r.versus_best("worse")
    assert vs["difference"] == verdicts.paired_difference([v + 0.3 for v in good], good)
    assert vs["verdict"] == "reproduced" and vs["finding"] == "best is better"
    assert (
        r.versus_best("close")["finding"] == "not told apart"
        and r.versus_best("close")["basis"] == "straddles"
    )
    det = r.versus_best("det")  # one value paired with every seed of the best
    assert det["difference"] == verdicts.paired_difference([0.9] * 7, good)
    assert good[r.median_run("good")] == np.median(good)
    eq = _result({"good": good, "close": close}, {"good": True, "close": True}, margin=0.05)
    assert (
        eq.versus_best("close")["verdict"] == "no difference"
        and "no difference at 0.05" in eq.versus_best("close")["finding"]
    )
    few = _result({"a": [0.5, 0.6, 0.7], "b": [0.8, 0.9, 1.0]}, {"a": True, "b": True})
    assert few.estimate("a")[0] is None and "6 runs" in few.estimate("a")[1]
    assert few.versus_best("b")["finding"] == "too few seeds for an interval"
    out = json.loads(json.dumps(few.to_dict(), allow_nan=False))
    assert (
        out["methods"][0]["rms"] is None and out["methods"][1]["versus_best"]["difference"] is None
    )


# ------------------------------------------------------------------------------------------ report folder
def test_the_report_folder_is_claimed_before_the_work_and_never_overwritten(sim, tmp_path):
    folder = tmp_path / "a" / "b"
    with pytest.raises(RuntimeError):
        with C.claimed_report(folder) as paths:
            assert all(Path(p).exists() for p in paths)
            raise RuntimeError("the work failed")
    assert not any(folder.iterdir())  # the claimed, empty files are gone again
    (folder / "compare.png").write_text("mine")
    with pytest.raises(InputError, match="compare.png: already exists; not overwritten"):
        with C.claimed_report(folder):
            pass
    assert (folder / "compare.png").read_text() == "mine" and not (folder / "compare.md").exists()
    (tmp_path / "file").write_text("")
    with pytest.raises(InputError, match="is a file"):
        with C.claimed_report(tmp_path / "file"):
            pass
    r = C.compare("compass", sim, methods="uncompensated,physical,ls8", seeds=1)
    with C.claimed_report(tmp_path / "rep") as paths:
        md, png = C.write_report(r, paths)
    text = md.read_text()
    assert (
        "| physical model | 1 |" in text
        and "![error against true heading" in text
        and png.stat().st_size > 0
    )


# ------------------------------------------------------------------------------------------ engine
def _fast_compare(**where):
    return C.compare(
        "compass",
        ROOT / "data" / "compass_sweeps.csv",
        methods="uncompensated,ls8,elm,elm_backtuned,bp_matlab,ade_bp_full_trainlm",
        seeds=5,
        seed=11,
        params=FAST,
        **where,
    )


@pytest.fixture(scope="module")
def one_process():
    return _fast_compare(workers=1)


def _same(a: C.CompareResult, b: C.CompareResult):
    assert a.methods == b.methods
    for m in a.methods:
        np.testing.assert_array_equal(a.errors[m], b.errors[m])
    assert a.to_dict() == b.to_dict()


@pytest.mark.slow
def test_a_local_cluster_gives_the_numbers_of_one_process(one_process):
    _same(one_process, _fast_compare(workers=2))
    e = one_process.errors["elm"]
    assert e.shape == (5, 242) and len({row.tobytes() for row in e}) == 5  # every seed its own run


@pytest.mark.slow
def test_a_scheduler_started_here_gives_the_numbers_of_one_process(one_process, remote):
    _same(one_process, _fast_compare(scheduler=remote))
