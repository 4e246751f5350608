"""The accelerometer chapter's other readings: the random split of the readings, the noise study, the tuners of
the clustering radius, "nearly two orders" at its two boundaries, and unit B as a function of the batch spread."""

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from navlib.errors import InputError
from navlib.methods.anfis import AnfisOptions
from navlib.methods.fish_swarm import FishSwarmParams
from navlib.methods.subclust import SubclustOptions, subclust, unit_sqdist
from navlib.sensors.accelerometer import TumbleExperiment
from navlib.studies import accelerometer as D

BEST = "IAFSA-SCM-ANFIS"


@pytest.fixture(scope="module")
def samples():
    p = D.PaperDParams()
    return p, D.samples(D.simulate(p, 0), "A")


# ------------------------------------------------------------------------------------------ random split
def test_random_split_is_deterministic_disjoint_and_covers_every_row(samples):
    p, s = samples
    a, again, other = D.random_split(s, p, 3), D.random_split(s, p, 3), D.random_split(s, p, 4)
    pd.testing.assert_series_equal(a, again)  # deterministic from the seed
    assert not a.equals(other)  # another seed, another split
    assert set(a) == {"train", "check", "test"} and a.index.equals(
        s.index
    )  # one label per row: disjoint, all rows
    by_t = D.split(s, p)
    for lab in ("train", "check", "test"):  # as many readings as by temperatures
        assert (a == lab).sum() == (by_t == lab).sum()
    test_t = s.loc[a == "test", "set_point_c"]
    assert test_t.nunique() > len(p.held_out_c)  # drawn from many temperatures
    assert not np.array_equal(a.to_numpy(), by_t.to_numpy())


def test_random_split_mode_is_validated():
    with pytest.raises(InputError, match="parameter split_mode"):
        D.PaperDParams(split_mode="rows")
    with pytest.raises(InputError, match="parameter grid_squash"):
        D.PaperDParams(grid_squash=(0.5,))


# --------------------------------------------------------------------------------------- tuners
def test_subclust_with_precomputed_distances_takes_the_same_decisions(samples):
    _, s = samples
    X = s[["temperature_c", "output_mg", "target_mg"]].to_numpy()[::3]
    d2 = unit_sqdist(X)
    for ra in (0.1, 0.25, 0.6):
        for q in (1.0, 1.5):
            o = subclust(
                X, ra, options=SubclustOptions(squash=q), max_centers=40, return_trace=True
            )
            w = subclust(
                X,
                ra,
                options=SubclustOptions(squash=q),
                max_centers=40,
                return_trace=True,
                sqdist=d2,
            )
            assert o[2] == w[2]
            np.testing.assert_allclose(o[0], w[0])
    with pytest.raises(InputError, match="sqdist"):
        subclust(X, 0.3, sqdist=d2[:-1, :-1])


def test_grid_search_uses_at_most_the_budget_and_finds_the_grid_minimum():
    calls = []

    def obj(Z):
        calls.append(len(Z))
        return (Z[:, 0] - 0.3) ** 2 + (Z[:, 1] - 1.5) ** 2

    x, fun, n = D.grid_search(obj, (0.1, 0.9), (1.0, 1.5, 2.0), 30)
    assert n == sum(calls) == 30 and calls == [30]
    assert x[1] == 1.5 and abs(x[0] - 0.3) <= 0.8 / 9 / 2 + 1e-12
    with pytest.raises(InputError, match="budget"):
        D.grid_search(obj, (0.1, 0.9), (1.0, 1.5, 2.0), 2)


def test_tuner_claims_are_paired_differences_against_iafsa():
    rows = [
        {"seed": s, "method": m, "set": "test", "RMSE_mg": v / 1000}
        for s in range(6)
        for m, v in ((BEST, 5.0 + s), ("AFSA-SCM-ANFIS", 6.0 + s), ("grid-SCM-ANFIS", 4.0 + s))
    ]
    cl = {c.key: c for c in D.tuner_claims(pd.DataFrame(rows), D.PaperDParams())}
    assert cl["accel_vs_afsa"].verdict == "reproduced" and cl[
        "accel_vs_afsa"
    ].estimate.value == pytest.approx(1.0)
    assert cl["accel_vs_grid"].verdict == "not reproduced" and all(
        c.source == "book" for c in cl.values()
    )


# -------------------------------------------------------------------------- two orders, noise levels
def _err(ratio_ann, ratio_fis, ratio_anfis, best=4.0, n=6):
    base = {
        BEST: best,
        "ANN": best * ratio_ann,
        "FIS": best * ratio_fis,
        "ANFIS": best * ratio_anfis,
        "physical (poly K0, K1, K2)": 30.0,
        "oracle": 0.15,
    }
    return pd.DataFrame(
        [
            {"seed": s, "method": m, "set": "test", "RMSE_mg": (v + 0.01 * s) / 1000}
            for s in range(n)
            for m, v in base.items()
        ]
    )


def test_nearly_two_orders_is_judged_per_model_and_per_boundary():
    p = D.PaperDParams(experiment=TumbleExperiment(noise_ug=0.1))
    cl = D.two_orders_claims(
        _err(60.0, 40.0, 20.0), p, D.paper_numbers(), "held-out temperatures", "x"
    )
    v = {c.key: c.verdict for c in cl}
    assert len(cl) == 6 and sorted({c.boundary for c in cl}) == pytest.approx([10**1.5, 50.0])
    assert v["x_two_orders_ann_50"] == v["x_two_orders_ann_32"] == "reproduced"
    assert (v["x_two_orders_fis_50"], v["x_two_orders_fis_32"]) == ("not reproduced", "reproduced")
    assert v["x_two_orders_anfis_50"] == v["x_two_orders_anfis_32"] == "not reproduced"
    # with 3 ug of noise the floor (4.24 ug) caps the ratio: FIS at 40 ug cannot show more than 9.4x, so a
    # ratio between that cap and 50x is excused by the noise, and one below the cap has failed
    p3 = D.PaperDParams()
    c = {
        c.key: c
        for c in D.two_orders_claims(
            _err(60.0, 40.0, 20.0, best=2.0), p3, D.paper_numbers(), "r", "x"
        )
    }
    assert (
        c["x_two_orders_fis_50"].basis == "noise floor"
        and "noise below" in c["x_two_orders_fis_50"].floor.needs
    )
    c = {
        c.key: c
        for c in D.two_orders_claims(
            _err(60.0, 40.0, 20.0, best=4.3), p3, D.paper_numbers(), "r", "x"
        )
    }
    assert (c["x_two_orders_fis_50"].verdict, c["x_two_orders_fis_50"].basis) == (
        "not reproduced",
        "interval",
    )


def test_noise_claims_give_one_verdict_per_level_and_the_permitted_noise():
    p, paper = D.PaperDParams(), D.paper_numbers()
    frames = []
    for v, best in ((1.0, 2.0), (10.0, 15.0)):
        e = _err(50.0, 10.0, 9.0, best=best)
        e.loc[e["method"] == "oracle", "RMSE_mg"] = np.sqrt(2) * v / 1000
        e.insert(0, "noise_ug", v)
        frames.append(e)
    ne = pd.concat(frames, ignore_index=True)
    cl = D.noise_claims(ne, p, paper)
    rmse = {c.reading: c for c in cl if c.claim == f"{BEST} RMSE 4 ug"}
    assert set(rmse) == {"held-out temperatures, noise 1 ug", "held-out temperatures, noise 10 ug"}
    assert rmse["held-out temperatures, noise 1 ug"].verdict == "reproduced"
    # at 10 ug the floor is 14.1 ug: 15 ug lies beyond both it and the 4 ug boundary
    assert (
        rmse["held-out temperatures, noise 10 ug"].verdict,
        rmse["held-out temperatures, noise 10 ug"].floor.value,
    ) == ("not reproduced", pytest.approx(14.142, rel=1e-3))
    assert len({(c.claim, c.reading) for c in cl}) == len(cl)
    perm = D.noise_permitted(ne, p, paper)["largest noise (ug per reading)"].to_numpy()
    assert perm[0] == pytest.approx(4 / np.sqrt(2)) and perm[1] > perm[0]
    assert perm[2] == pytest.approx(
        1.0 + (4.0 - 2.025) * 9.0 / 13.0, rel=1e-3
    )  # interpolated crossing
    grid = D.verdict_grid(cl, "noise")
    # the words every reading starts with are said once, in the first header
    assert list(grid.columns) == ["claim (by held-out temperatures, noise)", "1 ug", "10 ug"]
    # or one row per reading
    flip = D.verdict_grid(cl, "noise", rows="readings")
    assert list(flip["noise"]) == [
        "held-out temperatures, noise 1 ug",
        "held-out temperatures, noise 10 ug",
    ]
    assert len(flip.columns) == 1 + len(grid) and not flip.isna().any().any()
    with pytest.raises(InputError, match="rows="):
        D.verdict_grid(cl, "noise", rows="both")


# ------------------------------------------------------------------------------------------- unit B
def test_unit_b_is_drawn_per_seed_and_scaled_by_the_spread():
    p = D.PaperDParams()
    a = p.coefficients
    b1, b2 = D.unit_b_coefficients(p, 0, 0.01), D.unit_b_coefficients(p, 0, 0.02)
    assert D.unit_b_coefficients(p, 1, 0.01) != b1  # every seed its own unit
    assert D.unit_b_coefficients(p, 0) == D.unit_b_coefficients(p, 0, p.batch_spread_rel)
    dev1 = np.array(
        [getattr(b1, f) / getattr(a, f) - 1 for f in ("k0c_mg", "sf_lin_per_c", "kip_mg_g2")]
    )
    dev2 = np.array(
        [getattr(b2, f) / getattr(a, f) - 1 for f in ("k0c_mg", "sf_lin_per_c", "kip_mg_g2")]
    )
    np.testing.assert_allclose(dev2, 2 * dev1, rtol=1e-9)  # the same z at every spread
    df = D.simulate(p, 0)
    coef_b = D.unit_b_coefficients(p, 0)
    g = df[df["unit"] == "B"]
    from navlib.sensors.accelerometer import sensor_temperatures_c

    t = sensor_temperatures_c(p.experiment).ravel()
    np.testing.assert_allclose(
        g["true_output_mg"], coef_b.output_mg(t, g["position_deg"]), rtol=0, atol=1e-12
    )


def test_spread_needed_hits_the_papers_93_ug():
    p, paper = D.PaperDParams(), D.paper_numbers()
    need = D.spread_needed(p, paper, n_draws=3)
    _, diff0 = D._units_difference(p, 0, [0.0])
    assert 0 < diff0[0] < 9.3  # the exact model's ignored terms alone
    for k, s in enumerate(need["spread for 9.3 ug"]):
        assert 0 < s < 0.01
        _, d = D._units_difference(p, k, [s])
        assert d[0] == pytest.approx(9.3, rel=0.15)  # linear interpolation of a near-linear curve
    summ = D.spread_summary(need, paper)
    assert (
        len(summ) == len(D.BATCH_SPREADS)
        and (summ["drift p5 (mg)"] <= summ["drift p95 (mg)"]).all()
    )


def test_run_chapter_pairs_noise_levels_and_splits_over_the_same_seeds():
    p = D.PaperDParams(
        seeds=(0, 1),
        anfis=AnfisOptions(epochs=2),
        mlp=replace(D.PaperDParams().mlp, epochs=2),
        swarm=FishSwarmParams(n_fish=2, generations=1, try_number=1),
    )
    ch = D.run_chapter(p, noise_levels=(1.0, 3.0), random_reading=True, workers=1)
    assert [r.seed for r in ch.runs] == [0, 1] and set(D.TUNERS) <= set(ch.err["method"])
    assert sorted(ch.noise_err["noise_ug"].unique()) == [1.0, 3.0]
    at3 = (
        ch.noise_err[ch.noise_err["noise_ug"] == 3.0]
        .drop(columns="noise_ug")
        .reset_index(drop=True)
    )
    main = ch.err[~ch.err["method"].isin(D.TUNERS)].reset_index(drop=True)
    pd.testing.assert_frame_equal(at3, main)  # the default level is the main runs
    t = ch.random_err[(ch.random_err["method"] == BEST)]
    assert set(t["set"]) == {"train", "check", "test", "unit B"} and set(t["seed"]) == {0, 1}
    ub = D.unit_b_spread(ch.runs, p, (0.001, 0.25))
    assert (
        len(ub) == 4
        and (
            ub.groupby("seed")["units' difference (ug)"].apply(lambda v: v.is_monotonic_increasing)
        ).all()
    )
