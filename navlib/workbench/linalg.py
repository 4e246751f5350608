"""Linear algebra the workbench's fit, noise model, screening and diagnosis share."""

from __future__ import annotations

import numpy as np


def orth_basis(X: np.ndarray, rtol: float = 1e-7) -> np.ndarray:
    """An orthonormal basis of the column space of ``X``: columns are scaled to unit norm and a column is
    dropped when less than ``rtol`` of it is left after removing the previous ones."""
    n, k = X.shape
    Q = np.zeros((n, k), order="F")  # columns contiguous: Q[:, :r] is one block
    r = 0
    for j in range(k):
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
    return np.ascontiguousarray(Q[:, :r])
