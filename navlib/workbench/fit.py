"""A model of named effects fitted to measurements: residuals, held-out error, adding an effect in one call;
the compass and drift systems (loading, fitting, structure tests, simulated data).

See :mod:`navlib.workbench.effects` for the Effect/System types and the model equations.  Every refit starts
from several points and keeps the best: the previous model's parameters (new ones at zero) and the
system's *linearised* solution (for the compass the first-order harmonic model, in which hard iron is a
one-cycle and soft iron a two-cycle error; for a linear model the exact solution), so a refit never ends
worse than the linearised model that motivated it.  The exception is a refit of the same model on other
rows of the same data, or with more effects, from a fit's optimum (the outlier screen's rounds and its
richest model, :func:`refit_rows`): a system with a ``refit`` hook (the reference-free magnetometer)
continues from that optimum alone, which the several starts would also find (tested), at a fraction of
the cost.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from ..angles import heading_deg, wrap_deg
from ..data.compass_sweeps import SWEEP_COLUMNS, load_sweeps
from ..data.gyro_tables import USER_COLUMNS
from ..data.tables import read_table, require_variation
from ..errors import InputError
from ..sensors.ins import latitude_error_per_drift
from ..sensors.planar import PLANAR_EFFECTS, PlanarModel
from .effects import (
    COMPASS_EFFECTS,
    DRIFT_EFFECTS,
    Effect,
    System,
    call_contribution,
    get_system,
    register_system,
    resolve,
)
from .linalg import orth_basis
from .serial import ar1_noise
from ..threads import one_blas_thread

RAD = 180.0 / np.pi

#: Each system's measured columns, in the order of the residual's axes (``residual[i * k + j]`` is row i,
#: column j), and whether the measurement is an angle whose residual is wrapped to (-180, 180] deg.  The
#: outlier screen names a column from here; a system module adds its own entry when it registers.
MEASURED: dict[str, tuple[tuple[str, ...], bool]] = {
    "compass": (("measured_heading_deg",), True),
    "drift": (("drift_deg_h",), False),
}


def measured_columns(system: str, axes: int) -> tuple[str, ...]:
    """The names of a system's measured columns (:data:`MEASURED`; ``"axis j"`` for a system without an
    entry)."""
    cols = MEASURED.get(system, ((), False))[0]
    # a system whose residual has fewer axes on some data (magnetometer_free without an accelerometer)
    # names its first ones
    return cols[:axes] if len(cols) >= axes else tuple(f"axis {j}" for j in range(axes))


def columns_of(frame: pd.DataFrame, cols) -> np.ndarray:
    """``frame[list(cols)].to_numpy(float)``, column by column (the same numbers; pandas' multi-column take
    costs forty times more, and the fits read these columns often).  Each column's values are read
    straight from the frame's block where pandas offers it (``DataFrame._get_column_array``, a tenth of a
    ``frame[c]``); else, and for repeated column names, through ``frame[c]``."""
    get = getattr(frame, "_get_column_array", None)
    if get is not None and frame.columns.is_unique:
        loc = frame.columns.get_loc  # a hash per name (KeyError for a missing one, as frame[c])
        return np.column_stack([np.asarray(get(loc(c)), float) for c in cols])
    return np.column_stack([frame[c].to_numpy(float) for c in cols])


def residuals_on(fit: "Fit", frame: pd.DataFrame) -> np.ndarray:
    """Residuals (measured - model, in the system's unit; wrapped for an angle) of ``fit`` on the rows of
    ``frame``, shape (rows, axes): also on rows the fit did not use."""
    cols, wrapped = MEASURED[fit.system]
    model = np.asarray(fit.predict(frame), float).reshape(len(frame), -1)
    r = columns_of(frame, cols[: model.shape[1]]) - model
    return wrap_deg(r) if wrapped else r


@dataclass
class Fit:
    """A model (a set of named effects) fitted to measurements.

    ``residuals`` = measured - model (wrapped for the compass), one value per scalar observation (3 per row
    for a 3-D field), in the system's unit; ``jacobian`` d(model)/d(parameters) at the solution;
    ``loo_residuals`` the leave-one-out prediction errors (exact for a linear model, the leverage
    approximation ``e_i / (1 - h_ii)`` otherwise).  ``available`` holds every effect that may be added
    (catalogue and user effects)."""

    spec: System
    effects: tuple[str, ...]
    params: dict
    data: pd.DataFrame
    residuals: np.ndarray
    jacobian: np.ndarray
    predict: Callable[[pd.DataFrame], np.ndarray] = field(repr=False)
    model: object = field(default=None, repr=False)
    available: Mapping[str, Effect] = field(default_factory=dict, repr=False)

    @property
    def system(self) -> str:
        return self.spec.name

    @property
    def unit(self) -> str:
        return self.spec.unit

    @property
    def n(self) -> int:
        return len(self.residuals)

    @property
    def n_params(self) -> int:
        return int(self.jacobian.shape[1])

    @property
    def rss(self) -> float:
        return float(np.sum(self.residuals**2))

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.residuals**2)))

    @property
    def loo_residuals(self) -> np.ndarray:
        J = self.jacobian
        if J.shape[1] == 0:
            return self.residuals.copy()
        q = orth_basis(J)
        h = np.clip(np.sum(q**2, axis=1), 0.0, 1.0 - 1e-9)
        return self.residuals / (1.0 - h)

    @property
    def loo_rms(self) -> float:
        return float(np.sqrt(np.mean(self.loo_residuals**2)))

    @property
    def user_effects(self) -> tuple[Effect, ...]:
        return tuple(e for k, e in self.available.items() if k not in self.spec.catalogue)

    def add(self, effect: str) -> "Fit":
        """The same data fitted with one more effect (one call), starting from this fit's parameters."""
        if effect in self.effects:
            raise InputError(f"effect '{effect}' is already in the model")
        return fit_model(
            self.spec,
            self.data,
            self.effects + (effect,),
            start=self.params,
            user_effects=self.user_effects,
        )

    def remove(self, effect: str) -> "Fit":
        if effect not in self.effects:
            raise InputError(f"effect '{effect}' is not in the model")
        return fit_model(
            self.spec,
            self.data,
            tuple(e for e in self.effects if e != effect),
            user_effects=self.user_effects,
        )

    def summary(self) -> dict:
        return {
            "model": " + ".join(self.effects) or "(none)",
            "parameters": self.n_params,
            f"rms ({self.unit})": self.rms,
            f"min ({self.unit})": float(self.residuals.min()),
            f"max ({self.unit})": float(self.residuals.max()),
            f"held-out rms ({self.unit})": self.loo_rms,
        }


@one_blas_thread
def fit_model(
    system,
    data: pd.DataFrame,
    effects,
    start: dict | None = None,
    user_effects: tuple[Effect, ...] = (),
) -> Fit:
    """Fit the named effects of ``system`` (a name or a :class:`.System`) to ``data`` (a validated frame,
    see :func:`load`); ``user_effects`` are extra effects (with a contribution) the names may refer to."""
    spec = get_system(system) if isinstance(system, str) else system
    user_effects = tuple(user_effects)
    taken = {q: f"effect '{e.name}'" for e in spec.catalogue.values() for q in e.params}
    for i, e in enumerate(user_effects):
        if e.name in spec.catalogue or any(u.name == e.name for u in user_effects[:i]):
            raise InputError(
                f"{e.source or 'user effects'}: effect '{e.name}' is given twice (or is in the "
                f"{spec.name} catalogue); give each effect its own name"
            )
        if e.contribution is None:
            raise InputError(
                f"{e.source or 'user effects'}: effect '{e.name}' has no contribution(params, data)"
            )
        for q in e.params:
            if q in taken:
                raise InputError(
                    f"{e.source or 'user effects'}: effect '{e.name}': parameter '{q}' is already a "
                    f"parameter of {taken[q]}"
                )
            taken[q] = f"effect '{e.name}'"
    available = {**spec.catalogue, **{e.name: e for e in user_effects}}
    chosen = resolve(available, effects, data, spec.name)
    fit = spec.fit(data, chosen, start)
    fit.available = available
    return fit


@one_blas_thread
def refit_rows(fit: Fit, data: pd.DataFrame, effects=None) -> Fit:
    """``fit``'s model (or the model ``effects``) on ``data`` (rows of the same measurements, e.g. without
    outliers), started from ``fit``'s parameters: by the system's ``refit`` hook where it has one and it
    converges (the same minimum to the optimiser's tolerance, without the several starts of a full fit),
    else :func:`fit_model` from ``fit``'s parameters and the linearised start."""
    effects = tuple(fit.effects if effects is None else effects)
    if fit.spec.refit is not None:
        out = fit.spec.refit(fit, data, effects)
        if out is not None:
            out.available = fit.available
            return out
    return fit_model(fit.spec, data, effects, start=fit.params, user_effects=fit.user_effects)


def compare(*fits: Fit) -> pd.DataFrame:
    """Before/after table: one row per fit with RMS, residual range and held-out RMS."""
    return pd.DataFrame([f.summary() for f in fits]).set_index("model")


# ------------------------------------------------------------------------------ shared fitting helpers
# Tall matrices (thousands of rows, tens of columns) are orthonormalised by classical Gram-Schmidt applied
# twice (as accurate as Householder QR for our purposes) with matrix-vector products only: on a shared
# machine a threaded LAPACK factorisation of even a 40 x 40 matrix can take a hundred times longer.
def lstsq(X: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Minimum-norm least-squares solution of ``X b = y`` via the (column-scaled) normal equations."""
    if X.shape[1] == 0:
        return np.zeros(0)
    norms = np.linalg.norm(X, axis=0)
    norms[norms == 0] = 1.0
    Xs = X / norms
    return (np.linalg.pinv(Xs.T @ Xs, rcond=1e-12, hermitian=True) @ (Xs.T @ y)) / norms


def user_columns(effects, params: dict, data: pd.DataFrame, shape) -> np.ndarray:
    """Sum of the user effects' contributions, flattened to the residual vector.  Each is called through
    :func:`navlib.workbench.effects.call_contribution` (a read-only copy of the data; an exception, text,
    NaN, infinity or a wrong shape stops the run with one line naming the effect's file and the effect)."""
    total = np.zeros(int(np.prod(shape)))
    for e in effects:
        total += call_contribution(e, {k: params[k] for k in e.params}, data, shape).ravel()
    return total


def user_design(effects, data: pd.DataFrame, shape) -> np.ndarray:
    """Columns d(contribution)/d(parameter) of the user effects at zero (central differences, step 1 in
    the parameter's unit: exact for an effect linear in its parameters)."""
    cols = []
    for e in effects:
        for name in e.params:
            up = user_columns([e], {k: (1.0 if k == name else 0.0) for k in e.params}, data, shape)
            dn = user_columns([e], {k: (-1.0 if k == name else 0.0) for k in e.params}, data, shape)
            cols.append((up - dn) / 2.0)
    return np.column_stack(cols) if cols else np.zeros((int(np.prod(shape)), 0))


def best_least_squares(model_minus_obs, starts, lo, hi, jac="2-point", tr_solver=None):
    """``scipy.optimize.least_squares`` (trust-region reflective) from each distinct start; the lowest cost
    wins (a start equal to an earlier one is not solved again: scipy's solver is deterministic).
    ``jac``: a function returning d(model)/d(x), or scipy's finite differences; ``tr_solver``: scipy's
    (default: ``"exact"`` up to 6 parameters, ``"lsmr"`` above)."""
    best = None
    finite = np.isfinite(lo) & np.isfinite(hi)
    margin = np.where(finite, 1e-9 * (np.abs(np.where(finite, hi - lo, 0.0)) + 1), 0.0)
    done: list[np.ndarray] = []
    for x0 in starts:
        x0 = np.clip(np.asarray(x0, float), lo + margin, hi - margin)
        if any(np.array_equal(x0, d) for d in done):  # the same start gives the same solution
            continue
        done.append(x0)
        sol = least_squares(
            model_minus_obs,
            x0,
            jac=jac,
            bounds=(lo, hi),
            x_scale="jac",
            method="trf",
            tr_solver=tr_solver or ("lsmr" if len(x0) > 6 else "exact"),
        )
        if best is None or sol.cost < best.cost:
            best = sol
    return best


# --------------------------------------------------------------------------------------------- compass
def compass_linear_design(data: pd.DataFrame, names, t_ref: float) -> np.ndarray:
    """First-order (harmonic) model of the planar parameters, deg per unit parameter, about zero:
    ``err = yaw - (h_x + k_x dT) sin psi - (h_y + k_y dT) cos psi - e sin 2 psi - f cos 2 psi`` (rad)."""
    psi = np.radians(data["true_heading_deg"].to_numpy(float))
    dt = (
        (data["temperature_c"].to_numpy(float) - t_ref)
        if "temperature_c" in data
        else np.zeros(len(psi))
    )
    col = {
        "yaw_deg": np.ones_like(psi),
        "hard_x": -RAD * np.sin(psi),
        "hard_y": -RAD * np.cos(psi),
        "soft_e": -RAD * np.sin(2 * psi),
        "soft_f": -RAD * np.cos(2 * psi),
        "temp_x_per_c": -RAD * dt * np.sin(psi),
        "temp_y_per_c": -RAD * dt * np.cos(psi),
    }
    return np.column_stack([col[n] for n in names]) if names else np.zeros((len(psi), 0))


def _fit_compass(data: pd.DataFrame, effects: tuple[Effect, ...], start) -> Fit:
    true = data["true_heading_deg"].to_numpy(float)
    meas = data["measured_heading_deg"].to_numpy(float)
    temp = data["temperature_c"].to_numpy(float) if "temperature_c" in data else None
    planar = tuple(e.name for e in effects if e.contribution is None)
    users = tuple(e for e in effects if e.contribution is not None)
    pnames = [p for e in planar for p in PLANAR_EFFECTS[e]]
    unames = [p for e in users for p in e.params]
    names = pnames + unames
    if len(true) < len(names) + 1:
        raise InputError(f"{len(true)} readings cannot determine {len(names)} model parameters")
    t_ref = float(np.mean(temp)) if "temperature" in planar else 20.0
    shape = (len(true),)

    def model(x):
        p = dict(zip(names, x))
        pm = PlanarModel(planar, {k: p[k] for k in pnames}, t_ref)
        return pm.predict_measured(true, temp) + user_columns(users, p, data, shape)

    def resid(x):  # model - measured, wrapped
        return wrap_deg(model(x) - meas)

    if not names:
        r = wrap_deg(meas - model(np.zeros(0)))
        pm = PlanarModel(planar, {}, t_ref)
        return Fit(
            SYSTEMS_BASE["compass"],
            planar,
            {},
            data,
            r,
            np.zeros((len(r), 0)),
            lambda f: PlanarModel(planar, {}, t_ref).predict_measured(
                f["true_heading_deg"].to_numpy(float)
            ),
            pm,
        )
    lo = np.array([-180.0 if n == "yaw_deg" else -0.95 for n in pnames] + [-np.inf] * len(unames))
    hi = np.array([180.0 if n == "yaw_deg" else 0.95 for n in pnames] + [np.inf] * len(unames))
    # start 1: the previous model's parameters, new ones at zero (yaw from the mean error if new)
    x1 = np.array([(start or {}).get(n, 0.0) for n in names])
    if "yaw_deg" in pnames and "yaw_deg" not in (start or {}):
        x1[pnames.index("yaw_deg")] = float(
            np.degrees(np.angle(np.mean(np.exp(1j * np.radians(meas - true)))))
        )
    # start 2: the linearised (harmonic) model fitted by linear least squares
    X = np.column_stack(
        [compass_linear_design(data, pnames, t_ref), user_design(users, data, shape)]
    )
    x2 = lstsq(X, wrap_deg(meas - true))
    jac = "2-point"
    if not users:  # the planar model's exact derivatives

        def jac(x):
            return PlanarModel(planar, dict(zip(names, x)), t_ref).jacobian(true, names, temp)

    sol = best_least_squares(resid, [x1, x2], lo, hi, jac=jac)
    params = dict(zip(names, map(float, sol.x)))
    pm = PlanarModel(planar, {k: params[k] for k in pnames}, t_ref)
    r = wrap_deg(meas - model(sol.x))

    def predict(frame):
        t = frame["temperature_c"].to_numpy(float) if "temperature_c" in frame else None
        return pm.predict_measured(frame["true_heading_deg"].to_numpy(float), t) + user_columns(
            users, params, frame, (len(frame),)
        )

    return Fit(
        SYSTEMS_BASE["compass"],
        tuple(e.name for e in effects),
        params,
        data,
        r,
        np.asarray(sol.jac),
        predict,
        pm,
    )


def harmonic_columns(data: pd.DataFrame, k: int) -> np.ndarray:
    h = np.radians(data["true_heading_deg"].to_numpy(float))
    return np.column_stack([np.sin(k * h), np.cos(k * h)]) if k else np.ones((len(h), 1))


def compass_structure(fit: Fit) -> list[tuple[str, np.ndarray, float]]:
    """Shapes no catalogued compass effect produces on its own: a constant offset, heading harmonics 1..6,
    an offset and a one-cycle error that differ between sweeps, and a trend in time."""
    data = fit.data
    out = [("constant offset", harmonic_columns(data, 0), 1.0)]
    out += [
        (f"heading harmonic {k} (period {360 // k} deg)", harmonic_columns(data, k), np.sqrt(2.0))
        for k in range(1, 7)
    ]
    if "sweep" in data and data["sweep"].nunique() > 1:
        ids = sorted(data["sweep"].unique())
        d = np.column_stack([(data["sweep"] == i).to_numpy(float) for i in ids[1:]])
        d = d - d.mean(axis=0)
        out.append(("offset differing between sweeps", d, 2.0))
        h1 = harmonic_columns(data, 1)
        out.append(
            (
                "one-cycle error differing between sweeps",
                np.column_stack([d * h1[:, [0]], d * h1[:, [1]]]),
                2.0,
            )
        )
    if "time_s" in data and np.ptp(data["time_s"].to_numpy(float)) > 0:
        t = data["time_s"].to_numpy(float)
        out.append(("trend in time", (t - t.mean())[:, None], np.sqrt(3.0)))
    return out


def load_compass(path) -> pd.DataFrame:
    return load_sweeps(path)


# ----------------------------------------------------------------------------------------------- drift
def drift_design(
    data: pd.DataFrame, effects, centres: dict | None = None
) -> tuple[np.ndarray, dict]:
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


def fit_linear(
    y: np.ndarray,
    X: np.ndarray,
    cat_names,
    users,
    data: pd.DataFrame,
    start,
    *,
    what: str = "rows",
    model: str = "",
) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Least squares for a model linear in its catalogued parameters, ``y ~ X beta_cat + sum of user
    effects``.  The linear problem (user effects linearised by :func:`user_design`) is solved first; with
    user effects, which may be nonlinear, the solution is refined by nonlinear least squares from it and
    from ``start`` (:func:`best_least_squares`).

    Parameters
    ----------
    y : ndarray
        The measurements (n,).
    X : ndarray
        Design matrix of the catalogued effects (n, p).
    cat_names : sequence of str
        The catalogued parameters, one per column of ``X``.
    users : sequence of Effect
        User effects (with a ``contribution``).
    data : DataFrame
        The measurements' table (the user effects read their columns from it).
    start : dict or None
        Starting values by parameter name.
    what, model : str
        Words for the error message when there are too few measurements.

    Returns
    -------
    beta : ndarray
        All parameters, catalogued first.
    jacobian : ndarray
        d(model)/d(beta) at the solution.
    names : list of str
        The parameter names, in the order of ``beta``.
    """
    names = list(cat_names) + [p for e in users for p in e.params]
    if len(names) >= len(y):
        raise InputError(
            f"{len(y)} {what} cannot determine {len(names)} parameters of the model {model}; "
            f"at least {len(names) + 1} {what} are needed"
        )
    shape = (len(y),)
    XU = np.column_stack([X, user_design(users, data, shape)])
    beta = lstsq(XU, y)
    jac = XU
    if users:  # a user effect may be nonlinear: refine
        nc = X.shape[1]

        def resid(x):
            return X @ x[:nc] + user_columns(users, dict(zip(names, x)), data, shape) - y

        inf = np.full(len(names), np.inf)
        sol = best_least_squares(
            resid, [beta, np.array([(start or {}).get(n, 0.0) for n in names])], -inf, inf
        )
        beta, jac = sol.x, np.asarray(sol.jac)
    return beta, jac, names


def _fit_drift(data: pd.DataFrame, effects: tuple[Effect, ...], start) -> Fit:
    y = data["drift_deg_h"].to_numpy(float)
    cat = tuple(e.name for e in effects if e.contribution is None)
    users = tuple(e for e in effects if e.contribution is not None)
    X, centres = drift_design(data, cat)
    beta, jac, names = fit_linear(
        y,
        X,
        [DRIFT_EFFECTS[e].params[0] for e in cat],
        users,
        data,
        start,
        model=" + ".join(e.name for e in effects),
    )
    params = dict(zip(names, map(float, beta)))
    nc = X.shape[1]

    def predict(frame):
        Xf, _ = drift_design(frame, cat, centres)
        return Xf @ beta[:nc] + user_columns(users, params, frame, (len(frame),))

    return Fit(
        SYSTEMS_BASE["drift"],
        tuple(e.name for e in effects),
        params,
        data,
        y - predict(data),
        jac,
        predict,
        centres,
    )


def drift_structure(fit: Fit) -> list[tuple[str, np.ndarray, float]]:
    """Curvature in each drift covariate (a quadratic term no catalogued effect has)."""
    out = []
    for col in ("latitude_error_deg", "temperature_c", "temperature_change_c"):
        if col in fit.data and np.ptp(fit.data[col].to_numpy(float)) > 0:
            x = fit.data[col].to_numpy(float)
            x = (x - x.mean()) / (np.std(x) or 1.0)
            out.append((f"curvature in {col}", (x**2 - np.mean(x**2))[:, None], 1.0))
    return out


#: The earth-rate gain a drift table may show before its units are questioned (the textbook gain is 1;
#: paper C's tests give 0.88), and the correlation above which the gain is measured well enough to judge.
GAIN_BAND = (0.2, 5.0)
GAIN_CORRELATION = 0.9
#: Unit mistakes and the factor they put on the earth-rate gain.
DRIFT_UNIT_MISTAKES = (
    ("drift_deg_h in deg/s (multiply by 3600)", 1 / 3600.0),
    ("drift_deg_h in rad/h (multiply by 57.3)", np.pi / 180.0),
    ("latitude_error_deg in radians (multiply by 57.3)", 180.0 / np.pi),
    ("latitude_error_deg in arcmin (divide by 60)", 1 / 60.0),
)


def load_drift(path) -> pd.DataFrame:
    """A drift table (:data:`navlib.data.gyro_tables.USER_COLUMNS`: ``latitude_error_deg`` within +-1 deg,
    ``drift_deg_h`` within +-1 deg/h, optional ``temperature_c`` -60..120 degC and ``temperature_change_c``
    -180..180 degC; at least 2 rows), with two plausibility checks: the latitude error and the drift must
    vary (a constant one is a stuck or missing measurement), and where the two are strongly related
    (correlation above 0.9) the earth-rate gain ``g`` of ``drift = g dL12 / K`` (least squares with a
    constant; 1 is the textbook relation of paper C's Table 1) must lie within 0.2..5: a gain of 1/3600,
    1/57.3, 57.3 or 1/60 names the unit mistake, a negative one the sign convention."""
    frame = read_table(path, USER_COLUMNS, min_rows=2, kind="drift table")
    name = Path(path).name
    require_variation(frame, ["latitude_error_deg", "drift_deg_h"], path, "the earth-rate model")
    x = frame["latitude_error_deg"].to_numpy(float) / latitude_error_per_drift(12.0)
    y = frame["drift_deg_h"].to_numpy(float)
    if len(y) >= 4 and abs(np.corrcoef(x, y)[0, 1]) > GAIN_CORRELATION:
        gain = float(np.polyfit(x, y, 1)[0])
        lo, hi = GAIN_BAND
        if gain < 0:
            raise InputError(
                f"{name}: columns 'latitude_error_deg', 'drift_deg_h': the drift falls as the 12 h "
                f"latitude error rises (earth-rate gain {gain:.3g}, textbook +1): the latitude error "
                f"must be indicated - true, and the drift of the same sign convention"
            )
        if not lo <= gain <= hi:
            near = [what for what, f in DRIFT_UNIT_MISTAKES if 0.5 <= gain / f <= 2.0]
            look = f"; {' or '.join(near)}?" if near else ""
            raise InputError(
                f"{name}: columns 'latitude_error_deg', 'drift_deg_h': the drift is {gain:.3g} times "
                f"what the 12 h latitude error implies (earth-rate gain; textbook 1, accepted "
                f"{lo:g}..{hi:g}){look}"
            )
    return frame


SYSTEMS_BASE = {
    "compass": System(
        "compass",
        "deg",
        COMPASS_EFFECTS,
        load_compass,
        _fit_compass,
        compass_structure,
        "level compass heading; residual = measured - model heading, wrapped, deg",
        columns=tuple(SWEEP_COLUMNS),
    ),
    "drift": System(
        "drift",
        "deg/h",
        DRIFT_EFFECTS,
        load_drift,
        _fit_drift,
        drift_structure,
        "axial gyro drift of a rotating INS; residual = measured - model drift, deg/h",
        columns=tuple(USER_COLUMNS),
    ),
}
for _s in SYSTEMS_BASE.values():
    register_system(_s)


# ------------------------------------------------------------------------------------- simulated data
def simulate(
    system: str,
    params: dict,
    *,
    n: int | None = None,
    noise: float = 0.0,
    seed=0,
    noise_correlation: float = 0.0,
) -> pd.DataFrame:
    """Data from the catalogue model with the given parameters (effects absent = 0) plus noise.

    compass: two sweeps of 121 readings (0..360 every 3 deg, one reading every 5 s) while the carrier warms
    from 15 to 35 degC; ``noise`` is the heading noise in deg, added as field noise (so it is larger where
    the distorted horizontal field is weaker, as on a real compass): white, or with ``noise_correlation``
    an AR(1) process along the readings with that lag-1 correlation
    (:func:`navlib.workbench.serial.ar1_noise`).  drift: ``n`` tests (default 16) with covariates spread like
    paper C's tables (12 h latitude error within +-0.05 deg, mean temperature 10..65 degC, temperature
    change 0..30 degC); ``noise`` in deg/h (no time series: ``noise_correlation`` must be 0)."""
    rng = np.random.default_rng(seed)
    if system == "compass":
        true = np.tile(np.arange(0.0, 361.0, 3.0), 2)
        temp = np.linspace(15.0, 35.0, len(true))
        model = PlanarModel(tuple(COMPASS_EFFECTS), dict(params), float(np.mean(temp)))
        m = model._field(true, temp)
        if noise_correlation:
            m = m + np.radians(noise) * ar1_noise(rng, m.shape[::-1], 1.0, noise_correlation).T
        else:
            m = m + np.radians(noise) * rng.standard_normal(m.shape)
        meas = heading_deg(m[0], m[1])
        return pd.DataFrame(
            {
                "true_heading_deg": true,
                "measured_heading_deg": meas,
                "temperature_c": temp,
                "sweep": np.repeat([1, 2], 121),
                "time_s": 5.0 * np.arange(len(true)),
            }
        )
    if system != "drift":
        raise InputError(f"simulate: unknown system {system!r}; known: compass, drift")
    if noise_correlation:
        raise InputError(
            "simulate: noise_correlation must be 0 for the drift tables (not a time series)"
        )
    n = 16 if n is None else n
    frame = pd.DataFrame(
        {
            "latitude_error_deg": rng.uniform(-0.05, 0.05, n),
            "temperature_c": rng.uniform(10.0, 65.0, n),
            "temperature_change_c": rng.uniform(0.0, 30.0, n),
        }
    )
    X, _ = drift_design(frame, tuple(DRIFT_EFFECTS))
    beta = np.array([params.get(DRIFT_EFFECTS[e].params[0], 0.0) for e in DRIFT_EFFECTS])
    frame["drift_deg_h"] = X @ beta + noise * rng.standard_normal(n)
    return frame


def effect_rms(system: str, data: pd.DataFrame, params: dict, effect: str) -> float:
    """RMS (in the system's unit) of what ``effect`` contributes to the noiseless model on ``data``."""
    cat = get_system(system).catalogue
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


def load(system: str, path) -> pd.DataFrame:
    """Load and validate a measurement file for ``system`` (its ``load``; see the CLI help for columns)."""
    return get_system(system).load(path)
