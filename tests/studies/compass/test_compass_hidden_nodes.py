"""Tests for paper A's hidden-node claims (A16 "six hidden nodes suffice", A17 "too few generalise poorly,
too many overfit"): constructed per-seed test RMS where the answer is known, and the study's reuse of the
chapter's own M = 6 runs (the same seeds, the same numbers as training them again)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from navlib.claims import load_register
from navlib.data.compass_sweeps import load_sweeps, split_sweeps
from navlib.errors import InputError
from navlib.paths import data_path
from navlib.studies.compass import R3, StudyParams, Sweeps, seed_study
from navlib.studies.compass.hidden_nodes import (
    HIDDEN_GRID,
    hidden_node_claims,
    hidden_node_study,
    hidden_node_table,
)


def _nodes(rms_of_m, n_seeds=20):
    """A hidden-node frame: test RMS ``rms_of_m(m)`` plus a small per-seed wobble shared by every M (so the
    paired differences are exact)."""
    wobble = 0.002 * np.sin(np.arange(n_seeds))
    return pd.DataFrame(
        [
            {"n_hidden": m, "seed": s, "rms_deg": rms_of_m(m) + wobble[s], "epochs": 10.0}
            for m in HIDDEN_GRID
            for s in range(n_seeds)
        ]
    )


def _by_claim(nodes):
    return {c.claim: c for c in hidden_node_claims(nodes)}


PRIMARY_16 = "M = 6 no worse than more hidden nodes (worst of M = 8, 12, 20)"
ALL_16 = "M = 6 no worse than any other M (worst of M = 2, 3, 4, 8, 12, 20)"
MANY_17 = "M = 20 generalises worse than M = 6"
FEW_17 = "M = 2 generalises worse than M = 6"


def test_the_rows_are_the_registers():
    reg = {e.id: e for e in load_register("paper_a")}
    texts = {c.claim for c in hidden_node_claims(_nodes(lambda m: 0.1))}
    assert set(reg["A16"].rows) | set(reg["A17"].rows) == texts
    assert reg["A16"].primary_claim == PRIMARY_16 and reg["A17"].primary_claim == MANY_17
    assert reg["A16"].primary_reading == reg["A17"].primary_reading == R3


def test_a_u_shaped_curve_suffices_at_six_and_shows_both_halves():
    """Test RMS falls to M = 6 and rises beyond it by 0.05 deg per step: six is better than every larger
    M (reproduced, beyond the margin), M = 2 and M = 20 generalise worse."""
    u = {2: 1.0, 3: 0.3, 4: 0.15, 6: 0.1, 8: 0.15, 12: 0.2, 20: 0.25}
    by = _by_claim(_nodes(u.get))
    worst = by[PRIMARY_16]
    assert worst.rule == "bootstrap over rows" and worst.holds_when == "below"
    assert worst.estimate.value == pytest.approx(
        -0.05
    )  # the worst larger M is 8, the closest to six
    assert worst.verdict == "reproduced" and worst.margin == pytest.approx(0.01)
    assert by[ALL_16].estimate.value == pytest.approx(-0.05)
    assert by["M = 6 no worse than M = 20"].estimate.value == pytest.approx(-0.15)
    assert by[MANY_17].estimate.value == pytest.approx(0.15) and by[MANY_17].verdict == "reproduced"
    assert by[FEW_17].estimate.value == pytest.approx(0.9) and by[FEW_17].verdict == "reproduced"


def test_a_larger_net_that_does_better_refutes_six_suffice():
    """M = 12 beats six by 0.05 deg, every other larger M is worse: the worst case is M = 12's, and six do
    not suffice; nor does M = 20 overfit if it too beats six."""
    v = {2: 1.0, 3: 0.3, 4: 0.15, 6: 0.1, 8: 0.12, 12: 0.05, 20: 0.08}
    by = _by_claim(_nodes(v.get))
    assert by[PRIMARY_16].estimate.value == pytest.approx(0.05)
    assert by[PRIMARY_16].verdict == "not reproduced"
    assert by[MANY_17].verdict == "not reproduced"


def test_a_flat_curve_beyond_six_is_no_difference_at_the_margin():
    """Larger M within 0.003 deg of six: within the paper's printed precision, *no difference*; a smaller M
    that does better does not enter the primary (six would be more than enough, not too few)."""
    flat = {2: 0.09, 3: 0.1, 4: 0.1, 6: 0.1, 8: 0.101, 12: 0.099, 20: 0.103}
    by = _by_claim(_nodes(flat.get))
    assert by[PRIMARY_16].verdict == "no difference"
    assert by[PRIMARY_16].estimate.value == pytest.approx(0.001)
    assert by[ALL_16].estimate.value == pytest.approx(0.01)  # M = 2 is 0.01 deg better
    assert by[MANY_17].verdict == "no difference"


def test_too_few_seeds_leave_no_interval_and_a_missing_count_is_refused():
    by = _by_claim(_nodes(lambda m: 0.1 + 0.01 * m, n_seeds=4))
    assert by[MANY_17].estimate is None and by[MANY_17].verdict == "cannot be judged"
    nodes = _nodes(lambda m: 0.1)
    with pytest.raises(InputError, match="M = 20"):
        hidden_node_claims(nodes[nodes.n_hidden != 20])


def test_the_table_pairs_by_seed():
    u = {2: 1.0, 3: 0.3, 4: 0.15, 6: 0.1, 8: 0.15, 12: 0.2, 20: 0.25}
    t = hidden_node_table(_nodes(u.get))
    col = "rms(M) - rms(6), median paired (deg)"
    assert list(t.index) == list(HIDDEN_GRID) and (t.runs == 20).all()
    assert t.loc[20, col] == pytest.approx(0.15) and t.loc[6, col] == 0


def test_the_study_reuses_the_chapters_runs_at_six_and_pairs_the_seeds():
    """The M = 6 rows taken from the chapter's seed study are those training M = 6 again gives (run k
    draws from generator k at every M)."""
    sw = Sweeps(*split_sweeps(load_sweeps(data_path("compass_sweeps.csv"))))
    p = StudyParams()
    runs = seed_study(sw, p, seeds=range(2), methods=("bp_matlab",))
    reused = hidden_node_study(sw, p, runs, grid=(3, 6), seeds=range(2))
    fresh = hidden_node_study(sw, p, None, grid=(3, 6), seeds=range(2))
    assert list(reused.n_hidden) == [3, 3, 6, 6] and list(reused.seed) == [0, 1, 0, 1]
    pd.testing.assert_frame_equal(reused, fresh)
    six = reused[reused.n_hidden == 6].rms_deg.to_numpy()
    assert np.array_equal(six, runs.rms_deg.to_numpy())
    assert not np.allclose(reused[reused.n_hidden == 3].rms_deg.to_numpy(), six)
    with pytest.raises(InputError, match="repeats"):
        hidden_node_study(sw, p, runs, grid=(6, 6), seeds=range(2))
