"""navlib.studies.gyro: paper C's claims, their verdicts, and the register entries they fold into."""

import numpy as np
import pandas as pd
import pytest

from navlib import verdicts
from navlib.claims import Claim
from navlib.errors import InputError
from navlib.paths import data_path
from navlib.studies import gyro
from navlib.studies.gyro.simulation import _unit_position_gain


P = gyro.StudyParams()
FAST = gyro.StudyParams(sim=gyro.SimulationSettings(n_tests=3, n_seeds=1))
#: the fewest draws with which every claim has its interval (6 runs: 3 tests x 2 draws)
CLAIMS = gyro.StudyParams(
    sim=gyro.SimulationSettings(n_tests=3, n_seeds=2),
    thermal=gyro.ColdStudySettings(n_draws=7, batch_size=7, worlds=gyro.THERMAL_WORLDS[:2]),
)
#: the first claims, those of the hot-state readings and stored claims, 3 per thermal world, and the
#: register entries judged on the printed tables (C10 2, C11 2, C15 3, C13 3), and C12's RBF against BP
#: (9 sizes, the validation stop, convergence, the spread over initialisations)
N_CLAIMS = 16 + 14 + 3 * 2 + 10 + 12
SMALL = gyro.StudyParams(
    thermal=gyro.ColdStudySettings(n_draws=7, batch_size=3, worlds=gyro.THERMAL_WORLDS[:2])
)


def _t2():
    t = gyro.measured_tables().table2
    return t["latitude_error_deg"].to_numpy(), t["drift_deg_h"].to_numpy()


@pytest.fixture(scope="module")
def claims():
    return gyro.claims(CLAIMS)


def _by_key(cl):
    return {c.key: c for c in cl}


def test_claims_one_per_reading_all_judged_by_the_rule(claims):
    assert all(isinstance(c, Claim) for c in claims)
    keys = [(c.claim, c.reading) for c in claims]
    assert len(keys) == len(set(keys)) == N_CLAIMS
    assert len({c.key for c in claims}) == N_CLAIMS and all(
        c.key.startswith("gyro_") for c in claims
    )
    for c in claims:
        assert c.source == "paper" and c.paper != "(not in the paper)"
        # the verdict is the rule's, from the stored interval, boundary, side and floor
        assert (
            c.reproduced
            == verdicts.decide(
                c.interval, c.boundary, c.holds_when, None if c.floor is None else c.floor.value
            )[0]
        )
        assert c.estimate is not None or (c.verdict == "cannot be judged" and c.why)
        if c.estimate is not None:
            assert c.holds_when == "below" and c.statistic and c.unit
    t3 = {c.reading: c for c in claims if c.claim.endswith("(Table 3)")}
    assert len(t3) == 9
    for c in t3.values():  # the paper's bound, on Table 3's 3 rows: exact, and says so
        assert c.boundary == gyro.fact("claimed_accuracy") and c.rule == "exact"
        assert any("3 rows" in d for d in c.decided_by)
    e = gyro.table3_identification(CLAIMS).errors
    assert t3["input in arcmin, goal as MSE"].estimate.value == pytest.approx(
        np.max(np.abs(e["err our RBF"]))
    )
    assert t3["input in arcmin, goal as MSE"].reproduced is True
    assert t3["input in deg, goal as MSE"].reproduced is False
    assert _by_key(claims)["gyro_cold_accuracy"].basis == "no statistic"


def test_table3_output_claims_take_their_boundary_from_the_printed_precision(claims):
    k = _by_key(claims)
    dec = gyro.printed_decimals(3, "paper_rbf_drift_deg_h")
    out = gyro.table3_identification(CLAIMS).outputs
    for unit in ("arcmin", "deg"):
        c = k[f"gyro_t3_outputs_{unit}"]
        assert c.boundary == pytest.approx(0.5 * 10.0 ** -dec.min())  # not a tolerance of ours
        assert c.rule == "exact" and any("3 rows" in d for d in c.decided_by)
        # the floor (latitudes' rounding) is given and is what the rounding study says
        assert c.floor is not None and c.floor.value == pytest.approx(
            gyro.latitude_rounding_effect(CLAIMS, unit)
        )
    ours = out["our RBF"].to_numpy()
    assert k["gyro_t3_outputs_arcmin"].estimate.value == pytest.approx(
        np.max(np.abs(ours - out["paper RBF"]))
    )
    assert (
        k["gyro_t3_outputs_arcmin"].reproduced is True
        and k["gyro_t3_outputs_deg"].reproduced is False
    )


def test_leave_one_out_claims_bootstrap_the_rows(claims):
    k = _by_key(claims)
    for unit in ("arcmin", "deg"):
        c = k[f"gyro_loo_accuracy_{unit}"]
        x2, y2 = _t2()
        hot = gyro.HotNetSettings(input_unit=unit)
        e = y2 - np.array(
            [
                gyro.design_hot_net(np.delete(x2, i), np.delete(y2, i), hot).predict([x2[i]])[0]
                for i in range(16)
            ]
        )
        ref = verdicts.bootstrap(
            [e],
            lambda v: np.sqrt(np.mean(v**2)),
            seed=gyro.bootstrap_seed(CLAIMS.sim.seed, f"loo_{unit}"),
        )
        assert c.rule == "bootstrap over rows" and c.estimate.n == 16
        assert c.interval == pytest.approx(ref.interval) and c.estimate.value == pytest.approx(
            ref.value
        )
        assert c.boundary == gyro.fact("claimed_accuracy")
    assert k["gyro_loo_accuracy_deg"].reproduced is True


def test_comparisons_are_paired_over_the_same_rows_or_runs(claims):
    k = _by_key(claims)
    seed = CLAIMS.sim.seed
    rms = lambda v: np.sqrt(np.mean(np.square(v)))  # noqa: E731
    # simulated Table 5: the median paired difference over the same runs, cold - hot (claim holds below 0)
    runs = gyro.table5_simulation(CLAIMS).runs
    c = k["gyro_cold_beats_hot_sim"]
    ref = verdicts.paired_difference(runs["cold net (nmi)"], runs["hot net (nmi)"])
    assert c.rule == "paired difference" and c.interval == pytest.approx(ref.interval)
    assert (c.boundary, c.holds_when) == (0.0, "below")
    # the pairing matters: unpaired (the hot runs shuffled) the interval differs
    shuffled = verdicts.paired_difference(
        runs["cold net (nmi)"], runs["hot net (nmi)"].to_numpy()[::-1]
    )
    assert shuffled.interval != pytest.approx(c.interval)
    # real tables: a bootstrap that resamples the rows of both methods together
    for key, frame, a, b, name in (
        (
            "gyro_cold_beats_hot_table4",
            gyro.cold_leave_one_out(CLAIMS).rows,
            "err cold net",
            "err hot net",
            "table4_cold_vs_hot",
        ),
        (
            "gyro_nonlinear",
            gyro.hot_leave_one_out(CLAIMS).rows,
            "err our RBF",
            "err straight line",
            "nonlinear",
        ),
    ):
        c = k[key]
        ref = verdicts.bootstrap(
            [frame[a], frame[b]], lambda x, y: rms(x) - rms(y), seed=gyro.bootstrap_seed(seed, name)
        )
        unpaired = verdicts.bootstrap(
            [frame[a], frame[b]],
            lambda x, y: rms(x) - rms(y),
            seed=gyro.bootstrap_seed(seed, name),
            paired=False,
        )
        assert c.rule == "bootstrap over rows" and c.interval == pytest.approx(ref.interval)
        assert c.interval != pytest.approx(unpaired.interval)
        assert c.estimate.value == pytest.approx(rms(frame[a]) - rms(frame[b]))
        assert (c.boundary, c.holds_when) == (0.0, "below")
        assert c.reproduced is False  # the claimed method's error is the larger


def test_range_and_position_claims(claims):
    k = _by_key(claims)
    # the hot net's Table 4 miss: the RMS's distance outside the printed range, below 0 inside
    c = k["gyro_cold_hot_miss"]
    lo, hi = gyro.fact("cold_hot_net_drift_error_min"), gyro.fact("cold_hot_net_drift_error_max")
    e = gyro.table4_hot_net(CLAIMS)["err ours"].to_numpy()
    r = np.sqrt(np.mean(e**2))
    assert c.estimate.value == pytest.approx(max(lo - r, r - hi))
    assert (c.boundary, c.holds_when, c.rule) == (0.0, "below", "bootstrap over rows")
    # position after identification: median over the simulated runs, with the best compensation as floor
    c = k["gyro_position_after"]
    runs = gyro.fig3_position_errors(CLAIMS).runs
    assert c.interval == pytest.approx(verdicts.median_ci(runs["after_nmi"]).interval)
    assert c.boundary == gyro.fact("position_goal") and c.holds_when == "below"
    assert c.floor is not None and c.floor.value == pytest.approx(np.median(runs["best_nmi"]))
    assert c.floor.value <= c.estimate.value


def test_claims_need_enough_runs_for_their_intervals():
    with pytest.raises(InputError, match="at least 6 runs"):
        gyro.claims(FAST)


def test_methods_summary():
    m = gyro.methods_summary(P)
    loo = gyro.hot_leave_one_out(P).summary.set_index("method")
    assert m["our RBF, input in arcmin (LOO)"]["median_rms"] == pytest.approx(
        loo.loc["our RBF (LOO)", "RMS (deg/h)"]
    )
    assert m["straight line (LOO)"]["n_seeds"] == 1
    for stats in m.values():
        assert stats["median_min"] <= 0 <= stats["median_max"]
        assert stats["median_rms"] <= max(-stats["median_min"], stats["median_max"])
    assert len(m) == 4
    assert pd.notna(m["our RBF, input in deg (LOO)"]["median_rms"])


# ---------------------------------------------------------- hot-state readings, stored claims, thermal worlds
@pytest.fixture(scope="module")
def small_study():
    return gyro.cold_thermal_study(SMALL)


def test_new_claims_one_verdict_each(small_study):
    cl = gyro.cold_world_claims(SMALL) + gyro.reading_claims(SMALL)
    keys = [c.key for c in cl]
    assert len(keys) == len(set(keys))
    assert {
        "gyro_cold_world0_z",
        "gyro_cold_world0_raw",
        "gyro_cold_world1_pos",
        "gyro_required_needed",
        "gyro_cold_hot_miss_rows",
        "gyro_t3_outputs_arcmin_mse_gauss",
        "gyro_t3_outputs_arcmin_rss",
    } <= set(keys)
    assert all(c.verdict in ("reproduced", "not reproduced", "cannot be judged") for c in cl)
    rows = {c.key: c for c in cl}
    t4 = gyro.table4_hot_net(SMALL)
    e = np.abs(t4["err ours"].to_numpy())
    lo, hi = gyro.fact("cold_hot_net_drift_error_min"), gyro.fact("cold_hot_net_drift_error_max")
    assert rows["gyro_cold_hot_miss_rows"].estimate.value == np.sum((e < lo) | (e > hi))


# ------------------------------------------------------------------------ register entries C10, C11, C13, C15
def _raw(name):
    return pd.read_csv(data_path(name))


def test_register_claims_by_hand(claims):
    k = _by_key(claims)
    gain = _unit_position_gain(CLAIMS)
    lim = gyro.fact("claimed_accuracy")
    t3, t5, t2 = (
        _raw("gyro_table3_hot_test.csv"),
        _raw("gyro_table5_cold_test.csv"),
        _raw("gyro_table2_hot_train.csv"),
    )
    # C10: the largest cold-net position error over the gain, against the claimed accuracy
    c = k["gyro_cold_accuracy_table5"]
    assert c.rule == "exact" and c.boundary == lim
    assert c.estimate.value == pytest.approx(t5["paper_pos_error_cold_net_nmi_72h"].max() / gain)
    assert any("whole position error" in d for d in c.decided_by)
    other = max(t3["paper_pos_error_after_nmi_72h"] - gain * t3["paper_error_deg_h"].abs())
    assert k["gyro_cold_accuracy_table5_less_other"].estimate.value == pytest.approx(
        (t5["paper_pos_error_cold_net_nmi_72h"].max() - other) / gain
    )
    assert c.verdict == "not reproduced"  # 0.0005 deg/h implied, above 0.0003
    assert k["gyro_cold_accuracy"].basis == "no statistic"  # the row as printed is unchanged
    # C11: largest relative gap, boundary from the printed precision, floor from Table 3's other errors
    c = k["gyro_t3_before"]
    gap = (t3["paper_pos_error_before_nmi_72h"] - gain * t3["true_drift_deg_h"].abs()).abs() / t3[
        "paper_pos_error_before_nmi_72h"
    ]
    assert c.estimate.value == pytest.approx(gap.max()) and c.rule == "exact"
    assert c.floor.value == pytest.approx(other / t3["paper_pos_error_before_nmi_72h"].min())
    assert c.verdict == "not reproduced"
    g2 = gyro.fact("position_goal") / gyro.fact("required_accuracy")
    gap2 = (t3["paper_pos_error_before_nmi_72h"] - g2 * t3["true_drift_deg_h"].abs()).abs() / t3[
        "paper_pos_error_before_nmi_72h"
    ]
    assert k["gyro_t3_before_paper_gain"].estimate.value == pytest.approx(gap2.max())
    # C15: the largest printed span against 3 C
    span = t2["temperature_max_c"] - t2["temperature_min_c"]
    c = k["gyro_hot_temp_change"]
    assert c.boundary == gyro.fact("hot_state_max_temp_change") and c.estimate.value == span.max()
    assert c.verdict == "not reproduced"
    assert k["gyro_hot_temp_change_no_widest"].estimate.value == span.sort_values().iloc[-2]
    assert (
        k["gyro_hot_temp_change_t3"].estimate.value
        == (t3["temperature_max_c"] - t3["temperature_min_c"]).max()
    )
    # C13: against half a unit of Table 3's printed decimal
    br = gyro.basis_readings(CLAIMS).set_index("basis")
    c = k["gyro_basis_outputs"]
    assert c.boundary == pytest.approx(
        0.5 * 10.0 ** -gyro.printed_decimals(3, "paper_rbf_drift_deg_h").min()
    )
    assert c.estimate.value == pytest.approx(br["max |output - Gaussian| (deg/h)"].max())
    w = gyro.width_readings(CLAIMS).set_index("width")
    cols = [f"T3 #{i} (deg/h)" for i in (1, 2, 3)]
    assert k["gyro_basis_width"].estimate.value == pytest.approx(
        np.max(
            np.abs(w.loc["gaussian", cols].to_numpy(float) - w.loc["matlab", cols].to_numpy(float))
        )
    )


def test_register_claims_fold_into_their_entries(claims):
    from navlib import claims as reg

    recs = {r["id"]: r for r in reg.evaluate("gyro", [c.record() for c in claims])}
    for cid, key in (
        ("C10", "gyro_cold_accuracy_table5"),
        ("C11", "gyro_t3_before"),
        ("C13", "gyro_basis_outputs"),
        ("C15", "gyro_hot_temp_change"),
    ):
        assert recs[cid]["status"] == "judged" and recs[cid]["key"] == key, cid
        assert recs[cid]["rule"] == "exact" and recs[cid]["verdict"] == _by_key(claims)[key].verdict
