"""Strapdown INS with IMU errors and a star sensor (paper E's simulation; its device table is lost).

Device story (our choice, stated because paper E's Table 1 did not survive the OCR): a navigation-grade
fibre-optic-gyro IMU of the kind flown with star sensors on aircraft and missiles, and an arcsecond-class
star sensor.  The defaults are of the order that public simulation demos use (e.g. the star-sensor demo of
Yan Gongmin's PSINS toolbox, read for orders of magnitude only):

- gyro constant drift 0.01 deg/h per axis, angle random walk 0.001 deg/sqrt(h);
- accelerometer constant bias 50 ug per axis, white noise 10 ug/sqrt(Hz);
- gyro scale-factor error 100 ppm per axis: a switchable effect (``gyro_scale_ppm``), off in the filter's
  model; it matters only when the vehicle turns (error rate ``-C_b^n diag(w_ib^b) s``);
- star sensor, boresight along body z (up): 3 arcsec (1 sigma) about the two cross-boresight axes and
  15 arcsec about the boresight, at 10 Hz;
- initial attitude error of the INS 20 arcsec (level) and 60 arcsec (azimuth) 1 sigma, drawn per run.

IMU model per sample interval ``T`` (increments): ``dtheta_m = (I + diag(s_g)) dtheta + eps T + n_g``,
``dv_m = dv + nabla T + n_a`` with ``n_g ~ N(0, ARW^2 T)``, ``n_a ~ N(0, VRW^2 T)``.  Star sensor:
``C_s = exp([C_b^n dth_b x]) C_b^n`` with ``dth_b ~ N(0, diag(s_c^2, s_c^2, s_b^2))``.  With a time offset
``tau`` (``latency_ms``, an effect the filter does not model) the star sensor reports the attitude of
``tau`` earlier, ``C_b^n(t - tau)`` (spherical interpolation of the truth at the IMU rate), stamped ``t``:
to first order an attitude error ``-w_nb^b tau`` about the body axes.  With a rate-proportional error
``k`` (``smear_arcsec_per_deg_s``, motion blur: the star images smear during the exposure and their
centroids shift with the motion; also outside the filter's model) the star sensor's attitude is off by
``dth_k = k w_ib^b`` about the body axes (arcsec for ``w`` in deg/s, the true body rate at the epoch),
``C_s = C_b^n(t - tau) exp([dth_k x]) exp([dth_b x])``.  To first order it has the time offset's signature
with ``tau = -k / 3600`` s (both are the body rate times a constant), so no test on the innovations tells
the two apart; it stands for any rate-proportional error of the star sensor.

Mechanisation (ENU, batched over runs, two speeds): at the IMU rate the body increments are chained,
``C <- C exp([dtheta_m x])``, and the velocity increments ``dv_m + dtheta_m x dv_m / 2`` rotated into the
frame at the start of the filter epoch (vectorised over all epochs); at the filter rate the navigation
frame turns, ``C <- exp(-[w_in^n T x]) C``, (left and right factors of ``C`` commute, so the split is
exact up to the variation of ``w_in^n`` within an epoch), the velocity gets Coriolis and gravity
``(g^n - (2 w_ie^n + w_en^n) x v_mid) T`` with a midpoint velocity, and position follows by the trapezoid
rule.  Earth rate, transport rate and gravity come from the INS's own position and velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from ..angles import ARCSEC, DEG
from ..errors import InputError, check_param
from .trajectory import Trajectory, dcm_to_euler, earth_rates, euler_to_dcm, gravity, radii

UG = 9.80665e-6  #: one micro-g in m/s^2
DEG_H = DEG / 3600.0  #: one deg/h in rad/s


@dataclass(frozen=True)
class ImuSpec:
    """IMU errors (see the module docstring for the story). ``gyro_scale_ppm`` switches the gyro
    scale-factor error on (same value on each axis, sign as given)."""

    gyro_drift_deg_h: float = 0.01
    gyro_arw_deg_rt_h: float = 0.001
    accel_bias_ug: float = 50.0
    accel_noise_ug_rt_hz: float = 10.0
    gyro_scale_ppm: float = 0.0

    def __post_init__(self):
        check_param("gyro_drift_deg_h", self.gyro_drift_deg_h, lo=0.0, hi=100.0)
        check_param("gyro_arw_deg_rt_h", self.gyro_arw_deg_rt_h, lo=0.0, hi=10.0)
        check_param("accel_bias_ug", self.accel_bias_ug, lo=0.0, hi=1e5)
        check_param("accel_noise_ug_rt_hz", self.accel_noise_ug_rt_hz, lo=0.0, hi=1e5)
        check_param("gyro_scale_ppm", self.gyro_scale_ppm, lo=-1e5, hi=1e5)

    # SI values
    @property
    def drift_rad_s(self) -> float:
        return self.gyro_drift_deg_h * DEG_H

    @property
    def arw_rad_rt_s(self) -> float:
        return self.gyro_arw_deg_rt_h * DEG / 60.0

    @property
    def bias_m_s2(self) -> float:
        return self.accel_bias_ug * UG

    @property
    def vrw_m_s_rt_s(self) -> float:
        return self.accel_noise_ug_rt_hz * UG


@dataclass(frozen=True)
class StarSensorSpec:
    """Star sensor: attitude noise (1 sigma) about the two cross-boresight axes and about the boresight
    (body z), its output rate (the filter's rate), and two errors the filter does not model: a time offset
    ``latency_ms`` and an attitude error proportional to the body rate, ``smear_arcsec_per_deg_s`` (see the
    module docstring)."""

    cross_arcsec: float = 3.0
    boresight_arcsec: float = 15.0
    rate_hz: float = 10.0
    latency_ms: float = 0.0
    smear_arcsec_per_deg_s: float = 0.0

    def __post_init__(self):
        check_param("latency_ms", self.latency_ms, lo=0.0, hi=1000.0)
        check_param("smear_arcsec_per_deg_s", self.smear_arcsec_per_deg_s, lo=-3600.0, hi=3600.0)
        check_param("cross_arcsec", self.cross_arcsec, lo=0.0, lo_open=True, hi=3600.0)
        check_param("boresight_arcsec", self.boresight_arcsec, lo=0.0, lo_open=True, hi=3600.0)
        check_param("rate_hz", self.rate_hz, lo=0.0, lo_open=True, hi=200.0)

    @property
    def noise_rad(self) -> np.ndarray:
        return np.array([self.cross_arcsec, self.cross_arcsec, self.boresight_arcsec]) * ARCSEC


@dataclass(frozen=True)
class InitialError:
    """1-sigma initial attitude error of the INS (level, azimuth) in arcsec, drawn per run."""

    level_arcsec: float = 20.0
    azimuth_arcsec: float = 60.0

    def __post_init__(self):
        check_param("level_arcsec", self.level_arcsec, lo=0.0, hi=36000.0)
        check_param("azimuth_arcsec", self.azimuth_arcsec, lo=0.0, hi=36000.0)


def skew(v):
    """Cross-product matrices ``[v x]`` of vectors of shape (..., 3)."""
    v = np.asarray(v, float)
    s = np.zeros(v.shape + (3,))
    s[..., 0, 1], s[..., 0, 2] = -v[..., 2], v[..., 1]
    s[..., 1, 0], s[..., 1, 2] = v[..., 2], -v[..., 0]
    s[..., 2, 0], s[..., 2, 1] = -v[..., 1], v[..., 0]
    return s


def rotvec_to_dcm(v):
    """Rodrigues: ``exp([v x]) = I + sin|v|/|v| [v x] + (1 - cos|v|)/|v|^2 [v x]^2`` (batched)."""
    v = np.asarray(v, float)
    th2 = np.sum(v * v, -1)[..., None, None]
    small = th2 < 1e-12
    th = np.sqrt(np.where(small, 1.0, th2))
    a = np.where(small, 1 - th2 / 6, np.sin(th) / th)
    b = np.where(small, 0.5 - th2 / 24, (1 - np.cos(th)) / np.where(small, 1.0, th2))
    k = skew(v)
    return np.eye(3) + a * k + b * (k @ k)


def dcm_to_rotvec(c):
    """The small-angle inverse of :func:`rotvec_to_dcm`: ``vee((C - C^T)/2)`` scaled by ``theta/sin(theta)``."""
    c = np.asarray(c, float)
    w = 0.5 * np.stack(
        [c[..., 2, 1] - c[..., 1, 2], c[..., 0, 2] - c[..., 2, 0], c[..., 1, 0] - c[..., 0, 1]], -1
    )
    s = np.linalg.norm(w, axis=-1, keepdims=True)
    th = np.arcsin(np.clip(s, 0, 1))
    return w * np.where(s > 1e-15, th / np.where(s > 1e-15, s, 1.0), 1.0)


def misalignment(c_computed, c_true):
    """Platform misalignment ``phi`` of a computed attitude: ``C_computed = (I - [phi x]) C_true`` to first
    order, exactly ``C_computed C_true^T = exp(-[phi x])`` (direction-cosine route)."""
    return -dcm_to_rotvec(np.asarray(c_computed) @ np.swapaxes(np.asarray(c_true), -1, -2))


@dataclass(frozen=True)
class InsRun:
    """Strapdown output at the filter epochs (every ``decim`` IMU samples), for ``n_runs`` runs.

    Arrays have shape (n_runs, n_epochs, ...): ``t_s`` (n_epochs,), ``cbn`` INS attitude matrix,
    ``att`` INS Euler angles, ``vn``, ``pos``, ``cbn_true``/``att_true`` the truth, ``fn`` mean specific
    force in n over the preceding interval, ``rate_b`` mean measured body rate (rad/s), ``cw_b`` the mean of
    ``C_b^n diag(w_ib^b)`` (for the scale-factor states), ``cf_b`` the mean of ``C_b^n diag(f^b)``,
    ``star_att`` the star sensor's Euler angles, ``scale`` the gyro scale-factor error that was applied."""

    t_s: np.ndarray
    cbn: np.ndarray
    att: np.ndarray
    vn: np.ndarray
    pos: np.ndarray
    cbn_true: np.ndarray
    att_true: np.ndarray
    fn: np.ndarray
    rate_b: np.ndarray
    cw_b: np.ndarray
    cf_b: np.ndarray
    star_att: np.ndarray
    star_cbn: np.ndarray
    imu: ImuSpec
    star: StarSensorSpec

    @property
    def phi_true(self) -> np.ndarray:
        """True misalignment of the INS (rad), direction-cosine route."""
        return misalignment(self.cbn, self.cbn_true)

    @property
    def n_runs(self) -> int:
        return self.cbn.shape[0]


def delayed_attitude(traj: Trajectory, t_s, latency_ms: float) -> np.ndarray:
    """The true attitude matrices ``C_b^n(t - tau)`` at the times ``t_s`` for a time offset ``tau =
    latency_ms`` (spherical linear interpolation of the truth at the IMU rate; times before the start take the
    first attitude).  ``latency_ms = 0`` gives the truth at ``t_s`` itself."""
    check_param("latency_ms", latency_ms, lo=0.0, hi=1000.0)
    t_s = np.asarray(t_s, dtype=float)
    k = np.searchsorted(traj.t_s, t_s)
    if latency_ms == 0.0 and np.array_equal(traj.t_s[np.minimum(k, len(traj.t_s) - 1)], t_s):
        return euler_to_dcm(traj.att[k])  # on the IMU grid: the truth itself
    slerp = Slerp(traj.t_s, Rotation.from_matrix(euler_to_dcm(traj.att)))
    return slerp(np.clip(t_s - 1e-3 * latency_ms, traj.t_s[0], traj.t_s[-1])).as_matrix()


def smear_error(traj: Trajectory, idx, k_arcsec_per_deg_s: float) -> np.ndarray:
    """The star sensor's rate-proportional attitude error ``k w_ib^b`` (rad, body axes) at the IMU samples
    ``idx``: ``w`` the true body rate there (the mean of the rates at the midpoints of the two adjacent IMU
    intervals; the nearest one at the ends), ``k`` in arcsec per deg/s."""
    idx = np.asarray(idx)
    r = traj.rate_b
    w = 0.5 * (r[np.clip(idx - 1, 0, len(r) - 1)] + r[np.clip(idx, 0, len(r) - 1)])
    return k_arcsec_per_deg_s * ARCSEC * w / DEG


def decimation(traj: Trajectory, star: StarSensorSpec) -> int:
    """IMU samples per star-sensor epoch; the star rate must divide the IMU rate."""
    d = traj.profile.imu_rate_hz / star.rate_hz
    if abs(d - round(d)) > 1e-9 or round(d) < 1:
        raise InputError(
            f"parameter star_rate_hz={star.rate_hz!r}: must divide the IMU rate "
            f"{traj.profile.imu_rate_hz:g} Hz"
        )
    return int(round(d))


def strapdown(
    traj,
    seeds,
    imu: ImuSpec = ImuSpec(),
    star: StarSensorSpec = StarSensorSpec(),
    init: InitialError = InitialError(),
    ideal: bool = False,
) -> InsRun:
    """Fly ``len(seeds)`` INS runs along ``traj`` with IMU errors and star-sensor fixes.

    ``traj`` is one :class:`~navlib.sensors.trajectory.Trajectory` for every run, or a sequence of them, one
    per seed (runs along different paths of the same timing, flown together: each run's numbers are those of
    flying it alone).

    Each seed draws (``SeedSequence(seed).spawn(3)``) the initial attitude error, the IMU noise and the
    star-sensor noise; the device's constant errors (drift ``+eps`` on each axis, bias ``+nabla``, scale
    factor) are the same in every run (one device, many flights).  ``ideal=True`` flies the perfect IMU
    from the true initial state (the kinematic-consistency test).

    Returns
    -------
    InsRun
        INS, truth and star sensor at the filter epochs ``t = k / star.rate_hz``, k = 0..N.
    """
    seeds = [int(s) for s in np.atleast_1d(seeds)]
    if not seeds:
        raise InputError("parameter seeds: at least one run")
    trajs = [traj] * len(seeds) if isinstance(traj, Trajectory) else list(traj)
    if len(trajs) != len(seeds) or any(not isinstance(t, Trajectory) for t in trajs):
        raise InputError(
            f"parameter traj: one Trajectory, or one per seed ({len(seeds)}), got {len(trajs)}"
        )
    traj = trajs[0]
    if any(t.t_s.shape != traj.t_s.shape or not np.array_equal(t.t_s, traj.t_s) for t in trajs[1:]):
        raise InputError(
            "parameter traj: the trajectories must share their sample times (duration, IMU rate)"
        )
    one = all(t is traj for t in trajs)
    decim = decimation(traj, star)
    n, m = len(seeds), traj.profile.n_steps
    dt = traj.profile.dt_s
    rngs = [np.random.SeedSequence(s).spawn(3) for s in seeds]
    g_init = [np.random.default_rng(r[0]) for r in rngs]
    g_imu = [np.random.default_rng(r[1]) for r in rngs]
    g_star = [np.random.default_rng(r[2]) for r in rngs]

    c_true0 = (
        euler_to_dcm(traj.att[0]) if one else euler_to_dcm(np.stack([t.att[0] for t in trajs]))
    )
    if ideal:
        phi0 = np.zeros((n, 3))
    else:
        sd = np.array([init.level_arcsec, init.level_arcsec, init.azimuth_arcsec]) * ARCSEC
        phi0 = np.stack([g.standard_normal(3) * sd for g in g_init])
    c = rotvec_to_dcm(-phi0) @ c_true0  # C = exp(-[phi x]) C_true
    v = np.stack([t.vn[0] for t in trajs])
    p = np.stack([t.pos[0] for t in trajs])
    dtheta = traj.dtheta[None] if one else np.stack([t.dtheta for t in trajs])  # (1 or n, m, 3)
    dvel = traj.dvel[None] if one else np.stack([t.dvel for t in trajs])

    # IMU errors (all samples at once)
    if ideal:
        dth = np.broadcast_to(dtheta, (n, m, 3)).copy()
        dv = np.broadcast_to(dvel, (n, m, 3)).copy()
        scale = 0.0
    else:
        scale = imu.gyro_scale_ppm * 1e-6
        ng = np.stack([g.standard_normal((m, 3)) for g in g_imu]) * (imu.arw_rad_rt_s * np.sqrt(dt))
        na = np.stack([g.standard_normal((m, 3)) for g in g_imu]) * (imu.vrw_m_s_rt_s * np.sqrt(dt))
        dth = (1 + scale) * dtheta + imu.drift_rad_s * dt + ng
        dv = dvel + imu.bias_m_s2 * dt + na

    n_ep = m // decim + 1
    tint = decim * dt
    # fast loop, all samples at once: body increments chained within each epoch (P_j = E_1 ... E_j),
    # velocity increments rotated to the epoch's start frame with the rotation compensation
    e_all = rotvec_to_dcm(dth).reshape(n, n_ep - 1, decim, 3, 3)
    th = dth.reshape(n, n_ep - 1, decim, 3)
    u = (dv + 0.5 * np.cross(dth, dv)).reshape(n, n_ep - 1, decim, 3)
    dvr = dv.reshape(n, n_ep - 1, decim, 3)
    pj = np.broadcast_to(np.eye(3), (n, n_ep - 1, 3, 3)).copy()
    s0 = np.zeros((n, n_ep - 1, 3))
    s1 = np.zeros((n, n_ep - 1, 3))
    cw = np.zeros((n, n_ep - 1, 3, 3))
    cf = np.zeros((n, n_ep - 1, 3, 3))
    for j in range(decim):
        pu = np.einsum("reik,rek->rei", pj, u[:, :, j])
        s0 += pu
        s1 += (j + 0.5) * dt * pu
        cw += pj * th[:, :, j, None, :]
        cf += pj * dvr[:, :, j, None, :]
        pj = pj @ e_all[:, :, j]
    # slow loop, once per epoch: navigation-frame rotation, Coriolis, gravity, position (two-speed
    # mechanisation; the left (n-frame) and right (b-frame) rotations of C commute exactly)
    out = {
        k: np.empty((n, n_ep) + sh)
        for k, sh in [
            ("cbn", (3, 3)),
            ("vn", (3,)),
            ("pos", (3,)),
            ("fn", (3,)),
            ("rate_b", (3,)),
            ("cw_b", (3, 3)),
            ("cf_b", (3, 3)),
        ]
    }
    out["cbn"][:, 0], out["vn"][:, 0], out["pos"][:, 0] = c, v, p
    for k in ("fn", "rate_b", "cw_b", "cf_b"):
        out[k][:, 0] = 0.0
    out["rate_b"][:, 1:] = th.sum(2) / tint
    for j in range(1, n_ep):
        wie, wen = earth_rates(p, v)
        win = wie + wen
        dvn = np.einsum("rik,rk->ri", c, s0[:, j - 1])
        dvn -= np.cross(win, np.einsum("rik,rk->ri", c, s1[:, j - 1]))
        gn = np.zeros_like(v)
        gn[:, 2] = -gravity(p[:, 0], p[:, 2])
        v_mid = v + 0.5 * (dvn + gn * tint)
        wie, wen = earth_rates(p, v_mid)
        v_new = v + dvn + (gn - np.cross(2 * wie + wen, v_mid)) * tint
        rmh, rnh = radii(p[:, 0], p[:, 2])
        vm = 0.5 * (v + v_new)
        p = p + np.stack([vm[:, 1] / rmh, vm[:, 0] / (rnh * np.cos(p[:, 0])), vm[:, 2]], -1) * tint
        out["fn"][:, j] = dvn / tint
        out["cw_b"][:, j] = c @ cw[:, j - 1] / tint
        out["cf_b"][:, j] = c @ cf[:, j - 1] / tint
        c = rotvec_to_dcm(-(wie + wen) * tint) @ c @ pj[:, j - 1]
        v = v_new
        out["cbn"][:, j], out["vn"][:, j], out["pos"][:, j] = c, v, p
    idx = np.arange(n_ep) * decim
    paths = [traj] if one else trajs
    att_true = np.stack([t.att[idx] for t in paths])  # (1 or n, n_ep, 3)
    cbn_true = euler_to_dcm(att_true)
    if ideal:
        dstar = np.zeros((n, n_ep, 3))
    else:
        dstar = np.stack([g.standard_normal((n_ep, 3)) for g in g_star]) * star.noise_rad
    star_cbn = []
    for t in paths:
        c_star = delayed_attitude(t, t.t_s[idx], star.latency_ms)
        if star.smear_arcsec_per_deg_s:
            c_star = c_star @ rotvec_to_dcm(smear_error(t, idx, star.smear_arcsec_per_deg_s))
        star_cbn.append(c_star)
    star_cbn = np.stack(star_cbn) @ rotvec_to_dcm(dstar)  # noise about body axes
    return InsRun(
        t_s=traj.t_s[idx],
        cbn=out["cbn"],
        att=dcm_to_euler(out["cbn"]),
        vn=out["vn"],
        pos=out["pos"],
        cbn_true=np.broadcast_to(cbn_true, (n, n_ep, 3, 3)),
        att_true=np.broadcast_to(att_true, (n, n_ep, 3)),
        fn=out["fn"],
        rate_b=out["rate_b"],
        cw_b=out["cw_b"],
        cf_b=out["cf_b"],
        star_att=dcm_to_euler(star_cbn),
        star_cbn=star_cbn,
        imu=imu,
        star=star,
    )
