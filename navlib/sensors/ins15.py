"""The 15-state ENU phi-angle error model of a strapdown INS (paper E's state model), with optional gyro
scale-factor states (the augmented filter of the chapter).

This sits beside :mod:`navlib.sensors.ins` (the 7-state static-base model of paper C's rotating INS,
unchanged).  States, in order::

    phi (E, N, U) rad | dv (E, N, U) m/s | dL rad, dlon rad, dh m | eps (x, y, z) rad/s | nabla (x, y, z) m/s^2
    [| s_g (x, y, z) gyro scale-factor errors, dimensionless]

Continuous model (Titterton & Weston ch. 12; Yan Gongmin's notation), ``w_in = w_ie + w_en``::

    phi'   = -w_in x phi + M_av dv + M_ap dp - C_b^n eps            [- C_b^n diag(w_ib^b) s_g]
    dv'    = f^n x phi + M_vv dv + M_vp dp + C_b^n nabla
    dp'    = M_pv dv + M_pp dp,          eps' = 0,   nabla' = 0,    [s_g' = 0]

with ``M_av = [[0, -1/RMh, 0], [1/RNh, 0, 0], [tan L/RNh, 0, 0]]``, ``M_ap = M1 + M2``,
``M1 = [[0,0,0], [-w_ie sin L,0,0], [w_ie cos L,0,0]]``,
``M2 = [[0,0,vN/RMh^2], [0,0,-vE/RNh^2], [vE sec^2 L/RNh, 0, -vE tan L/RNh^2]]``,
``M_vv = [v x] M_av - [(2 w_ie + w_en) x]``, ``M_vp = [v x](2 M1 + M2)`` plus the free-air gravity gradient
``d g_U / dh = +3.086e-6 s^-2``, ``M_pv = [[0, 1/RMh, 0], [sec L/RNh, 0, 0], [0, 0, 1]]``,
``M_pp = [[0,0,-vN/RMh^2], [vE sec L tan L/RNh, 0, -vE sec L/RNh^2], [0,0,0]]``.

Discretisation over the filter period ``T`` (paper E's Phi_k,k-1 and Gamma_k,k-1):
``Phi = I + F T + (F T)^2 / 2`` (second order; the neglected third-order term is below 1e-9 of ``I`` at
``T <= 1 s``) and ``Q_k = Q T`` with the white-noise densities of the gyros (ARW) and accelerometers (VRW)
on the attitude and velocity states; the constants have no process noise.
"""

from __future__ import annotations

import numpy as np

from .strapdown import ImuSpec, skew
from .trajectory import EARTH_RATE_RAD_S, radii

N_BASE = 15
STATE_NAMES = (
    "phi_E",
    "phi_N",
    "phi_U",
    "dv_E",
    "dv_N",
    "dv_U",
    "dL",
    "dlon",
    "dh",
    "eps_x",
    "eps_y",
    "eps_z",
    "nabla_x",
    "nabla_y",
    "nabla_z",
)
SCALE_NAMES = ("sg_x", "sg_y", "sg_z")
GRAVITY_GRADIENT_S2 = 3.086e-6


def system_matrix(pos, vn, fn, cbn, cw_b=None):
    """Continuous system matrix ``F`` (batched over leading axes) of the 15-state model, or of the 18-state
    model when ``cw_b`` (the mean of ``C_b^n diag(w_ib^b)``) is given.

    Parameters
    ----------
    pos : (..., 3) latitude (rad), longitude (rad), height (m)
    vn : (..., 3) ENU velocity (m/s)
    fn : (..., 3) specific force in n (m/s^2)
    cbn : (..., 3, 3) body-to-navigation attitude matrix
    cw_b : (..., 3, 3) or None

    Returns
    -------
    ndarray (..., 15, 15) or (..., 18, 18)
    """
    pos, vn, fn, cbn = (np.asarray(a, float) for a in (pos, vn, fn, cbn))
    lead = pos.shape[:-1]
    d = N_BASE + (3 if cw_b is not None else 0)
    F = np.zeros(lead + (d, d))
    lat, h = pos[..., 0], pos[..., 2]
    rmh, rnh = radii(lat, h)
    sl, cl, tl = np.sin(lat), np.cos(lat), np.tan(lat)
    sec = 1.0 / cl
    ve, vnn = vn[..., 0], vn[..., 1]
    wie = np.stack([np.zeros_like(lat), EARTH_RATE_RAD_S * cl, EARTH_RATE_RAD_S * sl], -1)
    wen = np.stack([-vnn / rmh, ve / rnh, ve * tl / rnh], -1)
    z = np.zeros(lead + (3, 3))
    mav = z.copy()
    mav[..., 0, 1], mav[..., 1, 0], mav[..., 2, 0] = -1 / rmh, 1 / rnh, tl / rnh
    m1 = z.copy()
    m1[..., 1, 0], m1[..., 2, 0] = -EARTH_RATE_RAD_S * sl, EARTH_RATE_RAD_S * cl
    m2 = z.copy()
    m2[..., 0, 2], m2[..., 1, 2] = vnn / rmh**2, -ve / rnh**2
    m2[..., 2, 0], m2[..., 2, 2] = ve * sec**2 / rnh, -ve * tl / rnh**2
    vx = skew(vn)
    F[..., 0:3, 0:3] = -skew(wie + wen)
    F[..., 0:3, 3:6] = mav
    F[..., 0:3, 6:9] = m1 + m2
    F[..., 0:3, 9:12] = -cbn
    F[..., 3:6, 0:3] = skew(fn)
    F[..., 3:6, 3:6] = vx @ mav - skew(2 * wie + wen)
    mvp = vx @ (2 * m1 + m2)
    mvp[..., 2, 2] += GRAVITY_GRADIENT_S2
    F[..., 3:6, 6:9] = mvp
    F[..., 3:6, 12:15] = cbn
    F[..., 6, 4] = 1 / rmh
    F[..., 7, 3] = sec / rnh
    F[..., 8, 5] = 1.0
    F[..., 6, 8] = -vnn / rmh**2
    F[..., 7, 6] = ve * sec * tl / rnh
    F[..., 7, 8] = -ve * sec / rnh**2
    if cw_b is not None:
        F[..., 0:3, 15:18] = -np.asarray(cw_b, float)
    return F


def discretise(F, period_s: float):
    """``Phi = I + F T + (F T)^2 / 2`` (batched)."""
    ft = np.asarray(F) * period_s
    return np.eye(ft.shape[-1]) + ft + 0.5 * (ft @ ft)


def process_noise(imu: ImuSpec, period_s: float, n_states: int = N_BASE) -> np.ndarray:
    """``Q_k = Q T``: gyro ARW on the attitude states, accelerometer VRW on the velocity states (their
    densities are isotropic, so ``C_b^n Q C_n^b = Q``)."""
    q = np.zeros(n_states)
    q[0:3] = imu.arw_rad_rt_s**2
    q[3:6] = imu.vrw_m_s_rt_s**2
    return np.diag(q * period_s)
