"""The celestial study's scores per run, for comparisons paired run by run: one case, mode and method's
attitude error per held-out run (:func:`per_run`), the same on the scale-factor sweep (:func:`sweep_per_run`)
and over the turning or steady half of each S-turn run (:func:`phase_per_run`); and the rows of the
innovation diagnosis with an effect outside the candidates or with nothing missing."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...errors import InputError
from ...methods import kalman as km
from .parameters import AXES, CASES, PHASES, SWEEP_METHODS
from .simulation import StudyData

_ANGLES = ("all", "worst") + AXES


def per_run(data: StudyData, case: str, mode: str, method: str, angle: str = "all") -> pd.Series:
    """The attitude error of one case, mode and method per test run (arcsec), indexed by (repeat, run) in
    order, so that two methods' series pair run by run: ``angle="all"`` the RMS over the three Euler angles,
    ``"worst"`` the largest of the three per-angle RMS errors, or one angle (``"pitch"``, ``"roll"``,
    ``"yaw"``)."""
    if case not in CASES:
        raise InputError(f"parameter case={case!r}: must be one of {', '.join(CASES)}")
    if angle not in _ANGLES:
        raise InputError(f"parameter angle={angle!r}: must be one of {', '.join(_ANGLES)}")
    s = data.scores
    s = s[(s["case"] == case) & (s["mode"] == mode) & (s["method"] == method)]
    if s.empty:
        raise InputError(f"no scores for case={case!r}, mode={mode!r}, method={method!r}")
    return _by_angle(s, angle)


def _by_angle(s: pd.DataFrame, angle: str) -> pd.Series:
    """Per (repeat, run) of the score rows ``s``: one axis's RMS (arcsec), the worst axis, or the RMS over
    the three axes (``'all'``)."""
    if angle in AXES:
        return s[s["axis"] == angle].set_index(["repeat", "run"])["rms_arcsec"].sort_index()
    if angle == "worst":
        out = s.groupby(["repeat", "run"])["rms_arcsec"].max()
    else:
        out = np.sqrt((s["rms_arcsec"] ** 2).groupby([s["repeat"], s["run"]]).mean())
    return out.sort_index()


def sweep_per_run(
    data: StudyData,
    level_ppm: float,
    method: str,
    angle: str = "all",
    latency_ms: float | None = None,
    smear: float | None = None,
) -> pd.Series:
    """Like :func:`per_run` for the scale-factor sweep: one method's held-out S-turn error per run at one
    level (arcsec), indexed by (repeat, run); ``latency_ms`` and ``smear`` (arcsec per deg/s) select the
    star sensor's blind effects (default: the study's own)."""
    if method not in SWEEP_METHODS:
        raise InputError(f"parameter method={method!r}: must be one of {', '.join(SWEEP_METHODS)}")
    if angle not in _ANGLES:
        raise InputError(f"parameter angle={angle!r}: must be one of {', '.join(_ANGLES)}")
    latency_ms = data.spec.star_latency_ms if latency_ms is None else latency_ms
    smear = data.spec.star_smear_arcsec_per_deg_s if smear is None else smear
    s = data.sweep
    s = s[
        (s["level_ppm"] == float(level_ppm))
        & (s["latency_ms"] == float(latency_ms))
        & (_smear(s) == float(smear))
        & (s["method"] == method)
    ]
    if s.empty:
        raise InputError(
            f"parameter level_ppm={level_ppm!r}, latency_ms={latency_ms!r}, smear={smear!r}: "
            "not in the sweep"
        )
    return _by_angle(s, angle)


def phase_per_run(
    data: StudyData,
    method: str,
    phase: str,
    angle: str = "yaw",
    level_ppm: float | None = None,
    repeats: int | None = None,
) -> pd.Series:
    """One method's held-out S-turn error per run (arcsec) over the ``turning`` or the ``steady`` half of the
    run's scored epochs (:data:`~navlib.studies.celestial.parameters.PHASES`), indexed by (repeat, run):
    ``method`` ``"KF"`` or ``"BPKF 6 QR"``, at the gyro scale factor ``level_ppm`` (default: the study's own,
    all its repeats), from the first ``repeats`` repeats only if given (the sweep's)."""
    if data.phases is None or data.phases.empty:
        raise InputError("no turning and steady scores in this study (StudyData.phases)")
    if phase not in PHASES:
        raise InputError(f"parameter phase={phase!r}: must be one of {', '.join(PHASES)}")
    if angle not in _ANGLES:
        raise InputError(f"parameter angle={angle!r}: must be one of {', '.join(_ANGLES)}")
    level = float(data.spec.gyro_scale_ppm if level_ppm is None else level_ppm)
    p = data.phases
    p = p[(p["level_ppm"] == level) & (p["method"] == method) & (p["phase"] == phase)]
    if repeats is not None:
        p = p[p["repeat"] < repeats]
    if p.empty:
        raise InputError(f"no {phase} scores for method={method!r} at {level:g} ppm")
    return _by_angle(p, angle)


def _smear(df: pd.DataFrame) -> pd.Series:
    """The rate-proportional star-sensor error of each row (arcsec per deg/s; 0 where not recorded)."""
    return df["smear"] if "smear" in df.columns else pd.Series(0.0, index=df.index)


def _paired(a: pd.Series, b: pd.Series) -> tuple[np.ndarray, np.ndarray]:
    """Two per-run series as arrays, after checking that they cover the same runs in the same order."""
    if not a.index.equals(b.index):
        raise InputError("paired comparison: the two methods were not scored on the same runs")
    return a.to_numpy(), b.to_numpy()


def _diag(data: StudyData, latency: bool) -> pd.DataFrame:
    """The diagnosis rows without a scale factor or rate-proportional error: with a star-sensor time offset,
    or with nothing missing."""
    d = data.diagnosis
    sel = (d["latency_ms"] > 0) if latency else (d["latency_ms"] == 0)
    return d[sel & (d["level_ppm"] == 0) & (_smear(d) == 0)]


def _blind(data: StudyData, which: str = "both") -> pd.DataFrame:
    """The diagnosis rows with an effect outside the candidates and no scale factor: ``"latency"`` (time
    offset), ``"smear"`` (rate-proportional error) or ``"both"``."""
    d = data.diagnosis
    lat, sm = d["latency_ms"] > 0, _smear(d) != 0
    sel = {"latency": lat & ~sm, "smear": sm & ~lat, "both": lat | sm}[which]
    return d[sel & (d["level_ppm"] == 0)]


def _named(d: pd.DataFrame) -> pd.Series:
    """Whether the decision rule named a candidate in each row."""
    return ~d["decision"].isin([km.NOT_EXPLAINED, km.NOTHING])
