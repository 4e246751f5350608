"""Calibrate a magnetometer without a reference attitude, write the correction, and apply it to a file
(``python -m navlib calibrate magnetometer FILE --out cal.json`` and ``python -m navlib apply cal.json FILE
--out corrected.csv``).

The fit is the reference-free system :mod:`navlib.workbench.magnetometer_free` with the chosen effects
(default ``hard_iron, scale, soft_iron``: the full symmetric ellipsoid).  The correction is written in the
convention of MATLAB's ``magcal`` and the field's calibration scripts::

    m_corrected = (m - b) A          (row vectors; A symmetric)

with ``expected_field_strength_ut`` the intensity the corrected field has (magcal's ``expmfs``).  With the
system's correction ``u = M (m - b)`` (column vectors) and ``M`` symmetric, ``A = M^T = M``.  The
workbench's reference-based ``magnetometer`` system writes the *distortion* instead, ``m = A_wb C m_n + b``
with ``A_wb = R (I + S)``; the two are inverse to each other up to a rotation the reference-free
invariants cannot see: ``A ~ (I + S)^-1``, so ``A - I ~ -S`` for small soft iron.  A temperature-dependent
offset (``temperature`` effect) makes ``b`` a function of the temperature, ``b(T) = b + k (T - T_c)``; with
``misalignment`` (accelerometer columns) the corrected field is also turned into the accelerometer's axes,
``m_corrected R^T``.

Uncertainties: the parameters' standard errors from the fit's Jacobian (``s^2 (J'J)^-1``), on the whitened
residuals and Jacobian when the workbench's screen finds serially correlated noise (generalised least
squares), after setting aside the rows the screen calls outliers.  ``A``'s entries are linear in the scale
and soft-iron parameters, so their standard errors are those of the parameters.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ..data.tables import read_table, write_new, write_new_csv
from ..errors import InputError
from .fit import fit_model
from .local_field import field_check, parameter_covariance
from .magnetometer_free import (
    ACC,
    DERIVED,
    FREE_EFFECTS,
    MAG,
    SYSTEM,
    accelerometer_motion,
    check_units,
    correction_matrix,
    field_summary,
    free_columns,
    full_params,
    has_acc,
    load_free,
    site_of,
)
from .screen import screen
from ..threads import one_blas_thread

FORMAT = "navlib calibration"
VERSION = 1
DEFAULT_MODEL = ("hard_iron", "scale", "soft_iron")


@one_blas_thread
def calibrate(
    data: pd.DataFrame, model=DEFAULT_MODEL, source: str = "", site=None, date=None
) -> dict:
    """The calibration of ``data`` (a frame of :func:`navlib.workbench.magnetometer_free.load_free`) with
    the effects ``model``, as a JSON-ready dict (module docstring); where the site is known (``site`` =
    ``(lat, lon[, height_m])``, ``date``, or the data's site columns:
    :func:`navlib.workbench.magnetometer_free.site_of`) also ``"field"``, the estimated local field against
    IGRF-14 there (:func:`navlib.workbench.local_field.field_check`).

    Examples
    --------
    A magnetometer turned by hand for 40 s (0.3 uT of noise), with a hard-iron offset of (12, -5, 3) uT
    and some scale and soft iron; no reference attitude is needed:

    >>> import numpy as np
    >>> from navlib.workbench.calibration import calibrate
    >>> from navlib.workbench.free_simulation import simulate_free
    >>> truth = {"hard_x_ut": 12.0, "hard_y_ut": -5.0, "hard_z_ut": 3.0,
    ...          "scale_x": 0.02, "soft_xy": 0.01}
    >>> cal = calibrate(simulate_free(truth, seed=1))
    >>> cal["model"]
    ['hard_iron', 'scale', 'soft_iron']
    >>> [round(b) for b in cal["magcal"]["b_ut"]]
    [12, -5, 3]
    >>> round(cal["expected_field_strength_ut"]["value"], 1)
    43.5

    The corrected field is ``(m - b) A`` (``cal["magcal"]["A"]``).  From the command line:
    ``python -m navlib calibrate magnetometer FILE --out cal.json``, then
    ``python -m navlib apply cal.json FILE --out corrected.csv``.
    """
    fit = fit_model(SYSTEM, data, list(model))
    sc = screen(fit)
    fit = sc.refit(fit)
    noise = sc.noise
    names, cov = parameter_covariance(fit, noise)
    std = dict(zip(names, np.sqrt(np.clip(np.diag(cov), 0, None))))
    effects = {}
    for e in fit.effects:
        eff = FREE_EFFECTS[e]
        effects[e] = {
            q: {"value": fit.params[q], "std": float(std[q]), "unit": u}
            for q, u in zip(eff.params, eff.units)
        }
    p = full_params(fit.params)
    A = correction_matrix(p)
    dA = np.zeros((3, 3))
    for (i, j), q in {
        (0, 0): "scale_x",
        (1, 1): "scale_y",
        (0, 1): "soft_xy",
        (0, 2): "soft_xz",
        (1, 2): "soft_yz",
    }.items():
        dA[i, j] = dA[j, i] = std.get(q, 0.0)
    dA[2, 2] = (
        float(
            np.sqrt(
                cov[names.index("scale_x"), names.index("scale_x")]
                + cov[names.index("scale_y"), names.index("scale_y")]
                + 2 * cov[names.index("scale_x"), names.index("scale_y")]
            )
        )
        if "scale" in fit.effects
        else 0.0
    )
    hard = ["hard_x_ut", "hard_y_ut", "hard_z_ut"]
    summary = field_summary(fit)
    out = {
        "format": FORMAT,
        "version": VERSION,
        "system": SYSTEM.name,
        "source": source,
        "model": list(fit.effects),
        "rows": int(len(fit.data)),
        "outliers_set_aside": len(sc.outliers),
        "residual_rms_ut": fit.rms,
        "noise": noise.describe() if noise.series is not None else "independent samples",
        "columns": {
            "field": list(MAG),
            "acceleration": list(ACC) if has_acc(data) else None,
            "temperature": "temperature_c" if "temperature" in fit.effects else None,
        },
        "expected_field_strength_ut": {
            "value": fit.params["field_ut"],
            "std": float(std["field_ut"]),
            "unit": "uT",
        },
        "effects": effects,
        "magcal": {
            "convention": "m_corrected = (m - b(T)) A (row vectors); |m_corrected| = expected field strength",
            "A": A.tolist(),
            "A_std": dA.tolist(),
            "b_ut": [p[q] for q in hard],
            "b_std_ut": [float(std.get(q, 0.0)) for q in hard],
            "expected_field_strength_ut": fit.params["field_ut"],
        },
        "temperature": (
            {
                "centre_c": fit.model["temperature_centre_c"],
                "coef_ut_per_c": [p["temp_x_ut_c"], p["temp_y_ut_c"], p["temp_z_ut_c"]],
            }
            if "temperature" in fit.effects
            else None
        ),
        "to_accelerometer_axes": (
            Rotation.from_rotvec(np.radians([p["mis_x_deg"], p["mis_y_deg"], p["mis_z_deg"]]))
            .as_matrix()
            .tolist()
            if "misalignment" in fit.effects
            else None
        ),
    }
    if "dip (deg)" in summary:
        out["dip_deg"] = summary["dip (deg)"]
    moved = accelerometer_motion(data)
    out["warnings"] = [moved] if moved else []
    where = site_of(data, site, date, source or "data")
    if where is not None:
        out["field"] = field_check(fit, where, noise)
    return out


def write_calibration(cal: dict, path) -> Path:
    """Write ``cal`` as JSON to ``path`` (never over an existing file)."""
    return write_new(path, lambda fh: json.dump(cal, fh, indent=2, allow_nan=False))


#: Largest condition number (2-norm, ``cond(A) = s_max / s_min``) of a calibration's ``A`` that ``apply``
#: accepts.  A working magnetometer's scale and soft-iron errors give a correction near the identity: the
#: BROAD recordings' calibrations have 1.08 (trial 01, slow rotation) and 1.22 (trial 06, fast rotation); a
#: magnet glued 1 cm from the sensor (trial 32) 8.4.  Beyond 10 the correction stretches one direction ten
#: times more than another, which no scale or soft iron of a working sensor does: a failed fit, a hand edit, or
#: a (nearly) singular matrix that turns the data's noise into most of the corrected field.
COND_LIMIT = 10.0
#: How far the corrected field strength (median ``|m_corrected|`` over the file) may differ, relatively, from
#: the calibration's ``expected_field_strength_ut`` before ``apply`` warns (one line on stderr; the file is
#: written).  The same sensor in the same lab on other recordings shows up to 4.6 % (BROAD: trial 01's
#: calibration applied to each of the 17 recordings, magnets included: -1.2 % .. +4.6 %); 10 % leaves room
#: for a steel-framed building or a site some hundred km away (the main field changes by a few % per
#: 1000 km), and beyond it the user should know.
FIELD_WARN_REL = 0.10
#: Beyond this relative difference ``apply`` refuses (exit 2, nothing written): the corrected data are not
#: the Earth's field near the calibration's site seen by the calibrated sensor -- another sensor, another
#: unit, a calibration of another system, or a broken one (e.g. 58 uT against the expected 43.5: +33 %).
#: The whole Earth spans 22-67 uT, so a sensor taken to another continent needs a new calibration anyway.
FIELD_REFUSE_REL = 0.25


def _key_text(path: tuple) -> str:
    out = ""
    for k in path:
        out += f"[{k}]" if isinstance(k, int) else (f".{k}" if out else str(k))
    return out


def _short(v) -> str:
    text = (
        json.dumps(v, allow_nan=True)
        if isinstance(v, (dict, list, str, int, float, bool, type(None)))
        else repr(v)
    )
    return text if len(text) <= 40 else text[:37] + "..."


def _get(cal: dict, path: tuple, name: str, required: bool = True):
    """The value at ``path`` (a tuple of keys) of the calibration ``cal``; InputError naming the key when it
    is missing (``required``) or a container on the way is not a JSON object."""
    node = cal
    for i, k in enumerate(path):
        if not isinstance(node, dict):
            raise InputError(
                f"{name}: key '{_key_text(path[:i])}' must be a JSON object, got {_short(node)}"
            )
        if k not in node:
            if not required:
                return None
            raise InputError(
                f"{name}: key '{_key_text(path[: i + 1])}' is missing (a calibration written by "
                f"`navlib calibrate` has it)"
            )
        node = node[k]
    return node


def _number(value, path: tuple, name: str) -> float:
    """``value`` as a finite float; InputError naming the key for text, booleans, null, NaN or infinity."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{name}: key '{_key_text(path)}' = {_short(value)} is not a number")
    v = float(value)
    if not np.isfinite(v):
        raise InputError(
            f"{name}: key '{_key_text(path)}' = {_short(value)} is not a finite number"
        )
    return v


def _array(value, path: tuple, shape: tuple, name: str) -> np.ndarray:
    """``value`` as a float array of ``shape`` (nested JSON lists), every entry checked by :func:`_number`."""
    what = (
        f"{shape[0]} numbers"
        if len(shape) == 1
        else f"a {shape[0]}x{shape[1]} array ({shape[0]} rows of {shape[1]} numbers)"
    )

    def walk(v, p, dims):
        if not dims:
            return _number(v, p, name)
        if not isinstance(v, list) or len(v) != dims[0]:
            raise InputError(f"{name}: key '{_key_text(path)}' must be {what}, got {_short(value)}")
        return [walk(x, p + (i,), dims[1:]) for i, x in enumerate(v)]

    return np.array(walk(value, path, shape), dtype=float)


def check_calibration(cal, name: str) -> dict:
    """Validate every key ``apply`` reads, by name: ``format``, ``system``, ``version`` as written by
    :func:`calibrate`; ``magcal.A`` a 3x3 array and ``magcal.b_ut`` 3 finite numbers, ``A`` with a condition
    number at most :data:`COND_LIMIT`; ``magcal.expected_field_strength_ut`` a positive number (and the
    top-level ``expected_field_strength_ut.value``, where present, the same); ``temperature`` null or
    ``centre_c`` and 3 ``coef_ut_per_c``; ``to_accelerometer_axes`` null or a rotation matrix;
    ``columns.field``, where present, the columns apply corrects.  One-line InputError naming ``name`` (the
    file), the key, its value and the limit.  Returns the values: ``{"A", "b", "field_ut", "temperature":
    (centre, coef) or None, "rotation": R or None}``."""
    if not isinstance(cal, dict) or cal.get("format") != FORMAT:
        raise InputError(f'{name}: not a navlib calibration file (no "format": "{FORMAT}")')
    if cal.get("system") != SYSTEM.name:
        raise InputError(
            f"{name}: a calibration of the system {cal.get('system')!r}; apply corrects "
            f"'{SYSTEM.name}' calibrations (python -m navlib calibrate magnetometer)"
        )
    version = cal.get("version")
    if isinstance(version, bool) or version != VERSION:
        raise InputError(
            f"{name}: calibration format version {version!r}; this navlib reads {VERSION}"
        )
    A = _array(_get(cal, ("magcal", "A"), name), ("magcal", "A"), (3, 3), name)
    b = _array(_get(cal, ("magcal", "b_ut"), name), ("magcal", "b_ut"), (3,), name)
    key = ("magcal", "expected_field_strength_ut")
    field = _number(_get(cal, key, name), key, name)
    if field <= 0:
        raise InputError(
            f"{name}: key '{_key_text(key)}' = {field:g} must be a positive field strength (uT)"
        )
    top = _get(cal, ("expected_field_strength_ut",), name, required=False)
    if top is not None:
        value = _number(
            _get(cal, ("expected_field_strength_ut", "value"), name),
            ("expected_field_strength_ut", "value"),
            name,
        )
        if abs(value - field) > 1e-9 * field:
            raise InputError(
                f"{name}: key 'expected_field_strength_ut.value' = {value:g} differs from "
                f"'magcal.expected_field_strength_ut' = {field:g} (a hand edit of one of them?)"
            )
    with np.errstate(all="ignore"):
        cond = float(np.linalg.cond(A))
    if not cond <= COND_LIMIT:  # also NaN / inf: singular
        said = "infinite: A is singular" if not np.isfinite(cond) or cond > 1e12 else f"{cond:.3g}"
        raise InputError(
            f"{name}: key 'magcal.A': condition number {said} (the limit is {COND_LIMIT:g}): "
            f"not the correction of a working magnetometer"
        )
    temperature = _get(cal, ("temperature",), name, required=False)
    temp = None
    if temperature is not None:
        centre = _number(
            _get(cal, ("temperature", "centre_c"), name), ("temperature", "centre_c"), name
        )
        coef = _array(
            _get(cal, ("temperature", "coef_ut_per_c"), name),
            ("temperature", "coef_ut_per_c"),
            (3,),
            name,
        )
        temp = (centre, coef)
    axes = _get(cal, ("to_accelerometer_axes",), name, required=False)
    R = None
    if axes is not None:
        R = _array(axes, ("to_accelerometer_axes",), (3, 3), name)
        if not (np.allclose(R @ R.T, np.eye(3), atol=1e-6) and np.linalg.det(R) > 0):
            raise InputError(
                f"{name}: key 'to_accelerometer_axes' is not a rotation matrix (R R^T = I, det R = 1 "
                f"to 1e-6)"
            )
    columns = (
        _get(cal, ("columns", "field"), name, required=False)
        if cal.get("columns") is not None
        else None
    )
    if columns is not None and columns != list(MAG):
        raise InputError(
            f"{name}: key 'columns.field' = {_short(columns)}: apply corrects the columns "
            f"{', '.join(MAG)}"
        )
    return {"A": A, "b": b, "field_ut": field, "temperature": temp, "rotation": R}


def read_calibration(path) -> dict:
    """A calibration file written by :func:`write_calibration`; one-line InputError for anything else (not
    JSON, not a navlib calibration, a calibration of another system, a newer version, any key apply reads
    missing, of the wrong type or shape, not finite, or ``A`` ill conditioned: :func:`check_calibration`)."""
    name = Path(path).name
    try:
        cal = json.loads(Path(path).read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputError(
            f"{name}: not a calibration file (not JSON: {str(err).splitlines()[0]})"
        ) from None
    check_calibration(cal, name)
    return cal


def apply_calibration(cal: dict, frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with its field columns corrected: ``(m - b(T)) A`` (and turned into the accelerometer's
    axes when the calibration has a misalignment).  ``cal`` is checked first (:func:`check_calibration`)."""
    c = check_calibration(cal, "calibration")
    m = frame[list(MAG)].to_numpy(float) - c["b"]
    if c["temperature"] is not None:
        centre, coef = c["temperature"]
        m = m - (frame["temperature_c"].to_numpy(float) - centre)[:, None] * coef
    with np.errstate(over="ignore", invalid="ignore"):
        u = m @ c["A"]
        if c["rotation"] is not None:
            u = u @ c["rotation"].T
    out = frame.drop(columns=[c for c in DERIVED if c in frame]).copy()
    out[list(MAG)] = u
    return out


def check_corrected(cal: dict, corrected: pd.DataFrame, cal_name: str, data_name: str) -> list[str]:
    """Check the corrected field before it is written: every value finite, and the field strength it shows
    (median ``|m_corrected|``) within :data:`FIELD_REFUSE_REL` of the calibration's expected field strength
    (InputError otherwise, naming both files); beyond :data:`FIELD_WARN_REL` the returned list holds one
    warning line."""
    u = corrected[list(MAG)].to_numpy(float)
    bad = np.flatnonzero(~np.all(np.isfinite(u), axis=1))
    if bad.size:
        raise InputError(
            f"{data_name}: row {bad[0] + 1} (and {bad.size - 1} more): the field corrected with "
            f"{cal_name} is not finite; nothing written"
        )
    expected = float(cal["magcal"]["expected_field_strength_ut"])
    big = np.max(np.abs(u), axis=1)  # |u| without overflow: scaled by the largest component
    size = big * np.linalg.norm(u / np.where(big > 0, big, 1.0)[:, None], axis=1)
    seen = float(np.median(size))
    rel = seen / expected - 1.0
    said = (
        f"the corrected field strength (median |m_corrected|) is {seen:.4g} uT, {100 * rel:+.3g} % from "
        f"{cal_name}'s expected_field_strength_ut {expected:.4g} uT"
    )
    if not abs(rel) <= FIELD_REFUSE_REL:
        raise InputError(
            f"{data_name}: {said} (more than {100 * FIELD_REFUSE_REL:g} %: a calibration of another "
            f"sensor, unit or site?); nothing written"
        )
    if abs(rel) > FIELD_WARN_REL:
        return [
            f"{data_name}: {said} (more than {100 * FIELD_WARN_REL:g} %: another site, or steel nearby?)"
        ]
    return []


def apply_file(cal_path, data_path, out_path) -> tuple[Path, int, list[str]]:
    """Read a calibration and a measurement file, check they match, correct, check the corrected field
    (:func:`check_corrected`), write the corrected file (never over an existing one: checked before the
    work).  Returns the path, the rows written and the warnings (lines for stderr)."""
    out_path = Path(out_path)
    if out_path.exists() or out_path.is_symlink():
        raise InputError(f"{out_path}: already exists; not overwritten (choose another --out)")
    cal = read_calibration(cal_path)
    name = Path(data_path).name
    frame = read_table(data_path, free_columns(), min_rows=1, kind="magnetometer file")
    check_units(frame, name)
    if cal.get("temperature") and "temperature_c" not in frame:
        raise InputError(
            f"{name}: the calibration corrects a temperature-dependent offset: the file needs a "
            f"'temperature_c' column"
        )
    corrected = apply_calibration(cal, frame)
    warnings = check_corrected(cal, corrected, Path(cal_path).name, name)
    return write_new_csv(corrected, out_path), len(frame), warnings


def calibrate_file(data_path, model, out_path, site=None, date=None) -> tuple[Path, dict]:
    """Load a file (:func:`navlib.workbench.magnetometer_free.load_free`), calibrate it with ``model`` and write the JSON to ``out_path``
    (existing files refused before the work)."""
    out_path = Path(out_path)
    if out_path.exists() or out_path.is_symlink():
        raise InputError(f"{out_path}: already exists; not overwritten (choose another --out)")
    data = load_free(data_path)
    cal = calibrate(data, model, source=Path(data_path).name, site=site, date=date)
    return write_calibration(cal, out_path), cal
