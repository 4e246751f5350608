"""Angles and headings: the conventions every module shares.

- headings in degrees, clockwise from north, in [0, 360);
- heading errors and other angle differences wrapped to (-180, 180] (:func:`wrap_deg`);
- a level compass's heading from the horizontal field components in the sensor frame
  (x forward, y right, z down): ``psi = atan2(-m_y, m_x)`` (:func:`heading_deg`).
"""

from __future__ import annotations

import math

import numpy as np

DEG = math.pi / 180.0  #: one degree in radians
ARCMIN = DEG / 60.0  #: one arcminute in radians
ARCSEC = DEG / 3600.0  #: one arcsecond in radians
ARCMIN_PER_DEG = 60.0
ARCSEC_PER_DEG = 3600.0


def wrap_deg(a):
    """Wrap angles in degrees to (-180, 180]."""
    a = np.asarray(a, dtype=float)
    w = np.mod(a + 180.0, 360.0) - 180.0
    return np.where(w == -180.0, 180.0, w)


def heading_deg(m_x, m_y) -> np.ndarray:
    """Level-compass heading in [0, 360) deg from the horizontal field components of the sensor frame
    (x forward, y right): ``psi = atan2(-m_y, m_x)``, clockwise from (magnetic) north."""
    return np.mod(
        np.degrees(np.arctan2(-np.asarray(m_y, dtype=float), np.asarray(m_x, dtype=float))), 360.0
    )


def to_arcmin(angle_deg):
    """Degrees to arcminutes (of latitude: nautical miles)."""
    return np.asarray(angle_deg, dtype=float) * ARCMIN_PER_DEG
