"""Archibald Smith's compass deviation series and the 8-position least-squares fit (paper A's baseline).

Deviation as a function of the *compass* (measured) heading ``h``:

    delta(h) = A + B sin h + C cos h + D sin 2h + E cos 2h         (deg)

A: constant (misalignment, antisymmetric soft iron); B, C: one-cycle (hard iron, with a small soft-iron
part); D, E: two-cycle (symmetric soft iron).  It is the first-order harmonic approximation of the exact
planar model in :mod:`navlib.sensors.compass` (Bowditch, ch. on compass adjustment).  The compensated heading is
``h - delta(h)``.  Paper A fits it by least squares to 8 readings, from 0 deg every 45 deg; the paper does
not print its model, Smith's is the classical choice.

The same least squares with more harmonics (:func:`fit_smith` ``order``): to order ``K``

    delta(h) = A + sum_{k=1..K} (B_k sin kh + C_k cos kh)                                   (eq-harmonic)

has ``2K + 1`` coefficients; Smith's series is ``K = 2``.  Eight readings 45 deg apart determine up to
``K = 3`` (7 coefficients: the 4th harmonic's sine vanishes at those headings).  A hard iron of a fraction
``k`` of the horizontal field leaves harmonics of about ``k^n / n`` rad at order ``n``: the 3rd-order series
absorbs what the 5-term series cannot.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..angles import wrap_deg
from ..errors import InputError

COEFFICIENTS = ("A", "B", "C", "D", "E")


def design(h_deg, order: int = 2) -> np.ndarray:
    """Columns ``[1, sin h, cos h, sin 2h, cos 2h, ..., sin Kh, cos Kh]`` (``K = order``) for headings in
    degrees; ``order=2`` is Smith's A..E."""
    h = np.radians(np.asarray(h_deg, dtype=float))
    cols = [np.ones_like(h)]
    for k in range(1, int(order) + 1):
        cols += [np.sin(k * h), np.cos(k * h)]
    return np.stack(cols, axis=-1)


@dataclass(frozen=True)
class SmithModel:
    """Fitted A..E coefficients (deg)."""

    coef: np.ndarray

    @property
    def order(self) -> int:
        """Highest harmonic of the series (2 for Smith's A..E)."""
        return (len(self.coef) - 1) // 2

    def deviation(self, measured_deg) -> np.ndarray:
        return design(measured_deg, self.order) @ self.coef

    def correct(self, measured_deg) -> np.ndarray:
        """Compensated heading in [0, 360)."""
        m = np.asarray(measured_deg, dtype=float)
        return np.mod(m - self.deviation(m), 360.0)

    def as_dict(self) -> dict:
        """Coefficients by name: A..E, then ``B3``, ``C3``, ... for the harmonics above the second."""
        names = list(COEFFICIENTS) + [f"{c}{k}" for k in range(3, self.order + 1) for c in "BC"]
        return dict(zip(names, map(float, self.coef)))


def fit_smith(measured_deg, true_deg, order: int = 2) -> SmithModel:
    """Least-squares harmonic deviation series (:func:`design`; ``order=2``: Smith's A..E) from readings;
    deviation = wrap(measured - true).  Needs at least ``2 order + 1`` distinct readings."""
    if not isinstance(order, (int, np.integer)) or order < 1:
        raise InputError(f"parameter order: must be an integer >= 1, got {order!r}")
    m = np.asarray(measured_deg, dtype=float)
    t = np.asarray(true_deg, dtype=float)
    if m.shape != t.shape or m.ndim != 1:
        raise InputError("measured and true headings must be 1-D arrays of the same length")
    need = 2 * int(order) + 1
    if len(np.unique(np.round(np.mod(m, 360.0), 6))) < need:
        raise InputError(
            f"a harmonic series of order {order} ({need} coefficients) needs at least {need} "
            f"distinct headings, got {len(m)} readings"
        )
    coef, *_ = np.linalg.lstsq(design(m, order), wrap_deg(m - t), rcond=None)
    return SmithModel(coef)


def nearest_positions(true_deg, step_deg: float = 45.0, tol_deg: float = 1e-6) -> np.ndarray:
    """For each position ``0, step, 2 step, ...`` deg of true heading (paper A's 8 positions for 45 deg), the
    index of the reading nearest to it, or -1 where no reading lies within ``tol_deg`` of it.

    The distance is the wrapped angle ``|wrap(t - position)|``; a tie goes to the first reading.  A
    turntable sweep has a reading at each position (the default ``tol_deg`` asks for that); a hand-turned
    recording or a file binned by heading has the nearest within a few degrees.

    Parameters
    ----------
    true_deg : array_like
        True (reference) headings of the readings, deg.
    step_deg : float
        Spacing of the positions, deg (45: the 8 positions).
    tol_deg : float
        How far the nearest reading may lie from its position, deg (>= 0).

    Returns
    -------
    numpy.ndarray
        One index per position (int), -1 where the position has no reading within ``tol_deg``.
    """
    if not np.isfinite(tol_deg) or tol_deg < 0:
        raise InputError(f"parameter tol_deg: must be a number >= 0, got {tol_deg!r}")
    t = np.mod(np.asarray(true_deg, dtype=float), 360.0)
    out = []
    for w in np.arange(0.0, 360.0, step_deg):
        if t.size == 0:
            out.append(-1)
            continue
        d = np.abs(((t - w) + 180.0) % 360.0 - 180.0)
        j = int(np.argmin(d))
        out.append(j if d[j] <= tol_deg else -1)
    return np.array(out, dtype=int)


def eight_position_indices(true_deg, step_deg: float = 45.0, tol_deg: float = 1e-6) -> np.ndarray:
    """Indices of the readings at 0, 45, ..., 315 deg true heading (paper A's 8 positions): the nearest
    reading to each position (:func:`nearest_positions`), which must lie within ``tol_deg`` of it (default:
    a reading at the position itself, as on paper A's turntable)."""
    idx = nearest_positions(true_deg, step_deg, tol_deg)
    missing = np.arange(0.0, 360.0, step_deg)[idx < 0]
    if missing.size:
        within = "at" if tol_deg <= 1e-6 else f"within {tol_deg:g} deg of"
        raise InputError(
            f"no reading {within} true heading {missing[0]:g} deg for the 8-position fit"
        )
    return idx
