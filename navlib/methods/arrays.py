"""Array helpers shared by the methods (one place for input checks every estimator needs)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError


def as_2d(values, name: str) -> np.ndarray:
    """``values`` as a float matrix with samples along axis 0 (a 1-D array becomes one column).

    Raises :class:`InputError` naming ``name`` for non-numeric values, a shape other than 1-D or 2-D, an
    empty array, or NaN / infinite entries (naming the first such row and column, counted from 1)."""
    try:
        v = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name}: not numeric") from None
    if v.ndim == 1:
        v = v[:, None]
    if v.ndim != 2 or v.shape[0] == 0 or v.shape[1] == 0:
        raise InputError(
            f"{name}: need a non-empty 1-D or 2-D array (samples along axis 0), "
            f"got shape {np.shape(values)}"
        )
    bad = np.argwhere(~np.isfinite(v))
    if bad.size:
        r, c = bad[0]
        raise InputError(f"{name}: row {r + 1}, column {c + 1} is NaN or infinite")
    return v
