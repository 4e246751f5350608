"""Speed of navlib.sensors.ins.simulate (exact matrix-exponential steps) against scipy.integrate.solve_ivp on the same
static-base error equations and the same piecewise-constant forcing, for one 72 h run.  Prints both times,
their ratio and the largest difference in position error."""

import time

import numpy as np
from scipy.integrate import solve_ivp

from navlib.sensors import ins

imu = ins.ImuErrors(
    gyro_bias_x_deg_h=0.003,
    gyro_bias_y_deg_h=-0.002,
    axial_drift_deg_h=0.001,
    accel_bias_x_ug=20.0,
    accel_bias_y_ug=-15.0,
)
init = ins.InitialErrors(tilt_east_arcsec=2.0, azimuth_arcsec=10.0, vel_north_m_s=0.01)
earth, rot, step = ins.Earth(), ins.Rotation(), 60.0
hours = 72.0

ins.simulate(
    1.0, earth=earth, imu=imu, initial=init, rotation=rot, step_s=step
)  # warm the expm cache
t0 = time.perf_counter()
ours = ins.simulate(hours, earth=earth, imu=imu, initial=init, rotation=rot, step_s=step)
t_ours = time.perf_counter() - t0

A, B = ins.system_matrices(earth)
n = int(hours * 3600 / step)
cs, sn = rot.mean_cos_sin(0.0, n, step)
g = np.array([imu.gyro_bias_x_deg_h, imu.gyro_bias_y_deg_h]) * ins.DEG_H
a = np.array([imu.accel_bias_x_ug, imu.accel_bias_y_ug]) * ins.UG
U = np.c_[
    cs * g[0] - sn * g[1],
    sn * g[0] + cs * g[1],
    np.full(n, imu.axial_drift_deg_h * ins.DEG_H),
    cs * a[0] - sn * a[1],
    sn * a[0] + cs * a[1],
]


def rhs(t, x):
    k = min(int(t // step), n - 1)
    return A @ x + B @ U[k]


t0 = time.perf_counter()
sol = solve_ivp(
    rhs,
    (0.0, hours * 3600),
    init.state(),
    method="RK45",
    rtol=1e-10,
    atol=1e-14,
    max_step=step,
    t_eval=ours.t_h * 3600,
)
t_peer = time.perf_counter() - t0
peer = ins.NavErrors(t_h=sol.t / 3600, states=sol.y.T, earth=earth)
diff = np.max(np.abs(peer.position_error_nmi - ours.position_error_nmi))
print(f"72 h run, {n} steps of {step:g} s")
print(f"navlib.sensors.ins.simulate : {t_ours * 1000:8.1f} ms")
print(f"scipy solve_ivp RK45: {t_peer * 1000:8.1f} ms   (ratio {t_peer / t_ours:.0f}x)")
print(
    f"max |position error difference| {diff:.2e} nmi (final ours {ours.position_error_nmi[-1]:.4f} nmi)"
)
