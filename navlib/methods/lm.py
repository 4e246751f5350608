"""Levenberg-Marquardt training as MATLAB's ``trainlm`` does it, for many networks at once, and MATLAB's
``dividerand`` split with its validation stop.

MATLAB's default trainer of ``feedforwardnet`` (Neural Network Toolbox, 2015; see
``/work/shared/notes/algorithms.md``).  Each epoch, with ``e`` the errors (output - target, in target
units) and ``J = de/dw`` their Jacobian over the training samples,

    dw = -(J'J + mu I)^-1 J'e                                                          (trainlm step)

is tried; if the training performance (MSE) falls the step is taken and ``mu <- mu mu_dec``, otherwise
``mu <- mu mu_inc`` and the step is re-solved, until a step succeeds or ``mu > mu_max``.  Defaults:
``epochs`` 1000, ``goal`` 0, ``mu`` 0.001, ``mu_dec`` 0.1, ``mu_inc`` 10, ``mu_max`` 1e10, ``min_grad``
1e-7, ``max_fail`` 6.  Training stops (checked before every epoch, in MATLAB's order) at the epoch limit,
when the MSE is at most ``goal``, when ``mu > mu_max``, when the gradient norm ``||2 J'e / N||`` of the
MSE is at most ``min_grad``, or after ``max_fail`` consecutive epochs in which the validation MSE rose
above its best value (validation stop).  With a validation set the weights of the best validation epoch
are returned, as MATLAB does; without one, the final weights.

The implementation is batched: ``S`` networks of ``D`` weights each train together, each with its own
``mu``, masks and stopping state; every step is the same as training that network alone.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError, check_param


@dataclass(frozen=True)
class LMParams:
    """``trainlm`` settings; defaults are MATLAB's (``net.trainParam``)."""

    epochs: int = 1000
    goal: float = 0.0
    mu: float = 1e-3
    mu_dec: float = 0.1
    mu_inc: float = 10.0
    mu_max: float = 1e10
    min_grad: float = 1e-7
    max_fail: int = 6

    def __post_init__(self):
        check_param("epochs", self.epochs, lo=0, integer=True)
        check_param("goal", self.goal, lo=0)
        check_param("mu", self.mu, lo=0, lo_open=True)
        check_param("mu_dec", self.mu_dec, lo=0, lo_open=True, hi=1, hi_open=True)
        check_param("mu_inc", self.mu_inc, lo=1, lo_open=True)
        check_param("mu_max", self.mu_max, lo=self.mu)
        check_param("min_grad", self.min_grad, lo=0)
        check_param("max_fail", self.max_fail, lo=1, integer=True)


@dataclass
class LMResult:
    """Per network: returned weights ``theta (S, D)``, epochs run, the stop reason, the training MSE after
    each epoch (``perf``, row s padded with NaN after the stop; column 0 = the initial weights), the
    validation MSE likewise (``val_perf``, NaN without validation) and the epoch of the returned weights."""

    theta: np.ndarray
    epochs: np.ndarray
    stop: list
    perf: np.ndarray
    val_perf: np.ndarray
    best_epoch: np.ndarray


def dividerand(n: int, rng: np.random.Generator, ratios=(0.7, 0.15, 0.15)):
    """MATLAB's ``dividerand``: a random permutation of ``n`` samples cut into training, validation and
    test indices; ``n_val = round(r_val n)``, ``n_test = round(r_test n)``, the rest trains (121 -> 85, 18,
    18).  Returns three sorted index arrays."""
    check_param("n", n, lo=3, integer=True)
    r = np.asarray(ratios, dtype=float)
    if r.shape != (3,) or np.any(r < 0) or r.sum() <= 0:
        raise InputError(f"parameter ratios={ratios!r}: three non-negative fractions")
    r = r / r.sum()
    n_val, n_test = int(round(r[1] * n)), int(round(r[2] * n))
    perm = rng.permutation(n)
    n_tr = n - n_val - n_test
    return np.sort(perm[:n_tr]), np.sort(perm[n_tr : n_tr + n_val]), np.sort(perm[n_tr + n_val :])


def _solve(a: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``-a^-1 rhs`` per network; a singular system gives a NaN step, which fails the performance test
    and raises mu (MATLAB's backslash warns and goes on the same way)."""
    try:
        return -np.linalg.solve(a, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        out = np.full(rhs.shape, np.nan)
        for i in range(a.shape[0]):
            try:
                out[i] = -np.linalg.solve(a[i], rhs[i])
            except np.linalg.LinAlgError:
                pass
        return out


def _mse(r: np.ndarray, w: np.ndarray) -> np.ndarray:
    return np.einsum("sn,sn->s", w * r, r) / w.sum(axis=1)


def levenberg_marquardt(
    residuals: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    theta0,
    params: LMParams = LMParams(),
    train_mask=None,
    val_mask=None,
) -> LMResult:
    """Train ``S`` networks by ``trainlm`` (module docstring).

    ``residuals(theta (K, D)) -> (K, N)`` gives output - target for every sample; ``jacobian(theta) ->
    (K, N, D)`` its derivative.  ``train_mask``/``val_mask`` (``(S, N)`` or ``(N,)`` booleans) choose each
    network's training and validation samples (default: all samples train, no validation)."""
    theta = np.array(np.atleast_2d(theta0), dtype=float)
    s_count, dim = theta.shape
    r = residuals(theta)
    n = r.shape[1]
    wt = (
        np.ones((s_count, n))
        if train_mask is None
        else np.broadcast_to(np.asarray(train_mask, bool), (s_count, n)).astype(float)
    )
    if np.any(wt.sum(axis=1) == 0):
        raise InputError("levenberg_marquardt: a network has no training samples")
    do_val = val_mask is not None
    wv = np.broadcast_to(np.asarray(val_mask, bool), (s_count, n)).astype(float) if do_val else None
    if do_val and np.any(wv.sum(axis=1) == 0):
        raise InputError("levenberg_marquardt: a network has an empty validation set")
    p = params
    perf = _mse(r, wt)
    vperf = _mse(r, wv) if do_val else np.full(s_count, np.nan)
    hist = np.full((s_count, p.epochs + 1), np.nan)
    vhist = np.full((s_count, p.epochs + 1), np.nan)
    hist[:, 0], vhist[:, 0] = perf, vperf
    best_theta, best_v = theta.copy(), vperf.copy()
    best_epoch = np.zeros(s_count, dtype=int)
    fails = np.zeros(s_count, dtype=int)
    mu = np.full(s_count, float(p.mu))
    epochs = np.zeros(s_count, dtype=int)
    stop = [""] * s_count
    active = np.ones(s_count, dtype=bool)
    eye = np.eye(dim)
    J = jacobian(theta)
    for epoch in range(p.epochs + 1):
        idx = np.flatnonzero(active)
        rows = np.flatnonzero(wt[idx].any(axis=0))  # samples some net trains on
        Ju = J[idx][:, rows] if rows.size < n else J[idx]
        Jt = Ju.transpose(0, 2, 1) * wt[idx][:, None, rows]  # (S, D, N_used), masked
        jj = np.matmul(Jt, Ju)
        je = np.matmul(Jt, r[idx][:, rows, None])[..., 0]
        grad = np.linalg.norm(2.0 * je / wt[idx].sum(axis=1)[:, None], axis=1)
        for k, i in enumerate(idx):  # MATLAB's stopping tests, in its order
            why = (
                "maximum epoch"
                if epoch == p.epochs
                else "performance goal"
                if perf[i] <= p.goal
                else "maximum mu"
                if mu[i] > p.mu_max
                else "minimum gradient"
                if grad[k] <= p.min_grad
                else "validation stop"
                if do_val and fails[i] >= p.max_fail
                else ""
            )
            if why:
                stop[i], active[i] = why, False
        keep = active[idx]
        idx, jj, je = idx[keep], jj[keep], je[keep]
        if idx.size == 0:
            break
        pending = np.ones(idx.size, dtype=bool)
        while pending.any():
            pi = idx[pending]
            step = _solve(jj[pending] + mu[pi, None, None] * eye, je[pending])
            trial = theta[pi] + step
            r2 = residuals(trial)
            perf2 = _mse(r2, wt[pi])
            ok = perf2 < perf[pi]
            good = pi[ok]
            if good.size:
                theta[good], r[good], perf[good] = trial[ok], r2[ok], perf2[ok]
                mu[good] = np.maximum(mu[good] * p.mu_dec, 1e-20)
            bad = pi[~ok]
            mu[bad] *= p.mu_inc
            done = ok | (mu[pi] > p.mu_max)
            pending[np.flatnonzero(pending)[done]] = False
        epochs[idx] = epoch + 1
        hist[idx, epoch + 1] = perf[idx]
        J[idx] = jacobian(theta[idx])
        if do_val:
            vperf[idx] = _mse(r[idx], wv[idx])
            vhist[idx, epoch + 1] = vperf[idx]
            better = vperf[idx] < best_v[idx]
            worse = vperf[idx] > best_v[idx]
            bi = idx[better]
            best_theta[bi], best_v[bi], best_epoch[bi], fails[bi] = (
                theta[bi],
                vperf[bi],
                epoch + 1,
                0,
            )
            fails[idx[worse]] += 1
    if not do_val:
        best_theta, best_epoch = theta, epochs.copy()
    return LMResult(
        theta=best_theta, epochs=epochs, stop=stop, perf=hist, val_perf=vhist, best_epoch=best_epoch
    )
