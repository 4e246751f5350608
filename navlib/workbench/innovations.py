"""The projected noise model (:mod:`navlib.workbench.serial`, :class:`~navlib.workbench.serial.Projection`)
as a state-space model: whitening, colouring and ``log det R`` in O(n) time and memory by a Kalman filter,
instead of the Cholesky factor of the n x n correlation matrix.

**The model.**  The sensor's noise ``n(t)`` in R^3 is a stationary AR(1) process of unit variance on each
axis, the axes independent, on a continuous clock ``t`` in sampling steps::

    n(t') = phi n(t) + w,   phi = kappa^(t' - t),   w ~ N(0, (1 - phi^2) I)

(for ``kappa < 0`` only on a regular clock, whole steps ``L``: ``phi = sign(kappa)^L |kappa|^L``).
Observation ``i`` sees it along a direction: ``x_i = d_i . n(t_i) + v_i`` with a measurement nugget
``v_i ~ N(0, delta)``, ``delta = NUGGET mean_i |d_i|^2`` (the diagonal jitter the dense factor added against
round-off, kept so the numbers are those of the dense code).  So
``Cov(x_i, x_j) = kappa^|t_i - t_j| (d_i . d_j) + delta [i = j]`` (:func:`dense_covariance`).

**The filter** (Durbin and Koopman 2012, *Time Series Analysis by State Space Methods*, 2nd ed., sections
4.3 and 6.4: the univariate treatment, one scalar observation at a time).  Observations in time order; the
state's prediction ``a_i`` (3-vector) and its covariance ``P_i`` (3 x 3) start at ``a = 0``, ``P = I``
(the stationary law), and for each observation::

    a_i = phi_i a,   P_i = phi_i^2 P + (1 - phi_i^2) I
                     (phi_i = kappa^(t_i - t_(i-1)); 1 at equal times)
    e_i = x_i - d_i . a_i,   S_i = d_i' P_i d_i + delta,   K_i = P_i d_i / S_i
    a = a_i + K_i e_i,       P = P_i - S_i K_i K_i'

The innovations ``e_i`` are independent with variances ``S_i``: ``e_i / sqrt(S_i)`` is ``L^-1 x`` for the
lower Cholesky factor ``L`` of the covariance in this order (the innovations algorithm: Brockwell and
Davis 1991, *Time Series: Theory and Methods*, section 5.2; ``L_ii = sqrt(S_i)``), so
``log det R = sum_i log S_i``, and colouring -- ``L u`` -- runs the same recursion with
``x_i = d_i . a_i + sqrt(S_i) u_i``.  ``phi``, ``K`` and ``S`` depend on ``kappa`` and the series only, not on
the data (:func:`gains`, computed once); :func:`whiten_columns` and :func:`colour_columns` apply them to any
number of columns at once (regressors, bootstrap draws).  Cost: O(n) per column, O(n) memory.

The kernels are compiled with numba (``cache=True``, no fast-math: the conventions of
:mod:`navlib.methods.jit`); each kernel's plain-Python ``py_func`` is its reference, and
:func:`dense_covariance` the model's (tests).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

#: The measurement nugget relative to the mean observation variance ``mean |d_i|^2`` (round-off only; the
#: dense Cholesky factor's diagonal jitter).
NUGGET = 1e-10


@dataclass(frozen=True)
class Gains:
    """The filter of one ``(kappa, series)`` (module docstring), in filter (time) order: ``phi`` the state's
    propagation before each observation, ``d`` the directions, ``gain`` the Kalman gains ``K_i`` (n, 3),
    ``sd`` the innovations' standard deviations ``sqrt(S_i)``."""

    phi: np.ndarray
    d: np.ndarray
    gain: np.ndarray
    sd: np.ndarray

    @property
    def logdet(self) -> float:
        """``log det R = sum_i log S_i``."""
        return 2.0 * float(np.sum(np.log(self.sd)))


def propagation(kappa: float, clock: np.ndarray) -> np.ndarray:
    """``phi_i = kappa^(t_i - t_(i-1))`` for a clock in time order (``phi_0 = 1``: the first observation
    starts from the stationary law); a negative ``kappa`` on whole steps ``L``: ``sign^L |kappa|^L``."""
    k = float(kappa)
    dt = np.diff(np.asarray(clock, float), prepend=clock[0] if len(clock) else 0.0)
    if np.any(dt < 0):
        raise ValueError(
            "a projected series must be in time order (serial.with_projection orders it)"
        )
    phi = np.abs(k) ** dt
    if k < 0:
        phi = phi * np.where(np.round(dt) % 2 == 1, -1.0, 1.0)
    return phi


def nugget_of(d: np.ndarray) -> float:
    """The measurement nugget of directions ``d`` (:data:`NUGGET` times the mean ``|d_i|^2``)."""
    return NUGGET * float(np.mean(np.sum(d * d, axis=1))) if len(d) else 0.0


def gains(kappa: float, clock: np.ndarray, d: np.ndarray, nugget: float | None = None) -> Gains:
    """The :class:`Gains` of AR(1) axis noise of lag-1 correlation ``kappa`` seen along directions ``d``
    ((n, 3)) at times ``clock`` (in time order); ``nugget``: :func:`nugget_of` ``d``, if already known."""
    d = np.ascontiguousarray(d, float)
    phi = propagation(kappa, clock)
    nugget = nugget_of(d) if nugget is None else nugget
    gain, sd = _gains(phi, d, nugget)
    return Gains(phi, d, gain, sd)


@njit(error_model="numpy", cache=True)
def _gains(phi, d, nugget):
    """The filter's covariance recursion (module docstring): ``K_i`` and ``sqrt(S_i)``."""
    n = len(phi)
    gain = np.empty((n, 3))
    sd = np.empty(n)
    P = np.eye(3)
    pd = np.empty(3)
    for i in range(n):
        f2 = phi[i] * phi[i]
        for r in range(3):
            for c in range(3):
                P[r, c] *= f2
            P[r, r] += 1.0 - f2
        for r in range(3):
            pd[r] = P[r, 0] * d[i, 0] + P[r, 1] * d[i, 1] + P[r, 2] * d[i, 2]
        s = d[i, 0] * pd[0] + d[i, 1] * pd[1] + d[i, 2] * pd[2] + nugget
        for r in range(3):
            gain[i, r] = pd[r] / s
        for r in range(3):
            for c in range(3):
                P[r, c] -= pd[r] * pd[c] / s
        sd[i] = np.sqrt(s)
    return gain, sd


@njit(error_model="numpy", cache=True)
def _whiten(phi, d, gain, sd, x):
    """``e_i / sqrt(S_i)`` of every column of ``x`` (n, B), filter order."""
    n, B = x.shape
    out = np.empty((n, B))
    a = np.zeros((3, B))
    for i in range(n):
        f = phi[i]
        d0, d1, d2 = d[i, 0], d[i, 1], d[i, 2]
        k0, k1, k2 = gain[i, 0], gain[i, 1], gain[i, 2]
        s = sd[i]
        for b in range(B):
            a0 = f * a[0, b]
            a1 = f * a[1, b]
            a2 = f * a[2, b]
            e = x[i, b] - (d0 * a0 + d1 * a1 + d2 * a2)
            out[i, b] = e / s
            a[0, b] = a0 + k0 * e
            a[1, b] = a1 + k1 * e
            a[2, b] = a2 + k2 * e
    return out


@njit(error_model="numpy", cache=True)
def _colour(phi, d, gain, sd, u):
    """The inverse of :func:`_whiten`: ``x_i = d_i . a_i + sqrt(S_i) u_i`` for every column of ``u``."""
    n, B = u.shape
    out = np.empty((n, B))
    a = np.zeros((3, B))
    for i in range(n):
        f = phi[i]
        d0, d1, d2 = d[i, 0], d[i, 1], d[i, 2]
        k0, k1, k2 = gain[i, 0], gain[i, 1], gain[i, 2]
        s = sd[i]
        for b in range(B):
            a0 = f * a[0, b]
            a1 = f * a[1, b]
            a2 = f * a[2, b]
            e = s * u[i, b]
            out[i, b] = (d0 * a0 + d1 * a1 + d2 * a2) + e
            a[0, b] = a0 + k0 * e
            a[1, b] = a1 + k1 * e
            a[2, b] = a2 + k2 * e
    return out


def clock_steps(clock: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The clock's steps ``t_i - t_(i-1)`` (``0`` first) and whether each is an odd number of whole steps
    (a negative ``kappa``'s sign: :func:`propagation`), for :func:`whiten_steps`: computed once per series
    for a likelihood evaluated at many ``kappa``."""
    clock = np.asarray(clock, float)
    dt = np.diff(clock, prepend=clock[0] if len(clock) else 0.0)
    if np.any(dt < 0):
        raise ValueError(
            "a projected series must be in time order (serial.with_projection orders it)"
        )
    return dt, np.round(dt) % 2 == 1


@njit(error_model="numpy", cache=True)
def _filter_whiten_steps(kappa, dt, odd, d, nugget, x):
    """:func:`propagation`, :func:`_gains` and :func:`_whiten` in one compiled pass: ``phi_i`` from ``kappa`` and the
    steps ``dt`` (``odd``: an odd number of whole steps) as :func:`propagation` computes it, ``|kappa|^dt``
    evaluated once per run of equal steps (1 at a step of 0), then the filter and the whitening."""
    n, B = x.shape
    out = np.empty((n, B))
    sd = np.empty(n)
    a = np.zeros((3, B))
    P = np.eye(3)
    pd = np.empty(3)
    k = np.empty(3)
    ak = abs(kappa)
    last_dt = 0.0
    last_phi = 1.0
    for i in range(n):
        t = dt[i]
        if t == 0.0:
            f = 1.0
        else:
            if t != last_dt:
                last_phi = ak**t
                last_dt = t
            f = last_phi
            if kappa < 0 and odd[i]:
                f = -f
        f2 = f * f
        for r in range(3):
            for c in range(3):
                P[r, c] *= f2
            P[r, r] += 1.0 - f2
        d0, d1, d2 = d[i, 0], d[i, 1], d[i, 2]
        for r in range(3):
            pd[r] = P[r, 0] * d0 + P[r, 1] * d1 + P[r, 2] * d2
        S = d0 * pd[0] + d1 * pd[1] + d2 * pd[2] + nugget
        for r in range(3):
            k[r] = pd[r] / S
        for r in range(3):
            for c in range(3):
                P[r, c] -= pd[r] * pd[c] / S
        s = np.sqrt(S)
        sd[i] = s
        for b in range(B):
            a0 = f * a[0, b]
            a1 = f * a[1, b]
            a2 = f * a[2, b]
            e = x[i, b] - (d0 * a0 + d1 * a1 + d2 * a2)
            out[i, b] = e / s
            a[0, b] = a0 + k[0] * e
            a[1, b] = a1 + k[1] * e
            a[2, b] = a2 + k[2] * e
    return out, sd


def whiten_steps(
    kappa: float, steps: tuple, d: np.ndarray, nugget: float, x: np.ndarray
) -> tuple[np.ndarray, float]:
    """:func:`whiten_direct` from the clock's :func:`clock_steps` ``steps`` (computed once), the
    propagation inside the compiled pass: ``(L^-1 x, log det R)`` for ``x`` (n, B), C-contiguous, in
    filter order."""
    dt, odd = steps
    out, sd = _filter_whiten_steps(float(kappa), dt, odd, d, nugget, x)
    return out, 2.0 * float(np.sum(np.log(sd)))


def whiten_direct(kappa: float, clock: np.ndarray, d: np.ndarray, nugget: float, x: np.ndarray):
    """``(L^-1 x, log det R)`` for ``x`` (n, B) in filter order without keeping the gains
    (:func:`whiten_steps` from the clock): what a likelihood evaluated at many ``kappa`` needs."""
    return whiten_steps(kappa, clock_steps(clock), d, nugget, np.ascontiguousarray(x, float))


def _columns(kernel, g: Gains, x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, float)
    out = kernel(g.phi, g.d, g.gain, g.sd, np.ascontiguousarray(x.reshape(len(x), -1)))
    return out.reshape(x.shape)


def whiten_columns(g: Gains, x: np.ndarray) -> np.ndarray:
    """``L^-1 x`` for ``x`` (n,) or (n, B) in filter order."""
    return _columns(_whiten, g, x)


def colour_columns(g: Gains, u: np.ndarray) -> np.ndarray:
    """``L u`` for ``u`` (n,) or (n, B) in filter order."""
    return _columns(_colour, g, u)


def dense_covariance(kappa: float, clock: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The model's covariance (module docstring) as a dense n x n matrix, nugget included: the reference the
    filter is tested against (O(n^2) memory; not for use on data)."""
    t = np.asarray(clock, float)
    d = np.asarray(d, float)
    lag = np.abs(t[:, None] - t[None, :])
    k = float(kappa)
    rho = np.abs(k) ** lag
    if k < 0:
        rho = rho * np.where(np.round(lag) % 2 == 1, -1.0, 1.0)
    K = rho * (d @ d.T)
    K[np.diag_indices_from(K)] += NUGGET * np.mean(np.diag(d @ d.T))
    return K
