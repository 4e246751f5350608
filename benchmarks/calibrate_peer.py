"""``navlib calibrate`` beside a plain Levenberg-Marquardt ellipsoid fit, on real hand-held recordings
(issue 34): time per fit and held-out accuracy, in one run.

The peer is what a dedicated calibrator does (magcc's LM fit; magcc itself is not installed: it pulls a web
stack, FastAPI and uvicorn, into the environment): ``scipy.optimize.least_squares(method="lm")`` on the 9
parameters of ``m_c = S (m - b)``, S symmetric, residual ``|m_c| - F`` with ``F`` the mean field strength,
started from the algebraic ellipsoid fit.  navlib is the library call the CLI makes
(:func:`navlib.workbench.calibration.calibrate` on :func:`~navlib.workbench.magnetometer_free.load_free`
of the same rows), which also estimates the noise model, screens outliers, gives every parameter's
uncertainty and refuses data that cannot separate the parameters.

Split as in the issue: fit on the first 70 % of the rows, judge on the last 30 %.  Held-out metrics of the
corrected field: the spread of its magnitude (std / mean, %), and, with BROAD's reference attitude, the
RMS angle of the corrected field rotated to the world frame from its mean direction (deg).  Files:
``../shared/realdata/broad/3d/*.csv`` (CC BY 4.0, never copied here); without them, nothing to compare.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/calibrate_peer.py [FILE ...]
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from navlib.errors import InputError
from navlib.paths import ROOT
from navlib.workbench.calibration import calibrate
from navlib.workbench.magnetometer_free import MAG, load_free

BROAD = ROOT.parent / "shared" / "realdata" / "broad" / "3d"
TRAIN_SHARE = 0.7


def algebraic(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centre ``b`` and shape ``S`` (``|S (m - b)| = 1``) of the algebraic ellipsoid fit (9 quadric terms)."""
    x, y, z = m.T
    D = np.column_stack([x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z, 2 * x, 2 * y, 2 * z])
    v = np.linalg.lstsq(D, np.ones(len(m)), rcond=None)[0]
    Q = np.array([[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]])
    b = -np.linalg.solve(Q, v[6:])
    k = 1.0 + b @ Q @ b
    w, V = np.linalg.eigh(Q / k)
    S = V @ np.diag(np.sqrt(np.abs(w))) @ V.T
    return b, S


def peer_fit(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """LM fit of ``b`` and symmetric ``S`` (the field corrected as ``S (m - b)``, magnitude ``F``)."""
    b0, S0 = algebraic(m)
    F = float(np.mean(np.linalg.norm(m - b0, axis=1)))
    iu = np.triu_indices(3)

    def unpack(p):
        S = np.zeros((3, 3))
        S[iu] = p[3:]
        return p[:3], S + np.triu(S, 1).T

    def resid(p):
        b, S = unpack(p)
        return np.linalg.norm((m - b) @ S, axis=1) - F

    p0 = np.concatenate([b0, (S0 * F)[iu]])
    r = least_squares(resid, p0, method="lm")
    return unpack(r.x)


def held_out(mc: np.ndarray, q: np.ndarray | None) -> tuple[float, float]:
    """Spread of ``|mc|`` (std / mean, %) and, with attitudes ``q`` (w, x, y, z; body to world), the RMS
    angle of the world-frame field from its mean direction (deg)."""
    mag = np.linalg.norm(mc, axis=1)
    spread = 100.0 * float(np.std(mag) / np.mean(mag))
    if q is None:
        return spread, float("nan")
    w = Rotation.from_quat(q[:, [1, 2, 3, 0]]).apply(mc)
    u = w / np.linalg.norm(w, axis=1, keepdims=True)
    mean = u.mean(axis=0)
    ang = np.degrees(np.arccos(np.clip(u @ (mean / np.linalg.norm(mean)), -1, 1)))
    return spread, float(np.sqrt(np.mean(ang ** 2)))


def one(path: Path, tmp: Path) -> dict:
    d = pd.read_csv(path)
    cut = int(TRAIN_SHARE * len(d))
    train, test = d.iloc[:cut], d.iloc[cut:]
    m_test = test[list(MAG)].to_numpy(float)
    q = test[["q_w", "q_x", "q_y", "q_z"]].to_numpy(float) if "q_w" in test else None
    row = {"file": path.stem, "rows": len(d), "raw_spread_%": held_out(m_test, q)[0],
           "raw_angle_deg": held_out(m_test, q)[1]}
    t = time.perf_counter()
    b, S = peer_fit(train[list(MAG)].to_numpy(float))
    row["peer_s"] = time.perf_counter() - t
    row["peer_spread_%"], row["peer_angle_deg"] = held_out((m_test - b) @ S, q)
    part = tmp / f"{path.stem}_train.csv"
    train.to_csv(part, index=False)
    t = time.perf_counter()
    try:
        cal = calibrate(load_free(part))
    except InputError as err:
        row["navlib_s"] = time.perf_counter() - t
        row["navlib"] = f"refused: {str(err).split(': ', 1)[-1][:60]}"
        return row
    row["navlib_s"] = time.perf_counter() - t
    A, bn = np.asarray(cal["magcal"]["A"]), np.asarray(cal["magcal"]["b_ut"])
    row["navlib_spread_%"], row["navlib_angle_deg"] = held_out((m_test - bn) @ A, q)
    row["navlib"] = "calibrated, warned" if cal.get("warnings") else "calibrated"
    return row


def main(argv: list[str]) -> int:
    files = [Path(a) for a in argv] or sorted(BROAD.glob("*.csv"))
    if not files:
        print(f"no recordings: {BROAD} is absent and no FILE was given")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        calibrate(load_free(_warm_up(Path(tmp))))            # numba kernels and imports, not timed
        rows = [one(f, Path(tmp)) for f in files]
    t = pd.DataFrame(rows)
    pd.set_option("display.width", 200)
    print(t.to_string(index=False, float_format=lambda x: f"{x:.3g}"))
    ok = t[t.navlib.str.startswith("calibrated")]
    print(f"\nnavlib calibrated {len(ok)} of {len(t)} files, refused {len(t) - len(ok)}; time per fit: navlib "
          f"median {t.navlib_s.median():.2f} s, peer {t.peer_s.median() * 1000:.0f} ms, ratio "
          f"{(t.navlib_s / t.peer_s).median():.0f}x (median over files)")
    if len(ok):
        worse = ok[ok.navlib_angle_deg > ok.raw_angle_deg]
        print(f"held-out direction RMS, median over the calibrated files: raw {ok.raw_angle_deg.median():.2f}, "
              f"peer {ok.peer_angle_deg.median():.2f}, navlib {ok.navlib_angle_deg.median():.2f} deg; navlib made "
              f"the direction worse on {len(worse)} of them, {int((worse.navlib == 'calibrated, warned').sum())} of "
              f"which it warned about (an accelerated sensor)")
    refused = t[~t.navlib.str.startswith("calibrated")]
    if len(refused):
        worse = refused[refused.peer_angle_deg > refused.raw_angle_deg]
        print(f"on the {len(refused)} files navlib refused, the peer's fit made the held-out direction worse "
              f"than no calibration on {len(worse)}")
    return 0


def _warm_up(tmp: Path) -> Path:
    from navlib.workbench.magnetometer_free import DERIVED, simulate_free
    p = tmp / "warm.csv"
    simulate_free({"hard_x_ut": 5.0}, duration_s=20.0, seed=1).drop(columns=list(DERIVED)).to_csv(p, index=False)
    return p


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
