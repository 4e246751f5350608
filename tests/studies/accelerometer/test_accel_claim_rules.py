"""The accelerometer chapter's main claims on synthetic per-seed errors: each is built by the rule of
:mod:`navlib.verdicts`, paired over the same seeds, lands on each side of its boundary, and its noise floor is
the exact model's."""

import numpy as np
import pandas as pd
import pytest

from navbook.results_check import claim_problems
from navlib import verdicts
from navlib.errors import InputError
from navlib.sensors.accelerometer import AccelCoefficients, TumbleExperiment, simulate_tumble
from navlib.studies import accelerometer as D

BEST = "IAFSA-SCM-ANFIS"
PHYS = "physical (poly K0, K1, K2)"


def _err(test, train=None, unit_b=None, seeds=None):
    """A synthetic errors table (ug in, mg stored) for :func:`navlib.studies.accelerometer.claims.claims`:
    ``test`` maps every method of ``D.METHODS`` and "oracle" to per-seed held-out RMSE; ``train`` and
    ``unit_b`` (largest error) map IAFSA-SCM-ANFIS and "oracle"."""
    n = len(test[BEST])
    seeds = list(range(n)) if seeds is None else list(seeds)
    train = train or {BEST: np.full(n, 3.6), "oracle": np.full(n, 4.2)}
    unit_b = unit_b or {BEST: np.full(n, 1300.0), "oracle": np.full(n, 1300.0)}
    rows = []
    for s, table, col in (
        ("test", test, "RMSE_mg"),
        ("train", train, "RMSE_mg"),
        ("unit B", unit_b, "ME_mg"),
    ):
        for m, v in table.items():
            for seed, x in zip(seeds, v):
                rows.append(
                    {"seed": seed, "method": m, "set": s, "RMSE_mg": x / 1000, "ME_mg": x / 1000}
                )
    return pd.DataFrame(rows)


def _test_rmse(n=6, best=None, **over):
    base = {"ANN": 240.0, "FIS": 37.9, "ANFIS": 35.7, BEST: 5.4, PHYS: 28.3, "oracle": 4.3}
    base.update(over)
    out = {m: np.full(n, v) + 0.01 * np.arange(n) for m, v in base.items()}
    if best is not None:
        out[BEST] = np.asarray(best, float)
    return out


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


def _claims(err, noise_ug=3.0):
    p = D.PaperDParams(experiment=TumbleExperiment(noise_ug=noise_ug))
    return {(c.key): c for c in D.claims(err, _DRIFT, D.paper_numbers(), p)}


def test_every_claim_is_built_by_the_rule_and_stored_verdicts_rederive():
    cl = _claims(_err(_test_rmse()))
    assert len(cl) == 12 and all(cl)  # every claim has a key for the prose
    for c in cl.values():
        assert claim_problems(c.record()) == [], c.claim
        assert c.estimate is not None or c.by_construction
    book = [c for c in cl.values() if c.source == "book"]
    assert [c.key for c in book] == ["accel_vs_poly"] and book[0].paper == "(not in the paper)"
    # the paper's numbers are the boundaries, not our tolerances
    assert cl["accel_rmse_test"].boundary == pytest.approx(4.0) and cl[
        "accel_unit_b"
    ].boundary == pytest.approx(9.3)
    assert cl["accel_orders_ann"].boundary == cl["accel_orders_fis"].boundary == 10.0
    for k in ("accel_rmse_train", "accel_rmse_test", "accel_unit_b"):
        assert cl[k].holds_when == "below" and cl[k].floor is not None
    for k in ("accel_order_ann", "accel_order_fis", "accel_order_anfis", "accel_vs_poly"):
        assert (
            cl[k].holds_when == "above"
            and cl[k].boundary == 0.0
            and cl[k].rule == "paired difference"
        )
    for k in ("accel_orders_ann", "accel_orders_fis"):
        assert (
            cl[k].holds_when == "above" and cl[k].rule == "paired ratio" and cl[k].floor is not None
        )
    assert cl["accel_drifts"].by_construction and cl["accel_drifts"].verdict == "cannot be judged"


def test_comparisons_are_paired_over_the_same_seeds():
    best = np.array([5.0, 50.0, 8.0, 30.0, 12.0, 20.0])  # wide spread over seeds
    t = _test_rmse(best=best)
    t["ANN"] = 20.0 * best  # 20x on every seed
    t["ANFIS"] = best + 1.0  # 1 ug worse on every seed
    err = _err(t).sample(frac=1.0, random_state=0)  # row order must not matter
    cl = _claims(err, noise_ug=0.1)
    r, d = cl["accel_orders_ann"].estimate, cl["accel_order_anfis"].estimate
    assert (r.lo, r.hi, r.n) == pytest.approx((20.0, 20.0, 6)) and cl[
        "accel_orders_ann"
    ].verdict == "reproduced"
    assert (d.lo, d.hi) == pytest.approx((1.0, 1.0)) and cl[
        "accel_order_anfis"
    ].verdict == "reproduced"
    # unpaired, the same numbers would overlap: ANFIS's values lie among IAFSA-SCM-ANFIS's
    assert verdicts.median_ci(t["ANFIS"]).lo < verdicts.median_ci(best).hi
    # a seed that lacks a method is an error, not a silently shorter pairing
    with pytest.raises(InputError, match="lacks"):
        _claims(err[~((err["seed"] == 3) & (err["method"] == "FIS") & (err["set"] == "test"))])


@pytest.mark.parametrize(
    "best, noise, verdict, basis",
    [
        ([3.0, 3.1, 3.2, 3.3, 3.4, 3.5], 1.0, "reproduced", "interval"),
        ([6.0, 6.1, 6.2, 6.3, 6.4, 6.5], 1.0, "not reproduced", "interval"),
        ([3.0, 3.5, 3.9, 4.1, 4.5, 5.0], 1.0, "cannot be judged", "straddles"),
        # sqrt(2) x 3 = 4.24 ug > 4 ug: between the two, the noise excuses it; below 4, the data crossed the
        # floor estimate; beyond 4.24, it failed whatever the noise
        ([4.05, 4.08, 4.1, 4.12, 4.15, 4.2], 3.0, "cannot be judged", "noise floor"),
        ([3.0, 3.1, 3.2, 3.3, 3.4, 3.5], 3.0, "reproduced", "interval"),
        ([6.0, 6.1, 6.2, 6.3, 6.4, 6.5], 3.0, "not reproduced", "interval"),
    ],
)
def test_the_4ug_claim_lands_on_each_side(best, noise, verdict, basis):
    c = _claims(_err(_test_rmse(best=best)), noise_ug=noise)["accel_rmse_test"]
    assert (c.verdict, c.basis) == (verdict, basis)
    if noise == 3.0:
        assert c.floor.value == pytest.approx(np.sqrt(2) * 3.0)
        assert "2.83 ug" in c.floor.needs and "3 ug per reading" in c.floor.assumption


def test_training_floor_is_the_exact_models_on_training_readings():
    c = _claims(_err(_test_rmse()))["accel_rmse_train"]
    n_train = 23 - 3 - 3  # set points - held out - checking
    assert c.floor.value == pytest.approx(np.sqrt(2) * 3.0 * np.sqrt(1 - 1 / n_train))
    assert c.floor.value > 4.0  # the floor lies beyond the 4 ug boundary
    lo, hi = c.interval  # so the floor decides unless the data cross it
    assert (c.verdict, c.basis) == (
        ("reproduced", "interval")
        if hi < 4.0
        else ("not reproduced", "interval")
        if lo > c.floor.value
        else ("cannot be judged", "noise floor")
    )


def test_ratio_against_fis_needs_a_floor_below_our_fis():
    cl = _claims(_err(_test_rmse()))
    fis = cl["accel_orders_fis"]
    assert fis.floor.value < 10  # 37.9 / 4.24 < 10: our FIS caps the ratio
    # the ratio lies below even that cap: worse than anything the noise excuses
    assert fis.interval[1] < fis.floor.value and (fis.verdict, fis.basis) == (
        "not reproduced",
        "interval",
    )
    assert cl["accel_orders_ann"].basis == "interval"  # 240 / 4.24 > 10
    better = _claims(_err(_test_rmse(FIS=101.0)))["accel_orders_fis"]
    assert better.basis == "interval" and better.verdict == "reproduced"


def test_unit_b_claim_sides_and_floor():
    t = _test_rmse()
    far = _claims(_err(t), noise_ug=0.5)["accel_unit_b"]
    assert far.verdict == "not reproduced"
    near = _claims(
        _err(t, unit_b={BEST: np.linspace(4, 5, 6), "oracle": np.full(6, 3.0)}), noise_ug=0.5
    )
    assert near["accel_unit_b"].verdict == "reproduced"
    # with 3 ug noise the floor (13 ug) lies beyond 9.3 ug: a unit B between the two is excused ...
    floored = _claims(_err(t, unit_b={BEST: np.linspace(10, 12, 6), "oracle": np.full(6, 3.0)}))[
        "accel_unit_b"
    ]
    assert floored.basis == "noise floor" and floored.floor.value > 9.3
    # ... one inside 9.3 ug crossed the floor estimate, one beyond the floor failed
    crossed = _claims(_err(t, unit_b={BEST: np.linspace(4, 5, 6), "oracle": np.full(6, 3.0)}))[
        "accel_unit_b"
    ]
    assert crossed.verdict == "reproduced"
    beyond = _claims(_err(t, unit_b={BEST: np.linspace(20, 25, 6), "oracle": np.full(6, 3.0)}))[
        "accel_unit_b"
    ]
    assert beyond.verdict == "not reproduced"


def test_claims_need_six_seeds():
    with pytest.raises(InputError, match="at least 6 seeds, got 4"):
        _claims(_err(_test_rmse(n=4)))


def test_floors_match_the_simulated_exact_model():
    coef = AccelCoefficients(kip_mg_g2=0.0, delta_o_mg=0.0)
    exp = TumbleExperiment(noise_ug=3.0, lag_tau_min=0.0)
    orc = D.oracle(coef)
    sq_all, sq_new, maxima = [], [], []
    for seed in range(150):
        s = D.samples(simulate_tumble(coef, exp, seed=seed), "A")
        e = 1000 * (orc(s[["temperature_c", "output_mg"]].to_numpy()) - s["target_mg"].to_numpy())
        new = ~np.isclose(s["set_point_c"], 55.0)
        sq_all.append(np.mean(e**2))
        sq_new.append(np.mean(e[new] ** 2))
        maxima.append(np.abs(e[new]).max())
    assert np.sqrt(np.mean(sq_new)) == pytest.approx(D.rmse_floor_ug(3.0), rel=0.03)
    assert np.sqrt(np.mean(sq_all)) == pytest.approx(D.rmse_floor_ug(3.0, 1 / 23), rel=0.03)
    assert np.median(maxima) == pytest.approx(D.max_error_floor_ug(3.0, 22, 24), rel=0.05)
    assert D.max_error_floor_ug(6.0, 22, 24) == pytest.approx(2 * D.max_error_floor_ug(3.0, 22, 24))
    with pytest.raises(InputError, match="reference_share"):
        D.rmse_floor_ug(3.0, 1.5)
