"""Document B's claims about its data: the ELM fits N samples with zero error (register B17), min-max
normalisation improves the training accuracy (B15), and deep learning needs many samples (B19).

Patent B, summary of the invention (stage s701, before eq. 3): "with a nonlinear activation g(x), [the ELM]
can approximate the N input samples from the same continuous system with zero error"; description, third
step: "normalise the raw data by the max-min method, improving the training accuracy of the network
weights"; background, on the deep-learning compensation of patent CN104931028A: "deep learning needs a
large amount of error data for training and places high demands on the sample size".

How we read them (statistic, boundary and primary reading fixed from the patent's words before any run of
this module was read):

- B17 is Huang's interpolation theorem (Huang, Zhu & Siew 2006, Theorem 2.1): with L = N hidden nodes
  drawn from a continuous distribution and N distinct inputs, H is invertible with probability one, so
  ``beta = H^-1 T`` leaves no error.  A statement about every draw, so the statistic is the worst
  training RMS over the seeds, with a percentile bootstrap over the seeds (the chapter's convention for a
  worst case over runs), against the register's numerical zero (1e-6 deg; holds below).  The theorem
  holds in exact arithmetic; the ELM's solve (:func:`navlib.methods.elm.solve_output_weights`, LAPACK's
  SVD least squares, B's eq. 7 ``beta = H^+ T``) works in float64 and treats the singular values of H
  below ``eps max(N, L) s_max`` as zero.  What float64 can show is therefore bounded below, per run, by

  ::

      floor = span ( |T - U_r U_r^T T| + eps s_max |beta| ) / sqrt(N)        (deg)

  the part of the (normalised) target along the singular directions the solve drops (U_r: the left
  singular vectors kept) plus the rounding of H beta (``eps |H| |beta|``), and the claim's noise floor
  (:class:`navlib.verdicts.Floor`) is the worst of it over the seeds, with its own bootstrap interval.
  An error above the boundary but within that floor is the truncation, not the theorem: *cannot be
  judged*.  Primary reading: all of sweep 1 (the chapter's training set, N = 121) and the chapter's node
  draw; 30 and 8 evenly spread readings and Huang's U(-1, 1) draw are the other readings.
- B15: the back-tuned ELM trained on the raw headings (deg in, deg out) against the same scheme on
  min-max-normalised ones, the training RMS at the stop, raw minus normalised, paired by seed (boundary 0,
  holds above), with the chapter's goal (in deg), node cap, k and pruning bound (in deg of output).
  Drawing the raw network's input weights from the normalised run's U(-r, r) makes every sigmoid saturate
  on inputs of hundreds of degrees, and the claim would hold by that alone; so the primary reading draws
  them from U(-r / span_x, r / span_x) (the raw input span), the same pre-activations the normalised run
  draws up to a shift of the bias: what is left is what normalisation does to the training itself.  The
  same draw as the normalised run is the second reading.
- B19: on the chapter's small-sample runs (:func:`navlib.studies.compass.elm_patent.small_sample_study`:
  8, 15, 30, 60 evenly spread readings of sweep 1, the back-tuned ELM and the 1-50-1 net by two trainers,
  the same seeds at every size), per seed the fewest readings whose test RMS reaches a goal, the large
  net's minus the back-tuned ELM's, paired by seed (boundary 0, holds above).  The goal: twice the
  physical model's test RMS on the full sweep (the chapter's noise floor), and four times as the second
  goal.  A run that reaches the goal at no size counts at the full sweep's readings, a lower bound (the
  1-50-1 net is not trained on the full sweep).  The net trained by Adam from small weights is primary, as
  in B04 (B describes deep learning's tuning as gradient descent), ``trainlm`` the other reading.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from ... import engine, verdicts
from ...claims import Claim
from ...errors import InputError, check_param
from ...methods.compass_methods import fit_method
from ...methods.compensator import NetworkCompensator, ScaledRegressor
from ...methods.elm import ELMParams, fit_elm, fit_incremental_elm
from ...methods.scaling import MinMax
from ...methods.seeding import generators
from ...seeding import sequence
from .elm_patent import big_net_labels, even_indices
from .parameters import StudyParams
from .sweeps import TRAINING_ONLY, Sweeps, paired_seed_difference, per_seed, rms_deg

_READING = "document B"
#: B17's boundary: a training RMS below a millionth of a degree is zero for a compass (the register's
#: numerical zero).
ZERO_DEG = 1e-6
#: Entropy of the bootstrap of B17's worst run (spawn key: the reading's index; + 100 for its floor).
BOOTSTRAP_ENTROPY = 18
#: B17's smaller training sets (evenly spread readings of sweep 1), besides all of it.
INTERPOLATION_SIZES = (30, 8)
#: Huang's node draw for inputs in [0, 1], B17's other draw.
HUANG_RANGE = 1.0
_EPS = float(np.finfo(float).eps)

_PAPER_B17 = "approximates the N training samples with zero error (no numbers)"
_PAPER_B15 = "min-max normalisation improves the training accuracy (no numbers)"
_PAPER_B19 = "deep learning needs a large amount of error data (no numbers)"


# ------------------------------------------------------------------------------------------- B17
def interpolation_readings(sw: Sweeps, params: StudyParams) -> list[tuple[int, float]]:
    """B17's readings as ``(readings, weight_range)``: all of sweep 1 with the chapter's draw (primary),
    :data:`INTERPOLATION_SIZES` readings with it, and all of sweep 1 with :data:`HUANG_RANGE`."""
    n = int(sw.t_train.size)
    r = float(params.elm_range)
    return [(n, r)] + [(int(k), r) for k in INTERPOLATION_SIZES] + [(n, HUANG_RANGE)]


def interpolation_run(x, t, weight_range: float, seed: int) -> dict:
    """One plain ELM with as many nodes as readings on min-max-normalised ``x`` and ``t`` (node draw
    U(-weight_range, weight_range), run ``seed``): ``train_rms_deg`` (span sqrt(MSE), deg, unwrapped),
    ``cond`` (s_max / s_min of H), ``rank`` (singular values above the solve's cutoff
    ``eps max(N, L) s_max``), ``trunc_rms_deg`` (the target's part along the dropped singular directions),
    ``round_rms_deg`` (``eps s_max |beta|``) and ``floor_rms_deg`` (their sum), all as an RMS over the N
    readings in deg (the module docstring has the equation)."""
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
    xn, tn = xs.transform(x), ts.transform(t)
    n = int(xn.size)
    span = float(ts.span[0])
    model = fit_elm(
        xn,
        tn,
        n_hidden=n,
        rng=generators([seed])[0],
        params=ELMParams(weight_range=weight_range, bias_range=weight_range),
    )
    h = model.hidden(xn)
    u, s, _ = np.linalg.svd(h)
    rank = int(np.count_nonzero(s > _EPS * max(h.shape) * s[0]))
    kept = u[:, :rank]
    trunc = tn - kept @ (kept.T @ tn)
    scale = span / np.sqrt(n)
    t_rms = scale * float(np.linalg.norm(trunc))
    r_rms = scale * _EPS * float(s[0]) * float(np.linalg.norm(model.beta))
    return {
        "n_readings": n,
        "weight_range": float(weight_range),
        "seed": int(seed),
        "train_rms_deg": span * float(np.sqrt(model.loss(xn, tn))),
        "cond": float(s[0] / s[-1]) if s[-1] > 0 else np.inf,
        "rank": rank,
        "trunc_rms_deg": t_rms,
        "round_rms_deg": r_rms,
        "floor_rms_deg": t_rms + r_rms,
    }


def interpolation_study(
    sw: Sweeps, params: StudyParams = StudyParams(), seeds=range(20)
) -> pd.DataFrame:
    """:func:`interpolation_run` for every reading of :func:`interpolation_readings` and seed, on the
    chapter's target (``params.target``).  In this process: each run is one solve and one SVD
    of at most 121 x 121 (milliseconds)."""
    rows = []
    for n, wr in interpolation_readings(sw, params):
        sub = sw if n == sw.t_train.size else sw.subset(even_indices(sw.t_train.size, n))
        t = params.target.target(sub.x_train, sub.t_train)
        rows += [interpolation_run(sub.x_train, t, wr, int(s)) for s in seeds]
    return pd.DataFrame(rows)


def _worst(values: np.ndarray, key: int) -> verdicts.Estimate:
    return verdicts.bootstrap(
        [values], lambda a: float(np.max(a)), seed=sequence(BOOTSTRAP_ENTROPY, key)
    )


def interpolation_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per reading of :func:`interpolation_study`: runs, the median cond(H), the runs whose H has a
    numerical rank below N (the solve drops directions), the largest training RMS and the largest floor
    (deg), and the median ratio of training RMS to floor."""
    r = runs.assign(
        deficient=runs["rank"] < runs.n_readings, ratio=runs.train_rms_deg / runs.floor_rms_deg
    )
    g = r.groupby(["n_readings", "weight_range"], sort=False)
    return pd.DataFrame(
        {
            "runs": g.size(),
            "median cond(H)": g.cond.median(),
            "runs rank < N": g.deficient.sum().astype(int),
            "largest train rms (deg)": g.train_rms_deg.max(),
            "largest floor (deg)": g.floor_rms_deg.max(),
            "rms / floor (median)": g.ratio.median(),
        }
    )


def _draw(wr: float) -> str:
    return f"U(-{wr:g}, {wr:g})"


def interpolation_claims(runs: pd.DataFrame, params: StudyParams = StudyParams()) -> list[Claim]:
    """Register B17 from :func:`interpolation_study`, one row per reading: the worst training RMS over
    the seeds (bootstrap over seeds), boundary :data:`ZERO_DEG`, holds below, with the float64 floor of
    the module docstring (worst over the seeds, its own bootstrap interval) as the claim's noise floor."""
    n_full = int(runs.n_readings.max())
    out = []
    for key, ((n, wr), part) in enumerate(runs.groupby(["n_readings", "weight_range"], sort=False)):
        if part.duplicated("seed").any():
            raise InputError(f"interpolation runs: {n} readings, {_draw(wr)} repeats a seed")
        name = f"{int(n)} readings" + ("" if wr == params.elm_range else f", {_draw(wr)} nodes")
        est, short = verdicts.attempt(_worst, part.train_rms_deg.to_numpy(float), key)
        fl, _ = verdicts.attempt(_worst, part.floor_rms_deg.to_numpy(float), 100 + key)
        floor = (
            None
            if fl is None
            else verdicts.Floor(
                fl.value,
                "float64 least squares: singular values of H below eps max(N, L) s_max dropped, "
                "plus the rounding of H beta",
                f"cond(H) below about 1/(eps N) (median here {part.cond.median():.2g}), or "
                "arithmetic beyond float64",
                lo=fl.lo,
                hi=fl.hi,
            )
        )
        deficient = int((part["rank"] < part.n_readings).sum())
        ratio = float((part.train_rms_deg / part.floor_rms_deg).median())
        out.append(
            Claim(
                f"with as many hidden nodes as readings the ELM fits them with zero error [{name}]",
                _PAPER_B17,
                reading=_READING,
                statistic="training RMS of a plain ELM with as many hidden nodes as training "
                "readings, largest over seeds (bootstrap over seeds), deg",
                estimate=est,
                boundary=ZERO_DEG,
                holds_when="below",
                unit="deg",
                spec="{:.3g}",
                floor=floor,
                decided_by=(
                    f"{int(n)} readings of sweep 1"
                    + (" (all)" if n == n_full else " spread evenly")
                    + f", min-max normalised; node draw {_draw(wr)}",
                    "the theorem holds in exact arithmetic; the solve is float64 (LAPACK SVD "
                    "least squares, B's beta = H^+ T)",
                    TRAINING_ONLY,
                ),
                why="; ".join(
                    t
                    for t in (
                        short,
                        f"H numerically rank-deficient in {deficient} of {len(part)} runs "
                        f"(median cond(H) {part.cond.median():.2g}, 1/eps = {1 / _EPS:.2g}); "
                        f"training RMS / float64 floor {ratio:.3g} (median over runs)",
                    )
                    if t
                ),
                ours=f"largest {part.train_rms_deg.max():.3g} deg, median "
                f"{part.train_rms_deg.median():.3g} deg",
                key="b_zero_error"
                + ("" if (n, wr) == (n_full, params.elm_range) else f"_{int(n)}")
                + ("" if wr == params.elm_range else "_huang"),
            )
        )
    return out


# ------------------------------------------------------------------------------------------- B15
#: B15's runs: the patent's min-max-normalised run and the raw runs (input weights scaled to the raw
#: input span; the normalised run's draw).
NORMALISED, RAW_FAIR, RAW_SAME = (
    "min-max normalised",
    "raw, input weights scaled to the input span",
    "raw, the normalised run's node draw",
)
#: The runs of :func:`normalisation_study`, in display order.
NORMALISATION_RUNS = (NORMALISED, RAW_FAIR, RAW_SAME)
_IDENTITY = MinMax(lo=np.zeros(1), hi=np.ones(1))


def raw_params(params: StudyParams, x_span: float, t_span: float, scaled: bool):
    """The back-tuned ELM's settings for raw data (deg in, deg out): the chapter's goal as an MSE in
    deg^2, the pruning bound in deg of output (``elm_prune_tol`` of the target span), node cap and k
    unchanged; input weights U(-r / x_span, r / x_span) when ``scaled`` (else U(-r, r)), biases U(-r, r)."""
    check_param("x_span", x_span, lo=0, lo_open=True)
    check_param("t_span", t_span, lo=0, lo_open=True)
    r = float(params.elm_range)
    return replace(
        params.incremental_params(t_span),
        loss_goal=float(params.elm_goal_deg) ** 2,
        prune_tol=float(params.elm_prune_tol) * float(t_span),
        weight_range=r / float(x_span) if scaled else r,
        bias_range=r,
    )


def normalisation_study(
    sw: Sweeps,
    params: StudyParams = StudyParams(),
    seeds=range(20),
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """The back-tuned ELM on sweep 1 as each of :data:`NORMALISATION_RUNS`, one row per (run, seed):
    ``train_rms_deg`` and ``test_rms_deg`` (sweep 2) at the stop, ``reached`` (training goal),
    ``iterations`` (ELM stages) and ``n_nodes``.  Every seed is a task of :mod:`navlib.engine`
    (``workers``, ``scheduler``; the numbers do not depend on them)."""
    parts = engine.run(
        _normalisation_seed,
        [(sw, params, int(s)) for s in seeds],
        workers=workers,
        scheduler=scheduler,
        label="ELM normalisation",
    )
    return pd.DataFrame([r for part in parts for r in part])


def _normalisation_seed(sw: Sweeps, params: StudyParams, seed: int) -> list[dict]:
    """The rows of :func:`normalisation_study` for one seed (a task)."""
    tg = params.target
    x, t = sw.x_train, tg.target(sw.x_train, sw.t_train)
    x_span, t_span = float(np.ptp(x)), float(np.ptp(t))
    rows = []

    def add(run, comp, hist, goal):
        rows.append(
            {
                "run": run,
                "seed": seed,
                "train_rms_deg": rms_deg(comp.correct(sw.x_train), sw.t_train),
                "test_rms_deg": rms_deg(comp.correct(sw.x_test), sw.t_test),
                "reached": bool(hist.loss.iloc[-1] <= goal),
                "iterations": int((hist.stage == "elm").sum()),
                "n_nodes": int(comp.net.n_hidden),
            }
        )

    comp = fit_method("elm_backtuned", sw.x_train, sw.t_train, params, [seed])[0]
    add(NORMALISED, comp, comp.info["history"], params.incremental_params(t_span).loss_goal)
    for run, scaled in ((RAW_FAIR, True), (RAW_SAME, False)):
        ip = raw_params(params, x_span, t_span, scaled)
        model, hist = fit_incremental_elm(x, t, ip, rng=generators([seed])[0])
        comp = NetworkCompensator(ScaledRegressor(model, _IDENTITY, _IDENTITY), tg)
        add(run, comp, hist, ip.loss_goal)
    return rows


def normalisation_summary(runs: pd.DataFrame) -> pd.DataFrame:
    """Per run of :func:`normalisation_study`: median training and test RMS at the stop, runs that
    reached the training goal, median iterations and nodes."""
    g = runs.groupby("run", sort=False)
    return pd.DataFrame(
        {
            "train rms (deg)": g.train_rms_deg.median(),
            "test rms (deg)": g.test_rms_deg.median(),
            "reached goal": g.reached.sum().astype(int).astype(str) + " of " + g.size().astype(str),
            "iterations": g.iterations.median(),
            "nodes": g.n_nodes.median(),
        }
    ).reindex([r for r in NORMALISATION_RUNS if r in set(runs.run)])


def _by_seed(runs: pd.DataFrame, run: str, col: str) -> pd.Series:
    part = runs[runs.run == run]
    if part.empty:
        raise InputError(f"normalisation runs: no rows of run {run!r}")
    return pd.Series(part[col].to_numpy(float), index=part.seed.to_numpy(int), name=f"{run} {col}")


def normalisation_claims(runs: pd.DataFrame, params: StudyParams = StudyParams()) -> list[Claim]:
    """Register B15 from :func:`normalisation_study`: training RMS of the raw run minus the normalised
    run's, paired by seed, boundary 0, holds above; the raw run with input weights scaled to the input
    span (primary) and with the normalised run's draw."""
    norm = _by_seed(runs, NORMALISED, "train_rms_deg")
    reached = runs.groupby("run").reached.sum()
    n_runs = runs.groupby("run").size()
    settings = (
        f"the chapter's back-tuned ELM: goal {params.elm_goal_deg:g} deg training RMS, at most "
        f"{params.elm_max_nodes} nodes, k = {params.elm_max_iter} stages, pruning bound "
        f"{params.elm_prune_tol:g} of the target span; the same in deg for the raw runs"
    )
    out = []
    for run, name, key in (
        (RAW_FAIR, "raw input weights scaled to the input span", "b_minmax"),
        (RAW_SAME, "raw with the normalised run's node draw", "b_minmax_same"),
    ):
        raw = _by_seed(runs, run, "train_rms_deg")
        est, short = verdicts.attempt(paired_seed_difference, raw, norm)
        draw = (
            f"raw input weights U(-{params.elm_range:g} / span, {params.elm_range:g} / span), "
            "span the raw input's"
            if run == RAW_FAIR
            else f"raw input weights U(-{params.elm_range:g}, {params.elm_range:g}), as normalised"
        )
        out.append(
            Claim(
                f"min-max normalisation lowers the back-tuned ELM's training RMS [{name}]",
                _PAPER_B15,
                reading=_READING,
                statistic="training RMS of the back-tuned ELM on raw headings - on min-max "
                "normalised ones, paired by seed, deg",
                estimate=est,
                boundary=0.0,
                holds_when="above",
                unit="deg",
                spec="{:.3g}",
                decided_by=(settings, draw, TRAINING_ONLY),
                why="; ".join(
                    t
                    for t in (
                        short,
                        f"training goal reached in {int(reached.get(run, 0))} of "
                        f"{int(n_runs.get(run, 0))} raw runs and "
                        f"{int(reached.get(NORMALISED, 0))} of {int(n_runs.get(NORMALISED, 0))} "
                        "normalised runs",
                    )
                    if t
                ),
                ours=f"{norm.median():.3g} vs {raw.median():.3g} deg rms (medians)",
                key=key,
            )
        )
    return out


# ------------------------------------------------------------------------------------------- B19
#: B19's goals: multiples of the physical model's test RMS on the full sweep (primary first).
GOAL_FACTORS = (2.0, 4.0)
#: The back-tuned ELM's method label in the small-sample runs.
ELM_LABEL = "ELM back-tuned"


def readings_to_goal(small: pd.DataFrame, method: str, goal_deg: float, cap: int) -> pd.DataFrame:
    """Per seed of ``method`` in the small-sample runs ``small``: ``readings``, the fewest training
    readings whose test RMS is at most ``goal_deg``, and ``reached``; a seed that reaches it at no size
    counts at ``cap`` (the full sweep's readings: a lower bound) with ``reached`` False."""
    part = small[small.method == method]
    if part.empty:
        raise InputError(f"small-sample runs: no rows of method {method!r}")
    if part.duplicated(["n_train", "seed"]).any():
        raise InputError(f"small-sample runs: {method!r} repeats a (size, seed)")
    sizes = part.groupby("seed").n_train.apply(frozenset)
    if sizes.nunique() != 1:
        raise InputError(f"small-sample runs: {method!r} lacks a size for some seed")
    if cap <= int(part.n_train.max()):
        raise InputError(f"readings_to_goal: cap {cap} must exceed the largest size")
    first = part[part.test_rms_deg <= goal_deg].groupby("seed").n_train.min()
    seeds = pd.Index(sorted(part.seed.unique()), name="seed")
    n = first.reindex(seeds)
    return pd.DataFrame({"readings": n.fillna(cap).astype(int), "reached": n.notna()})


def _censoring(net: pd.DataFrame, elm: pd.DataFrame) -> str:
    r_net, r_elm = net.reached, elm.reached.reindex(net.index)
    only_net = int((~r_net & r_elm).sum())
    both = int((~r_net & ~r_elm).sum())
    only_elm = int((r_net & ~r_elm).sum())
    if only_net + both + only_elm == 0:
        return "every run reached the goal"
    return (
        f"{only_net} of {len(r_net)} pairs with only the net short of the goal at every size (a "
        f"lower bound), {both} with both short (no bound either way), {only_elm} with only the ELM "
        "short (an upper bound)"
    )


def _count(to_goal: pd.DataFrame, cap: int, top: int) -> str:
    """The median of :func:`readings_to_goal`'s counts in words: "more than ``top``" when censored."""
    m = float(to_goal.readings.median())
    return f"more than {top}" if m >= cap else f"{m:.0f}"


def _fit_at(small: pd.DataFrame, method: str, goal_deg: float) -> str:
    """The net's median training RMS at the largest size against the goal: a net short of the goal on
    its own training readings lacks a fit, not (only) readings."""
    part = small[small.method == method]
    n = int(part.n_train.max())
    train = float(part[part.n_train == n].train_rms_deg.median())
    return (
        f"at {n} readings the net's median training RMS is {train:.3g} deg "
        f"({'above' if train > goal_deg else 'within'} the goal)"
    )


def sample_claims(
    small: pd.DataFrame, runs: pd.DataFrame, big_hidden: int, n_full: int
) -> list[Claim]:
    """Register B19 from the small-sample runs ``small`` and the seed study ``runs`` (for the physical
    model's test RMS on the full sweep): per goal of :data:`GOAL_FACTORS` and trainer of the 1-M-1 net,
    the fewest readings to the goal of the net minus the back-tuned ELM's, paired by seed, boundary 0,
    holds above (:func:`readings_to_goal`, capped at ``n_full``)."""
    floor_deg = float(per_seed(runs, "physical").iloc[0])
    adam, lm = big_net_labels(big_hidden)
    sizes = ", ".join(str(int(n)) for n in sorted(small.n_train.unique()))
    top = int(small.n_train.max())
    out = []
    for factor in GOAL_FACTORS:
        goal = factor * floor_deg
        elm = readings_to_goal(small, ELM_LABEL, goal, n_full)
        for net_label, how, tag in (
            (adam, "Adam from U(-1, 1)", "adam"),
            (lm, "MATLAB trainlm, Nguyen-Widrow", "trainlm"),
        ):
            net = readings_to_goal(small, net_label, goal, n_full)
            est, short = verdicts.attempt(
                paired_seed_difference,
                net.readings.astype(float).rename("net readings"),
                elm.readings.astype(float).rename("ELM readings"),
            )
            out.append(
                Claim(
                    f"the ELM reaches the test-RMS goal with fewer readings than an over-sized net "
                    f"[{how}, goal {factor:g} x the floor]",
                    _PAPER_B19,
                    reading=_READING,
                    statistic=f"fewest training readings whose test RMS reaches the goal, "
                    f"1-{int(big_hidden)}-1 net - back-tuned ELM, paired by seed",
                    estimate=est,
                    boundary=0.0,
                    holds_when="above",
                    unit="readings",
                    spec="{:.3g}",
                    decided_by=(
                        f"the goal: {factor:g} x the physical model's test RMS on the full sweep",
                        f"training sizes {sizes} (evenly spread readings of sweep 1); a run short "
                        f"of the goal at every size counts at {int(n_full)} readings",
                        f"the over-sized net's trainer: {how} (the patent does not say)",
                        TRAINING_ONLY,
                    ),
                    why="; ".join(
                        t
                        for t in (short, _censoring(net, elm), _fit_at(small, net_label, goal))
                        if t
                    ),
                    ours=f"goal {goal:.3g} deg; {_count(elm, n_full, top)} vs "
                    f"{_count(net, n_full, top)} readings (medians)",
                    key=f"b_samples_{tag}" + ("" if factor == GOAL_FACTORS[0] else "_loose"),
                )
            )
    return out
