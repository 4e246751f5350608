"""Compass sweep files: loading with validation, splitting into the training and test sweeps, and the
unwrapped measured heading the networks take as input.

Columns (``data/compass_sweeps.md``): ``true_heading_deg`` and ``measured_heading_deg`` (deg, 0..360),
optional ``sweep`` (1 = train, 2 = test), ``temperature_c``, ``time_s``, the raw field ``mag_*_ut`` and
the accelerometer ``acc_*_ms2``.  Every fault is reported in one line naming file, column and row.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError
from .tables import Column, read_table

SWEEP_COLUMNS = [
    Column("true_heading_deg", "deg", lo=0.0, hi=360.0),
    Column("measured_heading_deg", "deg", lo=0.0, hi=360.0),
    Column("sweep", "", required=False, lo=0, integer=True),
    Column("temperature_c", "degC", required=False, lo=-80, hi=150),
    Column("time_s", "s", required=False, lo=0),
    Column("mag_x_ut", "uT", required=False), Column("mag_y_ut", "uT", required=False),
    Column("mag_z_ut", "uT", required=False),
    Column("acc_x_ms2", "m/s^2", required=False), Column("acc_y_ms2", "m/s^2", required=False),
    Column("acc_z_ms2", "m/s^2", required=False),
]


def load_sweeps(path, *, min_points: int = 8) -> pd.DataFrame:
    """Load a compass sweep CSV (one or several sweeps told apart by an optional ``sweep`` column) and
    validate it.  Errors (one line, naming file, column and row): missing or misnamed columns, non-numeric
    values, empty cells or NaN, headings outside 0..360 deg, headings that look like radians (every value
    within 0..2*pi over a sweep spanning more than a few degrees), a true heading repeated within a sweep
    (except 0 and 360 closing the circle), and fewer than ``min_points`` readings in a sweep."""
    frame = read_table(path, SWEEP_COLUMNS, min_rows=min_points, kind="compass sweep")
    name = Path(path).name
    if "sweep" not in frame:
        frame["sweep"] = 1
    frame["sweep"] = frame["sweep"].astype(int)
    for col in ("true_heading_deg", "measured_heading_deg"):
        v = frame[col].to_numpy()
        if v.max() <= 2 * np.pi + 1e-9 and len(v) >= 4:
            raise InputError(f"{name}: column '{col}': every value is within 0..{2 * np.pi:.4f}; these look "
                             f"like radians, the column must be in degrees")
    for sweep_id, part in frame.groupby("sweep", sort=True):
        if len(part) < min_points:
            raise InputError(f"{name}: sweep {sweep_id} has {len(part)} readings, at least {min_points} "
                             f"are needed")
        t = part["true_heading_deg"].to_numpy()
        key = np.round(np.where(t >= 360.0, t - 360.0, t), 9)
        closing = (t >= 360.0)
        dup = pd.Series(key[~closing]).duplicated().to_numpy()
        if dup.any():
            r = int(part.index[np.flatnonzero(~closing)[np.flatnonzero(dup)[0]]])
            raise InputError(f"{name}: column 'true_heading_deg', row {r + 1} (file line {r + 2}): heading "
                             f"{t[np.flatnonzero(~closing)[np.flatnonzero(dup)[0]]]:g} is repeated in "
                             f"sweep {sweep_id}")
    return frame


def split_sweeps(frame: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(train, test) = sweep 1 and sweep 2 of a two-sweep frame, as in paper A."""
    ids = sorted(frame["sweep"].unique())
    if len(ids) < 2:
        raise InputError(f"need two sweeps (train and test), found {len(ids)}")
    return (frame[frame.sweep == ids[0]].reset_index(drop=True),
            frame[frame.sweep == ids[1]].reset_index(drop=True))


def unwrap_measured(true_deg, measured_deg) -> np.ndarray:
    """The measured heading unwrapped along the sweep so that it runs continuously with the turntable
    (paper A feeds the measured heading to a single-input network; the wrap at 0/360 would break the
    one-to-one mapping).  The unwrapping uses only the reading order, never the true value."""
    m = np.degrees(np.unwrap(np.radians(np.asarray(measured_deg, dtype=float))))
    # start the branch within +-180 deg of the first true heading (the table starts at north)
    first = np.asarray(true_deg, dtype=float)[0]
    return m - 360.0 * np.round((m[0] - first) / 360.0)


