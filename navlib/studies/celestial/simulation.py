"""The celestial chapter's experiment: :func:`simulate` flies the runs, filters them and trains the networks
(the heavy step); :mod:`~navlib.studies.celestial.tables` and :mod:`~navlib.studies.celestial.claims` turn its
output (:class:`StudyData`) into the chapter's tables, figures and claims.

Protocol.  Each *repeat* (seed) draws a training set and a held-out test set of runs.  Simulation 1
(``level``): straight level flight, every run on the same path, different noise.  Simulation 2
(``s_turns``): irregular yaw S-manoeuvres; the training runs fly one manoeuvre sequence and the test runs
another (different ``manoeuvre_seed``).  One device (same constant drift, bias and gyro scale factor) in every
run; the initial attitude error, IMU noise and star-sensor noise are drawn per run.  The networks
(``n_in``-``n_hidden``-3, logsig, purelin) learn the KF's Euler-angle error (arcsec) from the gain features
at each filter epoch; the BPKF attitude is the KF attitude minus the network's output.  ``held-out``: trained
on the training runs, scored on the test runs; ``same run``: trained and scored on each test run alone (what a
single-run study may have done: the network is scored on the data it was trained on).  Accuracy: RMS over
the run after ``settle_s`` per Euler angle (arcsec).  Training time: ``n_timings`` paired repetitions, the
45-input and the 6-input net timed in the same repetition on the same training set; the running filter's
network step (features of the epoch's gain and one forward pass, :mod:`~navlib.studies.celestial.step`)
with 45 and 6 inputs in as many paired repetitions.  The innovation test
runs on each run alone (train and test runs), so how often it names an effect is a rate over runs.

Beyond the paper's tables: the paper's "average time of one training" as MATLAB trains, a whole
``trainlm`` training with validation stop of the 45-, 6- and 9-input nets (``_lm_timing``,
:mod:`navlib.methods.feedforward`) in ``lm_timings`` paired repetitions; the gyro scale factor swept over
``sweep_ppm`` on held-out S-turn runs (``_sweep``; the draws of the first ``sweep_repeats`` repeats at
every level, the study's own level taken from its repeats); a blind effect outside the innovation test's
candidates, a star-sensor time offset (``latency_ms_levels``, no scale factor), and a second one, a
star-sensor attitude error proportional to the body rate (``smear_levels_arcsec_per_deg_s``, motion blur),
with the candidate test, the generalised test (:func:`navlib.methods.kalman.innovation_structure_test`), the
test again on the filter with the scale-factor states, and the decision rule on every S-turn run
(:func:`navlib.methods.kalman.innovation_loop`: a candidate is named only when adding its state removes the
structure, otherwise "not explained by the candidates"; ``_diagnose``,
:func:`~navlib.studies.celestial.tables.loop_table`); up to ``quiet_repeats`` repeats of S-turn runs with
nothing missing for the tests' false-alarm rates (``_quiet``: filters and tests only, beyond the repeats the
sweep flies at 0 ppm; None: those alone); and the filter-residual features the paper rejects (case
``level_resid3``).
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field, fields, replace

import numpy as np
import pandas as pd

from ... import engine
from ...methods import kalman as km
from ...methods.feedforward import train_feedforward
from ...methods.mlp import train_mlp
from ...seeding import sequence
from ...sensors.strapdown import InitialError, strapdown
from ...sensors.trajectory import generate
from .step import StepNet, step_timings
from .parameters import (
    AXES,
    CASES,
    KINDS,
    LM_NETS,
    PHASES,
    SEED_PARTS,
    SWEEP_METHODS,
    StudySpec,
    bp_params,
    seed_of,
)

#: The sweep's BPKF methods and the case of the study's own scores each is taken from at the study's level.
_SWEEP_CASE = {
    "BPKF 6 QR": "sturn_qr6",
    "BPKF 6 QR + 3 rates": "sturn_qr6_rate",
    "BPKF 45 raw": "sturn_raw45",
}


@dataclass
class StudyData:
    """Everything the tables and figures need: per-run scores, one example test run's error traces,
    training times, the innovation test and the settings."""

    spec: StudySpec
    scores: pd.DataFrame  # repeat, case, mode, method, axis, rms_arcsec (per test run)
    traces: pd.DataFrame  # t_s, case, method, axis, err_arcsec (repeat 0, test run 0)
    timing: pd.DataFrame  # repeat, case, n_in, seconds_per_pass, seconds_total
    glr: pd.DataFrame  # repeat, kind, candidate, chi2, p_bonferroni, significant, named
    glr_runs: pd.DataFrame  # repeat, kind, runs (train/test), run, named (the test on one run)
    timings: pd.DataFrame  # timing, n_in, seconds_per_pass (paired repetitions, level repeat 0)
    rate_corr: pd.DataFrame  # repeat, kind, r, p
    yaw_profile: pd.DataFrame  # t_s, yaw_deg, rate_deg_s (repeat 0 test path)
    seconds: dict = field(default_factory=dict)
    lm_timing: pd.DataFrame | None = (
        None  # timing, n_in, n_weights, seconds, epochs, stop (whole trainlm trainings)
    )
    sweep: pd.DataFrame | None = (
        None  # level_ppm, latency_ms, smear, repeat, run, method, axis, rms_arcsec
    )
    diagnosis: pd.DataFrame | None = (
        None  # level_ppm, latency_ms, smear, repeat, runs, run, named, flagged,
    )
    #                                        flagged_aug, tried, flagged_after, decision, remains (per run)
    phases: pd.DataFrame | None = (
        None  # level_ppm, repeat, run, method, phase, axis, rms_arcsec (held-out
    )
    #                                        S-turn runs, turning and steady epochs apart; KF and BPKF 6 QR)
    step_timing: pd.DataFrame | None = (
        None  # timing, reading, n_in, seconds_per_epoch (the network step, level repeat 0)
    )


def _rms(err, mask):
    return np.sqrt(np.mean(err[:, mask] ** 2, axis=1))  # (runs, 3)


def _phase_rows(level_ppm: float, rep: int, method: str, err, rate_deg_s, mask) -> list[dict]:
    """Per run, the RMS (arcsec) per Euler angle over the scored epochs (``mask``) in which the magnitude of
    the measured body yaw rate is at or above its median over those epochs (``turning``) and below it
    (``steady``): the accuracy while the yaw axis manoeuvres beside the accuracy between the turns."""
    rows = []
    z = np.abs(np.asarray(rate_deg_s)[..., 2])
    for i in range(err.shape[0]):
        zi, ei = z[i, mask], err[i, mask]
        med = np.median(zi)
        for phase, sel in zip(PHASES, (zi >= med, zi < med)):
            r = np.sqrt(np.mean(ei[sel] ** 2, axis=0))
            for a, ax in enumerate(AXES):
                rows.append(
                    {
                        "level_ppm": float(level_ppm),
                        "repeat": rep,
                        "run": i,
                        "method": method,
                        "phase": phase,
                        "axis": ax,
                        "rms_arcsec": float(r[a]),
                    }
                )
    return rows


def _score_rows(rows, rep, case, mode, method, err, mask, first_run=0):
    r = _rms(err, mask)
    for i in range(r.shape[0]):
        for a, ax in enumerate(AXES):
            rows.append(
                {
                    "repeat": rep,
                    "case": case,
                    "mode": mode,
                    "method": method,
                    "run": first_run + i,
                    "axis": ax,
                    "rms_arcsec": float(r[i, a]),
                }
            )


def _paired_timings(spec: StudySpec, f_train) -> list[dict]:
    """Time per training pass of the 45-input and the 6-input net on the same training set, both in each of
    ``n_timings`` repetitions (alternating which goes first), after one untimed warm-up of each."""
    x = {45: km.gain_features(f_train, "raw45"), 6: km.gain_features(f_train, "qr6")}
    y = f_train.att_err_arcsec
    for n_in in (45, 6):
        train_mlp(
            x[n_in],
            y,
            bp_params(n_in, spec.n_hidden, spec.timing_epochs),
            seed=seed_of(spec, 0, "timing", 0),
        )
    rows = []
    for j in range(spec.n_timings):
        for n_in in (45, 6) if j % 2 == 0 else (6, 45):
            net = train_mlp(
                x[n_in],
                y,
                bp_params(n_in, spec.n_hidden, spec.timing_epochs),
                seed=seed_of(spec, 0, "timing", j),
            )
            rows.append({"timing": j, "n_in": n_in, "seconds_per_pass": net.seconds_per_pass})
    return rows


@functools.lru_cache(maxsize=2)
def _lm_training_set(spec: StudySpec) -> tuple[dict, np.ndarray]:
    """The training set of the ``trainlm`` timings (the first level-flight training run of repeat 0): the
    inputs per net and the targets, flown and filtered once per process (the timings time the trainings
    only)."""
    seed = seed_of(spec, 0, "noise", KINDS.index("level"), 0)
    run = strapdown(
        generate(spec.profile("level", 0)),
        [seed],
        spec.imu,
        spec.star,
        InitialError(spec.init_level_arcsec, spec.init_azimuth_arcsec),
    )
    f = km.run_filter(run, spec.filter)
    return {
        n_in: km.gain_features(f, feats)[0] for n_in, feats in LM_NETS.items()
    }, f.att_err_arcsec[0]


def _lm_timing(spec: StudySpec, j: int) -> list[dict]:
    """One timing repetition of the whole ``trainlm`` training (:func:`navlib.methods.feedforward.
    train_feedforward`: MATLAB's defaults, ``dividerand`` 70/15/15, validation stop) of the 45-, 6- and
    9-input nets (paper E's logsig hidden layer, 10 units), in a rotating order, on the same training set:
    the first level-flight training run of repeat 0 (one 150 s run, one sample per filter epoch).  Each net's
    initial weights and split come from
    :func:`~navlib.studies.celestial.parameters.seed_of` (``trainlm``, ``j``, inputs)."""
    xs, y = _lm_training_set(spec)
    order = list(LM_NETS)
    order = order[j % 3 :] + order[: j % 3]
    rows = []
    for n_in in order:
        x = xs[n_in]
        rng = np.random.default_rng(sequence(spec.seed, 0, SEED_PARTS["trainlm"], j, n_in))
        net = train_feedforward(x, y, spec.n_hidden, rng, activation="logsig")
        rows.append(
            {
                "timing": j,
                "n_in": n_in,
                "n_weights": net.info["n_weights"],
                "seconds": net.train_time_s,
                "epochs": net.info["epochs"],
                "stop": net.info["stop"],
            }
        )
    return rows


def _diagnose(
    rep: int, level_ppm: float, latency_ms: float, smear: float, train, f_train, test, f_test, aug
) -> list[dict]:
    """The filter's innovations on each S-turn run alone, through the decision rule
    (:func:`navlib.methods.kalman.innovation_loop`): what the candidate test names (``named``), whether the
    generalised test flags structure (``flagged``), the candidate whose state was added (``tried``), whether
    structure is left with it (``flagged_after``), and the rule's answer (``decision``: the candidate,
    "not explained by the candidates" or "nothing missing") with the regressors that carry what is left
    (``remains``); on the test runs also the generalised test on the filter with the three gyro
    scale-factor states (``flagged_aug``)."""
    rows = []
    for part, rr, ff, aa in (("train", train, f_train, None), ("test", test, f_test, aug)):
        loop = km.innovation_loop(rr, ff)
        gen_aug = km.innovation_structure_per_run(rr, aa) if aa is not None else [None] * len(loop)
        for i, (d, sa) in enumerate(zip(loop, gen_aug)):
            rows.append(
                {
                    "level_ppm": float(level_ppm),
                    "latency_ms": float(latency_ms),
                    "smear": float(smear),
                    "repeat": rep,
                    "runs": part,
                    "run": i,
                    "named": d.named_by_test or "none",
                    "chi2": d.chi2,
                    "flagged": d.flagged,
                    "flagged_aug": np.nan if sa is None else float(sa.flagged),
                    "tried": d.tried or "none",
                    "flagged_after": np.nan if d.flagged_after is None else float(d.flagged_after),
                    "decision": d.decision,
                    "remains": ", ".join(d.remains),
                }
            )
    return rows


def _sweep(
    spec: StudySpec, rep: int, level_ppm: float, latency_ms: float = 0.0, smear: float = 0.0
) -> dict:
    """One repeat of the S-turn simulation with the gyro scale factor set to ``level_ppm`` (a task of
    :func:`simulate`): the held-out scores of the KF, the three BPKF and the augmented KF.  The draws are
    those of the study's repeat ``rep`` (:func:`~navlib.studies.celestial.parameters.seed_of` does not depend
    on the level), so the levels are paired run by run; the filters are the study's (the augmented KF's prior
    on the scale factor is not set from the level).  ``latency_ms``: the star sensor's time offset (an effect
    outside the innovation test's candidates; then only the 9-input BPKF, the one with the rate inputs, is
    trained); ``smear``: the star sensor's rate-proportional error (arcsec per deg/s; a second effect outside
    the candidates, treated like the time offset).  Returns the score rows and the innovation diagnosis
    (``_diagnose``)."""
    sp = replace(
        spec,
        gyro_scale_ppm=float(level_ppm),
        star_latency_ms=float(latency_ms),
        star_smear_arcsec_per_deg_s=float(smear),
    )
    train, test, _ = _runs(sp, "s_turns", rep)
    f_train, f_test = km.run_filter(train, spec.filter), km.run_filter(test, spec.filter)
    mask = f_test.t_s >= spec.settle_s
    aug = km.run_filter(test, replace(spec.filter, scale_states=True))
    errs = {"KF": f_test.att_err_arcsec, "augmented KF": aug.att_err_arcsec}
    net_seed = seed_of(spec, rep, "network")
    for method, feats in SWEEP_METHODS.items():
        if feats is None or (
            (latency_ms or smear) and feats != "qr6_rate"
        ):  # blind effects: the rate net only
            continue
        net = train_mlp(
            km.gain_features(f_train, feats),
            f_train.att_err_arcsec,
            bp_params(km.N_INPUTS[feats], spec.n_hidden, spec.epochs),
            seed=net_seed,
        )
        errs[method] = f_test.att_err_arcsec - net.predict(km.gain_features(f_test, feats))
    rows = []
    for method, err in errs.items():
        one = []
        _score_rows(one, rep, "s_turns", "held-out", method, err, mask)
        rows += [
            dict(r, level_ppm=float(level_ppm), latency_ms=float(latency_ms), smear=float(smear))
            for r in one
        ]
    phase = (
        []
        if (latency_ms or smear)
        else [
            r
            for m in ("KF", "BPKF 6 QR")
            for r in _phase_rows(level_ppm, rep, m, errs[m], f_test.rate_deg_s, mask)
        ]
    )
    return {
        "scores": rows,
        "diag": _diagnose(rep, level_ppm, latency_ms, smear, train, f_train, test, f_test, aug),
        "phase": phase,
    }


def _quiet(spec: StudySpec, rep: int) -> list[dict]:
    """One repeat of the S-turn runs with nothing missing (no gyro scale factor, no star-sensor error) for the
    innovation tests' false-alarm rates only (a task of :func:`simulate`): the study's filters (15-state and
    with the scale-factor states) and the decision rule on each run alone (``_diagnose``), no networks.  The
    draws are those of repeat ``rep`` (:func:`~navlib.studies.celestial.parameters.seed_of`), so the repeats the
    sweep flies at 0 ppm are not flown again."""
    sp = replace(spec, gyro_scale_ppm=0.0, star_latency_ms=0.0, star_smear_arcsec_per_deg_s=0.0)
    train, test, _ = _runs(sp, "s_turns", rep)
    f_train, f_test = km.run_filter(train, spec.filter), km.run_filter(test, spec.filter)
    aug = km.run_filter(test, replace(spec.filter, scale_states=True))
    return _diagnose(rep, 0.0, 0.0, 0.0, train, f_train, test, f_test, aug)


def quiet_repeats_flown(spec: StudySpec) -> int:
    """How many repeats of the S-turn runs with nothing missing the study flies anyway: all its repeats
    when its own device has nothing missing, else the sweep's repeats when 0 ppm is a level of the sweep."""
    if not (spec.gyro_scale_ppm or spec.star_latency_ms or spec.star_smear_arcsec_per_deg_s):
        return spec.n_repeats
    return spec.sweep_repeats if 0.0 in [float(v) for v in spec.sweep_ppm] else 0


def _runs(spec: StudySpec, kind: str, rep: int):
    """Training and test runs of one repeat.  Level flight: one path, different noise seeds.  S-turns: each
    training run flies its own manoeuvre sequence (flown together, :func:`navlib.sensors.strapdown.strapdown`
    with one path per run), the test runs share another one.  Every run's noise and every manoeuvre has its
    own seed (:func:`~navlib.studies.celestial.parameters.seed_of`)."""
    k = KINDS.index(kind)
    seeds = [seed_of(spec, rep, "noise", k, i) for i in range(spec.n_train_runs + spec.n_test_runs)]
    init = InitialError(spec.init_level_arcsec, spec.init_azimuth_arcsec)
    if kind == "level":
        tr = generate(spec.profile(kind, 0))
        both = strapdown(tr, seeds, spec.imu, spec.star, init)
        return (
            _subset(both, slice(0, spec.n_train_runs)),
            _subset(both, slice(spec.n_train_runs, None)),
            tr,
        )
    train = strapdown(
        [
            generate(spec.profile(kind, seed_of(spec, rep, "manoeuvre", 1 + i)))
            for i in range(spec.n_train_runs)
        ],
        seeds[: spec.n_train_runs],
        spec.imu,
        spec.star,
        init,
    )
    tr_test = generate(spec.profile(kind, seed_of(spec, rep, "manoeuvre", 0)))
    test = strapdown(tr_test, seeds[spec.n_train_runs :], spec.imu, spec.star, init)
    return train, test, tr_test


def _subset(run, sl):
    arrays = {
        f.name: getattr(run, f.name)[sl]
        for f in fields(run)
        if isinstance(getattr(run, f.name), np.ndarray) and getattr(run, f.name).ndim >= 2
    }
    return replace(run, **arrays)


def _repeat(spec: StudySpec, rep: int, kind: str) -> dict:
    """One repeat of one simulation kind (a task of :func:`simulate`): its rows of every table; ``kind
    = "trainlm"``: timing repetition ``rep`` of ``_lm_timing``."""
    if kind == "trainlm":
        t0 = time.perf_counter()
        return {"lm": _lm_timing(spec, rep), "secs": {"trainlm": time.perf_counter() - t0}}
    if kind == "quiet":
        t0 = time.perf_counter()
        return {
            "sweep": {"scores": [], "diag": _quiet(spec, rep)},
            "secs": {"quiet": time.perf_counter() - t0},
        }
    if isinstance(
        kind, tuple
    ):  # (scale factor ppm, star-sensor latency ms, smear arcsec per deg/s)
        t0 = time.perf_counter()
        return {"sweep": _sweep(spec, rep, *kind), "secs": {"sweep": time.perf_counter() - t0}}
    out = {
        k: []
        for k in (
            "score",
            "trace",
            "time",
            "glr",
            "glr_run",
            "corr",
            "timing",
            "diag",
            "phase",
            "step",
        )
    }
    out["yaw"] = None
    secs = {"simulate_filter": 0.0, "train": 0.0, "timing": 0.0}
    score_rows, trace_rows, time_rows = out["score"], out["trace"], out["time"]
    t0 = time.perf_counter()
    train, test, tr_test = _runs(spec, kind, rep)
    f_train = km.run_filter(train, spec.filter)
    f_test = km.run_filter(test, spec.filter)
    t = f_test.t_s
    mask = t >= spec.settle_s
    _score_rows(score_rows, rep, kind, "held-out", "KF", f_test.att_err_arcsec, mask)
    _score_rows(score_rows, rep, kind, "same run", "KF", f_test.att_err_arcsec, mask)
    own_plain = not (spec.star_latency_ms or spec.star_smear_arcsec_per_deg_s)
    if kind == "s_turns" and own_plain:
        out["phase"] += _phase_rows(
            spec.gyro_scale_ppm, rep, "KF", f_test.att_err_arcsec, f_test.rate_deg_s, mask
        )
    if rep == 0:
        _trace(trace_rows, t, kind, "KF", f_test.att_err_arcsec[0])
    if kind == "s_turns":
        aug = km.run_filter(test, replace(spec.filter, scale_states=True))
        _score_rows(score_rows, rep, kind, "held-out", "augmented KF", aug.att_err_arcsec, mask)
        _score_rows(score_rows, rep, kind, "same run", "augmented KF", aug.att_err_arcsec, mask)
        if rep == 0:
            _trace(trace_rows, t, kind, "augmented KF", aug.att_err_arcsec[0])
            out["yaw"] = pd.DataFrame(
                {
                    "t_s": tr_test.t_s,
                    "yaw_deg": np.degrees(tr_test.att[:, 2]),
                    "rate_deg_s": np.degrees(np.r_[tr_test.rate_b[0, 2], tr_test.rate_b[:, 2]]),
                }
            )
    g = km.innovation_glr(train, f_train)
    for row in g.table.itertuples():
        out["glr"].append(
            {
                "repeat": rep,
                "kind": kind,
                "candidate": row.candidate,
                "chi2": row.chi2,
                "p_bonferroni": row.p_bonferroni,
                "significant": bool(row.significant),
                "named": g.named or "none",
            }
        )
    for part, (rr, ff) in (("train", (train, f_train)), ("test", (test, f_test))):
        for i, gi in enumerate(km.innovation_glr_per_run(rr, ff)):
            out["glr_run"].append(
                {"repeat": rep, "kind": kind, "runs": part, "run": i, "named": gi.named or "none"}
            )
    if kind == "s_turns":
        out["diag"] = _diagnose(
            rep,
            spec.gyro_scale_ppm,
            spec.star_latency_ms,
            spec.star_smear_arcsec_per_deg_s,
            train,
            f_train,
            test,
            f_test,
            aug,
        )
    r, p = km.rate_correlation(f_train)
    out["corr"].append({"repeat": rep, "kind": kind, "r": r, "p": p})
    secs["simulate_filter"] += time.perf_counter() - t0
    t0 = time.perf_counter()
    net_seed = seed_of(spec, rep, "network")
    held_nets = {}
    for case, (ck, feats) in CASES.items():
        if ck != kind:
            continue
        x_tr, x_te = km.gain_features(f_train, feats), km.gain_features(f_test, feats)
        mspec = bp_params(km.N_INPUTS[feats], spec.n_hidden, spec.epochs)
        net = train_mlp(x_tr, f_train.att_err_arcsec, mspec, seed=net_seed)
        held_nets[case] = net
        bp = f_test.att_err_arcsec - net.predict(x_te)
        _score_rows(score_rows, rep, case, "held-out", "BPKF", bp, mask)
        if case == "sturn_qr6" and own_plain:
            out["phase"] += _phase_rows(
                spec.gyro_scale_ppm, rep, "BPKF 6 QR", bp, f_test.rate_deg_s, mask
            )
        time_rows.append(
            {
                "repeat": rep,
                "case": case,
                "n_in": mspec.n_in,
                "seconds_per_pass": net.seconds_per_pass,
                "seconds_total": net.seconds_per_pass * spec.epochs,
            }
        )
        for i in range(spec.n_test_runs):
            one = slice(i, i + 1)
            same = train_mlp(x_te[one], f_test.att_err_arcsec[one], mspec, seed=net_seed)
            bp_same = f_test.att_err_arcsec[one] - same.predict(x_te[one])
            _score_rows(score_rows, rep, case, "same run", "BPKF", bp_same, mask, first_run=i)
            if rep == 0 and i == 0:
                _trace(trace_rows, t, case, "BPKF (held-out)", bp[0])
                _trace(trace_rows, t, case, "BPKF (same run)", bp_same[0])
    secs["train"] += time.perf_counter() - t0
    if rep == 0 and kind == "level":
        t0 = time.perf_counter()
        out["timing"] = _paired_timings(spec, f_train)
        # the network step of the running BPKF on test run 0, with the held-out nets
        out["step"] = step_timings(
            f_test.kf["K"][0, :, : km.N_BASE, :],
            {
                45: StepNet.from_mlp(held_nets["level_raw45"]),
                6: StepNet.from_mlp(held_nets["level_qr6"]),
            },
            spec.n_timings,
        )
        secs["timing"] += time.perf_counter() - t0
    out["secs"] = secs
    return out


def simulate(
    spec: StudySpec = StudySpec(), workers: int = 1, scheduler: str | None = None
) -> StudyData:
    """Fly, filter and train for every repeat (see the module docstring); returns :class:`StudyData`.

    Per repeat and simulation: KF on training and test runs; networks for every case of ``CASES``
    trained on the training runs (held-out) and on each test run alone (same run); for the S-turns also the
    augmented 18-state KF (gyro scale-factor states); the innovation GLR test of the 15-state KF pooled
    over the training runs and on each run alone; in the first repeat of the level flight the paired
    training-time repetitions and the paired timings of the running filter's network step with 45 and 6
    inputs (:func:`~navlib.studies.celestial.step.step_timings`, on test run 0 with the held-out nets).  Every (repeat, simulation) is a task of :mod:`navlib.engine` (``workers``
    local processes, or the cluster at ``scheduler``; the one with the timings starts first); the draws of
    each come from :func:`~navlib.studies.celestial.parameters.seed_of`, so the numbers (not the timings) do not
    depend on where they ran."""
    tasks = [(spec, rep, kind) for rep in range(spec.n_repeats) for kind in KINDS]
    cost = [
        (3.0 if kind == "s_turns" else 2.0)
        + (
            2.0 * spec.n_timings * spec.timing_epochs / spec.epochs + 0.05 * spec.n_timings
            if rep == 0 and kind == "level"
            else 0.0
        )
        for _, rep, kind in tasks
    ]
    tasks += [(spec, j, "trainlm") for j in range(spec.lm_timings)]
    cost += [4.0] * spec.lm_timings
    # the sweep: the study's own level is taken from its repeats (same draws, same filters and nets)
    levels = [float(v) for v in spec.sweep_ppm if float(v) != float(spec.gyro_scale_ppm)]
    own_smear = float(spec.star_smear_arcsec_per_deg_s)
    tasks += [
        (spec, rep, (v, float(spec.star_latency_ms), own_smear))
        for v in levels
        for rep in range(spec.sweep_repeats)
    ]
    # the blind effects: star-sensor time offsets, rate-proportional errors, with no scale factor
    tasks += [
        (spec, rep, (0.0, float(v), 0.0))
        for v in spec.latency_ms_levels
        for rep in range(spec.sweep_repeats)
    ]
    tasks += [
        (spec, rep, (0.0, 0.0, float(v)))
        for v in spec.smear_levels_arcsec_per_deg_s
        for rep in range(spec.sweep_repeats)
    ]
    n_sw = (
        len(levels) + len(spec.latency_ms_levels) + len(spec.smear_levels_arcsec_per_deg_s)
    ) * spec.sweep_repeats
    cost += [2.0] * n_sw
    # more runs with nothing missing for the false-alarm rates (filters and tests only)
    quiet = range(quiet_repeats_flown(spec), spec.quiet_repeats or 0)
    tasks += [(spec, rep, "quiet") for rep in quiet]
    cost += [1.0] * len(quiet)
    every = engine.run(
        _repeat, tasks, workers=workers, scheduler=scheduler, cost=cost, label="paper E repeats"
    )
    parts = [p for p in every if "lm" not in p and "sweep" not in p]
    lm_timing = pd.DataFrame([r for p in every if "lm" in p for r in p["lm"]])
    sweep = [r for p in every if "sweep" in p for r in p["sweep"]["scores"]]
    phases = pd.DataFrame(
        [r for p in every if "sweep" in p for r in p["sweep"].get("phase", [])]
        + [r for p in parts for r in p["phase"]]
    )
    diagnosis = pd.DataFrame(
        [r for p in every if "sweep" in p for r in p["sweep"]["diag"]]
        + [r for p in parts for r in p["diag"]]
    )

    def rows(key):
        return [r for part in parts for r in part[key]]

    secs = {
        k: sum(part["secs"][k] for part in parts) for k in ("simulate_filter", "train", "timing")
    }
    secs["trainlm"] = sum(p["secs"]["trainlm"] for p in every if "lm" in p)
    secs["sweep"] = sum(p["secs"].get("sweep", 0.0) for p in every if "sweep" in p)
    secs["quiet"] = sum(p["secs"].get("quiet", 0.0) for p in every if "sweep" in p)
    yaw_profile = next((part["yaw"] for part in parts if part["yaw"] is not None), None)
    scores = pd.DataFrame(rows("score"))
    # the KF rows belong to both cases of their simulation
    kf = scores[scores["case"].isin(["level", "s_turns"])]
    parts_ = [scores[~scores["case"].isin(["level", "s_turns"])]]
    for case, (ck, _) in CASES.items():
        parts_.append(kf[kf["case"] == ck].assign(case=case))
    scores = pd.concat(parts_, ignore_index=True)
    traces = pd.concat(rows("trace"), ignore_index=True)
    if float(spec.gyro_scale_ppm) in [float(v) for v in spec.sweep_ppm]:
        label = {
            ("sturn_qr6", "KF"): "KF",
            ("sturn_qr6", "augmented KF"): "augmented KF",
            **{(case, "BPKF"): m for m, case in _SWEEP_CASE.items()},
        }
        own = scores[(scores["mode"] == "held-out") & (scores["repeat"] < spec.sweep_repeats)]
        for r in own.itertuples():
            if (r.case, r.method) in label:
                sweep.append(
                    {
                        "repeat": r.repeat,
                        "case": "s_turns",
                        "mode": "held-out",
                        "method": label[(r.case, r.method)],
                        "run": r.run,
                        "axis": r.axis,
                        "rms_arcsec": r.rms_arcsec,
                        "level_ppm": float(spec.gyro_scale_ppm),
                        "latency_ms": float(spec.star_latency_ms),
                        "smear": own_smear,
                    }
                )
    sweep = pd.DataFrame(sweep)
    return StudyData(
        spec,
        scores,
        traces,
        pd.DataFrame(rows("time")),
        pd.DataFrame(rows("glr")),
        pd.DataFrame(rows("glr_run")),
        pd.DataFrame(rows("timing")),
        pd.DataFrame(rows("corr")),
        yaw_profile,
        secs,
        lm_timing,
        sweep,
        diagnosis,
        phases,
        pd.DataFrame(rows("step")),
    )


def _trace(rows, t, case, method, err):
    for a, ax in enumerate(AXES):
        rows.append(
            pd.DataFrame(
                {"t_s": t, "case": case, "method": method, "axis": ax, "err_arcsec": err[:, a]}
            )
        )
