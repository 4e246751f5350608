"""Unit B as a function of the batch spread: the chapter's runs' models on unit B drawn at every spread
(:func:`unit_b_spread`), and over many draws of unit B the spread at which the two units' difference
alone reaches the paper's 9.3 ug (:func:`spread_needed`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...errors import check_param
from ...sensors.accelerometer import sensor_temperatures_c, simulate_tumble
from .models import oracle
from .parameters import BATCH_SPREADS, PaperDParams, _paper_value
from .simulation import samples, sim_seed, unit_b_coefficients


def unit_b_spread(
    runs: list, params: PaperDParams, spreads=BATCH_SPREADS, method: str = "IAFSA-SCM-ANFIS"
) -> pd.DataFrame:
    """Unit B as a function of the batch spread: for every run (seed) and spread, unit B drawn by
    :func:`~navlib.studies.accelerometer.simulation.unit_b_coefficients` (the same ``z`` at every spread) with the
    seed's unit-B noise, compensated with the run's ``method`` and unit A's exact model.  Per row: largest
    ``|error|`` (ug) of both against the measured 55 degC target, the largest error unit A's exact model leaves on
    unit B's noise-free outputs (the units' difference alone, ug) and unit B's largest drift before compensation
    (mg)."""
    rows = []
    ref = params.experiment.reference_c
    for r in runs:
        for sp in spreads:
            coef_b = unit_b_coefficients(params, r.seed, float(sp))
            df = simulate_tumble(coef_b, params.experiment, sim_seed(r.seed, "noise_b"), "B")
            b = samples(df, "B", ref)  # the rows of df in order
            X = b[["temperature_c", "output_mg"]].to_numpy()
            Xt = np.column_stack([b["temperature_c"], df["true_output_mg"]])
            rows.append(
                {
                    "seed": r.seed,
                    "spread": float(sp),
                    "max drift before (mg)": float(np.max(np.abs(b["output_mg"] - b["target_mg"]))),
                    f"{method} max |e| (ug)": 1000
                    * float(np.max(np.abs(r.models[method](X) - b["target_mg"]))),
                    "exact model A max |e| (ug)": 1000
                    * float(np.max(np.abs(r.models["oracle"](X) - b["target_mg"]))),
                    "units' difference (ug)": 1000
                    * float(np.max(np.abs(r.models["oracle"](Xt) - b["target_true_mg"]))),
                }
            )
    return pd.DataFrame(rows)


def _units_difference(params: PaperDParams, draw: int, spreads) -> tuple:
    """Noise-free: unit B's largest drift (mg) and the largest error unit A's exact model leaves on it (ug),
    per spread, for unit B of draw ``draw``."""
    exp = params.experiment
    temps = sensor_temperatures_c(exp)
    pos = np.broadcast_to(exp.positions_deg, temps.shape)
    k_ref = int(np.flatnonzero(np.isclose(exp.set_points_c, exp.reference_c))[0])
    orc = oracle(params.coefficients, exp.reference_c)
    drift, diff = [], []
    for sp in spreads:
        out = unit_b_coefficients(params, draw, float(sp)).output_mg(temps, pos)
        target = np.broadcast_to(out[k_ref], out.shape)
        drift.append(float(np.max(np.abs(out - target))))
        pred = orc(np.column_stack([temps.ravel(), out.ravel()])).reshape(out.shape)
        diff.append(1000 * float(np.max(np.abs(pred - target))))
    return np.array(drift), np.array(diff)


def spread_needed(
    params: PaperDParams, paper: pd.DataFrame, spreads=BATCH_SPREADS, n_draws: int = 200
) -> pd.DataFrame:
    """Per draw of unit B (draw ``k`` uses :func:`~navlib.studies.accelerometer.simulation.sim_seed` ``(k,
    "batch_b")``; no draw is picked): its largest drift before compensation at every spread (mg), and the spread at
    which the units' difference alone (unit A's exact model on unit B's noise-free outputs) first reaches the
    paper's 9.3 ug (linear interpolation over 0 and ``spreads``; at spread 0 the exact model leaves only the
    cross-coupling and misalignment terms it ignores, a few ug; NaN when 9.3 ug is not reached within
    ``spreads``)."""
    check_param("n_draws", n_draws, lo=1, hi=100000, integer=True)
    b = _paper_value(paper, "unit_b_after") * 1000
    sp = np.asarray(spreads, float)
    rows = []
    for k in range(int(n_draws)):
        drift, diff0 = _units_difference(params, k, np.concatenate([[0.0], sp]))
        drift, diff = drift[1:], diff0[1:]
        s0 = np.concatenate([[0.0], sp])
        hit = np.flatnonzero(diff0 >= b)
        if hit.size == 0 or hit[0] == 0:
            need = np.nan
        else:
            i = int(hit[0])
            need = float(
                s0[i - 1] + (b - diff0[i - 1]) * (s0[i] - s0[i - 1]) / (diff0[i] - diff0[i - 1])
            )
        rows.append(
            {
                "draw": k,
                **{f"drift {s:g} (mg)": d for s, d in zip(sp, drift)},
                **{f"difference {s:g} (ug)": d for s, d in zip(sp, diff)},
                "spread for 9.3 ug": need,
            }
        )
    return pd.DataFrame(rows)
