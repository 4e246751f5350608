"""Document B, the ELM compass patent: ELM against node count, the patent's data preparation (median
filter, field-gravity screen, min-max, random 90/10 split) on sweeps with glitches, the small-sample study,
and document B's claims.  The ELM rows of paper A's comparison are in
:mod:`navlib.studies.compass.turntable`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ... import engine, verdicts
from ...angles import wrap_deg
from ...claims import Claim
from ...data.compass_sweeps import unwrap_measured
from ...errors import InputError, check_param
from ...methods.bpnet import train_adam_many, train_matlab_bp_many
from ...methods.compass_methods import ELM_METHODS, LS_MODELS, METHODS, fit_method, method_id
from ...methods.compensator import NetworkCompensator
from ...methods.elm import fit_elm, fit_incremental_elm
from ...methods.preprocess import DotScreen, dot_product_screen, median_filter, train_test_split
from ...methods.scaling import MinMax
from ...methods.seeding import generators
from ...sensors.compass import heading_from_field
from ...sensors.planar import fit_planar_model
from .elm_iterations import iteration_claims
from .parameters import StudyParams
from .sweeps import TRAINING_ONLY, Sweeps, ls_assumption, paired_seed_difference, per_seed, rms_deg

# ----------------------------------------------------------------------------------------------------------
# Patent B: test error against hidden-node count


def node_count_curve(
    sw: Sweeps,
    params: StudyParams = StudyParams(),
    seeds=range(20),
    max_nodes: int = 40,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Test-sweep RMS error (deg) against the hidden-node count, one row per (method, seed, n_nodes):

    - ``ELM``: a plain ELM fitted afresh with n = 1..max_nodes random nodes (seed ``seed``);
    - ``ELM back-tuned``: one run of the patent's incremental scheme per seed, grown to ``max_nodes``
      without the loss goal (so it does not stop early), scored after the back-tuning stage that follows
      each ELM stage (the history's ``val_loss``, evaluated on the test sweep); at a node count reached
      more than once (a prune stage took nodes away) the last such stage.

    ``prunes`` counts the prune stages of the run up to the row's stage (0 for the plain ELM), so that
    a step from one node count to the next that spans a prune stage can be told apart
    (:mod:`navlib.studies.compass.elm_nodes`).

    The error is the de-normalised network output minus the true heading without wrapping (the same as
    the wrapped error wherever it is below 180 deg), in both cases computed the same way.  Every seed is a
    task of :mod:`navlib.engine` (``workers``, ``scheduler``; the numbers do not depend on them)."""
    check_param("max_nodes", max_nodes, lo=1, integer=True)
    tg = params.target
    target, t_val = tg.target(sw.x_train, sw.t_train), tg.target(sw.x_test, sw.t_test)
    xs, ts = MinMax.fit(sw.x_train, name="network input"), MinMax.fit(target, name="network target")
    xn, tn = xs.transform(sw.x_train), ts.transform(target)
    xv, tv = xs.transform(sw.x_test), ts.transform(t_val)
    span = float(ts.span[0])
    parts = engine.run(
        _node_count_seed,
        [(xn, tn, xv, tv, span, params, int(seed), int(max_nodes)) for seed in seeds],
        workers=workers,
        scheduler=scheduler,
        label="ELM node counts",
    )
    rows = [r for part in parts for r in part]
    return pd.DataFrame(
        rows, columns=["method", "seed", "n_nodes", "train_rms_deg", "test_rms_deg", "prunes"]
    )


def _node_count_seed(xn, tn, xv, tv, span, params, seed, max_nodes) -> list[tuple]:
    """The rows of :func:`node_count_curve` for one seed (a task)."""
    rows = []
    for n in range(1, max_nodes + 1):  # the same stream for every n: run `seed`'s generator
        model = fit_elm(xn, tn, params.elm_params(), n_hidden=n, rng=generators([seed])[0])
        rows.append(
            (
                "ELM",
                seed,
                n,
                span * np.sqrt(model.loss(xn, tn)),
                span * np.sqrt(model.loss(xv, tv)),
                0,
            )
        )
    ip = replace(
        params.incremental_params(span), loss_goal=0.0, max_nodes=max_nodes, max_iter=2 * max_nodes
    )
    _, hist = fit_incremental_elm(xn, tn, ip, rng=generators([seed])[0], x_val=xv, t_val=tv)
    hist = hist.assign(prunes=(hist.stage == "prune").cumsum())
    tuned = hist[hist.stage == "tune"].groupby("n_nodes").last()
    for n, row in tuned.iterrows():
        rows.append(
            (
                "ELM back-tuned",
                seed,
                int(n),
                span * np.sqrt(row.loss),
                span * np.sqrt(row.val_loss),
                int(row.prunes),
            )
        )
    return rows


# ----------------------------------------------------------------------------------------------------------
# Patent B: data preparation and glitches

MAG_COLUMNS = ("mag_x_ut", "mag_y_ut", "mag_z_ut")
ACC_COLUMNS = ("acc_x_ms2", "acc_y_ms2", "acc_z_ms2")


@dataclass
class PatentData:
    """A sweep prepared as patent B's second to fifth steps describe (:func:`prepare_patent_data`).

    ``keep``: mask over the input rows (False = discarded by the dot-product screen); ``screen``: the
    :class:`navlib.methods.preprocess.DotScreen` (None when not screened); ``true_deg``/``measured_deg``: the kept
    readings (measured heading recomputed from the filtered field); ``x``: the measured heading unwrapped
    along the kept readings; ``x_scale``/``t_scale``: min-max scalers of ``x`` and ``true_deg``;
    ``train_idx``/``test_idx``: the random split (indices into the kept readings)."""

    keep: np.ndarray
    screen: DotScreen | None
    true_deg: np.ndarray
    measured_deg: np.ndarray
    x: np.ndarray
    x_scale: MinMax
    t_scale: MinMax
    train_idx: np.ndarray
    test_idx: np.ndarray

    @property
    def n_rejected(self) -> int:
        return int(self.keep.size - np.count_nonzero(self.keep))


def prepare_patent_data(
    frame: pd.DataFrame,
    *,
    window: int = 3,
    threshold: float = 4.0,
    frac: float = 0.9,
    rng=None,
    median: bool = True,
    screen: bool = True,
    mode: str = "closed",
) -> PatentData:
    """Patent B's data preparation of one sweep (``frame`` with true and measured heading, the field
    ``mag_*_ut`` and the accelerometer ``acc_*_ms2`` columns):

    1. sliding median filter of ``window`` readings over each field and accelerometer component
       (:func:`navlib.methods.preprocess.median_filter`; ``mode='closed'`` for a 0..360 deg inclusive sweep), the
       measured heading recomputed from the filtered field (skipped if ``median`` is False);
    2. discard readings whose field-gravity inner product is abnormal (robust z-score > ``threshold``,
       :func:`navlib.methods.preprocess.dot_product_screen`; skipped if ``screen`` is False);
    3. min-max normalisation of input and target (:class:`navlib.methods.scaling.MinMax`);
    4. random split, ``frac`` for training and the rest for the patent's check
       (:func:`navlib.methods.preprocess.train_test_split`, ``rng`` a seed or Generator).

    The patent prescribes the order (filter, then screen) but no window, threshold or split seed."""
    missing = [
        c
        for c in ("true_heading_deg", "measured_heading_deg", *MAG_COLUMNS, *ACC_COLUMNS)
        if c not in frame
    ]
    if missing:
        raise InputError(
            f"patent data preparation needs column '{missing[0]}' (field and accelerometer "
            f"columns: {', '.join(MAG_COLUMNS + ACC_COLUMNS)})"
        )
    mag = frame[list(MAG_COLUMNS)].to_numpy(float)
    acc = frame[list(ACC_COLUMNS)].to_numpy(float)
    true = frame["true_heading_deg"].to_numpy(float)
    measured = frame["measured_heading_deg"].to_numpy(float)
    if median:
        mag, acc = median_filter(mag, window, mode=mode), median_filter(acc, window, mode=mode)
        measured = heading_from_field(mag)
    scr = dot_product_screen(mag, acc, threshold=threshold) if screen else None
    keep = scr.keep.copy() if scr is not None else np.ones(len(frame), dtype=bool)
    if keep.sum() < 4:
        raise InputError(
            f"patent data preparation: only {int(keep.sum())} readings left after the "
            f"dot-product screen; need at least 4"
        )
    t, m = true[keep], measured[keep]
    x = unwrap_measured(t, m)
    train_idx, test_idx = train_test_split(int(keep.sum()), frac, rng)
    return PatentData(
        keep=keep,
        screen=scr,
        true_deg=t,
        measured_deg=m,
        x=x,
        x_scale=MinMax.fit(x, name="network input"),
        t_scale=MinMax.fit(t, name="network target"),
        train_idx=train_idx,
        test_idx=test_idx,
    )


GLITCH_VARIANTS = {
    "no preparation": dict(median=False, screen=False),
    "dot-product screen": dict(median=False, screen=True),
    "median filter": dict(median=True, screen=False),
    "median filter + screen (patent)": dict(median=True, screen=True),
}


def _check_elm(method: str) -> None:
    """The glitch study trains ELMs only: refuse any other method (one message for the study and a run)."""
    if method_id(method) not in ELM_METHODS:
        raise InputError(f"glitch study method {method!r}: one of {', '.join(ELM_METHODS)}")


def glitch_run(
    train: pd.DataFrame,
    test: pd.DataFrame,
    variant: str,
    params: StudyParams = StudyParams(),
    seed: int = 0,
    *,
    method: str = "elm_backtuned",
    window: int = 3,
    threshold: float = 4.0,
    frac: float = 0.9,
):
    """One run of :func:`glitch_study`: prepare ``train`` as ``variant`` (a key of ``GLITCH_VARIANTS``;
    split seed = ``seed``), train ``method`` (an ELM method, seed ``seed``) on the training part, and
    compensate every reading of ``test``.  Returns ``(test_errors_deg, clean, data, info)``: the wrapped
    test-sweep errors, the mask of glitch-free test readings (``glitch`` column; all True without it), the
    :class:`PatentData` and the training info (``n_nodes``, ``check_rms_deg`` on the patent's held-out
    part)."""
    if variant not in GLITCH_VARIANTS:
        raise InputError(f"unknown preparation {variant!r}; known: {', '.join(GLITCH_VARIANTS)}")
    _check_elm(method)
    d = prepare_patent_data(
        train,
        window=window,
        threshold=threshold,
        frac=frac,
        rng=generators([seed], base=1)[0],
        **GLITCH_VARIANTS[variant],
    )
    tr, ck = d.train_idx, d.test_idx
    comp = fit_method(method, d.x[tr], d.true_deg[tr], params, [seed])[0]
    t_test = test["true_heading_deg"].to_numpy(float)
    x_test = unwrap_measured(t_test, test["measured_heading_deg"].to_numpy(float))
    err = wrap_deg(comp.correct(x_test) - t_test)
    clean = ~test["glitch"].to_numpy(bool) if "glitch" in test else np.ones(len(test), bool)
    info = dict(comp.info, check_rms_deg=rms_deg(comp.correct(d.x[ck]), d.true_deg[ck]))
    return err, clean, d, info


def glitch_study(
    train: pd.DataFrame,
    test: pd.DataFrame,
    params: StudyParams = StudyParams(),
    seeds=range(20),
    *,
    method: str = "elm_backtuned",
    window: int = 3,
    threshold: float = 4.0,
    frac: float = 0.9,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """What patent B's data preparation buys on a training sweep with glitches: for each variant of
    ``GLITCH_VARIANTS`` and seed, :func:`glitch_run`, scored on the glitch-free readings of the test
    sweep (a compensation cannot repair a reading hit by a spike).

    One row per (variant, seed): ``test_rms_deg`` (test sweep), ``check_rms_deg`` (the patent's own
    held-out part of the training sweep), ``n_rejected``, ``glitches_rejected`` (rejected readings that
    were glitches, from the training sweep's ``glitch`` column), ``n_nodes``.  The runs are tasks of
    :mod:`navlib.engine` (``workers``, ``scheduler``; every run has its own seeds)."""
    _check_elm(method)
    items = [
        (train, test, variant, params, int(seed), method, window, threshold, frac)
        for variant in GLITCH_VARIANTS
        for seed in seeds
    ]
    return pd.DataFrame(
        engine.run_batches(
            _glitch_row,
            items,
            GLITCH_BATCH,
            workers=workers,
            scheduler=scheduler,
            label="glitch study",
        )
    )


#: Runs of :func:`glitch_study` per engine task.
GLITCH_BATCH = 5


def _glitch_row(train, test, variant, params, seed, method, window, threshold, frac) -> dict:
    """One row of :func:`glitch_study` (a task)."""
    glitch = train["glitch"].to_numpy(bool) if "glitch" in train else np.zeros(len(train), bool)
    err, clean, d, info = glitch_run(
        train,
        test,
        variant,
        params,
        seed,
        method=method,
        window=window,
        threshold=threshold,
        frac=frac,
    )
    return {
        "variant": variant,
        "seed": seed,
        "test_rms_deg": float(np.sqrt(np.mean(err[clean] ** 2))),
        "check_rms_deg": info["check_rms_deg"],
        "n_rejected": d.n_rejected,
        "glitches_rejected": int(np.sum(glitch & ~d.keep)),
        "n_nodes": info["n_nodes"],
    }


# ----------------------------------------------------------------------------------------------------------
# Patent B: small samples


def even_indices(n_total: int, n: int) -> np.ndarray:
    """``n`` readings spread evenly over a sweep of ``n_total`` (first and last included): a turntable
    calibration with fewer stops."""
    check_param("n", n, lo=2, hi=n_total, integer=True)
    return np.unique(np.round(np.linspace(0, n_total - 1, int(n))).astype(int))


def big_net_labels(big_hidden: int) -> tuple[str, str]:
    """The method labels of :func:`small_sample_study`'s over-sized nets: ``(Adam, trainlm)``."""
    return f"BP 1-{int(big_hidden)}-1 (Adam)", f"BP 1-{int(big_hidden)}-1 (trainlm)"


def small_sample_study(
    sw: Sweeps,
    sizes=(8, 15, 30, 60),
    params: StudyParams = StudyParams(),
    seeds=range(20),
    big_hidden: int = 50,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Patent B's claim that its ELM overfits less than a large network on small samples: train on ``n``
    evenly spread readings of the training sweep (:func:`even_indices`) and score on the whole test sweep.

    Methods (labels from :func:`big_net_labels`):

    - ``ELM back-tuned`` and ``ELM`` (as in :func:`navlib.studies.compass.turntable.compensate`);
    - ``BP 1-{big_hidden}-1 (trainlm)``: the over-sized net a MATLAB user of the patent's era gets from
      ``feedforwardnet(big_hidden)`` and ``train`` with every reading training (no validation split: the
      claim is about a net trained to convergence, and with 8 readings ``dividerand`` would leave 6):
      tansig, ``mapminmax``, Nguyen-Widrow, ``trainlm`` with ``params.lm``
      (:func:`navlib.methods.bpnet.train_matlab_bp_many`; the mu damping makes the step well defined with
      fewer readings than the ``3 big_hidden + 1`` weights), all seeds in one batch per size;
    - ``BP 1-{big_hidden}-1 (Adam)``: paper A's logsig net of the same size trained by Adam with the
      chapter's epochs and learning rate (:func:`navlib.methods.bpnet.train_adam_many`);
    - ``physical model`` (five parameters; seed -1).

    One row per (n_train, method, seed): ``train_rms_deg`` (on the n readings), ``test_rms_deg``,
    ``n_nodes`` (hidden nodes; NaN for the physical model).  Every size is a task of :mod:`navlib.engine`
    (``workers``, ``scheduler``), its seeds in one batch as above: the numbers do not depend on them."""
    check_param("big_hidden", big_hidden, lo=1, integer=True)
    seeds = [int(s) for s in seeds]
    for n in sizes:
        check_param("n", n, lo=2, hi=sw.t_train.size, integer=True)
    parts = engine.run(
        _small_sample_size,
        [(sw, int(n), params, seeds, int(big_hidden)) for n in sizes],
        workers=workers,
        scheduler=scheduler,
        cost=[float(n) for n in sizes],
        label="small samples",
    )
    return pd.DataFrame([r for part in parts for r in part])


def _small_sample_size(
    sw: Sweeps, n: int, params: StudyParams, seeds: list, big_hidden: int
) -> list[dict]:
    """The rows of :func:`small_sample_study` for one training size (a task)."""
    adam, lm = big_net_labels(big_hidden)
    tg = params.target
    rows = []
    sub = sw.subset(even_indices(sw.t_train.size, n))
    xtr, ttr, xte = sub.x_train, sub.t_train, sub.x_test

    def add(method, seed, comp, n_nodes):
        rows.append(
            {
                "n_train": int(n),
                "method": method,
                "seed": seed,
                "train_rms_deg": rms_deg(comp.correct(xtr), ttr),
                "test_rms_deg": rms_deg(comp.correct(xte), sub.t_test),
                "n_nodes": n_nodes,
            }
        )

    for method in ELM_METHODS[::-1]:
        for seed, comp in zip(seeds, fit_method(method, xtr, ttr, params, seeds)):
            add(METHODS[method].label, seed, comp, comp.info["n_nodes"])
    target = tg.target(xtr, ttr)
    for label, nets in (
        (adam, train_adam_many(xtr, target, big_hidden, params.adam, generators(seeds))),
        (lm, train_matlab_bp_many(xtr, target, big_hidden, generators(seeds), params.lm)),
    ):
        for seed, net in zip(seeds, nets):
            add(label, seed, NetworkCompensator(net, tg), big_hidden)
    phys = fit_planar_model(sub.t_train, sub.m_train)
    rows.append(
        {
            "n_train": int(n),
            "method": "physical model",
            "seed": -1,
            "train_rms_deg": rms_deg(phys.correct(sub.m_train), ttr),
            "test_rms_deg": rms_deg(phys.correct(sub.m_test), sub.t_test),
            "n_nodes": np.nan,
        }
    )
    return rows


# ----------------------------------------------------------------------------------------------------------
# Summaries and claims


def glitch_summary(g_runs: pd.DataFrame) -> pd.DataFrame:
    """Per preparation variant of :func:`glitch_study`: median test RMS with its 10th..90th percentiles,
    median check RMS, readings rejected, glitches among them, hidden nodes."""
    g = g_runs.groupby("variant", sort=False)
    return pd.DataFrame(
        {
            "test rms (deg)": g.test_rms_deg.median(),
            "p10 (deg)": g.test_rms_deg.quantile(0.1),
            "p90 (deg)": g.test_rms_deg.quantile(0.9),
            "check rms (deg)": g.check_rms_deg.median(),
            "rejected": g.n_rejected.median(),
            "glitches rejected": g.glitches_rejected.median(),
            "nodes": g.n_nodes.median(),
        }
    )


def small_sample_summary(small: pd.DataFrame) -> pd.DataFrame:
    """Per (n_train, method) of :func:`small_sample_study`: median training and test RMS, the test RMS's
    10th..90th percentiles, median hidden nodes."""
    g = small.groupby(["n_train", "method"], sort=False)
    return pd.DataFrame(
        {
            "train rms (deg)": g.train_rms_deg.median(),
            "test rms (deg)": g.test_rms_deg.median(),
            "test p10 (deg)": g.test_rms_deg.quantile(0.1),
            "test p90 (deg)": g.test_rms_deg.quantile(0.9),
            "nodes": g.n_nodes.median(),
        }
    )


def nodes_to_goal_runs(curve: pd.DataFrame, goal_deg: float) -> pd.DataFrame:
    """Per (method, seed) of :func:`node_count_curve`: ``n_nodes``, the fewest nodes whose training RMS is
    at most ``goal_deg``, and ``reached``; a run that never reaches the goal gets the curve's largest node
    count + 1 (a lower bound) and ``reached`` False."""
    cap = int(curve.n_nodes.max()) + 1
    first = curve[curve.train_rms_deg <= goal_deg].groupby(["method", "seed"]).n_nodes.min()
    all_runs = curve[["method", "seed"]].drop_duplicates().set_index(["method", "seed"]).index
    n = first.reindex(all_runs)
    return pd.DataFrame({"n_nodes": n.fillna(cap).astype(int), "reached": n.notna()}).reset_index()


def nodes_to_goal(curve: pd.DataFrame, goal_deg: float) -> pd.Series:
    """Per method of :func:`node_count_curve`: median over seeds of the fewest nodes whose training RMS is
    at most ``goal_deg`` (runs that never reach it are left out)."""
    ok = curve[curve.train_rms_deg <= goal_deg]
    return ok.groupby(["method", "seed"]).n_nodes.min().groupby("method").median()


#: The BP rows that start from random weights: the patent's claim that its start lowers the chance of a
#: local minimum is about these; the comparisons with paper A's DE-started nets are the book's own.
RANDOM_START = ("bp_matlab", "bp_matlab_val", "bp_adam", "bp_scipy_lm")


def _series(frame: pd.DataFrame, col: str) -> pd.Series:
    return pd.Series(frame[col].to_numpy(float), index=frame.seed.to_numpy(int))


def _paired(worse: pd.Series, better: pd.Series, name: str) -> tuple[verdicts.Estimate | None, str]:
    """The paired difference ``worse - better`` over the same seeds
    (:func:`navlib.studies.compass.sweeps.paired_seed_difference`), or None and the reason when there is no 95 %
    interval."""
    return verdicts.attempt(
        paired_seed_difference, worse.rename(f"{name} (first)"), better.rename(f"{name} (second)")
    )


def claims(
    runs: pd.DataFrame,
    node_runs: pd.DataFrame,
    g_runs: pd.DataFrame,
    small: pd.DataFrame,
    params: StudyParams,
    big_hidden: int,
    bp_rows=("bp_matlab", "ade_bp_hybrid_trainlm"),
    iterations: pd.DataFrame | None = None,
) -> list[Claim]:
    """Document B's claims (reading ``'document B'``), each judged by the one rule of
    :mod:`navlib.verdicts` on a paired difference over the same seeds (boundary 0, holds above):

    - the invention's own result, "the back-tuned ELM improves the uncompensated heading" (document B's
      headline): RMS(uncompensated) - RMS(ELM back-tuned), paired with every seed, boundary 0 (B states no
      amount);
    - "ELM back-tuned beats X": RMS(X) - RMS(ELM back-tuned) from paper A's seed study ``runs`` (method
      ids; a deterministic X is paired with every seed).  Against the 8-position LS (an explicit model)
      and a randomly started BP net (``bp_rows`` among :data:`RANDOM_START`) the claim is the patent's;
      against paper A's DE-started nets it is the book's own;
    - "the implicit ELM beats the exact physical model": true by construction (our simulator *is* that
      model); the interval is shown, the verdict is *cannot be judged*;
    - back-tuning against a plain ELM: RMS(plain) - RMS(back-tuned), paired by seed;
    - "fewer nodes": nodes a plain ELM needs for the training goal (``node_runs``, from
      :func:`nodes_to_goal_runs`) minus the nodes the back-tuned ELM stops at (``runs``), paired by seed;
    - the data preparation: test RMS without preparation minus with the patent's (``g_runs``,
      :func:`glitch_study`), paired by seed;
    - small samples: on the smallest training set of ``small`` (:func:`small_sample_study`), the
      overfitting gap (test - training RMS) of the over-sized net minus the back-tuned ELM's, paired by
      seed, once per trainer of the net (MATLAB's ``trainlm`` from Nguyen-Widrow weights, Adam from small
      weights), since the patent does not say which;
    - iterations (``iterations``, from :func:`navlib.studies.compass.elm_iterations.iteration_study`):
      against Huang's point-incremental ELM and with pruning off
      (:func:`navlib.studies.compass.elm_iterations.iteration_claims`).

    The intervals cover training randomness on fixed simulated sweeps, not sensor-noise draws."""
    r = "document B"
    rms = {m: per_seed(runs, m) for m in set(runs.method)}
    bt = rms["elm_backtuned"]
    elm_set = (
        f"our a-priori ELM settings ({params.elm_nodes} nodes plain; back-tuned: goal "
        f"{params.elm_goal_deg:g} deg, at most {params.elm_max_nodes} nodes; weights "
        f"U(-{params.elm_range:g}, {params.elm_range:g}))"
    )

    def beats(claim, paper, source, worse_id, key, extra=(), why="", by_construction=False):
        est, short = _paired(rms[worse_id], bt, claim)
        return Claim(
            claim,
            paper,
            reading=r,
            source=source,
            statistic=f"RMS {METHODS[worse_id].label} - RMS ELM back-tuned, paired by seed, deg",
            estimate=est,
            by_construction=by_construction,
            boundary=0.0,
            holds_when="above",
            unit="deg",
            decided_by=(elm_set, TRAINING_ONLY) + tuple(extra),
            ours=f"{bt.median():.3f} vs {rms[worse_id].median():.3f} deg rms",
            key=key,
            why="; ".join(t for t in (short, why) if t),
        )

    out = []
    if "uncompensated" in rms:
        # The invention's own result (its headline): the back-tuned ELM against no compensation at all.  B
        # states no amount, so "improves" is any reduction of the test RMS (boundary 0).
        out.append(
            beats(
                "the back-tuned ELM improves the uncompensated heading",
                "compensates the nonlinear error and improves the heading accuracy (no numbers)",
                "paper",
                "uncompensated",
                "b_bt_uncompensated",
                why="boundary 0: document B states no amount of improvement, so any reduction of "
                "the test RMS counts",
            )
        )
    out += [
        beats(
            f"ELM back-tuned beats 8-position LS [{name}]",
            "implicit beats explicit models (no numbers)",
            "paper",
            ls,
            "b_bt_ls" if ls == "ls8" else f"b_bt_ls_{ls.split('_')[-1]}",
            (ls_assumption(ls),),
        )
        for ls, name in LS_MODELS.items()
        if ls in rms
    ]
    out += [
        beats(
            "ELM back-tuned beats ADE-BP (pure DE)",
            "(not in the paper)",
            "book",
            "ade_bp_pure",
            "b_bt_ade_bp_pure",
            ("paper A's pure DE with its budget",),
        )
    ]
    for b in bp_rows:
        if b in rms:
            paper_side = b in RANDOM_START
            out.append(
                beats(
                    f"ELM back-tuned beats {METHODS[b].label}",
                    "fewer local minima than random starting weights (no numbers)"
                    if paper_side
                    else "(not in the paper)",
                    "paper" if paper_side else "book",
                    b,
                    f"b_bt_{b}",
                )
            )
    out.append(
        beats(
            "the implicit ELM beats the exact physical model",
            "implicit beats explicit models",
            "paper",
            "physical",
            "b_bt_physical",
            by_construction=True,
            why="our simulator is the exact five-parameter model that the physical model fits: on "
            "our sweeps only the noise draw can favour another model; real data must decide",
        )
    )
    est, short = _paired(rms["elm"], bt, "plain ELM")
    out.append(
        Claim(
            f"back-tuning beats a plain ELM of {params.elm_nodes} nodes",
            "higher accuracy",
            reading=r,
            statistic="RMS plain ELM - RMS ELM back-tuned, paired by seed, deg",
            estimate=est,
            boundary=0.0,
            holds_when="above",
            unit="deg",
            decided_by=(elm_set, TRAINING_ONLY),
            why=short,
            ours=f"{bt.median():.3f} vs {rms['elm'].median():.3f} deg rms",
            key="b_plain_elm",
        )
    )
    plain = node_runs[node_runs.method == "ELM"]
    nodes_bt = runs[runs.method == "elm_backtuned"]
    est, short = _paired(_series(plain, "n_nodes"), _series(nodes_bt, "n_nodes"), "nodes")
    unreached = int((~plain.reached.astype(bool)).sum())
    out.append(
        Claim(
            "back-tuning needs fewer nodes for the same training goal",
            "solves the node-count choice",
            reading=r,
            statistic="nodes a plain ELM needs for the training goal - nodes the back-tuned "
            "ELM stops at, paired by seed",
            estimate=est,
            boundary=0.0,
            holds_when="above",
            unit="nodes",
            spec="{:.3g}",
            decided_by=(elm_set, TRAINING_ONLY),
            why="; ".join(
                t
                for t in (
                    short,
                    f"{unreached} plain-ELM runs never reached the goal "
                    f"(counted at the curve's cap + 1)"
                    if unreached
                    else "",
                )
                if t
            ),
            ours=f"{nodes_bt.n_nodes.median():.1f} vs {plain.n_nodes.median():.1f} nodes (medians)",
            key="b_nodes",
        )
    )
    prep = g_runs[g_runs.variant == "median filter + screen (patent)"]
    raw = g_runs[g_runs.variant == "no preparation"]
    est, short = _paired(_series(raw, "test_rms_deg"), _series(prep, "test_rms_deg"), "glitches")
    out.append(
        Claim(
            "the data preparation lowers the error on sweeps with glitches",
            "rejects abnormal data",
            reading=r,
            statistic="test RMS without preparation - with the patent's, paired by seed, "
            "deg (glitch-free test readings)",
            estimate=est,
            boundary=0.0,
            holds_when="above",
            unit="deg",
            decided_by=(
                "our glitch model: field spikes in random directions",
                elm_set,
                TRAINING_ONLY,
            ),
            why=short,
            ours=f"{prep.test_rms_deg.median():.2f} vs {raw.test_rms_deg.median():.2f} deg rms",
            key="b_glitch",
        )
    )
    n0 = int(small.n_train.min())
    s0 = small[small.n_train == n0].assign(gap=lambda f: f.test_rms_deg - f.train_rms_deg)
    elm_gap = _series(s0[s0.method == "ELM back-tuned"], "gap")
    adam, lm = big_net_labels(big_hidden)
    # The patent does not say how its "BP network" is trained: one verdict per plausible trainer.
    for big, how, key in (
        (lm, "MATLAB trainlm, Nguyen-Widrow", "b_small_trainlm"),
        (adam, "Adam from U(-1, 1)", "b_small_adam"),
    ):
        part = s0[s0.method == big]
        if part.empty or elm_gap.empty:
            continue
        big_gap = _series(part, "gap")
        est, short = _paired(big_gap, elm_gap, "gap")
        out.append(
            Claim(
                f"on {n0} readings the ELM overfits less than an over-sized net ({how})",
                "less overfitting on small samples",
                reading=r,
                statistic=f"overfitting gap (test - training RMS) of the 1-{int(big_hidden)}-1 net - "
                f"the back-tuned ELM's, paired by seed, deg",
                estimate=est,
                boundary=0.0,
                holds_when="above",
                unit="deg",
                decided_by=(
                    f"the over-sized net's trainer: {how} (the patent does not say)",
                    f"{n0} evenly spread training readings",
                    elm_set,
                    TRAINING_ONLY,
                ),
                why=short,
                ours=f"gap {elm_gap.median():.2f} vs {big_gap.median():.2f} deg (medians)",
                key=key,
            )
        )
    if iterations is not None:
        out += iteration_claims(iterations, params)
    return out
