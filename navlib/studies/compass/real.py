"""Paper A's and document B's compensation methods on a real compass: BROAD's level sweeps.

The compass chapter judges every claim on our simulated compass; where that simulator decides the answer
(the exact planar model *is* our simulator, so nothing can beat it; the uncompensated range was set to match
the paper's) or where the verdict moves between drawn compasses, only real measurements can decide.  This
module runs the workbench's comparison (:func:`navlib.workbench.compare.compare`, ``navlib compare
compass``) on BROAD's real level sweeps (Laidig et al. 2021, CC BY 4.0; ``../shared/realdata/broad/level``,
read there and never copied into the repository) and judges those claims again on them, each as a
:class:`navlib.claims.Claim` with ``data="real"`` and the simulated row's wording.

Two recordings, two questions (:data:`RECORDINGS`):

- **BROAD trial 05** (``broad_trial05_level.csv``): one session, two sweeps (before and after t = 100 s);
  every method is fitted on one sweep and scored on the other, both ways (the comparison's ``sweep`` split).
  This is paper A's protocol (fit on sweep 1, test on an independent sweep 2 of the same compass), so its
  rows are the *primary* rows of the real-data claims.
- **BROAD trials 2, 3, 5, 7 pooled** (``broad_trials_level_by_trial.csv``): the file holds one pass per
  trial (its ``sweep`` column is the trial), so no trial has two sweeps and a per-trial sweep split does
  not exist; instead the pooled file is split by ``sweep`` = trial: each trial held out once, the methods
  fitted on the other three (leave one session out).  That asks another question, whether a calibration
  carries to another session: the local field differs between sessions and the reference's north moves by
  -3.5..+0.8 deg between trials (BROAD's README), which no method fitted on other sessions can know.  Its
  rows are the claims' sensitivity (reading ``"<primary reading>; <this recording>"``).

Methods: the comparison's default list (uncompensated; the 8-position LS under the three models; the exact
planar model fitted to every training reading; MATLAB's BP; DE-BP and ADE-BP in the primary reading of
paper A's register, reading 4: the full DE stage, then ``trainlm``; the plain and the back-tuned ELM), with
the chapter's settings (:class:`navlib.methods.compass_methods.MethodParams`).  The 8-position LS takes,
for each of 0, 45, ..., 315 deg true heading, the nearest training reading within ``ls_tolerance_deg``
(``--ls-tolerance``; at most 22.5 deg, half the spacing, so that no reading serves two positions); where a
fold's training part has no reading that close to a position the LS is left out with the reason
(``CompareResult.not_run``) and the claims that need it cannot be judged (*not run*), saying which position
is missing and by how much.

Every stochastic method runs over the same ``seeds`` (spawn keys of one seed, the comparison's rule), so
every claim is a paired difference of held-out RMS over the same seeds (a deterministic method pairs its
one value with every seed), judged by :func:`navlib.verdicts.decide`.  The intervals cover the training
randomness, not another recording of the compass.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ... import claims as registry
from ... import verdicts
from ...claims import Claim
from ...errors import InputError, check_param
from ...methods.compass_methods import LS_MODELS, METHODS, MethodParams
from ...paths import ROOT
from ...plotstyle import legend_below
from ...workbench.compare import CompareResult, compare
from ...workbench.compare import report_figure as _compare_figure
from .ellipse import ELLIPSE_TEXT
from .ellipse import PAPER_TEXT as ELLIPSE_PAPER_TEXT
from .explicit_model import EXPLICIT_TEXT
from .explicit_model import PAPER_TEXT as EXPLICIT_PAPER_TEXT
from .parameters import LS_TOLERANCE_MAX_DEG
from .sweeps import ordering_rate, paired_rms_difference, per_seed

#: Where BROAD's level compass sweeps live (beside the repository, never inside it).
LEVEL_DIR = ROOT.parent / "shared" / "realdata" / "broad" / "level"


@dataclass(frozen=True)
class Recording:
    """One real recording: ``key``, its ``file`` in :data:`LEVEL_DIR`, a ``label`` for tables and the
    ``question`` its split asks; ``primary``: whether its rows are the claims' primary rows."""

    key: str
    file: str
    label: str
    question: str
    primary: bool


#: The recordings and what their sweep split asks (module docstring).
RECORDINGS = (
    Recording(
        "trial05",
        "broad_trial05_level.csv",
        "BROAD trial 05",
        "one session: fitted on one sweep, scored on the other, both ways",
        True,
    ),
    Recording(
        "sessions",
        "broad_trials_level_by_trial.csv",
        "BROAD trials 2, 3, 5, 7",
        "another session (each trial held out once, fitted on the other three)",
        False,
    ),
)


@dataclass
class RealCompass:
    """The comparisons on the real recordings (``results[key]``, a
    :class:`navlib.workbench.compare.CompareResult` per :data:`RECORDINGS` key), the settings they ran
    with and the chapter's method settings."""

    results: dict[str, CompareResult]
    seeds: int
    seed: int
    ls_tolerance_deg: float
    params: MethodParams

    def recording(self, key: str) -> Recording:
        return next(r for r in RECORDINGS if r.key == key)


def available(folder=None) -> bool:
    """True when every file of :data:`RECORDINGS` is in ``folder`` (default :data:`LEVEL_DIR`)."""
    folder = Path(folder) if folder is not None else LEVEL_DIR
    return all((folder / r.file).is_file() for r in RECORDINGS)


def real_compass_study(
    seeds: int = 10,
    seed: int = 0,
    ls_tolerance_deg: float = LS_TOLERANCE_MAX_DEG,
    params: MethodParams | None = None,
    methods=None,
    folder=None,
    workers: int = 1,
    scheduler: str | None = None,
) -> RealCompass | None:
    """Run the comparison (:func:`navlib.workbench.compare.compare`, split by sweep) on each recording of
    :data:`RECORDINGS`.

    Parameters
    ----------
    seeds : int
        Runs of every stochastic method, the same seeds for all (at least 6 for a 95 % interval).
    seed : int
        Entropy of the runs' generators (spawn keys ``(1, fold, k)``).
    ls_tolerance_deg : float
        How far from each of the 8 positions the reading the 8-position LS uses may lie (deg, at most
        22.5); the LS is left out, with the reason, where a fold's training part has none that close.
    params : MethodParams, optional
        The methods' settings (the chapter's); default :class:`navlib.methods.compass_methods.MethodParams`.
    methods : str or sequence of str, optional
        Method ids (default: the comparison's default list).
    folder : path, optional
        Where the recordings are (default :data:`LEVEL_DIR`).
    workers, scheduler
        Where the runs go (:func:`navlib.engine.run`; the numbers do not depend on it).

    Returns
    -------
    RealCompass or None
        None when the recordings are not there (the chapter then says so in one line).
    """
    check_param("seeds", seeds, lo=1, integer=True)
    check_param("ls_tolerance_deg", ls_tolerance_deg, lo=0, hi=LS_TOLERANCE_MAX_DEG)
    if params is not None and not isinstance(params, MethodParams):
        raise InputError("parameter params: must be a navlib.methods.compass_methods.MethodParams")
    folder = Path(folder) if folder is not None else LEVEL_DIR
    if not available(folder):
        return None
    params = params or MethodParams()
    results = {
        r.key: compare(
            "compass",
            folder / r.file,
            methods=methods,
            split="sweep",
            seeds=seeds,
            seed=seed,
            workers=workers,
            scheduler=scheduler,
            ls_tolerance_deg=ls_tolerance_deg,
            params=params,
        )
        for r in RECORDINGS
    }
    return RealCompass(results, int(seeds), int(seed), float(ls_tolerance_deg), params)


# ------------------------------------------------------------------------------------------ tables
def _iv(v: float, lo: float, hi: float, spec: str) -> str:
    if not np.isfinite(v):
        return "–"
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo == hi:
        return spec.format(v)
    return f"{spec.format(v)} [{spec.format(lo)}, {spec.format(hi)}]"


#: The verdict column's words for the comparison's findings against the best method.
FINDINGS = {"best": "best", "best is better": "worse", "not told apart": "not told apart"}


def method_table(real: RealCompass, key: str = "trial05") -> pd.DataFrame:
    """One recording's comparison, best first: method, held-out RMS (deg; median over the seeds with
    its 95 % interval, one exact value for a deterministic method), the paired difference to the best
    method (deg, with its interval) and the verdict against the best (:func:`navlib.verdicts.decide` on
    that difference, boundary 0: *worse* than the best or *not told apart*; a method better than the best
    cannot occur)."""
    res = real.results[key]
    t = res.table()
    return pd.DataFrame(
        {
            "method": t["label"],
            "held-out RMS (deg)": [_iv(*v, "{:.3f}") for v in zip(t.rms, t.rms_lo, t.rms_hi)],
            "minus best (deg)": [
                "–" if m == res.best else _iv(*v, "{:+.3f}")
                for m, *v in zip(t.method, t.vs_best, t.vs_best_lo, t.vs_best_hi)
            ],
            "against the best": [FINDINGS.get(f, f) for f in t["finding"]],
        }
    )


def folds_table(real: RealCompass) -> pd.DataFrame:
    """Per recording and fold: what was fitted and what was scored, with the row counts."""
    rows = []
    for r in RECORDINGS:
        res = real.results[r.key]
        for k, f in enumerate(res.folds):
            rows.append(
                {
                    "recording": r.label,
                    "fold": k + 1,
                    "fitted on": f"{f.train_what} ({f.train.size} rows)",
                    "scored on": f"{f.test_what} ({f.test.size} rows)",
                }
            )
    return pd.DataFrame(rows)


def not_run(real: RealCompass) -> pd.DataFrame:
    """The default methods left out of each recording's comparison and why (the 8-position LS without a
    reading near each of its positions)."""
    rows = [
        {"recording": r.label, "methods": ", ".join(METHODS[m].label for m in ms), "why": why}
        for r in RECORDINGS
        for why, ms in _not_run_by_reason(real.results[r.key]).items()
    ]
    return pd.DataFrame(rows, columns=["recording", "methods", "why"])


def _not_run_by_reason(res: CompareResult) -> dict[str, list[str]]:
    by: dict[str, list[str]] = {}
    for x in res.not_run:
        by.setdefault(x["why"], []).append(x["method"])
    return by


def runs_frame(res: CompareResult) -> pd.DataFrame:
    """A comparison as paper A's seed-study runs (:func:`navlib.studies.compass.turntable.seed_study`'s columns
    ``method``, ``seed``, ``rms_deg``, ``min_deg``, ``max_deg``; a deterministic method has the one seed
    -1): the held-out RMS and error range of every run, so the chapter's statistics
    (:func:`~navlib.studies.compass.sweeps.paired_rms_difference`, :func:`~navlib.studies.compass.sweeps.ordering_rate`)
    apply unchanged."""
    rows = []
    for mid in res.methods:
        e = res.errors[mid]
        seeds = range(e.shape[0]) if res.stochastic[mid] else [-1]
        for k, run, rms in zip(seeds, e, res.rms(mid)):
            rows.append(
                {
                    "method": mid,
                    "seed": int(k),
                    "rms_deg": float(rms),
                    "min_deg": float(run.min()),
                    "max_deg": float(run.max()),
                }
            )
    return pd.DataFrame(rows)


# ------------------------------------------------------------------------------------------ claims
@dataclass(frozen=True)
class RealClaim:
    """A register row judged again on real data: the row's ``claim`` text (the simulated row's), the
    ``better`` and ``worse`` method ids of "better beats worse" (``kind="beats"``) or the (LS, BP, DE-BP,
    ADE-BP) ids of the ordering (``kind="order"``), and a glue ``key``."""

    claim: str
    kind: str
    methods: tuple[str, ...]
    key: str


def real_claim_specs(params: MethodParams | None = None) -> list[RealClaim]:
    """The claims of paper A and document B judged again on real data: those the simulator decides by
    construction or whose verdict moves between drawn compasses, and those the comparison can answer
    directly (the register rows, in their primary reading: paper A's reading 4, full DE + trainlm;
    document B):

    - paper A: ADE-BP beats DE-BP (A01, the headline; moves between readings), DE-BP beats BP (A03: flips
      between drawn compasses), ADE-BP and BP beat the 8-position LS (A02: flips against the planar LS; A04),
      one run shows LS > BP > DE-BP > ADE-BP (A05: moves on two of five drawn compasses) and ADE-BP beats
      ref. [3]'s ellipse (hard/soft-iron) model, the exact planar model (A20: decided by construction on
      our simulator, which *is* that model; :mod:`navlib.studies.compass.ellipse`);
    - document B: the back-tuned ELM improves the uncompensated heading (B01, its headline), beats the
      8-position LS (B05) and MATLAB's BP (B07), the back-tuned ELM beats the explicit (ellipse) model fitted
      on its training readings (B14, the patent's "any explicit error model can hardly include all error
      factors"; B08, the book's "the implicit ELM beats the exact physical model", is the same difference
      on our simulator, which *is* that model, so its real-data row is B14's), back-tuning beats a plain ELM
      (B09).

    Not judged again: the error-range claims (A06-A09: widths against the paper's compass at its noise),
    the uncompensated envelope (A10: a property of the paper's compass, which BROAD's is not), the
    convergence and stability of the DE stage (A11, A12: training curves, not held-out error), the LS
    sample-size claim (A18), the patent's glitch, node-count and small-sample claims (B02-B04: other
    experiments) and the ELM against paper A's DE-initialised BP (B06: reading 2, not in the comparison)."""
    p = params or MethodParams()
    out = [
        RealClaim(
            "ADE-BP beats DE-BP",
            "beats",
            ("ade_bp_full_trainlm", "de_bp_full_trainlm"),
            "real_a_ade_de",
        ),
        RealClaim("DE-BP beats BP", "beats", ("de_bp_full_trainlm", "bp_matlab"), "real_a_de_bp"),
        RealClaim(ELLIPSE_TEXT, "beats", ("ade_bp_full_trainlm", "physical"), "real_a_ellipse"),
    ]
    for ls, name in LS_MODELS.items():
        short = "" if ls == "ls8" else "_" + ls.split("_")[-1]
        out += [
            RealClaim(
                f"ADE-BP beats 8-position LS [{name}]",
                "beats",
                ("ade_bp_full_trainlm", ls),
                f"real_a_ade_ls{short}",
            ),
            RealClaim(
                f"BP beats 8-position LS [{name}]",
                "beats",
                ("bp_matlab", ls),
                f"real_a_bp_ls{short}",
            ),
            RealClaim(
                f"one run shows LS > BP > DE-BP > ADE-BP [{name}]",
                "order",
                (ls, "bp_matlab", "de_bp_full_trainlm", "ade_bp_full_trainlm"),
                f"real_a_order{short}",
            ),
        ]
    out += [
        RealClaim(
            "the back-tuned ELM improves the uncompensated heading",
            "beats",
            ("elm_backtuned", "uncompensated"),
            "real_b_bt_uncompensated",
        )
    ]
    out += [
        RealClaim(
            f"ELM back-tuned beats 8-position LS [{name}]",
            "beats",
            ("elm_backtuned", ls),
            "real_b_bt_ls" + ("" if ls == "ls8" else "_" + ls.split("_")[-1]),
        )
        for ls, name in LS_MODELS.items()
    ]
    out += [
        RealClaim(
            "ELM back-tuned beats BP MATLAB (trainlm)",
            "beats",
            ("elm_backtuned", "bp_matlab"),
            "real_b_bt_bp_matlab",
        ),
        RealClaim(EXPLICIT_TEXT, "beats", ("elm_backtuned", "physical"), "real_b_bt_physical"),
        RealClaim(
            f"back-tuning beats a plain ELM of {p.elm_nodes} nodes",
            "beats",
            ("elm_backtuned", "elm"),
            "real_b_plain_elm",
        ),
    ]
    return out


def _entries() -> dict[str, registry.Entry]:
    """The compass chapter's register entries by the claim text of each of their rows."""
    return {text: e for e in registry.entries("compass") for text in e.rows}


def _paper_text(entry: registry.Entry, spec: RealClaim, paper: pd.DataFrame) -> str:
    """What the paper prints for the claim: the same text as the simulated row's."""
    pr = paper.set_index("method")

    def rng(row):
        r = pr.loc[row]
        return f"{r.error_min_deg:+.2f}..{r.error_max_deg:+.2f}"

    if spec.kind == "order":
        return "one run per method"
    if entry.id == "A20":
        return ELLIPSE_PAPER_TEXT
    if entry.register == "paper_a":
        better, worse = (METHODS[m].paper_row for m in spec.methods)
        return f"{rng(better)} vs {rng(worse)} deg"
    return {
        "B01": "compensates the nonlinear error and improves the heading accuracy (no numbers)",
        "B05": "implicit beats explicit models (no numbers)",
        "B07": "fewer local minima than random starting weights (no numbers)",
        "B14": EXPLICIT_PAPER_TEXT,
        "B09": "higher accuracy",
    }[entry.id]


def _reading(entry: registry.Entry, rec: Recording) -> str:
    """The register entry's primary reading; on a recording that is not the primary one, with the
    recording: ``"4: full DE + trainlm; BROAD trials 2, 3, 5, 7"``."""
    return entry.primary_reading if rec.primary else f"{entry.primary_reading}; {rec.label}"


def real_claims(real: RealCompass, paper: pd.DataFrame) -> list[Claim]:
    """The claims of :func:`real_claim_specs` on each recording, as :class:`navlib.claims.Claim` with
    ``data="real"``, the simulated row's wording, the register entry's origin as ``source`` (the paper's
    claim or the book's own comparison), its primary reading (trial 05's rows; the pooled sessions' rows
    add the recording to the reading) and paper A's printed ranges (``paper``, the rows of
    ``data/paper_a_error_ranges.csv``) as the paper's text.

    "X beats Y": RMS(Y) - RMS(X) of the held-out rows over the same seeds
    (:func:`navlib.studies.compass.sweeps.paired_rms_difference`), boundary 0, holds above; "one run shows LS > BP
    > DE-BP > ADE-BP": the share of seeds whose runs show the ordering (Wilson interval, boundary 0.5, as
    on the simulated compass, :func:`navlib.studies.compass.sweeps.ordering_rate`).  Nothing is true by
    construction on real data.  A claim whose method was left out of the comparison (the 8-position LS
    without its 8 headings) has no statistic and says why (*not run*); one whose methods were not asked
    for is skipped."""
    entries = _entries()
    out = []
    for rec in RECORDINGS:
        res = real.results[rec.key]
        runs = runs_frame(res)
        skipped = {x["method"]: x["why"] for x in res.not_run}
        decided = (
            f"{rec.label}, real measurements (BROAD, Laidig et al. 2021): {rec.question}",
            "the interval covers training randomness (seeds), not another recording of the compass",
        )
        for spec in real_claim_specs(real.params):
            e = entries[spec.claim]
            missing = [m for m in spec.methods if m not in res.methods]
            if any(m not in skipped for m in missing):
                continue  # not asked for: not judged
            reading = _reading(e, rec)
            how = (
                (f"{e.primary_reading}: the full DE stage, then MATLAB trainlm",)
                if e.register == "paper_a"
                else ("our a-priori ELM settings (the chapter's)",)
            )
            common = dict(
                paper=_paper_text(e, spec, paper),
                reading=reading,
                source=e.origin,
                data="real",
                key=spec.key + ("" if rec.primary else f"_{rec.key}"),
            )
            if missing:  # left out (the LS without its 8 headings): one row per entry
                if spec.claim != e.primary_claim:
                    continue
                why = skipped[missing[0]]
                out.append(
                    Claim(
                        spec.claim,
                        statistic=e.statistic,
                        decided_by=decided,
                        why=f"not run: {METHODS[missing[0]].label} {why}",
                        **common,
                    )
                )
                continue
            if spec.kind == "order":
                est = ordering_rate(runs, *spec.methods)
                out.append(
                    Claim(
                        spec.claim,
                        statistic="share of seeds whose runs show the ordering by held-out RMS",
                        estimate=est,
                        boundary=0.5,
                        holds_when="above",
                        decided_by=decided + how,
                        spec="{:.2f}",
                        why="boundary 0.5: the paper shows one run per method as typical",
                        ours=f"{round(est.value * est.n)} of {est.n} seeds",
                        **common,
                    )
                )
                continue
            better, worse = spec.methods
            est, short = verdicts.attempt(paired_rms_difference, runs, worse, better)
            rb, rw = per_seed(runs, better), per_seed(runs, worse)
            out.append(
                Claim(
                    spec.claim,
                    statistic=f"held-out RMS {METHODS[worse].label} - held-out RMS "
                    f"{METHODS[better].label}, paired by seed, deg",
                    estimate=est,
                    boundary=0.0,
                    holds_when="above",
                    unit="deg",
                    decided_by=decided + how,
                    why=short,
                    ours=f"{rb.median():.3f} vs {rw.median():.3f} deg rms",
                    **common,
                )
            )
    return out


# ------------------------------------------------------------------------------------------ the answer
#: What the section glues when the recordings are absent.
ABSENT = "not computed (BROAD data absent)"
#: The texts :func:`answer` returns (the section's prose glues each as ``real_<key>``).
ANSWER_KEYS = (
    "best",
    "best_rms",
    "runner_up",
    "by",
    "by_verdict",
    "uncompensated",
    "ranking_holds",
    "de_bp",
    "ade_de",
    "ls",
    "b_uncompensated",
    "b_physical",
    "b_plain",
    "physical",
    "sessions_best",
    "sessions_best_rms",
    "sessions_uncompensated",
    "sessions_networks",
)


def answer(real: RealCompass | None, claims: list[Claim]) -> dict[str, str]:
    """The section's answer in parts, texts to glue (:data:`ANSWER_KEYS`; each :data:`ABSENT` when
    ``real`` is None): on trial 05 (the primary recording) ``best`` (the method with the smallest median
    held-out RMS), ``best_rms`` (its RMS with interval, deg), ``runner_up``, ``by`` (how much worse the
    runner-up is, paired difference with interval, deg) and ``by_verdict`` (told apart or not),
    ``uncompensated`` (deg); whether paper A's ranking holds (``ranking_holds``: "holds" when every one of
    its comparisons judged on real data is reproduced, "does not hold" when none is, else "holds only in
    part"), the verdicts of "DE-BP beats BP" (``de_bp``) and "ADE-BP beats DE-BP" (``ade_de``), what became
    of the 8-position LS (``ls``); document B's headline (``b_uncompensated``), the back-tuned ELM against
    the explicit (ellipse) model on its training readings (``b_physical``, B14) and "back-tuning beats
    a plain ELM" (``b_plain``); the physical model's verdict against the best (``physical``); on the
    pooled sessions the best method, its RMS, the uncompensated RMS and the networks' verdict against the
    best (``sessions_*``)."""
    if real is None:
        return dict.fromkeys(ANSWER_KEYS, ABSENT)
    res = real.results["trial05"]
    t = res.table()
    best, second = t.iloc[0], t.iloc[1]
    entries = _entries()
    mine = {
        c.claim: c
        for c in claims
        if c.data == "real" and c.reading == _reading(entries[c.claim], RECORDINGS[0])
    }

    def said(text):
        c = mine.get(text)
        return "not judged" if c is None else c.verdict_label

    def rms_of(table, mid):
        return (
            f"{float(table.loc[table.method == mid, 'rms'].iloc[0]):.2f}"
            if mid in set(table.method)
            else "–"
        )

    def row_verdict(table, mid):
        if mid not in set(table.method):
            return "not run"
        f = table.loc[table.method == mid, "finding"].iloc[0]
        return FINDINGS.get(f, f)

    ranking = [
        c
        for c in mine.values()
        if entries[c.claim].id in ("A01", "A02", "A03", "A04", "A05") and c.estimate is not None
    ]
    rep = [c.verdict == "reproduced" for c in ranking]
    holds = (
        "holds"
        if rep and all(rep) and len(ranking) == 5
        else "does not hold"
        if not any(rep)
        else "holds only in part"
    )
    why_ls = next((x["why"] for x in res.not_run if x["method"] == "ls8"), None)
    ls = (
        f"the 8-position LS cannot be placed on these sweeps: even {real.ls_tolerance_deg:g} deg from its "
        f"positions, {why_ls.split(' and ', 1)[-1]}"
        if why_ls
        else f"the 8-position LS (Smith's terms) ranks {int(t.index[t.method == 'ls8'][0]) + 1} of {len(t)}"
        if "ls8" in res.methods
        else "the 8-position LS was not run"
    )
    st = real.results["sessions"].table()
    nets = [
        m for m in ("bp_matlab", "de_bp_full_trainlm", "ade_bp_full_trainlm") if m in set(st.method)
    ]
    return {
        "best": str(best.label),
        "best_rms": _iv(best.rms, best.rms_lo, best.rms_hi, "{:.2f}"),
        "runner_up": str(second.label),
        "by": _iv(second.vs_best, second.vs_best_lo, second.vs_best_hi, "{:.2f}"),
        "by_verdict": FINDINGS.get(second.finding, second.finding),
        "uncompensated": rms_of(t, "uncompensated"),
        "ranking_holds": holds,
        "de_bp": said("DE-BP beats BP"),
        "ade_de": said("ADE-BP beats DE-BP"),
        "ls": ls,
        "b_uncompensated": said("the back-tuned ELM improves the uncompensated heading"),
        "b_physical": said(EXPLICIT_TEXT),
        "b_plain": said(f"back-tuning beats a plain ELM of {real.params.elm_nodes} nodes"),
        "physical": row_verdict(t, "physical"),
        "sessions_best": str(st.iloc[0].label),
        "sessions_best_rms": _iv(st.iloc[0].rms, st.iloc[0].rms_lo, st.iloc[0].rms_hi, "{:.2f}"),
        "sessions_uncompensated": rms_of(st, "uncompensated"),
        "sessions_networks": ", ".join(f"{METHODS[m].label} {row_verdict(st, m)}" for m in nets)
        or "not run",
    }


def verdict_changes(real_claims_: list[Claim], simulated: list[Claim]) -> pd.DataFrame:
    """Every real-data claim beside the verdict of the same claim under the same reading on our simulated
    compass (``simulated``: the chapter's claims): claim, recording, the two verdicts (their cases are in
    the claims' records) and whether they differ ("not run on real data" where the real claim has no
    statistic)."""
    sim = {(c.claim, c.reading): c.verdict for c in simulated if c.data == "simulated"}
    rows = []
    for c in real_claims_:
        base, _, rest = c.reading.partition("; ")
        rec = next((r for r in RECORDINGS if not r.primary and rest == r.label), RECORDINGS[0])
        s = sim.get((c.claim, base), "–")
        differs = (
            "not run on real data"
            if c.estimate is None
            else "–"
            if s == "–"
            else "yes"
            if s != c.verdict
            else "no"
        )
        rows.append(
            {
                "claim": c.claim,
                "recording": rec.label,
                "simulated compass": s,
                "real compass": c.verdict,
                "differs": differs,
            }
        )
    return pd.DataFrame(
        rows, columns=["claim", "recording", "simulated compass", "real compass", "differs"]
    )


# ------------------------------------------------------------------------------------------ the figure
def real_figure(real: RealCompass, paper: pd.DataFrame, key: str = "trial05"):
    """Error against true heading per method on the recording ``key`` (the workbench's comparison figure,
    :func:`navlib.workbench.compare.report_figure`: the run of median held-out RMS, each held-out sweep in
    its colour, no line across a gap in the headings), with paper A's printed residual range of the same
    method shaded (``paper``: ``data/paper_a_error_ranges.csv``; the compensated methods only: the
    uncompensated range belongs to the paper's compass, not BROAD's)."""
    res = real.results[key]
    fig = _compare_figure(res)
    pr = paper.set_index("method")
    for ax, mid in zip(fig.axes, res.table().method):
        row = METHODS[mid].paper_row
        if row and row != "uncompensated" and row in pr.index:
            ax.axhspan(
                pr.loc[row, "error_min_deg"],
                pr.loc[row, "error_max_deg"],
                color="tab:red",
                alpha=0.25,
                lw=0,
                label="paper A's printed range",
            )
    handles = {}
    for ax in fig.axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    for ax in fig.axes:
        if ax.get_legend() is not None:
            ax.get_legend().remove()
    spare = [ax for ax in fig.axes if not ax.get_visible()]
    if spare:  # an odd number of methods: the key in the empty panel
        spare[0].set_visible(True)
        spare[0].axis("off")
        spare[0].legend(
            list(handles.values()),
            list(handles),
            loc="center",
            title=f"{real.recording(key).label}, held out:",
        )
    else:
        legend_below(fig.axes[-1], handles=list(handles.values()), labels=list(handles), ncol=3)
    return fig


__all__ = [
    "ABSENT",
    "ANSWER_KEYS",
    "LEVEL_DIR",
    "RECORDINGS",
    "RealClaim",
    "RealCompass",
    "Recording",
    "answer",
    "available",
    "folds_table",
    "method_table",
    "not_run",
    "real_claim_specs",
    "real_claims",
    "real_compass_study",
    "real_figure",
    "runs_frame",
    "verdict_changes",
]
