"""Static-base error propagation of a single-axis rotation strapdown INS, and the Table 1 closed forms of
paper C (Yu et al. 2012, J. NUDT 34(3)) with their inverse (12 h latitude error -> axial gyro drift).

Sign conventions (used everywhere in this module and in the gyro chapter)
-------------------------------------------------------------------------
* Errors are *indicated minus true*: latitude error ``dL = L_ins - L_true``, likewise longitude, velocity.
* A gyro drift ``eps`` is the gyro's output minus the true rate (what has to be *subtracted* to correct it).
* Attitude error ``phi`` (phi-angle, local-level East-North-Up frame n) obeys Titterton & Weston's
  ``phi_dot = -w_in x phi + dw_in - C_b^n eps``.

With these conventions a positive axial drift gives a positive 12 h latitude error, which is what the measured
Tables 2-4 of the paper show (larger latitude output <-> positive drift).  Paper C's Table 1 prints the axial
drift term with the opposite sign, ``[-cos L / w_ie + cos L / w_ie cos(w_ie t)] eps``: its ``eps`` is the
opposite of ours (a correction rather than an error).  Its initial north velocity term is printed as
``dV_N sin(w_s t) / (R cos L g)``, which is not dimensionally a latitude; the Schuler solution is
``dV_N sin(w_s t) / (R w_s)`` and that is what :func:`table1_latitude_error` uses.

Error model (static base, v = 0, ENU, vertical channel omitted; Titterton & Weston 2004, ch. 12)::

    phi_E' =  W sinL phi_N - W cosL phi_U - dV_N / R                       - eps_E
    phi_N' = -W sinL phi_E + dV_E / R           - W sinL dL                 - eps_N
    phi_U' =  W cosL phi_E + tanL dV_E / R      + W cosL dL                 - eps_U
    dV_E'  = -g phi_N + 2 W sinL dV_N                                       + acc_E
    dV_N'  =  g phi_E - 2 W sinL dV_E                                       + acc_N
    dL'    =  dV_N / R
    dlon'  =  dV_E / (R cosL)

(``W`` Earth rate, ``g/R`` gives the Schuler loop, ``2 W sinL`` the Foucault coupling).  Sensor errors are
given in the body frame; the IMU turns about the vertical axis so ``eps^n = Rz(theta(t)) eps^b``: horizontal
gyro and accelerometer errors are modulated, the axial (vertical) drift ``eps_U = eps_z`` is not.

The system is linear and time-invariant; the forcing is held constant over each step of ``step_s`` seconds
(exact for indexing rotation whose dwell is a multiple of the step; for continuous rotation the forcing is the
exact average of ``Rz(theta)`` over the step).  Each step is then propagated exactly with the matrix
exponential of the augmented system ``[[A, B], [0, 0]]`` -- 72 h at 60 s steps is 4320 small mat-vec products.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Callable

import numpy as np
from scipy.linalg import expm
from scipy.optimize import minimize_scalar

from ..angles import ARCSEC, DEG
from ..errors import InputError, check_param
from ..seeding import child, sequence
from ..data.gyro_tables import (
    LOCAL_LATITUDE_DEG,
)  # paper C, the test site (re-exported: ins.LOCAL_LATITUDE_DEG)

DEG_H = DEG / 3600.0  # 1 deg/h in rad/s
UG = 9.80665e-6  # 1 micro-g in m/s^2
NMI = 1852.0

STATE_NAMES = ("phi_E", "phi_N", "phi_U", "dV_E", "dV_N", "dL", "dlon")


# ---------------------------------------------------------------------------------------------- parameters
@dataclass(frozen=True)
class Earth:
    """Site and Earth constants. ``gravity_m_s2=None`` uses the normal gravity at the latitude
    (``9.7803253359 (1 + 0.00193185 sin^2 L) / sqrt(1 - 0.00669438 sin^2 L)``, Somigliana/WGS-84)."""

    latitude_deg: float = LOCAL_LATITUDE_DEG
    radius_m: float = 6378137.0
    earth_rate_rad_s: float = 7.2921151467e-5
    gravity_m_s2: float | None = None

    def __post_init__(self):
        check_param("latitude_deg", self.latitude_deg, lo=-89.0, hi=89.0)
        check_param("radius_m", self.radius_m, lo=0, lo_open=True)
        check_param("earth_rate_rad_s", self.earth_rate_rad_s, lo=0)
        if self.gravity_m_s2 is not None:
            check_param("gravity_m_s2", self.gravity_m_s2, lo=0, lo_open=True)

    @property
    def lat_rad(self) -> float:
        return self.latitude_deg * DEG

    @property
    def g(self) -> float:
        if self.gravity_m_s2 is not None:
            return float(self.gravity_m_s2)
        s2 = math.sin(self.lat_rad) ** 2
        return 9.7803253359 * (1 + 0.00193185265241 * s2) / math.sqrt(1 - 0.00669437999013 * s2)

    @property
    def schuler_rad_s(self) -> float:
        return math.sqrt(self.g / self.radius_m)

    @property
    def schuler_period_min(self) -> float:
        return 2 * math.pi / self.schuler_rad_s / 60.0


@dataclass(frozen=True)
class ImuErrors:
    """Residual sensor errors in the body frame (x, y horizontal, z = rotation axis) after the horizontal
    calibration of the alignment.  ``axial_drift_deg_h`` is the constant (hot-state) axial gyro drift;
    ``gyro_arw_deg_rt_h`` white rate noise on every gyro (angle random walk), ``accel_noise_ug_rt_hz`` white
    acceleration noise on the horizontal accelerometers."""

    gyro_bias_x_deg_h: float = 0.0
    gyro_bias_y_deg_h: float = 0.0
    axial_drift_deg_h: float = 0.0
    accel_bias_x_ug: float = 0.0
    accel_bias_y_ug: float = 0.0
    gyro_arw_deg_rt_h: float = 0.0
    accel_noise_ug_rt_hz: float = 0.0

    def __post_init__(self):
        for f in (
            "gyro_bias_x_deg_h",
            "gyro_bias_y_deg_h",
            "axial_drift_deg_h",
            "accel_bias_x_ug",
            "accel_bias_y_ug",
        ):
            check_param(f, getattr(self, f))
        check_param("gyro_arw_deg_rt_h", self.gyro_arw_deg_rt_h, lo=0)
        check_param("accel_noise_ug_rt_hz", self.accel_noise_ug_rt_hz, lo=0)


@dataclass(frozen=True)
class InitialErrors:
    """Errors at the start of navigation (the outcome of the 4 h alignment): level tilts about East and
    North, azimuth error about Up, horizontal velocity errors.  Position starts exact (static base)."""

    tilt_east_arcsec: float = 0.0
    tilt_north_arcsec: float = 0.0
    azimuth_arcsec: float = 0.0
    vel_east_m_s: float = 0.0
    vel_north_m_s: float = 0.0

    def state(self) -> np.ndarray:
        return np.array(
            [
                self.tilt_east_arcsec * ARCSEC,
                self.tilt_north_arcsec * ARCSEC,
                self.azimuth_arcsec * ARCSEC,
                self.vel_east_m_s,
                self.vel_north_m_s,
                0.0,
                0.0,
            ]
        )


@dataclass(frozen=True)
class Rotation:
    """IMU rotation about the vertical axis.  ``kind``: ``"none"``; ``"indexing"`` (stop at
    ``positions_deg`` in turn, ``dwell_s`` at each; the usual 4-position 0/180/90/270 sequence);
    ``"continuous"`` (constant ``rate_deg_s``)."""

    kind: str = "indexing"
    positions_deg: tuple[float, ...] = (0.0, 180.0, 90.0, 270.0)
    dwell_s: float = 300.0
    rate_deg_s: float = 0.5

    def __post_init__(self):
        if self.kind not in ("none", "indexing", "continuous"):
            raise InputError(
                f"parameter rotation kind={self.kind!r}: must be 'none', 'indexing' or 'continuous'"
            )
        check_param("dwell_s", self.dwell_s, lo=0, lo_open=True)
        check_param("rate_deg_s", self.rate_deg_s)
        if self.kind == "indexing" and not self.positions_deg:
            raise InputError("parameter positions_deg: needs at least one position")

    def mean_cos_sin(
        self, t0_s: float, n_steps: int, step_s: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Average of ``cos(theta)``, ``sin(theta)`` over each step ``[t0 + k step, t0 + (k+1) step)``."""
        k = np.arange(n_steps)
        if self.kind == "none":
            return np.ones(n_steps), np.zeros(n_steps)
        if self.kind == "continuous":
            w = self.rate_deg_s * DEG
            th0 = w * (t0_s + k * step_s)
            if w == 0:
                return np.cos(th0), np.sin(th0)
            d = w * step_s
            return (np.sin(th0 + d) - np.sin(th0)) / d, (np.cos(th0) - np.cos(th0 + d)) / d
        ratio = self.dwell_s / step_s
        if abs(ratio - round(ratio)) > 1e-9:
            raise InputError(
                f"parameter dwell_s={self.dwell_s!r}: must be a whole multiple of the step "
                f"({step_s:g} s)"
            )
        pos = np.asarray(self.positions_deg, float) * DEG
        idx = (np.floor((t0_s + k * step_s) / self.dwell_s + 1e-9).astype(int)) % len(pos)
        return np.cos(pos[idx]), np.sin(pos[idx])


@dataclass(frozen=True)
class ColdStart:
    """Cold-start temperature history and its effect on the axial drift (paper C section 2.3).

    Temperature (C) is piecewise linear through the printed end points of Tables 4-5: from
    ``align_temp_min_c`` at power-on to ``calib_temp_min_c`` at the end of the ``align_h`` initial alignment,
    then to ``calib_temp_max_c`` at the end of the ``identify_h`` identification window, constant afterwards
    (the paper's cold tests keep the temperature steady while navigating).  The axial drift follows::

        eps(t) = eps_final + drift_per_c_deg_h * (T(t) - T_end) + drift_per_c_h_deg_h * dT/dt(t)

    so after warm-up the drift is ``eps_final``, while during the identification window it is biased by the
    temperature level and rate -- which is what misleads a drift estimate made from the 12 h latitude error.
    ``drift_per_c_h_deg_h`` is in (deg/h) per (C/h)."""

    align_temp_min_c: float
    calib_temp_min_c: float
    calib_temp_max_c: float
    drift_per_c_deg_h: float = 0.0
    drift_per_c_h_deg_h: float = 0.0
    align_h: float = 4.0
    identify_h: float = 12.0

    def __post_init__(self):
        for f in ("align_temp_min_c", "calib_temp_min_c", "calib_temp_max_c"):
            check_param(f, getattr(self, f), lo=-60, hi=120)
        check_param("drift_per_c_deg_h", self.drift_per_c_deg_h)
        check_param("drift_per_c_h_deg_h", self.drift_per_c_h_deg_h)
        check_param("align_h", self.align_h, lo=0, lo_open=True)
        check_param("identify_h", self.identify_h, lo=0, lo_open=True)

    def temperature_c(self, t_h) -> np.ndarray:
        t = np.asarray(t_h, float)
        return np.interp(
            t,
            [0.0, self.align_h, self.align_h + self.identify_h],
            [self.align_temp_min_c, self.calib_temp_min_c, self.calib_temp_max_c],
        )

    def rate_c_h(self, t_h) -> np.ndarray:
        t = np.asarray(t_h, float)
        r1 = (self.calib_temp_min_c - self.align_temp_min_c) / self.align_h
        r2 = (self.calib_temp_max_c - self.calib_temp_min_c) / self.identify_h
        return np.where(t < self.align_h, r1, np.where(t < self.align_h + self.identify_h, r2, 0.0))

    def axial_drift_deg_h(self, t_h, final_drift_deg_h: float) -> np.ndarray:
        return (
            final_drift_deg_h
            + self.drift_per_c_deg_h * (self.temperature_c(t_h) - self.calib_temp_max_c)
            + self.drift_per_c_h_deg_h * self.rate_c_h(t_h)
        )


# ---------------------------------------------------------------------------------------------- the model
def system_matrices(earth: Earth) -> tuple[np.ndarray, np.ndarray]:
    """``A`` (7 x 7) and ``B`` (7 x 5, inputs ``[eps_E, eps_N, eps_U, acc_E, acc_N]`` in rad/s, m/s^2) of the
    static-base error model in the module docstring."""
    W, R, g = earth.earth_rate_rad_s, earth.radius_m, earth.g
    L = earth.lat_rad
    s, c, tn = math.sin(L), math.cos(L), math.tan(L)
    A = np.zeros((7, 7))
    A[0, 1], A[0, 2], A[0, 4] = W * s, -W * c, -1 / R
    A[1, 0], A[1, 3], A[1, 5] = -W * s, 1 / R, -W * s
    A[2, 0], A[2, 3], A[2, 5] = W * c, tn / R, W * c
    A[3, 1], A[3, 4] = -g, 2 * W * s
    A[4, 0], A[4, 3] = g, -2 * W * s
    A[5, 4] = 1 / R
    A[6, 3] = 1 / (R * c)
    B = np.zeros((7, 5))
    B[0:3, 0:3] = -np.eye(3)
    B[3:5, 3:5] = np.eye(2)
    return A, B


@lru_cache(maxsize=32)
def _discrete(earth: Earth, step_s: float) -> tuple[np.ndarray, np.ndarray]:
    A, B = system_matrices(earth)
    M = np.zeros((12, 12))
    M[:7, :7], M[:7, 7:] = A, B
    E = expm(M * step_s)
    return E[:7, :7], E[:7, 7:]


@dataclass
class NavErrors:
    """Error history on a grid of ``t_h`` hours (relative to the start of this navigation run)."""

    t_h: np.ndarray
    states: np.ndarray  # (K+1, 7), see STATE_NAMES; angles in rad, velocities in m/s
    earth: Earth

    @property
    def latitude_error_deg(self) -> np.ndarray:
        return self.states[:, 5] / DEG

    @property
    def longitude_error_deg(self) -> np.ndarray:
        return self.states[:, 6] / DEG

    @property
    def north_m(self) -> np.ndarray:
        return self.states[:, 5] * self.earth.radius_m

    @property
    def east_m(self) -> np.ndarray:
        return self.states[:, 6] * self.earth.radius_m * math.cos(self.earth.lat_rad)

    @property
    def position_error_nmi(self) -> np.ndarray:
        """Radial position error ``R sqrt(dL^2 + (cos L dlon)^2)`` in nautical miles."""
        return np.hypot(self.north_m, self.east_m) / NMI

    def at(self, t_h: float) -> np.ndarray:
        """State at the grid time nearest ``t_h``."""
        return self.states[int(np.argmin(np.abs(self.t_h - t_h)))]


def simulate(
    duration_h: float,
    *,
    earth: Earth = Earth(),
    imu: ImuErrors = ImuErrors(),
    initial: InitialErrors | np.ndarray = InitialErrors(),
    rotation: Rotation = Rotation(),
    step_s: float = 60.0,
    axial_drift_deg_h: np.ndarray | None = None,
    t0_s: float = 0.0,
    seed: int | None = 0,
) -> NavErrors:
    """Propagate the navigation errors for ``duration_h`` hours.

    ``axial_drift_deg_h``: optional per-step axial drift (length = number of steps) replacing the constant
    ``imu.axial_drift_deg_h`` (cold start); ``t0_s`` sets the rotation phase; ``seed`` the noise draw.
    """
    check_param("duration_h", duration_h, lo=0, lo_open=True)
    check_param("step_s", step_s, lo=0, lo_open=True)
    n = int(round(duration_h * 3600.0 / step_s))
    if n < 1:
        raise InputError(
            f"parameter duration_h={duration_h!r}: shorter than one step ({step_s:g} s)"
        )
    Phi, Gam = _discrete(earth, float(step_s))
    cs, sn = rotation.mean_cos_sin(t0_s, n, step_s)
    gx, gy = imu.gyro_bias_x_deg_h * DEG_H, imu.gyro_bias_y_deg_h * DEG_H
    ax, ay = imu.accel_bias_x_ug * UG, imu.accel_bias_y_ug * UG
    if axial_drift_deg_h is None:
        ez = np.full(n, imu.axial_drift_deg_h * DEG_H)
    else:
        ez = np.asarray(axial_drift_deg_h, float) * DEG_H
        if ez.shape != (n,):
            raise InputError(f"axial_drift_deg_h has {ez.size} values, the run has {n} steps")
    gxb = np.full(n, gx)
    gyb = np.full(n, gy)
    axb = np.full(n, ax)
    ayb = np.full(n, ay)
    if imu.gyro_arw_deg_rt_h > 0 or imu.accel_noise_ug_rt_hz > 0:
        rng = np.random.default_rng(seed)
        sg = imu.gyro_arw_deg_rt_h * DEG / 60.0 / math.sqrt(step_s)  # deg/sqrt(h) -> rad/s per step
        sa = imu.accel_noise_ug_rt_hz * UG / math.sqrt(step_s)
        noise = rng.standard_normal((n, 5))
        gxb, gyb, ez = gxb + sg * noise[:, 0], gyb + sg * noise[:, 1], ez + sg * noise[:, 2]
        axb, ayb = axb + sa * noise[:, 3], ayb + sa * noise[:, 4]
    # body -> nav: Rz(theta) about Up (averaged over the step)
    u = np.empty((n, 5))
    u[:, 0] = cs * gxb - sn * gyb
    u[:, 1] = sn * gxb + cs * gyb
    u[:, 2] = ez
    u[:, 3] = cs * axb - sn * ayb
    u[:, 4] = sn * axb + cs * ayb
    forced = u @ Gam.T
    x = np.empty((n + 1, 7))
    x[0] = initial.state() if isinstance(initial, InitialErrors) else np.asarray(initial, float)
    for k in range(n):
        x[k + 1] = Phi @ x[k] + forced[k]
    return NavErrors(t_h=np.arange(n + 1) * step_s / 3600.0, states=x, earth=earth)


# ---------------------------------------------------------------------------------------------- Table 1
def table1_latitude_error(
    t_h,
    *,
    earth: Earth = Earth(),
    axial_drift_deg_h: float = 0.0,
    north_accel_bias_ug: float = 0.0,
    azimuth_error_arcsec: float = 0.0,
    north_velocity_error_m_s: float = 0.0,
) -> np.ndarray:
    """Paper C Table 1, latitude error (deg) on a static base, in this module's sign conventions::

        dL = (cos L / W)(1 - cos W t) eps                                    axial gyro drift
           + acc_N / (R (W^2 - w_s^2)) (cos w_s t - cos W t)                 north accelerometer bias
           - phi_U (cos L sin W t + (W / w_s) cos L sin w_s t)               initial azimuth error
           + dV_N sin(w_s t) / (R w_s)                                       initial north velocity error

    (the paper prints the first term with the opposite sign -- its eps is our -eps -- and the last with
    ``R cos L g`` in the denominator, a misprint; see the module docstring)."""
    t = np.asarray(t_h, float) * 3600.0
    W, ws, R, L = earth.earth_rate_rad_s, earth.schuler_rad_s, earth.radius_m, earth.lat_rad
    c = math.cos(L)
    dl = (c / W) * (1 - np.cos(W * t)) * axial_drift_deg_h * DEG_H
    dl = dl + north_accel_bias_ug * UG / (R * (W**2 - ws**2)) * (np.cos(ws * t) - np.cos(W * t))
    dl = dl - azimuth_error_arcsec * ARCSEC * (c * np.sin(W * t) + (W / ws) * c * np.sin(ws * t))
    dl = dl + north_velocity_error_m_s * np.sin(ws * t) / (R * ws)
    return dl / DEG


def latitude_error_per_drift(t_h: float = 12.0, earth: Earth = Earth()) -> float:
    """Table 1 gain: latitude error (deg) after ``t_h`` hours per 1 deg/h of axial drift,
    ``(cos L / W)(1 - cos W t)`` (= 2 cos L / W at 12 h, about 6.71 deg per deg/h at L = 28.222 deg)."""
    return float(table1_latitude_error(t_h, earth=earth, axial_drift_deg_h=1.0))


def drift_from_latitude_error(
    latitude_error_deg, t_h: float = 12.0, earth: Earth = Earth()
) -> np.ndarray:
    """Inverse of the Table 1 axial-drift term: the axial drift (deg/h) that alone would produce
    ``latitude_error_deg`` after ``t_h`` hours of navigation on a static base -- the physics baseline."""
    check_param("t_h", t_h, lo=0, lo_open=True)
    k = latitude_error_per_drift(t_h, earth)
    if 1 - math.cos(earth.earth_rate_rad_s * t_h * 3600.0) < 0.01:
        raise InputError(
            f"parameter t_h={t_h!r}: too close to a whole number of sidereal days, the latitude "
            f"error hardly depends on the axial drift then"
        )
    return np.asarray(latitude_error_deg, float) / k


# ---------------------------------------------------------------------------------------------- procedure
@dataclass(frozen=True)
class Procedure:
    """Paper C's test procedure: ``align_h`` alignment (modelled by its outcome, the initial errors),
    ``identify_h`` navigation whose final latitude error identifies the axial drift, then position and
    velocity reset (static base, known position), the identified drift subtracted, and ``navigate_h`` of
    navigation on which the position error is reported."""

    align_h: float = 4.0
    identify_h: float = 12.0
    navigate_h: float = 72.0
    step_s: float = 60.0

    def __post_init__(self):
        check_param("align_h", self.align_h, lo=0)
        check_param("identify_h", self.identify_h, lo=0, lo_open=True)
        check_param("navigate_h", self.navigate_h, lo=0, lo_open=True)
        check_param("step_s", self.step_s, lo=0, lo_open=True)


@dataclass
class ProcedureResult:
    identify_run: NavErrors
    latitude_error_12h_deg: float
    final_drift_deg_h: float  # the axial drift during the navigation after identification
    identified_drift_deg_h: float
    after: NavErrors  # navigation with the identified drift subtracted
    before: NavErrors  # same navigation without any axial compensation
    best_drift_deg_h: float  # the paper's "true drift": compensation minimising the 72 h error
    unit_response: NavErrors = field(repr=False, default=None)

    def position_error_nmi_for(self, compensation_deg_h: float) -> np.ndarray:
        """72 h position error (nmi) had ``compensation_deg_h`` been subtracted instead of the identified
        drift: the errors are affine in the residual axial drift, so this is exact without a re-run."""
        e = self.final_drift_deg_h - float(compensation_deg_h)
        n = self.before.north_m + (e - self.final_drift_deg_h) * self.unit_response.north_m
        east = self.before.east_m + (e - self.final_drift_deg_h) * self.unit_response.east_m
        return np.hypot(n, east) / NMI

    @property
    def max_error_after_nmi(self) -> float:
        return float(self.after.position_error_nmi.max())

    @property
    def max_error_before_nmi(self) -> float:
        return float(self.before.position_error_nmi.max())


def run_procedure(
    identify: Callable[[float], float] | None,
    *,
    imu: ImuErrors = ImuErrors(),
    initial: InitialErrors = InitialErrors(),
    earth: Earth = Earth(),
    rotation: Rotation = Rotation(),
    procedure: Procedure = Procedure(),
    cold: ColdStart | None = None,
    seed: int | np.random.SeedSequence | None = 0,
) -> ProcedureResult:
    """Run align -> identify -> compensate -> navigate.

    ``seed`` (an integer entropy or a ``numpy.random.SeedSequence``) draws the noise of the identification
    run; the navigation runs draw theirs from the child with spawn key ``seed.spawn_key + (1,)``.

    ``identify(latitude_error_12h_deg) -> drift_deg_h`` is the identification method (a network, the
    Table 1 inverse...); ``None`` means the Table 1 inverse.  In cold mode the axial drift follows
    ``cold.axial_drift_deg_h(t, imu.axial_drift_deg_h)`` during the identification window and is
    ``imu.axial_drift_deg_h`` afterwards.
    """
    p = procedure
    dt = p.step_s
    n_id = int(round(p.identify_h * 3600 / dt))
    t_mid = p.align_h + (np.arange(n_id) + 0.5) * dt / 3600.0  # hours since power-on
    drift_hist = None
    if cold is not None:
        drift_hist = cold.axial_drift_deg_h(t_mid, imu.axial_drift_deg_h)
    t0 = p.align_h * 3600.0
    run1 = simulate(
        p.identify_h,
        earth=earth,
        imu=imu,
        initial=initial,
        rotation=rotation,
        step_s=dt,
        axial_drift_deg_h=drift_hist,
        t0_s=t0,
        seed=seed,
    )
    lat12 = float(run1.latitude_error_deg[-1])
    est = float(
        drift_from_latitude_error(lat12, p.identify_h, earth)
        if identify is None
        else identify(lat12)
    )
    x_reset = run1.states[-1].copy()
    x_reset[3:] = 0.0  # velocity and position known
    t1 = t0 + p.identify_h * 3600.0
    # the navigation stage draws its own noise: part 1 of the run's seed (SeedSequence spawn key, no arithmetic)
    seed2 = None if seed is None else child(seed, 1)

    def nav(drift):
        return simulate(
            p.navigate_h,
            earth=earth,
            imu=replace(imu, axial_drift_deg_h=drift),
            initial=x_reset,
            rotation=rotation,
            step_s=dt,
            t0_s=t1,
            seed=seed2,
        )

    after = nav(imu.axial_drift_deg_h - est)
    before = nav(imu.axial_drift_deg_h)
    unit = simulate(
        p.navigate_h,
        earth=earth,
        imu=ImuErrors(axial_drift_deg_h=1.0),
        initial=np.zeros(7),
        rotation=rotation,
        step_s=dt,
        t0_s=t1,
        seed=None,
    )
    # position error is affine in the residual drift e: p(e) = p(0) + e * p_unit
    base_n = before.north_m - imu.axial_drift_deg_h * unit.north_m
    base_e = before.east_m - imu.axial_drift_deg_h * unit.east_m

    def worst(e):
        return float(np.max(np.hypot(base_n + e * unit.north_m, base_e + e * unit.east_m)))

    span = 0.02
    res = minimize_scalar(
        worst,
        bounds=(imu.axial_drift_deg_h - span, imu.axial_drift_deg_h + span),
        method="bounded",
        options={"xatol": 1e-8},
    )
    best = imu.axial_drift_deg_h - float(res.x)  # compensation value c with residual e = drift - c
    return ProcedureResult(
        identify_run=run1,
        latitude_error_12h_deg=lat12,
        final_drift_deg_h=imu.axial_drift_deg_h,
        identified_drift_deg_h=est,
        after=after,
        before=before,
        best_drift_deg_h=best,
        unit_response=unit,
    )


def random_test(
    rng: np.random.Generator,
    *,
    axial_drift_deg_h: float,
    gyro_bias_sd_deg_h: float = 0.002,
    accel_bias_sd_ug: float = 20.0,
    gyro_arw_deg_rt_h: float = 0.0003,
    tilt_sd_arcsec: float = 1.0,
    azimuth_sd_arcsec: float = 10.0,
    velocity_sd_m_s: float = 0.01,
) -> tuple[ImuErrors, InitialErrors]:
    """Draw one simulated test: residual horizontal sensor errors after calibration and the alignment
    outcome, all zero-mean normal with the given standard deviations."""
    g = rng.normal(0, gyro_bias_sd_deg_h, 2)
    a = rng.normal(0, accel_bias_sd_ug, 2)
    tl = rng.normal(0, tilt_sd_arcsec, 2)
    imu = ImuErrors(
        gyro_bias_x_deg_h=float(g[0]),
        gyro_bias_y_deg_h=float(g[1]),
        axial_drift_deg_h=float(axial_drift_deg_h),
        accel_bias_x_ug=float(a[0]),
        accel_bias_y_ug=float(a[1]),
        gyro_arw_deg_rt_h=gyro_arw_deg_rt_h,
    )
    init = InitialErrors(
        tilt_east_arcsec=float(tl[0]),
        tilt_north_arcsec=float(tl[1]),
        azimuth_arcsec=float(rng.normal(0, azimuth_sd_arcsec)),
        vel_east_m_s=float(rng.normal(0, velocity_sd_m_s)),
        vel_north_m_s=float(rng.normal(0, velocity_sd_m_s)),
    )
    return imu, init


def simulated_tests(
    axial_drifts_deg_h,
    *,
    seed: int,
    identify: Callable[[float], float] | None = None,
    cold: list[ColdStart | None] | None = None,
    earth: Earth = Earth(),
    rotation: Rotation = Rotation(),
    procedure: Procedure = Procedure(),
    **error_sd,
) -> list[ProcedureResult]:
    """Run the procedure once per axial drift, each test with its own residual sensor errors and alignment
    outcome drawn by :func:`random_test` (``error_sd``: its standard deviations); ``cold[i]`` optionally
    gives test i a cold-start temperature history.  Test ``i`` draws its errors from
    ``SeedSequence(seed, spawn_key=(i, 0))`` and its noise from ``SeedSequence(seed, spawn_key=(i, 1))``:
    every test and every part of it has its own stream."""
    drifts = np.atleast_1d(np.asarray(axial_drifts_deg_h, float))
    if cold is not None and len(cold) != drifts.size:
        raise InputError(f"{len(cold)} cold-start histories for {drifts.size} tests")
    out = []
    for i, d in enumerate(drifts):
        errors = sequence(seed, i, 0)
        imu, init = random_test(
            np.random.default_rng(errors), axial_drift_deg_h=float(d), **error_sd
        )
        out.append(
            run_procedure(
                identify,
                imu=imu,
                initial=init,
                earth=earth,
                rotation=rotation,
                procedure=procedure,
                cold=None if cold is None else cold[i],
                seed=sequence(seed, i, 1),
            )
        )
    return out
