"""Paper A's contribution (2): "training the network weights with ADE overcomes the difficulty of choosing
the BP network's initial weights" (A15), judged on the chapter's existing seed runs (no new fits).

The difficulty of choosing BP's initial weights is that some random starts end far from the best fit the
data allow (a local minimum, a poor stop); a start that overcomes it leaves fewer such runs.  The same
trainer (MATLAB's ``trainlm``) is started two ways on the same seeds: from Nguyen-Widrow weights (MATLAB's
BP, ``bp_matlab``) and from ADE's best individual (``ade_bp_full_trainlm``, reading 4; reading 2's short DE
stage and the validation-stop variants as sensitivity; pure ADE, reading 1, with no ``trainlm`` at all).

A run is *far from the floor* when its test RMS exceeds :data:`FAR_FACTOR` times the test RMS of the exact
physical model fitted to the same training sweep (the chapter's noise floor, ``physical``), a threshold fixed
before the runs::

    share(X) = #{seeds s : rms_X(s) > 2 rms_floor} / n
    statistic = share(BP) - share(ADE-BP)              (holds above 0)

with a percentile bootstrap over the seeds (the two runs of one seed resampled together).  The spread of
the test RMS over the seeds, IQR(BP) / IQR(ADE-BP) (holds above 1), is the sensitivity statistic.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ... import verdicts
from ...claims import Claim
from ...errors import InputError
from ...methods.compass_methods import METHODS, R1, R2, R2V, R4, R4V
from ...seeding import sequence
from .sweeps import TRAINING_ONLY, per_seed

#: A run is far from the floor above this multiple of the physical model's test RMS (fixed before the runs).
FAR_FACTOR = 2.0
#: Entropy of the bootstrap (spawn key: the row's index in :data:`PAIRS`, then 0 share, 1 IQR ratio).
BOOTSTRAP_ENTROPY = 15
#: (reading, ADE-started method, randomly started method with the same trainer, IQR row too).
PAIRS = (
    (R4, "ade_bp_full_trainlm", "bp_matlab", True),
    (R2, "ade_bp_hybrid_trainlm", "bp_matlab", True),
    (R4V, "ade_bp_full_trainlm_val", "bp_matlab_val", False),
    (R2V, "ade_bp_hybrid_trainlm_val", "bp_matlab_val", False),
    (R1, "ade_bp_pure", "bp_matlab", False),
)
#: The rows' claim texts.
SHARE_TEXT = "ADE's start leaves fewer runs far from the floor than random BP starts"
SPREAD_TEXT = "ADE's start narrows the spread of the test RMS over seeds"
_PAPER = "ADE training overcomes the difficulty of choosing BP's initial weights (no numbers)"


def far_share(rms, floor_rms: float, factor: float = FAR_FACTOR) -> float:
    """Share of runs whose test RMS exceeds ``factor`` x ``floor_rms``."""
    r = np.asarray(rms, dtype=float)
    return float(np.mean(r > factor * floor_rms))


def iqr(x) -> float:
    """Interquartile range (75th minus 25th percentile)."""
    q75, q25 = np.percentile(np.asarray(x, dtype=float), [75, 25])
    return float(q75 - q25)


def _pair(runs: pd.DataFrame, ade: str, bp: str) -> tuple[np.ndarray, np.ndarray]:
    a, b = per_seed(runs, ade), per_seed(runs, bp)
    common = a.index.intersection(b.index).sort_values()
    if len(common) < 2:
        raise InputError(f"{ade} and {bp}: need at least 2 common seeds, got {len(common)}")
    return b.loc[common].to_numpy(float), a.loc[common].to_numpy(float)


def share_difference(bp, ade, floor_rms: float, key: int) -> verdicts.Estimate:
    """share(BP) - share(ADE-BP) of runs far from the floor, percentile bootstrap over the seeds."""

    def stat(b, a):
        return far_share(b, floor_rms) - far_share(a, floor_rms)

    return verdicts.bootstrap([bp, ade], stat, seed=sequence(BOOTSTRAP_ENTROPY, key, 0))


def spread_ratio(bp, ade, key: int) -> verdicts.Estimate:
    """IQR(BP) / IQR(ADE-BP) of the test RMS over the seeds, percentile bootstrap over the seeds.  A
    resample whose ADE-BP runs are all equal has no ratio: refused (:class:`InputError`)."""
    if iqr(ade) <= 0:
        raise InputError("spread ratio: the ADE-started runs have no spread (IQR 0)")

    def stat(b, a):
        d = iqr(a)
        return iqr(b) / d if d > 0 else np.inf

    with np.errstate(invalid="ignore"):  # a resample without ADE-BP spread: inf, refused below
        est = verdicts.bootstrap([bp, ade], stat, seed=sequence(BOOTSTRAP_ENTROPY, key, 1))
    if not np.isfinite(est.hi):
        raise InputError("spread ratio: resamples with no ADE-BP spread (IQR 0)")
    return est


def initial_weight_claims(runs: pd.DataFrame, factor: float = FAR_FACTOR) -> list[Claim]:
    """A15 from the chapter's seed study ``runs``
    (:func:`~navlib.studies.compass.turntable.seed_study`, which must hold ``physical`` and the methods of
    :data:`PAIRS`; a pair missing from ``runs`` is skipped): per reading of :data:`PAIRS`, the share of
    runs far from the floor, BP minus ADE-BP (holds above 0), and for readings 4 and 2 the spread ratio
    IQR(BP) / IQR(ADE-BP) (holds above 1)."""
    floor = per_seed(runs, "physical")
    floor_rms = float(floor.iloc[0])
    if not np.isfinite(floor_rms) or floor_rms <= 0:
        raise InputError(f"initial_weight_claims: floor RMS {floor_rms!r} must be positive")
    have = set(runs.method)
    out = []
    for k, (reading, ade, bp, with_iqr) in enumerate(PAIRS):
        if ade not in have or bp not in have:
            continue
        b, a = _pair(runs, ade, bp)
        nb, na = int(np.sum(b > factor * floor_rms)), int(np.sum(a > factor * floor_rms))
        how = (
            f"{METHODS[bp].label} (random Nguyen-Widrow start) against {METHODS[ade].label} (ADE's "
            "best individual as the start), the same seeds",
            f"far from the floor: test RMS above {factor:g} x the physical model's "
            f"{floor_rms:.3f} deg",
            TRAINING_ONLY,
        )
        est, short = verdicts.attempt(share_difference, b, a, floor_rms, k)
        out.append(
            Claim(
                SHARE_TEXT,
                _PAPER,
                reading=reading,
                source="paper",
                statistic=f"share of runs with test RMS above {factor:g} x the floor RMS, BP - "
                "ADE-BP over the same seeds (bootstrap over seeds)",
                estimate=est,
                boundary=0.0,
                holds_when="above",
                unit="share of runs",
                spec="{:.2f}",
                decided_by=how,
                why=short,
                ours=f"{nb} of {b.size} BP runs vs {na} of {a.size} ADE-BP runs far from the floor",
                key=f"a_init_share_{k}",
            )
        )
        if not with_iqr:
            continue
        est, short = verdicts.attempt(spread_ratio, b, a, k)
        out.append(
            Claim(
                SPREAD_TEXT,
                _PAPER,
                reading=reading,
                source="paper",
                statistic="interquartile range of the test RMS over seeds, BP / ADE-BP (bootstrap "
                "over seeds)",
                estimate=est,
                boundary=1.0,
                holds_when="above",
                unit="",
                spec="{:.2f}",
                decided_by=how,
                why=short,
                ours=f"IQR {iqr(b):.4f} vs {iqr(a):.4f} deg",
                key=f"a_init_spread_{k}",
            )
        )
    return out


def initial_weight_table(runs: pd.DataFrame, factor: float = FAR_FACTOR) -> pd.DataFrame:
    """Per pair of :data:`PAIRS` held by ``runs``: the two methods, runs far from the floor (count of
    runs), median and IQR of the test RMS (deg)."""
    floor_rms = float(per_seed(runs, "physical").iloc[0])
    rows = []
    for reading, ade, bp, _ in PAIRS:
        if ade not in set(runs.method) or bp not in set(runs.method):
            continue
        b, a = _pair(runs, ade, bp)
        for mid, r in ((bp, b), (ade, a)):
            rows.append(
                {
                    "reading": reading,
                    "method": METHODS[mid].label,
                    "runs": r.size,
                    f"runs above {factor:g} x floor": int(np.sum(r > factor * floor_rms)),
                    "median test rms (deg)": float(np.median(r)),
                    "IQR (deg)": iqr(r),
                }
            )
    return pd.DataFrame(rows)
