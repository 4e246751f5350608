"""Paper A's introduction on its reference [3]: "an ellipse-hypothesis error model ... the accuracy is
limited" (A20), against ADE-BP in the register's primary reading (reading 4: the full DE stage, then
``trainlm``).

The ellipse hypothesis is the hard/soft-iron model of a level compass: over a turn, the measured horizontal
field traces an ellipse, ``m_xy = A r(psi) + c``.  In the heading domain that is the exact planar model of
:mod:`navlib.sensors.planar` (five parameters: yaw, hard iron, soft iron), the chapter's ``physical``
method fitted to every training reading.  The statistic is the paired difference of test RMS over the same
seeds::

    RMS(ellipse) - RMS(ADE-BP)        (holds above 0: the ellipse is the less accurate)

On our simulator that model *is* the compass (every simulated error source is affine in ``r``), so the
ellipse fit reaches the noise floor by construction and cannot lose: the simulated row is judged *by
construction*.  Real sweeps decide: BROAD's level sweeps in the real-data section
(:func:`navlib.studies.compass.real.real_claims`, the same row text, ``data="real"``).
"""

from __future__ import annotations

import pandas as pd

from ... import verdicts
from ...claims import Claim
from ...methods.compass_methods import R4
from .sweeps import TRAINING_ONLY, paired_rms_difference, per_seed

#: The row's claim text (the same on the simulated and the real compass).
ELLIPSE_TEXT = "ADE-BP beats the ellipse (hard/soft-iron) model"
#: The ellipse model's method id: the exact planar model fitted to every training reading.
ELLIPSE_ID = "physical"
#: ADE-BP in the register's primary reading.
ADE_ID = "ade_bp_full_trainlm"
#: What paper A says of ref. [3] (no numbers).
PAPER_TEXT = "ref. [3]'s ellipse-hypothesis model: accuracy limited (no numbers)"
#: Why the simulated row is true or false by construction.
BY_CONSTRUCTION = (
    "our simulator's errors are exactly the hard/soft-iron (ellipse) model that the fit estimates: on our "
    "sweeps it reaches the noise floor and cannot lose; only real sweeps (the real-data section) decide"
)


def ellipse_claims(runs: pd.DataFrame) -> list[Claim]:
    """A20 on the simulated compass from the chapter's seed study ``runs`` (methods ``physical`` and
    ``ade_bp_full_trainlm``): test RMS(ellipse) - RMS(ADE-BP), paired by seed, holds above 0, *by
    construction* (module docstring)."""
    est, short = verdicts.attempt(paired_rms_difference, runs, ELLIPSE_ID, ADE_ID)
    e, a = per_seed(runs, ELLIPSE_ID), per_seed(runs, ADE_ID)
    return [
        Claim(
            ELLIPSE_TEXT,
            PAPER_TEXT,
            reading=R4,
            source="paper",
            statistic="test RMS ellipse (planar hard/soft-iron) model - test RMS ADE-BP full DE + "
            "trainlm, paired by seed, deg",
            estimate=est,
            boundary=0.0,
            holds_when="above",
            unit="deg",
            by_construction=True,
            decided_by=(
                "the ellipse model fitted to every reading of sweep 1 (nonlinear least squares)",
                TRAINING_ONLY,
            ),
            why="; ".join(t for t in (short, BY_CONSTRUCTION) if t),
            ours=f"{a.median():.3f} vs {e.median():.3f} deg rms",
            key="a_ellipse",
        )
    ]
