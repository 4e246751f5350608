"""Electronic-compass turntable simulator and the exact planar heading-error model.

Physical story (paper A, Yue et al.): a three-axis magnetometer compass is mounted on a carrier whose
ferrous structure, DC supply and electronics sit close to it. The carrier stands on a level non-magnetic
turntable that turns it through a full revolution, read every 3 deg from north (121 readings, 0..360 deg
inclusive). The compass computes heading from the horizontal field components it measures.

Frames: NED navigation frame; body (carrier) frame x forward, y right, z down; the turntable angle is the
true magnetic heading ``psi`` (clockwise from magnetic north).  On a level table the Earth field seen in
the body frame is

    m_b(psi) = [H cos psi, -H sin psi, Z],   H = F cos I,  Z = F sin I           (dip I, total field F)

The carrier distorts it (soft iron ``S``: induced magnetisation proportional to the field; hard iron ``h``:
permanent magnetisation, possibly drifting with temperature), the sensor is mounted with a small rotation
``R`` (roll, pitch, yaw misalignment) and has its own per-axis scale errors ``K`` and non-orthogonality
``N`` (lower-triangular, small angles), plus white noise ``n``:

    m_meas = (I + K) N R [ (I + S) m_b + h(T) ] + n,     h(T) = h0 + dh/dT (T - T0)

and the heading is ``psi_m = atan2(-m_y, m_x)`` (level compass, no tilt compensation).  The heading error
is ``wrap(psi_m - psi)`` in (-180, 180].

Exact planar model.  Because the table is level, ``Z`` is constant over a sweep, so every effect above
(including tilt misalignment leaking ``Z`` into x and y) makes the measured horizontal field an affine
function of the true horizontal unit vector ``r(psi) = [cos psi, -sin psi]``:  ``m_xy = A r + c``.  Heading
sees only the direction of ``m_xy``, so the overall scale of ``A`` is unobservable and exactly five
parameters remain.  We write them as named physical effects:

    m_xy  ∝  Rot(yaw) [ (I + [[e, f], [f, -e]]) r(psi) + [hx, hy] ]

``misalignment`` = ``yaw`` (a rotation: a constant heading offset), ``soft_iron`` = ``(e, f)`` (the symmetric,
trace-free distortion: a two-cycle error), ``hard_iron`` = ``(hx, hy)`` in units of ``H`` (a one-cycle
error).  This model is *exact* (not a truncated harmonic series); Archibald Smith's A..E deviation
series (:mod:`navlib.methods.smith`) is its first-order harmonic approximation.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
import pandas as pd

from ..angles import heading_deg, wrap_deg
from ..errors import InputError, check_param
from .earth_field import Site, igrf_field

#: Where and when the simulator's default field is taken: Shenyang (41.8 N, 123.4 E, where paper A's
#: authors work), at sea level, on 2020-01-01.
COMPASS_SITE = Site(41.8, 123.4, 0.0, "2020-01-01")


@lru_cache(maxsize=1)
def _site_field() -> tuple[float, float]:
    f = igrf_field(COMPASS_SITE)
    return f.intensity_ut, f.dip_deg


@dataclass(frozen=True)
class EarthField:
    """The local geomagnetic field: total intensity (uT) and dip (deg, positive downward).  Defaults: the
    IGRF-14 main field at :data:`COMPASS_SITE` (:func:`navlib.sensors.earth_field.igrf_field`, computed by
    ppigrf on first use, offline).  Paper A's chapter keeps the round field it was built with,
    :data:`PAPER_A_EARTH`, explicitly."""

    total_ut: float = field(default_factory=lambda: _site_field()[0])
    dip_deg: float = field(default_factory=lambda: _site_field()[1])

    def __post_init__(self):
        check_param("total_ut", self.total_ut, lo=0, lo_open=True, hi=1e6)
        check_param("dip_deg", self.dip_deg, lo=-90, hi=90)

    @property
    def horizontal_ut(self) -> float:
        return self.total_ut * np.cos(np.radians(self.dip_deg))

    @property
    def vertical_ut(self) -> float:
        return self.total_ut * np.sin(np.radians(self.dip_deg))


#: The field paper A's simulations were built with, before the default came from IGRF (54.3 uT and 60.05
#: deg there): a round 54 uT at 60 deg dip.  Paper A's study, the stored sweeps (``data/compass_sweeps.csv``)
#: and ``navlib simulate-compass`` pass it explicitly, so that none of their numbers moves.
PAPER_A_EARTH = EarthField(total_ut=54.0, dip_deg=60.0)


@dataclass(frozen=True)
class CompassErrors:
    """Error sources of a carrier-mounted three-axis magnetometer compass (see module docstring).

    Defaults tell a plausible story: the compass sits about a decimetre from steel structure and a DC
    supply, whose permanent magnetisation (hard iron, ~10 uT, over a third of H) dominates; the steel's induced
    magnetisation (soft iron, up to 8 per cent) adds a two-cycle error; the sensor has 1-2 % scale mismatch,
    a fraction of a degree non-orthogonality and a 1.6 deg mounting yaw.  With these values the
    uncompensated heading error spans about -16..+30.7 deg, as in paper A's Fig 2.
    """

    hard_iron_ut: tuple[float, float, float] = (-6.1, 7.7, 3.0)
    soft_iron: tuple[tuple[float, float, float], ...] = (
        (0.08, 0.08, 0.01),
        (-0.03, -0.08, 0.00),
        (0.01, 0.00, 0.03),
    )
    scale_error: tuple[float, float, float] = (0.015, -0.01, 0.005)
    nonorthogonality_deg: tuple[float, float, float] = (0.4, 0.2, -0.3)  # xy, xz, yz
    misalignment_deg: tuple[float, float, float] = (0.3, -0.5, 1.6)  # roll, pitch, yaw
    hard_iron_tc_ut_per_c: tuple[float, float, float] = (
        0.0,
        0.0,
        0.0,
    )  # hard-iron drift with temperature
    reference_temperature_c: float = 20.0
    noise_ut: float = 0.04  # white noise per axis, 1 sigma

    def __post_init__(self):
        check_param("noise_ut", self.noise_ut, lo=0)
        for name in (
            "hard_iron_ut",
            "scale_error",
            "nonorthogonality_deg",
            "misalignment_deg",
            "hard_iron_tc_ut_per_c",
        ):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise InputError(
                    f"parameter {name}={getattr(self, name)!r}: must be three finite numbers"
                )
        s = np.asarray(self.soft_iron, dtype=float)
        if s.shape != (3, 3) or not np.all(np.isfinite(s)):
            raise InputError("parameter soft_iron: must be a 3x3 matrix of finite numbers")
        if np.any(np.abs(np.asarray(self.scale_error)) >= 0.5):
            raise InputError("parameter scale_error: each axis must be within (-0.5, 0.5)")

    def scaled(self, factor: float) -> "CompassErrors":
        """All deterministic error sources multiplied by ``factor`` (noise unchanged)."""
        return replace(
            self,
            hard_iron_ut=tuple(factor * np.asarray(self.hard_iron_ut)),
            soft_iron=tuple(map(tuple, factor * np.asarray(self.soft_iron))),
            scale_error=tuple(factor * np.asarray(self.scale_error)),
            nonorthogonality_deg=tuple(factor * np.asarray(self.nonorthogonality_deg)),
            misalignment_deg=tuple(factor * np.asarray(self.misalignment_deg)),
            hard_iron_tc_ut_per_c=tuple(factor * np.asarray(self.hard_iron_tc_ut_per_c)),
        )


NO_ERRORS = CompassErrors(
    hard_iron_ut=(0.0, 0.0, 0.0),
    soft_iron=((0.0,) * 3,) * 3,
    scale_error=(0.0, 0.0, 0.0),
    nonorthogonality_deg=(0.0, 0.0, 0.0),
    misalignment_deg=(0.0, 0.0, 0.0),
    noise_ut=0.0,
)


@dataclass(frozen=True)
class SweepConfig:
    """A turntable sweep: ``n_points`` readings from ``start_deg`` every ``step_deg`` (paper A: 121 points,
    0..360 deg every 3 deg). ``temperature_c`` is the temperature at the first reading and
    ``temperature_rate_c_per_point`` its change per reading (a warming carrier). ``gravity_noise_ms2`` and
    the glitch settings serve the ELM patent's data preparation: an occasional reading is hit by a field
    spike of ``glitch_ut`` in a random direction with probability ``glitch_prob``."""

    n_points: int = 121
    start_deg: float = 0.0
    step_deg: float = 3.0
    temperature_c: float = 20.0
    temperature_rate_c_per_point: float = 0.0
    gravity_ms2: float = 9.80
    gravity_noise_ms2: float = 0.002
    glitch_prob: float = 0.0
    glitch_ut: float = 15.0

    def __post_init__(self):
        check_param("n_points", self.n_points, lo=2, integer=True)
        check_param("step_deg", self.step_deg, lo=0, lo_open=True, hi=360)
        check_param("gravity_noise_ms2", self.gravity_noise_ms2, lo=0)
        check_param("glitch_prob", self.glitch_prob, lo=0, hi=1)
        check_param("glitch_ut", self.glitch_ut, lo=0)


def _rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, s], [0, -s, c]])


def _rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])


def _rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def mounting_matrix(misalignment_deg) -> np.ndarray:
    """Body-to-sensor rotation for mounting errors (roll, pitch, yaw) in degrees, yaw applied first."""
    roll, pitch, yaw = np.radians(np.asarray(misalignment_deg, dtype=float))
    return _rot_x(roll) @ _rot_y(pitch) @ _rot_z(yaw)


def sensor_matrix(err: CompassErrors) -> np.ndarray:
    """``(I + K) N R``: scale errors, non-orthogonality (small angles xy, xz, yz) and mounting rotation."""
    a_xy, a_xz, a_yz = np.radians(np.asarray(err.nonorthogonality_deg, dtype=float))
    nonorth = np.array([[1.0, 0.0, 0.0], [a_xy, 1.0, 0.0], [a_xz, a_yz, 1.0]])
    return (
        np.diag(1.0 + np.asarray(err.scale_error, dtype=float))
        @ nonorth
        @ mounting_matrix(err.misalignment_deg)
    )


def heading_from_field(m_xyz) -> np.ndarray:
    """Level-compass heading in [0, 360) deg from sensor-frame field components (x fwd, y right, z down)."""
    m = np.asarray(m_xyz, dtype=float)
    return heading_deg(m[..., 0], m[..., 1])


def simulate_sweep(
    errors: CompassErrors = CompassErrors(),
    earth: EarthField | None = None,
    config: SweepConfig = SweepConfig(),
    seed: int | None = 0,
    sweep: int = 1,
) -> pd.DataFrame:
    """One turntable sweep. Returns a frame with ``true_heading_deg``, ``measured_heading_deg`` (in [0, 360)),
    ``heading_error_deg`` (wrapped measured - true), the raw field ``mag_x_ut, mag_y_ut, mag_z_ut``, the
    accelerometer ``acc_x_ms2, acc_y_ms2, acc_z_ms2`` (specific force, sensor frame), ``temperature_c``,
    ``glitch`` (1 where a spike was injected) and ``sweep``; ``earth`` None: :class:`EarthField`'s IGRF
    default."""
    earth = EarthField() if earth is None else earth
    rng = np.random.default_rng(seed)
    psi = config.start_deg + config.step_deg * np.arange(config.n_points)
    true = np.where(psi == 360.0, 360.0, np.mod(psi, 360.0))  # paper A reads 0..360 inclusive
    p = np.radians(psi)
    H, Z = earth.horizontal_ut, earth.vertical_ut
    m_b = np.stack([H * np.cos(p), -H * np.sin(p), np.full_like(p, Z)], axis=1)
    temp = config.temperature_c + config.temperature_rate_c_per_point * np.arange(config.n_points)
    h = np.asarray(errors.hard_iron_ut, dtype=float)[None, :] + np.outer(
        temp - errors.reference_temperature_c, np.asarray(errors.hard_iron_tc_ut_per_c)
    )
    carrier = m_b @ (np.eye(3) + np.asarray(errors.soft_iron, dtype=float)).T + h
    T = sensor_matrix(errors)
    mag = carrier @ T.T + errors.noise_ut * rng.standard_normal(carrier.shape)
    glitch = rng.random(config.n_points) < config.glitch_prob
    if glitch.any():
        d = rng.standard_normal((int(glitch.sum()), 3))
        mag[glitch] += config.glitch_ut * d / np.linalg.norm(d, axis=1, keepdims=True)
    f_body = np.array([0.0, 0.0, -config.gravity_ms2])  # level and static: specific force points up
    acc = np.tile(mounting_matrix(errors.misalignment_deg) @ f_body, (config.n_points, 1))
    acc += config.gravity_noise_ms2 * rng.standard_normal(acc.shape)
    measured = heading_from_field(mag)
    return pd.DataFrame(
        {
            "true_heading_deg": true,
            "measured_heading_deg": measured,
            "heading_error_deg": wrap_deg(measured - true),
            "mag_x_ut": mag[:, 0],
            "mag_y_ut": mag[:, 1],
            "mag_z_ut": mag[:, 2],
            "acc_x_ms2": acc[:, 0],
            "acc_y_ms2": acc[:, 1],
            "acc_z_ms2": acc[:, 2],
            "temperature_c": temp,
            "glitch": glitch.astype(int),
            "sweep": sweep,
        }
    )


def simulate_train_test(
    errors: CompassErrors = CompassErrors(),
    earth: EarthField | None = None,
    config: SweepConfig = SweepConfig(),
    seed: int = 2024,
) -> pd.DataFrame:
    """Paper A's experiment: the same carrier swept twice with independent noise; ``sweep`` 1 trains,
    ``sweep`` 2 tests. Both are drawn deterministically from ``seed``; ``earth`` None: the IGRF default
    (paper A's own sweeps pass :data:`PAPER_A_EARTH`)."""
    earth = EarthField() if earth is None else earth
    s1, s2 = np.random.SeedSequence(seed).spawn(2)
    return pd.concat(
        [
            simulate_sweep(errors, earth, config, seed=np.random.default_rng(s1), sweep=1),
            simulate_sweep(errors, earth, config, seed=np.random.default_rng(s2), sweep=2),
        ],
        ignore_index=True,
    )
