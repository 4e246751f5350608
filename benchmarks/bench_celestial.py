"""Speed of paper E's aided filter for one 150 s run at the chapter's rates (star sensor and filter at
10 Hz, 1500 epochs): navlib's numpy Kalman filter + QR features + a trained 9-10-3 network's prediction,
against filterpy 2.0.0's KalmanFilter on the same sequence (predict/update per epoch, the peer).  Also the
time per training pass of the 45-10-3 and 6-10-3 networks in one run and their ratio (paper: 7.3x).
Prints the times and ratios; the INS simulation is not timed (it is the same for both)."""

import time

import numpy as np
import torch
from filterpy.kalman import KalmanFilter

from navlib.methods import kalman as km
from navlib.methods.mlp import train_mlp
from navlib.studies.celestial import bp_params
from navlib.sensors import ins15
from navlib.sensors.strapdown import ImuSpec, strapdown
from navlib.sensors.trajectory import FlightProfile, generate

torch.set_num_threads(1)
run = strapdown(generate(FlightProfile(kind="s_turns")), [1], ImuSpec(gyro_scale_ppm=100))
res = km.run_filter(run)
net = train_mlp(km.gain_features(res, "qr6_rate"), res.att_err_arcsec, bp_params(9, epochs=50))

t0 = time.perf_counter()
res = km.run_filter(run)
corrected = res.att_err_arcsec - net.predict(km.gain_features(res, "qr6_rate"))
t_ours = time.perf_counter() - t0

t0 = time.perf_counter()
kf = KalmanFilter(dim_x=15, dim_z=3)
kf.x, kf.P = np.zeros(15), res.spec.p0(float(run.pos[0, 0, 0]))
kf.H, kf.Q = np.c_[np.eye(3), np.zeros((3, 12))], ins15.process_noise(run.imu, 0.1)
z = km.star_measurement(run.att[0, 1:], run.star_att[0, 1:])
c = run.cbn[0, 1:]
r = c @ np.diag(run.star.noise_rad**2) @ np.swapaxes(c, 1, 2)
for k in range(res.phi.shape[1]):
    kf.F = res.phi[0, k]
    kf.predict()
    kf.update(z[k], R=r[k])
t_peer = time.perf_counter() - t0
print(
    f"150 s run, 1500 epochs: numpy KF + QR + 9-10-3 net {t_ours:.3f} s; filterpy KF alone {t_peer:.3f} s; "
    f"ratio peer/ours {t_peer / t_ours:.2f}"
)

x45, x6 = km.gain_features(res, "raw45"), km.gain_features(res, "qr6")
n45 = train_mlp(x45, res.att_err_arcsec, bp_params(45, epochs=300))
n6 = train_mlp(x6, res.att_err_arcsec, bp_params(6, epochs=300))
print(
    f"training pass: 45-10-3 {1e3 * n45.seconds_per_pass:.2f} ms, 6-10-3 {1e3 * n6.seconds_per_pass:.2f} ms, "
    f"ratio {n45.seconds_per_pass / n6.seconds_per_pass:.2f} (paper 0.3038 s / 0.0418 s = 7.27)"
)
