"""Archibald Smith's compass deviation series and the 8-position least-squares fit (paper A's baseline).

Deviation as a function of the *compass* (measured) heading ``h``:

    delta(h) = A + B sin h + C cos h + D sin 2h + E cos 2h         (deg)

A: constant (misalignment, antisymmetric soft iron); B, C: one-cycle (hard iron, with a small soft-iron
part); D, E: two-cycle (symmetric soft iron).  It is the first-order harmonic approximation of the exact
planar model in :mod:`navlib.sensors.compass` (Bowditch, ch. on compass adjustment).  The compensated heading is
``h - delta(h)``.  Paper A fits it by least squares to 8 readings, from 0 deg every 45 deg; the paper does
not print its model, Smith's is the classical choice.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..angles import wrap_deg
from ..errors import InputError

COEFFICIENTS = ("A", "B", "C", "D", "E")


def design(h_deg) -> np.ndarray:
    """Columns [1, sin h, cos h, sin 2h, cos 2h] for headings in degrees."""
    h = np.radians(np.asarray(h_deg, dtype=float))
    return np.stack([np.ones_like(h), np.sin(h), np.cos(h), np.sin(2 * h), np.cos(2 * h)], axis=-1)


@dataclass(frozen=True)
class SmithModel:
    """Fitted A..E coefficients (deg)."""

    coef: np.ndarray

    def deviation(self, measured_deg) -> np.ndarray:
        return design(measured_deg) @ self.coef

    def correct(self, measured_deg) -> np.ndarray:
        """Compensated heading in [0, 360)."""
        m = np.asarray(measured_deg, dtype=float)
        return np.mod(m - self.deviation(m), 360.0)

    def as_dict(self) -> dict:
        return dict(zip(COEFFICIENTS, map(float, self.coef)))


def fit_smith(measured_deg, true_deg) -> SmithModel:
    """Least-squares A..E from readings; deviation = wrap(measured - true). Needs >= 5 distinct readings."""
    m = np.asarray(measured_deg, dtype=float)
    t = np.asarray(true_deg, dtype=float)
    if m.shape != t.shape or m.ndim != 1:
        raise InputError("measured and true headings must be 1-D arrays of the same length")
    if len(np.unique(np.round(np.mod(m, 360.0), 6))) < 5:
        raise InputError(f"Smith's A..E model needs at least 5 distinct headings, got {len(m)} readings")
    coef, *_ = np.linalg.lstsq(design(m), wrap_deg(m - t), rcond=None)
    return SmithModel(coef)


def eight_position_indices(true_deg, step_deg: float = 45.0) -> np.ndarray:
    """Indices of the readings at 0, 45, ..., 315 deg true heading (paper A's 8 positions)."""
    t = np.mod(np.asarray(true_deg, dtype=float), 360.0)
    want = np.arange(0.0, 360.0, step_deg)
    idx = []
    for w in want:
        d = np.abs(((t - w) + 180.0) % 360.0 - 180.0)
        j = int(np.argmin(d))
        if d[j] > 1e-6:
            raise InputError(f"no reading at true heading {w:g} deg for the 8-position fit")
        idx.append(j)
    return np.array(idx)
