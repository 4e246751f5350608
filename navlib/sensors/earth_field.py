"""The Earth's main field at a site from the International Geomagnetic Reference Field (IGRF-14), through
``ppigrf`` (pure Python; the coefficient files IGRF13.shc and IGRF14.shc ship inside its wheel, so nothing
is downloaded at run time).

    B = -grad V,   V(r, theta, phi, t) = a sum_n sum_m (a / r)^(n+1) [g_n^m(t) cos m phi + h_n^m(t) sin m phi] P_n^m(cos theta)

(Alken et al. 2021, *Earth Planets Space* 73:49, IGRF-13; IGRF-14, IAGA 2024), evaluated in geodetic
coordinates (WGS84) by ``ppigrf.igrf``.  Reported in NED, uT: north, east, down, horizontal, intensity
``F``, dip (inclination, positive downward) and declination (positive east of true north).
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_param


@dataclass(frozen=True)
class Site:
    """Where and when: geodetic latitude and longitude (deg), height above the WGS84 ellipsoid (m), date
    (ISO ``YYYY-MM-DD``; IGRF-14 covers 1900-2030)."""

    lat_deg: float
    lon_deg: float
    height_m: float = 0.0
    date: str = "2025-01-01"

    def __post_init__(self):
        check_param("lat_deg", self.lat_deg, lo=-90, hi=90)
        check_param("lon_deg", self.lon_deg, lo=-180, hi=360)
        check_param("height_m", self.height_m, lo=-1e4, hi=1e6)
        when = parse_date(self.date)
        if not dt.date(1900, 1, 1) <= when <= dt.date(2030, 1, 1):
            raise InputError(f"parameter date={self.date!r}: IGRF-14 covers 1900-01-01..2030-01-01")


def parse_date(text) -> dt.date:
    if isinstance(text, dt.date):
        return text
    try:
        return dt.date.fromisoformat(str(text).strip())
    except ValueError:
        raise InputError(f"parameter date={text!r}: not a date (give YYYY-MM-DD)") from None


@dataclass(frozen=True)
class EarthField:
    """The model field at a site, NED, uT; angles in deg."""

    north_ut: float
    east_ut: float
    down_ut: float

    @property
    def horizontal_ut(self) -> float:
        return float(np.hypot(self.north_ut, self.east_ut))

    @property
    def intensity_ut(self) -> float:
        return float(np.sqrt(self.north_ut**2 + self.east_ut**2 + self.down_ut**2))

    @property
    def dip_deg(self) -> float:
        return float(np.degrees(np.arctan2(self.down_ut, self.horizontal_ut)))

    @property
    def declination_deg(self) -> float:
        return float(np.degrees(np.arctan2(self.east_ut, self.north_ut)))

    def to_dict(self) -> dict:
        return {
            "north_ut": self.north_ut,
            "east_ut": self.east_ut,
            "down_ut": self.down_ut,
            "horizontal_ut": self.horizontal_ut,
            "intensity_ut": self.intensity_ut,
            "dip_deg": self.dip_deg,
            "declination_deg": self.declination_deg,
        }


def igrf_field(site: Site) -> EarthField:
    """The IGRF-14 main field at ``site`` (module docstring)."""
    try:
        import ppigrf  # noqa: PLC0415  # lazy: ppigrf reads its coefficient files at import (0.3 s)
    except ImportError:  # a core dependency; said in one line if absent
        raise InputError(
            "the Earth-field model needs the package ppigrf (pip install ppigrf==2.1.0)"
        ) from None
    when = parse_date(site.date)
    be, bn, bu = ppigrf.igrf(
        site.lon_deg,
        site.lat_deg,
        site.height_m / 1000.0,
        dt.datetime(when.year, when.month, when.day),
    )
    return EarthField(
        float(np.ravel(bn)[0]) / 1000.0,
        float(np.ravel(be)[0]) / 1000.0,
        -float(np.ravel(bu)[0]) / 1000.0,
    )
