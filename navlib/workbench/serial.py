"""Serially correlated residuals: an AR(p) model of the noise and the whitening that keeps the workbench's
F tests honest on time series.

Samples of a recording (a magnetometer at 10 Hz turned by hand, a compass read every few seconds) are
rarely independent: the noise wanders, and neighbouring samples share it.  A shape that varies slowly in
time (a constant offset, a field that drifts, anything that follows a slow hand rotation) then picks up
far more of the noise than the independent-sample F test expects -- with a lag-1 correlation of 0.9 the
variance of a mean is (1 + 0.9) / (1 - 0.9) = 19 times larger -- and every such shape looks significant.
The workbench therefore models the noise and tests on whitened residuals (generalised least squares).

**The series.**  The residuals of one measurement axis in time order: by ``time_s`` when the data have it,
else in file order for a system that records time series (:data:`FILE_ORDER_SYSTEMS`, the
magnetometer); data with neither (a drift table, a tumble test, heading bins) are not a series and are not
whitened.  A series is cut into segments where a time step exceeds :data:`GAP_FACTOR` times the median
step (gaps where the reference was lost, rows set aside); within a segment the samples are taken as
equally spaced.

**The model.**  Every axis and segment shares one stationary AR(p) process, ``p <= MAX_ORDER``,
parametrised by its partial autocorrelations ``kappa_1..kappa_p`` in (-1, 1), so every value is a
stationary process (Barndorff-Nielsen and Schou 1973, J. Multivariate Anal. 3:408).  Whitening is the exact
inverse Cholesky factor of its correlation matrix on each segment: the t-th sample of a segment is
predicted from the previous ``min(t, p)`` with the Durbin-Levinson coefficients of that order and divided
by the square root of the prediction-error variance (Brockwell and Davis 1991, *Time Series: Theory and
Methods*, sections 5.2 and 8.7), so ``W e`` has independent samples of one variance.

**The projected model.**  Some systems' residuals are not the sensor's axes but scalars computed from
them along a direction that turns with the sensor: the reference-free magnetometer's invariants (the field
magnitude, ``e = n . u/|u|``, and the dip) see the axis-wise noise ``n`` through the field's direction,
which turns by tens of degrees within a correlation time of the noise when the sensor is turned by hand.
Their correlation in time is then ``rho(k) (d_t . d_(t+k))``, not an AR process of the residual, and an AR
model fitted to it is misspecified (on AR(1) noise of 0.9 its REML estimate runs to the bound
:data:`KAPPA_MAX`, the whitened tests and their bootstrap then describe a random walk, and data with nothing
missing fail the tests far more often than ``alpha``).  For such a system the series carries a
:class:`Projection` (the system's ``noise_directions`` hook gives ``d_i``, the gradient of each residual
with respect to the raw axes) and the noise model is the sensor's: AR(1) on each axis, continuous in time
(``rho(k) = kappa^|k|``, ``k`` in sampling steps, so gaps and rows set aside need no segments), seen
through the directions::

    Cov(x_i, x_j) = s^2 kappa^|t_i - t_j| (d_i . d_j)
                                     (positive definite: a Schur product)

Whitening and colouring are those of the Cholesky factor of this matrix (exact GLS for the invariants), and
its REML likelihood uses ``log det R`` of the same factor; the order is 0 or 1 (AIC), the rest of the
machinery -- tests, bootstrap, intervals -- unchanged.  The matrix is never formed: the model is a state-space
model (the 3-axis noise is the state, each residual a scalar observation of it), and a Kalman filter over
the observations in time order gives the innovations, whose standardised values are exactly ``L^-1 x`` for
the Cholesky factor ``L`` in that order, with ``log det R = sum log S_i`` (:mod:`navlib.workbench.innovations`;
O(n) time and memory instead of O(n^3) and O(n^2)).  A filter needs time order, so a projected series is
ordered *time-major* (:func:`with_projection`): the observations of each row together, rows in time order
(row 0's axes, row 1's axes, ...), where any other series is axis-major (each axis in time order, one
after the other).  Whitened vectors (``W x``), the bootstrap's unit draws (:func:`colour`) and ``pos`` are
in that order; no consumer depends on it (the tests use sums of squares and projections of whitened
vectors, and colour returns observation order), and the GLS quantities (``RSS_W``, the likelihood, the F
tests) do not depend on the order at all.

**The estimate.**  The kappas maximise the *restricted* (REML) log likelihood of the residual ``r`` given
the regressors ``X`` (the columns a least-squares fit has already taken out of it: the model's Jacobian
and the structure shapes), with ``R`` the AR correlation matrix and ``W' W = R^-1``::

    l_R(kappa) = -1/2 [ (N - k) log RSS_W  +  log det R  +  log det (X' R^-1 X) ],
    RSS_W = min_b |W (r - X b)|^2

(Harville 1977, JASA 72:320).  Restricted rather than plain likelihood because the residuals of a fit
with many smooth regressors look less correlated than the noise was: least-squares residual
autocorrelations, and plain ML, are biased towards zero, which would leave the tests too liberal; REML
removes most of that bias for AR errors in regression (Cheang and Reinsel 2000, JASA 95:1173).  The order
``p`` is chosen by AIC (Akaike 1974, IEEE Trans. Autom. Control 19:716), forward: orders 1, 2, ... up to
``MAX_ORDER`` while each lowers the AIC.  The likelihood is evaluated from lagged cross-products of the
regressors and the residual, computed once, and maximised over ``atanh(kappa)`` by L-BFGS-B with its
analytic gradient (:mod:`navlib.workbench.reml`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy import special
from scipy.linalg.lapack import dpotrf
from scipy.optimize import brentq, minimize, minimize_scalar

from . import innovations
from .linalg import orth_basis, orth_basis_split
from .reml import _Prepared, _Restricted, ar_colour, levinson  # noqa: F401  (re-exported: serial's names)

#: A time step more than this many times the median step starts a new segment.
GAP_FACTOR = 2.5
#: Highest AR order tried.
MAX_ORDER = 3
#: Partial autocorrelations are kept within +-KAPPA_MAX (a unit root cannot be whitened).
KAPPA_MAX = 0.995
#: Fewest samples beyond the regressors for an estimate (fewer: the samples are taken as independent).
MIN_SAMPLES = 20
#: Coverage of the profile-likelihood interval of kappa_1 reported with the noise model (``lag1_interval``).
KAPPA_LEVEL = 0.9
#: Penalty per parameter of the criterion that chooses the noise model's regressors (:func:`select`), as a
#: function of the number of observations: BIC's ``log N`` (Schwarz 1978, Ann. Stat. 6:461).
SELECT_PENALTY = np.log
#: Systems whose rows are a time series in file order when the data have no ``time_s`` column.
FILE_ORDER_SYSTEMS = {"magnetometer"}


@dataclass(frozen=True, eq=False)
class Projection:
    """How the residuals see a noise that lives on the sensor's axes: each observation ``i`` is
    ``x_i = d_i . n(t_i)`` with ``n`` the sensor's 3-axis noise (the same AR process on each axis,
    independent between axes) and ``d_i`` a unit vector (``directions``, observation order); ``clock`` is
    each observation's time in sampling steps.  Then ``Cov(x_i, x_j) = s^2 rho(|t_i - t_j|) (d_i . d_j)``
    (module docstring: the projected model)."""

    directions: np.ndarray
    clock: np.ndarray


@dataclass(frozen=True)
class Series:
    """Where the observations of a residual vector sit in time: ``order`` lists observation indices axis by
    axis, each axis in time order -- or, with a ``projection``, time-major: rows in time order, each row's
    observations together (:func:`with_projection`); ``pos`` is each ordered observation's place in its
    segment (0 starts a segment); ``source`` says what ordered them (``"time_s"`` or ``"file order"``);
    ``projection``: the residuals are a turning projection of axis-wise noise (:class:`Projection`), or
    None."""

    order: np.ndarray
    pos: np.ndarray
    source: str
    projection: Projection | None = None

    @property
    def segments(self) -> int:
        return int(np.sum(self.pos == 0))

    def without(self, drop: np.ndarray) -> "Series":
        """The series without the observations ``drop`` (a boolean mask over observations): each one
        removed ends its segment, and the next sample starts a new one."""
        gone = np.asarray(drop, bool)[self.order]
        if not gone.any():
            return self
        start = self.pos == 0
        start[1:] |= gone[:-1]  # after a removed sample a new segment starts
        start = start[~gone]
        seg = np.cumsum(start) - 1
        first = np.flatnonzero(start)
        return Series(
            self.order[~gone], np.arange(len(seg)) - first[seg], self.source, self.projection
        )


def series_of(data: pd.DataFrame, n_obs: int, system: str) -> Series | None:
    """The :class:`Series` of a residual vector of ``n_obs`` observations on ``data`` (``n_obs / len(data)``
    axes, flattened row by row as the systems do), or None when the data are not a time series."""
    n = len(data)
    if n < 3 or n_obs % n:
        return None
    axes = n_obs // n
    if "time_s" in data and np.ptp(data["time_s"].to_numpy(float)) > 0:
        t = data["time_s"].to_numpy(float)
        rows = np.argsort(t, kind="stable")
        source = "time_s"
        step = np.diff(t[rows])
    elif system in FILE_ORDER_SYSTEMS:
        rows = np.arange(n)
        source = "file order"
        step = np.ones(n - 1)
    else:
        return None
    positive = step[step > 0]
    typical = float(np.median(positive)) if positive.size else 1.0
    new = np.concatenate([[True], step > GAP_FACTOR * typical])
    seg = np.cumsum(new) - 1
    first = np.flatnonzero(new)
    pos_rows = np.arange(n) - first[seg]
    order = np.concatenate([rows * axes + j for j in range(axes)])
    pos = np.tile(pos_rows, axes)
    return Series(order, pos, source)


def with_projection(
    series: Series | None, data: pd.DataFrame, directions: np.ndarray
) -> Series | None:
    """``series`` with the :class:`Projection` of residuals that see axis-wise noise along ``directions``
    ((n_obs, 3), observation order, rows flattened as the systems do): each observation's clock is its
    row's ``time_s`` over the median time step (a series in file order: the row number).  The series is
    reordered time-major (rows in time order, each row's observations together: the order of the filter,
    module docstring); a segment starts where one of ``series``'s started."""
    if series is None:
        return None
    d = np.asarray(directions, float)
    n = len(data)
    axes = len(d) // n
    if series.source == "time_s":
        t = data["time_s"].to_numpy(float)
        steps = np.diff(np.sort(t))
        steps = steps[steps > 0]
        t = (t - t.min()) / (float(np.median(steps)) if steps.size else 1.0)
    else:
        t = np.arange(n, dtype=float)
    clock = np.repeat(t, axes)
    old = series.order
    starts = np.zeros(n * axes, bool)
    starts[old[series.pos == 0]] = True  # observations that started a segment
    row = old // axes
    first = np.full(n, len(old))  # each row's place in time: its first in ``old``
    np.minimum.at(first, row, np.arange(len(old)))
    order = old[np.lexsort((old % axes, first[row]))]
    row = order // axes
    start = starts[order] & np.r_[True, row[1:] != row[:-1]]
    start[0] = True
    seg = np.cumsum(start) - 1
    pos = np.arange(len(order)) - np.flatnonzero(start)[seg]
    return Series(order, pos, series.source, Projection(d, clock))


#: Filters of projected series kept (:func:`projected_gains`).
_KEEP_GAINS = 6
_GAINS: dict = {}
_INPUTS: dict = {}


def regular_clock(series: Series) -> bool:
    """Whether a projected series is sampled on whole steps (then a negative lag-1 correlation is an AR(1)
    process; on an irregular clock only ``kappa >= 0``, ``kappa^|dt|``, is a valid correlation)."""
    c = series.projection.clock
    r = np.round(c)
    return bool(np.all(np.abs(c - r) <= 1e-6 + 1e-5 * np.abs(r)))  # np.allclose's test, in one pass


def _projected_inputs(series: Series, k: float, steps: bool = False) -> tuple:
    """The filter's inputs for a projected ``series``: the clock and directions in series order and the
    nugget (computed once per series); with ``steps``, the clock's
    :func:`~navlib.workbench.innovations.clock_steps` instead of the clock.  ValueError for a negative
    ``k`` on an irregular clock."""
    inputs = _INPUTS.get(id(series))
    if inputs is None or inputs[0] is not series:  # the clock and directions in series order, once
        pr = series.projection
        d = np.ascontiguousarray(pr.directions[series.order], float)
        clock = pr.clock[series.order]
        inputs = (
            series,
            clock,
            d,
            regular_clock(series),
            innovations.nugget_of(d),
            innovations.clock_steps(clock),
        )
        _INPUTS.clear()
        _INPUTS[id(series)] = inputs
    _, clock, d, regular, nugget, clock_steps = inputs
    if k < 0 and not regular:
        raise ValueError("a negative correlation needs a regular clock (whole sampling steps)")
    return (clock_steps if steps else clock), d, nugget


def projected_gains(kappa, series: Series) -> innovations.Gains:
    """The Kalman filter of the projected model (module docstring; :mod:`navlib.workbench.innovations`)
    over the observations of ``series``, in series order (time-major), AR(1): ``kappa[0]``; the last few
    are kept (a likelihood's optimiser and a bootstrap come back to the same ones)."""
    k = float(kappa[0])
    key = (id(series), k)
    hit = _GAINS.get(key)
    if hit is not None and hit[0] is series:
        return hit[1]
    clock, d, nugget = _projected_inputs(series, k)
    g = innovations.gains(k, clock, d, nugget)
    if len(_GAINS) >= _KEEP_GAINS:
        _GAINS.pop(next(iter(_GAINS)))
    _GAINS[key] = (series, g)
    return g


def ar1_noise(rng: np.random.Generator, shape, sd: float, correlation: float) -> np.ndarray:
    """Gaussian AR(1) noise along axis 0: marginal standard deviation ``sd`` and lag-1 correlation
    ``correlation`` (stationary from the first sample: ``e_0 ~ N(0, sd^2)``,
    ``e_t = c e_(t-1) + sd sqrt(1 - c^2) u_t``)."""
    shape = tuple(np.atleast_1d(shape))
    u = rng.standard_normal(shape)
    e = np.empty(shape)
    e[0] = sd * u[0]
    s = sd * np.sqrt(1.0 - correlation**2)
    for t in range(1, shape[0]):
        e[t] = correlation * e[t - 1] + s * u[t]
    return e


def whiten(x: np.ndarray, kappa, series: Series, *, ordered: bool = False) -> np.ndarray:
    """``W x`` in series order: each sample minus its best linear prediction from the previous
    ``min(pos, p)`` samples of its segment, divided by the root of that prediction's error variance
    (relative to the process variance).  ``x``: (N,) or (N, k) in observation order, or already in series
    order (``x[series.order]``) with ``ordered`` (columns whitened many times under different models)."""
    x = np.asarray(x, float)
    xo = x if ordered else x[series.order]
    p = len(kappa)
    if p == 0:
        return xo
    if series.projection is not None:
        return innovations.whiten_columns(projected_gains(kappa, series), xo)
    phi, v = levinson(kappa)
    m = len(xo)
    out = xo.copy()
    for j in range(1, p + 1):  # the full-order filter on every sample from the p-th on
        out[p:] -= phi[p, j] * xo[p - j : m - j]
    out[p:] /= np.sqrt(v[p])
    early = np.flatnonzero(series.pos < p)  # near a segment start: the filter of a lower order
    order = series.pos[early]
    acc = xo[early].copy()
    for j in range(1, p):
        use = order >= j
        c = phi[order[use], j]
        acc[use] -= (c[:, None] * xo[early[use] - j]) if xo.ndim == 2 else c * xo[early[use] - j]
    scale = 1.0 / np.sqrt(v[order])
    out[early] = acc * (scale[:, None] if xo.ndim == 2 else scale)
    return out


def whiten_transpose(y: np.ndarray, kappa, series: Series) -> np.ndarray:
    """``W' y`` for ``y`` (N,) or (N, k) in series order, in series order: the adjoint of :func:`whiten`, so
    ``W' W x = R^-1 x`` (``R`` the AR correlation on each segment).  Sample ``t`` of order
    ``m = min(pos_t, p)`` gives ``y_t / sqrt(v_m)`` to itself and ``-phi_mj y_t / sqrt(v_m)`` to sample
    ``t - j`` (``j <= m``: within its segment).  Not for a series with a :class:`Projection`."""
    y = np.asarray(y, float)
    p = len(kappa)
    if p == 0:
        return y.copy()
    if series.projection is not None:
        raise ValueError("whiten_transpose: a projected series is whitened by its filter")
    phi, v = levinson(kappa)
    m = np.minimum(series.pos, p)
    scale = 1.0 / np.sqrt(v[m])
    z = y * (scale[:, None] if y.ndim == 2 else scale)
    out = z.copy()
    for j in range(1, p + 1):
        c = phi[m[j:], j]  # 0 where pos_t < j (phi[m, j] = 0 for j > m)
        out[:-j] -= (c[:, None] if y.ndim == 2 else c) * z[j:]
    return out


def whiten_each(
    x: np.ndarray, kappas: list, series: Series, *, transpose: bool = False
) -> np.ndarray:
    """Each column of ``x`` (N, B; series order) under its own partial autocorrelations ``kappas[b]`` (all
    of one order, no :class:`Projection`): ``W_b x_b`` (:func:`whiten`), or ``W_b' x_b`` with ``transpose``
    (:func:`whiten_transpose`); series order out.  Sample ``t`` of order ``m = min(pos_t, p)`` and column ``b``
    uses ``phi_b[m, j]`` (0 for ``j > m``: within its segment) and ``1 / sqrt(v_b[m])``."""
    x = np.asarray(x, float)
    p = len(kappas[0]) if len(kappas) else 0
    if any(len(k) != p for k in kappas):
        raise ValueError("whiten_each: the columns' models must have one order")
    if p == 0:
        return x.copy()
    if series.projection is not None:
        raise ValueError("whiten_each: a projected series is whitened by its filter")
    lev = [levinson(k) for k in kappas]
    phi, v = (
        np.stack([f for f, _ in lev]),
        np.stack([w for _, w in lev]),
    )  # (B, p + 1, p + 1), (B, p + 1)
    m = np.minimum(series.pos, p)
    scale = 1.0 / np.sqrt(v[:, m].T)  # (N, B)
    if transpose:
        z = x * scale
        out = z.copy()
        for j in range(1, p + 1):
            out[:-j] -= phi[:, m[j:], j].T * z[j:]
        return out
    out = x.copy()
    for j in range(1, p + 1):
        out[j:] -= phi[:, m[j:], j].T * x[:-j]
    return out * scale


def colour(u: np.ndarray, kappa, series: Series, n_obs: int) -> np.ndarray:
    """The inverse of :func:`whiten`: from independent unit samples ``u`` (N, or N x B, in *series order*,
    N = ``len(series.order)``) the stationary AR process with partial autocorrelations ``kappa`` and unit
    variance on each segment, returned in observation order (``n_obs`` rows; observations outside the
    series are 0).  ``whiten(colour(u)) == u``: the first samples of a segment are built with the
    Durbin-Levinson coefficients of their own order, the rest by the recursion of order p
    (:func:`navlib.workbench.reml.ar_colour`, compiled)."""
    u = np.asarray(u, float)
    p = len(kappa)
    out = np.zeros((n_obs,) + u.shape[1:])
    if p == 0:
        out[series.order] = u
        return out
    if series.projection is not None:
        out[series.order] = innovations.colour_columns(projected_gains(kappa, series), u)
        return out
    phi, v = levinson(kappa)
    starts = np.r_[np.flatnonzero(series.pos == 0), len(u)].astype(np.int64)
    cols = np.ascontiguousarray(u.reshape(len(u), -1))
    x = ar_colour(cols, phi, v, starts).reshape(u.shape)
    out[series.order] = x
    return out


@dataclass(frozen=True)
class NoiseModel:
    """The residuals' serial correlation: AR(p) partial autocorrelations ``kappa`` (empty = independent
    samples), the :class:`Series` they act on (None = not a time series) and the REML log likelihoods of
    the orders tried."""

    kappa: tuple = ()
    series: Series | None = None
    n_obs: int = 0
    loglik: tuple = ()
    note: str = ""
    bounds: tuple = ()
    ml: float = float("nan")
    regressors: int = 0
    around: str = ""

    @property
    def order(self) -> int:
        return len(self.kappa)

    @property
    def correlated(self) -> bool:
        return self.series is not None and self.order > 0

    @property
    def lag1(self) -> float:
        """Lag-1 autocorrelation of the AR model (= kappa_1)."""
        return float(self.kappa[0]) if self.kappa else 0.0

    @property
    def inflation(self) -> float:
        """How many times larger the variance of a long-run mean is than for independent samples:
        ``v_p / (1 - sum phi_p)^2`` (the AR spectrum at frequency 0 over the process variance)."""
        if not self.correlated:
            return 1.0
        phi, v = levinson(self.kappa)
        return float(v[-1] / (1.0 - phi[-1, 1:].sum()) ** 2)

    @property
    def effective_samples(self) -> float:
        """``n_obs / inflation``: the number of independent samples a slowly varying shape effectively
        sees."""
        return self.n_obs / self.inflation

    def whiten(self, x: np.ndarray, ordered: bool = False) -> np.ndarray:
        """``W x`` (rows reordered into series order), or ``x`` unchanged if the samples are independent;
        ``ordered``: ``x`` is already in series order (:func:`whiten`)."""
        return (
            whiten(x, self.kappa, self.series, ordered=ordered)
            if self.correlated
            else np.asarray(x, float)
        )

    def to_dict(self) -> dict:
        """The noise model in ``--json``: what ordered the series (``time_s``, ``file order`` or None), AR
        order, partial autocorrelations, lag-1 correlation and its interval, the variance inflation of a
        slow shape, the effective number of samples and the regressors it was estimated around
        (:func:`select`)."""
        return {
            "series": self.series.source if self.series is not None else None,
            "ar_order": self.order,
            "partial_autocorrelations": [float(k) for k in self.kappa],
            "lag1_correlation": self.lag1,
            "lag1_interval": [float(k) for k in self.bounds],
            "variance_inflation": self.inflation,
            "effective_samples": self.effective_samples,
            "estimated_around": self.around or None,
        }

    def describe(self) -> str:
        """One phrase for a report."""
        if self.series is None:
            return "samples taken as independent (not a time series)"
        if self.note:
            return f"samples taken as independent ({self.note})"
        if not self.correlated:
            return (
                f"no serial correlation found (AR order 0 by AIC; series in {self.series.source})"
            )
        slow = (
            f"a slow shape sees about {self.effective_samples:.0f} independent samples of {self.n_obs}"
            if self.inflation > 1
            else "neighbouring samples anti-correlated"
        )
        seen = (
            " on the sensor's axes, seen along the residuals' turning directions"
            if self.series.projection is not None
            else ""
        )
        return (
            f"serially correlated, AR({self.order}){seen} with lag-1 correlation {self.lag1:.2f} "
            f"(interval {self.bounds[0]:.2f}..{self.bounds[1]:.2f}; series in {self.series.source}): tests "
            f"on whitened residuals, {slow}"
        )


class _ProjectedLik:
    """:class:`_Restricted` for a series with a :class:`Projection`: the same REML and plain likelihoods,
    from the Kalman filter of the projected model (AR order 0 or 1): ``[Q, r]`` whitened, ``log det R`` the
    sum of the log innovation variances."""

    def __init__(self, r: np.ndarray, Q: np.ndarray, series: Series):
        self.Z = np.column_stack([np.asarray(Q, float), np.asarray(r, float)])[
            series.order
        ]  # [Q, r]
        self.Z = np.ascontiguousarray(self.Z)
        self.series = series
        self.n, self.k = self.Z.shape[0], self.Z.shape[1] - 1
        self._seen: dict = {}  # kappa -> parts: the optimiser and the interval come back to points
        self.values: dict = {}  # kappa -> the REML log likelihood: the interval's first brackets

    def __call__(self, kappa) -> float:
        rss, logdet_r, logdet_g = self._parts(kappa)
        value = -0.5 * ((self.n - self.k) * np.log(max(rss, 1e-300)) + logdet_r + logdet_g)
        self.values[tuple(float(k) for k in kappa)] = value
        return value

    def ml(self, kappa) -> float:
        rss, logdet_r, _ = self._parts(kappa)
        return -0.5 * (self.n * np.log(max(rss, 1e-300) / self.n) + logdet_r)

    def _parts(self, kappa):
        if len(kappa) > 1:
            raise ValueError("the projected noise model is of order 0 or 1")
        key = tuple(float(k) for k in kappa)
        hit = self._seen.get(key)
        if hit is not None:  # e.g. the plain likelihood at the REML estimate, an interval's ends
            return hit
        if len(kappa):
            # the propagation, the filter and the whitening in one compiled pass (no gains kept)
            steps, d, nugget = _projected_inputs(self.series, key[0], steps=True)
            w, logdet_r = innovations.whiten_steps(key[0], steps, d, nugget, self.Z)
        else:
            w, logdet_r = self.Z, 0.0
        rss, logdet_g = _rss_g_cholesky(w.T @ w, self.k)
        self._seen[key] = (rss, logdet_r, logdet_g)
        return rss, logdet_r, logdet_g


def _rss_g(M: np.ndarray, k: int) -> tuple[float, float]:
    """From the Gram matrix of whitened ``[Q, r]``: the whitened RSS of ``r`` after the regressors and
    ``log det`` of the regressors' Gram matrix."""
    if not k:
        return float(M[0, 0]), 0.0
    ev, U = np.linalg.eigh(M[:k, :k])
    ev = np.maximum(ev, 1e-300)
    return float(M[k, k] - np.sum((U.T @ M[:k, k]) ** 2 / ev)), float(np.sum(np.log(ev)))


def _rss_g_cholesky(M: np.ndarray, k: int) -> tuple[float, float]:
    """:func:`_rss_g` by the Cholesky factor of the whole Gram matrix (a tenth of the eigendecomposition's
    time): with ``M = L L'``, ``L[k, k]^2`` is the Schur complement of the regressors' block -- the RSS after
    them -- and ``log det`` of that block ``2 sum log L[i, i]``, ``i < k`` (equal to rounding).  Where ``M`` is
    not numerically positive definite (an RSS at round-off), :func:`_rss_g`."""
    if not k:
        return _rss_g(M, k)
    L, info = dpotrf(M, lower=1, clean=0)
    if info != 0:
        return _rss_g(M, k)
    d = np.diag(L)
    return float(d[k] * d[k]), 2.0 * float(np.sum(np.log(d[:k])))


def _restricted_loglik(kappa, r: np.ndarray, Q: np.ndarray, series: Series) -> float:
    """The REML log likelihood computed directly (whitening every column): the reference
    :class:`_Restricted` is tested against."""
    wr = whiten(r, kappa, series)
    n, k = len(series.order), Q.shape[1]
    logdet_r = 0.0
    if len(kappa):
        _, v = levinson(kappa)
        logdet_r = float(np.sum(np.log(v[np.minimum(series.pos, len(kappa))])))
    if k:
        wq = whiten(Q, kappa, series)
        G = wq.T @ wq
        b = wq.T @ wr
        w, U = np.linalg.eigh(G)
        w = np.maximum(w, 1e-300)
        rss = float(wr @ wr - np.sum((U.T @ b) ** 2 / w))
        logdet_g = float(np.sum(np.log(w)))
    else:
        rss, logdet_g = float(wr @ wr), 0.0
    rss = max(rss, 1e-300)
    return -0.5 * ((n - k) * np.log(rss) + logdet_r + logdet_g)


def basis_on(regressors: np.ndarray | None, series: Series, n_obs: int) -> np.ndarray:
    """Orthonormal basis of ``regressors`` (N x k, observation order) on the observations of ``series``
    (zero elsewhere): what :func:`estimate` takes out of the residuals.  Computed once, it can be passed to
    :func:`estimate` as ``basis`` for many residual vectors."""
    inc = series.order
    if regressors is None or not np.size(regressors):
        return np.zeros((n_obs, 0))
    X = np.asarray(regressors, float).reshape(n_obs, -1)
    Qi = orth_basis(X[inc])
    Q = np.zeros((n_obs, Qi.shape[1]))
    Q[inc] = Qi
    return Q


def basis_pair(
    base: np.ndarray, extra: np.ndarray, series: Series, n_obs: int
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`basis_on` of ``base`` and of ``[base, extra]`` in one orthogonalisation: the second's first
    columns are the first (:func:`navlib.workbench.linalg.orth_basis_split`; the same numbers)."""
    inc = series.order
    B = np.asarray(base, float).reshape(n_obs, -1)
    X = np.column_stack([B, np.asarray(extra, float).reshape(n_obs, -1)])
    Qi, r = orth_basis_split(X[inc], B.shape[1])
    Qe = np.zeros((n_obs, Qi.shape[1]))
    Qe[inc] = Qi
    Qb = np.zeros((n_obs, r))
    Qb[inc] = Qi[:, :r]
    return Qb, Qe


def _objective(loglik) -> tuple:
    """What :func:`estimate` minimises over ``a = atanh(kappa)`` (L-BFGS-B): ``fun`` and ``jac`` for
    ``scipy.optimize.minimize``.  With an analytic gradient (:meth:`_Restricted.value_and_gradient`),
    ``-l_R`` and ``-d l_R / d a = -(1 - kappa^2) d l_R / d kappa`` together (``jac=True``); else ``-l_R``
    alone (finite differences)."""
    if not hasattr(loglik, "value_and_gradient"):
        return lambda a: -loglik(np.tanh(a)), None

    def fun(a):
        kappa = np.tanh(a)
        value, grad = loglik.value_and_gradient(kappa)
        return -value, -grad * (1.0 - kappa * kappa)

    return fun, True


def estimate(
    residuals: np.ndarray,
    regressors: np.ndarray,
    series: Series | None,
    max_order: int = MAX_ORDER,
    *,
    order: int | None = None,
    interval: bool = True,
    basis: np.ndarray | None = None,
    prepared: _Prepared | None = None,
    start_at: tuple | None = None,
    cross: tuple | None = None,
) -> NoiseModel:
    """REML estimate of the AR noise model of ``residuals`` given the ``regressors`` a fit took out of
    them (module docstring), the order chosen by AIC over ``0..max_order``, or fixed at ``order``.
    ``interval``: also the profile-likelihood interval of ``kappa_1`` (``bounds``).  No series:
    independent.  ``basis``: :func:`basis_on` of the regressors, if already computed; ``prepared``: its
    residual-free likelihood parts (:class:`_Prepared`), likewise; ``start_at``: with a fixed ``order`` of 2
    or more, optimise that order only, from these partial autocorrelations; ``cross``: the residual's
    cross-products with ``prepared`` (``_Prepared.cross``), computed for many residual vectors at once
    (:func:`select_many`)."""
    return _estimate(
        residuals,
        regressors,
        series,
        max_order,
        order=order,
        interval=interval,
        basis=basis,
        prepared=prepared,
        start_at=start_at,
        cross=cross,
    )[0]


def _estimate(
    residuals: np.ndarray,
    regressors: np.ndarray,
    series: Series | None,
    max_order: int = MAX_ORDER,
    *,
    order: int | None = None,
    interval: bool = True,
    basis: np.ndarray | None = None,
    prepared: _Prepared | None = None,
    start_at: tuple | None = None,
    cross: tuple | None = None,
) -> tuple:
    """:func:`estimate`, and the likelihood it maximised, the lowest ``atanh kappa_1`` it allowed and the
    maximum (for :func:`_interval` later; None, 0 and NaN when nothing was estimated)."""
    r = np.asarray(residuals, float)
    if series is None:
        return NoiseModel((), None, len(r)), None, 0.0, float("nan")
    inc = series.order
    Q = basis_on(regressors, series, len(r)) if basis is None else basis
    if len(inc) - Q.shape[1] < MIN_SAMPLES:
        return (
            NoiseModel((), series, len(r), note="too few samples to estimate a serial correlation"),
            None,
            0.0,
            float("nan"),
        )
    if order is not None:
        max_order = int(order)
    if series.projection is not None:  # the sensor's AR(1), seen through the directions
        max_order = min(max_order, 1)
        loglik = _ProjectedLik(r, Q, series)
    else:
        loglik = _Restricted(r, Q, series, max(max_order, 1), prepared, cross)
    best = ((), loglik(()))
    logliks = [best[1]]
    aic_best = -2 * best[1] if order is None else np.inf
    start = ()
    if order is not None and order >= 2 and start_at is not None:
        # a fixed order from a given start (a bootstrap replicate starts at the data's estimate): that order only
        lim = np.arctanh(KAPPA_MAX)
        x0 = np.arctanh(np.clip(np.asarray(start_at, float)[:order], -KAPPA_MAX, KAPPA_MAX))
        fun, jac = _objective(loglik)
        sol = minimize(
            fun,
            x0,
            jac=jac,
            method="L-BFGS-B",
            bounds=[(-lim, lim)] * order,
            options={"maxiter": 60},
        )
        best = (tuple(float(k) for k in np.tanh(sol.x)), -float(sol.fun))
        logliks.append(best[1])
        max_order = 0  # skip the forward search
    # the lowest kappa_1: -KAPPA_MAX, or 0 for a projected series on an irregular clock
    low = (
        0.0
        if series.projection is not None and not regular_clock(series)
        else -np.arctanh(KAPPA_MAX)
    )
    for p in range(1, max_order + 1):
        if p == 1:
            sol = minimize_scalar(
                lambda a: -loglik((np.tanh(a),)),
                bounds=(low, np.arctanh(KAPPA_MAX)),
                method="bounded",
                options={"xatol": 1e-4},
            )
            kappa, ll = (float(np.tanh(sol.x)),), -float(sol.fun)
        else:
            x0 = np.arctanh(np.clip(np.r_[start, 0.0], -KAPPA_MAX, KAPPA_MAX))
            lim = np.arctanh(KAPPA_MAX)
            fun, jac = _objective(loglik)
            sol = minimize(
                fun,
                x0,
                jac=jac,
                method="L-BFGS-B",
                bounds=[(-lim, lim)] * p,
                options={"maxiter": 60},
            )
            kappa, ll = tuple(float(k) for k in np.tanh(sol.x)), -float(sol.fun)
            ll0 = loglik(np.r_[start, 0.0])
            if ll0 > ll:  # never worse than the previous order
                kappa, ll = tuple(float(k) for k in np.r_[start, 0.0]), ll0
        logliks.append(ll)
        start = kappa
        aic = -2 * ll + 2 * p
        if order is not None:
            best = (kappa, ll)
            continue
        if aic >= aic_best:
            break  # forward selection: stop at the first order that
        best, aic_best = (kappa, ll), aic  # does not lower the AIC
    kappa, ll = best
    bounds = _interval(loglik, kappa, ll, low) if kappa and interval else ()
    return (
        NoiseModel(
            tuple(kappa),
            series,
            len(r),
            tuple(logliks),
            bounds=bounds,
            ml=loglik.ml(kappa),
            regressors=Q.shape[1],
        ),
        loglik,
        low,
        ll,
    )


#: Tolerance on ``atanh kappa_1`` of the profile-likelihood interval's ends (``_interval``).
INTERVAL_XTOL = 1e-6


def _interval(loglik, kappa: tuple, ll: float, low: float) -> tuple:
    """The profile-likelihood interval of ``kappa_1`` (level :data:`KAPPA_LEVEL`) of the estimate ``kappa``
    (log likelihood ``ll``) with the other partial autocorrelations held; ``low`` the lowest ``atanh
    kappa_1`` allowed.

    Each end is the root of ``gap(a) = ll - l(a) - chi2_1(level) / 2`` between the estimate ``a0`` and the
    bound (the bound itself when ``gap`` there is not positive; the bound is not evaluated where a point
    the estimate evaluated on that side already has a positive ``gap``), found by Brent's method in
    ``u = (a - a0)^2``, where a quadratic log likelihood makes ``gap`` linear (the first secant step is then
    exact), to :data:`INTERVAL_XTOL` in ``a``; it starts from the tightest bracket among the points the
    estimate already evaluated (a likelihood's ``values``, where it keeps them), else from the estimate and
    the bound."""
    drop = special.gammaincinv(0.5, KAPPA_LEVEL)  # chi2.ppf(KAPPA_LEVEL, 1) / 2
    lim = np.arctanh(KAPPA_MAX)
    a0 = float(np.arctanh(np.clip(kappa[0], -KAPPA_MAX, KAPPA_MAX)))
    rest = tuple(kappa[1:])

    def gap(a):
        return ll - loglik((np.tanh(a),) + rest) - drop

    # the points evaluated already (the estimate's optimiser), as (a, gap)
    known = [
        (float(np.arctanh(k[0])), ll - v - drop)
        for k, v in getattr(loglik, "values", {}).items()
        if len(k) == len(kappa) and k[1:] == rest and abs(k[0]) < 1.0
    ]
    ends = []
    for edge in (min(low, a0), lim):
        s = 1.0 if edge > a0 else -1.0
        side = [(a, g) for a, g in known if 0 < s * (a - a0) < s * (edge - a0)]
        inside = [p for p in side if p[1] <= 0]
        outside = [p for p in side if p[1] > 0]
        # the bound is evaluated only where no point already evaluated on this side is beyond the drop
        g_edge = None if a0 == edge or outside else gap(edge)
        if a0 == edge or (g_edge is not None and g_edge <= 0):
            ends.append(float(np.tanh(edge)))
            continue
        a_in, g_in = max(inside, key=lambda p: s * p[0]) if inside else (a0, gap(a0))
        a_out, g_out = min(outside, key=lambda p: s * p[0]) if outside else (edge, g_edge)
        if s * (a_out - a_in) <= 0:  # not one crossing: from the estimate and the bound
            g_edge = gap(edge) if g_edge is None else g_edge
            if g_edge <= 0:
                ends.append(float(np.tanh(edge)))
                continue
            (a_in, g_in), (a_out, g_out) = (a0, gap(a0)), (edge, g_edge)
        u_in, u_out = (a_in - a0) ** 2, (a_out - a0) ** 2

        def gap_u(u, u_in=u_in, u_out=u_out, g_in=g_in, g_out=g_out, s=s):
            if u == u_in:
                return g_in
            if u == u_out:
                return g_out
            return gap(a0 + s * np.sqrt(u))

        # du = 2 |a - a0| da: the tolerance in u of INTERVAL_XTOL in a
        xtol = 2.0 * INTERVAL_XTOL * max(np.sqrt(u_in), 1e-3)
        u = brentq(gap_u, u_in, u_out, xtol=xtol)
        ends.append(float(np.tanh(a0 + s * np.sqrt(u))))
    return tuple(ends)


def select(
    residuals: np.ndarray,
    base: np.ndarray,
    extra: np.ndarray | None,
    series: Series | None,
    *,
    order: int | None = None,
    interval: bool = True,
    bases: Bases | None = None,
    start_at: tuple | None = None,
    cross: tuple = (None, None),
) -> NoiseModel:
    """The noise model around the better of two sets of regressors: ``base`` (the model's Jacobian) or
    ``base`` and ``extra`` (the structure shapes).  Each set gets its REML estimate (:func:`estimate`);
    the set with the lower BIC of the plain likelihood (:func:`criterion`) is used.

    Why: slow shapes among the regressors (a trend, offsets per sweep, harmonics of a heading that turns
    with time) soak up the low frequencies where an AR process of high correlation lives, and the
    correlation's estimate becomes loose (on 242 compass readings with AR(1) noise of 0.9, 5-95 % range
    0.73-0.98 with the shapes, 0.79-0.94 without); but a structure outside the model, if present and left
    out, is taken for correlated noise and hidden by it.  The likelihood decides which is the case.
    ``around`` in the result says which set was used; ``bases``: :func:`select_bases` of the regressors,
    if already computed (a bootstrap re-estimates on many residual vectors); ``cross``: the residual's
    cross-products with each set's likelihood parts (:func:`estimate`, :func:`select_many`)."""
    qb, qe, pb, pe = bases if bases is not None else Bases(None, None)
    if bases is None and series is not None and extra is not None and np.size(extra):
        qb, qe = basis_pair(base, extra, series, len(np.asarray(residuals)))
    mb, *lb = _estimate(
        residuals,
        base,
        series,
        order=order,
        interval=False,
        basis=qb,
        prepared=pb,
        start_at=start_at,
        cross=cross[0],
    )

    def chosen(m, fitted, around):
        # the interval of the set chosen only (the other's would be thrown away)
        loglik, low, ll = fitted
        if interval and m.kappa and loglik is not None:
            m = replace(m, bounds=_interval(loglik, m.kappa, ll, low))
        return replace(m, around=around)

    if extra is None or not np.size(extra) or series is None:
        return chosen(mb, lb, "model")
    me, *le = _estimate(
        residuals,
        None if qe is not None else np.column_stack([base, extra]),
        series,
        order=order,
        interval=False,
        basis=qe,
        prepared=pe,
        start_at=start_at,
        cross=cross[1],
    )
    if not np.isfinite(mb.ml) or not np.isfinite(me.ml):
        return chosen(me, le, "model and structure shapes")
    n = len(series.order)
    better = criterion(me.ml, me.regressors + me.order, n) < criterion(
        mb.ml, mb.regressors + mb.order, n
    )
    return chosen(me, le, "model and structure shapes") if better else chosen(mb, lb, "model")


def select_many(
    E: np.ndarray,
    base: np.ndarray,
    extra: np.ndarray | None,
    series: Series,
    bases: Bases,
    *,
    order: int,
    start_at: tuple | None = None,
) -> list[NoiseModel]:
    """:func:`select` (no interval) on each column of ``E`` (residual vectors in observation order: a
    bootstrap's replicates), the columns' cross-products with both regressor sets' likelihood parts
    (``bases`` of that ``order``: :func:`select_bases`) computed in one product per set."""
    Ze = np.asarray(E, float)[series.order]
    parts = [
        pre.cross(Ze) if pre is not None and pre.P >= max(order, 1) else None
        for pre in (bases.prepared_base, bases.prepared_extra)
    ]
    return [
        select(
            E[:, b],
            base,
            extra,
            series,
            order=order,
            interval=False,
            bases=bases,
            start_at=start_at,
            cross=tuple(None if c is None else (c[0][:, :, b], c[1][:, b]) for c in parts),
        )
        for b in range(E.shape[1])
    ]


def criterion(ml, parameters: int, n: int):
    """The information criterion :func:`select` compares: ``-2 l_ML + SELECT_PENALTY(n) * parameters``
    (regressors and AR coefficients)."""
    return -2 * ml + SELECT_PENALTY(n) * parameters


class Bases(NamedTuple):
    """What :func:`select` needs of its two regressor sets, computed once for many residual vectors: the
    orthonormal bases (:func:`basis_on`) of ``base`` and of ``base`` with ``extra`` (None without
    ``extra``), and optionally their likelihood parts for one AR order (:class:`_Prepared`)."""

    base: np.ndarray | None
    extra: np.ndarray | None
    prepared_base: "_Prepared | None" = None
    prepared_extra: "_Prepared | None" = None


def select_bases(
    base: np.ndarray, extra: np.ndarray | None, series: Series, n_obs: int, order: int | None = None
) -> Bases:
    """The :class:`Bases` of :func:`select`'s regressors on ``series``; with ``order``, also their
    likelihood parts for that AR order."""
    if extra is not None and np.size(extra):
        qb, qe = basis_pair(base, extra, series, n_obs)
    else:
        qb, qe = basis_on(base, series, n_obs), None
    if order is None or series.projection is not None:
        return Bases(qb, qe)
    P = max(int(order), 1)
    return Bases(
        qb, qe, _Prepared(qb, series, P), _Prepared(qe, series, P) if qe is not None else None
    )
