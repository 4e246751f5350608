"""The workbench chapter's studies: the loop on simulated data, on the real BROAD recordings (level compass
sweeps and 3-D magnetometer trials), the magnet-distance law, the ellipsoid fit users would pick, and the
claims of the chapter's Results at a glance.

Real data: the BROAD benchmark (D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD - A Benchmark for
Robust Inertial Orientation Estimation", Data 6(7):72, 2021, CC BY 4.0), derived files in
``../shared/realdata/broad`` (never copied into this repository; where the folder is absent the functions
return None and the chapter says so).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from ..angles import wrap_deg
from ..errors import InputError, check_param
from ..data.gyro_tables import drift_measurements
from ..paths import ROOT
from ..report import Claim
from ..workbench.diagnose import diagnose
from ..workbench.effects import CATALOGUES
from ..workbench.fit import effect_rms, fit_model, load, simulate
from ..workbench.loop import LoopResult, loop
from ..workbench.magnetometer import (MAG, apply_calibration, correct_field, ellipsoid_fit, field_summary,
                                      heading_error_deg)
from ..workbench.trials import random_params, scale_effect
from .paper_a import Sweeps, compensate, error_stats, test_errors

#: Where the third-party measurements live (beside the repository, never inside it).
REALDATA = ROOT.parent / "shared" / "realdata"
LEVEL_DIR = REALDATA / "broad" / "level"
MAG_DIR = REALDATA / "broad" / "3d"
CALIBRATION_TRIAL = "broad_05_undisturbed_slow_rotation_with_breaks_B.csv"
#: Attached-magnet trials (file -> nominal distance of the magnet from the IMU in cm, from BROAD's trial list).
ATTACHED = {"broad_32_attached_magnet_1cm.csv": 1.0, "broad_33_attached_magnet_2cm.csv": 2.0,
            "broad_34_attached_magnet_3cm.csv": 3.0, "broad_35_attached_magnet_4cm.csv": 4.0,
            "broad_36_attached_magnet_5cm.csv": 5.0}
STATIONARY = ("broad_28_stationary_magnet_A.csv", "broad_29_stationary_magnet_B.csv",
              "broad_30_stationary_magnet_C.csv", "broad_31_stationary_magnet_D.csv")
MAX_ATT_BLUR = 0.01      # README: keep the block attitude blur below 0.01 for precise fits


def realdata_available() -> bool:
    """True when ``../shared/realdata/broad`` holds both the level and the 3-D files."""
    return LEVEL_DIR.is_dir() and MAG_DIR.is_dir()


# ------------------------------------------------------------------------------------ simulated loop
def simulated_compass(hidden_effect: str, hidden_ratio: float, noise_deg: float, seed: int) -> tuple[pd.DataFrame, float]:
    """Two simulated compass sweeps with every catalogue effect, ``hidden_effect`` scaled so that its RMS
    is ``hidden_ratio * noise_deg``.  Returns the data and the hidden effect's RMS (deg)."""
    check_param("hidden_ratio", hidden_ratio, lo=0)
    check_param("noise_deg", noise_deg, lo=0, lo_open=True)
    rng = np.random.default_rng(seed)
    params = random_params("compass", rng, CATALOGUES["compass"])
    probe = simulate("compass", params, noise=0.0)
    params = scale_effect("compass", probe, params, hidden_effect, hidden_ratio * noise_deg)
    data = simulate("compass", params, noise=noise_deg, seed=seed)
    return data, effect_rms("compass", probe, params, hidden_effect)


def with_three_cycle(data: pd.DataFrame, amplitude_deg: float, phase_deg: float = 30.0) -> pd.DataFrame:
    """``data`` with a three-cycle heading error added (an effect outside the catalogue)."""
    out = data.copy()
    h = np.radians(out["true_heading_deg"].to_numpy(float))
    out["measured_heading_deg"] = np.mod(out["measured_heading_deg"]
                                         + amplitude_deg * np.sin(3 * h + np.radians(phase_deg)), 360.0)
    return out


def network_vs_physics(data: pd.DataFrame, effects, methods=("BP (LM)",), seed: int = 0) -> pd.DataFrame:
    """Train on sweep 1, test on sweep 2 (paper A's protocol): each network of :mod:`navlib.studies.paper_a`
    sees only the measured heading; the physical model (``effects`` fitted on sweep 1, with the temperature
    of each reading) is inverted on sweep 2.  Test error min, max, rms (deg) per compensation."""
    train = data[data.sweep == 1].reset_index(drop=True)
    test = data[data.sweep == 2].reset_index(drop=True)
    sw = Sweeps(train, test)
    rows = []
    for method in methods:
        corrected, _ = compensate(method, sw, seed=seed)
        rows.append({"compensation": method, **error_stats(test_errors(corrected, sw))})
    phys = fit_model("compass", train, list(effects)).model
    corrected = phys.correct(test.measured_heading_deg, test.temperature_c)
    rows.append({"compensation": "physical model (" + " + ".join(effects) + ")",
                 **error_stats(wrap_deg(corrected - test.true_heading_deg))})
    return pd.DataFrame(rows).set_index("compensation").rename(columns={
        "min_deg": "min (deg)", "max_deg": "max (deg)", "rms_deg": "rms (deg)"})


def added(result: LoopResult) -> str:
    """The effects a loop added, in order."""
    return ", ".join(d.missing for d in result.diagnoses[:-1]) or "-"


def steps_frame(result: LoopResult, label: str = "") -> pd.DataFrame:
    """One row per step of a loop: model, rms, held-out rms, effect named (unit in the headers)."""
    t = result.steps_table().reset_index()
    if label:
        t.insert(0, "data", label)
    return t


# ------------------------------------------------------------------------------------ real level sweeps
@dataclass
class LevelLoops:
    """The loop from ``misalignment`` on each level BROAD file: the results and a summary table."""

    results: dict
    summary: pd.DataFrame


def level_loops(start_model=("misalignment",), alpha: float | None = None) -> LevelLoops | None:
    """Run :func:`navlib.workbench.loop.loop` on every file in ``broad/level`` (None if absent).

    The summary has one row per file: rows, the effects added in order, final rms and held-out rms (deg),
    the outcome, and the largest unexplained structure amplitude as a multiple of the residual RMS."""
    if not LEVEL_DIR.is_dir():
        return None
    results, rows = {}, []
    for path in sorted(LEVEL_DIR.glob("*.csv")):
        res = loop("compass", load("compass", path), list(start_model), alpha=alpha)
        results[path.name] = res
        amp = max([u["amplitude"] for u in res.unexplained] + [0.0])
        rows.append({"file": path.name, "rows": len(res.final.data),
                     "effects added": added(res),
                     "start rms (deg)": res.fits[0].rms, "final rms (deg)": res.final.rms,
                     "final held-out rms (deg)": res.final.loo_rms, "outcome": res.outcome(),
                     "largest structure / rms": amp / res.final.rms})
    return LevelLoops(results, pd.DataFrame(rows).set_index("file"))


# ------------------------------------------------------------------------------------ 3-D magnetometer
def load_trial(name: str, row_step: int = 1, attached_only: bool = False) -> pd.DataFrame:
    """A BROAD 3-D trial: blocks with attitude blur below 0.01, without the magnet being handled
    (``magnet_attached`` = -1), only the magnet-on blocks if ``attached_only``, and in motion for the
    stationary-magnet trials (the magnet is put down while the IMU rests); every ``row_step``-th block."""
    check_param("row_step", row_step, lo=1, integer=True)
    d = load("magnetometer", MAG_DIR / name)
    keep = (d["att_blur"] < MAX_ATT_BLUR) & (d["magnet_attached"] >= 0)
    if attached_only:
        keep &= d["magnet_attached"] == 1
    if name in STATIONARY:
        keep &= d["moving"] == 1
    return d[keep].iloc[::int(row_step)].reset_index(drop=True)


@dataclass
class MagnetStudy:
    """The 3-D chapter section: the calibration loop, one loop per disturbed trial, tables."""

    calibration: LoopResult
    field: pd.DataFrame
    trials: pd.DataFrame          # one row per disturbed trial
    loops: dict                   # file -> LoopResult (on calibrated data)
    headings: pd.DataFrame        # heading error of our model and of the ellipsoid fit


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
        rows.append({"trial": short, "magnet": "attached" if name in ATTACHED else "stationary",
                     "nominal distance (cm)": ATTACHED.get(name, np.nan), "rows": len(data),
                     "calibrated rms (uT)": res.fits[0].rms, "first effect named": res.diagnoses[0].missing or "-",
                     "effects added": added(res),
                     "final rms (uT)": res.final.rms, "|hard iron| (uT)": float(np.linalg.norm(b)),
                     "outcome": res.outcome()})
        if name in ATTACHED:
            heads.append(_headings(short, raw, None, None, calibrated=cal.final, result=res))
    return MagnetStudy(cal, field, pd.DataFrame(rows).set_index("trial"), loops, pd.DataFrame(heads).set_index("trial"))


def _headings(label, raw, params, fit, calibrated=None, result=None) -> dict:
    """Heading error RMS (deg) of our model and of the ellipsoid fit on ``raw``."""
    if calibrated is None:
        ours = heading_error_deg(correct_field(params, raw), raw, _declination(fit))
    else:
        data = apply_calibration(calibrated, raw)
        ours = heading_error_deg(correct_field(result.final.params, data), data, _declination(result.final))
    W, c = ellipsoid_fit(raw)
    ell = heading_error_deg((raw[list(MAG)].to_numpy(float) - c) @ W.T, raw)
    return {"trial": label, "workbench model, heading rms (deg)": float(np.sqrt(np.mean(ours ** 2))),
            "ellipsoid fit, heading rms (deg)": float(np.sqrt(np.mean(ell ** 2))),
            "ellipsoid fit, max |error| (deg)": float(np.max(np.abs(ell)))}


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
    sol = least_squares(lambda x: x[0] - 3 * np.log(d + x[1]) - np.log(b), [np.log(b[0]) + 3 * np.log(d[0] + 1), 1.0],
                        bounds=([-np.inf, -0.99 * d.min()], [np.inf, 50.0]))
    k_dip, d0 = float(np.exp(sol.x[0])), float(sol.x[1])
    table = pd.DataFrame({"nominal distance (cm)": d, "|hard iron| (uT)": b,
                          "power law (uT)": np.exp(icpt) * d ** slope,
                          "dipole law (uT)": k_dip * (d + d0) ** -3.0}).set_index("nominal distance (cm)")
    return DistanceLaw(float(-slope), float(np.exp(icpt)), k_dip, d0, table)


# ------------------------------------------------------------------------------------ glance
def glance_claims(rates: pd.DataFrame, ooc: pd.DataFrame, level: LevelLoops | None,
                  magnets: MagnetStudy | None) -> list[Claim]:
    """The chapter's claims (our users' targets) and whether this run meets them.

    ``rates``: :func:`navlib.workbench.trials.detection_rates` tables concatenated with a ``data`` column
    (compass and drift with at least 16 tests); ``ooc``: :func:`navlib.workbench.trials.out_of_catalogue_rates`."""
    named = rates[rates.rate == "correctly named"]
    alarms = rates[rates.rate == "false alarms"]
    lo_named, hi_alarm = float(named.value.min()), float(alarms.value.max())
    quiet = float(ooc.loc["all kinds", "no catalogued effect named"])
    claims = [
        Claim("a hidden catalogued effect of at least 3x the noise is named", ">= 95 % of runs",
              f"lowest rate {100 * lo_named:.0f} % over {int(named.trials.sum())} runs", lo_named >= 0.95,
              reading="compass sweeps and drift tables of >= 16 tests"),
        Claim("data with nothing missing are called noise", "<= 5 % false alarms",
              f"highest rate {100 * hi_alarm:.1f} % over {int(alarms.trials.sum())} runs", hi_alarm <= 0.05),
        Claim("an error outside the catalogue (5-8x noise) names no catalogued effect", ">= 90 % of runs",
              f"{100 * quiet:.0f} % of {int(ooc.loc['all kinds', 'trials'])} runs", quiet >= 0.90,
              reading="3- and 4-cycle errors, a step between sweeps, a drift in time"),
    ]
    if level is None or magnets is None:
        claims.append(Claim("the loop ends honestly on real recordings", "noise or named structure",
                            "real data absent", None, why="../shared/realdata not found"))
        return claims
    s = level.summary
    worst = float(s["largest structure / rms"].max())
    ok = bool(((s.outcome == "consistent with noise") | s.outcome.str.startswith("unexplained")).all() and worst <= 3)
    claims.append(Claim("real level sweeps: the loop ends consistent with noise or with named structure",
                        "never a structure > 3x the residual rms",
                        f"{len(s)} files; largest structure {worst:.2f}x rms", ok, reading="BROAD level sweeps"))
    att = magnets.trials[magnets.trials.magnet == "attached"]
    hard_first = int((att["first effect named"] == "hard_iron").sum())
    claims.append(Claim("an attached magnet: the calibrated model fails, diagnose names hard_iron, the error "
                        "falls", "hard_iron named, error falls",
                        f"hard_iron first in {hard_first}/{len(att)}; rms {att['calibrated rms (uT)'].median():.1f}"
                        f" -> {att['final rms (uT)'].median():.2f} uT (median)",
                        hard_first == len(att) and bool((att["final rms (uT)"] < att["calibrated rms (uT)"]).all()),
                        reading="BROAD trials 32-36"))
    sta = magnets.trials[magnets.trials.magnet == "stationary"]
    pos = int(sta.outcome.str.contains("position").sum())
    claims.append(Claim("a stationary magnet is reported as structure no body-fixed effect explains",
                        "unexplained structure", f"field changing with position named in {pos}/{len(sta)}",
                        pos == len(sta), reading="BROAD trials 28-31"))
    return claims


# ------------------------------------------------------------------------------------ paper C's tables
@dataclass
class DriftStudy:
    """Paper C's measured drift tables in the workbench: the hot fit, the diagnoses, the held-out table."""

    hot: pd.DataFrame
    cold: pd.DataFrame
    hot_fit: object
    hot_diagnosis: object
    diagnoses: dict               # "cold tests only" / "hot and cold tests" -> Diagnosis (earth_rate + bias)
    loo: pd.DataFrame             # held-out rms (1e-4 deg/h) of cold and hot tests per model
    temperature_change_coef: float


def drift_study(alpha: float | None = None) -> DriftStudy:
    """The loop on paper C's Tables 2-4 (``data/gyro_drift_measurements.csv``): the Table 1 Earth-rate
    model fitted on the hot tests, diagnoses of the cold and pooled tests from ``earth_rate + bias``, and
    the exact leave-one-out RMS of cold and hot tests as effects are added."""
    allrows = drift_measurements()
    hot, cold = allrows[allrows.state == "hot"], allrows[allrows.state == "cold"]
    hot_fit = fit_model("drift", hot, ["earth_rate"])
    diags = {name: diagnose(fit_model("drift", frame, ["earth_rate", "bias"]), alpha=alpha)
             for name, frame in (("cold tests only", cold), ("hot and cold tests", allrows))}
    is_cold = allrows.state.to_numpy() == "cold"
    loo = {}
    for effects in (["earth_rate"], ["earth_rate", "bias"], ["earth_rate", "bias", "temperature_change"]):
        r = fit_model("drift", allrows, effects).loo_residuals
        loo[" + ".join(effects)] = {"cold tests, held-out rms (1e-4 deg/h)": np.sqrt(np.mean(r[is_cold] ** 2)) * 1e4,
                                    "hot tests, held-out rms (1e-4 deg/h)": np.sqrt(np.mean(r[~is_cold] ** 2)) * 1e4}
    full = fit_model("drift", allrows, ["earth_rate", "bias", "temperature_change"])
    return DriftStudy(hot, cold, hot_fit, diagnose(hot_fit, alpha=alpha), diags, pd.DataFrame(loo).T,
                      full.params["temperature_change_coef_deg_h_per_c"])
