"""Physical models built from named effects: fit them to measurements, look at the residuals, add an effect.

Two systems, each with a catalogue of effects (:data:`CATALOGUES`):

``compass`` (papers A and B) — measurement: the compass heading; residual = measured - model heading,
wrapped to (-180, 180] deg.  The model is the *exact* planar heading model of :mod:`navlib.compass`
(heading computed through the distorted field), not a truncated harmonic series; Smith's A..E series
(:mod:`navlib.smith`) is its first-order harmonic approximation and is offered separately.

``drift`` (paper C) — measurement: the axial gyro drift (deg/h) of a single-axis rotation INS, with the
12 h latitude error as the physical observable.  The model is linear in its parameters:

    drift = g * dL12 / K  +  b  +  c_T (T - mean T)  +  c_dT (dT - mean dT)

with ``K = (cos L / W)(1 - cos 12 h W)`` the Table 1 gain (:func:`navlib.ins.latitude_error_per_drift`).
``earth_rate`` adds only ``g`` (no constant: that is ``bias``); the temperature terms are centred, so they
add no constant either.  Effects in one model are identifiable together.

Usage::

    fit = fit_model("compass", frame, ["misalignment", "hard_iron"])
    fit.rms, fit.residuals                 # how well the model explains the data
    fit2 = fit.add("soft_iron")            # adding an effect is one call
    compare(fit, fit2)                     # before/after table (RMS, range, held-out RMS)
    diagnose(fit)                          # which effect is missing (see navlib.diagnose)
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import pandas as pd

from .compass import PLANAR_EFFECTS, PlanarModel, fit_planar_model, wrap_deg
from .errors import InputError


@dataclass(frozen=True)
class Effect:
    """One physical effect: its name, the parameters it adds (with units), what causes it and how it shows
    in the residuals, and the data columns it needs besides the system's own."""

    name: str
    params: tuple[str, ...]
    units: tuple[str, ...]
    meaning: str
    columns: tuple[str, ...] = ()


COMPASS_EFFECTS = {
    "misalignment": Effect(
        "misalignment", PLANAR_EFFECTS["misalignment"], ("deg",),
        "The sensor's axes are turned about the vertical relative to the carrier's datum (mounting yaw). "
        "Every heading reads too high or too low by the same amount: a constant residual."),
    "hard_iron": Effect(
        "hard_iron", PLANAR_EFFECTS["hard_iron"], ("H", "H"),
        "Permanent magnetisation of the carrier (steel, magnets, DC currents) adds a field fixed to the "
        "carrier. It shows as a one-cycle residual (one maximum and one minimum per revolution)."),
    "soft_iron": Effect(
        "soft_iron", PLANAR_EFFECTS["soft_iron"], ("-", "-"),
        "Soft steel near the sensor is magnetised by the Earth field itself and distorts it symmetrically "
        "(with per-axis scale mismatch). It shows as a two-cycle residual (two maxima per revolution)."),
    "temperature": Effect(
        "temperature", PLANAR_EFFECTS["temperature"], ("H/degC", "H/degC"),
        "The hard-iron field (magnet and sensor offsets) drifts as the carrier warms. The one-cycle residual "
        "changes with temperature: repeated sweeps at different temperatures disagree.",
        ("temperature_c",)),
}

DRIFT_EFFECTS = {
    "earth_rate": Effect(
        "earth_rate", ("earth_rate_gain",), ("-",),
        "An axial gyro drift tilts the azimuth reference; through the Earth rate it builds a latitude error "
        "that after 12 h is 2 cos L / w_ie times the drift (paper C, Table 1). Gain 1 is the textbook "
        "formula. Missing, the residual follows the 12 h latitude error."),
    "bias": Effect(
        "bias", ("bias_deg_h",), ("deg/h",),
        "A constant part of the drift not seen in the latitude error (e.g. a calibration offset of the "
        "identification procedure). Missing, the residuals have a non-zero mean."),
    "temperature": Effect(
        "temperature", ("temperature_coef_deg_h_per_c",), ("deg/h/degC",),
        "The gyro's drift depends on its temperature (thermal gradients in the laser block, bias "
        "temperature coefficient). Missing, the residual trends with the mean temperature of the test.",
        ("temperature_c",)),
    "temperature_change": Effect(
        "temperature_change", ("temperature_change_coef_deg_h_per_c",), ("deg/h/degC",),
        "A cold start: while the system warms during alignment, transient thermal gradients shift the drift "
        "that the 12 h identification sees. Missing, the residual trends with the temperature change.",
        ("temperature_change_c",)),
}

CATALOGUES = {"compass": COMPASS_EFFECTS, "drift": DRIFT_EFFECTS}
UNITS = {"compass": "deg", "drift": "deg/h"}


def catalogue_table(system: str) -> pd.DataFrame:
    """The catalogue of a system as a table: effect, parameters (units), needed columns, meaning."""
    cat = _catalogue(system)
    return pd.DataFrame([{"effect": e.name,
                          "parameters": ", ".join(f"{p} [{u}]" for p, u in zip(e.params, e.units)),
                          "needs columns": ", ".join(e.columns) or "-",
                          "meaning": e.meaning} for e in cat.values()]).set_index("effect")


def _catalogue(system: str) -> dict:
    if system not in CATALOGUES:
        raise InputError(f"unknown system {system!r}; known: {', '.join(CATALOGUES)}")
    return CATALOGUES[system]


def check_effects(system: str, effects, data: pd.DataFrame | None = None) -> tuple[str, ...]:
    """Validate a list of effect names (unknown names, repeats, missing or constant columns)."""
    cat = _catalogue(system)
    effects = tuple(e.strip() for e in effects if e and e.strip())
    for e in effects:
        if e not in cat:
            raise InputError(f"unknown {system} effect '{e}'; known: {', '.join(cat)}")
    if len(set(effects)) != len(effects):
        raise InputError(f"effect listed twice in the model: {', '.join(effects)}")
    if data is not None:
        for e in effects:
            for col in cat[e].columns:
                if col not in data:
                    raise InputError(f"effect '{e}' needs the column '{col}', which the data do not have")
                if np.ptp(data[col].to_numpy(float)) == 0:
                    raise InputError(f"effect '{e}' needs '{col}' to vary, but it is constant in the data")
    return tuple(e for e in cat if e in effects)   # catalogue order


def testable(system: str, data: pd.DataFrame) -> tuple[dict, dict]:
    """Split the catalogue into effects the data can test and those it cannot (with the reason)."""
    ok, why = {}, {}
    for name, e in _catalogue(system).items():
        missing = [c for c in e.columns if c not in data]
        if missing:
            why[name] = f"no column '{missing[0]}'"
        elif any(np.ptp(data[c].to_numpy(float)) == 0 for c in e.columns):
            why[name] = f"'{e.columns[0]}' is constant"
        else:
            ok[name] = e
    return ok, why


# ------------------------------------------------------------------------------------------------ fits
@dataclass
class Fit:
    """A model (a set of named effects) fitted to measurements.

    ``residuals`` = measured - model (wrapped for the compass), in the system's unit; ``loo_residuals`` the
    leave-one-out prediction errors (exact for the linear drift model; the leverage approximation
    ``e_i / (1 - h_ii)`` from the fit's Jacobian for the compass)."""

    system: str
    effects: tuple[str, ...]
    params: dict
    data: pd.DataFrame
    residuals: np.ndarray
    jacobian: np.ndarray
    predict: Callable[[pd.DataFrame], np.ndarray] = field(repr=False)
    model: object = field(default=None, repr=False)

    @property
    def unit(self) -> str:
        return UNITS[self.system]

    @property
    def n(self) -> int:
        return len(self.residuals)

    @property
    def n_params(self) -> int:
        return int(self.jacobian.shape[1])

    @property
    def rss(self) -> float:
        return float(np.sum(self.residuals ** 2))

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.residuals ** 2)))

    @property
    def loo_residuals(self) -> np.ndarray:
        J = self.jacobian
        if J.shape[1] == 0:
            return self.residuals.copy()
        q, _ = np.linalg.qr(J)
        h = np.clip(np.sum(q ** 2, axis=1), 0.0, 1.0 - 1e-9)
        return self.residuals / (1.0 - h)

    @property
    def loo_rms(self) -> float:
        return float(np.sqrt(np.mean(self.loo_residuals ** 2)))

    def add(self, effect: str) -> "Fit":
        """The same data fitted with one more effect (one call)."""
        if effect in self.effects:
            raise InputError(f"effect '{effect}' is already in the model")
        return fit_model(self.system, self.data, self.effects + (effect,), start=self.params)

    def remove(self, effect: str) -> "Fit":
        if effect not in self.effects:
            raise InputError(f"effect '{effect}' is not in the model")
        return fit_model(self.system, self.data, tuple(e for e in self.effects if e != effect))

    def summary(self) -> dict:
        return {"model": " + ".join(self.effects) or "(none)", "parameters": self.n_params,
                f"rms ({self.unit})": self.rms, f"min ({self.unit})": float(self.residuals.min()),
                f"max ({self.unit})": float(self.residuals.max()), f"held-out rms ({self.unit})": self.loo_rms}


def observed(system: str, data: pd.DataFrame) -> np.ndarray:
    col = "measured_heading_deg" if system == "compass" else "drift_deg_h"
    return data[col].to_numpy(float)


def fit_model(system: str, data: pd.DataFrame, effects, start: dict | None = None) -> Fit:
    """Fit the named effects of ``system`` to ``data`` (a validated frame, see :func:`load`)."""
    effects = check_effects(system, effects, data)
    if system == "compass":
        return _fit_compass(data, effects, start)
    return _fit_drift(data, effects)


def _fit_compass(data, effects, start):
    true = data["true_heading_deg"].to_numpy(float)
    meas = data["measured_heading_deg"].to_numpy(float)
    temp = data["temperature_c"].to_numpy(float) if "temperature_c" in data else None
    initial = {k: v for k, v in (start or {}).items()} or None
    model, sol = fit_planar_model(true, meas, effects, initial=initial, temperature_c=temp, full_output=True)
    # residual = measured - model, in degrees
    resid = wrap_deg(meas - model.predict_measured(true, temp))
    jac = -np.asarray(sol.jac) if sol is not None else np.zeros((len(true), 0))

    def predict(frame):
        t = frame["temperature_c"].to_numpy(float) if "temperature_c" in frame else None
        return model.predict_measured(frame["true_heading_deg"].to_numpy(float), t)

    return Fit("compass", effects, dict(model.params), data, resid, jac, predict, model)


def drift_design(data: pd.DataFrame, effects, centres: dict | None = None) -> tuple[np.ndarray, dict]:
    """Design matrix of the linear drift model; ``centres`` holds the means the temperature terms are
    centred on (taken from ``data`` when not given)."""
    from .ins import latitude_error_per_drift

    k = latitude_error_per_drift(12.0)
    centres = dict(centres or {})
    cols = []
    for e in effects:
        if e == "earth_rate":
            cols.append(data["latitude_error_deg"].to_numpy(float) / k)
        elif e == "bias":
            cols.append(np.ones(len(data)))
        else:
            c = DRIFT_EFFECTS[e].columns[0]
            centres.setdefault(c, float(data[c].mean()))
            cols.append(data[c].to_numpy(float) - centres[c])
    return (np.column_stack(cols) if cols else np.zeros((len(data), 0))), centres


def _fit_drift(data, effects):
    y = data["drift_deg_h"].to_numpy(float)
    X, centres = drift_design(data, effects)
    if X.shape[1] >= len(y):
        raise InputError(f"{len(y)} rows cannot determine {X.shape[1]} parameters of the model "
                         f"{' + '.join(effects)}; at least {X.shape[1] + 1} rows are needed")
    beta = np.linalg.lstsq(X, y, rcond=None)[0] if X.shape[1] else np.zeros(0)
    names = [DRIFT_EFFECTS[e].params[0] for e in effects]
    params = dict(zip(names, map(float, beta)))

    def predict(frame):
        Xf, _ = drift_design(frame, effects, centres)
        return Xf @ beta

    return Fit("drift", effects, params, data, y - X @ beta, X, predict, centres)


def compare(*fits: Fit) -> pd.DataFrame:
    """Before/after table: one row per fit with RMS, residual range and held-out RMS."""
    return pd.DataFrame([f.summary() for f in fits]).set_index("model")


# ------------------------------------------------------------------------------------------- loading
def load(system: str, path) -> pd.DataFrame:
    """Load and validate a measurement file for ``system`` (see the CLI help for the columns)."""
    from .tables import read_table

    _catalogue(system)
    if system == "compass":
        from .compass import load_sweeps
        return load_sweeps(path)
    from .gyro_data import USER_COLUMNS
    return read_table(path, USER_COLUMNS, min_rows=2, kind="drift table")


# ------------------------------------------------------------------------------------- simulated data
def simulate(system: str, params: dict, *, n: int | None = None, noise: float = 0.0, seed=0) -> pd.DataFrame:
    """Data from the catalogue model with the given parameters (effects absent = 0) plus white noise.

    compass: two sweeps of 121 readings (0..360 every 3 deg) while the carrier warms from 15 to 35 degC;
    ``noise`` is the heading noise in deg, added as field noise (so it is larger where the distorted
    horizontal field is weaker, as on a real compass).  drift: ``n`` tests (default 16) with covariates
    spread like paper C's tables (12 h latitude error within +-0.05 deg, mean temperature 10..65 degC,
    temperature change 0..30 degC); ``noise`` in deg/h."""
    rng = np.random.default_rng(seed)
    if system == "compass":
        true = np.tile(np.arange(0.0, 361.0, 3.0), 2)
        temp = np.linspace(15.0, 35.0, len(true))
        model = PlanarModel(tuple(COMPASS_EFFECTS), dict(params), float(np.mean(temp)))
        m = model._field(true, temp)
        m = m + np.radians(noise) * rng.standard_normal(m.shape)
        meas = np.mod(np.degrees(np.arctan2(-m[1], m[0])), 360.0)
        return pd.DataFrame({"true_heading_deg": true, "measured_heading_deg": meas, "temperature_c": temp,
                             "sweep": np.repeat([1, 2], 121)})
    _catalogue(system)
    n = 16 if n is None else n
    frame = pd.DataFrame({"latitude_error_deg": rng.uniform(-0.05, 0.05, n),
                          "temperature_c": rng.uniform(10.0, 65.0, n),
                          "temperature_change_c": rng.uniform(0.0, 30.0, n)})
    X, _ = drift_design(frame, tuple(DRIFT_EFFECTS))
    beta = np.array([params.get(DRIFT_EFFECTS[e].params[0], 0.0) for e in DRIFT_EFFECTS])
    frame["drift_deg_h"] = X @ beta + noise * rng.standard_normal(n)
    return frame


def effect_rms(system: str, data: pd.DataFrame, params: dict, effect: str) -> float:
    """RMS (in the system's unit) of what ``effect`` contributes to the noiseless model on ``data``."""
    cat = _catalogue(system)
    without = {k: v for k, v in params.items() if k not in cat[effect].params}
    if system == "compass":
        temp = data["temperature_c"].to_numpy(float)
        true = data["true_heading_deg"].to_numpy(float)
        ref = float(np.mean(temp))
        a = PlanarModel(tuple(cat), dict(params), ref).predict_measured(true, temp)
        b = PlanarModel(tuple(cat), without, ref).predict_measured(true, temp)
        return float(np.sqrt(np.mean(wrap_deg(a - b) ** 2)))
    X, _ = drift_design(data, (effect,))
    return float(np.sqrt(np.mean((X[:, 0] * params.get(cat[effect].params[0], 0.0)) ** 2)))
