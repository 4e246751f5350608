"""Paper D's "every evaluation index is greatly reduced compared with the single models" (section 5.2, Fig 8,
Table 2 lost in the OCR; register entry D13), judged on the per-seed indices the chapter's Table 2 already holds
(:func:`~navlib.studies.accelerometer.runs.metrics`): no new fits.

Per index ``i`` of :data:`INDICES` (ME, ``|AE|``, MAXE, MARE and the residual range ``max e - min e``) and
single model ``m`` of :data:`SINGLE_MODELS` (ANN, FIS, ANFIS), the paired difference over the same seeds on the
test readings

.. math:: d_s = i_m(s) - i_{\\mathrm{IAFSA\\text{-}SCM\\text{-}ANFIS}}(s), \\qquad \\text{boundary } 0,
   \\text{ holds above}

(:func:`navlib.verdicts.paired_difference`), with the paired ratio ``i_m / i_best`` beside: "greatly" has no
printed boundary (Table 2 is lost), so the boundary is 0 and the ratio says how much lower.  The claim is a
conjunction over the 5 x 3 cases, judged on the worst case (:func:`worst_case`), as the workbench judges its
rate claims over cases: reproduced only when every case's interval lies above 0, not reproduced when any case's
lies wholly below.  The cases have different units (ug, %), so the worst case is chosen on the paired ratio
(unit-free, boundary 1), whose interval lies above 1, straddles it or lies below it exactly when the paired
difference's lies above 0, straddles it or lies below it (the same order statistics of the same signs)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ... import verdicts
from ...claims import Claim
from ...errors import InputError
from .parameters import MIN_SEEDS_FOR_CLAIMS, PaperDParams
from .tables import per_seed

BEST = "IAFSA-SCM-ANFIS"
#: The single models the paper compares its model with (section 5.2).
SINGLE_MODELS = ("ANN", "FIS", "ANFIS")
#: Table 2's indices as the claim compares them: (name, column of the errors table, factor from the column's
#: unit (mg, or a fraction) to the shown unit, the shown unit, compare the magnitude).  AE is the signed mean
#: error, so its magnitude is what "reduced" can mean; ME (max ``|e|``) is a magnitude already.
INDICES = (
    ("ME", "ME_mg", 1000.0, "ug", False),
    ("|AE|", "AE_mg", 1000.0, "ug", True),
    ("MAXE", "MAXE", 100.0, "%", False),
    ("MARE", "MARE", 100.0, "%", False),
    ("residual range", "range_mg", 1000.0, "ug", False),
)


def index_by_seed(err: pd.DataFrame, s: str = "test") -> dict:
    """Per index of :data:`INDICES`: one row per seed, one column per model (the single models and
    IAFSA-SCM-ANFIS), in the index's shown unit, on set ``s``; seeds lacking a model are an error
    (:func:`~navlib.studies.accelerometer.tables.per_seed`), so the comparisons are paired."""
    out = {}
    for name, col, factor, _, magnitude in INDICES:
        # per_seed gives 1000 x the column (mg -> ug); rescale to the index's unit
        t = per_seed(err, (*SINGLE_MODELS, BEST), s, col) * (factor / 1000.0)
        out[name] = t.abs() if magnitude else t
    return out


def index_cases(err: pd.DataFrame, s: str = "test") -> pd.DataFrame:
    """The 5 x 3 cases of the claim on set ``s``: per index and single model, both medians over seeds,
    the paired difference (single - IAFSA-SCM-ANFIS) and the paired ratio (single / IAFSA-SCM-ANFIS), each
    with its 95 % interval (:mod:`navlib.verdicts`)."""
    rows = []
    for (name, _, _, unit, _), t in zip(INDICES, index_by_seed(err, s).values()):
        for m in SINGLE_MODELS:
            d = verdicts.paired_difference(t[m], t[BEST])
            r = verdicts.paired_ratio(t[m], t[BEST])
            rows.append(
                {
                    "index": name,
                    "model": m,
                    "unit": unit,
                    "single": float(t[m].median()),
                    BEST: float(t[BEST].median()),
                    "difference": d,
                    "ratio": r,
                }
            )
    return pd.DataFrame(rows)


def worst_case(cases: pd.DataFrame) -> pd.Series:
    """The case that decides the conjunction (every single model above IAFSA-SCM-ANFIS on every index),
    chosen on the unit-free paired ratio against 1: a case whose interval lies wholly below 1 if there is one
    (the lowest upper end), else the case with the lowest lower end.  Its paired difference then decides as
    every case's would together (:mod:`~navlib.studies.accelerometer.indices`)."""
    if cases.empty:
        raise InputError("worst_case: no cases")
    hi = np.array([r.hi for r in cases["ratio"]])
    lo = np.array([r.lo for r in cases["ratio"]])
    below = hi < 1.0
    k = int(np.argmin(np.where(below, hi, np.inf))) if below.any() else int(np.argmin(lo))
    return cases.iloc[k]


def _ratio_text(r: verdicts.Estimate) -> str:
    return f"ratio {r.value:.3g}x [{r.lo:.3g}, {r.hi:.3g}]"


def index_claims(err: pd.DataFrame, params: PaperDParams, reading: str, key: str = "") -> list:
    """D13 under one reading (a split) on the test readings of ``err`` (run with ``params``): first the
    conjunction (every index of every single model above IAFSA-SCM-ANFIS's, the worst case's paired
    difference, key ``key``), then one row per index and single model (paired difference, boundary 0, the
    ratio beside)."""
    n = err["seed"].nunique()
    if n < MIN_SEEDS_FOR_CLAIMS:
        raise InputError(
            f"parameter seeds: the 95 % intervals of the claims need at least "
            f"{MIN_SEEDS_FOR_CLAIMS} seeds, got {n}"
        )
    cases = index_cases(err)
    paper = "greatly reduced (Table 2 lost in the OCR)"
    decided = (
        f"sensor noise {params.experiment.noise_ug:g} ug per reading",
        "our simulated sensor",
        f"FIS/ANFIS clustering radius {params.fis_radius:g} (MATLAB's default)",
        f"ANN 2-{params.mlp.n_hidden}-1",
        "'greatly' unbounded: boundary 0, the paired ratio beside",
    )
    names = ", ".join(i[0] for i in INDICES)
    w = worst_case(cases)
    out = [
        Claim(
            f"{BEST} lower than ANN, FIS and ANFIS on every index",
            paper,
            reading=reading,
            statistic=f"worst of the {len(cases)} paired differences index of the single model - "
            f"index of {BEST} ({names} x {', '.join(SINGLE_MODELS)}; the worst chosen on the paired "
            f"ratio), test readings, same seeds, {w['unit']}",
            estimate=w["difference"],
            boundary=0.0,
            holds_when="above",
            unit=w["unit"],
            decided_by=decided,
            ours=f"worst of {len(cases)}: {w['model']} {w['index']}, {w['single']:.3g} vs "
            f"{w[BEST]:.3g} {w['unit']}, {_ratio_text(w['ratio'])}",
            spec="{:.3g}",
            key=key,
        )
    ]
    for _, c in cases.iterrows():
        out.append(
            Claim(
                f"{c['model']} {c['index']} > {BEST} {c['index']}",
                paper,
                reading=reading,
                statistic=f"{c['index']} {c['model']} - {c['index']} {BEST}, test readings, "
                f"same seeds, {c['unit']}",
                estimate=c["difference"],
                boundary=0.0,
                holds_when="above",
                unit=c["unit"],
                decided_by=decided,
                ours=f"{c['single']:.3g} vs {c[BEST]:.3g} {c['unit']}, {_ratio_text(c['ratio'])}",
                spec="{:.3g}",
            )
        )
    return out


def index_table(err: pd.DataFrame) -> pd.DataFrame:
    """The cases of :func:`index_cases` for display: medians over seeds, the paired difference and the
    paired ratio with their 95 % intervals."""
    c = index_cases(err)
    return pd.DataFrame(
        {
            "index": c["index"],
            "single model": c["model"],
            "unit": c["unit"],
            "single (median)": c["single"],
            f"{BEST} (median)": c[BEST],
            "difference": [e.value for e in c["difference"]],
            "difference 95 % low": [e.lo for e in c["difference"]],
            "difference 95 % high": [e.hi for e in c["difference"]],
            "ratio": [e.value for e in c["ratio"]],
            "ratio 95 % low": [e.lo for e in c["ratio"]],
            "ratio 95 % high": [e.hi for e in c["ratio"]],
        }
    )
