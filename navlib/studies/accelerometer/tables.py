"""The chapter's results shaped for display: Table 2 (:func:`table2`), the noise floors, per-seed statistics
of the methods (:func:`per_seed`, which the claims pair over the same seeds), the swarm's choices, unit B's
table, the noise study, the tuners and unit B's drift over the batch spreads."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...claims import method_stats
from ...errors import InputError
from .floors import _floors, rmse_floor_ug
from .parameters import BATCH_SPREADS, METHODS, TUNERS, PaperDParams, _paper_value
from .runs import Run


def table2(err: pd.DataFrame, paper: pd.DataFrame, sets=("train", "test")) -> pd.DataFrame:
    """Table 2: median over seeds of ME, AE, MAXE, MARE, RMSE (ug for errors) per method and set, with the
    10th-90th percentile of RMSE and the paper's RMSE beside."""
    e = err[err["set"].isin(sets) & err["method"].isin(METHODS)]
    g = e.groupby(["method", "set"], sort=False)
    out = g[["ME_mg", "AE_mg", "MAXE", "MARE", "RMSE_mg"]].median()
    out["RMSE p10"] = g["RMSE_mg"].quantile(0.1)
    out["RMSE p90"] = g["RMSE_mg"].quantile(0.9)
    out = out.reset_index()
    for c in ("ME_mg", "AE_mg", "RMSE_mg", "RMSE p10", "RMSE p90"):
        out[c] = out[c] * 1000.0
    out = out.rename(
        columns={
            "ME_mg": "ME (ug)",
            "AE_mg": "AE (ug)",
            "RMSE_mg": "RMSE (ug)",
            "RMSE p10": "RMSE p10 (ug)",
            "RMSE p90": "RMSE p90 (ug)",
        }
    )
    paper_rmse = {m: _paper_value(paper, "rmse", m) * 1000.0 for m in METHODS[:4]}
    out["paper RMSE (ug)"] = out["method"].map(paper_rmse)
    out["MAXE"] = out["MAXE"] * 100
    out["MARE"] = out["MARE"] * 100
    out = out.rename(columns={"MAXE": "MAXE (%)", "MARE": "MARE (%)"})
    order = {m: i for i, m in enumerate(METHODS)}
    return out.sort_values(
        ["set", "method"],
        key=lambda s: s.map(order) if s.name == "method" else s,
        ascending=[False, True],
    ).reset_index(drop=True)


def noise_floor(err: pd.DataFrame, params: PaperDParams) -> pd.DataFrame:
    """The noise floors of the chapter's statistics (ug): the RMSE on held-out temperatures (``sqrt(2) noise``) and
    on the training readings (:func:`~navlib.studies.accelerometer.floors.rmse_floor_ug`), the largest error on unit
    B (:func:`~navlib.studies.accelerometer.floors.max_error_floor_ug`), with the exact model's (oracle's) held-out
    and training RMSE (median over seeds) beside."""

    def orc(s):
        return 1000 * float(
            err[(err["method"] == "oracle") & (err["set"] == s)]["RMSE_mg"].median()
        )

    f = _floors(params)
    return pd.DataFrame(
        {
            "quantity": [
                "noise per reading",
                "held-out RMSE floor: sqrt(2) x noise",
                "exact model, held-out RMSE",
                "training RMSE floor (55 degC: e = 0)",
                "exact model, training RMSE",
                "unit B largest-error floor (median)",
            ],
            "value (ug)": [
                params.experiment.noise_ug,
                f["test"],
                orc("test"),
                f["train"],
                orc("train"),
                f["unit B max"],
            ],
        }
    )


def per_seed(err: pd.DataFrame, methods, s: str, col: str = "RMSE_mg") -> pd.DataFrame:
    """One row per seed, one column per method: statistic ``col`` on set ``s`` in ug (seeds that lack a
    method are an error, so that comparisons are paired over the same seeds)."""
    g = err[err["method"].isin(methods) & (err["set"] == s)]
    t = g.pivot_table(index="seed", columns="method", values=col, aggfunc="first")
    missing = [m for m in methods if m not in t.columns]
    if missing or t.isna().any().any():
        raise InputError(
            f"errors table: set {s!r} lacks {missing or 'some seeds'} for {list(methods)}"
        )
    return 1000.0 * t[list(methods)]


def method_summary(err: pd.DataFrame, s: str = "test") -> dict:
    """Per method ``navlib.claims.method_stats`` of the RMSE (ug) over seeds on set ``s``."""
    out = {}
    for m in METHODS:
        g = err[(err["method"] == m) & (err["set"] == s)]
        out[m] = method_stats(1000 * g["RMSE_mg"], None, 1000 * g["ME_mg"])
    return out


def swarm_choices(runs: list[Run]) -> pd.DataFrame:
    """Per seed: the swarm's clustering radius ``ra``, squash ``rb/ra``, the resulting rule count, and the
    best checking RMSE of genfis2's FIS (ug) it found."""
    return pd.DataFrame(
        [
            {
                "seed": r.seed,
                "ra": r.ra,
                "rb/ra": r.squash,
                "rules": r.n_rules["IAFSA-SCM-ANFIS"],
                "FIS rules (r = fis_radius)": r.n_rules["FIS"],
                "fitness (ug)": 1000 * float(r.swarm_history[-1]),
            }
            for r in runs
        ]
    )


def unit_b_table(err: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Unit B compensated with unit A's models: median over seeds of the maximum and RMS residual (ug),
    with the paper's 7.21 mg before and 9.3 ug after."""
    e = err[(err["set"] == "unit B") & err["method"].isin(("uncompensated", *METHODS, "oracle"))]
    g = e.groupby("method", sort=False)
    out = pd.DataFrame(
        {"max |e| (ug)": 1000 * g["ME_mg"].median(), "RMSE (ug)": 1000 * g["RMSE_mg"].median()}
    )
    out["paper max (ug)"] = np.nan
    out.loc["uncompensated", "paper max (ug)"] = 1000 * _paper_value(paper, "unit_b_before")
    out.loc["IAFSA-SCM-ANFIS", "paper max (ug)"] = 1000 * _paper_value(paper, "unit_b_after")
    return out.rename(index={"oracle": "unit A's exact model"}).reset_index()


def noise_table(noise_err: pd.DataFrame, s: str = "test") -> pd.DataFrame:
    """The noise study: median over seeds of every method's RMSE (ug) on set ``s`` per noise level, with
    the exact model's and the floor ``sqrt(2) noise`` beside."""
    e = noise_err[(noise_err["set"] == s) & noise_err["method"].isin((*METHODS, "oracle"))]
    t = 1000 * e.pivot_table(index="noise_ug", columns="method", values="RMSE_mg", aggfunc="median")
    t = t[[*METHODS, "oracle"]].rename(columns={"oracle": "exact model"})
    t["floor sqrt(2) x noise"] = [rmse_floor_ug(v) for v in t.index]
    t.columns.name = None
    return t.reset_index().rename(columns={"noise_ug": "noise (ug per reading)"})


def noise_permitted(
    noise_err: pd.DataFrame, params: PaperDParams, paper: pd.DataFrame
) -> pd.DataFrame:
    """The largest noise per reading the paper's 4 ug permits: where the floors reach 4 ug (held-out
    ``sqrt(2) noise``; training readings, the 55 degC share excluded) and where the median held-out RMSE of
    IAFSA-SCM-ANFIS over seeds crosses 4 ug (linear interpolation between the noise levels studied; NaN
    when it does not cross inside them)."""
    b4 = _paper_value(paper, "rmse", "IAFSA-SCM-ANFIS") * 1000
    exp = params.experiment
    n_train = exp.set_points_c.size - len(params.held_out_c) - len(params.check_c)
    t = noise_table(noise_err).set_index("noise (ug per reading)")
    x, y = t.index.to_numpy(float), t["IAFSA-SCM-ANFIS"].to_numpy()
    cross = np.nan
    for i in range(len(x) - 1):
        if (y[i] - b4) * (y[i + 1] - b4) <= 0 and y[i] != y[i + 1]:
            cross = float(x[i] + (b4 - y[i]) * (x[i + 1] - x[i]) / (y[i + 1] - y[i]))
            break
    return pd.DataFrame(
        {
            "bound": [
                "held-out floor sqrt(2) x noise = 4 ug",
                f"training-readings floor (1 in {n_train} its own target) = 4 ug",
                "our IAFSA-SCM-ANFIS, median held-out RMSE = 4 ug",
            ],
            "largest noise (ug per reading)": [
                b4 / rmse_floor_ug(1.0),
                b4 / rmse_floor_ug(1.0, 1.0 / n_train),
                cross,
            ],
        }
    )


def tuner_table(runs: list, err: pd.DataFrame) -> pd.DataFrame:
    """Does the swarm matter: per tuner, the median over seeds of the chosen ``ra``, ``rb/ra``, rules,
    fitness evaluations (``genfis2`` fits), best checking RMSE (ug) and the held-out RMSE (ug) after ANFIS,
    beside ANFIS at MATLAB's default radius."""
    rows = []
    for m in ("ANFIS", "IAFSA-SCM-ANFIS", *TUNERS):
        rmse = 1000 * err[(err["method"] == m) & (err["set"] == "test")]["RMSE_mg"]
        if m == "ANFIS":
            rows.append(
                {
                    "tuner": "none (radius 0.5, ANFIS)",
                    "ra": np.nan,
                    "rb/ra": np.nan,
                    "rules": float(np.median([r.n_rules["ANFIS"] for r in runs])),
                    "fitness fits": 0,
                    "checking RMSE (ug)": np.nan,
                    "held-out RMSE (ug)": float(rmse.median()),
                }
            )
            continue
        v = np.array([r.tuned[m] for r in runs], float)
        rows.append(
            {
                "tuner": m.split("-")[0] if m != "IAFSA-SCM-ANFIS" else "IAFSA",
                "ra": np.median(v[:, 0]),
                "rb/ra": np.median(v[:, 1]),
                "rules": np.median(v[:, 4]),
                "fitness fits": int(np.median(v[:, 2])),
                "checking RMSE (ug)": 1000 * np.median(v[:, 3]),
                "held-out RMSE (ug)": float(rmse.median()),
            }
        )
    return pd.DataFrame(rows)


def spread_summary(need: pd.DataFrame, paper: pd.DataFrame, spreads=BATCH_SPREADS) -> pd.DataFrame:
    """Over the draws of :func:`~navlib.studies.accelerometer.batch_spread.spread_needed`, per spread: unit B's
    largest drift (median, 5th and 95th percentile, mg) and the units' difference alone (median, ug); and the share
    of draws whose drift reaches the paper's 7.21 mg."""
    before = _paper_value(paper, "unit_b_before")
    rows = []
    for s in spreads:
        d, e = need[f"drift {s:g} (mg)"], need[f"difference {s:g} (ug)"]
        rows.append(
            {
                "spread": s,
                "drift median (mg)": d.median(),
                "drift p5 (mg)": d.quantile(0.05),
                "drift p95 (mg)": d.quantile(0.95),
                f"share >= {before:g} mg": float((d >= before).mean()),
                "units' difference median (ug)": e.median(),
            }
        )
    return pd.DataFrame(rows)
