"""The workbench chapter's studies: the loop on simulated data, on the real BROAD recordings (level compass
sweeps and 3-D magnetometer trials), the magnet-distance law, the ellipsoid fit users would pick, and the
claims of the chapter's Results at a glance.

Real data: the BROAD benchmark (D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD - A Benchmark for
Robust Inertial Orientation Estimation", Data 6(7):72, 2021, CC BY 4.0), derived files in
``../shared/realdata/broad`` (never copied into this repository; where the folder is absent the functions
return None and the chapter says so).
"""
from __future__ import annotations

import tempfile
import textwrap
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from ..angles import wrap_deg
from ..errors import InputError, check_param
from ..data.gyro_tables import drift_measurements
from ..methods.ellipsoid import lm_ellipsoid
from ..paths import ROOT, data_path
from .. import engine, verdicts
from ..claims import Claim
from ..workbench.diagnose import DEFAULT_ALPHA, diagnose
from ..workbench.effects import CATALOGUES
from ..workbench.fit import effect_rms, fit_model, load, simulate
from ..workbench.loop import LoopResult, loop, staircase_of
from ..workbench.magnetometer import (MAG, apply_calibration, correct_field, ellipsoid_fit, field_summary,
                                      heading_error_deg)
from ..workbench.calibration import calibrate
from ..workbench.magnetometer_free import load_free
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


# ------------------------------------------------------------------------------------ bring your own data
# The file each system's section of "Bring your own data" samples: shipped in ``data/`` or BROAD trial 05
# in ``../shared/realdata`` (read there, never copied; no doc comment: the API page would print this
# machine's folders).
OWN_DATA_FILES = {"compass": data_path("compass_sweeps.csv"), "drift": data_path("gyro_drift_measurements.csv"),
                  "magnetometer": MAG_DIR / CALIBRATION_TRIAL, "magnetometer_free": MAG_DIR / CALIBRATION_TRIAL,
                  "accelerometer": data_path("accel_tumble.csv")}
#: Options a system's command needs on its sample file: the workbench fits one accelerometer, and
#: ``data/accel_tumble.csv`` holds two (units A and B), so the command picks one.
OWN_DATA_COMMAND_OPTIONS = {"accelerometer": ["--unit", "A"]}
#: How many rows of each sample file are shown.
SAMPLE_ROWS = 5


@dataclass
class OwnData:
    """One system's part of "Bring your own data": the columns its loader reads (``columns``,
    :func:`navlib.workbench.effects.columns_table`), the first rows of a sample file (``sample``: one
    row per column of the schema the file holds, one column per row of the file, the cells as written; None
    where the file is absent), the file as a path relative to the repository's folder (``file``) and the
    command that runs the loop on it with a report (``command``)."""

    system: str
    columns: pd.DataFrame
    sample: pd.DataFrame | None
    file: str
    command: str


def _shown_path(path: Path) -> str:
    """A sample file as the reader types it from the repository's folder: ``data/NAME`` for a shipped
    file, ``../shared/realdata/...`` for the third-party recordings."""
    from ..paths import DATA_DIR
    if path.parent == DATA_DIR:
        return f"data/{path.name}"
    try:
        return str(Path("..") / path.relative_to(ROOT.parent))
    except ValueError:
        return str(path)


def shell_command(words, width: int = 80) -> str:
    """``words`` as one shell command, continued with a backslash onto indented lines where a line would
    pass ``width`` characters (a command shown in the book stays within the column)."""
    lines, line = [], ""
    for w in words:
        if line and len(line) + 1 + len(w) > width:
            lines.append(line + " \\")
            line = "    " + w
        else:
            line = f"{line} {w}" if line else w
    return "\n".join(lines + [line])


def wrap_report(text: str, width: int = 88) -> str:
    """A report's text with lines longer than ``width`` wrapped (tables and short lines as written)."""
    return "\n".join(textwrap.fill(ln, width) if len(ln) > width and not ln.startswith("|") else ln
                     for ln in text.splitlines())


def own_data(system: str, rows: int = SAMPLE_ROWS) -> OwnData:
    """The columns table, ``rows`` sample rows of ``OWN_DATA_FILES`` and the one command
    (``navlib loop SYSTEM FILE --report DIR``) for ``system`` on the sample file, with the options of
    :data:`OWN_DATA_COMMAND_OPTIONS` it needs."""
    from ..workbench.effects import columns_table
    check_param("rows", rows, lo=1, integer=True)
    if system not in OWN_DATA_FILES:
        raise InputError(f"parameter system={system!r}: one of {', '.join(OWN_DATA_FILES)}")
    path = OWN_DATA_FILES[system]
    cols = columns_table(system)
    sample = None
    if path.is_file():
        head = pd.read_csv(path, nrows=rows, dtype=str, keep_default_na=False)
        names = [c for c in cols["column"] if c in head.columns]
        sample = head[names].T
        sample.columns = [f"row {i + 1}" for i in range(len(head))]
        sample.index.name = "column"
    shown = _shown_path(path)
    return OwnData(system, cols, sample, shown,
                   shell_command(["navlib", "loop", system, shown, *OWN_DATA_COMMAND_OPTIONS.get(system, []),
                                  "--report", f"out_{system}/"]))


def own_data_report(folder, system: str = "compass", start_model=()) -> tuple[Path, Path]:
    """What ``navlib loop SYSTEM FILE --report FOLDER`` writes for the sample file of ``system``
    (``OWN_DATA_FILES``): the system's loader, :func:`navlib.workbench.loop.loop` from ``start_model``
    and the CLI's own :func:`navlib.workbench.loop.write_report` (never over existing files).  Returns the
    paths of ``loop.png`` and ``loop.md``."""
    from ..workbench.loop import write_report
    path = OWN_DATA_FILES[system]
    result = loop(system, load(system, path), list(start_model))
    return write_report(result, folder, source=_shown_path(path))


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


def undisturbed_trials() -> list[str]:
    """The undisturbed BROAD 3-D trials (01-07 and 21), file names in order ([] if the data are absent)."""
    return sorted(p.name for p in MAG_DIR.glob("*undisturbed*.csv")) if MAG_DIR.is_dir() else []


def undisturbed_loop(name: str, row_step: int = 3, alpha: float | None = None) -> dict:
    """The loop from the local field alone on one undisturbed trial (:func:`load_trial`): what it ends
    with -- rows used and set aside as outliers, the noise model, the effects added, the final rms, the
    outcome and the largest unexplained structure -- and ``staircase``, the loop's
    :class:`navlib.workbench.loop.Staircase`."""
    data = load_trial(name, row_step)
    res = loop("magnetometer", data, [], alpha=alpha)
    noise = res.screening.noise
    amp = max([u["amplitude"] for u in res.unexplained] + [0.0])
    return {"trial": name.replace("broad_", "").replace(".csv", "").replace("_", " "), "rows": len(data),
            "rows set aside": len(res.screening.rows_set_aside),
            "noise model": f"AR({noise.order}), lag-1 {noise.lag1:.2f}" if noise.correlated else "independent",
            "effects added": added(res), "final rms (uT)": res.final.rms,
            "largest structure (uT)": amp, "outcome": res.outcome(), "staircase": staircase_of(res)}


def undisturbed_loops(row_step: int = 3, alpha: float | None = None, workers: int = 1,
                      scheduler: str | None = None) -> pd.DataFrame | None:
    """:func:`undisturbed_loop` on every undisturbed BROAD 3-D trial, one row each (None if the data are
    absent); ``workers``, ``scheduler``: where they run (:mod:`navlib.engine`, the largest files first; the
    workers read the files, so a remote cluster needs them at the same path)."""
    return _on_undisturbed(undisturbed_loop, row_step, alpha, workers, scheduler, "BROAD loops")


def _on_undisturbed(fn, row_step, alpha, workers, scheduler, label) -> pd.DataFrame | None:
    """``fn(name, row_step, alpha)`` on every undisturbed BROAD 3-D trial on the engine (the longest
    recordings first), one row each indexed by ``trial``; each row's ``staircase`` (a loop's
    :class:`navlib.workbench.loop.Staircase`) goes into ``attrs["staircases"]`` (trial -> Staircase), not
    into the table.  None if the data are absent."""
    names = undisturbed_trials()
    if not names:
        return None
    check_param("row_step", row_step, lo=1, integer=True)
    rows = engine.run(fn, [(n, row_step, alpha) for n in names], workers=workers, scheduler=scheduler,
                      label=label, cost=[float((MAG_DIR / n).stat().st_size) for n in names])
    stairs = {r["trial"]: st for r in rows if (st := r.pop("staircase", None)) is not None}
    out = pd.DataFrame(rows).set_index("trial")
    out.attrs["staircases"] = stairs
    return out


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


#: The loops of :func:`magnet_study` drawn as staircases: the calibration, the nearest and the farthest
#: attached magnet, and the first stationary magnet.
MAGNET_STAIRCASES = ("broad_32_attached_magnet_1cm.csv", "broad_36_attached_magnet_5cm.csv",
                     "broad_28_stationary_magnet_A.csv")


def magnet_staircases(study: MagnetStudy) -> dict:
    """Representative loops of :func:`magnet_study` for :func:`navlib.workbench.loop.staircase_grid`,
    panel title -> LoopResult: the calibration on trial 05 and the trials of :data:`MAGNET_STAIRCASES`
    (after the trial-05 calibration)."""
    out = {"05 undisturbed (calibration)": study.calibration}
    for name in MAGNET_STAIRCASES:
        if name in study.loops:
            out[name.replace("broad_", "").replace(".csv", "").replace("_", " ")] = study.loops[name]
    return out


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
#: Our users' targets for the loop (the book's own; no paper states them), as shares of trials.
TARGET_NAMED = 0.95          # a hidden catalogued effect is named in at least 95 % of trials
TARGET_FALSE_ALARMS = 0.05   # data with nothing missing raise at most 5 % false alarms
TARGET_QUIET = 0.90          # an error outside the catalogue names no catalogued effect in at least 90 %
#: Our bound on a real sweep: the unexplained structure left at the end, as a multiple of the residual rms.
STRUCTURE_BOUND = 3.0
NOT_IN_PAPER = "(not in the paper)"
#: The level files' claims: file -> (glue key, reading); the other real-data keys: wb_attached, wb_stationary.
LEVEL_CLAIMS = {"broad_trial05_level.csv": ("wb_level_trial05", "BROAD trial 05, level sweeps"),
                "broad_trials_level_by_trial.csv": ("wb_level_by_trial", "BROAD trials 2, 3, 5, 7, level")}
REALDATA_KEYS = tuple(k for k, _ in LEVEL_CLAIMS.values()) + ("wb_attached", "wb_stationary", "wb_free_heading")


@dataclass(frozen=True)
class Case:
    """One case of a rate claim (e.g. one data set and hidden effect): ``k`` of ``n`` independent trials."""

    name: str
    k: int
    n: int

    @property
    def estimate(self) -> verdicts.Estimate:
        """The rate ``k / n`` with its 95 % Wilson interval (:func:`navlib.verdicts.wilson`)."""
        return verdicts.wilson(self.k, self.n)


def rate_cases(frame: pd.DataFrame, by, success: str) -> list[Case]:
    """One :class:`Case` per group of ``frame`` (grouped by the column(s) ``by``), counting the True
    values of the boolean column ``success``."""
    out = []
    for name, g in frame.groupby(by, sort=False):
        name = " / ".join(map(str, name)) if isinstance(name, tuple) else str(name)
        out.append(Case(name, int(g[success].astype(bool).sum()), int(len(g))))
    if not out:
        raise InputError(f"rate_cases: no trials to count ({success!r})")
    return out


def worst_case(cases: list[Case], boundary: float, holds_when: str) -> Case:
    """The case whose Wilson interval decides a rate claim that must hold in **every** case: a case whose
    whole interval lies on the wrong side of ``boundary`` if there is one (the farthest), else the case
    whose interval reaches nearest to the wrong side (lowest lower bound for ``"above"``, highest upper
    bound for ``"below"``).  So the claim is reproduced only if every case's interval is on its side, not
    reproduced if any case's interval is wholly on the other side, and cannot be judged otherwise."""
    if not cases:
        raise InputError("worst_case: no cases")
    if holds_when not in verdicts.SIDES:
        raise InputError(f"worst_case: holds_when={holds_when!r}: must be 'above' or 'below'")
    other = "below" if holds_when == "above" else "above"
    wrong = [c for c in cases if verdicts.on_side(c.estimate.lo, boundary, other)
             and verdicts.on_side(c.estimate.hi, boundary, other)]
    if holds_when == "above":
        return min(wrong, key=lambda c: c.estimate.hi) if wrong else min(cases, key=lambda c: c.estimate.lo)
    return max(wrong, key=lambda c: c.estimate.lo) if wrong else max(cases, key=lambda c: c.estimate.hi)


def _wilson_bounds(p: float, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return c - h, c + h


def trials_needed(k: int, n: int, boundary: float, holds_when: str, limit: int = 1_000_000) -> int | None:
    """How many trials a case would need, at its observed rate ``k / n``, for its 95 % Wilson interval
    to lie wholly on one side of ``boundary`` (None if the rate sits on the boundary or more than
    ``limit`` trials would be needed)."""
    p = k / n
    if p == boundary:
        return None

    def decisive(m: int) -> bool:
        lo, hi = _wilson_bounds(p, m)
        return lo > boundary or hi < boundary

    if decisive(n):
        return n
    hi = n
    while not decisive(hi):
        hi *= 2
        if hi > limit:
            return None
    lo = hi // 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if decisive(mid) else (mid, hi)
    return hi


def _sizes(frame: pd.DataFrame) -> str:
    """The effect sizes of a trial study, e.g. "3 and 10 x noise"."""
    return " and ".join(f"{r:g}" for r in sorted(frame.ratio.unique())) + " x noise"


def _levels(frame: pd.DataFrame) -> int:
    """The number of noise levels of a trial study (per data set when several are concatenated)."""
    return int(frame.groupby("data").noise.nunique().max()) if "data" in frame else int(frame.noise.nunique())


def _pct(e: verdicts.Estimate) -> verdicts.Estimate:
    """A Wilson rate in percent (same interval, same rule)."""
    return verdicts.Estimate(100 * e.value, 100 * e.lo, 100 * e.hi, e.rule, e.n)


def _rate_claim(claim: str, cases: list[Case], target: float, holds_when: str, *, statistic: str,
                reading: str, decided_by: tuple[str, ...], key: str, what: str = "") -> Claim:
    """A book claim on a rate that must meet ``target`` in every case, judged on the worst case's Wilson
    interval (:func:`worst_case`), in percent; if undecided, ``why`` says how many trials it would need."""
    w = worst_case(cases, target, holds_when)
    need = trials_needed(w.k, w.n, target, holds_when)
    why = ""
    if verdicts.decide(w.estimate.interval, target, holds_when)[1] == "straddles":
        where = f"{w.n} trials in the worst case" if len(cases) > 1 else f"{w.n} trials"
        why = (f"{where}; at this rate a decisive interval needs about {need}" if need is not None
               else f"{where}; at this rate no number of trials decides it")
    ours = f"worst of {len(cases)}: {w.name}, {w.k}/{w.n}" if len(cases) > 1 else f"{w.k} of {w.n} trials"
    return Claim(claim, NOT_IN_PAPER, reading=reading, source="book", statistic=statistic,
                 estimate=_pct(w.estimate), boundary=100 * target, holds_when=holds_when, unit="%",
                 decided_by=decided_by, why=why, key=key,
                 ours=ours + what)


def glance_claims(studies: dict, ooc: pd.DataFrame, level: LevelLoops | None,
                  magnets: MagnetStudy | None, alpha: float | None = None,
                  free_heads: pd.DataFrame | None = None) -> list[Claim]:
    """The chapter's claims: the book's own (our users' targets, not a paper's), each judged by the one
    rule of :mod:`navlib.verdicts`.

    ``studies``: data label -> :func:`navlib.workbench.trials.hidden_effect_study` table (the data sets
    the targets are claimed for); ``ooc``: :func:`navlib.workbench.trials.out_of_catalogue_study` table;
    ``level`` and ``magnets``: the real-data studies (None when ``../shared/realdata`` is absent: the
    claims on real data are then left out); ``alpha``: the level of ``diagnose`` in the real-data loops;
    ``free_heads``: :func:`reference_free_headings` (its claim, :func:`free_vs_reference_claim`, is added).

    Rates are judged on the 95 % Wilson interval of the worst case (one data set and hidden effect; one
    data set; one kind of error): every case must meet the target.  Within a case the trials of both
    effect sizes and both noise levels are pooled (the smaller size is the harder half).  The level
    sweeps are judged file by file on an exact statistic (a deterministic fit of fixed data)."""
    if not studies:
        raise InputError("glance_claims: give at least one hidden-effect study")
    a = f"diagnose at family-wise alpha {DEFAULT_ALPHA:g} (the trials' default)"
    real_a = f"diagnose at family-wise alpha {DEFAULT_ALPHA if alpha is None else alpha:g}"
    frames = [st.assign(data=name) for name, st in studies.items()]
    trials = pd.concat(frames, ignore_index=True)
    hidden, none = trials[trials.hidden != "(none)"], trials[trials.hidden == "(none)"]
    named = rate_cases(hidden, ["data", "hidden"], "correct")
    alarms = [Case(c.name, c.n - c.k, c.n) for c in rate_cases(none, "data", "correct")]
    quiet = rate_cases(ooc, "kind", "quiet")
    data_sets = ", ".join(studies)
    claims = [
        _rate_claim("a hidden catalogued effect is named (our target: >= 95 % of trials)", named,
                    TARGET_NAMED, "above", key="wb_named",
                    statistic=f"share of trials naming the hidden effect, worst case (data set x hidden "
                              f"effect), sizes {_sizes(hidden)} and {_levels(hidden)} noise levels "
                              f"pooled, %",
                    reading=f"{data_sets}; effect {_sizes(hidden)}",
                    decided_by=(a, "simulated data: random plausible parameters of every catalogued effect",
                                "the hidden effect's RMS set to its size x the noise")),
        _rate_claim("data with nothing missing are called noise (our target: <= 5 % false alarms)", alarms,
                    TARGET_FALSE_ALARMS, "below", key="wb_false_alarms",
                    statistic=f"share of trials with a false alarm, worst data set, "
                              f"{_levels(none)} noise levels pooled per data set, %",
                    reading=data_sets,
                    decided_by=(a, "simulated data: a random subset of effects, the model exactly that subset")),
        _rate_claim("an error outside the catalogue names no catalogued effect (our target: >= 90 %)", quiet,
                    TARGET_QUIET, "above", key="wb_quiet",
                    statistic=f"share of trials naming no catalogued effect, worst kind of error, sizes "
                              f"{_sizes(ooc)} and {_levels(ooc)} noise levels pooled, %",
                    reading="3- and 4-cycle errors, a step between sweeps, a drift in time; "
                            f"{_sizes(ooc)}",
                    decided_by=(a, "simulated compass sweeps; model = the catalogued effects present "
                                   "+ misalignment")),
    ]
    if level is None or magnets is None:
        return claims
    for name, res in level.results.items():
        amp = max([u["amplitude"] for u in res.unexplained] + [0.0])
        stem = "".join(ch if ch.isalnum() else "_" for ch in Path(name).stem)
        key, reading = LEVEL_CLAIMS.get(name, (f"wb_level_{stem}", f"BROAD {name}"))
        claims.append(Claim(
            f"a real level sweep: the loop leaves no structure > {STRUCTURE_BOUND:g}x the residual rms "
            f"(our bound)", NOT_IN_PAPER, reading=reading, source="book",
            statistic="largest unexplained structure amplitude / final residual rms (deterministic fit of "
                      "this file)",
            estimate=verdicts.exact(amp / res.final.rms), boundary=STRUCTURE_BOUND, holds_when="below",
            unit="x rms", decided_by=(real_a, "start model: misalignment", "BROAD reference heading (3-deg bins)"),
            key=key, ours="consistent with noise" if res.consistent_with_noise else
            f"{len(res.unexplained)} unexplained structures named"))
    att = magnets.trials[magnets.trials.magnet == "attached"]
    ok = (att["first effect named"] == "hard_iron") & (att["final rms (uT)"] < att["calibrated rms (uT)"])
    att_case = Case("BROAD trials 32-36", int(ok.sum()), int(len(att)))
    claims.append(_rate_claim(
        "an attached magnet: diagnose names hard_iron first and the error falls (our target: >= 95 %)",
        [att_case], TARGET_NAMED, "above", key="wb_attached",
        statistic="share of attached-magnet trials with hard_iron named first and a lower final rms, %",
        reading="BROAD trials 32-36 (magnet 1-5 cm)",
        decided_by=(real_a, "the trial-05 calibration, shared by every trial", "blocks with attitude blur < 0.01"),
        what=f"; rms {att['calibrated rms (uT)'].median():.1f} -> {att['final rms (uT)'].median():.2f} uT"))
    sta = magnets.trials[magnets.trials.magnet == "stationary"]
    pos = sta.outcome.str.contains("position")
    claims.append(_rate_claim(
        "a stationary magnet: reported as a field changing with position (our target: >= 90 %)",
        [Case("BROAD trials 28-31", int(pos.sum()), int(len(sta)))], TARGET_QUIET, "above",
        key="wb_stationary",
        statistic="share of stationary-magnet trials reported as a field changing with position, %",
        reading="BROAD trials 28-31 (moving blocks)",
        decided_by=(real_a, "the trial-05 calibration, shared by every trial", "moving blocks only")))
    if free_heads is not None:
        claims.append(free_vs_reference_claim(free_heads))
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
    loop: LoopResult | None = None  # the loop on every test (hot and cold) from no effect


def drift_study(alpha: float | None = None) -> DriftStudy:
    """The loop on paper C's Tables 2-4 (``data/gyro_drift_measurements.csv``): the Table 1 Earth-rate
    model fitted on the hot tests, diagnoses of the cold and pooled tests from ``earth_rate + bias``, the
    exact leave-one-out RMS of cold and hot tests as effects are added, and the whole loop on all tests
    from no effect (``loop``, drawn as a staircase by the chapter)."""
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
                      full.params["temperature_change_coef_deg_h_per_c"],
                      loop("drift", allrows, [], alpha=alpha))


def accelerometer_loop(unit: str = "A", start=("bias",), alpha: float | None = None) -> LoopResult:
    """The workbench loop on one accelerometer of the shipped tumble file ``data/accel_tumble.csv``
    (:func:`navlib.workbench.accelerometer.load_accelerometer` with ``unit``), from the model ``start``: what
    ``python -m navlib loop accelerometer FILE --unit A --model bias`` does."""
    from ..data.tumble import TUMBLE_FILE
    from ..workbench.accelerometer import load_accelerometer
    return loop("accelerometer", load_accelerometer(TUMBLE_FILE, unit=unit), list(start), alpha=alpha)


#: Share of each recording (its first rows, in time) the calibrations are fitted on; the rest judges them.
PEER_TRAIN_SHARE = 0.7


@dataclass(frozen=True)
class PeerComparison:
    """``navlib calibrate`` beside a dedicated calibrator's fit (:func:`calibration_beside_peer`):
    ``accuracy`` per trial (rows; held-out direction RMS, deg, and magnitude spread, %, raw, peer and
    navlib; each one's outcome), ``times`` per trial (seconds per fit, this machine's clock: volatile)."""

    accuracy: pd.DataFrame
    times: pd.DataFrame

    def summary(self) -> dict:
        """Counts for the prose: trials, calibrated, warned, refused; where navlib and the peer made the
        held-out direction worse than the raw field; the median time ratio."""
        a = self.accuracy
        cal = a[a["navlib"] != "refused"]
        worse = cal[cal["navlib direction (deg)"] > cal["raw direction (deg)"]]
        return {"trials": len(a), "calibrated": len(cal), "warned": int((a["navlib"] == "warned").sum()),
                "peer_failed": int((a["peer"] != "fitted").sum()),
                "refused": int((a["navlib"] == "refused").sum()), "navlib_worse": len(worse),
                "navlib_worse_warned": int((worse["navlib"] == "warned").sum()),
                "peer_worse": int((a["peer direction (deg)"] > a["raw direction (deg)"]).sum()),
                "time_ratio": float((self.times["navlib (s)"] / self.times["peer (s)"]).median())}


def held_out_field_errors(m_corrected: np.ndarray, q: np.ndarray) -> tuple[float, float]:
    """Held-out accuracy of a corrected field (n, 3): the RMS angle (deg) of the field rotated to the world
    frame by the reference attitude ``q`` (w, x, y, z; body to world) from its mean direction, and the
    spread of its magnitude (std / mean, %).  A perfect calibration in a clean field gives 0 and 0."""
    mag = np.linalg.norm(m_corrected, axis=1)
    w = Rotation.from_quat(np.asarray(q, float)[:, [1, 2, 3, 0]]).apply(m_corrected)
    u = w / np.linalg.norm(w, axis=1, keepdims=True)
    mean = u.mean(axis=0)
    ang = np.degrees(np.arccos(np.clip(u @ (mean / np.linalg.norm(mean)), -1.0, 1.0)))
    return float(np.sqrt(np.mean(ang ** 2))), 100.0 * float(np.std(mag) / np.mean(mag))


def calibration_beside_peer(files=None, train_share: float = PEER_TRAIN_SHARE) -> PeerComparison | None:
    """``navlib calibrate`` (the library call of the CLI: :func:`navlib.workbench.calibration.calibrate` on
    :func:`~navlib.workbench.magnetometer_free.load_free` of the training rows) beside the Levenberg-Marquardt
    ellipsoid fit a dedicated calibrator does (:func:`navlib.methods.ellipsoid.lm_ellipsoid`), on every BROAD
    3-D recording (or ``files``): each fitted on the first ``train_share`` of the rows and judged on the
    rest (:func:`held_out_field_errors`; the reference attitude only judges).  navlib's outcome per trial:
    "calibrated", "warned" (calibrated with a warning, e.g. an accelerated sensor) or "refused" (the data
    cannot separate the parameters).  None without the data."""
    check_param("train_share", train_share, lo=0.1, hi=0.9)
    files = sorted(MAG_DIR.glob("*.csv")) if files is None else [Path(f) for f in files]
    if not files:
        return None
    acc, times = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            d = pd.read_csv(path)
            cut = int(train_share * len(d))
            train, test = d.iloc[:cut], d.iloc[cut:]
            m = test[list(MAG)].to_numpy(float)
            q = test[["q_w", "q_x", "q_y", "q_z"]].to_numpy(float)
            label = path.stem.replace("broad_", "").replace("_", " ")
            row = {"trial": label, "rows": len(d)}
            row["raw direction (deg)"], row["raw spread (%)"] = held_out_field_errors(m, q)
            t0 = time.perf_counter()
            try:
                b, S, _ = lm_ellipsoid(train[list(MAG)].to_numpy(float))
            except InputError:                  # the algebraic start is no ellipsoid: the peer has no fit
                row["peer direction (deg)"] = row["peer spread (%)"] = float("nan")
                row["peer"] = "no ellipsoid"
            else:
                row["peer direction (deg)"], row["peer spread (%)"] = held_out_field_errors((m - b) @ S, q)
                row["peer"] = "fitted"
            t_peer = time.perf_counter() - t0
            part = Path(tmp) / path.name
            train.to_csv(part, index=False)
            t0 = time.perf_counter()
            try:
                cal = calibrate(load_free(part))
            except InputError:
                row["navlib direction (deg)"] = row["navlib spread (%)"] = float("nan")
                row["navlib"] = "refused"
            else:
                A, bn = np.asarray(cal["magcal"]["A"]), np.asarray(cal["magcal"]["b_ut"])
                row["navlib direction (deg)"], row["navlib spread (%)"] = held_out_field_errors((m - bn) @ A, q)
                row["navlib"] = "warned" if cal.get("warnings") else "calibrated"
            times.append({"trial": label, "navlib (s)": time.perf_counter() - t0, "peer (s)": t_peer})
            acc.append(row)
    return PeerComparison(pd.DataFrame(acc).set_index("trial"), pd.DataFrame(times).set_index("trial"))


def reference_free_headings(reference: LoopResult, row_step: int = 3) -> pd.DataFrame | None:
    """Issue 23: the reference-free calibration against the reference-based one on BROAD.  On the
    calibration trial 05 (every ``row_step``-th block) the reference-free system
    (:mod:`navlib.workbench.magnetometer_free`: field and accelerometer only, the reference quaternion
    ignored) is calibrated with hard iron, scale and soft iron (the full ellipsoid, what ``navlib calibrate
    magnetometer`` fits) and its correction ``(m - b) A`` applied to every undisturbed trial, beside the
    reference-based calibration ``reference`` (the loop of :func:`magnet_study` on the same trial) and the
    raw field.  Heading error (deg) of each against the optical reference: the corrected field levelled
    with the reference attitude, its declination minus its circular mean on that trial (so a constant
    heading offset, the declination and the rotation the invariants cannot see are not counted).  One row
    per trial: rows, RMS heading error raw / reference-free / reference-based, and the reference-free
    calibration's field strength and dip.  None if the data are absent."""
    from ..workbench.calibration import DEFAULT_MODEL, apply_calibration as apply_free, calibrate
    from ..workbench.magnetometer_free import ACC, with_invariants
    names = undisturbed_trials()
    if not names:
        return None
    check_param("row_step", row_step, lo=1, integer=True)

    def free_frame(d):
        return with_invariants(d[list(MAG) + list(ACC) + ["time_s"]])

    cal = calibrate(free_frame(load_trial(CALIBRATION_TRIAL, row_step)), DEFAULT_MODEL, source=CALIBRATION_TRIAL)
    rows = []
    for name in names:
        d = load_trial(name, row_step)
        free = apply_free(cal, free_frame(d))[list(MAG)].to_numpy(float)

        def rms(field):
            return float(np.sqrt(np.mean(heading_error_deg(field, d) ** 2)))

        rows.append({"trial": name.replace("broad_", "").replace(".csv", "").replace("_", " "), "rows": len(d),
                     "raw field (deg)": rms(d[list(MAG)].to_numpy(float)),
                     "reference-free calibration (deg)": rms(free),
                     "reference-based calibration (deg)": rms(correct_field(reference.final.params, d))})
    out = pd.DataFrame(rows).set_index("trial")
    out.attrs["field_ut"] = cal["expected_field_strength_ut"]["value"]
    out.attrs["dip_deg"] = cal.get("dip_deg", float("nan"))
    return out


# ------------------------------------------------------------------------- issue 23: without a reference
#: Where BROAD was recorded, as its README states it: it gives no site or date, so the reference-free
#: loop's local field is not compared with IGRF on BROAD (the CLI does it wherever a site is known).
BROAD_SITE = None
#: Every this-many 0.1 s blocks of a BROAD trial in the reference-free loops (about 1 Hz: the chapter's time
#: is bounded).
FREE_ROW_STEP = 9


def _free_frame(d: pd.DataFrame) -> pd.DataFrame:
    from ..workbench.magnetometer_free import ACC, with_invariants
    return with_invariants(d[list(MAG) + list(ACC) + ["time_s"]])


def free_undisturbed_loop(name: str, row_step: int = FREE_ROW_STEP, alpha: float | None = None) -> dict:
    """The reference-free loop (:mod:`navlib.workbench.magnetometer_free`: field and accelerometer only,
    the optical reference ignored) from the local field alone on one undisturbed BROAD trial, every
    ``row_step``-th block: what it ends with -- rows, rows set aside, the noise model, the effects added,
    the final rms, the outcome, and the local field it estimates (intensity and dip with their 95 %
    half-widths; the system's ``final_check`` without a site, :data:`BROAD_SITE`), and ``staircase`` (the
    loop's :class:`navlib.workbench.loop.Staircase`); a trial the system refuses (e.g. too few distinct
    orientations at this row step) says so in ``outcome`` and has no staircase."""
    from ..workbench.magnetometer_free import SYSTEM as FREE
    data = _free_frame(load_trial(name, row_step))
    label = name.replace("broad_", "").replace(".csv", "").replace("_", " ")
    try:
        res = loop(FREE, data, [], alpha=alpha)
    except InputError as err:          # what the CLI would refuse (e.g. too few distinct orientations)
        return {"trial": label, "rows": len(data), "rows set aside": 0, "noise model": "-", "effects added": "-",
                "final rms (uT)": float("nan"), "outcome": "refused: " + str(err).split(": ", 1)[-1][:60],
                "field (uT)": float("nan"), "field 95% (uT)": float("nan"), "dip (deg)": float("nan"),
                "dip 95% (deg)": float("nan"), "what is left": "-"}
    check, _ = FREE.final_check(res, BROAD_SITE, None)
    noise = res.screening.noise
    return {"trial": label, "rows": len(data),
            "rows set aside": len(res.screening.rows_set_aside),
            "noise model": f"AR({noise.order}), lag-1 {noise.lag1:.2f}" if noise.correlated else "independent",
            "effects added": added(res), "final rms (uT)": res.final.rms, "outcome": res.outcome(),
            "field (uT)": check["intensity_ut"], "field 95% (uT)": 1.96 * check["intensity_std_ut"],
            "dip (deg)": check["dip_deg"], "dip 95% (deg)": 1.96 * check["dip_std_deg"],
            "what is left": "-" if res.consistent_with_noise else _top_factor(res), "staircase": staircase_of(res)}


def _top_factor(res: LoopResult) -> str:
    """The factor holding the largest share of the final residuals (:meth:`LoopResult.remaining`), short."""
    table, _ = res.remaining()
    if table.empty:
        return "-"
    top = table.loc[table["share"].idxmax()]
    return f"{top['factor']} ({'|m|' if top['invariant'] == 'magnitude' else 'dip'}) {100 * top['share']:.0f}%"


def free_undisturbed_loops(row_step: int = FREE_ROW_STEP, alpha: float | None = None, workers: int = 1,
                           scheduler: str | None = None) -> pd.DataFrame | None:
    """:func:`free_undisturbed_loop` on every undisturbed BROAD 3-D trial, one row each (None if the data
    are absent)."""
    return _on_undisturbed(free_undisturbed_loop, row_step, alpha, workers, scheduler,
                           "BROAD reference-free loops")


def free_vs_reference_claim(heads: pd.DataFrame) -> Claim:
    """The book's claim on :func:`reference_free_headings`: without the optical reference the calibration
    is as good for heading as the reference-based one -- the RMS heading error with the reference-free
    calibration minus that with the reference-based one, paired over the undisturbed trials (median and its
    order-statistic interval, :func:`navlib.verdicts.paired_difference`), at most 0 deg."""
    free = heads["reference-free calibration (deg)"].to_numpy(float)
    ref = heads["reference-based calibration (deg)"].to_numpy(float)
    est = verdicts.paired_difference(free, ref)
    return Claim("without the reference, the calibration's heading error is no larger than with it",
                 NOT_IN_PAPER, reading=f"BROAD undisturbed trials ({len(heads)}), both calibrated on trial 05",
                 source="book",
                 statistic="RMS heading error against the optical reference, reference-free minus reference-"
                           "based calibration, paired over trials (median), deg",
                 estimate=est, boundary=0.0, holds_when="below", unit="deg",
                 decided_by=("full ellipsoid (hard iron, scale, soft iron) without reference",
                             "the reference-based loop's final model on trial 05",
                             "each trial's mean heading offset removed"),
                 key="wb_free_heading",
                 ours=f"median {np.median(free):.2f} vs {np.median(ref):.2f} deg")


def conventions_example() -> pd.DataFrame:
    """The library's heading and rotation conventions on one worked example, computed by navlib: the
    quaternion of a 90 deg yaw (scalar first, rotating body FRD into NED, as the ``magnetometer`` systems
    and BROAD's files use it), the body's forward axis it turns into NED, the body field a level compass
    sees there and its heading (:func:`navlib.angles.heading_deg`, deg clockwise from north), and the same
    turn in paper E's convention (:mod:`navlib.sensors.trajectory`: yaw in rad counter-clockwise from north,
    body x right, y forward, z up, navigation frame ENU), whose forward axis it also turns east."""
    from ..angles import DEG, heading_deg
    from ..sensors.trajectory import euler_to_dcm
    from ..workbench.magnetometer import QUAT, body_from_nav
    yaw = 90.0
    q = np.array([np.cos(yaw * DEG / 2), 0.0, 0.0, np.sin(yaw * DEG / 2)])
    C_nb = body_from_nav(pd.DataFrame([q], columns=list(QUAT)))[0]      # NED -> body
    forward_ned = C_nb.T @ np.array([1.0, 0.0, 0.0])
    field_ned = np.array([20.0, 0.0, 40.0])                                # north and down, uT
    field_body = C_nb @ field_ned
    e_yaw = -yaw * DEG                                                     # the same turn, paper E's way
    e_forward = euler_to_dcm(np.array([0.0, 0.0, e_yaw])) @ np.array([0.0, 1.0, 0.0])   # C_b^n, ENU
    rows = [("yaw (compass, workbench, BROAD)", f"{yaw:g} deg, clockwise from north (east of north)"),
            ("quaternion q_w, q_x, q_y, q_z", ", ".join(f"{v:.4f}" for v in q)),
            ("body x (forward) in NED", ", ".join(f"{v:+.3f}" for v in forward_ned) + "  (points east)"),
            ("field N, E, D = 20, 0, 40 uT seen in body axes", ", ".join(f"{v:+.2f}" for v in field_body)),
            ("compass heading atan2(-m_y, m_x)", f"{float(heading_deg(field_body[0], field_body[1])):.1f} deg"),
            ("paper E's yaw (rad, counter-clockwise, ENU)", f"{e_yaw:+.4f} rad"),
            ("paper E: body y (forward) in ENU", ", ".join(f"{v:+.3f}" for v in e_forward) + "  (points east)")]
    return pd.DataFrame(rows, columns=["quantity", "value"]).set_index("quantity")
