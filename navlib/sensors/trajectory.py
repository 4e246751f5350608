"""Flight trajectories for the INS/celestial chapter (paper E): true attitude, velocity and position, and
the ideal IMU increments that go with them.

Frames and conventions (shared by :mod:`navlib.sensors.strapdown`, :mod:`navlib.sensors.ins15` and
:mod:`navlib.methods.kalman`):

- navigation frame ``n``: local level East-North-Up (ENU);
- body frame ``b``: x right, y forward, z up (the star sensor's boresight is body z);
- attitude: ``C_b^n = Rz(yaw) Rx(pitch) Ry(roll)`` (yaw counter-clockwise from north, about Up);
  Euler angles are stored in the order ``(pitch, roll, yaw)``;
- the Euler-rate map: ``w_nb^n = M [pitch', roll', yaw']`` with paper E's matrix
  ``M = [[cos y, -sin y cos p, 0], [sin y, cos y cos p, 0], [0, sin p, 1]]`` (:func:`euler_rate_matrix`).

Two profiles (paper E section 3): ``level`` -- straight level flight at constant speed (simulation 1);
``s_turns`` -- irregular S-manoeuvres in yaw, pitch and roll held (simulation 2).  The yaw of the
S-manoeuvre is a sum of three sines with frequencies, weights and phases drawn from ``manoeuvre_seed``
(so different seeds give different manoeuvre sequences), scaled so that ``|yaw - yaw0| <= amplitude``;
the vehicle flies along its body y axis (a flat, skidding turn: roll held as in the paper).

The IMU increments over each sample interval are Simpson integrals of the analytic body rates and specific
forces, ``w_ib^b = C_n^b (w_ie^n + w_en^n + w_nb^n)`` and ``f^b = C_n^b (dv^n/dt + (2 w_ie^n + w_en^n) x v^n
- g^n)``; position follows from the velocity on a grid of half steps (trapezoid).  Integrating the
increments back with :func:`navlib.sensors.strapdown.strapdown` reproduces the truth (tested).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.integrate import cumulative_trapezoid

from ..angles import DEG
from ..errors import InputError, check_param

# WGS-84
EARTH_A_M = 6378137.0  #: equatorial radius (m)
EARTH_E2 = 0.00669437999013  #: first eccentricity squared
EARTH_RATE_RAD_S = 7.2921151467e-5  #: Earth rotation rate (rad/s)


def radii(lat_rad, h_m):
    """Meridian and prime-vertical radii plus height, ``(R_M + h, R_N + h)`` (WGS-84)."""
    s2 = np.sin(lat_rad) ** 2
    rn = EARTH_A_M / np.sqrt(1 - EARTH_E2 * s2)
    rm = rn * (1 - EARTH_E2) / (1 - EARTH_E2 * s2)
    return rm + h_m, rn + h_m


def gravity(lat_rad, h_m):
    """Normal gravity (m/s^2) at latitude and height: Somigliana with the free-air term
    ``g = 9.7803253359 (1 + 0.00193185 sin^2 L) / sqrt(1 - e^2 sin^2 L) - 3.086e-6 h``."""
    s2 = np.sin(lat_rad) ** 2
    return 9.7803253359 * (1 + 0.00193185265241 * s2) / np.sqrt(1 - EARTH_E2 * s2) - 3.086e-6 * h_m


def earth_rates(pos, vn):
    """Earth rate ``w_ie^n`` and transport rate ``w_en^n`` in ENU for positions ``pos = (L, lon, h)``
    (rad, rad, m) and velocities ``vn = (vE, vN, vU)``; arrays of shape (..., 3)."""
    pos = np.asarray(pos, float)
    vn = np.asarray(vn, float)
    lat, h = pos[..., 0], pos[..., 2]
    rmh, rnh = radii(lat, h)
    wie = np.stack(
        [np.zeros_like(lat), EARTH_RATE_RAD_S * np.cos(lat), EARTH_RATE_RAD_S * np.sin(lat)], -1
    )
    wen = np.stack([-vn[..., 1] / rmh, vn[..., 0] / rnh, vn[..., 0] * np.tan(lat) / rnh], -1)
    return wie, wen


def euler_to_dcm(att):
    """``C_b^n = Rz(yaw) Rx(pitch) Ry(roll)`` from Euler angles ``att = (pitch, roll, yaw)`` (rad),
    shape (..., 3) -> (..., 3, 3)."""
    att = np.asarray(att, float)
    p, r, y = att[..., 0], att[..., 1], att[..., 2]
    sp, cp, sr, cr, sy, cy = np.sin(p), np.cos(p), np.sin(r), np.cos(r), np.sin(y), np.cos(y)
    c = np.empty(att.shape[:-1] + (3, 3))
    c[..., 0, 0] = cy * cr - sy * sp * sr
    c[..., 0, 1] = -sy * cp
    c[..., 0, 2] = cy * sr + sy * sp * cr
    c[..., 1, 0] = sy * cr + cy * sp * sr
    c[..., 1, 1] = cy * cp
    c[..., 1, 2] = sy * sr - cy * sp * cr
    c[..., 2, 0] = -cp * sr
    c[..., 2, 1] = sp
    c[..., 2, 2] = cp * cr
    return c


def dcm_to_euler(c):
    """Euler angles ``(pitch, roll, yaw)`` (rad) of ``C_b^n = Rz(yaw) Rx(pitch) Ry(roll)``:
    ``pitch = asin(C32)``, ``roll = atan2(-C31, C33)``, ``yaw = atan2(-C12, C22)``."""
    c = np.asarray(c, float)
    return np.stack(
        [
            np.arcsin(np.clip(c[..., 2, 1], -1, 1)),
            np.arctan2(-c[..., 2, 0], c[..., 2, 2]),
            np.arctan2(-c[..., 0, 1], c[..., 1, 1]),
        ],
        -1,
    )


def euler_rate_matrix(att):
    """Paper E's matrix ``M`` (ENU): ``w_nb^n = M [pitch', roll', yaw']`` and, for small attitude errors
    ``d = (dpitch, droll, dyaw)``, the platform misalignment ``phi = -M d``;
    ``M = [[cos y, -sin y cos p, 0], [sin y, cos y cos p, 0], [0, sin p, 1]]``."""
    att = np.asarray(att, float)
    p, y = att[..., 0], att[..., 2]
    m = np.zeros(att.shape[:-1] + (3, 3))
    m[..., 0, 0] = np.cos(y)
    m[..., 0, 1] = -np.sin(y) * np.cos(p)
    m[..., 1, 0] = np.sin(y)
    m[..., 1, 1] = np.cos(y) * np.cos(p)
    m[..., 2, 1] = np.sin(p)
    m[..., 2, 2] = 1.0
    return m


@dataclass(frozen=True)
class FlightProfile:
    """The flight of paper E's simulations.

    ``kind``: ``level`` (simulation 1) or ``s_turns`` (simulation 2).  Position in degrees and metres,
    speed along the body y axis, yaw counter-clockwise from north; ``yaw_amplitude_deg`` bounds the
    S-manoeuvre's excursion from ``yaw0_deg`` and ``turn_period_s`` is the shortest period of its three
    sines (the others are drawn between it and three times it)."""

    kind: Literal["level", "s_turns"] = "level"
    duration_s: float = 150.0
    imu_rate_hz: float = 100.0
    speed_m_s: float = 200.0
    latitude_deg: float = 45.75
    longitude_deg: float = 126.6
    height_m: float = 8000.0
    yaw0_deg: float = 30.0
    pitch_deg: float = 0.0
    roll_deg: float = 0.0
    yaw_amplitude_deg: float = 30.0
    turn_period_s: float = 20.0
    manoeuvre_seed: int = 0

    def __post_init__(self):
        if self.kind not in ("level", "s_turns"):
            raise InputError(f"parameter kind={self.kind!r}: must be 'level' or 's_turns'")
        check_param("duration_s", self.duration_s, lo=1.0, hi=36000.0)
        check_param("imu_rate_hz", self.imu_rate_hz, lo=10.0, hi=2000.0)
        check_param("speed_m_s", self.speed_m_s, lo=0.0, hi=3000.0)
        check_param("latitude_deg", self.latitude_deg, lo=-80.0, hi=80.0)
        check_param("longitude_deg", self.longitude_deg, lo=-180.0, hi=360.0)
        check_param("height_m", self.height_m, lo=-1000.0, hi=30000.0)
        check_param("yaw0_deg", self.yaw0_deg, lo=-360.0, hi=360.0)
        check_param("pitch_deg", self.pitch_deg, lo=-60.0, hi=60.0)
        check_param("roll_deg", self.roll_deg, lo=-60.0, hi=60.0)
        check_param("yaw_amplitude_deg", self.yaw_amplitude_deg, lo=0.0, hi=90.0)
        check_param("turn_period_s", self.turn_period_s, lo=2.0, hi=3600.0)
        check_param("manoeuvre_seed", self.manoeuvre_seed, lo=0, integer=True)
        if (
            abs(self.duration_s * self.imu_rate_hz - round(self.duration_s * self.imu_rate_hz))
            > 1e-6
        ):
            raise InputError(
                f"parameter duration_s={self.duration_s!r}: must be a whole number of IMU "
                f"samples at imu_rate_hz={self.imu_rate_hz!r}"
            )

    @property
    def n_steps(self) -> int:
        return int(round(self.duration_s * self.imu_rate_hz))

    @property
    def dt_s(self) -> float:
        return 1.0 / self.imu_rate_hz

    def yaw_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The S-manoeuvre's sines: amplitudes (rad), angular frequencies (rad/s), phases (rad)."""
        if self.kind == "level" or self.yaw_amplitude_deg == 0:
            return np.zeros(1), np.zeros(1), np.zeros(1)
        rng = np.random.default_rng(np.random.SeedSequence(self.manoeuvre_seed).spawn(1)[0])
        periods = self.turn_period_s * rng.uniform(1.0, 3.0, 3)
        weights = rng.dirichlet(np.ones(3) * 2.0)
        phases = rng.uniform(0, 2 * np.pi, 3)
        return self.yaw_amplitude_deg * DEG * weights, 2 * np.pi / periods, phases


@dataclass(frozen=True)
class Trajectory:
    """Truth at the IMU sample times ``t_s`` (n+1 points) and the ideal IMU increments over the n intervals.

    ``att`` (pitch, roll, yaw) rad, ``vn`` ENU m/s, ``pos`` (lat rad, lon rad, h m); ``dtheta`` (rad) and
    ``dvel`` (m/s) are the body-frame angle and velocity increments, ``rate_b`` the body rate at the
    interval's midpoint (rad/s)."""

    profile: FlightProfile
    t_s: np.ndarray
    att: np.ndarray
    vn: np.ndarray
    pos: np.ndarray
    dtheta: np.ndarray
    dvel: np.ndarray
    rate_b: np.ndarray

    @property
    def cbn(self) -> np.ndarray:
        return euler_to_dcm(self.att)


def _kinematics(profile: FlightProfile, t: np.ndarray):
    """Attitude, Euler rates, velocity and acceleration (ENU) at times ``t`` (analytic)."""
    amp, om, ph = profile.yaw_terms()
    arg = np.outer(t, om) + ph
    yaw = profile.yaw0_deg * DEG + (np.sin(arg) - np.sin(ph)) @ amp
    yaw_dot = np.cos(arg) @ (amp * om)
    p = np.full_like(t, profile.pitch_deg * DEG)
    r = np.full_like(t, profile.roll_deg * DEG)
    att = np.stack([p, r, yaw], -1)
    att_dot = np.stack([np.zeros_like(t), np.zeros_like(t), yaw_dot], -1)
    cp = np.cos(p)
    s = profile.speed_m_s
    vn = s * np.stack([-np.sin(yaw) * cp, np.cos(yaw) * cp, np.sin(p)], -1)
    an = s * np.stack(
        [-np.cos(yaw) * cp * yaw_dot, -np.sin(yaw) * cp * yaw_dot, np.zeros_like(t)], -1
    )
    return att, att_dot, vn, an


def _position(profile: FlightProfile, t: np.ndarray, vn: np.ndarray) -> np.ndarray:
    """Latitude, longitude, height along the fine grid ``t`` by trapezoidal integration of
    ``L' = vN/(R_M+h)``, ``lon' = vE/((R_N+h) cos L)``, ``h' = vU`` (two passes: the radii of the second
    pass follow the latitude of the first)."""
    lat0, h0 = profile.latitude_deg * DEG, profile.height_m
    h = h0 + cumulative_trapezoid(vn[:, 2], t, initial=0.0)
    lat = np.full_like(t, lat0)
    for _ in range(2):
        rmh, rnh = radii(lat, h)
        lat = lat0 + cumulative_trapezoid(vn[:, 1] / rmh, t, initial=0.0)
    rmh, rnh = radii(lat, h)
    lon = profile.longitude_deg * DEG + cumulative_trapezoid(
        vn[:, 0] / (rnh * np.cos(lat)), t, initial=0.0
    )
    return np.stack([lat, lon, h], -1)


def _body_signals(profile: FlightProfile, t: np.ndarray):
    att, att_dot, vn, an = _kinematics(profile, t)
    pos = _position(profile, t, vn)
    cbn = euler_to_dcm(att)
    wie, wen = earth_rates(pos, vn)
    wnb_n = np.einsum("kij,kj->ki", euler_rate_matrix(att), att_dot)
    w_b = np.einsum("kji,kj->ki", cbn, wie + wen + wnb_n)
    gn = np.zeros_like(vn)
    gn[:, 2] = -gravity(pos[:, 0], pos[:, 2])
    f_n = an + np.cross(2 * wie + wen, vn) - gn
    f_b = np.einsum("kji,kj->ki", cbn, f_n)
    return att, vn, pos, w_b, f_b


def generate(profile: FlightProfile = FlightProfile()) -> Trajectory:
    """Generate the trajectory and its ideal IMU increments (Simpson's rule on the half-step grid).

    Returns
    -------
    Trajectory
        truth at ``t_k = k / imu_rate_hz`` and increments over ``[t_{k-1}, t_k]``.
    """
    n, dt = profile.n_steps, profile.dt_s
    tf = np.arange(2 * n + 1) * (dt / 2)
    att, vn, pos, w_b, f_b = _body_signals(profile, tf)
    simpson = lambda x: (x[0:-2:2] + 4 * x[1:-1:2] + x[2::2]) * (dt / 6)  # noqa: E731
    return Trajectory(
        profile=profile,
        t_s=tf[::2],
        att=att[::2],
        vn=vn[::2],
        pos=pos[::2],
        dtheta=simpson(w_b),
        dvel=simpson(f_b),
        rate_b=w_b[1::2],
    )
