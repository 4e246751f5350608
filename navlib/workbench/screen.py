"""Before any test: set aside outlying rows, find the data's numerical floor, and model the noise's serial
correlation.  :func:`screen` does all three once per data set; :func:`navlib.workbench.diagnose.diagnose`
and :func:`navlib.workbench.loop.loop` test on what it leaves.

**Outliers.**  The F tests compare variances, so one wild sample inflates the noise estimate until nothing
is significant (a 300 uT spike among 0.4 uT residuals hides every effect).  The screen fits the *richest*
model the data can test (every testable effect, catalogued and the user's: so no missing effect, e.g. a
time lag on the fast turns, is mistaken for outliers), takes the system's structure shapes out of its
residuals too (fitted to the residual clipped at :data:`Z_NOISE` robust standard deviations, one Huber
step, so that a spike is not smeared over its time cell; not on short tables, where they would absorb an
outlier), and studentises what is left with a robust scale, per measured column::

    z_ij = (u_ij - med_j) / s_j,   u_ij = r_ij / sqrt(1 - h_ij),   s_j = 1.4826 MAD_j(u)

(``h`` the leverage of the observation; median and MAD over the rows kept; 1.4826 makes the MAD a
consistent estimate of a normal standard deviation: Hampel 1974, JASA 69:383; Rousseeuw and Croux 1993,
JASA 88:1273).  An observation is an outlier when ``|z| > c`` with the Bonferroni cutoff
``c = max(Z_MIN, t_nu^-1(1 - OUTLIER_ALPHA / (2 N)))`` over the N observations, so a file of clean Gaussian
noise has at most about an ``OUTLIER_ALPHA`` chance of losing any row (``Z_MIN`` = 6 keeps real sensors'
heavier tails in).  Student's t with ``nu = 0.367 (N - p)`` degrees of freedom rather than the normal
quantile allows for the MAD's own scatter on short tables: the MAD has 36.7 % efficiency at the normal
(Rousseeuw and Croux 1993), so it is about as precise as a variance from ``0.367 (N - p)`` squares (a
Satterthwaite-style approximation; on a 19-row table the cutoff is about 7.7, on hundreds of rows it is
``Z_MIN``).  On a table of at most :data:`SMALL_TABLE` rows each row is also judged by its deletion
residual (the fit without it: one outlier at a high-leverage point otherwise pulls the fit to itself and
inflates everyone's residuals).  In a time series (``time_s``, or a magnetometer's file order) an outlier
must also stand out from its neighbours in time -- the robust z of ``u_t`` minus the median of the samples
within :data:`ISOLATION` of it must exceed ``c`` too (a Hampel filter, Pearson 2002, IEEE Trans. Control
Syst. Technol. 10:55) -- and be isolated: no other sample within :data:`ISOLATION` samples has a robust
``|z|`` above ``c`` (nor above a tenth of its own).  A spike is; a physical disturbance that lasts two samples
or more (a magnet passed at close range) is not, and stays in the data for the structure tests.  The
screen is iterated (Rousseeuw and Leroy 1987, *Robust Regression and Outlier Detection*, ch. 6:
reweighted least squares): the rows flagged whose ``|z|`` is within a factor :data:`DOMINANCE` of the
largest are set aside, the model is refitted without them, and every row (set-aside ones too) is judged
again against the cleaner fit, until the set is stable; so a huge spike that distorts the first fit
cannot condemn innocent rows.  A row with any outlying column is set aside whole.  More than
:data:`MAX_OUTLIER_SHARE` of the rows (5 %, at least one row) outlying: the data are refused (InputError)
-- a least-squares model is no description of them.  Fewer than :data:`MIN_DOF` residual degrees of
freedom: no screen (said in the result).

**Numerical floor.**  Residuals at the data's own precision are not evidence of anything: when the
residual RMS is at most ``FLOOR_REL`` (1e-9) times the RMS of the measured values, the residuals are
called noise without a test (round-off of float arithmetic is ~1e-16 of the values; no sensor resolves
1e-9 of its range).  The robust scale is never taken below this floor either.

**Serial correlation.**  :mod:`navlib.workbench.serial`: an AR(p) model of the noise estimated by REML from
the richest model's residuals, without the observations whose robust ``|z|`` exceeds :data:`Z_NOISE` (3.5,
the "potential outlier" cutoff of Iglewicz and Hoaglin 1993, *How to Detect and Handle Outliers*): the noise
model describes the bulk of the data, so a localised disturbance (a magnet passed at close range) is not
taken for strongly correlated noise that would then hide it.  The regressors are chosen by the likelihood
(:func:`navlib.workbench.serial.select`): the model's Jacobian alone, or with the system's structure shapes
as well when they fit the data better by BIC -- so a slow structure outside the catalogue is not mistaken
for correlated noise and stays testable, while on data without one the correlation keeps the precision
that the slow shapes would take from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from numba import njit
from scipy import special

from ..errors import InputError
from .effects import testable
from .fit import MEASURED, Fit, columns_of, measured_columns, refit_rows, residuals_on
from .linalg import least_squares_coef, leverage, orth_basis
from .serial import NoiseModel, select, series_of, with_projection

#: Lowest robust ``|z|`` that flags an outlier: a Gaussian sample beyond 6 standard deviations has probability
#: 2e-9; real sensor noise has heavier tails (the slow undisturbed BROAD trials reach 5.8) and stays below,
#: while an outlier that matters to an F test (one that inflates the residual sum of squares) lies far above.
Z_MIN = 6.0
#: Chance that a file of clean Gaussian noise loses any row to the screen (Bonferroni over observations).
OUTLIER_ALPHA = 0.01
#: More than this share of the rows flagged: the data are refused.
MAX_OUTLIER_SHARE = 0.05
#: Fewest residual degrees of freedom of the screening model for the screen to run.
MIN_DOF = 10
#: Each round sets aside the flagged rows whose ``|z|`` is at least the largest ``|z|`` divided by this.
DOMINANCE = 10.0
#: Observations with a robust ``|z|`` above this are left out of the noise model's estimate (they are what the
#: tests look at, not the noise; 3.5 is Iglewicz and Hoaglin's cutoff for a potential outlier).
Z_NOISE = 3.5
#: Residuals whose RMS is at most this share of the RMS of the measured values are noise.
FLOOR_REL = 1e-9
MAX_ROUNDS = 12
#: Tables of at most this many rows are screened with deletion residuals (and without structure shapes).
SMALL_TABLE = 60
#: In a time series an outlier stands out from the median of the samples within this many of it, and no
#: other sample that near is outlying too.
ISOLATION = 2
MAD_SD = 1.482602218505602  # 1 / Phi^-1(3/4)
#: Asymptotic efficiency of the MAD at the normal (Rousseeuw and Croux 1993).
MAD_EFFICIENCY = 0.367


@dataclass(frozen=True)
class Outlier:
    """One outlying observation: ``row`` is 1-based among the data rows (the loaders' row numbers),
    ``column`` the measured column, ``residual`` measured - model in the system's unit (the richest model
    fitted without the outliers), ``z`` its robust studentised value."""

    row: int
    column: str
    residual: float
    z: float

    def to_dict(self) -> dict:
        """``{"row", "column", "residual", "robust_z"}``."""
        return {
            "row": self.row,
            "column": self.column,
            "residual": self.residual,
            "robust_z": self.z,
        }


@dataclass
class Screening:
    """What :func:`screen` found on one data set.

    ``data``: the rows kept (original index); ``kept``: their 0-based positions in the data screened;
    ``outliers``: the observations set aside; ``cutoff``: the ``|z|`` that flags one; ``model``: the effects
    of the screening (richest) model; ``noise``: the serial-correlation model the tests whiten with;
    ``scale``, ``floor``: RMS of the measured values and the numerical floor (``FLOOR_REL * scale``);
    ``note``: why the screen did not run, if it did not; ``rich``: the richest model fitted to ``data``;
    ``regressors``: ``(jacobian, shapes)``, the columns the noise model was chosen around
    (:func:`navlib.workbench.serial.select`: the rich model's Jacobian, and its structure shapes or None;
    None when no noise model was estimated)."""

    data: pd.DataFrame
    kept: np.ndarray
    n_rows: int
    outliers: list
    cutoff: float | None
    model: tuple
    noise: NoiseModel
    scale: float
    floor: float
    note: str = ""
    rich: Fit | None = field(default=None, repr=False)
    regressors: tuple | None = field(default=None, repr=False)

    @property
    def rows_set_aside(self) -> list[int]:
        """The rows set aside (1-based, sorted)."""
        return sorted({o.row for o in self.outliers})

    def refit(self, fit: Fit) -> Fit:
        """``fit``'s model on the rows kept (``fit`` itself when no row was set aside), from ``fit``'s
        parameters (:func:`navlib.workbench.fit.refit_rows`)."""
        if len(self.kept) == self.n_rows:
            return fit
        return refit_rows(fit, self.data)

    def outlier_line(self, unit: str) -> str:
        """One line for a report: the rows set aside (empty when none)."""
        if not self.outliers:
            return ""
        rows = self.rows_set_aside
        shown = "; ".join(
            f"row {o.row} {o.column} {o.residual:+.4g} {unit} (z {o.z:.3g})"
            for o in self.outliers[:5]
        )
        more = f"; and {len(self.outliers) - 5} more" if len(self.outliers) > 5 else ""
        return (
            f"set aside {len(rows)} outlying row{'s' if len(rows) > 1 else ''} of {self.n_rows} "
            f"(robust |z| > {self.cutoff:.3g} against {' + '.join(self.model) or 'the model'}): "
            f"{shown}{more}"
        )

    def to_dict(self) -> dict:
        """The screen in ``--json``: ``rows`` (given), ``rows_used``, ``outliers``, ``outlier_cutoff`` (None if
        the screen did not run), ``screening_model``, ``numerical_floor``, ``noise``
        (:meth:`navlib.workbench.serial.NoiseModel.to_dict`), ``screen_note``."""
        return {
            "rows": self.n_rows,
            "rows_used": int(len(self.kept)),
            "outliers": [o.to_dict() for o in self.outliers],
            "outlier_cutoff": self.cutoff,
            "screening_model": list(self.model),
            "numerical_floor": self.floor,
            "noise": self.noise.to_dict(),
            "screen_note": self.note,
        }


def cutoff(n_obs: int, dof: int) -> float:
    """The robust ``|z|`` above which one of ``n_obs`` observations with ``dof`` residual degrees of freedom
    is an outlier (module docstring)."""
    nu = max(MAD_EFFICIENCY * dof, 1.0)
    return float(max(Z_MIN, -special.stdtrit(nu, OUTLIER_ALPHA / (2 * max(n_obs, 1)))))


def measurement_scale(fit: Fit, frame: pd.DataFrame) -> float:
    """RMS of the measured values of ``frame`` (:data:`navlib.workbench.fit.MEASURED`; for a system
    without an entry, of the model's prediction plus the residual)."""
    if fit.system in MEASURED:
        cols = [c for c in MEASURED[fit.system][0] if c in frame]
        v = columns_of(frame, cols) if cols else np.zeros((len(frame), 0))
    else:
        v = np.asarray(fit.predict(frame), float).ravel() + fit.residuals
    return float(np.sqrt(np.mean(v**2)))


def _robust_z(u: np.ndarray, ref: np.ndarray, floor: float) -> np.ndarray:
    """(u - median) / (1.4826 MAD) per column, median and MAD over the rows ``ref``; the scale is never
    below ``floor``."""
    median = np.nanmedian if np.isnan(u[ref]).any() else np.median
    med = median(u[ref], axis=0)
    mad = median(np.abs(u[ref] - med), axis=0)
    s = np.maximum(MAD_SD * mad, max(floor, 1e-300))
    return (u - med) / s


def _neighbour_gap(u: np.ndarray, ser) -> np.ndarray | None:
    """``u_t`` minus the median of its neighbours within ``ISOLATION`` samples in time (same segment; NaN
    where a segment has a single sample), or None if the data are not a time series (``ser``, the
    observations' :func:`navlib.workbench.serial.series_of`, is None).  The median (a Hampel filter's
    reference, Pearson 2002, *IEEE Trans. Control Syst. Technol.* 10:55) keeps a spike from making its
    neighbours look like spikes."""
    n, k = u.shape
    if ser is None:
        return None
    x = u.ravel()[ser.order]
    seg = np.cumsum(ser.pos == 0)
    gap = x - _neighbour_median(x, seg, ISOLATION)
    out = np.empty(n * k)
    out[ser.order] = gap
    return out.reshape(n, k)


@njit(error_model="numpy", cache=True)
def _neighbour_median(x, seg, width):  # pragma: no cover (compiled; tested against its numpy self)
    """For each sample of ``x``, the median of the samples within ``width`` of it in the same segment
    (``seg``), itself excluded (NaN where there are none): ``np.median`` / ``np.nanmedian`` of those
    values, to the bit (the middle one, or the mean of the middle two)."""
    m = len(x)
    out = np.empty(m)
    near = np.empty(2 * width)
    for i in range(m):
        c = 0
        for off in range(-width, width + 1):
            j = i + off
            if off == 0 or j < 0 or j >= m or seg[j] != seg[i] or np.isnan(x[j]):
                continue
            v = x[j]
            p = c  # insertion sort: at most 2 * width values
            while p > 0 and near[p - 1] > v:
                near[p] = near[p - 1]
                p -= 1
            near[p] = v
            c += 1
        if c == 0:
            out[i] = np.nan
        elif c % 2:
            out[i] = near[c // 2]
        else:
            out[i] = (near[c // 2 - 1] + near[c // 2]) / 2.0
    return out


def _neighbour_median_numpy(x: np.ndarray, seg: np.ndarray, width: int) -> np.ndarray:
    """The reference of ``_neighbour_median`` (numpy: the neighbours side by side, a median per row)."""
    m = len(x)
    near = np.full((m, 2 * width), np.nan)
    col = 0
    for off in [o for o in range(-width, width + 1) if o]:
        idx = np.arange(m) + off
        ok = (idx >= 0) & (idx < m)
        ok[ok] &= seg[idx[ok]] == seg[ok]
        near[ok, col] = x[idx[ok]]
        col += 1
    missing = np.isnan(near)
    has = ~np.all(missing, axis=1)
    ref = np.full(m, np.nan)
    full = ~np.any(missing, axis=1)
    ref[full] = np.median(near[full], axis=1)
    edge = has & ~full
    ref[edge] = np.nanmedian(near[edge], axis=1)
    return ref


def _richest(fit: Fit) -> list[tuple[str, ...]]:
    """Models to screen with, richest first: every testable effect (catalogue and user), the testable
    catalogue, the model itself."""
    ok, _ = testable(fit.available, fit.data)
    every = tuple(e for e in fit.available if e in ok or e in fit.effects)
    cat = tuple(e for e in every if e in fit.spec.catalogue or e in fit.effects)
    out = []
    for m in (every, cat, tuple(fit.effects)):
        if m not in out:
            out.append(m)
    return out


def _fit_rich(fit: Fit, frame: pd.DataFrame, models) -> Fit | None:
    for m in models:
        try:
            f = refit_rows(fit, frame, m)
        except InputError:
            continue
        if f.n - f.n_params >= MIN_DOF:
            return f
    return None


def screen(fit: Fit, *, outliers: bool = True, serial: bool = True) -> Screening:
    """Screen the data of ``fit`` (module docstring): outliers set aside, the numerical floor, the noise's
    serial correlation.  ``outliers=False`` / ``serial=False`` skip those parts.

    Raises
    ------
    InputError
        When more than ``MAX_OUTLIER_SHARE`` of the rows are outliers.
    """
    data = fit.data
    n = len(data)
    scale = measurement_scale(fit, data)
    floor = FLOOR_REL * scale
    rich = _fit_rich(fit, data, _richest(fit)) if outliers or serial else None
    kept = np.arange(n)
    found: list[Outlier] = []
    note = ""
    c = cutoff(rich.n, rich.n - rich.n_params) if rich is not None else None
    if not outliers:
        note = "not run"
    elif rich is None:
        note = f"not run: fewer than {MIN_DOF} residual degrees of freedom"
    elif fit.system not in MEASURED:
        note = f"not run: system '{fit.system}' names no measured columns"
    zk = None
    # the time series of the data's observations (the screen's rounds and the noise model share it)
    ser_all = series_of(data, rich.n, rich.system) if rich is not None else None
    shapes_all = None  # the structure shapes on every row (they read the data only)
    if rich is not None and outliers and fit.system in MEASURED and rich.rms > floor:
        shapes_all = _shapes_on(rich, data)
        rich, kept, found, zk = _screen_rows(fit, data, rich, c, floor, ser_all, shapes_all)
    if rich is not None and len(kept) < n:
        data = data.iloc[kept]
    noise = NoiseModel(n_obs=fit.n)
    regressors = None
    if serial and rich is not None and rich.rms > floor:
        ser = ser_all if rich.data is fit.data else series_of(rich.data, rich.n, rich.system)
        if (
            ser is not None and rich.spec.noise_directions is not None
        ):  # residuals see axis-wise noise
            ser = with_projection(ser, rich.data, rich.spec.noise_directions(rich))
        if ser is not None:
            if zk is not None:  # the noise model describes the bulk of the data
                ser = ser.without(np.abs(zk.ravel()) > Z_NOISE)
            if shapes_all is not None and len(rich.data) == n:  # no row set aside: the same shapes
                S = shapes_all if shapes_all.shape[1] else None
            else:
                shapes = [np.asarray(X, float) for _, X, _ in rich.spec.structure(rich)]
                S = np.column_stack(shapes) if shapes else None
            regressors = (rich.jacobian, S)
            noise = select(rich.residuals, *regressors, ser)
    return Screening(
        data,
        kept,
        n,
        found,
        c,
        rich.effects if rich is not None else tuple(fit.effects),
        noise,
        scale,
        floor,
        note,
        rich,
        regressors,
    )


def _shapes_on(rich: Fit, frame: pd.DataFrame) -> np.ndarray:
    """The system's structure shapes evaluated on the rows of ``frame`` (columns side by side)."""
    probe = replace(rich, data=frame)  # the structure functions read only the data
    cols = [np.asarray(X, float) for _, X, _ in rich.spec.structure(probe)]
    return np.column_stack(cols) if cols else np.zeros((len(frame) * (rich.n // len(rich.data)), 0))


def _isolated(size: np.ndarray, c: float, data: pd.DataFrame, axes: int, ser) -> np.ndarray:
    """In a time series (``ser``, the observations' :func:`navlib.workbench.serial.series_of`; None: not
    one), the rows whose largest robust ``|z|`` (``size``) no other row within ``ISOLATION`` samples of their
    segment comes near: none there exceeds ``max(c, size / DOMINANCE)``.  A run of large residuals is an
    event, left to the structure tests; the lesser residuals a huge spike causes around it in a fit it
    distorts do not hide the spike."""
    if ser is None:
        return np.ones(len(data), bool)
    n = len(data)
    rows, pos = ser.order[:n] // axes, ser.pos[:n]  # axis 0: rows in time order
    z = size[rows]
    bar = np.maximum(c, z / DOMINANCE)
    seg = np.cumsum(pos == 0)
    near = np.zeros(n, bool)
    for k in range(1, ISOLATION + 1):
        same = seg[k:] == seg[:-k]
        near[k:] |= (z[:-k] > bar[k:]) & same
        near[:-k] |= (z[k:] > bar[:-k]) & same
    out = np.zeros(n, bool)
    out[rows] = ~near
    return out


def _deletion_z(fit: Fit, data: pd.DataFrame, rich: Fit, floor: float) -> np.ndarray:
    """Robust z of every row's deletion residual: the row's prediction error by the model fitted without
    it, scaled by ``sqrt(1 - h)`` (its leverage in the full fit), against the median and MAD of the other
    rows' studentised residuals in that fit.  On a short table one outlier at a high-leverage point pulls
    the full fit towards itself and inflates everyone's residuals (masking); without it, it stands out.
    The fits without each row follow from the full fit's hat matrix ``H = Q Q'`` (``Q`` an orthonormal
    basis of the Jacobian) by the deletion formulas of Belsley, Kuh and Welsch (1980, *Regression
    Diagnostics*, ch. 2): ``e^(i) = e + H[:, B] (I - H[B, B])^-1 e[B]`` and
    ``h^(i) = h + diag(H[:, B] (I - H[B, B])^-1 H[B, :])`` for the observations ``B`` of row i (exact for a
    linear model, to first order otherwise)."""
    n = len(data)
    axes = rich.n // n
    q = orth_basis(rich.jacobian)
    H = q @ q.T
    e = rich.residuals
    h = np.clip(np.diag(H), 0.0, 0.99)
    z = np.zeros((n, axes))
    if axes == 1:  # every deletion at once: row i of U is the fit without i
        g = e / (1.0 - h)
        U = e[None, :] + H * g[:, None]
        hU = np.clip(h[None, :] + H**2 / (1.0 - h)[:, None], 0.0, 0.99)
        U = U / np.sqrt(1.0 - hU)
        U[np.arange(n), np.arange(n)] = np.nan
        med = np.nanmedian(U, axis=1)
        mad = np.nanmedian(np.abs(U - med[:, None]), axis=1)
        own = g * np.sqrt(1.0 - h)
        return ((own - med) / np.maximum(MAD_SD * mad, max(floor, 1e-300)))[:, None]
    for i in range(n):
        B = np.arange(i * axes, (i + 1) * axes)
        A = np.linalg.pinv(np.eye(axes) - H[np.ix_(B, B)])
        HB = H[:, B]
        ei = e + HB @ (A @ e[B])
        hi = np.clip(h + np.einsum("jb,bc,jc->j", HB, A, HB), 0.0, 0.99)
        u = (ei / np.sqrt(1.0 - hi)).reshape(n, axes)
        u[i] = ei[B] * np.sqrt(1.0 - h[B])
        z[i] = _robust_z(u, np.delete(np.arange(n), i), floor)[i]
    return z


def _screen_rows(fit: Fit, data: pd.DataFrame, rich: Fit, c: float, floor: float, ser, shapes_all):
    """The iteration of the module docstring; returns the richest fit on the rows kept, their positions
    and the outliers.  ``ser``: the series of ``data``'s observations (:func:`serial.series_of`, None if
    not a time series), ``shapes_all`` the structure shapes on them (:func:`_shapes_on`)."""
    n = len(data)
    axes = rich.n // n
    cols = measured_columns(fit.system, axes)
    aside = np.zeros(n, bool)
    limit = max(1, int(math.floor(MAX_OUTLIER_SHARE * n)))
    dof = rich.n - rich.n_params
    if n <= SMALL_TABLE or dof - shapes_all.shape[1] < max(MIN_DOF, dof / 2):
        shapes_all = shapes_all[:, :0]  # too few rows to take the structure out as well

    def judge(rich, aside):
        """Robust z of every observation against ``rich`` (fitted to the rows not ``aside``) and the
        structure shapes, and which observations are outliers."""
        kept = np.flatnonzero(~aside)
        r = r_model = residuals_on(rich, data)
        obs = (kept[:, None] * axes + np.arange(axes)).ravel()
        if shapes_all.shape[1]:
            # the shapes fitted to the residual clipped at Z_NOISE robust standard deviations (one Huber
            # step), so that a spike is not smeared over its time cell
            S = shapes_all if len(kept) == n else shapes_all[obs]  # every row: no copy
            lev = leverage(np.column_stack([rich.jacobian, S]))
            rk = r[kept]
            med = np.median(rk, axis=0)
            half = Z_NOISE * np.maximum(MAD_SD * np.median(np.abs(rk - med), axis=0), floor)
            coef = least_squares_coef(S, np.clip(rk, med - half, med + half).ravel())
            r = r - (shapes_all @ coef).reshape(n, axes)
        else:
            lev = leverage(rich.jacobian)
        h = np.zeros((n, axes))
        h[kept] = np.clip(lev, 0.0, 0.99).reshape(len(kept), axes)
        u = r / np.sqrt(1.0 - h)
        z = _robust_z(u, kept, floor)
        flagged = np.abs(z) > c
        gap = _neighbour_gap(u, ser)
        if gap is not None:
            zg = _robust_z(gap, kept, floor)
            flagged &= np.isnan(zg) | (np.abs(zg) > c)
            flagged &= _isolated(np.abs(z).max(axis=1), c, data, axes, ser)[:, None]
        return r_model, z, flagged

    for k in range(MAX_ROUNDS):
        r, z, flagged = judge(rich, aside)
        if k == 0 and n <= SMALL_TABLE:  # a short table: deletion residuals against masking
            zd = _deletion_z(fit, data, rich, floor)
            flagged = flagged | (np.abs(zd) > c)
            z = np.where(np.abs(zd) > np.abs(z), zd, z)
        row_flag = flagged.any(axis=1)
        zmax = np.where(flagged, np.abs(z), 0.0).max(axis=1)
        new = row_flag & ~aside
        dominant = new & (zmax >= zmax[new].max() / DOMINANCE) if new.any() else new
        nxt = (aside & row_flag) | dominant
        if np.array_equal(nxt, aside) or nxt.all():
            break
        aside = nxt
        rich = refit_rows(rich, data.iloc[np.flatnonzero(~aside)])
    else:
        r, z, flagged = judge(rich, aside)
    bad = np.flatnonzero(aside | flagged.any(axis=1))
    if len(bad) > limit:
        j = int(np.argmax(np.abs(z[bad[0]])))
        raise InputError(
            f"{len(bad)} of {n} rows are outliers (robust |z| > {c:.3g} against the model "
            f"{' + '.join(rich.effects) or '(none)'}; e.g. column '{cols[j]}', rows "
            f"{', '.join(str(int(b) + 1) for b in bad[:6])}{', ...' if len(bad) > 6 else ''}): more than "
            f"{limit} ({100 * MAX_OUTLIER_SHARE:g} % of the rows, at least 1) that the screen sets aside; a "
            f"least-squares model does not describe these data -- check the file"
        )
    kept = np.flatnonzero(~aside)
    found = []
    for i in np.flatnonzero(aside):
        js = np.flatnonzero(flagged[i]) if flagged[i].any() else [int(np.argmax(np.abs(z[i])))]
        found += [Outlier(int(i) + 1, cols[j], float(r[i, j]), float(z[i, j])) for j in js]
    return rich, kept, found, z[kept]
