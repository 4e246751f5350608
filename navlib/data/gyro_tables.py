"""Loaders for the axial-gyro-drift tables of paper C (Yu et al. 2012, Tables 2-5) and for user drift files.

All tables are validated with :func:`navlib.data.tables.read_table` (file, column and row in every message) plus
cross-column checks (a temperature range's minimum not above its maximum, a printed temperature change equal
to max - min, the calibration window inside the alignment range).  Every loader adds
``latitude_error_deg = latitude_deg - LOCAL_LATITUDE_DEG`` where a latitude is present (paper C: the
12 h latitude *output*, local latitude 28.222 deg).  Column meanings, units and provenance:
``data/gyro_tables.md``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError
from ..paths import data_path
from .tables import Column, read_table, where

#: Paper C's test site, the local latitude its 12 h latitude outputs are compared with (deg).
LOCAL_LATITUDE_DEG = 28.222

TABLE_FILES = {
    2: "gyro_table2_hot_train.csv",
    3: "gyro_table3_hot_test.csv",
    4: "gyro_table4_cold_train.csv",
    5: "gyro_table5_cold_test.csv",
}

_LAT = Column("latitude_deg", "deg", lo=28.0, hi=28.5)  # 12 h latitude output near the site
_DRIFT = dict(unit="deg/h", lo=-0.1, hi=0.1)
_TEMP = dict(unit="degC", lo=-60.0, hi=120.0)
_NMI = dict(unit="nmi/72h", lo=0.0, hi=1000.0)

COLUMNS = {
    2: [
        Column("sample", "", lo=1, integer=True),
        _LAT,
        Column("temperature_min_c", **_TEMP),
        Column("temperature_max_c", **_TEMP),
        Column("drift_deg_h", **_DRIFT),
    ],
    3: [
        Column("test", "", lo=1, integer=True),
        _LAT,
        Column("temperature_min_c", **_TEMP),
        Column("temperature_max_c", **_TEMP),
        Column("paper_rbf_drift_deg_h", **_DRIFT),
        Column("true_drift_deg_h", **_DRIFT),
        Column("paper_error_deg_h", **_DRIFT),
        Column("paper_pos_error_before_nmi_72h", **_NMI),
        Column("paper_pos_error_after_nmi_72h", **_NMI),
    ],
    4: [
        Column("sample", "", lo=1, integer=True),
        Column("align_temp_min_c", **_TEMP),
        Column("align_temp_max_c", **_TEMP),
        Column("align_temp_change_c", "degC", lo=0, hi=180),
        Column("calib_temp_min_c", **_TEMP),
        Column("calib_temp_max_c", **_TEMP),
        Column("calib_temp_change_c", "degC", lo=0, hi=180),
        _LAT,
        Column("true_drift_deg_h", **_DRIFT),
        Column("paper_hot_rbf_drift_deg_h", **_DRIFT),
    ],
    5: [
        Column("test", "", lo=1, integer=True),
        Column("align_temp_min_c", **_TEMP),
        Column("align_temp_max_c", **_TEMP),
        Column("align_temp_change_c", "degC", lo=0, hi=180),
        Column("calib_temp_min_c", **_TEMP),
        Column("calib_temp_max_c", **_TEMP),
        Column("calib_temp_change_c", "degC", lo=0, hi=180),
        Column("paper_pos_error_hot_net_nmi_72h", **_NMI),
        Column("paper_pos_error_cold_net_nmi_72h", **_NMI),
    ],
}
MIN_ROWS = {2: 2, 3: 1, 4: 2, 5: 1}
KIND = {
    2: "hot-state training table",
    3: "hot-state test table",
    4: "cold-state training table",
    5: "cold-state test table",
}


def _check_range(path, df, lo_col, hi_col) -> None:
    bad = np.flatnonzero(df[lo_col].to_numpy() > df[hi_col].to_numpy())
    if bad.size:
        r = int(bad[0])
        raise InputError(
            f"{where(path, lo_col, r)}: {df[lo_col].iloc[r]:g} is above "
            f"{hi_col} = {df[hi_col].iloc[r]:g}"
        )


def _check_change(path, df, lo_col, hi_col, change_col) -> None:
    diff = df[hi_col].to_numpy() - df[lo_col].to_numpy()
    bad = np.flatnonzero(np.abs(df[change_col].to_numpy() - diff) > 1e-9)
    if bad.size:
        r = int(bad[0])
        raise InputError(
            f"{where(path, change_col, r)}: {df[change_col].iloc[r]:g} is not "
            f"{hi_col} - {lo_col} = {diff[r]:g}"
        )


def _check_unique(path, df, col) -> None:
    dup = np.flatnonzero(df[col].duplicated().to_numpy())
    if dup.size:
        r = int(dup[0])
        raise InputError(f"{where(path, col, r)}: {df[col].iloc[r]:g} appears twice")


def load_table(number: int, path: str | os.PathLike | None = None) -> pd.DataFrame:
    """Load and validate paper C's Table ``number`` (2, 3, 4 or 5) from ``data/`` (or ``path``)."""
    if number not in TABLE_FILES:
        raise InputError(f"parameter table={number!r}: paper C has drift tables 2, 3, 4 and 5")
    p = Path(path) if path is not None else data_path(TABLE_FILES[number])
    df = read_table(p, COLUMNS[number], min_rows=MIN_ROWS[number], kind=KIND[number])
    key = "sample" if number in (2, 4) else "test"
    _check_unique(p, df, key)
    if number in (2, 3):
        _check_range(p, df, "temperature_min_c", "temperature_max_c")
    else:
        _check_range(p, df, "align_temp_min_c", "align_temp_max_c")
        _check_range(p, df, "calib_temp_min_c", "calib_temp_max_c")
        _check_change(p, df, "align_temp_min_c", "align_temp_max_c", "align_temp_change_c")
        _check_change(p, df, "calib_temp_min_c", "calib_temp_max_c", "calib_temp_change_c")
        _check_range(p, df, "align_temp_min_c", "calib_temp_min_c")
        _check_range(p, df, "calib_temp_max_c", "align_temp_max_c")
    if "latitude_deg" in df:
        df["latitude_error_deg"] = df["latitude_deg"] - LOCAL_LATITUDE_DEG
    df[key] = df[key].astype(int)
    return df


def load_hot_train(path=None) -> pd.DataFrame:
    """Table 2: hot-state training samples (16 rows)."""
    return load_table(2, path)


def load_hot_test(path=None) -> pd.DataFrame:
    """Table 3: hot-state test samples with the paper's RBF outputs and 72 h position errors (3 rows)."""
    return load_table(3, path)


def load_cold_train(path=None) -> pd.DataFrame:
    """Table 4: cold-state training samples with the paper's hot-net output (6 rows)."""
    return load_table(4, path)


def load_cold_test(path=None) -> pd.DataFrame:
    """Table 5: cold-state tests, temperature histories and the paper's 72 h position errors (3 rows)."""
    return load_table(5, path)


#: The columns of a user's drift table (what ``python -m navlib loop drift FILE`` reads), with their limits.
USER_COLUMNS = [
    Column(
        "latitude_error_deg",
        "deg",
        lo=-1.0,
        hi=1.0,
        meaning="12 h latitude error of the test, indicated - true",
    ),
    Column(
        "drift_deg_h", "deg/h", lo=-1.0, hi=1.0, meaning="axial gyro drift identified for the test"
    ),
    Column(
        "temperature_c",
        "degC",
        required=False,
        lo=-60.0,
        hi=120.0,
        meaning="mean temperature while the drift is identified",
    ),
    Column(
        "temperature_change_c",
        "degC",
        required=False,
        lo=-180.0,
        hi=180.0,
        meaning="temperature rise during the alignment (a cold start)",
    ),
]


def load_user_drift(
    path: str | os.PathLike, *, require_drift: bool = True, min_rows: int = 1
) -> pd.DataFrame:
    """A user's drift CSV: ``latitude_error_deg`` (12 h latitude error, indicated - true, deg),
    ``drift_deg_h`` (axial drift, deg/h; optional with ``require_drift=False`` for files to identify),
    optional ``temperature_c`` and ``temperature_change_c`` (C) for a cold-state network."""
    cols = list(USER_COLUMNS)
    if not require_drift:
        cols[1] = Column("drift_deg_h", "deg/h", required=False, lo=-1.0, hi=1.0)
    return read_table(path, cols, min_rows=min_rows, kind="drift table")


# ------------------------------------------------------------------------------- workbench drift files
def drift_measurements(which: str = "all") -> pd.DataFrame:
    """Paper C's measured tests in the drift-file schema of the workbench (``python -m navlib diagnose
    drift``): ``latitude_error_deg``, ``drift_deg_h``, ``temperature_c``, ``temperature_change_c``, plus
    ``state`` ('hot'/'cold'), ``table`` and ``row``.

    ``which``: 'hot' (Tables 2 and 3, 19 tests), 'cold' (Table 4, 6 tests) or 'all'.
    Temperature: the midpoint of the range over which the drift is identified (hot: the printed test
    range; cold: the 12 h calibration window).  Temperature change: the rise during the 16 h alignment
    (hot: the span of the printed range; cold: the printed alignment change), the quantity that defines
    paper C's cold state."""
    if which not in ("hot", "cold", "all"):
        raise InputError(f"parameter which={which!r}: must be 'hot', 'cold' or 'all'")
    parts = []
    if which in ("hot", "all"):
        for number, drift_col in ((2, "drift_deg_h"), (3, "true_drift_deg_h")):
            t = load_table(number)
            parts.append(
                pd.DataFrame(
                    {
                        "latitude_error_deg": t["latitude_error_deg"],
                        "drift_deg_h": t[drift_col],
                        "temperature_c": (t["temperature_min_c"] + t["temperature_max_c"]) / 2,
                        "temperature_change_c": t["temperature_max_c"] - t["temperature_min_c"],
                        "state": "hot",
                        "table": number,
                        "row": t["sample" if number == 2 else "test"],
                    }
                )
            )
    if which in ("cold", "all"):
        t = load_table(4)
        parts.append(
            pd.DataFrame(
                {
                    "latitude_error_deg": t["latitude_error_deg"],
                    "drift_deg_h": t["true_drift_deg_h"],
                    "temperature_c": (t["calib_temp_min_c"] + t["calib_temp_max_c"]) / 2,
                    "temperature_change_c": t["align_temp_change_c"],
                    "state": "cold",
                    "table": 4,
                    "row": t["sample"],
                }
            )
        )
    return pd.concat(parts, ignore_index=True)
