"""The robustness study: paper A's claims judged again on simulated compasses drawn by a stated rule
(:class:`~navlib.studies.compass.parameters.CompassDrawRule`), each kept only when its uncompensated error
envelope lies close to the paper's.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from ...data.compass_sweeps import split_sweeps
from ...errors import InputError
from ...methods.seeding import sequence
from ...sensors.compass import PAPER_A_EARTH, CompassErrors, simulate_sweep, simulate_train_test
from .parameters import ROBUST_METHODS, CompassDrawRule, StudyParams
from .sweeps import Sweeps
from .turntable import seed_studies
from .turntable_claims import claims


def draw_compass(rule: CompassDrawRule, k: int, noise_ut: float) -> CompassErrors:
    """Draw ``k`` of :class:`~navlib.studies.compass.parameters.CompassDrawRule` (its own ``SeedSequence`` spawn
    key)."""
    g = np.random.default_rng(sequence(rule.seed, k))
    h = PAPER_A_EARTH.horizontal_ut * g.uniform(*rule.hard_frac)
    ang = g.uniform(0.0, 2 * np.pi)
    hz = g.uniform(-rule.hard_z_ut, rule.hard_z_ut)
    return CompassErrors(
        hard_iron_ut=(h * np.cos(ang), h * np.sin(ang), hz),
        soft_iron=tuple(map(tuple, g.uniform(-rule.soft, rule.soft, (3, 3)))),
        scale_error=tuple(g.uniform(-rule.scale, rule.scale, 3)),
        nonorthogonality_deg=tuple(g.uniform(-rule.nonorth_deg, rule.nonorth_deg, 3)),
        misalignment_deg=(
            g.uniform(-rule.tilt_deg, rule.tilt_deg),
            g.uniform(-rule.tilt_deg, rule.tilt_deg),
            g.uniform(-rule.yaw_deg, rule.yaw_deg),
        ),
        noise_ut=float(noise_ut),
    )


def draw_compasses(
    rule: CompassDrawRule, paper_min_deg: float, paper_max_deg: float, noise_ut: float
) -> pd.DataFrame:
    """The robustness study's compasses: the first ``rule.n_compasses`` draws whose noiseless
    uncompensated error envelope lies within ``rule.tolerance_deg`` of ``paper_min_deg..paper_max_deg``.
    One row per compass: ``compass`` (name), ``draw`` (index), ``errors``
    (:class:`navlib.sensors.compass.CompassErrors`, with ``noise_ut``), ``min_deg``, ``max_deg`` (the
    envelope), and the mix: ``hard_frac`` (horizontal hard iron / H), ``soft_max`` (largest ``abs`` entry of S),
    ``tilt_deg`` (largest of roll, pitch), ``yaw_deg``."""
    rows = []
    for k in range(rule.max_draws):
        e = draw_compass(rule, k, 0.0)
        err = simulate_sweep(e, PAPER_A_EARTH, seed=0).heading_error_deg.to_numpy()
        lo, hi = float(err.min()), float(err.max())
        if (
            abs(lo - paper_min_deg) <= rule.tolerance_deg
            and abs(hi - paper_max_deg) <= rule.tolerance_deg
        ):
            rows.append(
                {
                    "compass": f"C{len(rows) + 1}",
                    "draw": k,
                    "errors": replace(e, noise_ut=float(noise_ut)),
                    "min_deg": lo,
                    "max_deg": hi,
                    "hard_frac": float(np.hypot(*e.hard_iron_ut[:2]) / PAPER_A_EARTH.horizontal_ut),
                    "soft_max": float(np.abs(np.asarray(e.soft_iron)).max()),
                    "tilt_deg": float(max(abs(e.misalignment_deg[0]), abs(e.misalignment_deg[1]))),
                    "yaw_deg": float(e.misalignment_deg[2]),
                }
            )
            if len(rows) == rule.n_compasses:
                break
    if len(rows) < rule.n_compasses:
        raise InputError(
            f"robustness: only {len(rows)} of {rule.n_compasses} compasses within "
            f"{rule.tolerance_deg} deg of the paper's envelope in {rule.max_draws} draws"
        )
    return pd.DataFrame(rows)


def robustness_study(
    compasses: pd.DataFrame,
    paper: pd.DataFrame,
    params: StudyParams = StudyParams(),
    seeds=range(6),
    methods=ROBUST_METHODS,
    sim_seed: int = 2024,
    workers: int = 1,
    scheduler: str | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Every claim of :func:`~navlib.studies.compass.turntable_claims.claims` on each compass of
    :func:`draw_compasses`: sweeps simulated from the compass (``sim_seed``, the chapter's noise),
    :func:`~navlib.studies.compass.turntable.seed_study` of ``methods`` over ``seeds`` (all compasses' tasks on the
    engine at once), the claims at that noise.  Returns ``(runs, verdicts)``: the runs with a ``compass`` column, and
    one row per (compass, claim, reading) with the verdict."""
    studies = [
        (
            Sweeps(*split_sweeps(simulate_train_test(e, PAPER_A_EARTH, seed=sim_seed))),
            params,
            seeds,
            methods,
        )
        for e in compasses.errors
    ]
    frames = seed_studies(studies, workers=workers, scheduler=scheduler)
    rows, allruns = [], []
    for (name, e), runs in zip(zip(compasses.compass, compasses.errors), frames):
        allruns.append(runs.assign(compass=name))
        for c in claims(runs, paper, default_ut=e.noise_ut):
            rows.append(
                {"compass": name, "claim": c.claim, "reading": c.reading, "verdict": c.verdict}
            )
    return pd.concat(allruns, ignore_index=True), pd.DataFrame(rows)


def robustness_table(robust: pd.DataFrame, main_claims=None) -> pd.DataFrame:
    """Claim and reading x compass: the verdicts of :func:`robustness_study` (plus the chapter's own compass,
    ``main_claims``, as column ``default``) and ``stable`` (True when every compass gives the same verdict)."""
    df = robust.copy()
    if main_claims is not None:
        keep = set(zip(df.claim, df.reading))
        df = pd.concat(
            [
                pd.DataFrame(
                    [
                        {
                            "compass": "default",
                            "claim": c.claim,
                            "reading": c.reading,
                            "verdict": c.verdict,
                        }
                        for c in main_claims
                        if (c.claim, c.reading) in keep
                    ]
                ),
                df,
            ],
            ignore_index=True,
        )
    t = df.pivot_table(
        index=["claim", "reading"], columns="compass", values="verdict", aggfunc="first", sort=False
    )
    t = t[list(dict.fromkeys(df.compass))]
    t["stable"] = t.nunique(axis=1) == 1
    return t


def robustness_flips(table: pd.DataFrame) -> pd.Series:
    """Per row of :func:`robustness_table`: True when the compasses give both *reproduced* and *not
    reproduced* (a change that a wider interval alone cannot make)."""
    verdict_cols = [c for c in table.columns if c != "stable"]
    return table[verdict_cols].apply(lambda r: {"reproduced", "not reproduced"} <= set(r), axis=1)
