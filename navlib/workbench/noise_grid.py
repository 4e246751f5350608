"""The AR(1) noise model on a grid of correlations, for many residual vectors at once: the parametric
bootstrap's re-estimates (:mod:`navlib.workbench.bootstrap`) choose each replicate's lag-1 correlation here
instead of maximising :mod:`navlib.workbench.serial`'s likelihood per replicate.

- :func:`ar1_grid`: REML and plain log likelihoods of AR(1) noise on :data:`AR1_GRID`, the same numbers as
  ``serial``'s restricted likelihood at order 1 (tested), vectorised over the residual vectors;
- :func:`projected_grid`: the same for a series with a projection (the reference-free magnetometer's
  noise along the field), one Kalman filter per grid point (:func:`navlib.workbench.serial.projected_gains`);
- :func:`select_ar1_many`: :func:`navlib.workbench.serial.select` at order 1 for every column: the
  correlation under the model's basis or the basis with the structure shapes, whichever the criterion
  prefers.
"""

from __future__ import annotations

import numpy as np

from . import innovations
from .reml import _Prepared
from .serial import KAPPA_MAX, Bases, Series, criterion, projected_gains, regular_clock

#: The grid of lag-1 correlations on which :func:`ar1_grid` evaluates the likelihoods: uniform in
#: ``atanh(kappa)`` over ``+-atanh(KAPPA_MAX)`` (spacing 0.025, so 0.005 in ``kappa`` near 0.9).
AR1_GRID = np.tanh(np.linspace(-np.arctanh(KAPPA_MAX), np.arctanh(KAPPA_MAX), 241))


def ar1_grid(
    E: np.ndarray,
    basis: np.ndarray,
    series: Series,
    grid: np.ndarray = AR1_GRID,
    prepared: _Prepared | None = None,
) -> tuple:
    """REML and plain log likelihoods of AR(1) noise (module docstring) for many residual vectors at once,
    on a grid of correlations: ``E`` (N_obs x B), ``basis`` the regressors' orthonormal basis
    (:func:`~navlib.workbench.serial.basis_on`).  Returns ``(reml, ml)``, each (len(grid) x B).  The same numbers as
    ``serial._Restricted`` at order 1 (tested), vectorised over the residual vectors: the regressors' Gram
    blocks are shared, each grid point costs one Cholesky factor of a k x k matrix, all grid points in one
    batch.  ``prepared``: the
    basis's own blocks (``reml._Prepared`` of order 1), when many calls share the basis."""
    pre = prepared if prepared is not None and prepared.P == 1 else _Prepared(basis, series, 1)
    Ze = np.asarray(E, float)[series.order]
    Cqe, Cee = pre.cross(Ze)
    n, k = pre.n, pre.k
    w, ws, logdet_r = _ar1_weights(pre, np.asarray(grid, float))
    mee = ws @ Cee  # (grid, B)
    if k:
        L = np.linalg.cholesky((ws @ pre.Gq).reshape(len(grid), k, k))
        z = np.linalg.solve(L, np.tensordot(w, Cqe, axes=1))  # L^-1 b: (grid, k, B), one C loop
        rss = mee - np.einsum("gij,gij->gj", z, z)
        logdet_g = 2.0 * np.sum(np.log(np.diagonal(L, axis1=1, axis2=2)), axis=1)
    else:
        rss, logdet_g = mee, np.zeros(len(grid))
    rss = np.maximum(rss, 1e-300)
    reml = -0.5 * ((n - k) * np.log(rss) + logdet_r[:, None] + logdet_g[:, None])
    ml = -0.5 * (n * np.log(rss / n) + logdet_r[:, None])
    return reml, ml


def _ar1_weights(pre: _Prepared, grid: np.ndarray) -> tuple:
    """``_Prepared.weights`` at order 1 (``P = 1``) for every correlation of ``grid`` at once: the
    ordered and unordered pairs' weights (grid x pairs) and ``log det R`` (grid).  Group 0 is whitened
    by ``A_0 = (1, 0)``, the bulk by ``A_1 = (1, -kappa) / sqrt(1 - kappa^2)`` (``levinson`` at order 1)."""
    v1 = 1.0 * (1.0 - grid**2)
    s1 = 1.0 / np.sqrt(v1)
    A = np.zeros((len(grid), 4))  # A[g * 2 + i]
    A[:, 0] = 1.0
    A[:, 2] = s1
    A[:, 3] = -grid * s1
    (oi, oj), (si, sj) = pre._flat
    logdet_r = pre.count[0] * np.log(1.0) + pre.count[1] * np.log(v1)
    return A[:, oi] * A[:, oj], A[:, si] * A[:, sj], logdet_r


def select_ar1_many(
    E: np.ndarray, bases: Bases, series: Series, grid: np.ndarray = AR1_GRID
) -> np.ndarray:
    """:func:`~navlib.workbench.serial.select` at AR order 1 for many residual vectors at once (the columns of ``E``), the
    correlation estimated on :data:`AR1_GRID` (REML maximised over the grid): the chosen lag-1
    correlation of each vector."""
    qb, qe = bases.base, bases.extra
    if series.projection is not None:
        grid = PROJECTED_GRID if regular_clock(series) else PROJECTED_GRID[PROJECTED_GRID >= 0]
        parts = projected_grid(E, [q for q in (qb, qe) if q is not None], series, grid)
        rb, mb = parts[0]
        re_, me = parts[-1]
    else:
        rb, mb = ar1_grid(E, qb, series, grid, bases.prepared_base)
    ib = np.argmax(rb, axis=0)
    cols = np.arange(E.shape[1])
    if qe is None:
        return grid[ib]
    if series.projection is None:
        re_, me = ar1_grid(E, qe, series, grid, bases.prepared_extra)
    ie = np.argmax(re_, axis=0)
    n = len(series.order)
    better = criterion(me[ie, cols], qe.shape[1] + 1, n) < criterion(
        mb[ib, cols], qb.shape[1] + 1, n
    )
    return np.where(better, grid[ie], grid[ib])


#: The grid of lag-1 correlations of the projected model's bootstrap re-estimates (:func:`projected_grid`):
#: every fourth point of :data:`AR1_GRID` (spacing 0.1 in ``atanh(kappa)``, 0.02 in ``kappa`` near 0.9),
#: since each point costs a pass of the filter over every replicate.
PROJECTED_GRID = AR1_GRID[::4]


def projected_grid(
    E: np.ndarray, bases: list, series: Series, grid: np.ndarray = PROJECTED_GRID
) -> list:
    """:func:`ar1_grid` for a series with a :class:`~navlib.workbench.serial.Projection`: for each regressor basis of ``bases``,
    ``(reml, ml)`` (len(grid) x B) of the columns of ``E``; one filter per grid point, shared."""
    Ze = np.asarray(E, float)[series.order]
    Qs = [np.asarray(Q, float)[series.order] for Q in bases]
    n, B = Ze.shape
    out = [(np.empty((len(grid), B)), np.empty((len(grid), B))) for _ in Qs]
    for g, phi in enumerate(grid):
        gains = projected_gains((float(phi),), series)
        logdet_r = gains.logdet
        we = innovations.whiten_columns(gains, Ze)
        ee = np.einsum("ij,ij->j", we, we)
        for (reml, ml), Q in zip(out, Qs):
            k = Q.shape[1]
            if k:
                wq = innovations.whiten_columns(gains, Q)
                ev, U = np.linalg.eigh(wq.T @ wq)
                ev = np.maximum(ev, 1e-300)
                z = (U.T @ (wq.T @ we)) / np.sqrt(ev)[:, None]
                rss = ee - np.einsum("ij,ij->j", z, z)
                logdet_g = float(np.sum(np.log(ev)))
            else:
                rss, logdet_g = ee, 0.0
            rss = np.maximum(rss, 1e-300)
            reml[g] = -0.5 * ((n - k) * np.log(rss) + logdet_r + logdet_g)
            ml[g] = -0.5 * (n * np.log(rss / n) + logdet_r)
    return out
