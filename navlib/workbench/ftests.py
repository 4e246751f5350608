"""The F tests of the diagnosis (:mod:`navlib.workbench.diagnose`): the nested-model test of a
candidate effect and of a structure shape, on the residual as the tests see it (whitened and freed of
the model's Jacobian under correlated noise, :func:`gls`), and the part of a shape the model cannot
absorb (:func:`shape_bases`); the parametric bootstrap (:mod:`navlib.workbench.bootstrap`) calls them
on every replicate."""

from __future__ import annotations

import math

import numpy as np
from scipy import special
from scipy.special import fdtrc

from .fit import Fit
from .linalg import orth_basis
from .serial import NoiseModel

# A structure shape is "already in the model" when less than this share of its norm is left after
# projecting it off the model's Jacobian.
SPANNED = 0.1


def f_test(rss0: float, rss1: float, q: int, df2: int) -> tuple[float, float]:
    """Nested-model F test: (p, log p)."""
    if df2 <= 0 or q <= 0:
        return 1.0, 0.0
    if rss1 <= 0:
        return (0.0, -np.inf) if rss0 > 0 else (1.0, 0.0)
    f = max((rss0 - rss1) / q, 0.0) / (rss1 / df2)
    with np.errstate(divide="ignore"):
        logp = float(
            np.log(special.fdtrc(q, df2, f))
        )  # scipy.stats.f.logsf, without importing scipy.stats
    return float(math.exp(logp)), logp


def projector(J: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the model Jacobian's column space (rank-revealing SVD)."""
    return orth_basis(J)


def gls(fit: Fit, noise: NoiseModel | None) -> tuple[np.ndarray, np.ndarray]:
    """The residual of ``fit`` as the tests see it and the orthonormal basis of its Jacobian: with
    correlated noise, ``W r`` freed of what ``W J`` absorbs (the GLS residual, to first order) and the
    basis of ``W J``; otherwise ``r`` and the basis of ``J``."""
    return gls_of(fit.residuals, fit.jacobian, noise)


def gls_of(r: np.ndarray, J: np.ndarray, noise: NoiseModel | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`gls` of a residual ``r`` and a Jacobian ``J``."""
    if noise is None or not noise.correlated:
        return r, projector(J)
    e = noise.whiten(r)
    Q = projector(noise.whiten(J))
    return e - Q @ (Q.T @ e), Q


def shape_bases(
    Q: np.ndarray, shapes: list, noise: NoiseModel | None, n: int
) -> list[tuple[int, np.ndarray, int, int]]:
    """For each structure shape ``X0`` the part the model of (whitened) Jacobian basis ``Q`` cannot absorb:
    ``(index, u, q, df2)`` with ``u`` an orthonormal basis of it (q columns) and ``df2`` the F test's
    denominator degrees of freedom; shapes the model already spans, or with too few rows left, are
    skipped."""
    white = noise is not None and noise.correlated
    return unspanned(Q, [noise.whiten(X0) if white else X0 for X0 in shapes], n)


def unspanned(Q: np.ndarray, shapes: list, n: int) -> list[tuple[int, np.ndarray, int, int]]:
    """:func:`shape_bases` of shapes already whitened (or of independent samples)."""
    out = []
    for i, X in enumerate(shapes):
        X = X / np.maximum(np.linalg.norm(X, axis=0), 1e-300)
        Xp = X - Q @ (Q.T @ X)
        # directions of the shape the model cannot absorb: singular values of Xp above SPANNED (unit columns;
        # the Gram matrix is small: a structure shape has at most a few tens of columns)
        w, V = np.linalg.eigh(Xp.T @ Xp)
        keep = w > SPANNED**2
        q = int(np.sum(keep))
        df2 = n - Q.shape[1] - q
        if q == 0 or df2 < 3:
            continue  # the model already spans this shape, or too few rows
        out.append((i, (Xp @ V[:, keep]) / np.sqrt(w[keep]), q, df2))
    return out


def shape_tests(
    e: np.ndarray, Q: np.ndarray, shapes: list, noise: NoiseModel | None, n: int
) -> list[tuple[int, float, float]]:
    """F tests of structure shapes ``X0`` against the (whitened, projected) residual ``e`` of a model with
    (whitened) Jacobian basis ``Q``: ``(index, p, log p)`` of each shape the model does not already span."""
    rss = float(e @ e)
    out = []
    for i, u, q, df2 in shape_bases(Q, shapes, noise, n):
        drop = float(np.sum((u.T @ e) ** 2))
        p, logp = f_test(rss, rss - drop, q, df2)
        out.append((i, p, logp))
    return out


def f_p(drop: np.ndarray, rss1: np.ndarray, q: int, df2: int) -> np.ndarray:
    """p of the nested F test (:func:`f_test`), vectorised: ``F = (drop / q) / (rss1 / df2)``."""
    f = np.maximum(drop / q, 0.0) / np.maximum(rss1 / df2, 1e-300)
    return np.where(rss1 > 0, fdtrc(q, df2, f), np.where(drop > 0, 0.0, 1.0))
