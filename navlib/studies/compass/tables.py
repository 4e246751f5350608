"""The compass chapter's runs shaped for display and for the results file: the summary over seeds and the
paper's ranges beside ours, the ordering probabilities, the noise and convergence summaries, the panels of
Fig 4, and the methods' statistics for the book's ``write_results``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...claims import method_stats
from ...methods.compass_methods import METHODS, R1, R4, READINGS, RULE_READINGS, label
from .parameters import BASE_READINGS, BP_VARIANTS
from .sweeps import ordering_probability


def summarize(runs: pd.DataFrame) -> pd.DataFrame:
    """Per method id (in order of appearance): label, runs, median min/max/RMS error, RMS spread (10th..90th
    percentile), median training time, and the hidden-node count of the ELMs (median, min, max)."""
    g = runs.groupby("method", sort=False)
    out = pd.DataFrame(
        {
            "label": g["label"].first() if "label" in runs else g.size().index.map(label),
            "runs": g.size(),
            "median_min_deg": g["min_deg"].median(),
            "median_max_deg": g["max_deg"].median(),
            "median_rms_deg": g["rms_deg"].median(),
            "rms_p10_deg": g["rms_deg"].quantile(0.1),
            "rms_p90_deg": g["rms_deg"].quantile(0.9),
            "median_time_s": g["train_time_s"].median(),
        }
    )
    if "n_nodes" in runs:
        out["median_nodes"] = g["n_nodes"].median()
        out["min_nodes"] = g["n_nodes"].min()
        out["max_nodes"] = g["n_nodes"].max()
    return out


def side_by_side(
    summary: pd.DataFrame, paper: pd.DataFrame, single: pd.DataFrame | None = None
) -> pd.DataFrame:
    """Paper's range beside ours, one row per method of ``summary``: reading, paper's min..max (the row of
    ``paper`` the method answers), ours for one run (``single``, indexed by method id, optional), our
    median range and median RMS over seeds."""
    pidx = paper.set_index("method")
    rows = []
    for mid in summary.index:
        spec = METHODS[mid]
        p = pidx.loc[spec.paper_row] if spec.paper_row in pidx.index else None
        row = {
            "method": spec.label,
            "reading": spec.reading or "-",
            "paper (deg)": f"{p.error_min_deg:+.2f} .. {p.error_max_deg:+.2f}"
            if p is not None
            else "-",
        }
        if single is not None:
            s = single.loc[mid]
            row["one run (deg)"] = f"{s.min_deg:+.2f} .. {s.max_deg:+.2f}"
        row["median range (deg)"] = (
            f"{summary.loc[mid, 'median_min_deg']:+.2f} .. "
            f"{summary.loc[mid, 'median_max_deg']:+.2f}"
        )
        row["median rms (deg)"] = summary.loc[mid, "median_rms_deg"]
        rows.append(row)
    return pd.DataFrame(rows).set_index("method")


def ordering_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Probability that one draw of each method shows paper A's ordering (LS worse than BP worse than
    DE-BP worse than ADE-BP), per DE reading and per BP variant, judged by the RMS error and by the
    largest absolute error."""
    rows = []
    by = {m: g for m, g in runs.groupby("method")}
    for reading, (ls, _, de, ade) in READINGS.items():
        if reading in RULE_READINGS or not all(k in by for k in (ls, de, ade)):
            continue
        for bp in BP_VARIANTS:
            if bp not in by:
                continue
            row = {"DE reading": reading, "BP": METHODS[bp].label}
            for metric, col in (("rms", "rms_deg"), ("max |e|", None)):

                def vals(m):
                    g = by[m]
                    return (g[col] if col else np.maximum(-g.min_deg, g.max_deg)).to_numpy(float)

                p = ordering_probability(vals(ls)[0], vals(bp), vals(de), vals(ade))
                row[f"P(order), {metric}"] = p
            rows.append(row)
    return pd.DataFrame(rows)


def noise_summary(noise_runs: pd.DataFrame) -> pd.DataFrame:
    """Per (noise_ut, method): label, runs, median RMS and median min / max error (deg)."""
    g = noise_runs.groupby(["noise_ut", "method"], sort=False)
    return pd.DataFrame(
        {
            "label": g["label"].first(),
            "runs": g.size(),
            "median_rms_deg": g["rms_deg"].median(),
            "median_min_deg": g["min_deg"].median(),
            "median_max_deg": g["max_deg"].median(),
        }
    ).reset_index()


def reach_summary(reach: pd.DataFrame) -> pd.DataFrame:
    """Per (method, training-RMS level) of :func:`~navlib.studies.compass.turntable.generations_to_reach`: the median
    generations, the share of runs that reached the level, and the final J's median, 10th and 90th percentiles
    (deg^2)."""
    g = reach.groupby(["label", "rms_level_deg"], sort=False)
    return (
        pd.DataFrame(
            {
                "generations (median)": g.generations.median(),
                "share reached": g.reached.mean(),
                "final J (deg2)": g.final_j.median(),
                "J p10": g.final_j.quantile(0.1),
                "J p90": g.final_j.quantile(0.9),
            }
        )
        .reset_index()
        .rename(columns={"rms_level_deg": "train rms (deg)"})
    )


def fig4_panels() -> list[tuple[str, list[str]]]:
    """The panels of the chapter's Fig 4 (DE-BP against ADE-BP after compensation): one per main reading
    (its DE-BP and ADE-BP), then pure DE and full DE + trainlm with every reading of ADE's rules."""
    panels = [(r, [READINGS[r][2], READINGS[r][3]]) for r in BASE_READINGS]
    for base in (R1, R4):
        panels.append(
            (
                f"{base}, ADE rules",
                [READINGS[base][2], READINGS[base][3]]
                + [ade for r, ade in RULE_READINGS.items() if r.startswith(base)],
            )
        )
    return panels


def results_methods(runs: pd.DataFrame) -> dict:
    """``{label: method_stats}`` for the book's ``write_results`` (one label per reading and
    trainer)."""
    return {
        METHODS[m].label: method_stats(g.rms_deg, g.min_deg, g.max_deg)
        for m, g in runs.groupby("method", sort=False)
    }
