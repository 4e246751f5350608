"""Calibrations of the BROAD magnetometer compared: ``navlib calibrate`` beside a dedicated calibrator's
ellipsoid fit on held-out rows, and the reference-free calibration beside the reference-based one in
heading.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ...errors import InputError, check_param
from ...methods.ellipsoid import lm_ellipsoid
from ...workbench.calibration import DEFAULT_MODEL, apply_calibration as apply_free, calibrate
from ...workbench.loop import LoopResult
from ...workbench.magnetometer import MAG, correct_field, heading_error_deg
from ...workbench.magnetometer_free import ACC, load_free, with_invariants
from .broad_loops import load_trial, undisturbed_trials
from .parameters import CALIBRATION_TRIAL, MAG_DIR, PEER_TRAIN_SHARE


@dataclass(frozen=True)
class PeerComparison:
    """``navlib calibrate`` beside a dedicated calibrator's fit (:func:`calibration_beside_peer`):
    ``accuracy`` per trial (rows; held-out direction RMS, deg, and magnitude spread, %, raw, peer and
    navlib; each one's outcome), ``times`` per trial (seconds per fit, this machine's clock: volatile)."""

    accuracy: pd.DataFrame
    times: pd.DataFrame

    def summary(self) -> dict:
        """Counts for the prose: trials, calibrated, warned, refused; where navlib and the peer made the
        held-out direction worse than the raw field; the median time ratio."""
        a = self.accuracy
        cal = a[a["navlib"] != "refused"]
        worse = cal[cal["navlib direction (deg)"] > cal["raw direction (deg)"]]
        return {
            "trials": len(a),
            "calibrated": len(cal),
            "warned": int((a["navlib"] == "warned").sum()),
            "peer_failed": int((a["peer"] != "fitted").sum()),
            "refused": int((a["navlib"] == "refused").sum()),
            "navlib_worse": len(worse),
            "navlib_worse_warned": int((worse["navlib"] == "warned").sum()),
            "peer_worse": int((a["peer direction (deg)"] > a["raw direction (deg)"]).sum()),
            "time_ratio": float((self.times["navlib (s)"] / self.times["peer (s)"]).median()),
        }


def held_out_field_errors(m_corrected: np.ndarray, q: np.ndarray) -> tuple[float, float]:
    """Held-out accuracy of a corrected field (n, 3): the RMS angle (deg) of the field rotated to the world
    frame by the reference attitude ``q`` (w, x, y, z; body to world) from its mean direction, and the
    spread of its magnitude (std / mean, %).  A perfect calibration in a clean field gives 0 and 0."""
    mag = np.linalg.norm(m_corrected, axis=1)
    w = Rotation.from_quat(np.asarray(q, float)[:, [1, 2, 3, 0]]).apply(m_corrected)
    u = w / np.linalg.norm(w, axis=1, keepdims=True)
    mean = u.mean(axis=0)
    ang = np.degrees(np.arccos(np.clip(u @ (mean / np.linalg.norm(mean)), -1.0, 1.0)))
    return float(np.sqrt(np.mean(ang**2))), 100.0 * float(np.std(mag) / np.mean(mag))


def calibration_beside_peer(
    files=None, train_share: float = PEER_TRAIN_SHARE
) -> PeerComparison | None:
    """``navlib calibrate`` (the library call of the CLI: :func:`navlib.workbench.calibration.calibrate` on
    :func:`~navlib.workbench.magnetometer_free.load_free` of the training rows) beside the Levenberg-Marquardt
    ellipsoid fit a dedicated calibrator does (:func:`navlib.methods.ellipsoid.lm_ellipsoid`), on every BROAD
    3-D recording (or ``files``): each fitted on the first ``train_share`` of the rows and judged on the
    rest (:func:`held_out_field_errors`; the reference attitude only judges).  navlib's outcome per trial:
    "calibrated", "warned" (calibrated with a warning, e.g. an accelerated sensor) or "refused" (the data
    cannot separate the parameters).  None without the data."""
    check_param("train_share", train_share, lo=0.1, hi=0.9)
    files = sorted(MAG_DIR.glob("*.csv")) if files is None else [Path(f) for f in files]
    if not files:
        return None
    acc, times = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            d = pd.read_csv(path)
            cut = int(train_share * len(d))
            train, test = d.iloc[:cut], d.iloc[cut:]
            m = test[list(MAG)].to_numpy(float)
            q = test[["q_w", "q_x", "q_y", "q_z"]].to_numpy(float)
            label = path.stem.replace("broad_", "").replace("_", " ")
            row = {"trial": label, "rows": len(d)}
            row["raw direction (deg)"], row["raw spread (%)"] = held_out_field_errors(m, q)
            t0 = time.perf_counter()
            try:
                b, S, _ = lm_ellipsoid(train[list(MAG)].to_numpy(float))
            except InputError:  # the algebraic start is no ellipsoid: the peer has no fit
                row["peer direction (deg)"] = row["peer spread (%)"] = float("nan")
                row["peer"] = "no ellipsoid"
            else:
                row["peer direction (deg)"], row["peer spread (%)"] = held_out_field_errors(
                    (m - b) @ S, q
                )
                row["peer"] = "fitted"
            t_peer = time.perf_counter() - t0
            part = Path(tmp) / path.name
            train.to_csv(part, index=False)
            t0 = time.perf_counter()
            try:
                cal = calibrate(load_free(part))
            except InputError:
                row["navlib direction (deg)"] = row["navlib spread (%)"] = float("nan")
                row["navlib"] = "refused"
            else:
                A, bn = np.asarray(cal["magcal"]["A"]), np.asarray(cal["magcal"]["b_ut"])
                row["navlib direction (deg)"], row["navlib spread (%)"] = held_out_field_errors(
                    (m - bn) @ A, q
                )
                row["navlib"] = "warned" if cal.get("warnings") else "calibrated"
            times.append(
                {"trial": label, "navlib (s)": time.perf_counter() - t0, "peer (s)": t_peer}
            )
            acc.append(row)
    return PeerComparison(
        pd.DataFrame(acc).set_index("trial"), pd.DataFrame(times).set_index("trial")
    )


def reference_free_headings(reference: LoopResult, row_step: int = 3) -> pd.DataFrame | None:
    """The reference-free calibration against the reference-based one on BROAD.  On the calibration
    trial 05 (every ``row_step``-th block) the reference-free system
    (:mod:`navlib.workbench.magnetometer_free`: field and accelerometer only, the reference quaternion
    ignored) is calibrated with hard iron, scale and soft iron (the full ellipsoid, what ``navlib calibrate
    magnetometer`` fits) and its correction ``(m - b) A`` applied to every undisturbed trial, beside the
    reference-based calibration ``reference`` (the loop of
    :func:`~navlib.studies.workbench.magnets.magnet_study` on the same trial) and the raw field.  Heading
    error (deg) of each against the optical reference: the corrected field levelled with the reference
    attitude, its declination minus its circular mean on that trial (so a constant heading offset, the
    declination and the rotation the invariants cannot see are not counted).  One row per trial: rows, RMS
    heading error raw / reference-free / reference-based, and the reference-free calibration's field
    strength and dip.  None if the data are absent."""
    names = undisturbed_trials()
    if not names:
        return None
    check_param("row_step", row_step, lo=1, integer=True)

    def free_frame(d):
        return with_invariants(d[list(MAG) + list(ACC) + ["time_s"]])

    cal = calibrate(
        free_frame(load_trial(CALIBRATION_TRIAL, row_step)), DEFAULT_MODEL, source=CALIBRATION_TRIAL
    )
    rows = []
    for name in names:
        d = load_trial(name, row_step)
        free = apply_free(cal, free_frame(d))[list(MAG)].to_numpy(float)

        def rms(field):
            return float(np.sqrt(np.mean(heading_error_deg(field, d) ** 2)))

        rows.append(
            {
                "trial": name.replace("broad_", "").replace(".csv", "").replace("_", " "),
                "rows": len(d),
                "raw field (deg)": rms(d[list(MAG)].to_numpy(float)),
                "reference-free calibration (deg)": rms(free),
                "reference-based calibration (deg)": rms(correct_field(reference.final.params, d)),
            }
        )
    out = pd.DataFrame(rows).set_index("trial")
    out.attrs["field_ut"] = cal["expected_field_strength_ut"]["value"]
    out.attrs["dip_deg"] = cal.get("dip_deg", float("nan"))
    return out
