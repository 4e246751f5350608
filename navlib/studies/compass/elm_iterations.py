"""Document B's iteration claims: the back-tuned ELM against Huang's point-incremental ELM (I-ELM), and what
pruning small output weights does to the back-tuned ELM's iterations.

Patent B (description, Fig. 1 paragraph): the point-incremental ELM finds the node count by adding nodes;
"many of the k+1 hidden neurons have very small output weights ...; removing these 'useless' neurons greatly
reduces the incremental ELM's iterations" (register B10), and with back-tuning "this method both reduces the
number of iterations and guarantees the network's training accuracy" (B11).

How we count (fixed before running): one iteration of the back-tuned ELM is one ELM solve with its
back-tuning stage (the patent's fourth step: "train by ELM, back-tune, ... add 1 to the node count and to the
iteration count"), i.e. the ELM stages of :func:`navlib.methods.elm.fit_incremental_elm`'s history; one
iteration of the I-ELM is one node added (:func:`navlib.methods.ielm.fit_ielm`).  Both train on sweep 1 with
the chapter's normalisation, node draw (U(-elm_range, elm_range)) and goal (``elm_goal_deg`` training RMS);
with the same seed both draw the same random nodes in the same order.  The I-ELM's cap is the back-tuned
ELM's own k (``elm_max_iter`` / 2 ELM + tune pairs) and, as a sensitivity, ten times that; a run that does
not reach the goal is counted at its cap (censored) and flagged.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from ... import engine, verdicts
from ...claims import Claim, load_register
from ...methods.compass_methods import fit_method
from ...methods.compensator import NetworkCompensator, ScaledRegressor
from ...methods.ielm import IELMParams, first_nodes, fit_ielm
from ...methods.seeding import generators
from .parameters import StudyParams
from .sweeps import TRAINING_ONLY, Sweeps, paired_seed_difference, rms_deg

#: The runs of :func:`iteration_study`, per seed: the back-tuned ELM at the chapter's pruning tolerance,
#: without pruning, and pruning at the training goal; the I-ELM at the back-tuned ELM's cap and at ten times.
BT, BT_NO_PRUNE, BT_GOAL_PRUNE = (
    "back-tuned ELM",
    "back-tuned ELM, no pruning",
    "back-tuned ELM, pruning at the goal",
)
IELM_K, IELM_10K = "I-ELM, cap k", "I-ELM, cap 10 k"
RUNS = (BT, BT_NO_PRUNE, BT_GOAL_PRUNE, IELM_K, IELM_10K)
#: The sensitivity cap of the I-ELM, in multiples of the back-tuned ELM's k.
LONG_CAP_FACTOR = 10


def iteration_cap(params: StudyParams) -> int:
    """The back-tuned ELM's k in ELM + tune pairs (``elm_max_iter`` counts stages, two per pair)."""
    return max(1, int(params.elm_max_iter) // 2)


def prune_tolerances(params: StudyParams, span_deg: float) -> dict[str, float]:
    """The back-tuned runs' pruning tolerances (max ``|beta_j|`` of a pruned node, normalised output units):
    the chapter's (``elm_prune_tol``), none (0: only exact zeros), and the goal's, ``elm_goal_deg`` /
    ``span_deg``: since ``|g| <= 1``, the largest tolerance at which one pruned node moves the output by no
    more than the training goal."""
    return {
        BT: float(params.elm_prune_tol),
        BT_NO_PRUNE: 0.0,
        BT_GOAL_PRUNE: float(params.elm_goal_deg) / float(span_deg),
    }


def iteration_study(
    sw: Sweeps,
    params: StudyParams = StudyParams(),
    seeds=range(20),
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Iterations to the training goal of the runs in ``RUNS``, one row per (run, seed):
    ``iterations`` (counted as the module docstring says; at the cap when not reached), ``cap``,
    ``reached``, ``prune_tol`` (NaN for the I-ELM), ``train_rms_deg`` and ``test_rms_deg`` (sweep 2)
    at the stop, ``n_nodes``, ``prune_stages`` (ELM solves followed by a prune; 0 for the I-ELM) and
    ``min_abs_beta`` (the smallest output weight of the final net, normalised units).  Every seed is a task of
    :mod:`navlib.engine` (``workers``, ``scheduler``; the numbers do not depend on them)."""
    parts = engine.run(
        _iteration_seed,
        [(sw, params, int(s)) for s in seeds],
        workers=workers,
        scheduler=scheduler,
        label="ELM iterations",
    )
    return pd.DataFrame([r for part in parts for r in part])


def _iteration_seed(sw: Sweeps, params: StudyParams, seed: int) -> list[dict]:
    """The rows of :func:`iteration_study` for one seed (a task)."""
    target = params.target.target(sw.x_train, sw.t_train)
    span = float(np.ptp(target))
    k = iteration_cap(params)
    rows = []

    def row(run, comp, iterations, cap, reached, n_nodes, prune_stages, beta, tol=np.nan):
        return {
            "run": run,
            "seed": seed,
            "prune_tol": float(tol),
            "iterations": int(iterations),
            "cap": int(cap),
            "reached": bool(reached),
            "train_rms_deg": rms_deg(comp.correct(sw.x_train), sw.t_train),
            "test_rms_deg": rms_deg(comp.correct(sw.x_test), sw.t_test),
            "n_nodes": int(n_nodes),
            "prune_stages": int(prune_stages),
            "min_abs_beta": float(np.min(np.abs(beta))),
        }

    for run, tol in prune_tolerances(params, span).items():
        p = replace(params, elm_prune_tol=tol)
        comp = fit_method("elm_backtuned", sw.x_train, sw.t_train, p, [seed])[0]
        hist = comp.info["history"]
        goal = p.incremental_params(span).loss_goal
        net = comp.net.model
        rows.append(
            row(
                run,
                comp,
                (hist.stage == "elm").sum(),
                k,
                hist.loss.iloc[-1] <= goal,
                net.n_hidden,
                (hist.stage == "prune").sum(),
                net.beta,
                tol,
            )
        )
    long_cap = LONG_CAP_FACTOR * k
    goal = params.incremental_params(span).loss_goal
    ip = IELMParams(
        max_nodes=long_cap,
        loss_goal=goal,
        weight_range=params.elm_range,
        bias_range=params.elm_range,
    )
    rng = generators([seed])[0]
    reg = ScaledRegressor.fit(sw.x_train, target, lambda xn, tn: fit_ielm(xn, tn, ip, rng=rng)[0])
    full = reg.model
    for run, cap in ((IELM_K, k), (IELM_10K, long_cap)):
        model = first_nodes(full, min(cap, full.n_hidden))
        comp = NetworkCompensator(replace(reg, model=model), params.target)
        loss = model.loss(reg.x_scale.transform(sw.x_train), reg.t_scale.transform(target))
        rows.append(
            row(run, comp, model.n_hidden, cap, loss <= goal, model.n_hidden, 0, model.beta)
        )
    return rows


def iteration_summary(runs: pd.DataFrame) -> pd.DataFrame:
    """Per run of :func:`iteration_study`: median iterations (censored runs at their cap), the runs that
    reached the goal, median training and test RMS at the stop, how many runs pruned at all and the
    prune stages over all runs, the median smallest output weight."""
    g = runs.groupby("run", sort=False)
    return pd.DataFrame(
        {
            "iterations": g.iterations.median(),
            "cap": g.cap.first(),
            "reached": g.reached.sum().astype(int).astype(str) + " of " + g.size().astype(str),
            "train rms (deg)": g.train_rms_deg.median(),
            "test rms (deg)": g.test_rms_deg.median(),
            "runs that pruned": g.prune_stages.apply(lambda s: int((s > 0).sum())),
            "prune stages": g.prune_stages.sum(),
            "smallest |beta|": g.min_abs_beta.median(),
        }
    ).reindex([r for r in RUNS if r in set(runs.run)])


# ------------------------------------------------------------------------------------------------ claims
def _per_seed(runs: pd.DataFrame, run: str, col: str) -> pd.Series:
    part = runs[runs.run == run]
    return pd.Series(part[col].to_numpy(float), index=part.seed.to_numpy(int), name=f"{run} {col}")


def _paired(runs: pd.DataFrame, worse: str, better: str, col: str):
    """``col(worse) - col(better)`` paired by seed (median, 95 % interval), or None and why."""
    return verdicts.attempt(
        paired_seed_difference, _per_seed(runs, worse, col), _per_seed(runs, better, col)
    )


def _censoring(runs: pd.DataFrame, a: str, b: str, a_name: str, b_name: str) -> str:
    """How the pairs of runs ``a`` (the slower, called ``a_name``) and ``b`` are censored at their caps,
    in words."""
    ra = runs[runs.run == a].set_index("seed").reached
    rb = runs[runs.run == b].set_index("seed").reached.reindex(ra.index)
    only_a, both, only_b = int((~ra & rb).sum()), int((~ra & ~rb).sum()), int((ra & ~rb).sum())
    if only_a + both + only_b == 0:
        return "every run reached the goal"
    return (
        f"{only_a} of {len(ra)} pairs with only the {a_name} at its cap (the difference a lower "
        f"bound: biased against the claim), {both} with both at their caps (no bound either way), "
        f"{only_b} with only the {b_name} at its cap (an upper bound: biased for the claim)"
    )


def iteration_claims(runs: pd.DataFrame, params: StudyParams) -> list[Claim]:
    """Registers B10 and B11 from :func:`iteration_study` (reading ``'document B'``), paired by seed:

    - B11 "the back-tuned ELM needs fewer iterations than the point-incremental ELM": iterations of the
      I-ELM (at its cap when unreached) minus the back-tuned ELM's, boundary 0, holds above; at the
      back-tuned ELM's cap k (primary) and at 10 k; and "guarantees the training accuracy": test RMS of
      the I-ELM at its stop minus the back-tuned ELM's, deg, holds above;
    - B10 "pruning small output weights greatly reduces the iterations": iterations of the back-tuned ELM
      without pruning minus with it, at the chapter's tolerance (primary) and at the goal's, boundary 0,
      holds above; B10's equivalence margin is the register's (a row within it is *no difference*)."""
    r = "document B"
    margin = {e.id: e.margin for e in load_register("patent_b")}.get("B10")
    elm_set = (
        f"our a-priori ELM settings (goal {params.elm_goal_deg:g} deg training RMS, weights "
        f"U(-{params.elm_range:g}, {params.elm_range:g}), back-tuned ELM at most "
        f"{params.elm_max_nodes} nodes and k = {iteration_cap(params)} ELM + tune pairs)"
    )
    count = (
        "an iteration of the back-tuned ELM is one ELM solve with its back-tuning (the patent's "
        "fourth step); of the I-ELM one node added"
    )
    med = runs.groupby("run").iterations.median()
    out = []
    for ielm, cap_name, key in ((IELM_K, "k", "b_ielm"), (IELM_10K, "10 k", "b_ielm_10k")):
        cap = int(runs[runs.run == ielm].cap.iloc[0])
        est, short = _paired(runs, ielm, BT, "iterations")
        out.append(
            Claim(
                f"the back-tuned ELM needs fewer iterations than the I-ELM [I-ELM capped at "
                f"{cap_name}]",
                "fewer iterations than the incremental ELM (no numbers)",
                reading=r,
                statistic="iterations to the training goal of the I-ELM (at its cap when not "
                "reached) - of the back-tuned ELM, paired by seed",
                estimate=est,
                boundary=0.0,
                holds_when="above",
                unit="iterations",
                spec="{:.4g}",
                decided_by=(elm_set, count, f"the I-ELM's cap: {cap} iterations", TRAINING_ONLY),
                why="; ".join(
                    t for t in (short, _censoring(runs, ielm, BT, "I-ELM", "back-tuned ELM")) if t
                ),
                ours=f"{med[BT]:.0f} vs {med[ielm]:.0f} iterations (medians)",
                key=key,
            )
        )
    cap = int(runs[runs.run == IELM_K].cap.iloc[0])
    est, short = _paired(runs, IELM_K, BT, "test_rms_deg")
    t = runs.groupby("run").test_rms_deg.median()
    out.append(
        Claim(
            "the back-tuned ELM is no less accurate than the I-ELM at the stop (test RMS)",
            "guarantees the training accuracy (no numbers)",
            reading=r,
            statistic="test RMS of the I-ELM at its stop - of the back-tuned ELM at its stop, "
            "paired by seed, deg",
            estimate=est,
            boundary=0.0,
            holds_when="above",
            unit="deg",
            decided_by=(elm_set, f"the I-ELM's cap: {cap} iterations", TRAINING_ONLY),
            why="; ".join(
                t for t in (short, _censoring(runs, IELM_K, BT, "I-ELM", "back-tuned ELM")) if t
            ),
            ours=f"{t[BT]:.3f} vs {t[IELM_K]:.3f} deg rms (medians)",
            key="b_ielm_accuracy",
        )
    )
    for run, name, key in (
        (BT, "the chapter's", "b_prune"),
        (BT_GOAL_PRUNE, "the goal's", "b_prune_goal"),
    ):
        est, short = _paired(runs, BT_NO_PRUNE, run, "iterations")
        part = runs[runs.run == run]
        tol = float(part.prune_tol.iloc[0])
        fired = int((part.prune_stages > 0).sum())
        out.append(
            Claim(
                f"pruning small output weights reduces the back-tuned ELM's iterations "
                f"[{name} tolerance]",
                "greatly reduces the incremental ELM's iterations (no numbers)",
                reading=r,
                statistic="iterations to the training goal of the back-tuned ELM without pruning - "
                "with it, paired by seed",
                estimate=est,
                boundary=0.0,
                holds_when="above",
                unit="iterations",
                spec="{:.4g}",
                margin=margin,
                decided_by=(
                    elm_set,
                    count,
                    f"{name} pruning tolerance: a node goes when max |beta_j| <= {tol:.3g} "
                    "(normalised output)",
                    TRAINING_ONLY,
                ),
                why="; ".join(
                    t
                    for t in (
                        short,
                        f"a prune stage fired in {fired} of {len(part)} runs "
                        f"({int(part.prune_stages.sum())} prune stages in all)",
                        _censoring(runs, BT_NO_PRUNE, run, "unpruned run", "pruned run"),
                    )
                    if t
                ),
                ours=f"{med[run]:.0f} vs {med[BT_NO_PRUNE]:.0f} iterations (medians)",
                key=key,
            )
        )
    return out
