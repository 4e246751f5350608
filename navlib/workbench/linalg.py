"""Linear algebra the workbench's fit, noise model, screening and diagnosis share."""

from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dpotrf, dpotrs, dtrtri, dtrtrs


def orth_basis(X: np.ndarray, rtol: float = 1e-7) -> np.ndarray:
    """An orthonormal basis of the column space of ``X``: columns are scaled to unit norm and a column is
    dropped when less than ``rtol`` of it is left after removing the previous ones."""
    return orth_basis_split(X, X.shape[1], rtol)[0]


def orth_basis_split(X: np.ndarray, split: int, rtol: float = 1e-7) -> tuple[np.ndarray, int]:
    """:func:`orth_basis` of ``X`` and how many of its columns come from ``X``'s first ``split`` columns:
    ``Q[:, :r]`` is ``orth_basis(X[:, :split])`` bit for bit (the columns are taken in order)."""
    n, k = X.shape
    Q = np.zeros((n, k), order="F")  # columns contiguous: Q[:, :r] is one block
    r = 0
    r_split = 0
    for j in range(k):
        if j == split:
            r_split = r
        v = X[:, j].astype(float)
        norm = np.linalg.norm(v)
        if norm == 0:
            continue
        v = v / norm
        for _ in range(2):
            if r:
                v = v - Q[:, :r] @ (Q[:, :r].T @ v)
        left = np.linalg.norm(v)
        if left > rtol:
            Q[:, r] = v / left
            r += 1
    if split >= k:
        r_split = r
    return np.ascontiguousarray(Q[:, :r]), r_split


#: :func:`leverage` takes the Cholesky route when every column keeps more than this share of its norm after
#: the previous ones (the Gram matrix then has a condition number below about 1e6, and the leverages are
#: exact to about 1e-10); else the Gram-Schmidt basis, which drops the dependent columns.
LEVERAGE_CHOL_MIN = 1e-3


def _scaled_cholesky(X: np.ndarray):
    """``(X / norms, norms, L)`` with ``L`` the lower Cholesky factor of the column-scaled Gram matrix,
    where every column keeps more than :data:`LEVERAGE_CHOL_MIN` of its norm after the previous ones; else
    None (a zero column, no columns, or a Gram matrix too ill conditioned for the normal equations)."""
    norms = np.sqrt(np.einsum("ij,ij->j", X, X))
    if not X.shape[1] or not np.all(norms > 0):
        return None
    Xs = X / norms
    L, info = dpotrf(Xs.T @ Xs, lower=1, clean=1)
    if info != 0 or np.min(np.diag(L)) <= LEVERAGE_CHOL_MIN:
        return None
    return Xs, norms, L


def leverage(X: np.ndarray, rtol: float = 1e-7) -> np.ndarray:
    """The leverages ``h_i`` (the diagonal of the hat matrix) of the column space of ``X``: the row sums of
    squares of :func:`orth_basis` ``(X, rtol)``, from the Cholesky factor of the column-scaled Gram matrix
    (``h_i = |L^-1 x_i|^2``; a tenth of Gram-Schmidt's time on thousands of rows) where it is well
    conditioned (:data:`LEVERAGE_CHOL_MIN`), else from the basis itself."""
    n, k = X.shape
    if not k:
        return np.zeros(n)
    scaled = _scaled_cholesky(X)
    if scaled is not None:
        Xs, _, L = scaled
        Z, _ = dtrtrs(L, Xs.T, lower=1)  # L^-1 Xs' (k x n)
        return np.einsum("ij,ij->j", Z, Z)
    q = orth_basis(X, rtol)
    return np.einsum("ij,ij->i", q, q)


def least_squares_coef(X: np.ndarray, y: np.ndarray, rcond: float = 1e-10) -> np.ndarray:
    """``argmin_c |X c - y|``: from the Cholesky factor of the column-scaled Gram matrix (the normal
    equations; a fifth of an SVD's time on thousands of rows) where every column keeps more than
    :data:`LEVERAGE_CHOL_MIN` of its norm after the previous ones (the Gram matrix's condition number below
    about 1e6, so the coefficients are exact to about 1e-10 relative), else ``numpy.linalg.lstsq`` with
    ``rcond`` (the minimum-norm solution of a rank-deficient ``X``)."""
    scaled = _scaled_cholesky(X)
    if scaled is not None:
        Xs, norms, L = scaled
        c, info = dpotrs(L, Xs.T @ y, lower=1)
        if info == 0:
            return c / norms
    return np.linalg.lstsq(X, y, rcond=rcond)[0]


def lower_solve(L: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``L^-1 b`` for stacked lower-triangular ``L`` (B, k, k) and ``b`` (B, k) or (B, k, r)."""
    if not L.shape[1]:
        return np.zeros(b.shape)
    return np.linalg.solve(L, b[..., None])[..., 0] if b.ndim == 2 else np.linalg.solve(L, b)


def cholesky_solve(G: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For stacked ``G`` (B, k, k) positive definite and ``b`` (B, k): the Cholesky factors ``L`` and
    ``z = L^-1 b`` (``|z|^2 = b' G^-1 b``); ``LinAlgError`` if a ``G`` is not numerically positive definite."""
    L = np.linalg.cholesky(G) if G.shape[1] else G
    return L, lower_solve(L, b)


def inverse_factor(G: np.ndarray) -> np.ndarray:
    """``T`` with ``T G T' = I`` on the range of ``G`` (``|T h|^2 = h' G^+ h``): the inverse of the Cholesky
    factor, or for a numerically singular ``G`` the eigenvectors over the roots of the eigenvalues above
    ``1e-12`` of the largest."""
    if not G.shape[0]:
        return np.zeros((0, 0))
    L, info = dpotrf(G, lower=1, clean=1)
    if info == 0:
        Ti, info = dtrtri(L, lower=1)
        if info == 0:
            return Ti
    w, V = np.linalg.eigh(G)
    keep = w > 1e-12 * max(w[-1], 1e-300)
    return (V[:, keep] / np.sqrt(w[keep])).T
