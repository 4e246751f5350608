"""The restricted (REML) log likelihood of the AR noise model of :mod:`navlib.workbench.serial`, fast, with its
analytic gradient, and the Durbin-Levinson recursion (and its derivatives) it shares with the whitening there.

The likelihood and its notation are those of :mod:`navlib.workbench.serial` (module docstring: the
estimate): ``l_R(kappa) = -1/2 [(N - k) log RSS_W + log det R + log det (X' R^-1 X)]``.  Every Gram matrix
of whitened columns is a weighted sum of lagged cross-products of the columns, computed once
(:class:`_Prepared`); the weights, and their derivatives, come from the Durbin-Levinson coefficients
(``_Prepared.weights``), so an evaluation of ``l_R`` and its gradient costs a few small products
(:class:`_Restricted`), whatever the length of the series.  This module does not import
:mod:`~navlib.workbench.serial` (which imports it); the ``series``
argument (a :class:`~navlib.workbench.serial.Series`) is used only through its ``order`` and ``pos``.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.linalg.lapack import dpotrf, dtrtri, dtrtrs


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
        phi[m, 1:m] = phi[m - 1, 1:m] - kappa[m - 1] * phi[m - 1, m - 1 : 0 : -1]
        v[m] = v[m - 1] * (1.0 - kappa[m - 1] ** 2)
    return phi, v


@njit(error_model="numpy", cache=True)
def ar_colour(u, phi, v, starts):
    """The AR process on segments from independent unit samples: for rows ``t`` of each segment
    ``starts[s] .. starts[s + 1] - 1`` (``k = t - starts[s]`` samples into it, order ``m = min(k, p)``)::

        x_t = sum_(j=1..m) phi[m, j] x_(t-j) + sqrt(v[m]) u_t

    with ``phi``, ``v`` from :func:`levinson` (p = ``len(v) - 1``): the first samples of a segment by the
    Durbin-Levinson coefficients of their own order (exactly the stationary law), the rest by the order-p
    recursion.  ``u`` is (N, B): every column coloured alike.  Compiled (numba, no fast-math); its
    ``py_func`` and ``scipy.signal.lfilter`` on the same recursion are its references (tests)."""
    n, b = u.shape
    p = len(v) - 1
    x = np.empty((n, b))
    for s in range(len(starts) - 1):
        a0 = starts[s]
        for t in range(a0, starts[s + 1]):
            m = min(t - a0, p)
            sd = np.sqrt(v[m])
            for c in range(b):
                acc = sd * u[t, c]
                for j in range(1, m + 1):
                    acc += phi[m, j] * x[t - j, c]
                x[t, c] = acc
    return x


def levinson_derivatives(kappa) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`levinson` and its derivatives with respect to each partial autocorrelation (forward mode):
    ``(phi, v, dphi, dv)`` with ``dphi[l, m, j] = d phi[m, j] / d kappa_l`` and ``dv[l, m] = d v[m] / d kappa_l``,
    from the recursion differentiated::

        d phi[m, m]   = [l = m]
        d phi[m, 1:m] = d phi[m-1, 1:m] - kappa_m d phi[m-1, m-1:0:-1]
                        - [l = m] phi[m-1, m-1:0:-1]
        d v[m]        = (1 - kappa_m^2) d v[m-1] - [l = m] 2 kappa_m v[m-1]
    """
    kappa = [float(k) for k in kappa]  # plain floats: p is a few, numpy calls cost more
    p = len(kappa)
    phi = [[0.0] * (p + 1) for _ in range(p + 1)]
    v = [1.0] * (p + 1)
    dphi = [[[0.0] * (p + 1) for _ in range(p + 1)] for _ in range(p)]
    dv = [[0.0] * (p + 1) for _ in range(p)]
    for m in range(1, p + 1):
        km = kappa[m - 1]
        for j in range(1, m):
            phi[m][j] = phi[m - 1][j] - km * phi[m - 1][m - j]
            for d in dphi:
                d[m][j] = d[m - 1][j] - km * d[m - 1][m - j]
            dphi[m - 1][m][j] -= phi[m - 1][m - j]
        phi[m][m] = km
        dphi[m - 1][m][m] = 1.0
        v[m] = v[m - 1] * (1.0 - km**2)
        for d in dv:
            d[m] = d[m - 1] * (1.0 - km**2)
        dv[m - 1][m] -= 2.0 * km * v[m - 1]
    dphi, dv = np.array(dphi).reshape(p, p + 1, p + 1), np.array(dv).reshape(p, p + 1)
    phi, v = np.array(phi), np.array(v)
    return phi, v, dphi, dv


@njit(error_model="numpy", cache=True)
def _restricted_parts(kappa, P, count, oi, oj, si, sj, Gq, Cqr, Crr, k, gradient):
    """``_Restricted``'s likelihood parts at ``kappa`` in one compiled call: ``(rss, logdet_r, logdet_g)``
    and, with ``gradient``, their derivatives ``(drss, dlogdet_r, dlogdet_g)`` with respect to each
    ``kappa_l`` -- the formulas of ``_Prepared.weights`` (with :func:`levinson_derivatives`) and
    ``_Restricted.value_and_gradient`` (docstrings there), written as loops over the few pairs and
    regressors.  ``G`` is factored by its own Cholesky loop; a non-positive pivot (``G`` numerically
    singular) falls back to its eigenvalues, floored at 1e-300, as the numpy code does.  The numpy code
    is its reference (tests)."""
    p = kappa.shape[0]
    phi = np.zeros((p + 1, p + 1))
    v = np.ones(p + 1)
    dphi = np.zeros((p, p + 1, p + 1))
    dv = np.zeros((p, p + 1))
    for m in range(1, p + 1):
        km = kappa[m - 1]
        for j in range(1, m):
            phi[m, j] = phi[m - 1, j] - km * phi[m - 1, m - j]
            for q_ in range(p):
                dphi[q_, m, j] = dphi[q_, m - 1, j] - km * dphi[q_, m - 1, m - j]
            dphi[m - 1, m, j] -= phi[m - 1, m - j]
        phi[m, m] = km
        dphi[m - 1, m, m] = 1.0
        v[m] = v[m - 1] * (1.0 - km**2)
        for q_ in range(p):
            dv[q_, m] = dv[q_, m - 1] * (1.0 - km**2)
        dv[m - 1, m] -= 2.0 * km * v[m - 1]
    width = P + 1
    A = np.zeros(width * width)
    dA = np.zeros((p, width * width))
    logdet_r = 0.0
    dlogdet_r = np.zeros(p)
    for g in range(width):
        mg = min(g, p)
        vm = v[mg]
        scale = 1.0 / np.sqrt(vm)
        logdet_r += count[g] * np.log(vm)
        A[g * width] = scale
        for i in range(1, p + 1):
            A[g * width + i] = -phi[mg, i] * scale
        if gradient:
            for q_ in range(p):
                rel = dv[q_, mg] / vm
                dlogdet_r[q_] += rel * count[g]
                for i in range(width):
                    d = -dphi[q_, mg, i] * scale if 1 <= i <= p else 0.0
                    dA[q_, g * width + i] = d - 0.5 * rel * A[g * width + i]
    no, ns = oi.shape[0], si.shape[0]
    w = np.empty(no)
    ws = np.empty(ns)
    for o in range(no):
        w[o] = A[oi[o]] * A[oj[o]]
    for t in range(ns):
        ws[t] = A[si[t]] * A[sj[t]]
    c = 0.0
    for t in range(ns):
        c += ws[t] * Crr[t]
    drss = np.zeros(p)
    dlogdet_g = np.zeros(p)
    if gradient:
        dw = np.empty((p, no))
        dws = np.empty((p, ns))
        for q_ in range(p):
            for o in range(no):
                dw[q_, o] = dA[q_, oi[o]] * A[oj[o]] + A[oi[o]] * dA[q_, oj[o]]
            for t in range(ns):
                dws[q_, t] = dA[q_, si[t]] * A[sj[t]] + A[si[t]] * dA[q_, sj[t]]
                drss[q_] += dws[q_, t] * Crr[t]
    if k == 0:
        return c, logdet_r, 0.0, drss, dlogdet_r, dlogdet_g
    G = np.dot(ws, Gq).reshape(k, k)  # BLAS, as the numpy code
    b = np.dot(w, Cqr)
    L = np.zeros((k, k))
    ok = True
    for j in range(k):
        d = G[j, j]
        for q in range(j):
            d -= L[j, q] * L[j, q]
        if not d > 0.0:
            ok = False
            break
        L[j, j] = np.sqrt(d)
        for i in range(j + 1, k):
            e = G[i, j]
            for q in range(j):
                e -= L[i, q] * L[j, q]
            L[i, j] = e / L[j, j]
    Gi = np.zeros((k, k))
    logdet_g = 0.0
    if ok:  # Gi = L'^-1 L^-1 from the inverse of the triangular factor
        Li = np.zeros((k, k))
        for j in range(k):
            Li[j, j] = 1.0 / L[j, j]
            for i in range(j + 1, k):
                e = 0.0
                for q in range(j, i):
                    e -= L[i, q] * Li[q, j]
                Li[i, j] = e / L[i, i]
            logdet_g += 2.0 * np.log(L[j, j])
        for a in range(k):
            for bb in range(k):
                e = 0.0
                for q in range(max(a, bb), k):
                    e += Li[q, a] * Li[q, bb]
                Gi[a, bb] = e
    else:  # numerically singular: the eigenvalues, floored
        ev, U = np.linalg.eigh(G)
        for q in range(k):
            e = max(ev[q], 1e-300)
            logdet_g += np.log(e)
            for a in range(k):
                for bb in range(k):
                    Gi[a, bb] += U[a, q] * U[bb, q] / e
    y = np.dot(Gi, b)
    rss = c
    for a in range(k):
        rss -= b[a] * y[a]
    if gradient:
        # y' Gq_s y and tr(G^-1 Gq_s) of every pair in one product (BLAS)
        M = np.empty((k * k, 2))
        for a in range(k):
            for bb in range(k):
                M[a * k + bb, 0] = y[a] * y[bb]
                M[a * k + bb, 1] = Gi[a, bb]
        H = np.dot(Gq, M)
        cy = np.dot(Cqr, y)
        for q_ in range(p):
            for t in range(ns):
                drss[q_] += dws[q_, t] * H[t, 0]
                dlogdet_g[q_] += dws[q_, t] * H[t, 1]
            for o in range(no):
                drss[q_] -= 2.0 * dw[q_, o] * cy[o]
    return rss, logdet_r, logdet_g, drss, dlogdet_r, dlogdet_g


class _Prepared:
    """The parts of :class:`_Restricted` that depend only on the regressors' basis ``Q`` and the series (not
    on the residual): computed once when many residual vectors share them (a bootstrap).

    The samples fall into ``P + 1`` *groups* by their place in their segment: group ``g < P`` holds the
    samples ``g`` into their segment, group ``P`` (the bulk) those ``P`` or more in.  At any order
    ``p <= P`` every sample of a group is whitened with the same coefficients (order ``m_g = min(g, p)``;
    :class:`_Restricted`) from its own and its ``g`` (bulk: ``P``) previous samples, so the Gram matrix of
    the whitened columns needs only each group's lagged cross-products
    ``C_gij = sum_(t in g) z_(t-i) z_(t-j)'`` (``i, j <= min(g, P)``).  Here those of ``Q``, as the sums
    ``Gq_s = C_gij + C_gji`` (``C_gii`` when ``i = j``) over the unordered pairs ``s = (g, i <= j)``; ``Q``
    need not be orthonormal for them (the bootstrap's tests use them for any columns:
    :class:`navlib.workbench.bootstrap.Family`)."""

    def __init__(self, Q: np.ndarray, series, max_order: int):
        Zq = np.asarray(Q, float)[series.order]
        self.k, self.P, self.n = Zq.shape[1], int(max_order), len(Zq)
        P, k = self.P, self.k
        self.pos = series.pos
        group = np.minimum(self.pos, P)
        #: samples per group
        self.count = np.bincount(group, minlength=P + 1)
        #: each group's lagged samples: ``idx[g][j]`` = the group's samples, j steps back (in their segment)
        self.idx = [
            np.flatnonzero(group == g)[None, :] - np.arange(g + 1)[:, None] for g in range(P + 1)
        ]
        #: the regressors' lags: ``lag_q[g][j]`` = ``Q[idx[g][j]]`` (n_g, k)
        self.lag_q = [Zq[ix] for ix in self.idx]
        #: ordered pairs ``(g, i, j)`` and unordered ones (``i <= j``), group by group
        self.pairs = np.array(
            [(g, i, j) for g in range(P + 1) for i in range(g + 1) for j in range(g + 1)]
        )
        self.sym = self.pairs[self.pairs[:, 1] <= self.pairs[:, 2]]
        self._flat = [
            (x[:, 0] * (P + 1) + x[:, 1], x[:, 0] * (P + 1) + x[:, 2])
            for x in (self.pairs, self.sym)
        ]
        #: the same indices as contiguous int64 arrays, for the compiled likelihood
        self.flat_arrays = tuple(
            np.ascontiguousarray(a, dtype=np.int64) for pair in self._flat for a in pair
        )
        Gq = np.empty((len(self.sym), k, k))
        for s, (g, i, j) in enumerate(self.sym):
            c = self.lag_q[g][i].T @ self.lag_q[g][j]
            Gq[s] = c if i == j else c + c.T
        #: ``Gq_s`` flattened, (pairs, k * k)
        self.Gq = Gq.reshape(len(self.sym), k * k)

    def cross(self, Ze: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The residual-dependent cross-products of columns ``Ze`` (n, B; series order): ``Cqr`` (ordered
        pairs, k, B), ``sum_(t in g) q_(t-i) e_(t-j)``, and ``Crr`` (unordered pairs, B),
        ``sum_(t in g) e_(t-i) e_(t-j)`` doubled when ``i < j``."""
        Cqr, Crr = [], []
        B, k = Ze.shape[1], self.k
        for g, ix in enumerate(self.idx):
            R = Ze[ix]  # (g + 1, n_g, B): the group's lags
            # one product per regressors' lag i for every (j, b): the residuals' lags side by side
            Rj = R.transpose(1, 0, 2).reshape(ix.shape[1], (g + 1) * B)
            C = np.stack([lag.T @ Rj for lag in self.lag_q[g]])  # (i, q, (j, b))
            Cqr.append(
                C.reshape(g + 1, k, g + 1, B).transpose(0, 2, 1, 3).reshape((g + 1) ** 2, k, B)
            )
            i, j = np.triu_indices(g + 1)
            Crr.append(np.where((i < j)[:, None], 2.0, 1.0) * np.einsum("snb,snb->sb", R[i], R[j]))
        return np.concatenate(Cqr), np.concatenate(Crr)

    def weights(self, kappa, gradient: bool = False) -> tuple:
        """At partial autocorrelations ``kappa`` (order ``p <= P``): the weights of the ordered and unordered
        pairs, ``A_gi A_gj`` with ``A_g = (1, -phi_(m_g, 1..m_g), 0, ...) / sqrt(v_(m_g))``, ``m_g = min(g, p)``
        (the whitening of group ``g``), and ``log det R = sum_g n_g log v_(m_g)``.  ``gradient``: also their
        derivatives with respect to each ``kappa_l`` (rows; :func:`levinson_derivatives`), from
        ``d A_gi = -d phi_(m_g, i) / sqrt(v_(m_g)) - A_gi d v_(m_g) / (2 v_(m_g))`` and
        ``d (A_gi A_gj) = d A_gi A_gj + A_gi d A_gj``."""
        p = len(kappa)
        if p > self.P:
            raise ValueError("order above the cache's")
        phi, v, dphi, dv = (
            levinson_derivatives(kappa) if gradient else levinson(kappa) + (None, None)
        )
        m = np.minimum(np.arange(self.P + 1), p)
        vm = v[m]
        scale = 1.0 / np.sqrt(vm)
        A = np.zeros((self.P + 1, self.P + 1))
        A[:, 0] = 1.0
        A[:, 1 : p + 1] = -phi[m, 1:]
        A *= scale[:, None]
        A = A.ravel()  # A[g * (P + 1) + i]: the pairs' flat indices
        (oi, oj), (si, sj) = self._flat
        out = (A[oi] * A[oj], A[si] * A[sj], float(self.count @ np.log(vm)))
        if not gradient:
            return out
        rel = dv[:, m] / vm  # d log v_(m_g) / d kappa_l: (p, P + 1)
        dA = np.zeros((p, self.P + 1, self.P + 1))
        dA[:, :, 1 : p + 1] = -dphi[:, m, 1:] * scale[None, :, None]
        dA = dA.reshape(p, A.size) - 0.5 * np.repeat(rel, self.P + 1, axis=1) * A
        dw = dA[:, oi] * A[oj] + A[oi] * dA[:, oj]
        dws = dA[:, si] * A[sj] + A[si] * dA[:, sj]
        return out + (dw, dws, rel @ self.count)


class _Restricted:
    """The REML log likelihood (module docstring) of AR partial autocorrelations for a residual ``r`` with
    regressors of orthonormal basis ``Q``, fast: with ``Z = [Q, r]`` the Gram matrix of the whitened
    columns is ``M = sum_t w_t w_t'``; a sample of group ``g`` (:class:`_Prepared`) is whitened as
    ``w_t = sum_j a_j z_(t-j) / sqrt(v_m)`` (order ``m = min(g, p)``, ``a_0 = 1``, ``a_j = -phi_mj``), so::

        M = sum_g sum_ij A_gi A_gj C_gij,   A_gj = a_j / sqrt(v_m),
        C_gij = sum_(t in g) z_(t-i) z_(t-j)'

    with the lagged cross-products ``C_gij`` computed once; then ``G = M_QQ`` (``X' R^-1 X`` for
    orthonormal ``X``), ``b = M_Qr``, ``RSS_W = M_rr - b' G^-1 b`` (Cholesky factor of ``G``)."""

    def __init__(
        self,
        r: np.ndarray,
        Q: np.ndarray,
        series,
        max_order: int,
        prepared: "_Prepared | None" = None,
        cross: tuple | None = None,
    ):
        """``cross``: ``r``'s cross-products ``(Cqr, Crr)`` with ``prepared`` (``_Prepared.cross`` of one
        column), when computed for many residual vectors at once."""
        usable = prepared is not None and prepared.P >= int(max_order)
        pre = prepared if usable else _Prepared(Q, series, int(max_order))
        self.pre = pre
        self.k, self.P, self.n = pre.k, pre.P, pre.n
        if cross is None or not usable:
            Cqr, Crr = pre.cross(np.asarray(r, float)[series.order][:, None])
            cross = (Cqr[:, :, 0], Crr[:, 0])
        self.Cqr, self.Crr = (np.ascontiguousarray(x, dtype=float) for x in cross)

    def __call__(self, kappa) -> float:
        rss, logdet_r, logdet_g = self._parts(kappa)
        return -0.5 * ((self.n - self.k) * np.log(max(rss, 1e-300)) + logdet_r + logdet_g)

    def ml(self, kappa) -> float:
        """The plain (not restricted) log likelihood, the noise variance profiled out and constants common
        to every model of these data dropped: ``-1/2 [N log(RSS_W / N) + log det R]`` -- comparable between
        regressor sets, which the restricted one is not."""
        rss, logdet_r, _ = self._parts(kappa)
        return -0.5 * (self.n * np.log(max(rss, 1e-300) / self.n) + logdet_r)

    def value_and_gradient(self, kappa) -> tuple[float, np.ndarray]:
        """``l_R`` and its gradient with respect to ``kappa`` (:meth:`_value_and_gradient_numpy`), by the
        compiled ``_restricted_parts``."""
        rss, logdet_r, logdet_g, drss, dlogdet_r, dlogdet_g = self._compiled(kappa, True)
        if rss <= 1e-300:
            rss, drss = 1e-300, 0.0 * drss
        value = -0.5 * ((self.n - self.k) * np.log(rss) + logdet_r + logdet_g)
        return value, -0.5 * ((self.n - self.k) * drss / rss + dlogdet_r + dlogdet_g)

    def _compiled(self, kappa, gradient: bool) -> tuple:
        pre = self.pre
        return _restricted_parts(
            np.asarray(kappa, dtype=float).reshape(-1),
            pre.P,
            pre.count,
            *pre.flat_arrays,
            pre.Gq,
            self.Cqr,
            self.Crr,
            self.k,
            gradient,
        )

    def _value_and_gradient_numpy(self, kappa) -> tuple[float, np.ndarray]:
        """``l_R`` and its gradient with respect to ``kappa``: with ``y = G^-1 b`` and the pair weights'
        derivatives (``_Prepared.weights``)::

            d RSS_W = d M_rr - 2 y' d b + y' d G y,   d log det G = tr(G^-1 d G),
            d l_R   = -1/2 [ (N - k) d RSS_W / RSS_W  +  d log det R  +  d log det G ]

        where ``d G = sum_s dw_s Gq_s`` and likewise ``d b``, ``d M_rr``: each term is a weighted sum of the
        pairs' contractions ``y' Gq_s y``, ``tr(G^-1 Gq_s)``, ``y' Cqr_o``."""
        pre, k = self.pre, self.k
        w, ws, logdet_r, dw, dws, dlogdet_r = pre.weights(kappa, gradient=True)
        c = float(ws @ self.Crr)
        drss = dws @ self.Crr
        if k:
            G = (ws @ pre.Gq).reshape(k, k)
            b = w @ self.Cqr
            L, info = dpotrf(G, lower=1, clean=1)
            Li, info = dtrtri(L, lower=1) if info == 0 else (None, 1)
            if info == 0:  # Cholesky: G = L L' is positive definite
                Gi = Li.T @ Li
                logdet_g = 2.0 * float(np.sum(np.log(np.diag(L))))
            else:  # numerically singular: the eigenvalues, floored
                ev, U = np.linalg.eigh(G)
                ev = np.maximum(ev, 1e-300)
                Gi = (U / ev) @ U.T
                logdet_g = float(np.sum(np.log(ev)))
            y = Gi @ b
            rss = c - float(b @ y)
            # y' Gq_s y and tr(G^-1 Gq_s) of every pair in one product
            hq, hg = (pre.Gq @ np.column_stack([np.outer(y, y).ravel(), Gi.ravel()])).T
            drss = drss + dws @ hq - 2.0 * (dw @ (self.Cqr @ y))
            dlogdet_g = dws @ hg
        else:
            rss, logdet_g, dlogdet_g = c, 0.0, 0.0
        if rss <= 1e-300:
            rss, drss = 1e-300, 0.0 * drss
        value = -0.5 * ((self.n - self.k) * np.log(rss) + logdet_r + logdet_g)
        return value, -0.5 * ((self.n - self.k) * drss / rss + dlogdet_r + dlogdet_g)

    def _parts(self, kappa) -> tuple[float, float, float]:
        """``(RSS_W, log det R, log det X' R^-1 X)`` at ``kappa`` (:meth:`_parts_numpy`, compiled)."""
        return self._compiled(kappa, False)[:3]

    def _parts_numpy(self, kappa) -> tuple[float, float, float]:
        """``(RSS_W, log det R, log det X' R^-1 X)`` at ``kappa``: the reference of :meth:`_parts`."""
        w, ws, logdet_r = self.pre.weights(kappa)
        k = self.k
        c = float(ws @ self.Crr)
        if not k:
            return c, logdet_r, 0.0
        G = (ws @ self.pre.Gq).reshape(k, k)
        b = w @ self.Cqr
        try:  # Cholesky: G is positive definite
            L = np.linalg.cholesky(G)
            z = dtrtrs(L, b, lower=1)[0]
            rss = c - float(z @ z)
            logdet_g = 2.0 * float(np.sum(np.log(np.diag(L))))
        except np.linalg.LinAlgError:  # numerically singular: the eigenvalues, floored
            ev, U = np.linalg.eigh(G)
            ev = np.maximum(ev, 1e-300)
            rss = c - float(np.sum((U.T @ b) ** 2 / ev))
            logdet_g = float(np.sum(np.log(ev)))
        return rss, logdet_r, logdet_g
