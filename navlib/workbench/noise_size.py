"""Whether residuals are small enough to be noise: the check "consistent with noise" needs besides the tests
(issue 35).

A correlated-noise model (AR with lag-1 correlation near 1) can take up a large, slowly varying error: on
a hand-held recording whose reference attitude was bad in segments the loop once ended "consistent with
noise" at 6.9 uT rms, twenty times the other recordings, because an AR(3) of lag-1 0.81 absorbed it.  The
data themselves show how large their noise is at short lags: consecutive samples differ by noise (and by
whatever changes quickly), not by a slow error.  With ``d_t = r_t - r_(t-1)`` in time order within each
residual column::

    s_short = 1.4826 MAD(d) / sqrt(2)                 (the sample-to-sample noise, robust)
    ratio   = rms(r) / s_short

For AR(1) noise of lag-1 correlation ``phi``, ``var(d) = 2 sigma^2 (1 - phi)`` and the ratio is
``1 / sqrt(1 - phi)``: 1 for independent noise, 3.2 at ``phi = 0.9``, 5 at 0.96, 7.1 at 0.98.  Residuals are called noise only when

1. the ratio's lower 95 % bound is at most ``RATIO_MAX`` (slow variation larger than that is not called
   noise: at that size noise and a slow error cannot be told apart, and calling it noise would be confident
   and wrong).  The bound allows for the few independent samples correlated noise leaves:
   ``rms_lo = rms sqrt(nu / chi2_0.975(nu))`` with ``nu`` the effective samples of the noise model (those
   a slowly varying shape sees, ``NoiseModel.effective_samples``; all of them for independent noise), so
   AR(1) noise of lag-1 0.9 on a 242-reading compass sweep pair (``nu`` about 13, ratio 2.8 typical, 5.2
   seen once in 100 trials) is not flagged by chance; and
2. no candidate effect explains more than ``EXPLAINED_MAX`` times ``s_short`` (rms of the fitted
   change), however undecided the correlated-noise test leaves it: noise does not make an effect's shape
   that large.

Tables shorter than :data:`MIN_ROWS` are not checked (too few differences for a robust spread).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import special

#: Largest rms / sample-to-sample noise of residuals still called noise (AR(1) noise of lag-1 0.96).
RATIO_MAX = 5.0
#: Largest rms a candidate may explain, in units of the sample-to-sample noise, for the rest to be noise
#: (AR(1) noise of lag-1 0.9 on 242 rows: a slowly varying effect of 2 parameters takes out about 1.3 on
#: average by chance).
EXPLAINED_MAX = 4.0
#: Fewer rows than this: not checked.
MIN_ROWS = 30
#: One-sided tail of the ratio's lower bound.
TAIL = 0.025
MAD_SD = 1.482602218505602


@dataclass(frozen=True)
class NoiseSize:
    """The check's numbers: ``short`` (s_short), ``rms``, ``ratio``; ``biggest`` the candidate that
    explains the most and ``explained`` its rms (or None); ``problem``: why the residuals are not noise
    ("" when they may be)."""

    short: float
    rms: float
    ratio: float
    ratio_low: float
    biggest: str | None
    explained: float
    problem: str

    def to_dict(self) -> dict:
        return {
            "sample_to_sample_noise": self.short,
            "rms": self.rms,
            "ratio": self.ratio,
            "ratio_low": self.ratio_low,
            "largest_candidate": self.biggest,
            "largest_explained_rms": self.explained,
            "problem": self.problem,
        }


def short_lag_noise(residuals: np.ndarray, data: pd.DataFrame) -> float:
    """``s_short`` (module docstring) of residuals in observation order (rows x columns of ``data``'s
    rows), the rows in time order where ``data`` has ``time_s``; the columns pooled in quadrature."""
    n = len(data)
    r = np.asarray(residuals, float).reshape(n, -1)
    if "time_s" in data:
        r = r[np.argsort(data["time_s"].to_numpy(float), kind="stable")]
    d = np.diff(r, axis=0)
    s = MAD_SD * np.median(np.abs(d - np.median(d, axis=0)), axis=0) / np.sqrt(2.0)
    return float(np.sqrt(np.mean(s**2)))


def noise_size(
    fit, candidates: dict, unit: str, effective: float | None = None
) -> NoiseSize | None:
    """The check of the module docstring on the residuals of ``fit`` (a :class:`navlib.workbench.fit.Fit`),
    ``candidates``: ``{effect: fit with it added}``, ``effective``: the noise model's effective samples
    (default: every observation); None for a table under :data:`MIN_ROWS` rows or residuals whose
    short-lag spread is zero."""
    if len(fit.data) < MIN_ROWS:
        return None
    short = short_lag_noise(fit.residuals, fit.data)
    if not short > 0:
        return None
    rms = float(np.sqrt(np.mean(np.asarray(fit.residuals, float) ** 2)))
    ratio = rms / short
    nu = float(fit.n if effective is None else max(min(effective, fit.n), 1.0))
    ratio_low = ratio * float(np.sqrt(nu / (2.0 * special.gammaincinv(nu / 2.0, 1.0 - TAIL))))
    biggest, explained = None, 0.0
    for name, f1 in candidates.items():
        e = float(np.sqrt(max(fit.rss - f1.rss, 0.0) / fit.n))
        if e > explained:
            biggest, explained = name, e
    problem = ""
    if explained > EXPLAINED_MAX * short:
        problem = (
            f"'{biggest}' would take out {explained:.3g} {unit} rms, {explained / short:.1f} times the "
            f"sample-to-sample noise ({short:.3g} {unit}), though the correlated-noise test leaves it "
            f"undecided"
        )
    elif ratio_low > RATIO_MAX:
        problem = (
            f"slow variation of {rms:.3g} {unit} rms, {ratio:.1f} times the sample-to-sample noise "
            f"({short:.3g} {unit}; at least {ratio_low:.1f} times at 95 %, where noise is called noise up "
            f"to {RATIO_MAX:g} times)"
        )
    return NoiseSize(short, rms, ratio, ratio_low, biggest, explained, problem)
