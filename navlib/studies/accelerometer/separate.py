"""Paper D's core design claim (section 2, eqs 5-7; conclusion 2): "modelling bias and scale factor
separately introduces the modelling error twice; we design an integrated model". The separate compensator
the paper argues against, built from the same readings and by the same fitting method as the integrated
one (register entry D11; the paired comparison is
:func:`~navlib.studies.accelerometer.claims.separate_claims`).

The separate compensator (:class:`SeparateCompensator`) has two models::

    K0 = f(T)        bias, from the 0/180 deg bias test (section 2.1.1): (U(0) + U(180)) / 2
    K1 = g(T, a)     scale factor, eq 3 (lost in the OCR; read as in Fig 4): (U - K0(T)) / a

and inverts the output model ``N = K0(T) + K1(T, a) a`` for the input ``a`` by fixed-point steps
``a <- (N - K0(T)) / K1(T, a)``, then gives the output at the reference temperature::

    Nc = K0(T55) + K1(T55, a) a

with ``T55`` the sensor temperature of the reference tumble.  Both models are fitted like the integrated
model they are compared with (``genfis2`` then ANFIS, :func:`fit_separate`), so the comparison isolates the
structure the claim is about.  ``K1`` is trained on readings with ``|a| >= K1_MIN_INPUT_G`` (it is
undefined at ``a = 0``); near ``a = 0`` it is the fitted model's extrapolation, multiplied by the small
``a``.  The bias points come from the same split as the integrated model's readings: a set point gives a
``K0`` point for training (or checking) only when both its 0 and 180 deg readings are training (or
checking) readings, so no test reading reaches either model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...errors import InputError, check_param
from ...methods.anfis import AnfisOptions, anfis
from ...methods.subclust import genfis2
from .parameters import K1_MIN_INPUT_G, PaperDParams

#: Fixed-point steps of the inversion ``a <- (N - K0) / K1(T, a)`` (K1 is about 1000 mg/g and changes
#: by parts per thousand with ``a``, so each step gains about three digits).
INVERSION_STEPS = 8


@dataclass(frozen=True)
class SeparateCompensator:
    """``k0``: the bias model, (n, 1) sensor temperatures (degC) -> K0 (mg); ``k1``: the scale-factor model,
    (n, 2) [T (degC), a (g)] -> K1 (mg/g); ``reference_temperature_c``: the sensor temperature of the
    reference tumble; ``k1_range_mg_g``: the range of the scale factors the ``k1`` model was trained on.
    ``__call__(X)`` maps rows (T, N) (degC, mg) to the 55 degC-equivalent output Nc (mg), see the module's
    equations.

    The inversion starts from ``a = (N - K0) / K1`` at the middle of ``k1_range_mg_g`` and takes ``steps``
    fixed-point steps with ``K1`` held inside ``k1_range_mg_g``: a fitted ``K1`` model can be far off
    between the inputs it was trained on (ANFIS may narrow a rule around a few noisy points near
    ``|a| = K1_MIN_INPUT_G``, where eq 3 divides the noise by ``a``), and a value it never saw in training
    would send the steps to infinity; inside the range every output is finite, and where the model is
    that far off the output is as wrong as the model."""

    k0: object
    k1: object
    reference_temperature_c: float
    k1_range_mg_g: tuple = (-np.inf, np.inf)
    steps: int = INVERSION_STEPS

    def __post_init__(self):
        lo, hi = (float(v) for v in self.k1_range_mg_g)
        if not lo <= hi or (lo <= 0.0 <= hi and np.isfinite([lo, hi]).all()):
            raise InputError(
                f"SeparateCompensator.k1_range_mg_g={self.k1_range_mg_g!r}: must be an interval of "
                f"one sign (the scale factor divides)"
            )
        check_param("steps", self.steps, lo=0, hi=1000, integer=True)

    def _k1(self, t, a):
        lo, hi = self.k1_range_mg_g
        return np.clip(self.k1(np.column_stack([t, a])), lo, hi)

    def input_g(self, X) -> np.ndarray:
        """The input ``a`` (g) of each row (T, N), by the fixed-point inversion of ``N = K0 + K1 a``."""
        X = np.atleast_2d(np.asarray(X, float))
        t, n = X[:, 0], X[:, 1]
        num = n - self.k0(t[:, None])
        lo, hi = self.k1_range_mg_g
        a = num / (0.5 * (lo + hi) if np.isfinite([lo, hi]).all() else self._k1(t, np.ones_like(t)))
        for _ in range(self.steps):
            a = num / self._k1(t, a)
        return a

    def __call__(self, X) -> np.ndarray:
        a = self.input_g(X)
        t55 = np.full_like(a, self.reference_temperature_c)
        return self.k0(t55[:, None]) + self._k1(t55, a) * a


def bias_points(s: pd.DataFrame) -> pd.DataFrame:
    """The 0/180 deg bias test inside a tumble's samples ``s`` (columns ``set_point_c``,
    ``temperature_c``, ``position_deg``, ``output_mg``, ``set``): per set point whose 0 and 180 deg
    readings carry the same label, the bias ``(U(0) + U(180)) / 2`` (mg) at their mean sensor
    temperature; columns ``set_point_c``, ``temperature_c``, ``bias_mg``, ``set``."""
    q = np.round(np.asarray(s["position_deg"], float) % 360.0, 6)
    g = s[np.isin(q, (0.0, 180.0))]
    rows = []
    for sp, p in g.groupby("set_point_c", sort=True):
        pq = np.round(p["position_deg"].to_numpy() % 360.0, 6)
        if len(p) != 2 or set(pq) != {0.0, 180.0} or p["set"].nunique() != 1:
            continue
        rows.append(
            {
                "set_point_c": float(sp),
                "temperature_c": float(p["temperature_c"].mean()),
                "bias_mg": float(p["output_mg"].mean()),
                "set": p["set"].iloc[0],
            }
        )
    return pd.DataFrame(rows, columns=["set_point_c", "temperature_c", "bias_mg", "set"])


def _fit(X, y, ck, radius, options: AnfisOptions):
    """``genfis2`` at ``radius`` trained by ANFIS, checked on ``ck`` = (X, y) where it has rows."""
    check = ck if len(ck[1]) else None
    return anfis(X, y, genfis2(X, y, radius), options, check=check).fis


def fit_separate(
    s: pd.DataFrame,
    params: PaperDParams,
    radius: float | None = None,
    reference_c: float | None = None,
) -> SeparateCompensator:
    """The separate compensator from the labelled samples ``s`` of one unit
    (:func:`~navlib.studies.accelerometer.simulation.samples` with a ``set`` column): ``K0`` on :func:`bias_points`' training set
    points, ``K1 = (U - K0(T)) / a`` on the training readings with ``|a| >= K1_MIN_INPUT_G`` (``K0(T)`` the
    fitted bias model, so its error enters ``K1``: the paper's "modelling error twice"); each
    ``genfis2`` at ``radius`` (default ``params.fis_radius``, as the chapter's ``ANFIS``) then ANFIS
    (``params.anfis``) with the checking readings or set points.  The unit's samples must include the
    reference tumble (``params.experiment.reference_c`` unless ``reference_c``)."""
    radius = params.fis_radius if radius is None else float(radius)
    check_param("radius", radius, lo=0.01, hi=10)
    ref = params.experiment.reference_c if reference_c is None else float(reference_c)
    at_ref = np.isclose(s["set_point_c"], ref)
    if not at_ref.any():
        raise InputError(f"separate model: no readings at the reference {ref:g} degC")
    t55 = float(s.loc[at_ref, "temperature_c"].mean())
    bp = bias_points(s)
    tr0, ck0 = bp[bp["set"] == "train"], bp[bp["set"] == "check"]
    if len(tr0) < 3:
        raise InputError(
            f"separate model: {len(tr0)} set points with both 0 and 180 deg readings in training, "
            f"the bias model needs 3"
        )
    k0 = _fit(
        tr0[["temperature_c"]].to_numpy(),
        tr0["bias_mg"].to_numpy(),
        (ck0[["temperature_c"]].to_numpy(), ck0["bias_mg"].to_numpy()),
        radius,
        params.anfis,
    )
    a = np.round(np.cos(np.deg2rad(np.asarray(s["position_deg"], float))), 12)
    t = s["temperature_c"].to_numpy(float)
    k1_target = (s["output_mg"].to_numpy(float) - k0(t[:, None])) / np.where(a == 0, np.nan, a)
    use = np.abs(a) >= K1_MIN_INPUT_G
    tr = use & (s["set"] == "train").to_numpy()
    ck = use & (s["set"] == "check").to_numpy()
    X1 = np.column_stack([t, a])
    k1 = _fit(X1[tr], k1_target[tr], (X1[ck], k1_target[ck]), radius, params.anfis)
    return SeparateCompensator(
        k0, k1, t55, (float(k1_target[tr].min()), float(k1_target[tr].max()))
    )
