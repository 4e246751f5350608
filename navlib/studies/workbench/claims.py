"""The workbench chapter's claims: the book's own targets for the loop (not a paper's), rates judged on the
worst case's Wilson interval, the real-data claims, and the reference-free heading claim.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ... import verdicts
from ...claims import Claim
from ...errors import InputError
from ...workbench.diagnose import DEFAULT_ALPHA
from .broad_loops import LevelLoops
from .magnets import MagnetStudy
from .parameters import STRUCTURE_BOUND, TARGET_FALSE_ALARMS, TARGET_NAMED, TARGET_QUIET

NOT_IN_PAPER = "(not in the paper)"
#: The level files' claims: file -> (glue key, reading); the other real-data keys: wb_attached, wb_stationary.
LEVEL_CLAIMS = {
    "broad_trial05_level.csv": ("wb_level_trial05", "BROAD trial 05, level sweeps"),
    "broad_trials_level_by_trial.csv": ("wb_level_by_trial", "BROAD trials 2, 3, 5, 7, level"),
}
REALDATA_KEYS = tuple(k for k, _ in LEVEL_CLAIMS.values()) + (
    "wb_attached",
    "wb_stationary",
    "wb_free_heading",
)


@dataclass(frozen=True)
class Case:
    """One case of a rate claim (e.g. one data set and hidden effect): ``k`` of ``n`` independent trials."""

    name: str
    k: int
    n: int

    @property
    def estimate(self) -> verdicts.Estimate:
        """The rate ``k / n`` with its 95 % Wilson interval (:func:`navlib.verdicts.wilson`)."""
        return verdicts.wilson(self.k, self.n)


def rate_cases(frame: pd.DataFrame, by, success: str) -> list[Case]:
    """One :class:`Case` per group of ``frame`` (grouped by the column(s) ``by``), counting the True
    values of the boolean column ``success``."""
    out = []
    for name, g in frame.groupby(by, sort=False):
        name = " / ".join(map(str, name)) if isinstance(name, tuple) else str(name)
        out.append(Case(name, int(g[success].astype(bool).sum()), int(len(g))))
    if not out:
        raise InputError(f"rate_cases: no trials to count ({success!r})")
    return out


def worst_case(cases: list[Case], boundary: float, holds_when: str) -> Case:
    """The case whose Wilson interval decides a rate claim that must hold in **every** case: a case whose
    whole interval lies on the wrong side of ``boundary`` if there is one (the farthest), else the case
    whose interval reaches nearest to the wrong side (lowest lower bound for ``"above"``, highest upper
    bound for ``"below"``).  So the claim is reproduced only if every case's interval is on its side, not
    reproduced if any case's interval is wholly on the other side, and cannot be judged otherwise."""
    if not cases:
        raise InputError("worst_case: no cases")
    if holds_when not in verdicts.SIDES:
        raise InputError(f"worst_case: holds_when={holds_when!r}: must be 'above' or 'below'")
    other = "below" if holds_when == "above" else "above"
    wrong = [
        c
        for c in cases
        if verdicts.on_side(c.estimate.lo, boundary, other)
        and verdicts.on_side(c.estimate.hi, boundary, other)
    ]
    if holds_when == "above":
        return (
            min(wrong, key=lambda c: c.estimate.hi)
            if wrong
            else min(cases, key=lambda c: c.estimate.lo)
        )
    return (
        max(wrong, key=lambda c: c.estimate.lo)
        if wrong
        else max(cases, key=lambda c: c.estimate.hi)
    )


def _wilson_bounds(p: float, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return c - h, c + h


def trials_needed(
    k: int, n: int, boundary: float, holds_when: str, limit: int = 1_000_000
) -> int | None:
    """How many trials a case would need, at its observed rate ``k / n``, for its 95 % Wilson interval
    to lie wholly on one side of ``boundary`` (None if the rate sits on the boundary or more than
    ``limit`` trials would be needed)."""
    p = k / n
    if p == boundary:
        return None

    def decisive(m: int) -> bool:
        lo, hi = _wilson_bounds(p, m)
        return lo > boundary or hi < boundary

    if decisive(n):
        return n
    hi = n
    while not decisive(hi):
        hi *= 2
        if hi > limit:
            return None
    lo = hi // 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if decisive(mid) else (mid, hi)
    return hi


def _sizes(frame: pd.DataFrame) -> str:
    """The effect sizes of a trial study, e.g. "3 and 10 x noise"."""
    return " and ".join(f"{r:g}" for r in sorted(frame.ratio.unique())) + " x noise"


def _levels(frame: pd.DataFrame) -> int:
    """The number of noise levels of a trial study (per data set when several are concatenated)."""
    return (
        int(frame.groupby("data").noise.nunique().max())
        if "data" in frame
        else int(frame.noise.nunique())
    )


def _pct(e: verdicts.Estimate) -> verdicts.Estimate:
    """A Wilson rate in percent (same interval, same rule)."""
    return verdicts.Estimate(100 * e.value, 100 * e.lo, 100 * e.hi, e.rule, e.n)


def _rate_claim(
    claim: str,
    cases: list[Case],
    target: float,
    holds_when: str,
    *,
    statistic: str,
    reading: str,
    decided_by: tuple[str, ...],
    key: str,
    what: str = "",
) -> Claim:
    """A book claim on a rate that must meet ``target`` in every case, judged on the worst case's Wilson
    interval (:func:`worst_case`), in percent; if undecided, ``why`` says how many trials it would need."""
    w = worst_case(cases, target, holds_when)
    need = trials_needed(w.k, w.n, target, holds_when)
    why = ""
    if verdicts.decide(w.estimate.interval, target, holds_when)[1] == "straddles":
        where = f"{w.n} trials in the worst case" if len(cases) > 1 else f"{w.n} trials"
        why = (
            f"{where}; at this rate a decisive interval needs about {need}"
            if need is not None
            else f"{where}; at this rate no number of trials decides it"
        )
    ours = (
        f"worst of {len(cases)}: {w.name}, {w.k}/{w.n}"
        if len(cases) > 1
        else f"{w.k} of {w.n} trials"
    )
    return Claim(
        claim,
        NOT_IN_PAPER,
        reading=reading,
        source="book",
        statistic=statistic,
        estimate=_pct(w.estimate),
        boundary=100 * target,
        holds_when=holds_when,
        unit="%",
        decided_by=decided_by,
        why=why,
        key=key,
        ours=ours + what,
    )


def glance_claims(
    studies: dict,
    ooc: pd.DataFrame,
    level: LevelLoops | None,
    magnets: MagnetStudy | None,
    alpha: float | None = None,
    free_heads: pd.DataFrame | None = None,
) -> list[Claim]:
    """The chapter's claims: the book's own (our users' targets, not a paper's), each judged by the one
    rule of :mod:`navlib.verdicts`.

    ``studies``: data label -> :func:`navlib.workbench.trials.hidden_effect_study` table (the data sets
    the targets are claimed for); ``ooc``: :func:`navlib.workbench.trials.out_of_catalogue_study` table;
    ``level`` and ``magnets``: the real-data studies (None when ``../shared/realdata`` is absent: the
    claims on real data are then left out); ``alpha``: the level of ``diagnose`` in the real-data loops;
    ``free_heads``: :func:`~navlib.studies.workbench.calibrations.reference_free_headings` (its claim,
    :func:`free_vs_reference_claim`, is added).

    Rates are judged on the 95 % Wilson interval of the worst case (one data set and hidden effect; one
    data set; one kind of error): every case must meet the target.  Within a case the trials of both
    effect sizes and both noise levels are pooled (the smaller size is the harder half).  The level
    sweeps are judged file by file on an exact statistic (a deterministic fit of fixed data)."""
    if not studies:
        raise InputError("glance_claims: give at least one hidden-effect study")
    a = f"diagnose at family-wise alpha {DEFAULT_ALPHA:g} (the trials' default)"
    real_a = f"diagnose at family-wise alpha {DEFAULT_ALPHA if alpha is None else alpha:g}"
    frames = [st.assign(data=name) for name, st in studies.items()]
    trials = pd.concat(frames, ignore_index=True)
    hidden, none = trials[trials.hidden != "(none)"], trials[trials.hidden == "(none)"]
    named = rate_cases(hidden, ["data", "hidden"], "correct")
    alarms = [Case(c.name, c.n - c.k, c.n) for c in rate_cases(none, "data", "correct")]
    quiet = rate_cases(ooc, "kind", "quiet")
    data_sets = ", ".join(studies)
    claims = [
        _rate_claim(
            "a hidden catalogued effect is named (our target: >= 95 % of trials)",
            named,
            TARGET_NAMED,
            "above",
            key="wb_named",
            statistic=f"share of trials naming the hidden effect, worst case (data set x hidden "
            f"effect), sizes {_sizes(hidden)} and {_levels(hidden)} noise levels "
            f"pooled, %",
            reading=f"{data_sets}; effect {_sizes(hidden)}",
            decided_by=(
                a,
                "simulated data: random plausible parameters of every catalogued effect",
                "the hidden effect's RMS set to its size x the noise",
            ),
        ),
        _rate_claim(
            "data with nothing missing are called noise (our target: <= 5 % false alarms)",
            alarms,
            TARGET_FALSE_ALARMS,
            "below",
            key="wb_false_alarms",
            statistic=f"share of trials with a false alarm, worst data set, "
            f"{_levels(none)} noise levels pooled per data set, %",
            reading=data_sets,
            decided_by=(
                a,
                "simulated data: a random subset of effects, the model exactly that subset",
            ),
        ),
        _rate_claim(
            "an error outside the catalogue names no catalogued effect (our target: >= 90 %)",
            quiet,
            TARGET_QUIET,
            "above",
            key="wb_quiet",
            statistic=f"share of trials naming no catalogued effect, worst kind of error, sizes "
            f"{_sizes(ooc)} and {_levels(ooc)} noise levels pooled, %",
            reading=f"3- and 4-cycle errors, a step between sweeps, a drift in time; {_sizes(ooc)}",
            decided_by=(
                a,
                "simulated compass sweeps; model = the catalogued effects present + misalignment",
            ),
        ),
    ]
    if level is None or magnets is None:
        return claims
    for name, res in level.results.items():
        amp = max([u["amplitude"] for u in res.unexplained] + [0.0])
        stem = "".join(ch if ch.isalnum() else "_" for ch in Path(name).stem)
        key, reading = LEVEL_CLAIMS.get(name, (f"wb_level_{stem}", f"BROAD {name}"))
        claims.append(
            Claim(
                f"a real level sweep: the loop leaves no structure > {STRUCTURE_BOUND:g}x the residual rms "
                f"(our bound)",
                NOT_IN_PAPER,
                reading=reading,
                source="book",
                statistic="largest unexplained structure amplitude / final residual rms (deterministic fit of "
                "this file)",
                estimate=verdicts.exact(amp / res.final.rms),
                boundary=STRUCTURE_BOUND,
                holds_when="below",
                unit="x rms",
                decided_by=(
                    real_a,
                    "start model: misalignment",
                    "BROAD reference heading (3-deg bins)",
                ),
                key=key,
                ours="consistent with noise"
                if res.consistent_with_noise
                else f"{len(res.unexplained)} unexplained structures named",
            )
        )
    att = magnets.trials[magnets.trials.magnet == "attached"]
    ok = (att["first effect named"] == "hard_iron") & (
        att["final rms (uT)"] < att["calibrated rms (uT)"]
    )
    att_case = Case("BROAD trials 32-36", int(ok.sum()), int(len(att)))
    claims.append(
        _rate_claim(
            "an attached magnet: diagnose names hard_iron first and the error falls (our target: >= 95 %)",
            [att_case],
            TARGET_NAMED,
            "above",
            key="wb_attached",
            statistic="share of attached-magnet trials with hard_iron named first and a lower final rms, %",
            reading="BROAD trials 32-36 (magnet 1-5 cm)",
            decided_by=(
                real_a,
                "the trial-05 calibration, shared by every trial",
                "blocks with attitude blur < 0.01",
            ),
            what=f"; rms {att['calibrated rms (uT)'].median():.1f} -> {att['final rms (uT)'].median():.2f} uT",
        )
    )
    sta = magnets.trials[magnets.trials.magnet == "stationary"]
    pos = sta.outcome.str.contains("position")
    claims.append(
        _rate_claim(
            "a stationary magnet: reported as a field changing with position (our target: >= 90 %)",
            [Case("BROAD trials 28-31", int(pos.sum()), int(len(sta)))],
            TARGET_QUIET,
            "above",
            key="wb_stationary",
            statistic="share of stationary-magnet trials reported as a field changing with position, %",
            reading="BROAD trials 28-31 (moving blocks)",
            decided_by=(
                real_a,
                "the trial-05 calibration, shared by every trial",
                "moving blocks only",
            ),
        )
    )
    if free_heads is not None:
        claims.append(free_vs_reference_claim(free_heads))
    return claims


def free_vs_reference_claim(heads: pd.DataFrame) -> Claim:
    """The book's claim on :func:`~navlib.studies.workbench.calibrations.reference_free_headings`: without
    the optical reference the calibration is as good for heading as the reference-based one -- the RMS
    heading error with the reference-free calibration minus that with the reference-based one, paired over
    the undisturbed trials (median and its order-statistic interval,
    :func:`navlib.verdicts.paired_difference`), at most 0 deg."""
    free = heads["reference-free calibration (deg)"].to_numpy(float)
    ref = heads["reference-based calibration (deg)"].to_numpy(float)
    est = verdicts.paired_difference(free, ref)
    return Claim(
        "without the reference, the calibration's heading error is no larger than with it",
        NOT_IN_PAPER,
        reading=f"BROAD undisturbed trials ({len(heads)}), both calibrated on trial 05",
        source="book",
        statistic="RMS heading error against the optical reference, reference-free minus reference-"
        "based calibration, paired over trials (median), deg",
        estimate=est,
        boundary=0.0,
        holds_when="below",
        unit="deg",
        decided_by=(
            "full ellipsoid (hard iron, scale, soft iron) without reference",
            "the reference-based loop's final model on trial 05",
            "each trial's mean heading offset removed",
        ),
        key="wb_free_heading",
        ours=f"median {np.median(free):.2f} vs {np.median(ref):.2f} deg",
    )
