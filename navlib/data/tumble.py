"""Multi-position full-temperature (tumble) files of an accelerometer on a dividing head (paper D).

Schema (``data/accel_tumble.md``): ``temperature_c`` (sensor temperature, degC, -60..130), ``position_deg``
(dividing-head angle, on the head's grid: a multiple of ``grid_deg``, 0 <= q < 360), ``output_mg`` (output
divided by the nominal scale factor: a perfect sensor reads ``1000 cos q``), ``unit`` (the accelerometer's
name); optional ``set_point_c`` (chamber set point) and ``true_output_mg`` (simulations only).  Every fault
is one line naming file, column and row.
"""

from __future__ import annotations

import os

import numpy as np
import pandas as pd

from ..errors import InputError
from ..paths import data_path
from .tables import Column, read_table, where

TUMBLE_FILE = data_path("accel_tumble.csv")
COLUMNS = [
    Column(
        "temperature_c", "degC", lo=-60.0, hi=130.0, meaning="sensor temperature at the reading"
    ),
    Column(
        "position_deg",
        "deg",
        lo=0.0,
        hi=360.0,
        meaning="dividing-head angle q, on the head's 15-deg grid (input a = cos q)",
    ),
    Column(
        "output_mg",
        "mg",
        lo=-5000.0,
        hi=5000.0,
        meaning="output / nominal scale factor (a perfect sensor reads 1000 cos q)",
    ),
    Column("unit", required=True, text=True, meaning="accelerometer name"),
    Column(
        "set_point_c",
        "degC",
        required=False,
        lo=-60.0,
        hi=130.0,
        meaning="chamber set point (the temperature rounded to 0.5 degC if absent)",
    ),
    Column(
        "true_output_mg",
        "mg",
        required=False,
        lo=-5000.0,
        hi=5000.0,
        meaning="noise-free output (simulations only; not read by the models)",
    ),
]


def read_tumble(path: str | os.PathLike = TUMBLE_FILE, grid_deg: float = 15.0) -> pd.DataFrame:
    """Read and validate a tumble file.

    Checks beyond :func:`navlib.data.tables.read_table` (limits: temperatures -60..130 degC, positions
    0..360 deg, outputs +-5000 mg): ``position_deg`` not in radians (four or more positions all within
    0..2 pi), below 360 and on the dividing head's grid (a multiple of ``grid_deg`` within 1e-6 deg), ``unit`` present and non-empty.  Adds
    ``set_point_c`` (the temperature rounded to 0.5 degC) when the file has none.
    """
    if not (0 < float(grid_deg) <= 180):
        raise InputError(f"parameter grid_deg={grid_deg!r}: must be in (0, 180]")
    df = read_table(path, COLUMNS, min_rows=3, kind="tumble file")
    name = os.path.basename(str(path))
    unit = df["unit"].astype(str).str.strip()
    empty = np.flatnonzero(unit.to_numpy() == "")
    if empty.size:
        raise InputError(f"{where(path, 'unit', int(empty[0]), df)}: is empty")
    df["unit"] = unit
    q = df["position_deg"].to_numpy()
    if q.max() <= 2 * np.pi + 1e-9 and len(np.unique(q)) >= 4:
        raise InputError(
            f"{name}: column 'position_deg': every value is within 0..{2 * np.pi:.4f}; these look "
            f"like radians, the column must be in degrees"
        )
    off = np.abs(q / grid_deg - np.round(q / grid_deg)) * grid_deg > 1e-6
    off |= q >= 360.0
    if off.any():
        r = int(np.flatnonzero(off)[0])
        raise InputError(
            f"{where(path, 'position_deg', r, df)}: {q[r]:g} is not on the dividing head's "
            f"{grid_deg:g} deg grid (0 <= q < 360)"
        )
    if "set_point_c" not in df.columns:
        df["set_point_c"] = np.round(df["temperature_c"].to_numpy() * 2) / 2
    return df


def require_levels(
    df: pd.DataFrame,
    *,
    temperatures: int = 0,
    positions: int = 0,
    what: str = "this model",
    name: str = "tumble data",
) -> None:
    """Raise unless every unit in ``df`` has at least ``temperatures`` set points and ``positions``
    distinct positions (e.g. a temperature polynomial of degree 2 needs 3 temperatures)."""
    for unit, g in df.groupby("unit", sort=False):
        nt = g["set_point_c"].nunique()
        npos = g["position_deg"].nunique()
        if nt < temperatures:
            raise InputError(
                f"{name}: unit {unit} has {nt} temperature{'s' if nt != 1 else ''}; "
                f"{what} needs at least {temperatures}"
            )
        if npos < positions:
            raise InputError(
                f"{name}: unit {unit} has {npos} position{'s' if npos != 1 else ''}; "
                f"{what} needs at least {positions}"
            )
