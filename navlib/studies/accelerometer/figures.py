"""The paper's figures as tidy tables: the output, bias and scale-factor drifts of the simulated sensor
(Figs 2-4, :func:`drift_summary`, :func:`drift_by_seed`), a run's residuals (Fig 8) and the second unit
before and after compensation (Fig 9)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...sensors.accelerometer import T_REF_C, bias_test, simulate_tumble
from .parameters import K1_MIN_INPUT_G, METHODS, PaperDParams, _paper_value
from .runs import Run
from .simulation import samples, sim_seed


def fig2_output_drift(
    df: pd.DataFrame, unit: str = "A", reference_c: float = T_REF_C
) -> pd.DataFrame:
    """Fig 2: output drift ``N(T, q) - N(55, q)`` (mg) against temperature and input ``a = cos q`` (g)."""
    s = samples(df, unit, reference_c)
    return pd.DataFrame(
        {
            "set_point_c": s["set_point_c"],
            "temperature_c": s["temperature_c"],
            "position_deg": s["position_deg"],
            "input_g": np.round(np.cos(np.deg2rad(s["position_deg"])), 6),
            "drift_mg": s["output_mg"] - s["target_mg"],
        }
    )


def fig3_bias(params: PaperDParams, seed: int = 0) -> pd.DataFrame:
    """Fig 3: the 0/180 deg bias test (mg) and its drift against 55 degC, measured and model K0."""
    bt = bias_test(params.coefficients, params.experiment, seed=sim_seed(seed, "bias_test"))
    ref = bt.loc[np.isclose(bt["set_point_c"], params.experiment.reference_c)]
    bt["bias_drift_mg"] = bt["bias_mg"] - float(ref["bias_mg"].iloc[0])
    bt["true_bias_drift_mg"] = bt["true_bias_mg"] - float(ref["true_bias_mg"].iloc[0])
    return bt


def fig4_scale_factor(
    df: pd.DataFrame,
    params: PaperDParams,
    unit: str = "A",
    min_input_g: float = K1_MIN_INPUT_G,
    seed: int = 0,
) -> pd.DataFrame:
    """Fig 4: scale factor by the paper's eq 3, ``K1(T, a) = (U(T, a) - K0(T))/a`` with ``K0`` from the
    bias test (mg/g, i.e. relative x 1000), and its drift against 55 degC, for ``|a| >= min_input_g``."""
    bt = fig3_bias(params, seed).set_index("set_point_c")["bias_mg"]
    g = df[df["unit"] == unit]
    a = np.cos(np.deg2rad(g["position_deg"].to_numpy()))
    keep = np.abs(a) >= min_input_g
    g = g[keep]
    a = np.round(a[keep], 6)
    k1 = (g["output_mg"].to_numpy() - bt.loc[g["set_point_c"]].to_numpy()) / a
    out = pd.DataFrame({"set_point_c": g["set_point_c"].to_numpy(), "input_g": a, "k1_mg_g": k1})
    ref = (
        out[np.isclose(out["set_point_c"], params.experiment.reference_c)]
        .groupby("input_g")["k1_mg_g"]
        .mean()
    )
    out["k1_drift_mg_g"] = out["k1_mg_g"] - out["input_g"].map(ref).to_numpy()
    return out


def fig8_residuals(run: Run, sets=("test",)) -> pd.DataFrame:
    """Fig 8: residuals (ug) of the four models (and the physical baseline) on the held-out samples of one
    run, in sample order."""
    g = run.a[run.a["set"].isin(sets)].reset_index(drop=True)
    frames = [
        pd.DataFrame(
            {
                "sample": np.arange(len(g)),
                "set_point_c": g["set_point_c"],
                "method": m,
                "residual_ug": 1000 * (g[f"pred_{m}"] - g["target_mg"]),
            }
        )
        for m in METHODS
    ]
    return pd.concat(frames, ignore_index=True)


def fig9_unit_b(run: Run, method: str = "IAFSA-SCM-ANFIS") -> pd.DataFrame:
    """Fig 9: unit B's drift against its own 55 degC output before and after compensation with unit A's
    model (mg), per sample."""
    b = run.b
    return pd.DataFrame(
        {
            "sample": np.arange(len(b)),
            "set_point_c": b["set_point_c"],
            "position_deg": b["position_deg"],
            "before_mg": b["output_mg"] - b["target_mg"],
            "after_mg": b[f"pred_{method}"] - b["target_mg"],
        }
    )


def drift_summary(
    df: pd.DataFrame, params: PaperDParams, paper: pd.DataFrame, seed: int = 0
) -> pd.DataFrame:
    """Figs 2-4 and 9 in numbers: maximum output, bias and scale-factor drift (unit A) and unit B's maximum
    output drift, ours beside the paper's."""
    f2 = fig2_output_drift(df, "A", params.experiment.reference_c)
    f3 = fig3_bias(params, seed)
    f4 = fig4_scale_factor(df, params, seed=seed)
    fb = fig2_output_drift(df, "B", params.experiment.reference_c)
    rows = [
        (
            "max |output drift|, unit A",
            "mg",
            f2["drift_mg"].abs().max(),
            _paper_value(paper, "max_output_drift"),
        ),
        (
            "max |bias drift|",
            "mg",
            f3["bias_drift_mg"].abs().max(),
            _paper_value(paper, "max_bias_drift"),
        ),
        (
            "max |scale-factor drift|",
            "mg/g",
            f4["k1_drift_mg_g"].abs().max(),
            _paper_value(paper, "max_scale_factor_drift"),
        ),
        (
            "max |output drift|, unit B",
            "mg",
            fb["drift_mg"].abs().max(),
            _paper_value(paper, "unit_b_before"),
        ),
    ]
    return pd.DataFrame(rows, columns=["quantity", "unit", "ours", "paper"])


def drift_by_seed(params: PaperDParams, seeds) -> pd.DataFrame:
    """Figs 2-3 per seed (unit A, measured, against 55 degC): the largest ``|bias drift|`` of the 0/180 deg bias
    test (:func:`fig3_bias`, noise :func:`~navlib.studies.accelerometer.simulation.sim_seed` ``(seed,
    "bias_test")``) and the largest ``|N(T, q) - N(55, q)|`` of the tumble (:func:`fig2_output_drift`, unit A's
    noise ``(seed, "noise_a")``), in mg; one row per seed."""
    rows = []
    for s in seeds:
        s = int(s)
        df = simulate_tumble(params.coefficients, params.experiment, sim_seed(s, "noise_a"), "A")
        rows.append(
            {
                "seed": s,
                "max |bias drift| (mg)": float(fig3_bias(params, s)["bias_drift_mg"].abs().max()),
                "max |output drift| (mg)": float(
                    fig2_output_drift(df, "A", params.experiment.reference_c)["drift_mg"]
                    .abs()
                    .max()
                ),
            }
        )
    return pd.DataFrame(rows)
