"""The celestial chapter's tables and figures, each a tidy DataFrame from the study's output
(:class:`~navlib.studies.celestial.simulation.StudyData`): paper E's surviving numbers, the accuracy tables
(Tables 2-5), the training times, the error traces (Figs 3-4, 6-9), the yaw manoeuvre (Fig 5), the
innovation test, the scale-factor sweep, the blind-effect diagnosis and the decision rule per case, the
simulated devices (our stand-in for the lost Table 1)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...claims import method_stats
from ...data.tables import Column, read_table
from ...errors import InputError
from ...methods import kalman as km
from ...paths import data_path
from .parameters import CASE_LABEL, CASES, SWEEP_METHODS, StudySpec
from .step import STEP_READINGS, step_flops
from .scores import _paired, _smear, sweep_per_run
from .simulation import StudyData


def paper_numbers() -> pd.DataFrame:
    """Paper E's four surviving numbers, ``data/paper_e_numbers.csv`` (indexed by quantity)."""
    df = read_table(
        data_path("paper_e_numbers.csv"), [Column("value", lo=0)], kind="table of paper numbers"
    )
    need = {"train_time_45_s", "train_time_6_s", "improvement_min_pct", "attitude_error_max_arcsec"}
    if "quantity" not in df.columns or not need <= set(df["quantity"].str.strip()):
        raise InputError(
            f"paper_e_numbers.csv: column 'quantity' must list {', '.join(sorted(need))}"
        )
    df["quantity"] = df["quantity"].str.strip()
    df["value"] = df["value"].astype(float)
    return df.set_index("quantity")


def accuracy_table(data: StudyData, case: str) -> pd.DataFrame:
    """Tables 2-5: attitude accuracy per method and axis for one case: the median over repeats of the
    mean RMS over the test runs, with the 10th and 90th percentiles over repeats and BPKF's improvement over
    KF (%); held-out and same-run rows."""
    if case not in CASES:
        raise InputError(f"parameter case={case!r}: must be one of {', '.join(CASES)}")
    s = data.scores[data.scores["case"] == case]
    per_rep = (
        s.groupby(["mode", "method", "axis", "repeat"], sort=False)["rms_arcsec"]
        .mean()
        .reset_index()
    )
    g = per_rep.groupby(["mode", "method", "axis"], sort=False)["rms_arcsec"]
    out = pd.DataFrame(
        {"median": g.median(), "p10": g.quantile(0.1), "p90": g.quantile(0.9)}
    ).reset_index()
    kf = per_rep[per_rep["method"] == "KF"].set_index(["mode", "axis", "repeat"])["rms_arcsec"]
    imp = per_rep.assign(kf=per_rep.set_index(["mode", "axis", "repeat"]).index.map(kf))
    imp["improvement_pct"] = 100 * (1 - imp["rms_arcsec"] / imp["kf"])
    out["improvement_pct"] = (
        imp.groupby(["mode", "method", "axis"], sort=False)["improvement_pct"].median().values
    )
    out.loc[out["method"] == "KF", "improvement_pct"] = np.nan
    return out.rename(columns={"median": "rms_arcsec", "p10": "p10_arcsec", "p90": "p90_arcsec"})


def overall(data: StudyData) -> pd.DataFrame:
    """Attitude accuracy of every case, mode and method over all repeats and test runs: the RMS over the
    three Euler angles of each run (arcsec), median / p10 / p90 over runs, and the median improvement (%)
    of BPKF over KF on the same runs."""
    s = data.scores
    per_run = (
        s.groupby(["case", "mode", "method", "repeat", "run"], sort=False)["rms_arcsec"]
        .apply(lambda v: float(np.sqrt(np.mean(v**2))))
        .reset_index()
    )
    kf = per_run[per_run["method"] == "KF"].set_index(["case", "mode", "repeat", "run"])[
        "rms_arcsec"
    ]
    per_run["kf"] = per_run.set_index(["case", "mode", "repeat", "run"]).index.map(kf)
    per_run["improvement_pct"] = 100 * (1 - per_run["rms_arcsec"] / per_run["kf"])
    g = per_run.groupby(["case", "mode", "method"], sort=False)
    out = pd.DataFrame(
        {
            "rms_arcsec": g["rms_arcsec"].median(),
            "p10_arcsec": g["rms_arcsec"].quantile(0.1),
            "p90_arcsec": g["rms_arcsec"].quantile(0.9),
            "max_arcsec": g["rms_arcsec"].max(),
            "improvement_pct": g["improvement_pct"].median(),
            "n_runs": g.size(),
        }
    ).reset_index()
    out.loc[out["method"] == "KF", "improvement_pct"] = np.nan
    # the filters do not depend on the network's inputs: show them once per simulation
    keep = (out["method"] == "BPKF") | out["case"].isin(["level_qr6", "sturn_qr6"])
    return out[keep].reset_index(drop=True)


def training_time(data: StudyData) -> pd.DataFrame:
    """Training time per pass (one epoch over the training set) per input size: median, 10th and 90th
    percentile over the paired timing repetitions (this machine, ``timing_epochs`` passes each), beside
    the paper's times; the 45-over-6 ratio is in :func:`time_ratio`."""
    t = data.timings
    paper = paper_numbers()["value"]
    rows = []
    for n_in, case, key in (
        (45, "level_raw45", "train_time_45_s"),
        (6, "level_qr6", "train_time_6_s"),
    ):
        v = 1e3 * t[t["n_in"] == n_in]["seconds_per_pass"]
        rows.append(
            {
                "inputs": n_in,
                "case": CASE_LABEL[case],
                "ours_median_ms": float(v.median()),
                "ours_p10_ms": float(v.quantile(0.1)),
                "ours_p90_ms": float(v.quantile(0.9)),
                "paper_ms": 1e3 * float(paper[key]),
            }
        )
    return pd.DataFrame(rows)


def timing_pairs(data: StudyData) -> tuple[np.ndarray, np.ndarray]:
    """Time per pass (s) of the 45-input and of the 6-input net, paired by timing repetition."""
    w = data.timings.pivot(index="timing", columns="n_in", values="seconds_per_pass").sort_index()
    return w[45].to_numpy(), w[6].to_numpy()


def time_ratio(data: StudyData) -> dict:
    """The 45-input over 6-input training time per pass: the median of the paired ratios over the timing
    repetitions (``ours``) and the paper's ratio."""
    t45, t6 = timing_pairs(data)
    p = paper_numbers()["value"]
    return {
        "ours": float(np.median(t45 / t6)),
        "paper": float(p["train_time_45_s"] / p["train_time_6_s"]),
    }


def lm_timing_pairs(
    data: StudyData, n_in: int = 45, base: int = 6
) -> tuple[np.ndarray, np.ndarray]:
    """Whole ``trainlm`` training time (s) of the ``n_in``-input and of the ``base``-input net, paired by
    timing repetition."""
    if data.lm_timing is None or data.lm_timing.empty:
        raise InputError("no trainlm timings (lm_timings = 0)")
    w = data.lm_timing.pivot(index="timing", columns="n_in", values="seconds").sort_index()
    return w[n_in].to_numpy(), w[base].to_numpy()


def step_timing_pairs(data: StudyData, reading: str = "epoch") -> tuple[np.ndarray, np.ndarray]:
    """Time per filter epoch (s) of the running BPKF's network step with the 45 raw gains and with the 6
    QR features, paired by timing repetition; ``reading``: ``"epoch"`` (one epoch at a time, as the
    running filter does it) or ``"batch"`` (vectorised over a run's epochs)."""
    if reading not in STEP_READINGS:
        raise InputError(
            f"parameter reading={reading!r}: must be one of {', '.join(STEP_READINGS)}"
        )
    t = data.step_timing
    if t is None or t.empty:
        raise InputError("no timings of the network step (n_timings = 0)")
    w = (
        t[t["reading"] == reading]
        .pivot(index="timing", columns="n_in", values="seconds_per_epoch")
        .sort_index()
    )
    return w[45].to_numpy(), w[6].to_numpy()


def step_time(data: StudyData) -> pd.DataFrame:
    """The running BPKF's network step per filter epoch (features of the epoch's gain and one forward
    pass, :mod:`~navlib.studies.celestial.step`) with the 45 raw gains and with the 6 QR features: per
    reading (one epoch at a time, vectorised over a run) the median, 10th and 90th percentile over the
    paired timing repetitions (this machine, microseconds), the operation count of the step
    (:func:`~navlib.studies.celestial.step.step_flops`), and the median paired ratio 45 / 6."""
    rows = []
    labels = {"epoch": "one epoch at a time", "batch": "vectorised over a run"}
    for reading in STEP_READINGS:
        a, b = step_timing_pairs(data, reading)
        for n_in, v in ((45, a), (6, b)):
            us = 1e6 * v
            rows.append(
                {
                    "step": labels[reading],
                    "inputs": n_in,
                    "ours_median_us": float(np.median(us)),
                    "ours_p10_us": float(np.quantile(us, 0.1)),
                    "ours_p90_us": float(np.quantile(us, 0.9)),
                    "flops": step_flops(n_in, data.spec.n_hidden),
                    "ratio_45_to_6": float(np.median(a / b)),
                }
            )
    return pd.DataFrame(rows)


def trainlm_time(data: StudyData) -> pd.DataFrame:
    """The time of one whole training as MATLAB trains (``trainlm``, defaults, ``dividerand``, validation
    stop) per input set: median, 10th and 90th percentile over the timing repetitions (this machine), the
    median epochs and time per epoch, the stop reasons, and the paper's "average time of one training"; the
    last column is the median paired ratio to the 6-input net's time in the same repetition."""
    t = data.lm_timing
    paper = paper_numbers()["value"]
    rows = []
    for n_in, grp in t.groupby("n_in", sort=False):
        a, b = lm_timing_pairs(data, int(n_in))
        key = {45: "train_time_45_s", 6: "train_time_6_s"}.get(int(n_in))
        rows.append(
            {
                "inputs": int(n_in),
                "weights": int(grp["n_weights"].iloc[0]),
                "ours_median_s": float(grp["seconds"].median()),
                "ours_p10_s": float(grp["seconds"].quantile(0.1)),
                "ours_p90_s": float(grp["seconds"].quantile(0.9)),
                "median_epochs": float(grp["epochs"].median()),
                "ms_per_epoch": float(
                    1e3 * (grp["seconds"] / grp["epochs"].clip(lower=1)).median()
                ),
                "stops": ", ".join(f"{k} {v}" for k, v in grp["stop"].value_counts().items()),
                "paper_s": float(paper[key]) if key else np.nan,
                "ratio_to_6": float(np.median(a / b)),
            }
        )
    return pd.DataFrame(rows).sort_values("inputs", ascending=False).reset_index(drop=True)


def error_traces(
    data: StudyData, case: str, first_s: float | None = None, axis: str | None = None
) -> pd.DataFrame:
    """Figs 3-4, 6-9: the Euler-angle errors (arcsec) of KF and BPKF on test run 0 of repeat 0; ``first_s``
    keeps the first seconds (Figs 7, 9: 50 s), ``axis`` one angle."""
    if case not in CASES:
        raise InputError(f"parameter case={case!r}: must be one of {', '.join(CASES)}")
    kind = CASES[case][0]
    tr = data.traces
    out = pd.concat([tr[tr["case"] == kind], tr[tr["case"] == case]], ignore_index=True)
    if first_s is not None:
        out = out[out["t_s"] <= first_s]
    if axis is not None:
        out = out[out["axis"] == axis]
    return out.reset_index(drop=True)


def innovation_test(data: StudyData) -> pd.DataFrame:
    """The GLR test of the 15-state KF's innovations per simulation: per candidate effect the median
    chi-square over repeats and how often it was significant (Bonferroni, alpha = 0.01) when pooled over a
    repeat's training runs, how often it was the named effect pooled, and on each run alone (train and test
    runs)."""
    g, gr = data.glr, data.glr_runs
    rows = []
    for (kind, cand), grp in g.groupby(["kind", "candidate"], sort=False):
        runs = gr[gr["kind"] == kind]
        rows.append(
            {
                "simulation": kind,
                "candidate": cand,
                "median_chi2": float(grp["chi2"].median()),
                "significant_in": f"{int(grp['significant'].sum())}/{len(grp)}",
                "named_in": f"{int((grp['named'] == cand).sum())}/{len(grp)}",
                "named_in_runs": f"{int((runs['named'] == cand).sum())}/{len(runs)}",
            }
        )
    return pd.DataFrame(rows)


def named_effect(data: StudyData, kind: str = "s_turns") -> str:
    """The effect the innovation test names most often for one simulation ('none' if none)."""
    g = data.glr[data.glr["kind"] == kind].drop_duplicates(["repeat"])
    return str(g["named"].mode().iloc[0])


def sweep_table(data: StudyData) -> pd.DataFrame:
    """The scale-factor sweep on held-out S-turn runs: per level and method the median over runs of the
    RMS over the three angles (arcsec) with its 10th and 90th percentiles, the median yaw RMS, and the
    median paired improvement over the KF on the same runs (%)."""
    rows = []
    sw = data.sweep
    own = (sw["latency_ms"] == float(data.spec.star_latency_ms)) & (
        _smear(sw) == float(data.spec.star_smear_arcsec_per_deg_s)
    )
    for level in sorted(sw.loc[own, "level_ppm"].unique()):
        kf = sweep_per_run(data, level, "KF")
        for method in SWEEP_METHODS:
            v = sweep_per_run(data, level, method)
            a, b = _paired(v, kf)
            rows.append(
                {
                    "scale_ppm": level,
                    "method": method,
                    "rms_arcsec": float(v.median()),
                    "p10_arcsec": float(v.quantile(0.1)),
                    "p90_arcsec": float(v.quantile(0.9)),
                    "yaw_arcsec": float(sweep_per_run(data, level, method, "yaw").median()),
                    "improvement_pct": np.nan
                    if method == "KF"
                    else float(np.median(100 * (1 - a / b))),
                    "n_runs": int(v.size),
                }
            )
    return pd.DataFrame(rows)


def case_label(level_ppm: float, latency_ms: float = 0.0, smear: float = 0.0) -> str:
    """A diagnosis case in words: the gyro scale factor, the star sensor's time offset and rate-proportional
    error, or nothing missing."""
    parts = [f"scale factor {level_ppm:g} ppm"] if level_ppm else []
    parts += [f"time offset {latency_ms:g} ms"] if latency_ms else []
    parts += [f"rate error {smear:g} arcsec per deg/s"] if smear else []
    return ", ".join(parts) or "nothing missing"


def _cases(d: pd.DataFrame):
    """The diagnosis rows grouped by case (scale factor, time offset, rate error), in a fixed order."""
    d = d.assign(smear=_smear(d))
    for (level, lat, sm), g in d.groupby(["level_ppm", "latency_ms", "smear"], sort=True):
        yield (float(level), float(lat), float(sm)), g


def blind_effect_table(data: StudyData) -> pd.DataFrame:
    """The innovation diagnosis per case (gyro scale factor, star-sensor time offset or rate-proportional
    error): over the S-turn runs (training and test runs, each alone) the effect the candidate test names
    most often and how often it names any, how often the generalised test flags structure, on the test runs
    how often structure is left once the three gyro scale-factor states are in the filter, and the median RMS
    (three angles, arcsec) of the KF, the 9-input BPKF and the augmented KF on the held-out runs (first
    ``sweep_repeats`` repeats)."""
    rows = []
    for (level, lat, sm), g in _cases(data.diagnosis):
        test = g[g["runs"] == "test"]
        named = g["named"][g["named"] != "none"]
        row = {
            "case": case_label(level, lat, sm),
            "runs": len(g),
            "named_most": named.mode().iloc[0] if len(named) else "none",
            "named_any": f"{len(named)}/{len(g)}",
            "generalised_flags": f"{int(g['flagged'].sum())}/{len(g)}",
            "left_after_scale_states": f"{int(test['flagged_aug'].sum())}/{len(test)}",
        }
        for method in ("KF", "BPKF 6 QR + 3 rates", "augmented KF"):
            try:
                row[f"{method} (arcsec)"] = float(
                    sweep_per_run(data, level, method, latency_ms=lat, smear=sm).median()
                )
            except InputError:
                row[f"{method} (arcsec)"] = np.nan
        rows.append(row)
    return pd.DataFrame(rows)


def loop_table(data: StudyData) -> pd.DataFrame:
    """The decision rule (:func:`navlib.methods.kalman.innovation_loop`) per case, over the S-turn runs each
    alone: the candidate whose state was added (the candidate test's name, most often) and in how many runs,
    in how many of those structure was left, and the rule's answers: a candidate named (which, most often),
    "not explained by the candidates", "nothing missing", with the regressors that carry the structure left
    (most often)."""
    rows = []
    for (level, lat, sm), g in _cases(data.diagnosis):
        tried = g[g["tried"] != "none"]
        named = g[~g["decision"].isin([km.NOT_EXPLAINED, km.NOTHING])]
        left = g.loc[g["decision"] == km.NOT_EXPLAINED, "remains"]
        rows.append(
            {
                "case": case_label(level, lat, sm),
                "runs": len(g),
                "state added": tried["tried"].mode().iloc[0] if len(tried) else "none",
                "added in": len(tried),
                "left after": int(tried["flagged_after"].sum()),
                "named": f"{len(named)}: {named['decision'].mode().iloc[0]}" if len(named) else "0",
                "not explained": int((g["decision"] == km.NOT_EXPLAINED).sum()),
                "nothing missing": int((g["decision"] == km.NOTHING).sum()),
                "structure left in": (left.mode().iloc[0] or "-") if len(left) else "-",
            }
        )
    return pd.DataFrame(rows)


def loop_runs(data: StudyData) -> list[dict]:
    """The decision rule per run (for the results file): case, repeat, train or test runs, run, what the
    candidate test named, whether the generalised test flagged, the state added and whether structure was left
    with it, the decision and the regressors carrying what is left."""
    out = []
    for (level, lat, sm), g in _cases(data.diagnosis):
        for r in g.sort_values(["repeat", "runs", "run"]).itertuples():
            out.append(
                {
                    "case": case_label(level, lat, sm),
                    "repeat": int(r.repeat),
                    "runs": r.runs,
                    "run": int(r.run),
                    "named_by_test": r.named,
                    "flagged": bool(r.flagged),
                    "tried": r.tried,
                    "flagged_after": None if pd.isna(r.flagged_after) else bool(r.flagged_after),
                    "decision": r.decision,
                    "remains": r.remains,
                }
            )
    return out


def method_summary(data: StudyData) -> dict:
    """Headline statistics per method on held-out runs (RMS over the three angles per run, arcsec) for the
    results file."""
    s = data.scores[data.scores["mode"] == "held-out"]
    per_run = (
        s.groupby(["case", "method", "repeat", "run"], sort=False)["rms_arcsec"]
        .apply(lambda v: float(np.sqrt(np.mean(v**2))))
        .reset_index()
    )
    out = {}
    for (case, method), grp in per_run.groupby(["case", "method"], sort=False):
        if method == "KF" and case not in ("level_qr6", "sturn_qr6"):
            continue
        if method == "augmented KF" and case != "sturn_qr6":
            continue
        kind = "level" if case.startswith("level") else "S-turns"
        label = {"KF": f"KF ({kind})", "augmented KF": "augmented KF (S-turns)"}.get(
            method, f"BPKF {CASE_LABEL[case].split(' (')[0]}"
        )
        out[label] = method_stats(grp["rms_arcsec"].to_numpy())
    return out


def device_table(spec: StudySpec) -> pd.DataFrame:
    """The simulated devices (our stand-in for paper E's lost Table 1), with the reason for each value."""
    rows = [
        ("gyro constant drift", spec.gyro_drift_deg_h, "deg/h", "navigation-grade FOG, per axis"),
        ("gyro angle random walk", spec.gyro_arw_deg_rt_h, "deg/sqrt(h)", "navigation-grade FOG"),
        ("gyro scale-factor error", spec.gyro_scale_ppm, "ppm", "the effect the KF does not model"),
        ("accelerometer bias", spec.accel_bias_ug, "ug", "navigation-grade, per axis"),
        ("accelerometer noise", spec.accel_noise_ug_rt_hz, "ug/sqrt(Hz)", "navigation-grade"),
        (
            "star sensor, cross-boresight",
            spec.star_cross_arcsec,
            "arcsec (1 sigma)",
            "arcsecond-class tracker",
        ),
        (
            "star sensor, about boresight",
            spec.star_boresight_arcsec,
            "arcsec (1 sigma)",
            "about 5x the cross-boresight noise",
        ),
        ("star sensor and filter rate", spec.star_rate_hz, "Hz", "typical 1-10 Hz"),
        ("IMU rate", spec.imu_rate_hz, "Hz", "strapdown update"),
        (
            "initial attitude error, level / azimuth",
            f"{spec.init_level_arcsec:g} / {spec.init_azimuth_arcsec:g}",
            "arcsec (1 sigma)",
            "after a coarse transfer alignment",
        ),
        ("flight", f"{spec.duration_s:g} s at 200 m/s, 8 km", "", "paper E: 150 s"),
        (
            "S-manoeuvre",
            f"+-{spec.yaw_amplitude_deg:g} deg yaw, shortest period {spec.turn_period_s:g} s",
            "",
            "paper E: irregular yaw S-turns",
        ),
    ]
    return pd.DataFrame(
        [
            {"item": a, "value": b if isinstance(b, str) else f"{b:g}", "unit": c, "why": d}
            for a, b, c, d in rows
        ]
    )


def yaw_manoeuvre(data: StudyData) -> pd.DataFrame:
    """Fig 5: the yaw angle (deg) and yaw rate (deg/s) of the test path of repeat 0 (S-turns)."""
    return data.yaw_profile.copy()
