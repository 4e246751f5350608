"""Paper E's claims on the running filter's network step (E11: QR features make the navigation algorithm
cheaper, not only its training) and on dropping the three rate inputs in level flight (E12), for
:func:`navlib.studies.celestial.claims.claims`.

Timings are this machine's (``volatile``); the step and its operation count are
:mod:`navlib.studies.celestial.step`'s."""

from __future__ import annotations

import numpy as np

from ... import verdicts
from ...claims import Claim, load_register
from ...errors import InputError
from .scores import _paired, per_run
from .simulation import StudyData
from .step import step_flops
from .tables import paper_numbers, step_timing_pairs

#: Paper E Sec. 2.1 (E11): QR raises the training speed and the navigation algorithm's efficiency.
EFFICIENCY_CLAIM = "QR features make the BPKF's network cheaper (45 vs 6 inputs)"
#: Paper E Sec. 2.2 (E12): outside high dynamics the three rate inputs can be dropped.
NO_RATES_CLAIM = (
    "Outside high dynamics the 3 rate inputs can be dropped (level, 6 QR vs 6 QR + 3 rates)"
)


def _efficiency_claims(data: StudyData, lm: tuple, adam: tuple) -> list[Claim]:
    """E11, that QR "raises the training speed of the BP network and the computational efficiency of the
    integrated navigation algorithm", as one claim under five readings, each on the ratio 45 inputs / 6
    inputs against 1 (any gain), holds above: the running filter's network step per epoch (one epoch at a
    time, the primary; vectorised over a run; its operation count, exact) and the training (one whole
    ``trainlm`` training, time per Adam pass: the timings of E03, here against 1).  Timings are this
    machine's (``volatile``)."""
    sp = data.spec
    paper_v = paper_numbers()["value"]
    t45_p, t6_p = float(paper_v["train_time_45_s"]), float(paper_v["train_time_6_s"])
    out = []
    clock = "this machine and its load during the build"
    step = "our network step in numpy (float64, one thread): LAPACK QR of the 15x3 gain, standardised inputs"
    no_impl = "the paper's implementation and computer are not stated"
    paper = "raises the computational efficiency (no number)"
    for reading, what, key in (
        (
            "epoch",
            "the running filter's network step, one epoch at a time (features of the epoch's 15x3 "
            "gain and one forward pass), this machine",
            "cel_step",
        ),
        (
            "batch",
            "the network step vectorised over a run's epochs (features and forward pass of all "
            "epochs at once), this machine",
            "cel_step_batch",
        ),
    ):
        try:
            a, b = step_timing_pairs(data, reading)
        except InputError as err:
            a = b = None
            why = f"no statistic: {err}"
        if a is not None:
            est, why = verdicts.attempt(verdicts.paired_ratio, a, b)
        else:
            est = None
        out.append(
            Claim(
                EFFICIENCY_CLAIM,
                paper,
                reading=what,
                statistic=(
                    f"median over {0 if a is None else len(a)} paired repetitions (both steps in each, "
                    "the same held-out run's gains, alternating order) of the time per filter epoch of "
                    "the network step with 45 raw gains / with 6 QR features"
                ),
                estimate=est,
                boundary=1.0,
                holds_when="above",
                unit="x",
                spec="{:.2f}",
                ours=""
                if a is None
                else f"{1e6 * np.median(a):.1f} vs {1e6 * np.median(b):.1f} us per epoch",
                decided_by=(step, no_impl, clock),
                why=why,
                key=key,
                volatile=True,
            )
        )
    f45, f6 = step_flops(45, sp.n_hidden), step_flops(6, sp.n_hidden)
    out.append(
        Claim(
            EFFICIENCY_CLAIM,
            paper,
            reading="the network step's floating-point operations per epoch (a compiled step: no "
            "interpreter overhead per call)",
            statistic="operations per epoch of the network step with 45 raw gains / with 6 QR features "
            "(Householder QR, R only, 2 n^2 (m - n/3); forward pass with scaling; exp one operation)",
            estimate=verdicts.exact(f45 / f6),
            boundary=1.0,
            holds_when="above",
            unit="x",
            spec="{:.2f}",
            ours=f"{f45} vs {f6} operations",
            decided_by=(
                "an operation count, not a timing: memory access and the cost of exp and sqrt "
                "against a multiply are left out",
            ),
            key="cel_step_flops",
        )
    )
    for (a, b), what, stat, key in (
        (
            lm,
            "the training: one whole training as MATLAB trains (trainlm, MATLAB defaults, "
            "validation stop), faster at all, this machine",
            "median over {n} paired repetitions (both nets in each, own initial weights and split) of "
            "the training time with 45 inputs / with 6 inputs",
            "cel_train_faster_lm",
        ),
        (
            adam,
            "the training: time per pass of full-batch Adam (fixed epochs), faster at all, this machine",
            "median over {n} paired timings (both nets in each, same training set) of the time per "
            "pass with 45 inputs / with 6 inputs",
            "cel_train_faster",
        ),
    ):
        est, why = verdicts.attempt(verdicts.paired_ratio, a, b)
        out.append(
            Claim(
                EFFICIENCY_CLAIM,
                f"raises the training speed (Sec. 3.1: {t45_p:.4f} s vs {t6_p:.4f} s)",
                reading=what,
                statistic=stat.format(n=len(a)),
                estimate=est,
                boundary=1.0,
                holds_when="above",
                unit="x",
                spec="{:.2f}",
                decided_by=("the timings of E03 (same repetitions), judged against 1", clock),
                why=why,
                key=key,
                volatile=True,
            )
        )
    return out


def _no_rate_claims(data: StudyData, rms3: str, device: str, trainer: str) -> list[Claim]:
    """E12, that outside high-dynamic conditions the three rate inputs can be dropped: the median over
    level-flight runs of the paired difference RMS 6 QR - RMS 6 QR + 3 rates (arcsec), holds below 0, with
    the register's equivalence margin (a row within it is *no difference*); held-out runs (the primary)
    and in-sample (same run).  In straight level flight the body rates are the constant Earth and
    transport rates plus gyro noise, so the rates carry almost nothing: the equivalence is close to true by
    construction of our simulator (said in ``decided_by``)."""
    margin = {e.id: e.margin for e in load_register("paper_e")}.get("E12")
    out = []
    for mode in ("held-out", "same run"):
        held = mode == "held-out"
        est, why = verdicts.attempt(
            verdicts.paired_difference,
            *_paired(
                per_run(data, "level_qr6", mode, "BPKF"),
                per_run(data, "level_qr6_rate", mode, "BPKF"),
            ),
        )
        out.append(
            Claim(
                NO_RATES_CLAIM,
                "the last three inputs can be dropped (no number)",
                reading="held-out runs"
                if held
                else "in-sample (same run): the nets scored on their training data",
                statistic=f"median over runs of the paired difference RMS 6 QR - RMS 6 QR + 3 rates, {rms3}, arcsec",
                estimate=est,
                boundary=0.0,
                holds_when="below",
                unit="arcsec",
                decided_by=(
                    device,
                    trainer,
                    "straight level flight: the body rates are the constant Earth and transport rates "
                    "plus gyro noise, so the rate inputs carry almost nothing (close to true by "
                    "construction of our simulator)",
                ),
                why=why,
                key=f"cel_norates_{'held' if held else 'same'}",
                margin=margin,
            )
        )
    return out
