"""The ``magnetometer`` system: a 3-D magnetometer with a reference attitude.

Measurement model (body frame FRD, navigation frame NED, field in uT)::

    m_i = A C_n^b(t_i + dt) m_n + b + noise,    A = R(theta) (I + S)

- ``m_n`` the local Earth field in NED, always estimated (its dip ``atan(m_d / |m_h|)`` and intensity
  ``|m_n|`` are reported by :func:`field_summary`);
- ``hard_iron`` = ``b`` (uT): a field fixed to the body (a magnet on the board, sensor offsets);
- ``soft_iron`` = ``S``, symmetric and trace-free (5 parameters): induced magnetisation and scale mismatch
  (the mean scale is not observable: it trades against ``|m_n|``);
- ``misalignment`` = ``theta`` (deg, a rotation vector): the sensor's axes turned against the body frame of
  the reference attitude;
- ``time_lag`` = ``dt`` (s): the magnetometer and the reference clock disagree; to first order
  ``C_n^b(t + dt) m_n = C_n^b m_n - dt omega x (C_n^b m_n)`` with the body rate ``omega`` (gyro columns).
  This is what the residuals of the undisturbed BROAD trials called for: against angular rate they grow
  linearly, against time and position they do not.

The residual is ``m - model`` (3 values per row, uT).  Structure tests (shapes no body-fixed effect
produces): a per-axis trend in time (a drifting offset), a per-axis linear dependence on position (a
field that changes across the room, as near a stationary magnet), and a per-axis dependence on ``|omega|``.

Files: ``mag_x_ut, mag_y_ut, mag_z_ut`` and the reference attitude quaternion ``q_w, q_x, q_y, q_z``
(scalar first, rotating body FRD into NED); optional ``time_s``, ``gyr_*_dps``, ``pos_*_m`` and others
(``../shared/realdata/broad/3d``).  :func:`load_magnetometer` reports bad input in one line naming file,
column and row.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ..angles import wrap_deg
from ..data.tables import Column, read_table, require_variation, where
from ..errors import InputError
from ..methods.ellipsoid import algebraic_ellipsoid
from .effects import Effect, System, register_system
from .fit import MEASURED, Fit, best_least_squares, lstsq, user_columns, user_design
from .serial import ar1_noise

MAG = ("mag_x_ut", "mag_y_ut", "mag_z_ut")
QUAT = ("q_w", "q_x", "q_y", "q_z")
GYR = ("gyr_x_dps", "gyr_y_dps", "gyr_z_dps")
POS = ("pos_n_m", "pos_e_m", "pos_d_m")
FIELD = ("field_n_ut", "field_e_ut", "field_d_ut")
QUAT_TOL = 0.01  # |q| must be within 1 +- this
MIN_ORIENTATIONS = 12  # distinct 30-deg attitude cells needed to separate the effects
MIN_TILT_DEG = 10.0  # the down axis must leave the body z axis by at least this much somewhere

MAGNETOMETER_EFFECTS = {
    "hard_iron": Effect(
        "hard_iron",
        ("hard_x_ut", "hard_y_ut", "hard_z_ut"),
        ("uT", "uT", "uT"),
        "A field fixed to the body (a magnet or magnetised steel on the board, sensor offsets) adds the same "
        "vector in every attitude. Missing, the residual is a constant vector in the body frame.",
    ),
    "soft_iron": Effect(
        "soft_iron",
        ("soft_xx", "soft_yy", "soft_xy", "soft_xz", "soft_yz"),
        ("-",) * 5,
        "Soft iron magnetised by the Earth field and per-axis scale mismatch scale the field differently "
        "along different body axes (symmetric, trace-free). Missing, the residual is quadratic in the "
        "attitude: the measured field traces an ellipsoid, not a sphere.",
    ),
    "misalignment": Effect(
        "misalignment",
        ("mis_x_deg", "mis_y_deg", "mis_z_deg"),
        ("deg", "deg", "deg"),
        "The magnetometer's axes are turned against the body frame the reference attitude describes. "
        "Missing, the residual is the field rotated by a small fixed angle: perpendicular to the field.",
    ),
    "time_lag": Effect(
        "time_lag",
        ("time_lag_s",),
        ("s",),
        "The magnetometer and the attitude reference are sampled with a time offset. Missing, the residual "
        "grows with the angular rate (omega x field).",
        GYR,
    ),
}

_PARAMS = [p for e in MAGNETOMETER_EFFECTS.values() for p in e.params]
#: The local field of BROAD's room (pooled undisturbed trials, ../shared/realdata README), NED, uT: the
#: simulators' default.
BROAD_FIELD = {"field_n_ut": 15.2, "field_e_ut": -0.3, "field_d_ut": 40.8}


# Limits of the checked columns (a value outside is refused in one line naming file, column and row):
# field +-1e6 uT (1 T, beyond any magnetometer's range; a file in nT still passes, so that the unit check
# can name the unit), quaternion components +-1.5, rates +-1e5 deg/s, positions +-1e7 m, time +-1e10 s.
# The other columns BROAD's files carry are informational (never refused).
MAG_LIMIT_UT = 1e6
#: The intensity of the field that follows the reference attitude must be within this band (uT): the
#: Earth's field is 22-67 uT at the surface; a building changes it by a few tens of per cent.
FIELD_BAND_UT = (10.0, 150.0)
#: Units a field may have been written in by mistake, with the factor that converts them to uT.
FIELD_UNITS = (("gauss or oersted", 100.0), ("mG", 0.1), ("nT", 1e-3), ("mT", 1e3), ("T", 1e6))
#: The share of the field's variation the attitude must explain (through any fixed linear map of the
#: axes, plus a constant); below it the columns are not a magnetometer turned with that attitude.
MIN_EXPLAINED = 0.25
#: Rows whose field is farther than this many times the median distance from the attitude fit are set aside
#: before the checks (at most half of them; Gaussian noise reaches 5 medians with probability below 1e-9).
TRIM = 5.0


#: The body axes (FRD) in words, for the file schemas' meanings.
AXES = {"x": "x forward", "y": "y right", "z": "z down"}
# The file schema of the ``magnetometer`` system (what :func:`load_magnetometer` reads; the data
# dictionary of :func:`navlib.data.tables.schema_table`).
MAGNETOMETER_COLUMNS = tuple(
    [
        Column(
            c, "uT", lo=-MAG_LIMIT_UT, hi=MAG_LIMIT_UT, meaning=f"magnetometer, {AXES[c[4]]} (FRD)"
        )
        for c in MAG
    ]
    + [
        Column(
            c,
            "",
            lo=-1.5,
            hi=1.5,
            meaning=(
                "reference attitude, unit quaternion, scalar first, body FRD to NED"
                if c == "q_w"
                else "reference attitude quaternion, vector part"
            ),
        )
        for c in QUAT
    ]
    + [
        Column(
            c,
            "deg/s",
            required=False,
            lo=-1e5,
            hi=1e5,
            meaning=f"angular rate, {AXES[c[4]]} (the time_lag effect needs all three)",
        )
        for c in GYR
    ]
    + [
        Column(
            c,
            "m",
            required=False,
            lo=-1e7,
            hi=1e7,
            meaning=f"position, {d} (a field that changes with position)",
        )
        for c, d in zip(POS, ("north", "east", "down"))
    ]
    + [
        Column(
            "time_s",
            "s",
            required=False,
            lo=-1e10,
            hi=1e10,
            meaning="time of the sample (a field that changes in time)",
        )
    ]
    + [
        Column(c, u, required=False, checked=False, meaning=m)
        for c, u, m in (
            ("moving", "0/1", "1 while the sensor moves (information only)"),
            ("magnet_attached", "-1/0/1", "BROAD's magnet flag (information only)"),
            ("att_blur", "-", "attitude blur of a block mean (information only)"),
            ("acc_x_ms2", "m/s^2", "specific force, x forward (information only)"),
            ("acc_y_ms2", "m/s^2", "specific force, y right (information only)"),
            ("acc_z_ms2", "m/s^2", "specific force, z down (information only)"),
            ("ref_roll_deg", "deg", "reference roll (information only)"),
            ("ref_pitch_deg", "deg", "reference pitch (information only)"),
            ("ref_heading_deg", "deg", "reference heading (information only)"),
        )
    ]
)


def quaternion_columns() -> list[Column]:
    """The columns of ``MAGNETOMETER_COLUMNS``, as a list."""
    return list(MAGNETOMETER_COLUMNS)


def load_magnetometer(path, *, min_rows: int = 30) -> pd.DataFrame:
    """Load and validate a 3-D magnetometer file with reference attitude.

    One-line errors naming file, column and row: missing field or attitude columns; empty cells, text,
    NaN or infinity; a value outside its limits (field +-1e6 uT, quaternion components +-1.5, gyro
    +-1e5 deg/s, position +-1e7 m, time +-1e10 s); a quaternion whose norm is farther than 0.01 from 1;
    fewer than ``min_rows`` rows; too few distinct orientations (fewer than 12 attitude cells of 30 deg,
    or no tilt of 10 deg) to separate the hard iron from the local field; and the plausibility checks of
    :func:`check_field` (a stuck axis, a field that does not follow the attitude, axes in another frame
    than FRD, a unit other than uT) and :func:`check_rates` (gyro rates in another unit than deg/s).  Informational columns (``moving``, ``magnet_attached``,
    ``att_blur``, ``acc_*_ms2``, ``ref_*_deg``) and columns not named here are never refused."""
    frame = read_table(path, MAGNETOMETER_COLUMNS, min_rows=min_rows, kind="magnetometer file")
    q = frame[list(QUAT)].to_numpy(float)
    norm = np.linalg.norm(q, axis=1)
    bad = np.flatnonzero(np.abs(norm - 1.0) > QUAT_TOL)
    if bad.size:
        r = int(bad[0])
        raise InputError(
            f"{where(path, 'q_w..q_z', r, frame)}: quaternion norm "
            f"{norm[r]:.4f}; a unit quaternion is needed (within {QUAT_TOL:g})"
        )
    check_orientations(frame, Path(path).name)
    check_field(frame, Path(path).name)
    check_rates(frame, Path(path).name)
    return frame


#: Units a rate may have been written in by mistake, with the factor that converts them to deg/s.
RATE_UNITS = (("rad/s", 180.0 / np.pi), ("mdeg/s", 1e-3), ("deg/h", 1 / 3600.0), ("rpm", 6.0))


def check_rates(frame: pd.DataFrame, name: str = "data") -> None:
    """Plausibility of the gyro columns (used by ``time_lag`` and the rate structure test), where the file
    is a trajectory with times: the rate of the reference attitude between consecutive rows (rotation
    angle over time step, rows at most 0.5 s apart; a trajectory when the median step is below 60 deg) is
    compared with the mean ``|omega|`` of the two rows, over the rows turning faster than 5 deg/s (at
    least 20).  The median ratio must lie within 0.5..2 (BROAD: 1.00-1.01); otherwise one line names the
    unit that brings it there (rad/s x57.3, mdeg/s, deg/h, rpm) or says that the rates do not match."""
    if "time_s" not in frame or not all(c in frame for c in GYR):
        return
    q = frame[list(QUAT)].to_numpy(float)
    rot = Rotation.from_quat(q[:, [1, 2, 3, 0]] / np.linalg.norm(q, axis=1, keepdims=True))
    step = np.degrees((rot[:-1].inv() * rot[1:]).magnitude())
    dt = np.diff(frame["time_s"].to_numpy(float))
    ok = (dt > 0) & (dt <= 0.5)
    if ok.sum() < 20 or np.median(step[ok]) >= 60.0:
        return
    rate = step / np.where(ok, dt, 1.0)
    w = np.linalg.norm(frame[list(GYR)].to_numpy(float), axis=1)
    gyro = 0.5 * (w[:-1] + w[1:])
    turning = ok & (rate > 5.0)
    if turning.sum() < 20:
        return
    ratio = float(np.median(gyro[turning] / rate[turning]))
    if 0.5 <= ratio <= 2.0:
        return
    near = [(u, f) for u, f in RATE_UNITS if 0.5 <= ratio * f <= 2.0]
    look = (
        f"these look like {near[0][0]} (multiply by {near[0][1]:.6g} for deg/s)"
        if near
        else "the gyro and the reference attitude disagree"
    )
    raise InputError(
        f"{name}: columns {', '.join(GYR)}: |omega| is {ratio:.3g} times the rate at which the "
        f"reference attitude turns (median over {int(turning.sum())} turning rows; 0.5..2 accepted): "
        f"{look}"
    )


_AXES = ("x", "y", "z")


def _signed_permutation(M: np.ndarray) -> np.ndarray | None:
    """The signed permutation matrix nearest to ``M`` (each row's largest entry), or None if the rows do
    not pick three different axes."""
    k = np.argmax(np.abs(M), axis=1)
    if len(set(k.tolist())) != 3:
        return None
    P = np.zeros((3, 3))
    P[np.arange(3), k] = np.sign(M[np.arange(3), k])
    return P


def check_field(frame: pd.DataFrame, name: str = "data") -> None:
    """Plausibility of the field columns; each failure is one line naming the columns and what they look
    like.  Method: linear least squares of the field on the reference attitude ``C = C_n^b``.

    1. No axis may be constant (a stuck or unconnected axis).  The fits below set aside rows farther than
       ``TRIM`` (5) median distances from the fit (refitted up to four times, never more than half of the
       rows), so that a few spikes are left to the outlier screening and not mistaken for a unit.
    2. The field must follow the attitude: ``m_j = sum_kl W_jkl C_kl + b_j`` (any fixed linear map of the
       axes, soft iron and misalignment included, plus a constant) must explain at least ``MIN_EXPLAINED``
       (25 %) of the field's variation (the undisturbed BROAD trials: more than 97 %; trial 32, with a
       magnet attached and removed during the recording: 57 %).
    3. The axes must be FRD: ``W_jkl = M_jk n_l`` is factorised (the leading singular pair; ``n`` taken
       with a northward component); if the signed permutation nearest to ``M`` is not the identity and
       ``M`` is within 0.5 of it (Frobenius), the axes are in another frame (FLU, swapped or reversed axes)
       and the message says how each axis reads.
    4. The unit must be uT: the intensity ``|m_n|`` of the field that follows the attitude
       (``m = C m_n + b``) must lie in ``FIELD_BAND_UT`` (10-150 uT; the Earth's field is 22-67 uT, BROAD's
       room 43-55 uT); outside it the message names the unit that brings it into the band (gauss or
       oersted x100, mG x0.1, nT x0.001, mT x1000, T x1e6) and the median ``|m|``.
    """
    require_variation(frame, MAG, name, "a magnetometer turned through many attitudes")
    m = frame[list(MAG)].to_numpy(float)
    C = body_from_nav(frame)
    cols = "columns mag_x_ut, mag_y_ut, mag_z_ut"
    X = np.column_stack([C.reshape(len(m), 9), np.ones(len(m))])
    keep = np.ones(len(m), bool)
    for _ in range(4):  # set wild rows aside (a spike must not pass for a unit)
        W = np.column_stack([lstsq(X[keep], m[keep, j]) for j in range(3)])  # (10, 3)
        e = np.linalg.norm(m - X @ W, axis=1)
        inside = e <= TRIM * np.median(e[keep])
        if np.array_equal(inside, keep) or inside.sum() < len(m) // 2:
            break
        keep = inside
    m, C, X = m[keep], C[keep], X[keep]
    explained = 1.0 - float(np.sum((m - X @ W) ** 2)) / float(np.sum((m - m.mean(axis=0)) ** 2))
    if explained < MIN_EXPLAINED:
        raise InputError(
            f"{name}: {cols}: the reference attitude explains only {100 * max(explained, 0.0):.0f} "
            f"% of the field's variation (a magnetometer turned with it: more than "
            f"{100 * MIN_EXPLAINED:.0f} %); a stuck or disconnected sensor, or the attitude of "
            f"another body or time?"
        )
    # W[k*3 + l, j] = M_jk n_l: rows (j, k), columns l
    G = W[:9].T.reshape(3, 3, 3).reshape(9, 3)
    u, s, vt = np.linalg.svd(G, full_matrices=False)
    M, n = u[:, 0].reshape(3, 3) * np.sqrt(3.0), vt[0] * s[0] / np.sqrt(3.0)
    if n[0] < 0:
        M, n = -M, -n
    P = _signed_permutation(M)
    if (
        P is not None
        and not np.array_equal(P, np.eye(3))
        and np.linalg.norm(M - P) < 0.5
        and n[0] > 0.2 * np.linalg.norm(n)
    ):
        k = np.argmax(np.abs(P), axis=1)
        said = " and ".join(
            f"{MAG[j]} holds {'-' if P[j, k[j]] < 0 else ''}{_AXES[k[j]]}"
            for j in range(3)
            if not (k[j] == j and P[j, k[j]] > 0)
        )
        hint = (
            " (FLU: y left, z up; multiply y and z by -1)"
            if np.array_equal(P, np.diag([1.0, -1.0, -1.0]))
            else ""
        )
        raise InputError(
            f"{name}: {cols}: the axes are not FRD (x forward, y right, z down): the field "
            f"follows the attitude only if {said}{hint}; convert the axes to FRD"
        )
    Xf = np.column_stack(
        [C[:, :, j].reshape(-1) for j in range(3)]
        + [np.tile(np.eye(3)[j], len(m)) for j in range(3)]
    )
    intensity = float(np.linalg.norm(lstsq(Xf, m.ravel())[:3]))
    lo, hi = FIELD_BAND_UT
    if not lo <= intensity <= hi:
        median = float(np.median(np.linalg.norm(m, axis=1)))
        units = [(unit, f) for unit, f in FIELD_UNITS if lo <= intensity * f <= hi]
        look = (
            f"these look like {units[0][0]} (multiply by {units[0][1]:g} for uT)"
            if units
            else "this is not a field in uT"
        )
        raise InputError(
            f"{name}: {cols}: the field that follows the attitude has an intensity of "
            f"{intensity:.4g} (median |m| {median:.4g}), where the Earth's field is 22-67 uT "
            f"and {lo:g}-{hi:g} uT is accepted: {look}"
        )


def body_from_nav(frame: pd.DataFrame) -> np.ndarray:
    """``C_n^b`` for every row, shape (n, 3, 3), from the scalar-first quaternion rotating body into NED."""
    q = frame[list(QUAT)].to_numpy(float)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix().transpose(0, 2, 1)


def check_orientations(frame: pd.DataFrame, name: str = "data") -> None:
    """Enough distinct orientations to separate the effects (see :func:`load_magnetometer`)."""
    C = body_from_nav(frame)
    down = C[:, :, 2]  # NED down in body axes
    north = C[:, :, 0]
    cells = {tuple(v) for v in np.round(np.column_stack([down, north]) * 2).astype(int)}
    tilt = np.degrees(np.arccos(np.clip(down[:, 2], -1, 1)))
    failed = []
    if len(cells) < MIN_ORIENTATIONS:
        failed.append(
            f"only {len(cells)} distinct orientations (30-deg cells; at least {MIN_ORIENTATIONS} "
            f"are needed)"
        )
    if np.max(np.abs(tilt - np.median(tilt))) < MIN_TILT_DEG:
        failed.append(
            f"a tilt of at most {np.max(np.abs(tilt - np.median(tilt))):.1f} deg from the median "
            f"(at least {MIN_TILT_DEG:g} deg is needed)"
        )
    if failed:
        raise InputError(
            f"{name}: columns q_w..q_z, rows 1..{len(frame)}: {' and '.join(failed)}, to separate "
            f"hard iron from the local field"
        )


def _rotation(theta_deg) -> np.ndarray:
    return Rotation.from_rotvec(np.radians(theta_deg)).as_matrix()


def _matrix(p: dict) -> np.ndarray:
    """A = R(theta) (I + S)."""
    S = np.array(
        [
            [p["soft_xx"], p["soft_xy"], p["soft_xz"]],
            [p["soft_xy"], p["soft_yy"], p["soft_yz"]],
            [p["soft_xz"], p["soft_yz"], -p["soft_xx"] - p["soft_yy"]],
        ]
    )
    return _rotation([p["mis_x_deg"], p["mis_y_deg"], p["mis_z_deg"]]) @ (np.eye(3) + S)


def full_params(params: dict) -> dict:
    p = {k: 0.0 for k in _PARAMS}
    p.update(params)
    return p


def predict_field(
    params: dict, frame: pd.DataFrame, C: np.ndarray | None = None, w: np.ndarray | None = None
) -> np.ndarray:
    """Model field (n, 3) in body axes for catalogued parameters ``params`` (absent = 0); ``C`` and the body
    rate ``w`` (rad/s) may be given precomputed from ``frame``."""
    p = full_params(params)
    C = body_from_nav(frame) if C is None else C
    v = C @ np.array([p[k] for k in FIELD])
    if p["time_lag_s"]:
        w = np.radians(frame[list(GYR)].to_numpy(float)) if w is None else w
        v = v - p["time_lag_s"] * np.cross(w, v)
    return v @ _matrix(p).T + np.array([p["hard_x_ut"], p["hard_y_ut"], p["hard_z_ut"]])


def correct_field(params: dict, frame: pd.DataFrame) -> np.ndarray:
    """Invert the body-fixed part: ``A^-1 (m - b)``, (n, 3) uT."""
    p = full_params(params)
    m = frame[list(MAG)].to_numpy(float) - np.array(
        [p["hard_x_ut"], p["hard_y_ut"], p["hard_z_ut"]]
    )
    return m @ np.linalg.inv(_matrix(p)).T


def _fit_magnetometer(data: pd.DataFrame, effects: tuple[Effect, ...], start) -> Fit:
    cat = tuple(e.name for e in effects if e.contribution is None)
    users = tuple(e for e in effects if e.contribution is not None)
    names = (
        list(FIELD)
        + [p for e in cat for p in MAGNETOMETER_EFFECTS[e].params]
        + [p for e in users for p in e.params]
    )
    clash = sorted({n for n in names if names.count(n) > 1})
    if clash:
        raise InputError(
            f"parameter '{clash[0]}' is named twice in the model (a user effect's parameter must "
            f"not be named like the local field {', '.join(FIELD)})"
        )
    m = data[list(MAG)].to_numpy(float)
    C = body_from_nav(data)
    shape = m.shape
    if m.size < len(names) + 1:
        raise InputError(f"{len(m)} rows cannot determine {len(names)} model parameters")

    rate = np.radians(data[list(GYR)].to_numpy(float)) if all(c in data for c in GYR) else None

    def model(x):
        p = dict(zip(names, x))
        return predict_field(p, data, C, rate).ravel() + user_columns(users, p, data, shape)

    # start 2 (linearised): m = C m_n + b (+ linear user terms), all else zero -- linear least squares
    lin = [C[:, :, j].reshape(-1) for j in range(3)]  # d m / d m_n
    hard = "hard_iron" in cat
    if hard:
        lin += [np.tile(np.eye(3)[j], len(m)) for j in range(3)]
    X = np.column_stack(lin + ([user_design(users, data, shape)] if users else []))
    beta = lstsq(X, m.ravel())
    x2 = np.zeros(len(names))
    x2[:3] = beta[:3]
    if hard:
        x2[names.index("hard_x_ut") : names.index("hard_x_ut") + 3] = beta[3:6]
    if users:
        k = len([p for e in users for p in e.params])
        x2[-k:] = beta[-k:]
    # start 1: the previous model's parameters, new ones at zero (field from start 2 if new)
    x1 = np.array([(start or {}).get(n, x2[i] if i < 3 else 0.0) for i, n in enumerate(names)])
    inf = np.full(len(names), np.inf)
    w = np.radians(data[list(GYR)].to_numpy(float)) if "time_lag" in cat else None

    def jacobian(x):
        return _jacobian(dict(zip(names, x)), names, C, w, users, data)

    sol = best_least_squares(lambda x: model(x) - m.ravel(), [x1, x2], -inf, inf, jac=jacobian)
    params = dict(zip(names, map(float, sol.x)))

    def predict(frame):
        return predict_field(params, frame) + user_columns(
            users, params, frame, (len(frame), 3)
        ).reshape(-1, 3)

    return Fit(
        SYSTEM,
        tuple(e.name for e in effects),
        params,
        data,
        m.ravel() - model(sol.x),
        np.asarray(sol.jac),
        predict,
    )


_SOFT_BASIS = {
    "soft_xx": np.diag([1.0, 0.0, -1.0]),
    "soft_yy": np.diag([0.0, 1.0, -1.0]),
    "soft_xy": np.array([[0, 1.0, 0], [1.0, 0, 0], [0, 0, 0]]),
    "soft_xz": np.array([[0, 0, 1.0], [0, 0, 0], [1.0, 0, 0]]),
    "soft_yz": np.array([[0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]]),
}


def _jacobian(params: dict, names, C, w, users, data) -> np.ndarray:
    """d(model)/d(parameters) of :func:`predict_field` (analytic; the rotation's derivative by central
    differences of the 3x3 matrix; user effects by central differences)."""
    p = full_params(params)
    theta = np.array([p["mis_x_deg"], p["mis_y_deg"], p["mis_z_deg"]])
    R = _rotation(theta)
    W = _matrix({**p, "mis_x_deg": 0.0, "mis_y_deg": 0.0, "mis_z_deg": 0.0})
    A = R @ W
    dt = p["time_lag_s"]

    def lag(u):
        return u - dt * np.cross(w, u) if (dt and w is not None) else u

    v = C @ np.array([p[k] for k in FIELD])
    vl = lag(v)
    cols = {}
    for k, name in enumerate(FIELD):
        cols[name] = lag(C[:, :, k]) @ A.T
    for j, name in enumerate(("hard_x_ut", "hard_y_ut", "hard_z_ut")):
        e = np.zeros((len(v), 3))
        e[:, j] = 1.0
        cols[name] = e
    for name, D in _SOFT_BASIS.items():
        cols[name] = vl @ (R @ D).T
    h = 1e-4
    for k, name in enumerate(("mis_x_deg", "mis_y_deg", "mis_z_deg")):
        step = np.zeros(3)
        step[k] = h
        dR = (_rotation(theta + step) - _rotation(theta - step)) / (2 * h)
        cols[name] = vl @ (dR @ W).T
    if w is not None:
        cols["time_lag_s"] = -np.cross(w, v) @ A.T
    for e in users:
        for name in e.params:
            q = dict(params)
            d = 1e-6 * (1.0 + abs(q[name]))
            q[name] = params[name] + d
            up = user_columns([e], q, data, v.shape)
            q[name] = params[name] - d
            cols[name] = ((up - user_columns([e], q, data, v.shape)) / (2 * d)).reshape(-1, 3)
    return np.column_stack([cols[n].reshape(-1) for n in names])


def _per_axis(x: np.ndarray) -> np.ndarray:
    """A row covariate as three columns, one per axis of the flattened (n, 3) residual."""
    n = len(x)
    out = np.zeros((3 * n, 3))
    for j in range(3):
        out[j::3, j] = x
    return out


def _cells(x: np.ndarray, bins: int) -> np.ndarray:
    """Quantile cell index (0..bins-1) of each value."""
    edges = np.quantile(x, np.linspace(0, 1, bins + 1)[1:-1])
    return np.searchsorted(edges, x, side="right")


def _cell_offsets(cell: np.ndarray) -> np.ndarray:
    """Per-axis offset of every cell but the first, centred: columns for a piecewise-constant field."""
    ids = np.unique(cell)
    cols = [_per_axis((cell == i).astype(float) - np.mean(cell == i)) for i in ids[1:]]
    return np.column_stack(cols) if cols else np.zeros((3 * len(cell), 0))


def magnetometer_structure(fit: Fit) -> list[tuple[str, np.ndarray, float]]:
    """Shapes no body-fixed effect produces (module docstring): a field that changes in time (an offset
    per 10 % of the recording and axis), with position (an offset per position cell -- the room split at
    the median along each axis, 8 cells -- and axis), and with the angular rate ``|omega|`` (per axis)."""
    d = fit.data
    out = []
    if "time_s" in d and np.ptp(d["time_s"].to_numpy(float)) > 0:
        out.append(
            (
                "field changing in time (per axis)",
                _cell_offsets(_cells(d["time_s"].to_numpy(float), 10)),
                2.0,
            )
        )
    if all(c in d for c in POS):
        P = d[list(POS)].to_numpy(float)
        cell = _cells(P[:, 0], 2) * 4 + _cells(P[:, 1], 2) * 2 + _cells(P[:, 2], 2)
        out.append(("field changing with position (per axis)", _cell_offsets(cell), 2.0))
    if all(c in d for c in GYR):
        w = np.linalg.norm(d[list(GYR)].to_numpy(float), axis=1)
        out.append(
            ("dependence on angular rate |omega| (per axis)", _per_axis(w - w.mean()), np.sqrt(3.0))
        )
    return out


def apply_calibration(fit: Fit, frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with its field corrected by the body-fixed part of a fitted model, ``A^-1 (m - b)``: the
    data as a calibrated sensor would see them (a new disturbance then shows as a missing effect)."""
    out = frame.copy()
    out[list(MAG)] = correct_field(fit.params, frame)
    return out


def field_summary(fit: Fit) -> dict:
    """The estimated local field: north, east, down (uT), horizontal, intensity (uT), dip (deg)."""
    n, e, dn = (fit.params[k] for k in FIELD)
    h = float(np.hypot(n, e))
    return {
        "north (uT)": n,
        "east (uT)": e,
        "down (uT)": dn,
        "horizontal (uT)": h,
        "intensity (uT)": float(np.sqrt(h * h + dn * dn)),
        "dip (deg)": float(np.degrees(np.arctan2(dn, h))),
    }


def heading_error_deg(
    body_field: np.ndarray, frame: pd.DataFrame, north_deg: float | None = None
) -> np.ndarray:
    """Heading error (deg) of a calibrated body-frame field, levelled with the reference attitude: the
    field's declination in NED minus ``north_deg`` (default: its circular mean), with the sign of a heading
    error (a field seen turned anticlockwise reads as a heading too high)."""
    f = np.einsum("nji,nj->ni", body_from_nav(frame), body_field)  # C_b^n m = (C_n^b)^T m
    dec = np.degrees(np.arctan2(f[:, 1], f[:, 0]))
    if north_deg is None:
        north_deg = float(np.degrees(np.angle(np.mean(np.exp(1j * np.radians(dec))))))
    return -wrap_deg(dec - north_deg)


def ellipsoid_fit(frame: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """The calibration users pick without a reference attitude: a least-squares ellipsoid through the
    measured field, ``(m - c)^T M (m - c) = 1``, fitted algebraically (linear least squares on the quadric
    ``a x^2 + b y^2 + c z^2 + 2d xy + 2e xz + 2f yz + 2g x + 2h y + 2i z = 1``); the calibration is
    ``m_cal = W (m - c)`` with ``W = r M^(1/2)`` (symmetric) and ``r`` the mean field radius.

    Returns
    -------
    (W, c) : the 3x3 matrix and the centre (uT).  (:func:`navlib.methods.ellipsoid.algebraic_ellipsoid`,
    scaled to the mean radius.)"""
    m = frame[list(MAG)].to_numpy(float)
    c, S = algebraic_ellipsoid(m)
    radius = float(np.mean(np.linalg.norm(m - c, axis=1)))
    return radius * S, c


MEASURED["magnetometer"] = (MAG, False)
SYSTEM = register_system(
    System(
        "magnetometer",
        "uT",
        MAGNETOMETER_EFFECTS,
        load_magnetometer,
        _fit_magnetometer,
        magnetometer_structure,
        "3-D magnetometer with reference attitude; residual = measured - model field, 3 values per row, uT",
        columns=MAGNETOMETER_COLUMNS,
    )
)


def simulate_magnetometer(
    params: dict, *, n: int = 400, noise_ut: float = 0.1, seed=0
) -> pd.DataFrame:
    """3-D samples from the model (eq. in the module docstring) at ``n`` random attitudes (uniform over
    rotations), a body rate of up to 60 deg/s per axis, 0.1 s apart; ``params`` as in the catalogue plus
    the local field ``field_*_ut`` (default: BROAD's room, (15.2, -0.3, 40.8) uT); white noise ``noise_ut``."""
    rng = np.random.default_rng(seed)
    p = {"field_n_ut": 15.2, "field_e_ut": -0.3, "field_d_ut": 40.8, **params}
    rot = Rotation.random(n, random_state=rng)  # body -> NED
    q = rot.as_quat()[:, [3, 0, 1, 2]]
    frame = pd.DataFrame(q, columns=list(QUAT))
    frame[list(GYR)] = rng.uniform(-60, 60, (n, 3))
    frame["time_s"] = 0.1 * np.arange(n)
    m = predict_field(p, frame) + noise_ut * rng.standard_normal((n, 3))
    frame[list(MAG)] = m
    return frame


def simulate_hand_turned(
    params: dict,
    *,
    duration_s: float = 60.0,
    rate_hz: float = 10.0,
    noise_ut: float = 0.1,
    noise_correlation: float = 0.0,
    turn_rate_dps: float = 45.0,
    turn_time_s: float = 1.0,
    seed=0,
) -> pd.DataFrame:
    """A magnetometer turned by hand and sampled at ``rate_hz``: the body rate of each axis is an
    Ornstein-Uhlenbeck process (standard deviation ``turn_rate_dps``, correlation time ``turn_time_s``),
    integrated from a random attitude into the reference quaternion (so the attitude, and every effect's
    shape, changes slowly from sample to sample, as in BROAD's hand-held trials); the field follows the
    model of the module docstring with ``params`` (plus the local field, default BROAD's room) and AR(1)
    noise of marginal standard deviation ``noise_ut`` and lag-1 correlation ``noise_correlation``
    (:func:`navlib.workbench.serial.ar1_noise`, the same process on each axis, independent between axes).  Columns as a BROAD
    3-D file: ``time_s``, quaternion, gyro, field."""
    for name, value, lo in (
        ("duration_s", duration_s, 0.0),
        ("rate_hz", rate_hz, 0.0),
        ("turn_rate_dps", turn_rate_dps, 0.0),
        ("turn_time_s", turn_time_s, 0.0),
    ):
        if not (np.isfinite(value) and value > lo):
            raise InputError(f"parameter {name}={value!r}: must be > {lo:g}")
    if not (np.isfinite(noise_ut) and noise_ut >= 0):
        raise InputError(f"parameter noise_ut={noise_ut!r}: must be >= 0")
    if not (-1.0 < noise_correlation < 1.0):
        raise InputError(f"parameter noise_correlation={noise_correlation!r}: must be in (-1, 1)")
    rng = np.random.default_rng(seed)
    n = int(round(duration_s * rate_hz))
    if n < 30:
        raise InputError(f"duration_s x rate_hz = {n} samples; at least 30 are needed")
    dt = 1.0 / rate_hz
    w = ar1_noise(rng, (n, 3), turn_rate_dps, float(np.exp(-dt / turn_time_s)))  # body rate, deg/s
    steps = Rotation.from_rotvec(np.radians(w[:-1]) * dt).as_quat()[:, [3, 0, 1, 2]]
    q = np.empty((n, 4))
    q[0] = Rotation.random(random_state=rng).as_quat()[[3, 0, 1, 2]]  # body -> NED
    for k in range(n - 1):  # q_(k+1) = q_k (x) dq_k: the body-frame increment
        a0, a1, a2, a3 = q[k]
        b0, b1, b2, b3 = steps[k]
        q[k + 1] = (
            a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
        )
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q = q * np.where(q[:, :1] < 0, -1.0, 1.0)
    frame = pd.DataFrame({"time_s": dt * np.arange(n)})
    frame[list(QUAT)] = q
    frame[list(GYR)] = w
    p = {**BROAD_FIELD, **params}
    frame[list(MAG)] = predict_field(p, frame) + ar1_noise(rng, (n, 3), noise_ut, noise_correlation)
    return frame


def effect_rms(data: pd.DataFrame, params: dict, effect: str) -> float:
    """RMS (uT, over rows and axes) of what ``effect`` adds to the noiseless model on ``data`` (the local
    field from ``params``, default :data:`BROAD_FIELD`)."""
    if effect not in MAGNETOMETER_EFFECTS:
        raise InputError(
            f"unknown magnetometer effect '{effect}'; known: {', '.join(MAGNETOMETER_EFFECTS)}"
        )
    p = {**BROAD_FIELD, **params}
    without = {k: v for k, v in p.items() if k not in MAGNETOMETER_EFFECTS[effect].params}
    return float(np.sqrt(np.mean((predict_field(p, data) - predict_field(without, data)) ** 2)))
