"""The gyro chapter's models: paper C's hot and cold RBF networks, and the models set against them.

- inputs: :func:`latitude_scaler` (the hot net's latitude-error unit) and :func:`cold_inputs` (the cold net's
  three inputs);
- the hot net: :func:`design_hot_net` (MATLAB ``newrb`` on Table 2, :mod:`navlib.methods.rbf`) and the goal
  readings :data:`GOAL_READINGS`;
- the cold state: :func:`rate_coefficient` (the rate correction's ``k_R``) and :func:`design_cold_net`;
- other models: a polynomial fit, and :func:`swap_basis` (other basis functions, :data:`BASIS_FUNCTIONS`, at a
  Gaussian net's centres and width).
"""

from __future__ import annotations

from functools import lru_cache
from typing import get_args

import numpy as np
import pandas as pd

from navlib.angles import ARCMIN_PER_DEG, ARCSEC_PER_DEG, to_arcmin
from navlib.errors import InputError
from navlib.methods.rbf import InputScaler, RBFNet, leave_one_out, newrb

from .measured import _hot_xy
from .parameters import ColdDtColumn, HotNetSettings, StudyParams


# --------------------------------------------------------------------------------------------- network inputs
LATITUDE_UNITS = {"deg": 1.0, "arcmin": 1 / ARCMIN_PER_DEG, "arcsec": 1 / ARCSEC_PER_DEG}


def latitude_scaler(unit: str = "arcmin") -> InputScaler:
    """Explicit input scaling of the hot-state network: latitude error (deg) expressed in ``unit``.

    ``s(x) = x / scale`` with scale 1 (``deg``), 1/60 (``arcmin`` = nautical miles of latitude) or 1/3600
    (``arcsec``), so SPREAD is measured in that unit (paper C does not say which; Sec. 2.2).

    Parameters
    ----------
    unit : {"deg", "arcmin", "arcsec"}

    Returns
    -------
    navlib.methods.rbf.InputScaler
    """
    if unit not in LATITUDE_UNITS:
        raise InputError(
            f"parameter INPUT_UNIT={unit!r}: must be one of {', '.join(LATITUDE_UNITS)}"
        )
    return InputScaler.affine(0.0, LATITUDE_UNITS[unit], names=("latitude_error",), units=(unit,))


def cold_inputs(
    df: pd.DataFrame, temperature_change_column: str = "calib_temp_change_c"
) -> np.ndarray:
    """Cold-state network inputs (paper C Sec. 2.3: latitude error, temperature, temperature change).

    From a Table 4-like frame: ``[latitude_error_deg, calib_temp_max_c, <temperature_change_column>]``; the
    temperature is the one at the end of the alignment, when the drift is identified.

    Parameters
    ----------
    df : pandas.DataFrame
        Columns ``latitude_error_deg``, ``calib_temp_max_c`` and ``temperature_change_column``.
    temperature_change_column : {"calib_temp_change_c", "align_temp_change_c"}

    Returns
    -------
    numpy.ndarray
        (rows, 3) inputs in deg, C, C.
    """
    allowed = get_args(ColdDtColumn)
    if temperature_change_column not in allowed:
        raise InputError(
            f"parameter COLD_DT_COLUMN={temperature_change_column!r}: must be one of "
            f"{', '.join(allowed)}"
        )
    return np.c_[
        df["latitude_error_deg"].to_numpy(float),
        df["calib_temp_max_c"].to_numpy(float),
        df[temperature_change_column].to_numpy(float),
    ]


def _cold_net_inputs(df: pd.DataFrame, column: str) -> np.ndarray:
    """:func:`cold_inputs` with the latitude error in arcmin, like the hot net (z-scored afterwards)."""
    x = cold_inputs(df, column)
    x[:, 0] = to_arcmin(x[:, 0])
    return x


# ---------------------------------------------------------------------------------------------------- hot net
def design_hot_net(x_deg, drift_deg_h, hot: HotNetSettings) -> RBFNet:
    """``newrb`` on (latitude error in deg, drift in deg/h) with the hot-net settings.

    ``y = w0 + sum_i w_i exp(-(b |s(x) - c_i|)^2)``, ``b = sqrt(-ln 0.5) / SPREAD``, ``s`` =
    :func:`latitude_scaler` (paper C eq. 1-2, MATLAB ``newrb``).

    Parameters
    ----------
    x_deg, drift_deg_h : array_like
        Training inputs and targets.
    hot : HotNetSettings

    Returns
    -------
    navlib.methods.rbf.RBFNet
    """
    return newrb(
        x_deg,
        drift_deg_h,
        goal=hot.goal,
        spread=hot.matlab_spread,
        goal_kind=hot.goal_kind,
        scaler=latitude_scaler(hot.input_unit),
    )


@lru_cache(maxsize=16)
def _table2_net(hot: HotNetSettings) -> RBFNet:
    """The hot net designed on all of Table 2 (cached per settings; read-only)."""
    x2, y2, _, _ = _hot_xy()
    return design_hot_net(x2, y2, hot)


#: Readings of the printed goal: name -> (``goal_kind``, whether the printed value is squared first).
GOAL_READINGS = {
    "MSE": ("mse", False),
    "SSE": ("sse", False),
    "RMS": ("mse", True),
    "RSS": ("sse", True),
}


@lru_cache(maxsize=8)
def _hot_loo_errors(hot: HotNetSettings) -> np.ndarray:
    """Leave-one-out errors (true - predicted, deg/h) of the hot net over Table 2's rows (read-only)."""
    x2, y2, _, _ = _hot_xy()
    return y2 - leave_one_out(x2, y2, lambda x, y: design_hot_net(x, y, hot))


# --------------------------------------------------------------------------------------------------- cold net
def rate_coefficient(hot_error_deg_h, rate_c_h) -> float:
    """Least-squares coefficient ``k_R`` of ``hot-net output - true = k_R * dT/dt`` through the origin:
    ``k_R = sum(r e) / sum(r^2)``, in (deg/h) per (C/h); ``r`` the temperature rate in the identification
    window (calibration-window change / 12 h).

    Parameters
    ----------
    hot_error_deg_h : array_like
        Hot-net output minus true drift, deg/h.
    rate_c_h : array_like
        Temperature rate, C/h.

    Returns
    -------
    float
    """
    e, r = np.asarray(hot_error_deg_h, float), np.asarray(rate_c_h, float)
    if e.shape != r.shape or e.size < 1:
        raise InputError(f"rate_coefficient: {e.size} errors for {r.size} rates")
    rr = float(r @ r)
    if rr == 0:
        raise InputError("rate_coefficient: every temperature rate is zero")
    return float(r @ e / rr)


def design_cold_net(x, drift_deg_h, params: StudyParams, spread_sd: float | None = None) -> RBFNet:
    """``newrb`` on cold-net inputs (:func:`cold_inputs`, latitude in arcmin), z-scored on these rows.

    Parameters
    ----------
    x : array_like
        (rows, 3) inputs.
    drift_deg_h : array_like
    params : StudyParams
        Goal from ``params.hot``; SPREAD ``params.cold.spread_sd`` unless ``spread_sd`` is given.

    Returns
    -------
    navlib.methods.rbf.RBFNet
    """
    sp = params.cold.spread_sd if spread_sd is None else spread_sd
    return newrb(
        x,
        drift_deg_h,
        goal=params.hot.goal,
        spread=sp,
        goal_kind=params.hot.goal_kind,
        scaler=InputScaler.standardize(x),
    )


# ----------------------------------------------------------------------------------------------- other models
def _poly_fit(degree: int):
    def fit(x, y):
        p = np.polyfit(x[:, 0], y, degree)
        return lambda q: np.polyval(p, q[:, 0])

    return fit


#: Basis functions set against the Gaussian (``radbas``) at the Gaussian net's own centres and width
#: (paper C Sec. 1: "the choice of Phi(.) has little influence"); ``r = b |s(x) - c|``.
BASIS_FUNCTIONS = {
    "multiquadric": lambda r: np.sqrt(1.0 + r * r),
    "inverse multiquadric": lambda r: 1.0 / np.sqrt(1.0 + r * r),
    "thin-plate spline": lambda r: np.where(r > 0, r * r * np.log(np.where(r > 0, r, 1.0)), 0.0),
}


def swap_basis(net: RBFNet, x, y, basis: str):
    """The net ``net`` with its Gaussian neurons replaced by ``basis`` (:data:`BASIS_FUNCTIONS`, or
    ``"gaussian"``) at the same centres and width ``b``; output weights and bias refitted by least squares on
    ``(x, y)`` (as ``newrb`` fits them for its own neurons).  Returns a predictor on raw inputs."""
    phi = (lambda r: np.exp(-r * r)) if basis == "gaussian" else BASIS_FUNCTIONS.get(basis)
    if phi is None:
        raise InputError(f"parameter basis={basis!r}: one of {['gaussian', *BASIS_FUNCTIONS]}")

    def design(xx):
        r = net.b * np.sqrt(
            ((net.scaler.transform(xx)[:, None, :] - net.centers[None, :, :]) ** 2).sum(axis=2)
        )
        return np.hstack([phi(r), np.ones((r.shape[0], 1))])

    sol, *_ = np.linalg.lstsq(design(x), np.asarray(y, dtype=float), rcond=None)
    return lambda xx: design(xx) @ sol
