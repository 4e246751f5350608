"""Convert the original BROAD recordings into the workbench's CSV files (``broad/3d/`` and the level sweeps).

BROAD (D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD - A Benchmark for Robust Inertial Orientation
Estimation", Data 6(7):72, 2021, doi:10.3390/data6070072; CC BY 4.0) is published at
github.com/dlaidig/broad.  Download its folder ``data_mat`` (one MATLAB file per trial, ``<NN>_<name>.mat``)
and run::

    python -m navlib.data.broad --in broad/data_mat --out my_broad/

which writes ``my_broad/3d/broad_<NN>_<name>.csv`` for every trial file found (``--trials 05,32`` for a
few) and, for the trials with level headings, ``my_broad/level/broad_trial<NN>_level.csv``.  Existing
files are never overwritten (the run stops with one line naming the file), and a run that stops (a
truncated trial file, Ctrl-C) writes nothing: the files go into a staging folder first and are moved into
place only when every trial is converted.  The files written are derived
and modified data under the same licence: cite BROAD wherever they are used.

What a trial file holds (its own ``info`` text says so): ``imu_gyr`` (rad/s), ``imu_acc`` (m/s^2),
``imu_mag`` (uT), all ``(n, 3)`` in the IMU's frame x forward, y left, z up (FLU); ``opt_quat`` ``(n, 4)``,
the optical reference attitude, a unit quaternion, scalar first, rotating FLU into ENU (NaN where the
cameras lost the body); ``opt_pos`` ``(n, 3)``, m, ENU; ``movement`` ``(n, 1)``, 1 in the movement phase;
``sampling_rate`` (Hz, 285.7).

**3-D files** (:func:`trial_blocks`; the schema of ``../shared/realdata/README.md``, ``broad/3d/``): the
sensor vectors are multiplied by ``diag(1, -1, -1)`` (FLU -> FRD), positions are mapped ENU -> NED
``(n, e, d) = (y, x, -z)``, and the attitude becomes ``C_b^n = P C_flu^enu D`` with ``D = diag(1, -1,
-1)`` and ``P`` the ENU -> NED permutation.  Samples ``i`` (time ``t = i / f_s``) are grouped in blocks of
0.1 s (``floor(t / 0.1)``); a block is written where at least 75 % of its samples have a valid optical
attitude, and every column is the mean over those valid samples: the attitude is the chordal mean
(the rotation nearest, in the Frobenius norm, to the mean rotation matrix ``M``: ``R = U diag(1, 1,
det(U V^T)) V^T`` from the SVD ``M = U S V^T``), ``att_blur = |M - R|_F``, roll, pitch and heading its
z-y-x Euler angles, ``moving`` 1 if at least half of the block lies in the movement phase.
``magnet_attached`` cannot be read from the recordings: for the attached-magnet trials 32-36 it is set from
the times the realdata README states (:data:`MAGNET_TIMES`: magnet put on at ``t_on``, removed at
``t_off``): -1 (handled) for blocks with mean time within ``t_on - 2 .. t_on + 3`` s and
``t_off - 1.5 .. t_off + 1.5`` s, 1 between, 0 elsewhere -- windows chosen to match the shared files, not
derived from the data; 0 in every other trial.

**Level sweeps** (:func:`level_sweep`): valid samples in motion with tilt below 10 deg and ``|gyro|``
below 100 deg/s; the FRD field levelled with the reference roll and pitch; heading error = heading of the
levelled field (``atan2(-m_y, m_x)``) minus the reference heading, wrapped; averaged in 3-deg bins of
reference heading (bins with fewer than 20 samples dropped), ``sweep`` 1 before ``t = 100`` s and 2 after
(the split the realdata README uses for trial 05).

Checked against the originals: trials 05 and 32 of github.com/dlaidig/broad (commit 7e2f818, the commit
the shared files name) converted by this module and compared with ``../shared/realdata/broad``: the same
blocks (2002 and 1590) and every 3-D column identical to the last written digit, except ``time_s``, which
differs by 0.001 s in about 5 % of the blocks (a block mean that falls on a tie of the third decimal, rounded
the other way); the level sweep of trial 05 has the same 144 bins (70 + 74) and columns identical except
``error_sd_deg`` (at most 0.0005 deg) and ``time_median_s`` (0.01 s), the same kind of tie.  The tests
(``tests/data/test_broad_convert.py``) use small synthetic trial files in BROAD's layout; the original files are
not part of this project.
"""

from __future__ import annotations

import argparse
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ..angles import wrap_deg
from ..errors import InputError
from .tables import publish, staging_folder, write_new_csv

#: The variables a BROAD trial file must hold, with their number of columns.
VARIABLES = {"imu_gyr": 3, "imu_acc": 3, "imu_mag": 3, "opt_quat": 4, "opt_pos": 3, "movement": 1}
#: Length of a block (s) and the share of its samples that must have a valid optical attitude.
BLOCK_S, MIN_VALID = 0.1, 0.75
#: Attached-magnet trials: (t_on, t_off) in s, as the realdata README states them (not derived here).
MAGNET_TIMES = {
    32: (38.2, 95.3),
    33: (42.4, 98.6),
    34: (45.1, 99.7),
    35: (42.7, 99.5),
    36: (37.0, 98.5),
}
#: Blocks flagged -1 (magnet handled): mean time within these offsets (s) of t_on and of t_off.
ON_WINDOW_S, OFF_WINDOW_S = (-2.0, 3.0), (-1.5, 1.5)
#: Level-sweep selection and binning (realdata README, ``broad/level``).
LEVEL_TILT_DEG, LEVEL_RATE_DPS, LEVEL_BIN_DEG, LEVEL_MIN_SAMPLES, LEVEL_SPLIT_S = (
    10.0,
    100.0,
    3.0,
    20,
    100.0,
)

_FLU_FRD = np.array([1.0, -1.0, -1.0])
_ENU_NED = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
_TRIAL = re.compile(r"^(\d\d)_(.+)\.mat$")

COLUMNS_3D = [
    "time_s",
    "mag_x_ut",
    "mag_y_ut",
    "mag_z_ut",
    "acc_x_ms2",
    "acc_y_ms2",
    "acc_z_ms2",
    "gyr_x_dps",
    "gyr_y_dps",
    "gyr_z_dps",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "ref_roll_deg",
    "ref_pitch_deg",
    "ref_heading_deg",
    "moving",
    "pos_n_m",
    "pos_e_m",
    "pos_d_m",
    "magnet_attached",
    "att_blur",
]
#: Decimals written per column (as in the shared files).
DECIMALS = {"time_s": 3, "mag": 3, "acc": 4, "gyr": 3, "q_": 6, "ref": 3, "pos": 4, "att_blur": 4}


# ------------------------------------------------------------------------------------------- reading
def read_trial(path) -> dict:
    """The arrays of one BROAD trial file (``.mat``), checked: every variable of :data:`VARIABLES` present
    with ``n`` rows and its number of columns, ``sampling_rate`` a positive number.  Bad input: one line
    naming the file and the variable."""
    from scipy.io import loadmat  # noqa: PLC0415  # lazy: only the .mat converter needs it

    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file")
    try:
        mat = loadmat(p)
    except Exception as err:  # scipy raises several types for a file that is not MATLAB
        raise InputError(
            f"{p.name}: not a readable MATLAB file ({type(err).__name__}: "
            f"{str(err).splitlines()[0] if str(err) else ''})"
        ) from None
    out = {}
    n = None
    for name, cols in VARIABLES.items():
        if name not in mat:
            raise InputError(
                f"{p.name}: no variable '{name}'; a BROAD trial file holds "
                f"{', '.join(VARIABLES)} and sampling_rate"
            )
        v = np.asarray(mat[name], dtype=float)
        v = v.reshape(-1, 1) if v.ndim == 1 else v
        if v.ndim != 2 or v.shape[1] != cols:
            raise InputError(
                f"{p.name}: variable '{name}' has shape {v.shape}, expected (n, {cols})"
            )
        if n is None:
            n = v.shape[0]
        elif v.shape[0] != n:
            raise InputError(f"{p.name}: variable '{name}' has {v.shape[0]} rows, imu_gyr has {n}")
        if name != "opt_quat" and name != "opt_pos" and not np.all(np.isfinite(v)):
            r = int(np.flatnonzero(~np.all(np.isfinite(v), axis=1))[0])
            raise InputError(f"{p.name}: variable '{name}', sample {r + 1}: not a finite number")
        out[name] = v
    if "sampling_rate" not in mat:
        raise InputError(f"{p.name}: no variable 'sampling_rate'")
    fs = np.asarray(mat["sampling_rate"], dtype=float).ravel()
    if fs.size != 1 or not np.isfinite(fs[0]) or fs[0] <= 0:
        raise InputError(f"{p.name}: variable 'sampling_rate' must be one positive number (Hz)")
    if n < 2:
        raise InputError(f"{p.name}: {n} samples; a trial needs more")
    out["sampling_rate"] = float(fs[0])
    return out


def trial_number(path) -> int:
    """The trial number of a BROAD file name ``NN_name.mat`` (InputError for another name)."""
    m = _TRIAL.match(Path(path).name)
    if not m:
        raise InputError(f"{Path(path).name}: not a BROAD trial file name (NN_name.mat)")
    return int(m.group(1))


def output_name(path) -> str:
    """``broad_NN_name.csv`` for ``NN_name.mat`` (``disturbed_`` dropped, as in the shared files)."""
    m = _TRIAL.match(Path(path).name)
    if not m:
        raise InputError(f"{Path(path).name}: not a BROAD trial file name (NN_name.mat)")
    name = m.group(2)
    name = name[len("disturbed_") :] if name.startswith("disturbed_") else name
    return f"broad_{m.group(1)}_{name}.csv"


# ------------------------------------------------------------------------------------------ rotations
def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(n, 3, 3)`` of unit quaternions ``(n, 4)``, scalar first (normalised here;
    :class:`scipy.spatial.transform.Rotation`)."""
    return Rotation.from_quat(np.asarray(q, float)[:, [1, 2, 3, 0]]).as_matrix()


def matrix_to_quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(n, 4)``, scalar first and non-negative, of rotation matrices ``(n, 3, 3)``."""
    q = Rotation.from_matrix(np.asarray(R, float).reshape(-1, 3, 3)).as_quat()[:, [3, 0, 1, 2]]
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def euler_zyx_deg(R: np.ndarray) -> np.ndarray:
    """Roll, pitch, heading (deg; heading in [0, 360)) of ``C_b^n`` matrices ``(n, 3, 3)``, z-y-x order."""
    heading, pitch, roll = (
        Rotation.from_matrix(np.asarray(R, float)).as_euler("ZYX", degrees=True).T
    )
    return np.column_stack([roll, pitch, np.mod(heading, 360.0)])


def attitude_frd_ned(opt_quat: np.ndarray) -> np.ndarray:
    """BROAD's optical attitude (FLU -> ENU) as ``C_b^n`` matrices, body FRD -> NED."""
    return _ENU_NED @ quat_to_matrix(opt_quat) @ np.diag(_FLU_FRD)


def chordal_mean(R: np.ndarray) -> tuple[np.ndarray, float]:
    """The chordal mean of rotations ``(k, 3, 3)`` and how far the mean matrix is from it (Frobenius
    norm, ``att_blur``)."""
    M = R.mean(axis=0)
    U, _, Vt = np.linalg.svd(M)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt))])
    Rm = U @ D @ Vt
    return Rm, float(np.linalg.norm(M - Rm))


# ------------------------------------------------------------------------------------------- 3-D files
def trial_blocks(trial: dict, number: int | None = None) -> pd.DataFrame:
    """The 0.1 s blocks of one trial (:func:`read_trial`) in the ``broad/3d`` schema (module docstring);
    ``number``: the BROAD trial number (sets ``magnet_attached`` for 32-36)."""
    fs = trial["sampling_rate"]
    n = len(trial["imu_mag"])
    t = np.arange(n) / fs
    block = np.floor(t / BLOCK_S + 1e-9).astype(np.int64)
    valid = np.all(np.isfinite(trial["opt_quat"]), axis=1) & np.all(
        np.isfinite(trial["opt_pos"]), axis=1
    )
    mag, acc = trial["imu_mag"] * _FLU_FRD, trial["imu_acc"] * _FLU_FRD
    gyr = np.degrees(trial["imu_gyr"]) * _FLU_FRD
    pos = trial["opt_pos"] @ _ENU_NED.T
    C = np.full((n, 3, 3), np.nan)
    C[valid] = attitude_frd_ned(trial["opt_quat"][valid])
    moving = trial["movement"].ravel() > 0
    starts = np.flatnonzero(np.r_[True, np.diff(block) != 0])
    ends = np.r_[starts[1:], n]
    rows = []
    for a, b in zip(starts, ends):
        ok = valid[a:b]
        if ok.sum() < MIN_VALID * (b - a) - 1e-9 or not ok.any():
            continue
        idx = np.arange(a, b)[ok]
        R, blur = chordal_mean(C[idx])
        rows.append(
            np.r_[
                t[idx].mean(),
                mag[idx].mean(0),
                acc[idx].mean(0),
                gyr[idx].mean(0),
                matrix_to_quat(R[None])[0],
                euler_zyx_deg(R[None])[0],
                float(moving[a:b].mean() >= 0.5),
                pos[idx].mean(0),
                0.0,
                blur,
            ]
        )
    if not rows:
        raise InputError(
            "no 0.1 s block has a valid optical attitude in at least 75 % of its samples"
        )
    out = pd.DataFrame(np.array(rows), columns=COLUMNS_3D)
    out["moving"] = out["moving"].astype(int)
    out["magnet_attached"] = magnet_flags(out["time_s"].to_numpy(), number)
    return out


def magnet_flags(time_s: np.ndarray, number: int | None) -> np.ndarray:
    """``magnet_attached`` per block: from :data:`MAGNET_TIMES` for trials 32-36 (module docstring), else 0."""
    flag = np.zeros(len(time_s), dtype=int)
    if number not in MAGNET_TIMES:
        return flag
    on, off = MAGNET_TIMES[number]
    flag[(time_s >= on + ON_WINDOW_S[1]) & (time_s < off + OFF_WINDOW_S[0])] = 1
    handled = ((time_s >= on + ON_WINDOW_S[0]) & (time_s < on + ON_WINDOW_S[1])) | (
        (time_s >= off + OFF_WINDOW_S[0]) & (time_s < off + OFF_WINDOW_S[1])
    )
    flag[handled] = -1
    return flag


def rounded(frame: pd.DataFrame) -> pd.DataFrame:
    """The 3-D columns rounded as in the shared files (:data:`DECIMALS`)."""
    out = frame.copy()
    for col in out.columns:
        for prefix, d in DECIMALS.items():
            if col.startswith(prefix) and pd.api.types.is_float_dtype(out[col]):
                out[col] = out[col].round(d)
                break
    return out


# ----------------------------------------------------------------------------------------- level sweeps
def level_sweep(
    trial: dict, number: int | None = None, split_s: float = LEVEL_SPLIT_S
) -> pd.DataFrame:
    """A level compass sweep of one trial in the compass CSV schema (module docstring): one row per 3-deg
    bin of reference heading with at least 20 selected samples (``error_sd_deg``: the population standard
    deviation of the samples' errors about the bin's mean error; ``trials``: ``number`` as two digits),
    rounded as the shared files; empty when the trial has none."""
    fs = trial["sampling_rate"]
    n = len(trial["imu_mag"])
    t = np.arange(n) / fs
    valid = np.all(np.isfinite(trial["opt_quat"]), axis=1)
    moving = trial["movement"].ravel() > 0
    C = np.full((n, 3, 3), np.nan)
    C[valid] = attitude_frd_ned(trial["opt_quat"][valid])
    eul = np.full((n, 3), np.nan)
    eul[valid] = euler_zyx_deg(C[valid])
    rate = np.linalg.norm(np.degrees(trial["imu_gyr"]), axis=1)
    tilt = np.full(n, np.nan)
    tilt[valid] = np.degrees(np.arccos(np.clip(C[valid][:, 2, 2], -1.0, 1.0)))
    sel = valid & moving & (tilt < LEVEL_TILT_DEG) & (rate < LEVEL_RATE_DPS)
    if not sel.any():
        return pd.DataFrame(columns=["true_heading_deg", "measured_heading_deg", "sweep"])
    mag = trial["imu_mag"][sel] * _FLU_FRD
    acc = trial["imu_acc"][sel] * _FLU_FRD
    roll, pitch, ref = np.radians(eul[sel, 0]), np.radians(eul[sel, 1]), eul[sel, 2]
    # level the field: undo roll (about x) and pitch (about y), C_b^n = Rz Ry Rx
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    hx = cp * mag[:, 0] + sp * sr * mag[:, 1] + sp * cr * mag[:, 2]
    hy = cr * mag[:, 1] - sr * mag[:, 2]
    err = wrap_deg(np.degrees(np.arctan2(-hy, hx)) - ref)
    sweep = np.where(t[sel] < split_s, 1, 2)
    frame = pd.DataFrame(
        {
            "ref": ref,
            "err": err,
            "sweep": sweep,
            "t": t[sel],
            "tilt": tilt[sel],
            "roll": eul[sel, 0],
            "pitch": eul[sel, 1],
            **{f"mag_{a}_ut": mag[:, i] for i, a in enumerate("xyz")},
            **{f"acc_{a}_ms2": acc[:, i] for i, a in enumerate("xyz")},
        }
    )
    frame["bin"] = np.floor(frame["ref"] / LEVEL_BIN_DEG).astype(int)
    rows = []
    for (s, _), g in frame.groupby(["sweep", "bin"], sort=True):
        if len(g) < LEVEL_MIN_SAMPLES:
            continue
        true = np.mod(np.degrees(np.angle(np.mean(np.exp(1j * np.radians(g["ref"]))))), 360.0)
        e = np.degrees(np.angle(np.mean(np.exp(1j * np.radians(g["err"])))))
        rows.append(
            {
                "true_heading_deg": true,
                "measured_heading_deg": np.mod(true + e, 360.0),
                "heading_error_deg": e,
                "error_sd_deg": float(np.std(wrap_deg(g["err"] - e))),
                "n_samples": len(g),
                "sweep": int(s),
                "time_median_s": float(np.median(g["t"])),
                "trials": "" if number is None else f"{int(number):02d}",
                **{c: float(g[c].mean()) for c in frame.columns if c.startswith(("mag_", "acc_"))},
                "ref_roll_deg": float(g["roll"].mean()),
                "ref_pitch_deg": float(g["pitch"].mean()),
                "ref_tilt_deg": float(g["tilt"].mean()),
            }
        )
    out = pd.DataFrame(rows)
    for col in out.columns:
        if pd.api.types.is_float_dtype(out[col]):
            out[col] = out[col].round(
                2 if col == "time_median_s" else 3 if col.startswith("ref_") else 4
            )
    return out


# ---------------------------------------------------------------------------------------------- folders
def convert(in_dir, out_dir, trials=None, level: bool = True) -> list[Path]:
    """Convert every ``NN_name.mat`` in ``in_dir`` (or the trial numbers in ``trials``) into
    ``out_dir/3d/broad_NN_name.csv`` and, where a trial has level headings, ``out_dir/level/
    broad_trialNN_level.csv``.  All or nothing: every file is written into a staging folder beside the
    target first (:func:`navlib.data.tables.staging_folder`) and moved into ``out_dir`` only when every trial
    has been converted (:func:`navlib.data.tables.publish`), so a bad or truncated trial file, an error or
    Ctrl-C leaves ``out_dir`` as it was.  Never overwrites a file: an existing output stops the run before any
    file is written (one-line InputError naming it).  Returns the paths written."""
    src = Path(in_dir)
    if not src.is_dir():
        raise InputError(f"{src}: no such folder (give --in the folder data_mat of BROAD)")
    files = sorted(p for p in src.glob("*.mat") if _TRIAL.match(p.name))
    if trials is not None:
        wanted = {int(t) for t in trials}
        missing = wanted - {trial_number(p) for p in files}
        if missing:
            raise InputError(
                f"{src}: no file for trial {', '.join(f'{m:02d}' for m in sorted(missing))}"
            )
        files = [p for p in files if trial_number(p) in wanted]
    if not files:
        raise InputError(f"{src}: no BROAD trial file (NN_name.mat) in this folder")
    out = Path(out_dir)
    targets = [
        (
            p,
            out / "3d" / output_name(p),
            out / "level" / f"broad_trial{trial_number(p):02d}_level.csv",
        )
        for p in files
    ]
    for _, f3, fl in targets:
        for f in (f3, fl) if level else (f3,):
            if f.exists():
                raise InputError(f"{f}: already exists; not overwritten (choose another --out)")
    staging = staging_folder(out)  # all or nothing: written here, then moved into out
    try:
        written = []
        for p, f3, fl in targets:
            trial = read_trial(p)
            written.append(
                write_new_csv(
                    rounded(trial_blocks(trial, trial_number(p))), staging / f3.relative_to(out)
                )
            )
            if level:
                sweep = level_sweep(trial, trial_number(p))
                if len(sweep):
                    written.append(write_new_csv(sweep, staging / fl.relative_to(out)))
        where = publish(staging, out)
        return [where[w] for w in written]
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def main(argv: list[str] | None = None) -> int:
    """``python -m navlib.data.broad --in DIR --out DIR [--trials 05,32] [--no-level]``; bad input: one
    line on stderr, exit status 2; Ctrl-C: one line, exit status 130, nothing written."""
    ap = argparse.ArgumentParser(
        prog="python -m navlib.data.broad",
        description="Convert BROAD's data_mat/*.mat into the workbench's CSV files.",
    )
    ap.add_argument(
        "--in", dest="in_dir", required=True, help="folder holding BROAD's NN_name.mat files"
    )
    ap.add_argument(
        "--out", required=True, help="folder for 3d/ and level/ (existing files are never replaced)"
    )
    ap.add_argument(
        "--trials", default=None, help="comma-separated trial numbers (default: every file)"
    )
    ap.add_argument("--no-level", action="store_true", help="write the 3-D files only")
    args = ap.parse_args(argv)
    try:
        trials = None
        if args.trials:
            try:
                trials = [int(t) for t in args.trials.split(",") if t.strip()]
            except ValueError:
                raise InputError(
                    f"--trials {args.trials!r}: comma-separated trial numbers, e.g. 05,32"
                ) from None
        for path in convert(args.in_dir, args.out, trials, level=not args.no_level):
            print(path)
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C: nothing was written (convert is all or nothing)
        print("interrupted; nothing written", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
