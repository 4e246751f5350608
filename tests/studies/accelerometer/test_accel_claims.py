"""Paper D's register entries judged from rows the chapter already computes: D12 (FIS more accurate than
ANN, a paired difference of the per-seed RMSEs under every split and noise level) and D07 (the drifts our
simulator was set to, median over seeds, true by construction)."""

import numpy as np
import pandas as pd
import pytest

from navlib import claims as register
from navlib import verdicts
from navbook.results_check import claim_problems
from navlib.sensors.accelerometer import AccelCoefficients, TumbleExperiment
from navlib.studies import accelerometer as D

BEST = "IAFSA-SCM-ANFIS"
PHYS = "physical (poly K0, K1, K2)"


def _err(ann, fis, n=6):
    """Synthetic per-seed RMSEs (ug in, mg stored) on every set :func:`D.claims` reads."""
    test = {
        "ANN": ann,
        "FIS": fis,
        "ANFIS": np.full(n, 35.7),
        BEST: np.full(n, 5.4),
        PHYS: np.full(n, 28.3),
        "oracle": np.full(n, 4.3),
    }
    rows = []
    for s in range(n):
        for m, v in test.items():
            rows.append(
                {
                    "seed": s,
                    "method": m,
                    "set": "test",
                    "RMSE_mg": v[s] / 1000,
                    "ME_mg": v[s] / 1000,
                }
            )
        for m in (BEST, "oracle"):
            rows.append({"seed": s, "method": m, "set": "train", "RMSE_mg": 0.004, "ME_mg": 0.004})
            rows.append({"seed": s, "method": m, "set": "unit B", "RMSE_mg": 1.3, "ME_mg": 1.3})
    return pd.DataFrame(rows)


_DRIFT = pd.DataFrame(
    {
        "quantity": [
            "max |output drift|, unit A",
            "max |bias drift|",
            "max |scale-factor drift|",
            "max |output drift|, unit B",
        ],
        "unit": ["mg", "mg", "mg/g", "mg"],
        "ours": [5.8, 1.68, 5.0, 6.7],
        "paper": [5.0, 1.7, 6.0, 7.21],
    }
)


def _claims(err, params=None):
    return {c.key: c for c in D.claims(err, _DRIFT, D.paper_numbers(), params or D.PaperDParams())}


# ------------------------------------------------------------------------------------------------ D12
def test_fis_beats_ann_is_the_paired_difference_and_lands_on_each_side():
    ann = np.array([100.0, 300.0, 150.0, 250.0, 120.0, 200.0])  # wide spread over seeds
    c = _claims(_err(ann, ann - 60.0))["accel_order_ann_fis"]  # FIS 60 ug better on every seed
    assert (c.claim, c.reading) == ("ANN RMSE > FIS RMSE", "held-out temperatures")
    assert c.rule == "paired difference" and (c.estimate.lo, c.estimate.hi) == pytest.approx(
        (60.0, 60.0)
    )
    assert (c.boundary, c.holds_when, c.verdict) == (0.0, "above", "reproduced")
    assert c.paper == "138 > 101 ug"  # from data/paper_d_results.csv
    assert claim_problems(c.record()) == []
    worse = _claims(_err(ann, ann + 5.0))["accel_order_ann_fis"]  # FIS worse on every seed
    assert worse.verdict == "not reproduced"
    mixed = _claims(_err(ann, ann + np.array([-3.0, 2.0, -1.0, 4.0, -2.0, 1.0])))[
        "accel_order_ann_fis"
    ]
    assert mixed.verdict == "cannot be judged" and mixed.basis == "straddles"


def test_fis_beats_ann_in_every_reading_and_noise_level():
    e = _err(np.full(6, 200.0) + np.arange(6), np.full(6, 30.0))
    p = D.PaperDParams()
    cl = [
        c
        for c in D.reading_claims(
            e, p, D.paper_numbers(), "random split of the readings", "accel_random"
        )
        if c.claim == "ANN RMSE > FIS RMSE"
    ]
    assert (
        len(cl) == 1 and cl[0].key == "accel_random_order_ann_fis" and cl[0].verdict == "reproduced"
    )
    assert cl[0].estimate.value == pytest.approx(172.5)
    ne = pd.concat([e.assign(noise_ug=v) for v in (1.0, 10.0)], ignore_index=True)
    rows = [c for c in D.noise_claims(ne, p, D.paper_numbers()) if c.claim == "ANN RMSE > FIS RMSE"]
    assert sorted(c.reading for c in rows) == [
        "held-out temperatures, noise 1 ug",
        "held-out temperatures, noise 10 ug",
    ]
    # a grid over readings that lack the row shows a dash, not NaN
    grid = D.verdict_grid(cl + [c for c in D.claims(e, _DRIFT, D.paper_numbers(), p)[:7]])
    assert not grid.isna().any().any() and "–" in grid.to_numpy()


# ------------------------------------------------------------------------------------------------ D07
def test_drifts_are_medians_over_the_seeds_and_true_by_construction():
    p = D.PaperDParams()
    d = D.drift_by_seed(p, range(6))
    assert (
        list(d["seed"]) == list(range(6)) and d["max |bias drift| (mg)"].nunique() == 6
    )  # every seed its own noise
    # the same numbers as the chapter's first-seed table (drift_summary) on seed 0
    s0 = D.drift_summary(D.simulate(p, 0), p, D.paper_numbers(), seed=0).set_index("quantity")[
        "ours"
    ]
    assert d.loc[0, "max |bias drift| (mg)"] == pytest.approx(s0["max |bias drift|"])
    assert d.loc[0, "max |output drift| (mg)"] == pytest.approx(s0["max |output drift|, unit A"])
    cl = {c.key: c for c in D.drift_claims(p, D.paper_numbers(), range(6))}
    out, bias = cl["accel_drifts"], cl["accel_drift_bias"]
    assert (out.claim, bias.claim) == (
        "output drift up to 5 mg vs 55 degC",
        "bias drift up to 1.7 mg vs 55 degC",
    )
    assert out.estimate.value == pytest.approx(np.median(d["max |output drift| (mg)"]))
    assert (out.estimate.lo, out.estimate.hi) == pytest.approx(
        (d["max |output drift| (mg)"].min(), d["max |output drift| (mg)"].max())
    )
    assert (out.boundary, bias.boundary) == pytest.approx((5.0, 1.7))
    for c in (out, bias):
        assert (
            c.by_construction and c.basis == "by construction" and c.verdict == "cannot be judged"
        )
        assert (
            "bias_lin" not in c.why and "b1 = 0.0175 mg/degC" in c.why and "k1 = -4.2e-05" in c.why
        )
        assert claim_problems(c.record()) == []
    # without the flag the rule would judge our simulator: output above 5 mg, bias just below 1.7 mg
    assert verdicts.decide(out.interval, out.boundary, "above")[0] is True
    assert verdicts.decide(bias.interval, bias.boundary, "above")[0] is False


def test_drifts_follow_the_simulator_not_a_typed_number():
    flat = D.PaperDParams(
        coefficients=AccelCoefficients(
            bias_lin_mg_c=0.0,
            bias_quad_mg_c2=0.0,
            bias_cub_mg_c3=0.0,
            bias_step_mg=0.0,
            k2_temp_mg_g2_c=0.0,
        ),
        experiment=TumbleExperiment(noise_ug=0.0),
    )
    d = D.drift_by_seed(flat, range(3))
    assert np.allclose(
        d["max |bias drift| (mg)"], 0.0, atol=1e-3
    )  # no bias (nor K2) drift: below 1 ug
    assert (d["max |output drift| (mg)"] > 1.0).all()  # the scale factor still drifts


def test_claims_use_the_seeds_of_the_runs():
    e = _err(np.full(7, 200.0), np.full(7, 30.0), n=7)
    cl = _claims(e)
    assert cl["accel_drifts"].estimate.n == 7 and cl["accel_order_ann_fis"].estimate.n == 7


# ---------------------------------------------------------------------------------------- the register
def test_register_names_the_new_rows_with_their_primary_readings():
    es = {e.id: e for e in register.load_register("paper_d")}
    d12, d07 = es["D12"], es["D07"]
    assert d12.status == d07.status == "judged"
    assert (
        d12.rows == ("ANN RMSE > FIS RMSE",)
        and d12.primary_reading == "random split of the readings"
    )
    assert d07.rows == ("output drift up to 5 mg vs 55 degC", "bias drift up to 1.7 mg vs 55 degC")
    assert (d07.primary_claim, d07.primary_reading) == (
        "output drift up to 5 mg vs 55 degC",
        "simulator defaults",
    )
    cl = _claims(_err(np.full(6, 200.0) + np.arange(6), np.full(6, 30.0)))
    for e, key in ((d12, "accel_order_ann_fis"), (d07, "accel_drifts")):
        c = cl[key]
        assert (e.boundary, e.holds_when, e.unit) == (c.boundary, c.holds_when, c.unit)
    assert d07.statistic == cl["accel_drifts"].statistic
    assert d12.statistic == cl["accel_order_ann_fis"].statistic.replace(
        "held-out temperatures", "test readings"
    )
