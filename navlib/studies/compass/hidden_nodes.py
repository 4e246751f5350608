"""Paper A's hidden-node count: "six hidden nodes suffice" (A16) and "too few hidden nodes generalise poorly,
too many overfit" (A17), judged on MATLAB's BP (the chapter's ``bp_matlab``: tansig, ``mapminmax``,
Nguyen-Widrow weights, ``trainlm``; the final training stage of reading 4) over a grid of hidden-node counts M,
the chapter's seeds and sweeps (sweep 1 trains, sweep 2 tests).

ADE-BP per M (reading 4) is not run: its DE stage (95 x 3000 network fitnesses per run) costs the chapter's
whole time budget per M; MATLAB's BP per M costs a few seconds in all (:func:`hidden_node_study`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from ... import verdicts
from ...claims import Claim, load_register
from ...errors import InputError, check_param
from ...methods.compass_methods import R3, MethodParams
from ...seeding import sequence
from .sweeps import TRAINING_ONLY, Sweeps, paired_seed_difference
from .turntable import seed_studies

#: Paper A's M = 6 (Sec. 1.1), the methods' default network size; every claim compares against it.
HIDDEN_REF = MethodParams().n_hidden
#: The hidden-node counts M of the study, fixed before the runs: 2, 3, 4 below the paper's 6 (a 1-M-1 net
#: bends its output once per tansig unit, and the heading error has a 1st and a 2nd harmonic, so the capacity
#: runs out among these), 8 and 12 above it, and 20 (61 weights on 121 training readings: the size at which a
#: net with no validation stop has the most freedom to fit the training sweep's noise), about evenly spaced on
#: a log scale.
HIDDEN_GRID = (2, 3, 4, 6, 8, 12, 20)
#: A17's "too few" and "too many": the ends of :data:`HIDDEN_GRID`.
FEW, MANY = HIDDEN_GRID[0], HIDDEN_GRID[-1]
#: Entropy of the bootstrap of the worst-case rows (spawn key: 0 the larger M, 1 every other M).
BOOTSTRAP_ENTROPY = 16
#: What the rows' verdicts rest on.
_HOW = (
    "MATLAB's BP (tansig, mapminmax, Nguyen-Widrow, trainlm without the validation stop), the final "
    "training stage of reading 4; ADE-BP per M not run (cost)"
)


def hidden_node_study(
    sw: Sweeps,
    params: MethodParams = MethodParams(),
    runs: pd.DataFrame | None = None,
    grid=HIDDEN_GRID,
    seeds=range(20),
    method: str = "bp_matlab",
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """``method`` (default MATLAB's BP) with each hidden-node count M of ``grid``, the chapter's ``params``
    otherwise, trained on sweep 1 and scored on sweep 2 over ``seeds`` (run ``k`` draws from generator ``k``,
    as in :func:`~navlib.studies.compass.turntable.seed_study`, so the runs of one seed pair across M).  The
    runs of the chapter's own M (``params.n_hidden``) are taken from ``runs`` (its seed study) when it holds
    them, not trained again.  One row per (``n_hidden``, seed) with the seed study's columns (``rms_deg``,
    ``min_deg``, ``max_deg``, ``epochs``, ``stop``, ...)."""
    grid = [int(m) for m in grid]
    for m in grid:
        check_param("hidden-node count", m, lo=1, integer=True)
    if len(set(grid)) != len(grid):
        raise InputError(f"hidden_node_study: grid {grid} repeats a count")
    seeds = [int(s) for s in seeds]
    own = None
    if runs is not None and params.n_hidden in grid:
        own = runs[(runs.method == method) & runs.seed.isin(seeds)]
        if sorted(own.seed) != sorted(seeds):
            own = None
    todo = [m for m in grid if own is None or m != params.n_hidden]
    frames = seed_studies(
        [(sw, replace(params, n_hidden=m), seeds, (method,)) for m in todo],
        workers=workers,
        scheduler=scheduler,
    )
    by = dict(zip(todo, frames))
    if own is not None:
        by[params.n_hidden] = own
    cols = ["method", "label", "seed", "min_deg", "max_deg", "rms_deg", "epochs", "stop"]
    return pd.concat([by[m][cols].assign(n_hidden=m) for m in grid], ignore_index=True).sort_values(
        ["n_hidden", "seed"], kind="stable", ignore_index=True
    )


def _by_seed(nodes: pd.DataFrame, m: int) -> pd.Series:
    g = nodes[nodes.n_hidden == m]
    if g.empty:
        raise InputError(f"hidden-node study: no runs with M = {m}")
    return pd.Series(g.rms_deg.to_numpy(float), index=g.seed.to_numpy(int), name=f"M={m}")


def hidden_node_table(nodes: pd.DataFrame, ref: int = HIDDEN_REF) -> pd.DataFrame:
    """Per hidden-node count M of :func:`hidden_node_study` ``nodes``: runs, the test RMS over the seeds
    (median, 10th and 90th percentiles, deg), the median paired difference RMS(M) - RMS(``ref``) over the
    same seeds (deg), and the median number of ``trainlm`` epochs."""
    r0 = _by_seed(nodes, ref)
    rows = []
    for m, g in nodes.groupby("n_hidden", sort=True):
        r = _by_seed(nodes, m)
        common = r.index.intersection(r0.index)
        rows.append(
            {
                "M": int(m),
                "runs": len(g),
                "median test rms (deg)": g.rms_deg.median(),
                "p10": g.rms_deg.quantile(0.1),
                "p90": g.rms_deg.quantile(0.9),
                f"rms(M) - rms({ref}), median paired (deg)": float(
                    np.median(r.loc[common] - r0.loc[common])
                ),
                "median epochs": g.epochs.median(),
            }
        )
    return pd.DataFrame(rows).set_index("M")


def _worst_case(r0: pd.Series, others: dict[int, pd.Series], key: int) -> verdicts.Estimate:
    """max over M of the median paired difference RMS(ref) - RMS(M), with a percentile bootstrap over the
    seeds (the rows of one seed resampled together)."""
    seeds = r0.index
    for m, r in others.items():
        if not r.index.equals(seeds):
            raise InputError(f"hidden-node study: M = {m} was not run on the same seeds")
    cols = [r0.to_numpy(float)] + [r.to_numpy(float) for r in others.values()]

    def worst(a, *bs):
        return float(max(np.median(a - b) for b in bs))

    return verdicts.bootstrap(cols, worst, seed=sequence(BOOTSTRAP_ENTROPY, key))


def hidden_node_claims(
    nodes: pd.DataFrame, ref: int = HIDDEN_REF, few: int = FEW, many: int = MANY
) -> list[Claim]:
    """A16 and A17 from :func:`hidden_node_study` ``nodes`` (reading 3, MATLAB's BP), paired by seed:

    - A16, "six hidden nodes suffice" (holds below 0; the register's equivalence margin makes a difference
      within the paper's printed precision *no difference*): the worst case over the larger M of the median
      paired difference RMS(``ref``) - RMS(M) (percentile bootstrap over the seeds), the same over every other
      M of the grid, and RMS(``ref``) - RMS(M) for each larger M (order-statistic interval);
    - A17, "too few generalise poorly, too many overfit" (test side only; holds above 0): RMS(``few``) -
      RMS(``ref``) and RMS(``many``) - RMS(``ref``).

    Each row carries its entry's equivalence margin from the register (paper A's printed precision), so the
    chapter's tables and prose show the verdict the results file records."""
    grid = sorted(int(m) for m in set(nodes.n_hidden))
    for m in (ref, few, many):
        if m not in grid:
            raise InputError(f"hidden_node_claims: no runs with M = {m} (grid {grid})")
    r = {m: _by_seed(nodes, m) for m in grid}
    larger = [m for m in grid if m > ref]
    other = [m for m in grid if m != ref]
    if not larger:
        raise InputError(f"hidden_node_claims: the grid {grid} has no M above {ref}")
    dec = (_HOW, TRAINING_ONLY)
    margins = {e.id: e.margin for e in load_register("paper_a")}
    med = {m: float(r[m].median()) for m in grid}

    def ours(ms):
        return "median test RMS " + ", ".join(f"M={m}: {med[m]:.3f}" for m in ms) + " deg"

    def listed(ms):
        return ", ".join(map(str, ms))

    out = []
    for key, ms, text in (
        (0, larger, f"M = {ref} no worse than more hidden nodes (worst of M = {listed(larger)})"),
        (1, other, f"M = {ref} no worse than any other M (worst of M = {listed(other)})"),
    ):
        est, short = verdicts.attempt(_worst_case, r[ref], {m: r[m] for m in ms}, key)
        out.append(
            Claim(
                text,
                f"M = {ref} chosen from simulation results and training accuracy",
                reading=R3,
                source="paper",
                statistic=f"max over M in {{{listed(ms)}}} of the median paired difference test RMS(M = "
                f"{ref}) - test RMS(M), paired by seed (bootstrap over seeds), deg",
                estimate=est,
                boundary=0.0,
                holds_when="below",
                unit="deg",
                spec="{:.4f}",
                margin=margins.get("A16"),
                decided_by=dec,
                why=short,
                ours=ours([ref, *ms]),
                key=f"a_nodes_worst_{'larger' if key == 0 else 'all'}",
            )
        )
    for m in larger:
        est, short = verdicts.attempt(paired_seed_difference, r[ref], r[m])
        out.append(
            Claim(
                f"M = {ref} no worse than M = {m}",
                f"M = {ref} chosen from simulation results and training accuracy",
                reading=R3,
                source="paper",
                statistic=f"test RMS(M = {ref}) - test RMS(M = {m}), paired by seed, deg",
                estimate=est,
                boundary=0.0,
                holds_when="below",
                unit="deg",
                spec="{:.4f}",
                margin=margins.get("A16"),
                decided_by=dec,
                why=short,
                ours=ours([ref, m]),
                key=f"a_nodes_six_vs_{m}",
            )
        )
    for m, half, k in (
        (few, "too few hidden nodes: poor recognition of unlearned samples", "few"),
        (many, "too many hidden nodes: overfitting", "many"),
    ):
        est, short = verdicts.attempt(paired_seed_difference, r[m], r[ref])
        out.append(
            Claim(
                f"M = {m} generalises worse than M = {ref}",
                half,
                reading=R3,
                source="paper",
                statistic=f"test RMS(M = {m}) - test RMS(M = {ref}), paired by seed, deg",
                estimate=est,
                boundary=0.0,
                holds_when="above",
                unit="deg",
                spec="{:.4f}",
                margin=margins.get("A17"),
                decided_by=dec,
                why=short,
                ours=ours([m, ref]),
                key=f"a_nodes_{k}",
            )
        )
    return out
