"""The workbench chapter's claims (navlib.studies.workbench.claims): the book's targets judged on the worst
case's Wilson interval, the trials a decisive interval needs, the real-data claims, the reference-free
heading claim; and the study's distance law, level loops and conventions example."""

import numpy as np
import pandas as pd
import pytest

from navlib import verdicts
from navlib.errors import InputError
from navlib.studies import workbench as wb
from navlib.studies.workbench.claims import _wilson_bounds


def test_distance_law_recovers_a_dipole_with_offset():
    d = np.arange(1.0, 6.0)
    trials = pd.DataFrame(
        {"nominal distance (cm)": d, "|hard iron| (uT)": 2000.0 * (d + 2.5) ** -3}
    )
    law = wb.distance_law(trials)
    assert law.dipole_offset_cm == pytest.approx(
        2.5, abs=1e-4
    ) and law.dipole_coef == pytest.approx(2000, rel=1e-4)
    assert 1.0 < law.power_exponent < 3.0


@pytest.mark.skipif(not wb.LEVEL_DIR.is_dir(), reason="../shared/realdata absent")
def test_real_level_files_end_honestly():
    level = wb.level_loops()
    for name, res in level.results.items():
        assert res.consistent_with_noise or res.unexplained, name
        assert max([u["amplitude"] for u in res.unexplained] + [0]) <= 3 * res.final.rms, name
        assert res.final.rms < 0.8 * res.fits[0].rms, name


def test_conventions_example_and_the_heading_claim():
    """The chapter's worked example of the conventions, and the reference-free vs reference-based heading
    claim decided by the one rule on paired trials."""
    t = wb.conventions_example()["value"]
    assert t["compass heading atan2(-m_y, m_x)"] == "90.0 deg"
    assert t["body x (forward) in NED"].startswith("+0.000, +1.000, +0.000")
    assert t["paper E: body y (forward) in ENU"].startswith("+1.000, +0.000, +0.000")
    assert t["paper E's yaw (rad, counter-clockwise, ENU)"] == f"{-np.pi / 2:+.4f} rad"
    base = np.array([2.0, 2.5, 3.0, 1.8, 2.2, 2.9, 1.9, 2.4])

    def heads(diff):
        return pd.DataFrame(
            {
                "reference-free calibration (deg)": base + diff,
                "reference-based calibration (deg)": base,
            }
        )

    assert wb.free_vs_reference_claim(heads(-0.1 - 0.01 * np.arange(8))).verdict == "reproduced"
    assert wb.free_vs_reference_claim(heads(0.1 + 0.01 * np.arange(8))).verdict == "not reproduced"
    assert (
        wb.free_vs_reference_claim(heads(0.1 * np.tile([-1.0, 1.0], 4))).verdict
        == "cannot be judged"
    )


def fake_study(cases, nulls=(300, 6), ratios=(3.0, 10.0)):
    """A hidden-effect study table: ``cases`` = {hidden effect: (k named, n)}; ``nulls`` = (n, false alarms)."""
    rows = []
    for hidden, (k, n) in cases.items():
        rows += [
            {
                "hidden": hidden,
                "ratio": ratios[i % len(ratios)],
                "noise": 0.1 * (1 + i % 2),
                "correct": i < k,
            }
            for i in range(n)
        ]
    n0, alarms = nulls
    rows += [
        {"hidden": "(none)", "ratio": 0.0, "noise": 0.1 * (1 + i % 2), "correct": i >= alarms}
        for i in range(n0)
    ]
    return pd.DataFrame(rows)


def fake_ooc(per_kind=40, misses=0):
    return pd.DataFrame(
        [
            {"kind": kind, "ratio": 5.0, "noise": 0.1, "quiet": not (kind == "b" and i < misses)}
            for kind in ("a", "b")
            for i in range(per_kind)
        ]
    )


def by_key(claims):
    return {c.key: c for c in claims}


def test_claims_are_the_books_targets_judged_on_wilson_intervals_not_point_values():
    # 16 of 16 named everywhere: a perfect score, but its Wilson lower bound is 0.81 < 0.95
    claims = by_key(
        wb.glance_claims(
            {"compass": fake_study({"x": (16, 16), "y": (16, 16)})}, fake_ooc(), None, None
        )
    )
    for c in claims.values():
        assert c.source == "book" and c.paper == "(not in the paper)" and c.rule == "wilson rate"
        assert "our target" in c.claim
    named = claims["wb_named"]
    assert (named.boundary, named.holds_when) == (95.0, "above")
    lo, hi = verdicts.wilson(16, 16).interval
    assert named.interval == pytest.approx((100 * lo, 100 * hi))
    assert (
        named.verdict == "cannot be judged" and "73" in named.reason
    )  # trials a decisive interval needs
    fa = claims["wb_false_alarms"]
    assert (fa.boundary, fa.holds_when) == (5.0, "below") and fa.estimate.value == pytest.approx(
        2.0
    )
    assert fa.verdict == "reproduced"  # 6 of 300: [0.9, 4.3] %
    assert (claims["wb_quiet"].boundary, claims["wb_quiet"].holds_when) == (90.0, "above")
    assert claims["wb_quiet"].verdict == "reproduced"  # 40 of 40: lower bound 91.2 %


def test_rate_claims_are_judged_on_the_worst_case_not_pooled():
    # 80/80 and 70/80: pooled 150/160 would straddle 95 %; the worst case (70/80) lies wholly below it
    claims = by_key(
        wb.glance_claims(
            {"compass": fake_study({"x": (80, 80), "y": (70, 80)})}, fake_ooc(), None, None
        )
    )
    named = claims["wb_named"]
    assert named.estimate.n == 80 and named.estimate.value == pytest.approx(100 * 70 / 80)
    assert named.verdict == "not reproduced" and "compass / y" in named.ours
    assert (
        verdicts.decide(verdicts.wilson(150, 160).interval, 0.95, "above")[0] is None
    )  # what pooling gave
    # false alarms: the worst data set is the one with the most alarms, on the "below" side
    b = fake_study({"x": (80, 80)}, nulls=(300, 30))
    claims = by_key(
        wb.glance_claims(
            {"A": fake_study({"x": (80, 80)}, nulls=(300, 0)), "B": b.assign(noise=b.noise * 1e-3)},
            fake_ooc(),
            None,
            None,
        )
    )
    fa = claims["wb_false_alarms"]
    assert fa.ours.startswith("worst of 2: B") and fa.verdict == "not reproduced"
    assert "2 noise levels" in fa.statistic and "2 noise levels" in claims["wb_named"].statistic
    # out of catalogue: one kind with misses decides
    claims = by_key(
        wb.glance_claims({"A": fake_study({"x": (80, 80)})}, fake_ooc(40, misses=12), None, None)
    )
    assert "b, 28/40" in claims["wb_quiet"].ours and claims["wb_quiet"].verdict == "not reproduced"


def test_worst_case_prefers_a_case_wholly_on_the_wrong_side():
    a, b = wb.Case("a", 0, 2), wb.Case("b", 10, 100)  # a: lowest lower bound but straddles 95 %
    assert wb.worst_case([a, b], 0.95, "above") is b
    assert wb.worst_case([wb.Case("c", 79, 80), wb.Case("d", 80, 80)], 0.95, "above").name == "c"
    low, high = wb.Case("low", 1, 300), wb.Case("high", 9, 300)
    assert wb.worst_case([low, high], 0.05, "below") is high
    with pytest.raises(InputError):
        wb.worst_case([a], 0.95, "up")


@pytest.mark.parametrize(
    "k,n,boundary,side",
    [
        (16, 16, 0.95, "above"),
        (8, 300, 0.05, "below"),
        (5, 5, 0.95, "above"),
        (4, 4, 0.90, "above"),
        (70, 80, 0.95, "above"),
    ],
)
def test_trials_needed_agrees_with_the_wilson_interval_of_the_rule(k, n, boundary, side):
    assert _wilson_bounds(k / n, n) == pytest.approx(verdicts.wilson(k, n).interval, abs=1e-12)
    m = wb.trials_needed(k, n, boundary, side)
    p = k / n

    def decisive(trials):
        lo, hi = verdicts.wilson(round(p * trials), trials).interval
        return lo > boundary or hi < boundary

    def decisive_at_rate(trials):  # the rate held at k / n exactly
        lo, hi = _wilson_bounds(p, trials)
        return lo > boundary or hi < boundary

    assert decisive_at_rate(m) and (m == n or not decisive_at_rate(m - 1))
    if k in (0, n):  # no rounding of the count: exact
        assert decisive(m) and (m == n or not decisive(m - 1))


def test_claims_on_real_data_are_left_out_without_it():
    claims = wb.glance_claims({"compass": fake_study({"x": (80, 80)})}, fake_ooc(), None, None)
    assert [c.key for c in claims] == ["wb_named", "wb_false_alarms", "wb_quiet"]
    assert not {c.key for c in claims} & set(wb.REALDATA_KEYS)


def fake_real(structure_over_rms=(0.7,), hard_first=5, rising=0, position=4):
    from types import SimpleNamespace

    results = {
        f"file{i}.csv": SimpleNamespace(
            unexplained=[{"structure": "h3", "amplitude": 0.2 * r}],
            final=SimpleNamespace(rms=0.2),
            consistent_with_noise=False,
        )
        for i, r in enumerate(structure_over_rms)
    }
    level = wb.LevelLoops(results, pd.DataFrame())
    att = [
        {
            "magnet": "attached",
            "first effect named": "hard_iron" if i < hard_first else "soft_iron",
            "calibrated rms (uT)": 6.0,
            "final rms (uT)": 7.0 if i < rising else 0.4,
            "outcome": "noise",
        }
        for i in range(5)
    ]
    sta = [
        {
            "magnet": "stationary",
            "first effect named": "-",
            "calibrated rms (uT)": 3.0,
            "final rms (uT)": 3.0,
            "outcome": "unexplained structure: field changing with position"
            if i < position
            else "noise",
        }
        for i in range(4)
    ]
    mag = SimpleNamespace(trials=pd.DataFrame(att + sta))
    return level, mag


def test_real_data_claims_exact_per_file_and_wilson_over_trials():
    level, mag = fake_real(structure_over_rms=(0.7, 4.0))
    claims = wb.glance_claims(
        {"compass": fake_study({"x": (80, 80)})}, fake_ooc(), level, mag, alpha=0.025
    )
    lv = [c for c in claims if c.key.startswith("wb_level")]
    assert [c.rule for c in lv] == ["exact", "exact"] and all(
        c.boundary == 3.0 and c.holds_when == "below" for c in lv
    )
    assert [c.verdict for c in lv] == ["reproduced", "not reproduced"]
    assert all(c.source == "book" and "0.025" in c.decided_by[0] for c in lv)
    att, sta = by_key(claims)["wb_attached"], by_key(claims)["wb_stationary"]
    assert att.rule == sta.rule == "wilson rate" and att.estimate.n == 5 and sta.estimate.n == 4
    assert att.verdict == "cannot be judged" and "73" in att.reason  # 5 of 5 cannot show >= 95 %
    assert sta.verdict == "cannot be judged" and sta.boundary == 90.0
    assert any("calibration" in d for d in att.decided_by)
    # a trial whose error rises after the loop does not count as a success
    _, mag = fake_real(rising=1)
    att = by_key(wb.glance_claims({"c": fake_study({"x": (80, 80)})}, fake_ooc(), level, mag))[
        "wb_attached"
    ]
    assert att.estimate.value == pytest.approx(80.0)
