"""A ring-laser gyro's axial drift after a cold start: a temperature coefficient and a thermal-gradient term
with a lag (paper C Sec. 2.3), and the exact linear map from a test's errors to its 12 h latitude error.

Thermal model (a first-order thermal lag between the case and the sensing element)::

    tau dT_s/dt = T_c(t) - T_s(t)                                   sensor temperature lags the case
    eps(t) = eps_final + k_T (T_s(t) - T_end) + k_G (T_c(t) - T_s(t))

``T_c`` is the case (system) temperature the paper prints (piecewise linear through Table 4/5's end points,
:class:`navlib.sensors.ins.ColdStart`), ``T_s`` the sensing element's, ``T_end`` the temperature at which the
system settles (``eps_final`` is the drift there), ``k_T`` (deg/h per C) the temperature coefficient and
``k_G`` (deg/h per C) the sensitivity to the case-to-sensor gradient.  Closed forms (checked in
``tests/sensors/test_thermal_gyro.py``): at a constant case temperature ``T_s`` relaxes to it with time constant
``tau`` (``T_s(t) = T_c + (T_s0 - T_c) exp(-t / tau)``) and the drift to the steady state
``eps_final + k_T (T_c - T_end)``; on a ramp of rate ``r`` the gradient settles to ``r tau``, so for
``tau -> 0`` with ``k_G tau = k_R`` the model is the rate term ``eps_final + k_R dT/dt`` of
:class:`navlib.sensors.ins.ColdStart` (the world the "hot net + rate correction" baseline is made for).
Physical background: the thermal bias of a ring laser gyro follows both its temperature and the temperature
gradient across the block (Titterton & Weston 2004, ch. 5; Aronowitz, in *Laser Applications* 1971).

The 12 h latitude error of the static-base error model (:mod:`navlib.sensors.ins`) is linear in every error
source, so :func:`identification_map` computes once, by the adjoint of the discrete propagation, the weight
of each source (axial drift at each step, horizontal gyro and accelerometer biases, the initial state) and the
standard deviation that gyro white noise adds; :meth:`IdentificationMap.latitude_error_deg` then gives a
test's 12 h latitude error without re-running the simulator (agreement with :func:`navlib.sensors.ins.simulate`
is tested).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..angles import DEG
from ..errors import InputError, check_param
from . import ins


@dataclass(frozen=True)
class ThermalGyro:
    """Axial gyro with a temperature coefficient and a lagged thermal-gradient term (module docstring).

    ``temp_coeff_deg_h_per_c`` = ``k_T``, ``gradient_coeff_deg_h_per_c`` = ``k_G``, ``lag_h`` = ``tau``."""

    temp_coeff_deg_h_per_c: float = 0.0
    gradient_coeff_deg_h_per_c: float = 0.0
    lag_h: float = 1.0

    def __post_init__(self):
        check_param("temp_coeff_deg_h_per_c", self.temp_coeff_deg_h_per_c, lo=-0.01, hi=0.01)
        check_param("gradient_coeff_deg_h_per_c", self.gradient_coeff_deg_h_per_c, lo=-1.0, hi=1.0)
        check_param("lag_h", self.lag_h, lo=0, lo_open=True, hi=100)

    @property
    def rate_coeff_deg_h_per_c_h(self) -> float:
        """``k_G tau``: the drift per C/h of a steady ramp (the rate-term limit)."""
        return self.gradient_coeff_deg_h_per_c * self.lag_h

    def sensor_temperature_c(
        self, t_h, knots_h, case_c, start_c: float | None = None
    ) -> np.ndarray:
        """``T_s(t)`` for a case temperature piecewise linear through ``(knots_h, case_c)`` (constant after
        the last knot), exactly: on a segment ``T_c = a + r s``,
        ``T_s(s) = a + r s - r tau + (T_s(0) - a + r tau) exp(-s / tau)``.  ``start_c``: ``T_s`` at
        ``knots_h[0]`` (default: the case temperature there, a soaked system at power-on)."""
        kt, kc = np.asarray(knots_h, float), np.asarray(case_c, float)
        if kt.ndim != 1 or kt.shape != kc.shape or kt.size < 1 or np.any(np.diff(kt) <= 0):
            raise InputError("parameter knots_h: increasing times, one case temperature each")
        t = np.asarray(t_h, float)
        if np.any(t < kt[0]):
            raise InputError(f"parameter t_h: times before the first knot ({kt[0]:g} h)")
        tau = self.lag_h
        ts0 = [float(kc[0]) if start_c is None else float(start_c)]
        rates = np.r_[np.diff(kc) / np.diff(kt), 0.0]
        for i in range(kt.size - 1):  # T_s at each knot
            a, r, d = kc[i], rates[i], kt[i + 1] - kt[i]
            ts0.append(a + r * d - r * tau + (ts0[i] - a + r * tau) * math.exp(-d / tau))
        seg = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, kt.size - 1)
        s = t - kt[seg]
        a, r, s0 = kc[seg], rates[seg], np.asarray(ts0)[seg]
        return a + r * s - r * tau + (s0 - a + r * tau) * np.exp(-s / tau)

    def axial_drift_deg_h(
        self, t_h, knots_h, case_c, final_drift_deg_h: float, end_c: float | None = None
    ) -> np.ndarray:
        """``eps(t) = eps_final + k_T (T_s - T_end) + k_G (T_c - T_s)``; ``T_end`` defaults to the last knot's
        case temperature."""
        t = np.asarray(t_h, float)
        tc = np.interp(t, knots_h, case_c)
        ts = self.sensor_temperature_c(t, knots_h, case_c)
        te = float(np.asarray(case_c, float)[-1]) if end_c is None else float(end_c)
        return (
            final_drift_deg_h
            + self.temp_coeff_deg_h_per_c * (ts - te)
            + self.gradient_coeff_deg_h_per_c * (tc - ts)
        )

    def steady_state_drift_deg_h(
        self, case_c: float, final_drift_deg_h: float, end_c: float
    ) -> float:
        """The drift at a constant case temperature once the lag has settled: ``eps_final + k_T (T_c - T_end)``."""
        return float(final_drift_deg_h + self.temp_coeff_deg_h_per_c * (case_c - end_c))


def cold_start_knots(history: ins.ColdStart) -> tuple[np.ndarray, np.ndarray]:
    """The case-temperature knots of a cold-start history: power-on, end of alignment, end of identification
    (``(0, align_h, align_h + identify_h)`` h, ``(align_temp_min_c, calib_temp_min_c, calib_temp_max_c)``)."""
    return (
        np.array([0.0, history.align_h, history.align_h + history.identify_h]),
        np.array([history.align_temp_min_c, history.calib_temp_min_c, history.calib_temp_max_c]),
    )


@dataclass(frozen=True)
class IdentificationMap:
    """Weights of the 12 h latitude error (deg) of :func:`navlib.sensors.ins.run_procedure`'s identification
    run: ``axial`` (per step, deg per deg/h held over that step), ``biases`` (per deg/h of gyro x, y and per
    ug of accelerometer x, y), ``initial`` (per unit of each initial state, rad or m/s), ``noise_per_arw``
    (standard deviation, deg, per deg/sqrt(h) of gyro angle random walk on all three gyros); ``t_mid_h``: the
    mid-step times since power-on."""

    axial: np.ndarray
    biases: np.ndarray
    initial: np.ndarray
    noise_per_arw: float
    t_mid_h: np.ndarray
    step_s: float

    def latitude_error_deg(
        self,
        axial_deg_h,
        imu: ins.ImuErrors,
        initial: ins.InitialErrors,
        noise: np.ndarray | float = 0.0,
    ) -> np.ndarray:
        """The 12 h latitude error for axial drift histories ``axial_deg_h`` (rows: tests; columns: steps),
        the residual errors ``imu``/``initial`` (the axial field of ``imu`` is ignored) and standard-normal
        ``noise`` draws scaled by the gyro noise."""
        ax = np.atleast_2d(np.asarray(axial_deg_h, float))
        if ax.shape[1] != self.axial.size:
            raise InputError(
                f"parameter axial_deg_h: {ax.shape[1]} steps, the run has {self.axial.size}"
            )
        b = np.array(
            [imu.gyro_bias_x_deg_h, imu.gyro_bias_y_deg_h, imu.accel_bias_x_ug, imu.accel_bias_y_ug]
        )
        return (
            ax @ self.axial
            + float(b @ self.biases)
            + float(initial.state() @ self.initial)
            + self.noise_per_arw * imu.gyro_arw_deg_rt_h * np.asarray(noise, float)
        )


@lru_cache(maxsize=8)
def identification_map(
    earth: ins.Earth = ins.Earth(),
    procedure: ins.Procedure = ins.Procedure(),
    rotation: ins.Rotation = ins.Rotation(),
) -> IdentificationMap:
    """The exact linear map of the identification run (adjoint of ``x_{k+1} = Phi x_k + Gam u_k``):
    ``dL_n = l_0 . x_0 + sum_k (Gam^T l_{k+1}) . u_k`` with ``l_n = e_dL``, ``l_k = Phi^T l_{k+1}``; the body
    inputs enter ``u_k`` through the rotation as in :func:`navlib.sensors.ins.simulate` (same step, same
    rotation phase ``t0 = align_h``).

    Returns
    -------
    IdentificationMap
    """
    dt = float(procedure.step_s)
    n = int(round(procedure.identify_h * 3600.0 / dt))
    Phi, Gam = ins._discrete(earth, dt)
    lam = np.zeros(7)
    lam[5] = 1.0 / DEG
    sens = np.empty((n, 5))
    for k in range(n - 1, -1, -1):
        sens[k] = Gam.T @ lam
        lam = Phi.T @ lam
    cs, sn = rotation.mean_cos_sin(procedure.align_h * 3600.0, n, dt)
    dgx = sens[:, 0] * cs + sens[:, 1] * sn
    dgy = -sens[:, 0] * sn + sens[:, 1] * cs
    dax = sens[:, 3] * cs + sens[:, 4] * sn
    day = -sens[:, 3] * sn + sens[:, 4] * cs
    biases = np.array(
        [dgx.sum() * ins.DEG_H, dgy.sum() * ins.DEG_H, dax.sum() * ins.UG, day.sum() * ins.UG]
    )
    sg = DEG / 60.0 / math.sqrt(dt)  # 1 deg/sqrt(h) of ARW -> rad/s per step
    noise = sg * math.sqrt(float(np.sum(dgx**2 + dgy**2 + sens[:, 2] ** 2)))
    t_mid = procedure.align_h + (np.arange(n) + 0.5) * dt / 3600.0
    return IdentificationMap(sens[:, 2] * ins.DEG_H, biases, lam.copy(), noise, t_mid, dt)
