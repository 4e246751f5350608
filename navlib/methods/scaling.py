"""Explicit, invertible min-max scaling (the normalisation step of papers A and B).

Paper A (compass ADE-BP) and patent B (ELM with autonomous back-tuning, "third step") both normalise
inputs and outputs by the max-min method,

    x' = (x - x_min) / (x_max - x_min),        x = x_min + x' (x_max - x_min),

and de-normalise the network output after.  :class:`MinMax` holds ``x_min`` and ``x_max`` per column so
the same transform can be applied to test data and inverted on predictions.  Test data outside the
training range map outside [0, 1]; nothing is clipped.  MATLAB's ``mapminmax`` (the default processing
of ``feedforwardnet``) is the same map onto [-1, 1]: ``MinMax.fit(values, out=(-1, 1))``,

    x' = y_min + (y_max - y_min) (x - x_min) / (x_max - x_min).
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
    out_lo: float = 0.0
    out_hi: float = 1.0

    @classmethod
    def fit(
        cls, values, *, name: str = "values", out: tuple[float, float] = (0.0, 1.0)
    ) -> "MinMax":
        """Scaler mapping the column minima to ``out[0]`` and maxima to ``out[1]`` (default 0 and 1;
        ``(-1, 1)`` is MATLAB's ``mapminmax``).

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
            raise InputError(
                f"{name}: column {int(flat[0])} is constant ({lo[flat[0]]:g}); "
                "min-max scaling needs a range"
            )
        if not out[1] > out[0]:
            raise InputError(f"{name}: output range {out!r} must be increasing")
        return cls(lo=lo, hi=hi, out_lo=float(out[0]), out_hi=float(out[1]))

    @property
    def span(self) -> np.ndarray:
        """``hi - lo`` per column."""
        return self.hi - self.lo

    def _check(self, v: np.ndarray) -> np.ndarray:
        v2 = v.reshape(v.shape[0], -1) if v.ndim else v.reshape(1, 1)
        if v2.shape[1] != self.lo.size:
            raise InputError(f"MinMax: fitted on {self.lo.size} column(s), got {v2.shape[1]}")
        return v2

    @property
    def gain(self) -> np.ndarray:
        """Original units per normalised unit, per column: ``(hi - lo) / (out_hi - out_lo)``."""
        return self.span / (self.out_hi - self.out_lo)

    def transform(self, values) -> np.ndarray:
        """``out_lo + (x - lo) / gain``, same shape as ``values`` (``(x - lo)/(hi - lo)`` by default)."""
        v = np.asarray(values, dtype=float)
        return (self.out_lo + (self._check(v) - self.lo) / self.gain).reshape(v.shape)

    def inverse(self, values) -> np.ndarray:
        """``lo + (x' - out_lo) gain``, same shape as ``values``: undoes :meth:`transform`."""
        v = np.asarray(values, dtype=float)
        return (self.lo + (self._check(v) - self.out_lo) * self.gain).reshape(v.shape)

    def inverse_scale(self, values) -> np.ndarray:
        """Scale a *difference* (e.g. an error) back to original units: ``x' gain`` (no offset)."""
        v = np.asarray(values, dtype=float)
        return (self._check(v) * self.gain).reshape(v.shape)
