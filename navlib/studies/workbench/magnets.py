"""The 3-D magnetometer with a magnet: calibrate on the undisturbed BROAD trial 05, run the loop on every
attached- and stationary-magnet trial, the ellipsoid fit beside it, and the law of hard iron against the
magnet's distance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from ...errors import InputError
from ...workbench.loop import LoopResult, loop
from ...workbench.magnetometer import (
    MAG,
    apply_calibration,
    correct_field,
    ellipsoid_fit,
    field_summary,
    heading_error_deg,
)
from .broad_loops import load_trial
from .parameters import ATTACHED, CALIBRATION_TRIAL, MAG_DIR, MAGNET_STAIRCASES, STATIONARY
from .tables import added


@dataclass
class MagnetStudy:
    """The 3-D chapter section: the calibration loop, one loop per disturbed trial, tables."""

    calibration: LoopResult
    field: pd.DataFrame
    trials: pd.DataFrame  # one row per disturbed trial
    loops: dict  # file -> LoopResult (on calibrated data)
    headings: pd.DataFrame  # heading error of our model and of the ellipsoid fit


def magnet_study(row_step: int = 3, alpha: float | None = None) -> MagnetStudy | None:
    """Calibrate on the undisturbed trial 05 (loop from the field alone), correct every disturbed trial
    with that calibration, and run the loop again from the field alone: on the attached-magnet trials the
    loop should name ``hard_iron`` first; on the stationary-magnet trials the field changes with position,
    which no body-fixed effect explains.  Beside it, the least-squares ellipsoid fit (no reference
    attitude) on the same data, and both heading errors.  ``row_step`` thins the calibration and
    attached-magnet trials (every n-th block, for speed).  None if the data are absent."""
    if not MAG_DIR.is_dir():
        return None
    cal_data = load_trial(CALIBRATION_TRIAL, row_step)
    cal = loop("magnetometer", cal_data, [], alpha=alpha)
    field = pd.DataFrame([field_summary(cal.final)], index=["trial 05 (calibration)"])
    rows, loops, heads = [], {}, []
    heads.append(_headings("05 undisturbed", cal_data, cal.final.params, cal.final))
    for name in list(ATTACHED) + list(STATIONARY):
        # the stationary-magnet trials keep few moving blocks: all of them are used
        raw = load_trial(name, row_step if name in ATTACHED else 1, attached_only=name in ATTACHED)
        data = apply_calibration(cal.final, raw)
        res = loop("magnetometer", data, [], alpha=alpha)
        loops[name] = res
        b = [res.final.params.get(k, 0.0) for k in ("hard_x_ut", "hard_y_ut", "hard_z_ut")]
        short = name.replace("broad_", "").replace(".csv", "").replace("_", " ")
        rows.append(
            {
                "trial": short,
                "magnet": "attached" if name in ATTACHED else "stationary",
                "nominal distance (cm)": ATTACHED.get(name, np.nan),
                "rows": len(data),
                "calibrated rms (uT)": res.fits[0].rms,
                "first effect named": res.diagnoses[0].missing or "-",
                "effects added": added(res),
                "final rms (uT)": res.final.rms,
                "|hard iron| (uT)": float(np.linalg.norm(b)),
                "outcome": res.outcome(),
            }
        )
        if name in ATTACHED:
            heads.append(_headings(short, raw, None, None, calibrated=cal.final, result=res))
    return MagnetStudy(
        cal,
        field,
        pd.DataFrame(rows).set_index("trial"),
        loops,
        pd.DataFrame(heads).set_index("trial"),
    )


def magnet_staircases(study: MagnetStudy) -> dict:
    """Representative loops of :func:`magnet_study` for :func:`navlib.workbench.loop.staircase_grid`,
    panel title -> LoopResult: the calibration on trial 05 and the trials of
    :data:`~navlib.studies.workbench.parameters.MAGNET_STAIRCASES` (after the trial-05 calibration)."""
    out = {"05 undisturbed (calibration)": study.calibration}
    for name in MAGNET_STAIRCASES:
        if name in study.loops:
            out[name.replace("broad_", "").replace(".csv", "").replace("_", " ")] = study.loops[
                name
            ]
    return out


def _headings(label, raw, params, fit, calibrated=None, result=None) -> dict:
    """Heading error RMS (deg) of our model and of the ellipsoid fit on ``raw``."""
    if calibrated is None:
        ours = heading_error_deg(correct_field(params, raw), raw, _declination(fit))
    else:
        data = apply_calibration(calibrated, raw)
        ours = heading_error_deg(
            correct_field(result.final.params, data), data, _declination(result.final)
        )
    W, c = ellipsoid_fit(raw)
    ell = heading_error_deg((raw[list(MAG)].to_numpy(float) - c) @ W.T, raw)
    return {
        "trial": label,
        "workbench model, heading rms (deg)": float(np.sqrt(np.mean(ours**2))),
        "ellipsoid fit, heading rms (deg)": float(np.sqrt(np.mean(ell**2))),
        "ellipsoid fit, max |error| (deg)": float(np.max(np.abs(ell))),
    }


def _declination(fit) -> float:
    return float(np.degrees(np.arctan2(fit.params["field_e_ut"], fit.params["field_n_ut"])))


@dataclass
class DistanceLaw:
    power_exponent: float
    power_coef: float
    dipole_coef: float
    dipole_offset_cm: float
    table: pd.DataFrame


def distance_law(trials: pd.DataFrame) -> DistanceLaw:
    """Fitted hard iron against the nominal magnet distance ``d``: a power law ``|b| = k d^-p`` (least
    squares in log-log) and a dipole law ``|b| = k (d + d0)^-3`` whose distance offset ``d0`` (the magnet's
    centre and the sensing element need not sit at the nominal distance) is fitted too (least squares on
    log ``|b|``)."""
    t = trials.dropna(subset=["nominal distance (cm)"])
    d = t["nominal distance (cm)"].to_numpy(float)
    b = t["|hard iron| (uT)"].to_numpy(float)
    if len(d) < 3 or np.any(b <= 0):
        raise InputError("distance_law: need at least 3 trials with a fitted hard iron")
    slope, icpt = np.polyfit(np.log(d), np.log(b), 1)
    sol = least_squares(
        lambda x: x[0] - 3 * np.log(d + x[1]) - np.log(b),
        [np.log(b[0]) + 3 * np.log(d[0] + 1), 1.0],
        bounds=([-np.inf, -0.99 * d.min()], [np.inf, 50.0]),
    )
    k_dip, d0 = float(np.exp(sol.x[0])), float(sol.x[1])
    table = pd.DataFrame(
        {
            "nominal distance (cm)": d,
            "|hard iron| (uT)": b,
            "power law (uT)": np.exp(icpt) * d**slope,
            "dipole law (uT)": k_dip * (d + d0) ** -3.0,
        }
    ).set_index("nominal distance (cm)")
    return DistanceLaw(float(-slope), float(np.exp(icpt)), k_dip, d0, table)
