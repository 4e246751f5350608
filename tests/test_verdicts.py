"""navlib.verdicts: the one rule, and the intervals it is applied to."""
import numpy as np
import pytest
from scipy import stats

from navlib import verdicts
from navlib.errors import InputError


@pytest.mark.parametrize("interval,side,expected", [
    ((0.1, 0.9), "below", (True, "interval")),          # wholly on the claim's side
    ((1.1, 2.0), "below", (False, "interval")),         # wholly on the other side
    ((0.5, 1.5), "below", (None, "straddles")),         # contains the boundary
    ((0.5, 1.0), "below", (None, "straddles")),         # touches it
    ((1.1, 2.0), "above", (True, "interval")),
    ((0.1, 0.9), "above", (False, "interval")),
    ((1.0, 1.0), "above", (None, "straddles")),
])
def test_decide_on_each_side_of_the_boundary(interval, side, expected):
    assert verdicts.decide(interval, 1.0, side) == expected


def test_decide_floor_construction_and_missing_statistic():
    # a floor on the wrong side (or on the boundary) makes even a decisive interval undecidable
    assert verdicts.decide((0.1, 0.2), 1.0, "below", floor=1.0) == (None, "noise floor")
    assert verdicts.decide((1.5, 2.0), 1.0, "below", floor=1.2) == (None, "noise floor")
    assert verdicts.decide((0.1, 0.2), 1.0, "below", floor=0.05) == (True, "interval")
    assert verdicts.decide((5.0, 6.0), 10.0, "above", floor=12.0) == (False, "interval")
    assert verdicts.decide((5.0, 6.0), 10.0, "above", floor=8.0) == (None, "noise floor")
    assert verdicts.decide((0.1, 0.2), 1.0, "below", by_construction=True) == (None, "by construction")
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
    assert (e.lo, e.value, e.hi, e.n) == (5.0, 9.5, 14.0, 20)      # ranks 6 and 15 of 20


def test_quantile_interval_refuses_too_few_runs():
    with pytest.raises(InputError, match="at least 6 runs"):
        verdicts.median_ci([1.0, 2.0, 3.0, 4.0, 5.0])
    with pytest.raises(InputError, match="0.9 quantile needs at least"):
        verdicts.quantile_ci(np.arange(20.0), 0.9)
    e = verdicts.quantile_ci(np.arange(100.0), 0.9)
    assert e.lo < 90 < e.hi


def test_paired_difference_and_ratio_use_the_pairs():
    rng = np.random.default_rng(np.random.SeedSequence(1))
    common = rng.normal(0, 10, 30)                  # a large seed effect shared by both methods
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
    assert e.value == 1.0 and e.hi == 1.0 and 0.80 < e.lo < 0.81          # the 0.81
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
    assert d.lo == pytest.approx(0.5) and d.hi == pytest.approx(0.5)      # rows resampled together


def test_exact_and_estimate_validation():
    e = verdicts.exact(0.25)
    assert e.interval == (0.25, 0.25) and e.rule == "exact"
    with pytest.raises(InputError, match="rule"):
        verdicts.Estimate(1.0, 0.0, 2.0, "guess", 3)
    with pytest.raises(InputError, match="lo must not exceed"):
        verdicts.Estimate(1.0, 2.0, 0.0, "exact", 1)
    with pytest.raises(InputError, match="Floor.needs"):
        verdicts.Floor(1.0, "noise 3 ug", " ")
