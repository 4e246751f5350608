"""Tests for document B's node-count claims (B16 each added node lowers the error, B18 the node count's
influence): :mod:`navlib.studies.compass.elm_nodes`."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from navlib.claims import load_register
from navlib.data.compass_sweeps import load_sweeps, split_sweeps
from navlib.errors import InputError
from navlib.paths import data_path
from navlib.studies.compass import StudyParams, Sweeps
from navlib.studies.compass import elm_nodes as en
from navlib.studies.compass.elm_patent import node_count_curve

N_SEEDS, MAX_NODES = 20, 6


def _curve(rms_by_seed: dict[int, list[float]], method: str, prunes=None) -> pd.DataFrame:
    rows = []
    for seed, rms in rms_by_seed.items():
        for k, r in enumerate(rms, start=1):
            p = 0 if prunes is None else prunes[seed][k - 1]
            rows.append((method, seed, k, r, r, p))
    cols = ["method", "seed", "n_nodes", "train_rms_deg", "test_rms_deg", "prunes"]
    return pd.DataFrame(rows, columns=cols)


def _falling(first: float = 10.0, last: float = 0.1) -> list[float]:
    return list(np.geomspace(first, last, MAX_NODES))


def _both(bt: dict, plain: dict | None = None, prunes=None) -> pd.DataFrame:
    plain = bt if plain is None else plain
    return pd.concat([_curve(bt, en.BACKTUNED, prunes), _curve(plain, en.PLAIN)], ignore_index=True)


def _by_claim(claims):
    return {c.claim: c for c in claims}


def _order_row(curve, which="back-tuned scheme"):
    return _by_claim(en.node_claims(curve))[
        f"each added hidden node lowers the training RMS [{which}]"
    ]


def _effect_row(curve, which="plain ELM"):
    return _by_claim(en.node_claims(curve))[
        f"the hidden-node count strongly affects the training accuracy [{which}]"
    ]


def test_node_steps_are_the_changes_between_consecutive_counts():
    c = _curve({0: [4.0, 2.0, 3.0, 1.0], 1: [5.0, 4.0, 4.5, 4.0]}, en.BACKTUNED)
    c = c[~((c.seed == 1) & (c.n_nodes == 3))]  # seed 1 has no 3-node row: 2 -> 4 is no step
    s = en.node_steps(c)
    got = {(r.seed, r.k): r.change_deg for r in s.itertuples()}
    assert got == {(0, 1): -2.0, (0, 2): 1.0, (0, 3): -2.0, (1, 1): -1.0}
    assert not s.pruned.any()


def test_every_step_falling_reproduces_b16_and_one_rise_in_many_seeds_refutes_it():
    falling = {s: _falling() for s in range(N_SEEDS)}
    row = _order_row(_both(falling))
    assert row.verdict == "reproduced" and row.estimate.hi < 0
    # a rise of 0.5 deg at one step in half of the runs: the worst step is far above 0
    risen = {
        s: (_falling()[:3] + [_falling()[2] + 0.5] + _falling()[4:]) if s % 2 else _falling()
        for s in range(N_SEEDS)
    }
    row = _order_row(_both(risen))
    assert row.verdict == "not reproduced" and row.estimate.lo > 0
    assert row.estimate.value == pytest.approx(0.5, rel=1e-9)
    assert row.ours.startswith(f"{N_SEEDS // 2} of {N_SEEDS * (MAX_NODES - 1)} steps rose")


def test_a_rise_in_one_run_of_twenty_is_not_enough_for_a_verdict():
    # the bootstrap over seeds leaves the one rising run out often enough: the interval straddles 0
    runs = {s: _falling() for s in range(N_SEEDS)}
    runs[7] = _falling()[:2] + [_falling()[1] + 0.2] + _falling()[3:]
    row = _order_row(_both(runs))
    assert row.estimate.lo < 0 < row.estimate.hi and row.verdict == "cannot be judged"


def test_changes_within_the_registers_margin_are_no_change():
    margin = {e.id: e.margin for e in load_register("patent_b")}["B16"]
    assert margin and margin > 0
    flat = {s: [1.0] * MAX_NODES for s in range(N_SEEDS)}
    flat[3] = [1.0, 1.0, 1.0 + margin / 10, 1.0, 1.0, 1.0]
    assert _order_row(_both(flat)).verdict == "no difference"


def test_a_rise_across_a_prune_stage_is_reported_apart():
    runs = {s: _falling() for s in range(N_SEEDS)}
    prunes = {s: [0] * MAX_NODES for s in range(N_SEEDS)}
    for s in range(0, N_SEEDS, 2):  # half the runs rise by 1 deg at 3 -> 4 nodes, over a prune
        runs[s] = _falling()[:3] + [_falling()[2] + 1.0] + _falling()[4:]
        prunes[s] = [0, 0, 0, 1, 1, 1]
    row = _order_row(_both(runs, prunes=prunes))
    assert row.verdict == "reproduced"
    assert "10 steps span a prune stage" in row.why and "+1" in row.why
    # the same rises without the prune stage refute the claim
    assert _order_row(_both(runs)).verdict == "not reproduced"


def test_b18_ratio_against_its_boundary():
    strong = {s: _falling(10.0, 0.1) for s in range(N_SEEDS)}
    row = _effect_row(_both(strong))
    assert row.verdict == "reproduced" and row.estimate.value == pytest.approx(100.0)
    weak = {s: _falling(0.15, 0.1) for s in range(N_SEEDS)}
    row = _effect_row(_both(weak))
    assert row.verdict == "not reproduced" and row.estimate.value == pytest.approx(1.5)
    assert row.boundary == en.LARGE_RATIO
    # the ratio is to the smallest RMS over the counts, wherever it falls
    dip = {s: [4.0, 1.0, 2.0, 2.0, 2.0, 2.0] for s in range(N_SEEDS)}
    assert en.one_node_ratio(_both(dip)).eq(4.0).all()


def test_broken_curves_are_refused():
    c = _both({s: _falling() for s in range(3)})
    with pytest.raises(InputError, match="repeats"):
        en.node_steps(pd.concat([c, c.iloc[:1]]))
    with pytest.raises(InputError, match="no rows of method"):
        en.node_steps(c[c.method == en.PLAIN])
    with pytest.raises(InputError, match="one-node"):
        en.one_node_ratio(c[c.n_nodes > 1])
    zero = c.copy()
    zero.loc[zero.n_nodes == MAX_NODES, "train_rms_deg"] = 0.0
    with pytest.raises(InputError, match="zero training RMS"):
        en.one_node_ratio(zero)
    # too few runs for a 95 % interval of B18's median: no statistic, and the row says why
    row = _effect_row(c)
    assert row.estimate is None and "no 95 % interval" in row.why


@pytest.fixture(scope="module")
def sw():
    return Sweeps(*split_sweeps(load_sweeps(data_path("compass_sweeps.csv"))))


def test_the_curve_counts_prune_stages_and_the_steps_flag_them(sw):
    # a pruning tolerance far above any output weight's size prunes at every ELM solve
    c = node_count_curve(sw, replace(StudyParams(), elm_prune_tol=1e3), seeds=[0], max_nodes=4)
    bt = c[c.method == en.BACKTUNED]
    assert (bt.prunes > 0).any()
    c0 = node_count_curve(sw, StudyParams(), seeds=[0, 1], max_nodes=8)
    assert (c0[c0.method == en.PLAIN].prunes == 0).all()
    for _, g in c0[c0.method == en.BACKTUNED].groupby("seed"):
        assert g.sort_values("n_nodes").prunes.is_monotonic_increasing
    s = en.node_steps(c0)
    assert set(s.k) == set(range(1, 8)) and len(s) == 2 * 7


def test_the_register_names_the_rows_the_code_writes():
    curve = _both({s: _falling() for s in range(N_SEEDS)})
    written = {c.claim for c in en.node_claims(curve)}
    reg = {e.id: e for e in load_register("patent_b")}
    for eid in ("B16", "B18"):
        e = reg[eid]
        assert e.status == "judged" and e.primary_claim in e.rows
        assert set(e.rows) <= written
    assert set(reg["B16"].rows) | set(reg["B18"].rows) == written
    assert reg["B20"].status == "open"
