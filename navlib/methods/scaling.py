"""Explicit, invertible min-max scaling (the normalisation step of papers A and B).

Paper A (compass ADE-BP) and patent B (ELM with autonomous back-tuning, "third step") both normalise
inputs and outputs by the max-min method,

    x' = (x - x_min) / (x_max - x_min),        x = x_min + x' (x_max - x_min),

and de-normalise the network output after.  :class:`MinMax` holds ``x_min`` and ``x_max`` per column so
the same transform can be applied to test data and inverted on predictions.  Test data outside the
training range map outside [0, 1]; nothing is clipped.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class MinMax:
    """Per-column min-max scaler.  Build it with :meth:`MinMax.fit`.

    ``lo`` and ``hi`` have one entry per column (a 1-D input counts as one column).  1-D arrays stay 1-D
    through :meth:`transform` and :meth:`inverse`.
    """

    lo: np.ndarray
    hi: np.ndarray

    @classmethod
    def fit(cls, values, *, name: str = "values") -> "MinMax":
        """Scaler mapping the column minima to 0 and maxima to 1.

        Raises :class:`~navlib.errors.InputError` for an empty array, non-finite values, or a constant column (the
        transform would divide by zero); ``name`` is used in the message."""
        v = np.asarray(values, dtype=float)
        if v.ndim not in (1, 2) or v.shape[0] == 0:
            raise InputError(f"{name}: need a non-empty 1-D or 2-D array, got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InputError(f"{name}: contains NaN or infinite values")
        v2 = v.reshape(v.shape[0], -1)
        lo, hi = v2.min(axis=0), v2.max(axis=0)
        flat = np.flatnonzero(hi <= lo)
        if flat.size:
            raise InputError(f"{name}: column {int(flat[0])} is constant ({lo[flat[0]]:g}); "
                             "min-max scaling needs a range")
        return cls(lo=lo, hi=hi)

    @property
    def span(self) -> np.ndarray:
        """``hi - lo`` per column."""
        return self.hi - self.lo

    def _check(self, v: np.ndarray) -> np.ndarray:
        v2 = v.reshape(v.shape[0], -1) if v.ndim else v.reshape(1, 1)
        if v2.shape[1] != self.lo.size:
            raise InputError(f"MinMax: fitted on {self.lo.size} column(s), got {v2.shape[1]}")
        return v2

    def transform(self, values) -> np.ndarray:
        """``(x - lo) / (hi - lo)``, same shape as ``values``."""
        v = np.asarray(values, dtype=float)
        return ((self._check(v) - self.lo) / self.span).reshape(v.shape)

    def inverse(self, values) -> np.ndarray:
        """``lo + x' (hi - lo)``, same shape as ``values``: undoes :meth:`transform`."""
        v = np.asarray(values, dtype=float)
        return (self.lo + self._check(v) * self.span).reshape(v.shape)

    def inverse_scale(self, values) -> np.ndarray:
        """Scale a *difference* (e.g. an error) back to original units: ``x' (hi - lo)`` (no offset)."""
        v = np.asarray(values, dtype=float)
        return (self._check(v) * self.span).reshape(v.shape)
