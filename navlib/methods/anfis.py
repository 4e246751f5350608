"""ANFIS with Jang's hybrid learning, as MATLAB ``anfis`` (Fuzzy Logic Toolbox) runs it (paper D).

Per epoch ``k``:

1. forward pass: with the premises (Gaussian centres ``c`` and widths ``s``) fixed, the consequents come
   from one global least-squares solve (:func:`navlib.methods.subclust.solve_consequents`);
2. the training error ``E_k`` (RMSE) and, if checking data are given, the checking error are recorded;
   the parameters of the epoch with the lowest checking error (training error without checking data) are
   kept and returned;
3. backward pass: gradient ``g`` of the sum of squared errors with respect to all premise parameters, and a
   normalised step ``p <- p - ss g/||g||``;
4. step-size rule (:func:`update_step`): ``ss <- 1.1 ss`` after four consecutive error decreases
   (``E_{k-4} > E_{k-3} > E_{k-2} > E_{k-1} > E_k``), ``ss <- 0.9 ss`` after two consecutive
   increase-decrease combinations (``E_{k-4} < E_{k-3} > E_{k-2} < E_{k-1} > E_k``); initial ``ss`` 0.01.

Gradients (``w_r`` firing strength, ``S = sum w``, ``f_r`` rule output, ``y`` output, ``e = y - t``)::

    dE/dc_ri = sum_n 2 e (f_r - y)/S w_r (x_i - c_ri)/s_ri^2
    dE/ds_ri = sum_n 2 e (f_r - y)/S w_r (x_i - c_ri)^2/s_ri^3
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_param
from .subclust import SugenoFIS, solve_consequents


@dataclass(frozen=True)
class AnfisOptions:
    """MATLAB ``anfis`` training options: epochs, error goal (RMSE), initial step, step increase and
    decrease rates."""

    epochs: int = 10
    error_goal: float = 0.0
    initial_step: float = 0.01
    step_increase: float = 1.1
    step_decrease: float = 0.9

    def __post_init__(self):
        check_param("epochs", self.epochs, lo=1, hi=100000, integer=True)
        check_param("error_goal", self.error_goal, lo=0)
        check_param("initial_step", self.initial_step, lo=0, lo_open=True)
        check_param("step_increase", self.step_increase, lo=1)
        check_param("step_decrease", self.step_decrease, lo=0, lo_open=True, hi=1)


@dataclass(frozen=True)
class AnfisResult:
    """The trained FIS (best epoch), the per-epoch training and checking RMSE, step sizes, and the best
    epoch (0-based)."""

    fis: SugenoFIS
    train_rmse: np.ndarray
    check_rmse: np.ndarray | None
    step_sizes: np.ndarray
    best_epoch: int
    history: dict = field(default_factory=dict)


def update_step(errors, ss: float, increase: float = 1.1, decrease: float = 0.9) -> float:
    """MATLAB's step-size rule applied after the latest error in ``errors`` (see the module docstring)."""
    e = np.asarray(errors, float)
    if e.size < 5:
        return ss
    w = e[-5:]
    d = np.diff(w)
    if np.all(d < 0):
        return ss * increase
    if d[0] > 0 and d[1] < 0 and d[2] > 0 and d[3] < 0:
        return ss * decrease
    return ss


def premise_gradient(fis: SugenoFIS, X: np.ndarray, t: np.ndarray):
    """Gradient of ``sum (y - t)^2`` with respect to the centres and sigmas, each (R, n)."""
    w = fis.firing(X)
    s = w.sum(axis=1)
    s = np.where(s > 0, s, np.finfo(float).tiny)
    f = X @ fis.consequents[:, :-1].T + fis.consequents[:, -1]
    y = np.sum(w * f, axis=1) / s
    e = y - t
    a = 2.0 * e[:, None] * (f - y[:, None]) / s[:, None] * w  # (N, R)
    dx = X[:, None, :] - fis.centers[None]  # (N, R, n)
    sg = fis.sigmas[None]
    gc = np.einsum("nr,nri->ri", a, dx / sg**2)
    gs = np.einsum("nr,nri->ri", a, dx**2 / sg**3)
    return gc, gs


def _rmse(fis: SugenoFIS, X, t) -> float:
    return float(np.sqrt(np.mean((fis(X) - t) ** 2)))


def anfis(X, t, init: SugenoFIS, options: AnfisOptions = AnfisOptions(), check=None) -> AnfisResult:
    """Hybrid-learning ANFIS training started from ``init`` (e.g. :func:`.genfis2`).

    Parameters
    ----------
    X, t : training inputs (N, n) and targets (N,)
    init : SugenoFIS
        Initial premises (its consequents are recomputed).
    options : AnfisOptions
    check : tuple (Xc, tc), optional
        Checking data; the returned FIS is the one of the epoch with the lowest checking RMSE.

    Returns
    -------
    AnfisResult
    """
    X = np.atleast_2d(np.asarray(X, float))
    t = np.asarray(t, float).ravel()
    if X.shape[1] != init.centers.shape[1] or len(t) != len(X):
        raise InputError(
            f"anfis: inputs {X.shape}, targets {t.shape}, FIS for {init.centers.shape[1]} inputs"
        )
    c, s = init.centers.copy(), init.sigmas.copy()
    ss = options.initial_step
    trn, chk, steps = [], [], []
    best, best_err, best_k = None, np.inf, 0
    for k in range(options.epochs):
        fis = SugenoFIS(c, s, solve_consequents(X, t, c, s))
        trn.append(_rmse(fis, X, t))
        if check is not None:
            chk.append(_rmse(fis, *check))
        crit = chk[-1] if check is not None else trn[-1]
        if crit < best_err:
            best, best_err, best_k = fis, crit, k
        steps.append(ss)
        if trn[-1] <= options.error_goal:
            break
        gc, gs = premise_gradient(fis, X, t)
        norm = np.sqrt(np.sum(gc**2) + np.sum(gs**2))
        if norm > 0:
            c = c - ss * gc / norm
            s = np.maximum(s - ss * gs / norm, 1e-12)
        ss = update_step(trn, ss, options.step_increase, options.step_decrease)
    return AnfisResult(
        best, np.array(trn), np.array(chk) if check is not None else None, np.array(steps), best_k
    )
