"""The restricted (REML) log likelihood of the AR noise model of :mod:`navlib.workbench.serial`, fast, and the
Durbin-Levinson recursion it shares with the whitening there.

The likelihood and its notation are those of :mod:`navlib.workbench.serial` (module docstring: the
estimate): ``l_R(kappa) = -1/2 [(N - k) log RSS_W + log det R + log det (X' R^-1 X)]``.  This module does not
import :mod:`~navlib.workbench.serial` (which imports it); a :class:`~navlib.workbench.serial.Series` is used
only through its ``order`` and ``pos``.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dtrtrs


def levinson(kappa) -> tuple[np.ndarray, np.ndarray]:
    """Durbin-Levinson: from partial autocorrelations ``kappa`` (length p) the AR coefficients of every
    order, ``phi[m, 1..m]`` (row m = order m), and the prediction-error variances ``v[m]`` relative to the
    process variance, ``v[m] = prod_{j<=m} (1 - kappa_j^2)``."""
    kappa = np.asarray(kappa, float)
    p = len(kappa)
    phi = np.zeros((p + 1, p + 1))
    v = np.ones(p + 1)
    for m in range(1, p + 1):
        phi[m, m] = kappa[m - 1]
        phi[m, 1:m] = phi[m - 1, 1:m] - kappa[m - 1] * phi[m - 1, m - 1:0:-1]
        v[m] = v[m - 1] * (1.0 - kappa[m - 1] ** 2)
    return phi, v


class _Prepared:
    """The parts of :class:`_Restricted` that depend only on the regressors' basis ``Q`` and the series (not
    on the residual): computed once when many residual vectors share them (a bootstrap)."""

    def __init__(self, Q: np.ndarray, series: "Series", max_order: int):
        Zq = np.asarray(Q, float)[series.order]
        self.k, self.P, self.n = Zq.shape[1], int(max_order), len(Zq)
        self.pos = series.pos
        self.bulk = np.flatnonzero(self.pos >= self.P)
        self.lq = [Zq[self.bulk - i] for i in range(self.P + 1)]
        self.C = [[self.lq[i].T @ self.lq[j] for j in range(self.P + 1)] for i in range(self.P + 1)]
        self.early = np.flatnonzero(self.pos < self.P)
        self.early_pos = self.pos[self.early]
        self.elags = [Zq[self.early]] + [Zq[np.maximum(self.early - j, 0)] for j in range(1, self.P)]


class _Restricted:
    """The REML log likelihood (module docstring) of AR partial autocorrelations for a residual ``r`` with
    regressors of orthonormal basis ``Q``, fast: with ``Z = [Q, r]`` the Gram matrix of the whitened
    columns is ``sum_t w_t w_t'``; for the samples at least ``P = max_order`` into their segment
    ``w_t = sum_j a_j z_(t-j) / sqrt(v_p)`` (``a_0 = 1``, ``a_j = -phi_pj``), so their part is
    ``sum_ij a_i a_j C_ij / v_p`` with the lagged cross-products ``C_ij = sum_t z_(t-i) z_(t-j)'`` computed
    once; the few samples nearer a segment start are whitened directly."""

    def __init__(self, r: np.ndarray, Q: np.ndarray, series: "Series", max_order: int,
                 prepared: "_Prepared | None" = None):
        pre = prepared if prepared is not None and prepared.P >= int(max_order) else \
            _Prepared(Q, series, int(max_order))
        self.k, self.P, self.n = pre.k, pre.P, pre.n
        ro = np.asarray(r, float)[series.order]
        rl = [ro[pre.bulk - i] for i in range(self.P + 1)]
        k = self.k
        self.C = []
        for i in range(self.P + 1):
            row = []
            for j in range(self.P + 1):
                c = np.empty((k + 1, k + 1))
                c[:k, :k] = pre.C[i][j]
                c[:k, k] = pre.lq[i].T @ rl[j]
                c[k, :k] = rl[i] @ pre.lq[j]
                c[k, k] = rl[i] @ rl[j]
                row.append(c)
            self.C.append(row)
        self.early, self.early_pos, self.pos = pre.early, pre.early_pos, pre.pos
        self.lags = [np.column_stack([pre.elags[0], ro[self.early]])] + \
            [np.column_stack([pre.elags[j], ro[np.maximum(self.early - j, 0)]]) for j in range(1, self.P)]

    def __call__(self, kappa) -> float:
        rss, logdet_r, logdet_g = self._parts(kappa)
        return -0.5 * ((self.n - self.k) * np.log(max(rss, 1e-300)) + logdet_r + logdet_g)

    def ml(self, kappa) -> float:
        """The plain (not restricted) log likelihood, the noise variance profiled out and constants common
        to every model of these data dropped: ``-1/2 [N log(RSS_W / N) + log det R]`` -- comparable between
        regressor sets, which the restricted one is not."""
        rss, logdet_r, _ = self._parts(kappa)
        return -0.5 * (self.n * np.log(max(rss, 1e-300) / self.n) + logdet_r)

    def _parts(self, kappa) -> tuple[float, float, float]:
        """``(RSS_W, log det R, log det X' R^-1 X)`` at ``kappa``."""
        p = len(kappa)
        if p > self.P:
            raise ValueError("order above the cache's")
        phi, v = levinson(kappa)
        a = np.r_[1.0, -phi[p, 1:p + 1]] if p else np.ones(1)
        M = sum(a[i] * a[j] * self.C[i][j] for i in range(p + 1) for j in range(p + 1)) / v[p]
        m = np.minimum(self.early_pos, p)
        w = self.lags[0].copy()
        for j in range(1, min(p, self.P - 1) + 1):     # samples near a segment start: their own order
            use = m >= j
            w[use] -= phi[m[use], j][:, None] * self.lags[j][use]
        w /= np.sqrt(v[m])[:, None]
        M = M + w.T @ w
        k = self.k
        logdet_r = float(np.sum(np.log(v[np.minimum(self.pos, p)]))) if p else 0.0
        if k:
            try:                                        # Cholesky: G = M[:k, :k] is positive definite
                L = np.linalg.cholesky(M[:k, :k])
                z = dtrtrs(L, M[:k, k], lower=1)[0]
                rss = float(M[k, k] - z @ z)
                logdet_g = 2.0 * float(np.sum(np.log(np.diag(L))))
            except np.linalg.LinAlgError:               # numerically singular: the eigenvalues, floored
                ev, U = np.linalg.eigh(M[:k, :k])
                ev = np.maximum(ev, 1e-300)
                rss = float(M[k, k] - np.sum((U.T @ M[:k, k]) ** 2 / ev))
                logdet_g = float(np.sum(np.log(ev)))
        else:
            rss, logdet_g = float(M[0, 0]), 0.0
        return rss, logdet_r, logdet_g
