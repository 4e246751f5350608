"""The ``magnetometer_free`` system: a 3-D magnetometer turned by hand, with no reference attitude.

What holds without an attitude (document B's "magnitude constraint" and "dot-product invariance"): the
Earth field at one place has a constant intensity ``F``, and, while the sensor is still or slow, a constant
angle to gravity, so its component along the measured gravity direction is a constant ``D = F sin(dip)``.
The sensor model is written, as magcal and the field's calibration scripts write it, as its correction::

    u_i = M (m_i - b - k (T_i - T_c)),      M = I + K   (K symmetric, trace-free)
    e_i = |u_i| - F,     g_i = a_i/|a_i| . R(theta) u_i - D,     c = D / F
    residual_i = ( e_i ,  (g_i - c e_i) / sqrt(1 - c^2) )
                                  [uT; the second only with an accelerometer]

The second residual is the dot-product misfit with its share of the magnitude misfit taken out: the same
sensor noise ``n`` enters ``e ~ n . u/|u|`` and ``g ~ n . a/|a|``, which are correlated by ``c`` (0.94 at a
dip of 70 deg); the combination is the noise across the field in the plane of field and gravity, i.e.
``F`` times the error of the dip angle, independent of ``e`` and of the same variance for isotropic noise,
so the F tests of the workbench hold.

- ``hard_iron`` = ``b`` (uT): a field fixed to the body (the centre of the ellipsoid the raw field traces);
- ``scale`` = the diagonal of ``K`` (2 parameters, the third is minus their sum): per-axis scale mismatch,
  the ellipsoid's axes along the sensor's axes (magcal's ``diag``);
- ``soft_iron`` = the off-diagonal of ``K`` (3): cross-axis soft iron, the ellipsoid's axes turned;
  ``scale`` + ``soft_iron`` together are the full symmetric ellipsoid (magcal's ``sym``).  The two are kept
  apart in the catalogue so that each can be missing from a model and be named; the trace of ``K`` is not
  observable (it trades against ``F``) and is fixed at zero;
- ``misalignment`` = ``theta`` (deg, a rotation vector, only with ``acc_*_ms2``): the magnetometer's axes
  turned against the accelerometer's; it breaks the dot-product invariance and leaves the magnitude alone;
- ``temperature`` = ``k`` (uT/degC, only with ``temperature_c``): an offset drifting with temperature
  (``T_c`` the mean temperature).

``F`` (``field_ut``) and, with an accelerometer, ``D`` (``field_down_ut``) are always estimated; the dip is
``asin(D / F)`` with the sign convention of the accelerometer's specific force (``a`` points up at rest, so
``D`` is minus the downward component; :func:`field_summary` reports the dip positive downward).

The residual is (measured - model) of two derived columns the loader adds, ``field_norm_ut = |m|`` and
``field_gravity_ut = a/|a| . m`` (raw), so that the workbench's outlier screen can name a column; the model's
"prediction" of them is the measured value minus the invariants' residual.  Residuals per row: 1 (no
accelerometer) or 2, flattened row by row.

Relation to the ``magnetometer`` system: there ``m = A C m_n + b`` with ``A = R (I + S)``, the distortion;
here ``M`` is the correction, ``M = A^-1`` up to the rotation the invariants cannot see and the overall
scale: ``(I + S)^-1 = I - S + S^2 ...``, so ``K ~ -S`` for small soft iron.

Serial correlation: the invariants are the sensor's axis noise seen along the field's direction (and the
dip's), which turns with the hand; an AR model of the invariants themselves is misspecified (with AR(1)
noise of 0.9 on the axes its estimate runs to the bound and false alarms rise to about 14 %).  The system
therefore gives the screen each residual's gradient with respect to the raw axes (:func:`noise_directions`,
the ``System.noise_directions`` hook) and the workbench models the noise on the axes
(:class:`navlib.workbench.serial.Projection`: exact GLS, the same bootstrap-calibrated tests).

Structure tests (shapes no catalogued effect produces): the magnitude changing in time (an offset per
10 % of the recording, per residual column), and the magnitude depending on the direction of the sample on
the sphere beyond the ellipsoid (the seven third-degree harmonics of the field's direction: an ellipsoid
is of degree <= 2).

Files: ``mag_x_ut, mag_y_ut, mag_z_ut``; optional ``acc_x_ms2, acc_y_ms2, acc_z_ms2``, ``time_s``,
``temperature_c``, ``gyr_*_dps``, and where and when (:data:`SITE_COLUMNS`: ``lat_deg``, ``lon_deg``,
``height_m``, ``date``; :func:`site_of`), which the loop's field check and ``calibrate`` use for the IGRF
field; other columns ignored.  :func:`load_free` refuses bad input in one line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ..data.tables import Column, read_table, require_variation
from ..errors import InputError
from ..methods.preprocess import field_gravity_dot
from ..sensors.earth_field import Site
from .effects import Effect, System, register_system
from .fit import MEASURED, Fit, best_least_squares, columns_of, user_columns, user_design
from . import free_breakdown
from .free_kernel import FreeKernel
from .local_field import field_check, field_lines
from .magnetometer import (
    AXES,
    FIELD_BAND_UT,
    FIELD_UNITS,
    GYR,
    MAG,
    MAG_LIMIT_UT,
)

ACC = ("acc_x_ms2", "acc_y_ms2", "acc_z_ms2")
DERIVED = ("field_norm_ut", "field_gravity_ut")
G0 = 9.80665
#: Median ``|a|`` must lie in this band (m/s^2) for an accelerometer in m/s^2 held still or turned slowly.
GRAVITY_BAND = (5.0, 15.0)
#: Distinct 30-deg cells of the field's direction needed (and at least one per model parameter).
MIN_ORIENTATIONS = 12
#: The field's directions must span 3-D: smallest eigenvalue of their second moment at least this (a
#: sensor turned about one axis only traces an ellipse, which cannot give an ellipsoid: 0).
MIN_SPREAD = 0.02

FREE_EFFECTS = {
    "hard_iron": Effect(
        "hard_iron",
        ("hard_x_ut", "hard_y_ut", "hard_z_ut"),
        ("uT", "uT", "uT"),
        "A field fixed to the body (magnet, magnetised steel, sensor offsets): the raw field traces a sphere "
        "whose centre is off the origin. Missing, the magnitude varies as one cycle over the sphere.",
    ),
    "scale": Effect(
        "scale",
        ("scale_x", "scale_y"),
        ("-", "-"),
        "Per-axis scale mismatch (z = -x - y; the mean scale is in the field strength): an ellipsoid with "
        "its axes along the sensor's. Missing, the magnitude varies as two cycles, aligned with the axes.",
    ),
    "soft_iron": Effect(
        "soft_iron",
        ("soft_xy", "soft_xz", "soft_yz"),
        ("-", "-", "-"),
        "Cross-axis soft iron (induced magnetisation): the ellipsoid's axes are turned against the sensor's. "
        "Missing, the magnitude varies as two cycles along the diagonals.",
    ),
    "misalignment": Effect(
        "misalignment",
        ("mis_x_deg", "mis_y_deg", "mis_z_deg"),
        ("deg", "deg", "deg"),
        "The magnetometer's axes are turned against the accelerometer's. Missing, the angle between field and "
        "gravity (the dip) seems to change with orientation while the magnitude stays constant.",
        ACC,
    ),
    "temperature": Effect(
        "temperature",
        ("temp_x_ut_c", "temp_y_ut_c", "temp_z_ut_c"),
        ("uT/degC",) * 3,
        "The offset (hard iron, sensor bias) drifts with temperature. Missing, the ellipsoid's centre moves "
        "as the sensor warms.",
        ("temperature_c",),
    ),
}
_PARAMS = [p for e in FREE_EFFECTS.values() for p in e.params]
#: The simulators' local field: BROAD's room (:data:`navlib.workbench.magnetometer.BROAD_FIELD`), intensity
#: 43.5 uT, dip 69.6 deg.
SIM_FIELD_UT, SIM_DIP_DEG = 43.54, 69.56


#: Optional columns that say where and when the recording was made (:func:`site_of`): geodetic latitude
#: and longitude (deg, WGS84), height above the ellipsoid (m), and ``date`` (ISO 8601 text: a date
#: ``2021-03-04`` or a date-time ``2021-03-04T10:15:00Z``; the day is used).
SITE_COLUMNS = ("lat_deg", "lon_deg", "height_m", "date")
#: Largest spread within one file of latitude or longitude (deg) and height (m): one site per file.  0.1 deg
#: (about 11 km) and 500 m move the IGRF main field by well under the 0.3 uT crustal tolerance of the
#: field check (:data:`navlib.workbench.local_field.CRUST_TOL_UT`).
SITE_TOL_DEG, HEIGHT_TOL_M = 0.1, 500.0
#: Largest spread of the ``date`` column (days): the main field changes by up to about 0.1 uT a year.
DATE_TOL_DAYS = 366


# The file schema of the ``magnetometer_free`` system (what :func:`load_free` reads; the data dictionary
# of :func:`navlib.data.tables.schema_table`).
FREE_COLUMNS = tuple(
    [
        Column(c, "uT", lo=-MAG_LIMIT_UT, hi=MAG_LIMIT_UT, meaning=f"magnetometer, {AXES[c[4]]}")
        for c in MAG
    ]
    + [
        Column(
            c,
            "m/s^2",
            required=False,
            lo=-1e4,
            hi=1e4,
            meaning=f"specific force, {AXES[c[4]]} (all three or none; misalignment needs them)",
        )
        for c in ACC
    ]
    + [
        Column("time_s", "s", required=False, lo=-1e10, hi=1e10, meaning="time of the sample"),
        Column(
            "temperature_c",
            "degC",
            required=False,
            lo=-80.0,
            hi=200.0,
            meaning="sensor temperature (the temperature effect needs it)",
        ),
    ]
    + [
        Column(c, "deg/s", required=False, checked=False, meaning="angular rate (information only)")
        for c in GYR
    ]
    + [
        Column(
            "lat_deg", "deg", required=False, lo=-90.0, hi=90.0, meaning="site latitude (WGS84)"
        ),
        Column("lon_deg", "deg", required=False, lo=-180.0, hi=360.0, meaning="site longitude"),
        Column(
            "height_m",
            "m",
            required=False,
            lo=-1e4,
            hi=1e6,
            meaning="site height above the ellipsoid",
        ),
        Column("date", required=False, text=True, meaning="date of the recording (ISO 8601)"),
    ]
)


def free_columns() -> list[Column]:
    """The columns of ``FREE_COLUMNS``, as a list."""
    return list(FREE_COLUMNS)


def _one_value(
    frame: pd.DataFrame, col: str, tol: float, unit: str, name: str, circle: bool = False
) -> float:
    """The column's one value (its median), refused when it spreads by more than ``tol``.  ``circle``: a
    longitude, compared on the circle (179.99 and -179.99 deg are 0.02 deg apart, and so are 359.99 and
    0.01): the spread and the median of the differences from the first value, wrapped into [-180, 180)."""
    v = frame[col].to_numpy(float)
    if circle and len(v):
        d = np.mod(v - v[0] + 180.0, 360.0) - 180.0
        spread = float(np.ptp(d))
        value = float(v[0] + np.median(d))
        value = value + 360.0 if value < -180.0 else value - 360.0 if value > 360.0 else value
    else:
        spread = float(np.ptp(v)) if len(v) else 0.0
        value = float(np.median(v)) if len(v) else float("nan")
    if spread > tol:
        raise InputError(
            f"{name}: column '{col}' varies by {spread:.4g} {unit} within the file (more than "
            f"{tol:g} {unit}): one site per file"
        )
    return value


def _date_of(frame: pd.DataFrame, name: str) -> str:
    text = frame["date"].astype(str).str.strip()
    when = pd.to_datetime(text, utc=True, format="ISO8601", errors="coerce")
    bad = np.flatnonzero(when.isna().to_numpy() | ~text.str.match(r"\d{4}-\d{2}-\d{2}").to_numpy())
    if bad.size:
        raise InputError(
            f"{name}: column 'date', row {bad[0] + 1}: {str(frame['date'].iloc[bad[0]])[:40]!r} is not an "
            f"ISO 8601 date (YYYY-MM-DD or YYYY-MM-DDTHH:MM:SSZ)"
        )
    for row in (int(np.argmin(when.to_numpy())), int(np.argmax(when.to_numpy()))):
        try:
            Site(0.0, 0.0, 0.0, when.iloc[row].date().isoformat())  # the years IGRF-14 covers
        except InputError as err:
            raise InputError(
                f"{name}: column 'date', row {row + 1}: {str(frame['date'].iloc[row])[:40]!r} is "
                f"outside the model's years ({str(err).split(': ', 1)[-1]})"
            ) from None
    days = (when.max() - when.min()).total_seconds() / 86400.0
    if days > DATE_TOL_DAYS:
        raise InputError(
            f"{name}: column 'date' spans {days:.0f} days (more than {DATE_TOL_DAYS}): one recording per "
            f"file"
        )
    return (when.min() + (when.max() - when.min()) / 2).date().isoformat()


def site_of(frame: pd.DataFrame, site=None, date: str | None = None, name: str = "data"):
    """The :class:`navlib.sensors.earth_field.Site` of a recording, or None when nothing says where it was
    made.  ``site`` (``(lat, lon)`` or ``(lat, lon, height_m)``, e.g. from ``--site``) and ``date`` (from
    ``--date``) override the columns :data:`SITE_COLUMNS`; otherwise latitude, longitude and height are the
    columns' medians and the date the middle of the ``date`` column (default: the Site's).  One-line
    InputError: only one of ``lat_deg``/``lon_deg``; a position spread beyond :data:`SITE_TOL_DEG` or
    :data:`HEIGHT_TOL_M` (longitudes compared on the circle), dates spanning more than
    :data:`DATE_TOL_DAYS`, not ISO 8601 or outside IGRF-14's years; a date with no site (out-of-range values
    are refused by the loader, naming column and row).  Each message names what the value came from: the
    file (``name``, or the file the frame was read from: ``frame.attrs["source"]``) and its column, or the
    option --site / --date."""
    if name == "data":
        name = frame.attrs.get("source", name)
    date_given = date is not None
    if site is None:
        have = [c for c in ("lat_deg", "lon_deg") if c in frame]
        if len(have) == 1:
            raise InputError(
                f"{name}: column '{have[0]}' without "
                f"'{({'lat_deg', 'lon_deg'} - set(have)).pop()}': give both, or --site"
            )
        if have:
            site = (
                _one_value(frame, "lat_deg", SITE_TOL_DEG, "deg", name),
                _one_value(frame, "lon_deg", SITE_TOL_DEG, "deg", name, circle=True),
            )
            if "height_m" in frame:
                site += (_one_value(frame, "height_m", HEIGHT_TOL_M, "m", name),)
    if date is None and "date" in frame:
        date = _date_of(frame, name)
    if site is None:
        if date_given:
            raise InputError(
                "parameter --date: a date without a site: give --site LAT,LON[,HEIGHT_M] or the "
                "columns lat_deg, lon_deg"
            )
        if date is not None:
            raise InputError(
                f"{name}: column 'date' without a site (no columns lat_deg, lon_deg, no --site): the "
                f"field check needs where as well as when; add the columns or give --site "
                f"LAT,LON[,HEIGHT_M]"
            )
        return None
    site = tuple(float(v) for v in site)
    return Site(
        site[0], site[1], site[2] if len(site) > 2 else 0.0, *((date,) if date is not None else ())
    )


def has_acc(frame: pd.DataFrame) -> bool:
    return all(c in frame for c in ACC)


#: The dip invariant takes the accelerometer's direction for gravity's.  Where the 95th percentile of
#: ``| |a| - median |a| |`` exceeds this (m/s^2) the sensor was accelerated, not still or slowly turned: 1.5
#: m/s^2 of non-gravitational acceleration tilts the apparent vertical by up to 9 deg, far more than the dip
#: constraint tolerates (a free choice, stated; BROAD's slow hand-held trials stay below 1, its fast and
#: magnet trials reach 2-15).
ACC_STILL_TOL_MS2 = 1.5


def accelerometer_motion(frame: pd.DataFrame) -> str | None:
    """One sentence when the accelerometer of ``frame`` measured more than gravity (:data:`ACC_STILL_TOL_MS2`),
    else None (no accelerometer, or a still or slowly turned one)."""
    if not has_acc(frame):
        return None
    g = np.linalg.norm(columns_of(frame, ACC), axis=1)
    dev = np.abs(g - np.median(g))
    p95 = float(np.percentile(dev, 95))
    if p95 <= ACC_STILL_TOL_MS2:
        return None
    share = float(np.mean(dev > ACC_STILL_TOL_MS2))
    return (
        f"columns {', '.join(ACC)}: |a| departs from gravity by more than {ACC_STILL_TOL_MS2:g} m/s^2 on "
        f"{100 * share:.0f} % of the rows (95th percentile {p95:.2g} m/s^2): the sensor was accelerated, "
        f"so the dip constraint, which takes a/|a| for the vertical, is biased; calibrate without the "
        f"acceleration columns, or on the still or slowly turned part of the recording"
    )


def with_invariants(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with the derived columns ``field_norm_ut`` (``|m|``) and, with an accelerometer,
    ``field_gravity_ut`` (``a/|a| . m``), the raw values of the two invariants."""
    out = frame.copy()
    m = out[list(MAG)].to_numpy(float)
    out["field_norm_ut"] = np.linalg.norm(m, axis=1)
    if has_acc(out):
        a = out[list(ACC)].to_numpy(float)
        out["field_gravity_ut"] = field_gravity_dot(m, a) / np.linalg.norm(a, axis=1)  # a/|a| . m
    return out


def _directions(frame: pd.DataFrame) -> np.ndarray:
    """The raw field's unit directions, one row per sample."""
    m = columns_of(frame, MAG)
    return m / np.maximum(np.linalg.norm(m, axis=1, keepdims=True), 1e-300)


def _cells(u: np.ndarray) -> int:
    cell = np.round(u * 2).astype(np.int64) + 2  # each component in 0..4
    ids = cell @ np.array([25, 5, 1])  # 0..124 for unit vectors
    if ids.size and ids.min() >= 0:
        return int(np.count_nonzero(np.bincount(ids)))  # the distinct ids without sorting them
    return int(np.unique(ids).size)


def _spread(u: np.ndarray) -> float:
    return float(np.linalg.eigvalsh(np.cov(u.T))[0])


def orientation_cells(frame: pd.DataFrame) -> int:
    """Distinct 30-deg cells of the raw field's direction (each component of the unit vector x 2, rounded)."""
    return _cells(_directions(frame))


def orientation_spread(frame: pd.DataFrame) -> float:
    """Smallest eigenvalue of the second moment of the field's unit directions (about their mean)."""
    return _spread(_directions(frame))


def check_orientations(frame: pd.DataFrame, name: str, needed: int = MIN_ORIENTATIONS) -> None:
    """Refuse data whose field directions cannot separate the model's parameters, naming each limit that
    failed with its value: at least ``needed`` distinct 30-deg cells of the field's direction, and a
    smallest spread (:func:`orientation_spread`) of at least :data:`MIN_SPREAD`."""
    u = _directions(frame)
    cells, spread = _cells(u), _spread(u)
    failed = []
    if cells < needed:
        failed.append(
            f"only {cells} distinct orientations (30-deg cells of the field's direction; the model "
            f"needs at least {needed})"
        )
    if spread < MIN_SPREAD:
        failed.append(
            f"a smallest spread of the field's directions of {spread:.3f} (the model needs at least "
            f"{MIN_SPREAD:g}: the directions lie near a plane or a line)"
        )
    if failed:
        raise InputError(
            f"{name}: columns mag_x_ut..mag_z_ut: {' and '.join(failed)}; turn the sensor through "
            f"all directions, not about one axis"
        )


def load_free(path, *, min_rows: int = 30) -> pd.DataFrame:
    """Load and validate a magnetometer file without reference attitude (one-line InputError naming file,
    column and row): missing field columns; empty cells, text, NaN, infinity; values outside their limits
    (field +-1e6 uT, acceleration +-1e4 m/s^2, temperature -80..200 degC); fewer than ``min_rows`` rows; a
    stuck axis; a unit other than uT (the median ``|m|`` must lie in 10-150 uT: the Earth's field is 22-67 uT; the
    message names gauss, mG, nT, mT or T when one of them brings it there); an accelerometer in g (the
    median ``|a|`` must lie in 5-15 m/s^2; near 1 names g); too few distinct orientations
    (``check_orientations``); site columns that disagree (:func:`site_of`).  Adds the derived columns of :func:`with_invariants`."""
    name = Path(path).name
    frame = read_table(path, FREE_COLUMNS, min_rows=min_rows, kind="magnetometer file")
    require_variation(frame, MAG, name, "a magnetometer turned through many orientations")
    check_units(frame, name)
    check_orientations(frame, name)
    if "lat_deg" in frame or "lon_deg" in frame:  # the site columns, checked at load
        site_of(frame, name=name)
    elif "date" in frame:
        _date_of(frame, name)
    return with_invariants(frame)


def check_units(frame: pd.DataFrame, name: str = "data") -> None:
    """Field in uT and acceleration in m/s^2 (see :func:`load_free`)."""
    med = float(np.median(np.linalg.norm(frame[list(MAG)].to_numpy(float), axis=1)))
    lo, hi = FIELD_BAND_UT
    if not lo <= med <= hi:
        units = [(u, f) for u, f in FIELD_UNITS if lo <= med * f <= hi]
        look = (
            f"these look like {units[0][0]} (multiply by {units[0][1]:g} for uT)"
            if units
            else "this is not a field in uT"
        )
        raise InputError(
            f"{name}: columns mag_x_ut, mag_y_ut, mag_z_ut: median |m| is {med:.4g}, where the Earth's "
            f"field is 22-67 uT and {lo:g}-{hi:g} uT is accepted: {look}"
        )
    if any(c in frame for c in ACC) and not has_acc(frame):
        raise InputError(f"{name}: give all three of {', '.join(ACC)} or none")
    if has_acc(frame):
        g = float(np.median(np.linalg.norm(frame[list(ACC)].to_numpy(float), axis=1)))
        glo, ghi = GRAVITY_BAND
        if not glo <= g <= ghi:
            look = (
                "these look like g (multiply by 9.80665 for m/s^2)"
                if glo <= g * G0 <= ghi
                else "this is not a still or slowly turned accelerometer in m/s^2"
            )
            raise InputError(
                f"{name}: columns {', '.join(ACC)}: median |a| is {g:.4g}, where gravity is 9.81 m/s^2 "
                f"and {glo:g}-{ghi:g} is accepted: {look}"
            )


# ------------------------------------------------------------------------------------------- the model
def full_params(params: dict) -> dict:
    p = {k: 0.0 for k in _PARAMS}
    p.update(params)
    return p


def correction_matrix(params: dict) -> np.ndarray:
    """``M = I + K`` (symmetric; K trace-free) from the scale and soft-iron parameters (absent = 0)."""
    p = full_params(params)
    sx, sy = p["scale_x"], p["scale_y"]
    return np.eye(3) + np.array(
        [
            [sx, p["soft_xy"], p["soft_xz"]],
            [p["soft_xy"], sy, p["soft_yz"]],
            [p["soft_xz"], p["soft_yz"], -sx - sy],
        ]
    )


def offset(params: dict, frame: pd.DataFrame, t_c: float) -> np.ndarray:
    """``b + k (T - T_c)`` per row, (n, 3) uT."""
    p = full_params(params)
    b = np.array([p["hard_x_ut"], p["hard_y_ut"], p["hard_z_ut"]])
    k = np.array([p["temp_x_ut_c"], p["temp_y_ut_c"], p["temp_z_ut_c"]])
    if "temperature_c" in frame and np.any(k):
        return b + (frame["temperature_c"].to_numpy(float) - t_c)[:, None] * k
    return np.broadcast_to(b, (len(frame), 3))


def corrected(params: dict, frame: pd.DataFrame, t_c: float = 0.0) -> np.ndarray:
    """The corrected field ``u = M (m - b - k (T - T_c))``, (n, 3) uT, in the magnetometer's axes."""
    return (columns_of(frame, MAG) - offset(params, frame, t_c)) @ correction_matrix(params).T


def invariant_residuals(params: dict, frame: pd.DataFrame, t_c: float = 0.0) -> np.ndarray:
    """(n, 1) or (n, 2): ``e = |u| - F`` and, with an accelerometer, ``(g - c e) / sqrt(1 - c^2)`` (uT;
    module docstring)."""
    names = list(params)
    return kernel_of(frame, names, t_c).residuals(np.array([params[q] for q in names], float))


def kernel_of(frame: pd.DataFrame, names, t_c: float = 0.0) -> FreeKernel:
    """The frame's arrays in a :class:`navlib.workbench.free_kernel.FreeKernel` for the parameters ``names``."""
    a = columns_of(frame, ACC) if has_acc(frame) else None
    dt = frame["temperature_c"].to_numpy(float) - t_c if "temperature_c" in frame else None
    return FreeKernel(names, columns_of(frame, MAG), a, dt)


def _fit_free(data: pd.DataFrame, effects: tuple[Effect, ...], start) -> Fit:
    if not all(c in data for c in DERIVED[: 1 + has_acc(data)]):
        data = with_invariants(data)
    cat = tuple(e.name for e in effects if e.contribution is None)
    users = tuple(e for e in effects if e.contribution is not None)
    acc = has_acc(data)
    base = ["field_ut"] + (["field_down_ut"] if acc else [])
    names = (
        base
        + [p for e in cat for p in FREE_EFFECTS[e].params]
        + [p for e in users for p in e.params]
    )
    clash = sorted({n for n in names if names.count(n) > 1})
    if clash:
        raise InputError(
            f"parameter '{clash[0]}' is named twice in the model (a user effect's parameter must "
            f"not be named like the field strength {', '.join(base)})"
        )
    k = 2 if acc else 1
    if len(data) * k < len(names) + 1:
        raise InputError(f"{len(data)} rows cannot determine {len(names)} model parameters")
    check_orientations(data, "magnetometer data", max(MIN_ORIENTATIONS, len(names)))
    t_c = float(data["temperature_c"].mean()) if "temperature_c" in data else 0.0
    shape = (len(data), k)
    kern = kernel_of(data, names, t_c)

    def resid(x):
        r = kern.residuals(x).ravel()
        return r - user_columns(users, dict(zip(names, x)), data, shape) if users else r

    # start 2 (linearised): a sphere fit |m|^2 = 2 m.b + c for the centre (if hard iron is in the model)
    m = columns_of(data, MAG)
    x2 = dict.fromkeys(names, 0.0)
    if "hard_iron" in cat:
        X = np.column_stack([2 * m, np.ones(len(m))])
        sol = np.linalg.lstsq(X, np.sum(m * m, axis=1), rcond=None)[0]
        x2.update(hard_x_ut=sol[0], hard_y_ut=sol[1], hard_z_ut=sol[2])
    r0 = kern.residuals(np.array([x2[q] for q in names], float))  # invariant_residuals(x2, ...)
    x2["field_ut"] = float(np.mean(r0[:, 0]))
    if acc:
        x2["field_down_ut"] = float(np.mean(r0[:, 1]))
    if users:
        U = user_design(users, data, shape)
        r0 = kern.residuals(np.array([x2[q] for q in names], float)).ravel()
        beta = np.linalg.lstsq(U, -r0, rcond=None)[0]
        x2.update(zip([p for e in users for p in e.params], beta))
    x2v = np.array([x2[n] for n in names])
    x1v = np.array([(start or {}).get(n, x2[n]) for n in names])
    if not users and np.array_equal(x1v, x2v):
        # one start: Gauss-Newton from it (the steps scipy's trust region would take, without its
        # per-step SVD); scipy where it does not converge
        gn = gauss_newton(kern, x2v)
        if gn is not None:
            x, J = gn
            return _free_fit(
                data, effects, dict(zip(names, map(float, x))), J, t_c, kern.residuals(x)
            )
    inf = np.full(len(names), np.inf)
    sol = best_least_squares(
        resid,
        [x1v, x2v],
        -inf,
        inf,
        jac="2-point" if users else kern.jacobian,
        tr_solver=None if users else "exact",
    )
    return _free_fit(
        data,
        effects,
        dict(zip(names, map(float, sol.x))),
        sol.jac,
        t_c,
        None if users else kern.residuals(sol.x),
    )


def _free_fit(data: pd.DataFrame, effects, params: dict, jac, t_c: float, misfit=None) -> Fit:
    """The :class:`~navlib.workbench.fit.Fit` of the parameters ``params`` found on ``data`` (``jac``: the
    invariants' Jacobian d(model - measured)/dx there, ``t_c`` the temperature centre; ``misfit``: the
    invariants' residuals there, (n, k), if already computed -- without user effects only)."""
    users = tuple(e for e in effects if e.contribution is not None)
    k = 2 if has_acc(data) else 1

    def predict(frame):
        r = invariant_residuals(params, frame, t_c) - user_columns(
            users, params, frame, (len(frame), k)
        ).reshape(len(frame), k)
        return columns_of(frame, DERIVED[:k]) - r

    obs = columns_of(data, DERIVED[:k])
    model = predict(data) if misfit is None or users else obs - misfit  # predict's numbers
    # residual = measured - model = -(model - measured): the invariants' residual with the sign of a misfit
    return Fit(
        SYSTEM,
        tuple(e.name for e in effects),
        params,
        data,
        (obs - model).ravel(),
        -np.asarray(jac),
        predict,
        {"temperature_centre_c": t_c},
    )


#: :func:`gauss_newton`: at most this many steps; converged when the next Gauss-Newton step moves the
#: parameters by less than ``WARM_TOL`` of their standard errors (the step's length in the metric
#: ``J'J / s^2``, ``s^2 = RSS / (N - p)``).  scipy's least_squares, which the full fit uses, stops when the sum
#: of squares changes by less than 1e-8 of it: on BROAD's 2,700 invariants some 0.005 standard errors from
#: the minimum; on real data with large residuals Gauss-Newton converges linearly (about 0.4 per step).
WARM_STEPS = 50
WARM_TOL = 1e-3
#: :func:`gauss_newton`'s extrapolation: tried when a step is at most ``ACCEL_RHO`` times the last and the
#: two point the same way (cosine above ``ACCEL_COS``).
ACCEL_RHO, ACCEL_COS = 0.95, 0.9


def gauss_newton(kern: FreeKernel, x0: np.ndarray, steps: int = WARM_STEPS):
    """Minimise the invariants' sum of squares from ``x0`` by Gauss-Newton steps (columns scaled, the normal
    equations of the analytic Jacobian: a p x p solve per step), damped (Levenberg-Marquardt) only when a
    step would raise the sum.  Where the residuals are large (a sensor in motion: the dip invariant's
    curvature in ``D / F``) Gauss-Newton converges linearly, each step a fraction ``rho`` of the last in
    about the same direction; then the step is first tried extrapolated to the limit of that geometric
    series, ``dx / (1 - rho)`` (Aitken), and kept if it lowers the sum.  Returns ``(x, J)`` (J the Jacobian
    at ``x``), or None when it has not converged in ``steps`` steps (``WARM_TOL``) or the normal
    equations are singular."""
    x = np.asarray(x0, float).copy()
    r = kern.residuals(x).ravel()
    cost = float(r @ r)
    dof = max(len(r) - len(x), 1)
    lam = 0.0
    last = None  # the previous undamped step
    for _ in range(steps):
        J = kern.jacobian(x)
        norms = np.sqrt(np.einsum("ij,ij->j", J, J))
        norms[norms == 0] = 1.0
        Js = J / norms
        A = Js.T @ Js
        g = Js.T @ r
        try:
            gn = np.linalg.solve(A, g)
        except np.linalg.LinAlgError:
            return None
        # the step's length in standard errors: (dx' J'J dx / s^2)^(1/2), dx' J'J dx = g' A^-1 g
        if not float(g @ gn) * dof > WARM_TOL**2 * cost:
            return x, J
        step = gn / norms
        tried = False
        if lam == 0.0 and last is not None:
            size, before = np.linalg.norm(step), np.linalg.norm(last)
            rho = size / before
            if rho < ACCEL_RHO and float(step @ last) > ACCEL_COS * size * before:
                xn = x - step / (1.0 - rho)
                rn = kern.residuals(xn).ravel()
                cn = float(rn @ rn)
                tried = np.isfinite(cn) and cn <= cost
        if not tried:
            while True:
                dx = (
                    step
                    if lam == 0.0
                    else np.linalg.solve(A + lam * np.diag(np.diag(A)), g) / norms
                )
                xn = x - dx
                rn = kern.residuals(xn).ravel()
                cn = float(rn @ rn)
                if np.isfinite(cn) and cn <= cost:
                    break
                lam = max(10.0 * lam, 1e-6)
                if lam > 1e6:
                    return None
        last = step if lam == 0.0 else None
        lam = lam / 10.0 if lam > 1e-6 else 0.0
        x, r, cost = xn, rn, cn
    return None


def warm_refit(fit: Fit, data: pd.DataFrame, effects=None) -> Fit | None:
    """The system's ``refit`` hook: ``fit``'s model (or the catalogue's ``effects``, parameters ``fit`` lacks
    starting at zero) on ``data`` (rows of the same recording, e.g. without the screen's outliers) by
    :func:`gauss_newton` from ``fit``'s parameters -- the minimum the full fit (``_fit_free`` from
    several starts) finds when the data or the model change little, in a few p x p solves.  None for a
    model with user effects or when the steps do not converge (the caller then fits in full)."""
    effects = tuple(fit.effects if effects is None else effects)
    if any(e not in FREE_EFFECTS for e in effects):
        return None
    if not all(c in data for c in DERIVED[: 1 + has_acc(data)]):
        data = with_invariants(data)
    acc = has_acc(data)
    names = (
        ["field_ut"]
        + (["field_down_ut"] if acc else [])
        + [p for e in effects for p in FREE_EFFECTS[e].params]
    )
    k = 2 if acc else 1
    if len(data) * k < len(names) + 1:
        raise InputError(f"{len(data)} rows cannot determine {len(names)} model parameters")
    check_orientations(data, "magnetometer data", max(MIN_ORIENTATIONS, len(names)))
    t_c = float(data["temperature_c"].mean()) if "temperature_c" in data else 0.0
    kern = kernel_of(data, names, t_c)
    x0 = np.array([fit.params.get(q, 0.0) for q in names], float)
    # the same offsets about the new temperature centre
    if "temperature" in fit.effects and "hard_iron" in effects:
        old = fit.model.get("temperature_centre_c", t_c)
        for j, h in enumerate(("hard_x_ut", "hard_y_ut", "hard_z_ut")):
            x0[names.index(h)] += fit.params[f"temp_{'xyz'[j]}_ut_c"] * (t_c - old)
    sol = gauss_newton(kern, x0)
    if sol is None:
        return None
    x, J = sol
    chosen = tuple(FREE_EFFECTS[e] for e in effects)
    return _free_fit(data, chosen, dict(zip(names, map(float, x))), J, t_c, kern.residuals(x))


def _per_column(x: np.ndarray, k: int, cols=None) -> np.ndarray:
    n = len(x)
    cols = range(k) if cols is None else cols
    out = np.zeros((k * n, len(cols) * x.shape[1]))
    for i, j in enumerate(cols):
        out[j::k, i * x.shape[1] : (i + 1) * x.shape[1]] = x
    return out


def _cubic_harmonics(u: np.ndarray) -> np.ndarray:
    """The seven real third-degree harmonics of unit vectors ``u`` (unnormalised)."""
    x, y, z = u.T
    return np.column_stack(
        [
            x * (x * x - 3 * y * y),
            y * (3 * x * x - y * y),
            z * (x * x - y * y),
            x * y * z,
            x * (5 * z * z - 1),
            y * (5 * z * z - 1),
            z * (5 * z * z - 3),
        ]
    )


def free_structure(fit: Fit) -> list[tuple[str, np.ndarray, float]]:
    """Module docstring: magnitude (and dip) changing in time; magnitude depending on the direction on
    the sphere beyond an ellipsoid."""
    d = fit.data
    k = fit.n // len(d)
    out = []
    if "time_s" in d and np.ptp(d["time_s"].to_numpy(float)) > 0:
        t = d["time_s"].to_numpy(float)
        edges = np.quantile(t, np.linspace(0, 1, 11)[1:-1])
        cell = np.searchsorted(edges, t, side="right")
        X = np.column_stack(
            [(cell == i).astype(float) - np.mean(cell == i) for i in np.unique(cell)[1:]]
        )
        out.append(("field changing in time (per invariant)", _per_column(X, k), 2.0))
    m = columns_of(d, MAG)
    u = m / np.linalg.norm(m, axis=1, keepdims=True)
    H = _cubic_harmonics(u)
    out.append(
        (
            "magnitude depending on direction beyond an ellipsoid (3rd-degree harmonics)",
            _per_column(H - H.mean(axis=0), k, [0]),
            np.sqrt(2.0),
        )
    )
    return out


def noise_directions(fit: Fit) -> np.ndarray:
    """Each residual's gradient with respect to the raw field axes, (n_obs, 3) in observation order (the
    system's ``noise_directions`` hook): the magnitude residual ``e = |u| - F`` moves by ``n . M' u/|u|``
    for axis noise ``n``, the dip residual by ``n . M' (R' a/|a| - c u/|u|) / sqrt(1 - c^2)``; unit vectors
    for ``M = I`` and a field at the dip ``c``.  The noise of the invariants is the sensor's axis noise seen
    along these turning directions (:class:`navlib.workbench.serial.Projection`)."""
    d = fit.data
    p = full_params(fit.params)
    M = correction_matrix(p)
    u = corrected(p, d, fit.model.get("temperature_centre_c", 0.0))
    uh = u / np.linalg.norm(u, axis=1, keepdims=True)
    cols = [uh @ M]
    if has_acc(d):
        a = columns_of(d, ACC)
        R = Rotation.from_rotvec(
            np.radians([p["mis_x_deg"], p["mis_y_deg"], p["mis_z_deg"]])
        ).as_matrix()
        c = float(
            np.clip(p.get("field_down_ut", 0.0) / max(p.get("field_ut", 0.0), 1e-9), -0.99, 0.99)
        )
        ga = (a / np.linalg.norm(a, axis=1, keepdims=True)) @ R @ M
        cols.append((ga - c * cols[0]) / np.sqrt(1.0 - c * c))
    return np.stack(cols, axis=1).reshape(-1, 3)


def loop_field_check(result, site=None, date: str | None = None) -> tuple[dict, list[str]]:
    """The system's ``final_check`` hook: the local field the loop's final model estimates, beside the
    IGRF-14 field at the recording's site (:func:`site_of`: ``site``/``date`` or the data's columns;
    :func:`navlib.workbench.local_field.field_check`), as a dict and report lines."""
    check = field_check(
        result.final,
        site_of(result.final.data, site, date),
        result.screening.noise if result.screening is not None else None,
    )
    return check, field_lines(check)


def remaining_structure(fit: Fit) -> tuple[pd.DataFrame, str]:
    """The system's ``remaining`` hook: the final residuals by time, turn rate, orientation and acceleration
    (:func:`navlib.workbench.free_breakdown.breakdown`) and the sentence reading them."""
    d = fit.data
    k = fit.n // len(d)
    u = corrected(full_params(fit.params), d, fit.model.get("temperature_centre_c", 0.0))
    gyr = d[list(GYR)].to_numpy(float) if all(c in d for c in GYR) else None
    rate = np.linalg.norm(gyr, axis=1) if gyr is not None and np.all(np.isfinite(gyr)) else None
    cells = free_breakdown.factors(
        d["time_s"].to_numpy(float) if "time_s" in d else None,
        rate,
        u,
        d[list(ACC)].to_numpy(float) if has_acc(d) else None,
    )
    table = free_breakdown.breakdown(
        fit.residuals.reshape(len(d), k), ["magnitude", "dip"][:k], cells
    )
    return table, free_breakdown.reading(table)


MEASURED["magnetometer_free"] = (DERIVED, False)
SYSTEM = register_system(
    System(
        "magnetometer_free",
        "uT",
        FREE_EFFECTS,
        load_free,
        _fit_free,
        free_structure,
        "3-D magnetometer without reference attitude; residual = the invariants' misfit: |corrected field| - F "
        "and (with an accelerometer) its component along gravity - D, uT",
        noise_directions=noise_directions,
        final_check=loop_field_check,
        columns=FREE_COLUMNS,
        remaining=remaining_structure,
        refit=warm_refit,
    )
)


def field_summary(fit: Fit) -> dict:
    """The local field the invariants estimate: intensity (uT) and, with an accelerometer, the dip (deg,
    positive downward)."""
    F = fit.params["field_ut"]
    out = {"intensity (uT)": F}
    if "field_down_ut" in fit.params:
        out["dip (deg)"] = float(
            np.degrees(np.arcsin(np.clip(-fit.params["field_down_ut"] / F, -1, 1)))
        )
    return out
