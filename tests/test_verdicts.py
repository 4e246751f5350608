"""navlib.verdicts: the one rule, and the intervals it is applied to."""

import numpy as np
import pytest
from scipy import stats

from navlib import verdicts
from navlib.errors import InputError


@pytest.mark.parametrize(
    "interval,side,expected",
    [
        ((0.1, 0.9), "below", (True, "interval")),  # wholly on the claim's side
        ((1.1, 2.0), "below", (False, "interval")),  # wholly on the other side
        ((0.5, 1.5), "below", (None, "straddles")),  # contains the boundary
        ((0.5, 1.0), "below", (None, "straddles")),  # touches it
        ((1.1, 2.0), "above", (True, "interval")),
        ((0.1, 0.9), "above", (False, "interval")),
        ((1.0, 1.0), "above", (None, "straddles")),
    ],
)
def test_decide_on_each_side_of_the_boundary(interval, side, expected):
    assert verdicts.decide(interval, 1.0, side) == expected


@pytest.mark.parametrize(
    "interval,side,floor,expected",
    [
        # a clear failure far beyond both boundary and floor is a failure (ADE-BP's range: [14.1, 20.8] deg
        # against boundary 0.42 and floor 0.487)
        ((14.1, 20.8), "below", 0.487, (False, "interval")),
        # beyond the boundary but not beyond the floor: the noise excuses it
        ((0.45, 0.47), "below", 0.487, (None, "noise floor")),
        (
            (0.45, 0.49),
            "below",
            0.487,
            (None, "noise floor"),
        ),  # reaches past the floor: still excused
        # the data crossed the floor estimate: a result on the claim's side is reproduced
        ((0.40, 0.41), "below", 0.487, (True, "interval")),
        # straddling the boundary with a separated floor: the floor is why it cannot be decided
        ((0.40, 0.45), "below", 0.487, (None, "noise floor")),
        # a floor on the claim's side does not change anything
        ((0.1, 0.2), 1.0, None, None),
        ((5.0, 6.0), "above", 12.0, (False, "interval")),  # floor on the claim's side of 10
        ((8.5, 9.0), "above", 8.0, (None, "noise floor")),  # within [8, 10]: excused
        ((5.0, 6.0), "above", 8.0, (False, "interval")),  # below the floor too: failed
        # the floor's own interval: it decides only where the whole interval is separated from the boundary
        (
            (0.43, 0.44),
            "below",
            (0.41, 0.50),
            (False, "interval"),
        ),  # floor straddles 0.42: plain rule
        ((0.43, 0.44), "below", (0.43, 0.50), (None, "noise floor")),
        ((0.52, 0.60), "below", (0.43, 0.50), (False, "interval")),  # beyond the floor's far end
        ((0.49, 0.60), "below", (0.43, 0.50), (None, "noise floor")),  # touches the far end
    ],
)
def test_decide_with_a_noise_floor(interval, side, floor, expected):
    if side == 1.0:  # the no-op row
        assert verdicts.decide(interval, 1.0, "below", floor=0.05) == (True, "interval")
        return
    b = 10.0 if side == "above" else 0.42
    assert verdicts.decide(interval, b, side, floor=floor) == expected


def test_worse_bound_is_the_floor_only_when_separated():
    assert verdicts.worse_bound(0.42, "below", 0.487) == 0.487
    assert verdicts.worse_bound(0.42, "below", 0.30) == 0.42
    assert verdicts.worse_bound(0.42, "below", (0.40, 0.50)) == 0.42
    assert verdicts.worse_bound(10.0, "above", (7.0, 9.0)) == 7.0
    assert verdicts.worse_bound(10.0, "above", None) == 10.0
    with pytest.raises(InputError, match="lo <= hi"):
        verdicts.worse_bound(1.0, "below", (2.0, 1.5))


def test_floor_interval_must_contain_its_value():
    f = verdicts.Floor(0.487, "noise 0.04 uT", "noise below 0.03 uT", lo=0.47, hi=0.50)
    assert f.interval == (0.47, 0.50)
    assert verdicts.Floor(1.0, "a", "b").interval == (1.0, 1.0)
    with pytest.raises(InputError, match="must contain its value"):
        verdicts.Floor(1.0, "a", "b", lo=1.1, hi=1.2)
    assert verdicts.decide((0.43, 0.44), 0.42, "below", floor=f) == (None, "noise floor")


def test_decide_construction_and_missing_statistic():
    assert verdicts.decide((0.1, 0.2), 1.0, "below", by_construction=True) == (
        None,
        "by construction",
    )
    assert verdicts.decide(None, None, None) == (None, "no statistic")
    with pytest.raises(InputError, match="holds_when"):
        verdicts.decide((0, 1), 2.0, "left")
    with pytest.raises(InputError, match="lo <= hi"):
        verdicts.decide((2, 1), 2.0, "below")


def test_median_interval_covers_at_least_95_percent():
    """The order-statistic interval of the median covers the true median in >= 95 % of samples."""
    rng = np.random.default_rng(np.random.SeedSequence(20261201))
    for n in (6, 10, 20, 41):
        hits = 0
        for _ in range(2000):
            e = verdicts.median_ci(rng.exponential(size=n))
            hits += e.lo <= np.log(2) <= e.hi
        assert hits / 2000 >= 0.94, n
    e = verdicts.median_ci(np.arange(20.0))
    assert (e.lo, e.value, e.hi, e.n) == (5.0, 9.5, 14.0, 20)  # ranks 6 and 15 of 20


def test_quantile_interval_refuses_too_few_runs():
    with pytest.raises(InputError, match="at least 6 runs"):
        verdicts.median_ci([1.0, 2.0, 3.0, 4.0, 5.0])
    with pytest.raises(InputError, match="0.9 quantile needs at least"):
        verdicts.quantile_ci(np.arange(20.0), 0.9)
    e = verdicts.quantile_ci(np.arange(100.0), 0.9)
    assert e.lo < 90 < e.hi


def test_paired_difference_and_ratio_use_the_pairs():
    rng = np.random.default_rng(np.random.SeedSequence(1))
    common = rng.normal(0, 10, 30)  # a large seed effect shared by both methods
    a, b = common + 1.0 + rng.normal(0, 0.1, 30), common
    d = verdicts.paired_difference(a, b)
    assert d.rule == "paired difference" and 0.8 < d.lo < 1.0 < d.hi < 1.2
    # unpaired, the seed effect would swamp the difference: the pairing is what resolves it
    assert verdicts.decide(d.interval, 0.0, "above") == (True, "interval")
    r = verdicts.paired_ratio(np.full(10, 3.0), np.full(10, 1.5))
    assert (r.lo, r.value, r.hi) == (2.0, 2.0, 2.0)
    with pytest.raises(InputError, match="same runs"):
        verdicts.paired_difference([1, 2, 3], [1, 2])
    with pytest.raises(InputError, match="positive"):
        verdicts.paired_ratio([1, 2, 3, 4, 5, 6], [1, 2, 0, 4, 5, 6])


def test_wilson_interval_matches_scipy_and_a_perfect_score_is_not_certainty():
    e = verdicts.wilson(16, 16)
    assert e.value == 1.0 and e.hi == 1.0 and 0.80 < e.lo < 0.81  # the 0.81
    ci = stats.binomtest(7, 20).proportion_ci(method="wilson")
    e = verdicts.wilson(7, 20)
    assert (e.lo, e.hi) == (ci.low, ci.high)
    # a claim ">= 95 % named" on 16/16 cannot be judged; on 400/400 it is reproduced
    assert verdicts.decide(verdicts.wilson(16, 16).interval, 0.95, "above")[0] is None
    assert verdicts.decide(verdicts.wilson(400, 400).interval, 0.95, "above")[0] is True
    with pytest.raises(InputError, match="wilson"):
        verdicts.wilson(5, 4)


def test_bootstrap_is_seeded_and_brackets_the_value():
    x = np.random.default_rng(np.random.SeedSequence(3)).normal(2.0, 1.0, 40)
    a = verdicts.bootstrap([x], np.mean, seed=np.random.SeedSequence(7))
    b = verdicts.bootstrap([x], np.mean, seed=np.random.SeedSequence(7))
    assert a == b and a.lo < a.value < a.hi and a.rule == "bootstrap over rows"
    y = x + 0.5
    d = verdicts.bootstrap([y, x], lambda u, v: np.mean(u - v), seed=1)
    assert d.lo == pytest.approx(0.5) and d.hi == pytest.approx(0.5)  # rows resampled together


def test_exact_and_estimate_validation():
    e = verdicts.exact(0.25)
    assert e.interval == (0.25, 0.25) and e.rule == "exact"
    with pytest.raises(InputError, match="rule"):
        verdicts.Estimate(1.0, 0.0, 2.0, "guess", 3)
    with pytest.raises(InputError, match="lo must not exceed"):
        verdicts.Estimate(1.0, 2.0, 0.0, "exact", 1)
    with pytest.raises(InputError, match="Floor.needs"):
        verdicts.Floor(1.0, "noise 3 ug", " ")


def test_an_equivalence_margin_gives_the_fourth_outcome():
    # "A beats B" where the two differ by at most 0.005 deg: within the paper's 0.01 deg precision
    assert verdicts.decide((-0.004, 0.005), 0.0, "above", margin=0.01) == (None, "equivalent")
    assert verdicts.verdict_name(None, "equivalent") == "no difference"
    assert verdicts.verdict_label(None, "equivalent") == "no difference"
    assert verdicts.decide((0.002, 0.008), 0.0, "above", margin=0.01) == (
        None,
        "equivalent",
    )  # checked first
    assert verdicts.decide((-0.004, 0.015), 0.0, "above", margin=0.01) == (None, "straddles")
    assert verdicts.decide((0.02, 0.05), 0.0, "above", margin=0.01) == (True, "interval")
    assert verdicts.decide((-0.05, -0.02), 0.0, "above", margin=0.01) == (False, "interval")
    with pytest.raises(InputError, match="positive number"):
        verdicts.decide((0, 1), 0.0, "above", margin=0.0)
    assert "no difference" in verdicts.VERDICTS and "no difference" in verdicts.VERDICT_DEFINITIONS


def test_unpaired_bootstrap_takes_samples_of_different_sizes():
    a, b = np.array([1.8, 1.7, 1.3, 1.6]), np.array([0.5, 0.6, 0.6])
    d = verdicts.bootstrap([a, b], lambda u, v: np.mean(u) - np.mean(v), seed=2, paired=False)
    # each sample resampled on its own: the interval lies within the extremes of the two
    assert a.min() - b.max() <= d.lo <= d.value <= d.hi <= a.max() - b.min()
    assert d.n == a.size + b.size
    with pytest.raises(InputError, match="same length"):
        verdicts.bootstrap([a, b], lambda u, v: np.mean(u) - np.mean(v), seed=2)
    with pytest.raises(InputError, match="length >= 2"):
        verdicts.bootstrap([a, b[:1]], lambda u, v: 0.0, seed=2, paired=False)
