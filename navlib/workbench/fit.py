"""A model of named effects fitted to measurements: residuals, held-out error, adding an effect in one call;
loading a system's measurement file, and simulated data from the catalogue model.

See :mod:`navlib.workbench.effects` for the catalogues and the model equations.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import pandas as pd

from ..angles import heading_deg, wrap_deg
from ..data.compass_sweeps import load_sweeps
from ..data.gyro_tables import USER_COLUMNS
from ..data.tables import read_table
from ..errors import InputError
from ..sensors.ins import latitude_error_per_drift
from ..sensors.planar import PlanarModel, fit_planar_model
from .effects import COMPASS_EFFECTS, DRIFT_EFFECTS, UNITS, _catalogue, check_effects

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
    _catalogue(system)
    if system == "compass":
        return load_sweeps(path)
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
        meas = heading_deg(m[0], m[1])
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
