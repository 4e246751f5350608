"""The parametric bootstrap that calibrates the diagnosis's family of tests on correlated noise
(:func:`bootstrap_level`; the method: :mod:`navlib.workbench.diagnose`, module docstring), and the
Bonferroni alternative's result type (:class:`Calibration`)."""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from ..seeding import child
from .fit import Fit
from .ftests import SPANNED, f_p, projector, unspanned
from .linalg import cholesky_solve, inverse_factor, lower_solve, orth_basis
from .noise_grid import select_ar1_many
from .reml import _Prepared
from .screen import Screening
from .serial import (
    NoiseModel,
    colour,
    select_bases,
    select_many,
    whiten,
    whiten_each,
    whiten_transpose,
)

#: Parametric-bootstrap replicates of the family's smallest p-value on correlated noise (at least
#: ``2.5 / alpha - 1``: :func:`bootstrap_replicates`).
REPLICATES = 99
# The bootstrap's random stream: spawn key under the diagnosis seed (the permutation test uses the seed itself).
BOOTSTRAP_KEY = 1
# Replicates simulated at once (the early stop is checked after each batch; fixed, so results never depend on it).
BATCH = 20


@dataclass(frozen=True)
class Calibration:
    """The per-test critical p-value of a family of tests (a test is significant when its p is below
    ``level``) and how it was found: ``method`` "Bonferroni" (``alpha / m``) or "parametric bootstrap"
    (``replicates`` simulated; ``stopped_early`` when enough of them reached the smallest observed p)."""

    level: float
    method: str
    replicates: int = 0
    stopped_early: bool = False

    def to_dict(self) -> dict:
        return {
            "level": self.level,
            "method": self.method,
            "replicates": self.replicates,
            "stopped_early": self.stopped_early,
        }


def bootstrap_replicates(alpha: float) -> int:
    """Replicates of the parametric bootstrap: :data:`REPLICATES`, or more when ``alpha`` needs them (at
    least ``2.5 / alpha - 1``, so that one replicate may reach the observed p and the test still be
    significant)."""
    return max(REPLICATES, int(math.ceil(2.5 / alpha)) - 1)


#: Noise models whose whitened bases one bootstrap keeps (replicates share the grid's correlations).
KEEP_BASES = 4
#: The replicates' re-estimated noise models of the last bootstrap inputs (:func:`reestimates`).
REESTIMATES: dict = {}


def bootstrap_level(
    fit: Fit, fits: dict, sc: Screening, alpha: float, p_min: float, seed: int
) -> Calibration:
    """The family-wise critical p-value on correlated noise, by a parametric bootstrap of the smallest
    plug-in p-value of the family (Westfall and Young 1993, *Resampling-Based Multiple Testing*, single-step
    minP; module docstring).  Each replicate: AR noise with the estimated partial autocorrelations on the
    same series (:func:`navlib.workbench.serial.colour`), the noise model re-estimated on it as the screen
    does (:func:`navlib.workbench.serial.select`: same regressors, REML; the AR order fixed at the
    data's), then every test of the family -- each candidate's
    nested GLS F test and each structure shape's -- with that re-estimated model; the replicate's smallest p
    is kept.  A test is significant when ``(1 + #{replicates whose minimum <= p}) / (B + 1) < alpha``,
    i.e. ``p`` below the K-th smallest replicate minimum, ``K = ceil(alpha (B + 1) - 1)``.  The replicates
    stop early once K minima fall at or below the smallest observed p (nothing can then be significant;
    Besag and Clifford 1991, Biometrika 78:301).

    The simulated noise and its re-estimates depend only on the screen (noise model, regressors) and the
    seed, not on the model tested: the diagnoses of one loop share them (:func:`reestimates`)."""
    noise = sc.noise
    B = bootstrap_replicates(alpha)
    K = int(math.ceil(alpha * (B + 1) - 1 - 1e-12))  # >= 2: B >= 2.5 / alpha - 1
    family = Family(fit, fits, noise.series, noise.order)
    rng = np.random.default_rng(child(seed, BOOTSTRAP_KEY))
    ser = noise.series
    memo = reestimates(sc, seed, B, fit.n)
    U = None
    minima = np.empty(0)
    # a projected noise model (:class:`navlib.workbench.serial.Projection`) re-estimates every replicate on
    # one grid of filters (each a pass over the series): all replicates in one batch
    batch = B if ser.projection is not None else BATCH
    for start in range(0, B, batch):
        if start not in memo["batches"]:
            if U is None:
                U = rng.standard_normal((len(ser.order), B))  # every replicate's draw, made once
            E = colour(U[:, start : start + batch], noise.kappa, ser, fit.n)
            memo["batches"][start] = (E, reestimate(E, memo["bases"], noise, sc.regressors))
        E, models = memo["batches"][start]
        minima = np.r_[minima, family.minima(E, models)]
        if np.sum(minima <= p_min) >= K:
            return Calibration(
                float(np.sort(minima)[K - 1]), "parametric bootstrap", len(minima), True
            )
    return Calibration(float(np.sort(minima)[K - 1]), "parametric bootstrap", B)


def reestimates(sc: Screening, seed: int, B: int, n: int) -> dict:
    """What the bootstrap of :func:`bootstrap_level` re-estimates on the screen ``sc`` with ``seed``:
    ``bases`` (:func:`navlib.workbench.serial.select_bases` of the screen's regressors, with the basis-only
    likelihood parts) and ``batches``: by the index of its first replicate, each batch's simulated noise and
    the replicates' noise models (:func:`reestimate`), filled as batches are drawn.
    The same inputs (the same noise model and regressors, by identity: the diagnoses of one loop) give the
    same memo; it is dropped with the noise model."""
    noise = sc.noise
    key = (id(noise), id(sc.regressors), seed, B, n)
    memo = REESTIMATES.get(key)
    if memo is None or memo["noise"]() is not noise or memo["regressors"] is not sc.regressors:
        REESTIMATES.clear()
        memo = {
            "noise": weakref.ref(noise),
            "regressors": sc.regressors,
            "batches": {},
            "bases": select_bases(*sc.regressors, noise.series, n, order=noise.order),
        }
        REESTIMATES[key] = memo
        weakref.finalize(noise, REESTIMATES.pop, key, None)
    return memo


def reestimate(E: np.ndarray, bases, noise: NoiseModel, regressors: tuple) -> list:
    """Each column's noise model of ``E`` (residual vectors in observation order), chosen as the screen chose
    the data's (:func:`navlib.workbench.serial.select` around ``regressors``, whose orthonormal ``bases`` are
    given; the AR order fixed at the data's).  AR(1): every column's correlation on the grid at once
    (:func:`navlib.workbench.noise_grid.select_ar1_many`)."""
    if noise.order == 1:
        return [
            NoiseModel((float(k),), noise.series, len(E))
            for k in select_ar1_many(E, bases, noise.series)
        ]
    return select_many(E, *regressors, noise.series, bases, order=noise.order, start_at=noise.kappa)


class Family:
    """The tests of one diagnosis, re-run on simulated residual vectors: each candidate's nested GLS F test
    and each structure shape's, with the noise model each vector's own estimate.

    The tests need only inner products of whitened columns: with ``F`` the columns side by side (bases of
    the model's Jacobian and of each candidate's -- the tests see only their column spaces -- and the
    structure shapes) and ``e`` a residual vector, ``H = F' R^-1 F``, ``h = F' R^-1 e`` and ``e' R^-1 e``.
    For AR noise on segments ``H`` is a weighted sum of ``F``'s lagged cross-products, computed once
    (``navlib.workbench.reml._Prepared``), and ``h = F' W' (W e)``
    (:func:`navlib.workbench.serial.whiten_transpose`), so no replicate whitens ``F``.  Then, with ``T0``
    the inverse Cholesky factor of the Jacobian's block ``H_00`` and ``z0 = T0 h_0``::

        RSS_0 = e' R^-1 e - |z0|^2,   RSS_1 = e' R^-1 e - |T1 h_1|^2      (candidates)
        X' (I - P_0) X = D^-1 H_ss D^-1 - B' B,   B = T0 H_0s D^-1    (shapes, D: norms)

    the shape's unspanned directions the eigenvectors of the latter above ``SPANNED^2`` (as in
    :func:`navlib.workbench.ftests.shape_bases`) and its drop ``|u' e_0|^2`` from
    ``X' (I - P_0) e = D^-1 h_s - B' z0``.  A series
    with a :class:`navlib.workbench.serial.Projection` is whitened by its filter: there each noise model
    whitens the columns (all in one call) and the tests run on them (``_min_p_whitened``)."""

    def __init__(self, fit: Fit, fits: dict, series, order: int):
        self.n = fit.n
        cands = [
            (f1.jacobian, f1.n_params - fit.n_params, f1.n - f1.n_params) for f1 in fits.values()
        ]
        cands = [c for c in cands if c[1] > 0 and c[2] > 0]
        self.tests = [(q, df2) for _, q, df2 in cands]
        shapes = [np.asarray(X0, float) for _, X0, _ in fit.spec.structure(fit)]
        jacobians = [
            np.asarray(J, float).reshape(self.n, -1)
            for J in [fit.jacobian] + [J1 for J1, _, _ in cands]
        ]
        self.series = series
        self.gram = series.projection is None
        blocks = ([orth_basis(J) for J in jacobians] if self.gram else jacobians) + shapes
        edges = np.cumsum([0] + [X.shape[1] for X in blocks])
        self.spans = [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]
        X = np.column_stack(blocks)
        self.F = X[series.order]
        self.pre = _Prepared(X, series, max(order, 1)) if self.gram else None
        self._cache: dict = {}  # by noise model: _factors (Gram path)
        self._whitened: dict = {}  # and _bases (whitened path)

    def minima(self, E: np.ndarray, models: list) -> np.ndarray:
        """The smallest p of the family on each column of ``E`` (residual vectors in observation order), each
        under its own noise model (``models``, :func:`reestimate`); columns with the same model share it."""
        out = np.ones(E.shape[1])
        Eo = np.asarray(E, float)[self.series.order]
        orders: dict = {}
        for b, nm in enumerate(models):
            orders.setdefault(nm.order if nm.correlated else 0, []).append(b)
        for cols in orders.values():
            if self.gram:
                try:  # every column at once, each under its own model
                    out[cols] = self._min_p_many(Eo[:, cols], [models[b] for b in cols])
                    continue
                except (
                    np.linalg.LinAlgError
                ):  # a Gram block numerically singular: one model at a time
                    pass
            groups: dict = {}
            for b in cols:
                groups.setdefault(
                    tuple(models[b].kappa) if models[b].correlated else (), []
                ).append(b)
            for same in groups.values():
                run = self._min_p if self.gram else self._min_p_whitened
                out[same] = run(Eo[:, same], models[same[0]])
        return out

    def _min_p_many(self, Eo: np.ndarray, models: list) -> np.ndarray:
        """:meth:`_min_p` of every column of ``Eo`` (series order) under its own noise model ``models[b]``
        (all of one order) at once: each column whitened with its own coefficients
        (:func:`navlib.workbench.serial.whiten_each`), the Gram matrices ``H`` stacked and factored together
        (batched LAPACK); raises ``LinAlgError`` when a block is not numerically positive definite."""
        kappas = [tuple(nm.kappa) if nm.correlated else () for nm in models]
        We = whiten_each(Eo, kappas, self.series)
        c = np.einsum("ij,ij->j", We, We)  # e' R^-1 e
        h = (self.F.T @ whiten_each(We, kappas, self.series, transpose=True)).T  # F' R^-1 e: (B, m)
        m = self.F.shape[1]
        H = (np.array([self.pre.weights(k)[1] for k in kappas]) @ self.pre.Gq).reshape(-1, m, m)
        a0 = self.spans[0]
        L0, z0 = cholesky_solve(H[:, a0, a0], h[:, a0])
        fit0 = np.einsum("bi,bi->b", z0, z0)
        rss0 = c - fit0
        best = np.ones(Eo.shape[1])
        for s, (q, df2) in zip(self.spans[1:], self.tests):
            z1 = cholesky_solve(H[:, s, s], h[:, s])[1]
            fit1 = np.einsum("bi,bi->b", z1, z1)
            best = np.minimum(best, f_p(fit1 - fit0, c - fit1, q, df2))
        k0 = a0.stop - a0.start
        for s in self.spans[1 + len(self.tests) :]:
            Hss = H[:, s, s]
            d = np.maximum(
                np.sqrt(np.maximum(np.diagonal(Hss, axis1=1, axis2=2), 0.0)), 1e-300
            )  # (B, q)
            Bm = lower_solve(L0, H[:, a0, s]) / d[:, None, :]
            w, V = np.linalg.eigh(
                Hss / (d[:, :, None] * d[:, None, :]) - Bm.transpose(0, 2, 1) @ Bm
            )
            keep = w > SPANNED**2
            y = np.einsum("bsr,bs->br", V, h[:, s] / d - np.einsum("bks,bk->bs", Bm, z0))
            drop = np.sum(np.where(keep, y * y / np.where(keep, w, 1.0), 0.0), axis=1)
            q = np.sum(keep, axis=1)
            df2 = self.n - k0 - q
            ok = (q > 0) & (df2 >= 3)  # else the model spans the shape, or too few rows
            p = f_p(drop, rss0 - drop, np.maximum(q, 1), np.maximum(df2, 1))
            best = np.minimum(best, np.where(ok, p, 1.0))
        return best

    def _factors(self, kappa: tuple) -> tuple:
        """Under the AR noise ``kappa``: ``T0`` and each candidate's ``T1`` (inverse factors of the blocks of
        ``H``) and each shape's ``(u, B, d, q, df2)`` (class docstring; ``u`` maps ``X' (I - P_0) e`` to the
        coordinates of the drop); the last few are kept, since replicates share grid correlations."""
        if kappa not in self._cache:
            _, ws, _ = self.pre.weights(kappa)
            m = self.F.shape[1]
            H = (ws @ self.pre.Gq).reshape(m, m)
            T = [inverse_factor(H[s, s]) for s in self.spans[: 1 + len(self.tests)]]
            a0, T0 = self.spans[0], T[0]
            shapes = []
            for s in self.spans[1 + len(self.tests) :]:
                d = np.maximum(np.sqrt(np.maximum(np.diag(H[s, s]), 0.0)), 1e-300)
                Bm = (T0 @ H[a0, s]) / d
                w, V = np.linalg.eigh(H[s, s] / np.outer(d, d) - Bm.T @ Bm)
                keep = w > SPANNED**2
                q = int(np.sum(keep))
                df2 = self.n - T0.shape[0] - q
                if q == 0 or df2 < 3:
                    continue  # the model already spans this shape, or too few rows
                shapes.append((s, V[:, keep] / np.sqrt(w[keep]), Bm, d, q, df2))
            if len(self._cache) >= KEEP_BASES:
                self._cache.pop(next(iter(self._cache)))
            self._cache[kappa] = (T, shapes)
        return self._cache[kappa]

    def _min_p(self, Eo: np.ndarray, nm: NoiseModel) -> np.ndarray:
        """The smallest p of the family on the columns ``Eo`` (series order), all under the noise model
        ``nm``, from inner products (class docstring)."""
        kappa = tuple(nm.kappa) if nm.correlated else ()
        T, shapes = self._factors(kappa)
        We = whiten(Eo, kappa, self.series, ordered=True)
        c = np.einsum("ij,ij->j", We, We)  # e' R^-1 e
        h = self.F.T @ whiten_transpose(We, kappa, self.series)  # F' R^-1 e
        z0 = T[0] @ h[self.spans[0]]
        fit0 = np.einsum("ij,ij->j", z0, z0)
        rss0 = c - fit0
        best = np.ones(Eo.shape[1])
        for T1, s, (q, df2) in zip(T[1:], self.spans[1:], self.tests):
            z1 = T1 @ h[s]
            fit1 = np.einsum("ij,ij->j", z1, z1)
            best = np.minimum(best, f_p(fit1 - fit0, c - fit1, q, df2))
        for s, u, Bm, d, q, df2 in shapes:
            y = u.T @ (h[s] / d[:, None] - Bm.T @ z0)
            drop = np.einsum("ij,ij->j", y, y)
            best = np.minimum(best, f_p(drop, rss0 - drop, q, df2))
        return best

    def _bases(self, nm: NoiseModel) -> tuple:
        """The whitened model's and candidates' orthonormal bases and the shapes' (:func:`navlib.workbench.ftests.shape_bases`)
        under the noise model ``nm`` (all columns whitened in one call); the last few are kept, since
        replicates share grid correlations."""
        key = tuple(nm.kappa)
        if key not in self._whitened:
            WF = nm.whiten(self.F, ordered=True)
            blocks = [WF[:, s] for s in self.spans]
            Q0 = projector(blocks[0])
            Q1s = [(projector(W1), q, df2) for W1, (q, df2) in zip(blocks[1:], self.tests)]
            if len(self._whitened) >= KEEP_BASES:
                self._whitened.pop(next(iter(self._whitened)))
            self._whitened[key] = (Q0, Q1s, unspanned(Q0, blocks[1 + len(self.tests) :], self.n))
        return self._whitened[key]

    def _min_p_whitened(self, Eo: np.ndarray, nm: NoiseModel) -> np.ndarray:
        """:meth:`_min_p` on whitened columns (a projected series): ``Eo`` in series order."""
        W = nm.whiten(Eo, ordered=True)
        Q0, Q1s, shape_bases = self._bases(nm)
        e0 = W - Q0 @ (Q0.T @ W)
        rss0 = np.einsum("ij,ij->j", e0, e0)
        best = np.ones(Eo.shape[1])
        for Q1, q, df2 in Q1s:
            e1 = W - Q1 @ (Q1.T @ W)
            rss1 = np.einsum("ij,ij->j", e1, e1)
            best = np.minimum(best, f_p(rss0 - rss1, rss1, q, df2))
        for _, u, q, df2 in shape_bases:
            drop = np.sum((u.T @ e0) ** 2, axis=0)
            best = np.minimum(best, f_p(drop, rss0 - drop, q, df2))
        return best
