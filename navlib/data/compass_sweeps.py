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
from .tables import Column, read_table, require_variation, where

# Limits: headings 0..360 deg, sweep a whole number 0..1e6, temperature -80..150 degC, time 0..1e9 s
# (about 32 years).  The raw field and accelerometer columns are informational: no model of the compass
# reads them, so they are converted where they parse and never refused.
SWEEP_COLUMNS = [
    Column(
        "true_heading_deg",
        "deg",
        lo=0.0,
        hi=360.0,
        meaning="true (reference) heading, clockwise from magnetic north",
    ),
    Column(
        "measured_heading_deg",
        "deg",
        lo=0.0,
        hi=360.0,
        meaning="heading the compass reads, clockwise from magnetic north",
    ),
    Column(
        "sweep",
        "",
        required=False,
        lo=0,
        hi=1e6,
        integer=True,
        meaning="sweep number (1 = train, 2 = test); one sweep if absent",
    ),
    Column(
        "temperature_c",
        "degC",
        required=False,
        lo=-80,
        hi=150,
        meaning="carrier temperature at the reading (the temperature effect needs it)",
    ),
    Column(
        "time_s",
        "s",
        required=False,
        lo=0,
        hi=1e9,
        meaning="time of the reading (a trend in time; the noise model's time series)",
    ),
    *[
        Column(c, u, required=False, checked=False, meaning=m)
        for c, u, m in (
            ("mag_x_ut", "uT", "raw field, x forward (information only)"),
            ("mag_y_ut", "uT", "raw field, y right (information only)"),
            ("mag_z_ut", "uT", "raw field, z down (information only)"),
            ("acc_x_ms2", "m/s^2", "specific force, x forward (information only)"),
            ("acc_y_ms2", "m/s^2", "specific force, y right (information only)"),
            ("acc_z_ms2", "m/s^2", "specific force, z down (information only)"),
        )
    ],
]
#: A measured heading that follows the true one keeps the error ``measured - true`` in one direction:
#: the mean resultant length of the error is above 0.7 even with the largest hard iron the compass model
#: accepts (0.95 of the horizontal field); below ``FOLLOWS_MIN`` the heading does not follow.
FOLLOWS_MIN = 0.3


def load_sweeps(path, *, min_points: int = 8) -> pd.DataFrame:
    """Load a compass sweep CSV (one or several sweeps told apart by an optional ``sweep`` column) and
    validate it.  Errors (one line, naming file, column and row): missing, misnamed or repeated columns,
    non-numeric values, empty cells, NaN or infinity, values outside the limits (headings 0..360 deg,
    ``sweep`` 0..1e6, ``temperature_c`` -80..150 degC, ``time_s`` 0..1e9 s), headings that look like
    radians (every value within 0..2*pi over a sweep spanning more than a few degrees), a true heading
    repeated within a sweep (except 0 and 360 closing the circle), fewer than ``min_points`` readings in a
    sweep, and two plausibility checks: a measured heading that never changes (a stuck compass), and one
    that does not follow the true heading (the mean resultant length of ``measured - true`` below
    ``FOLLOWS_MIN``, 0.3) -- named as running the other way (counter-clockwise headings) when
    ``measured + true`` is nearly constant instead.  The raw field and accelerometer columns are
    informational and never refused."""
    frame = read_table(path, SWEEP_COLUMNS, min_rows=min_points, kind="compass sweep")
    name = Path(path).name
    if "sweep" not in frame:
        frame["sweep"] = 1
    frame["sweep"] = frame["sweep"].astype(int)
    for col in ("true_heading_deg", "measured_heading_deg"):
        v = frame[col].to_numpy()
        if v.max() <= 2 * np.pi + 1e-9 and len(v) >= 4:
            raise InputError(
                f"{name}: column '{col}': every value is within 0..{2 * np.pi:.4f}; these look "
                f"like radians, the column must be in degrees"
            )
    require_variation(
        frame, ["measured_heading_deg"], path, "a compass turned through its headings"
    )
    check_follows(frame, name)
    for sweep_id, part in frame.groupby("sweep", sort=True):
        if len(part) < min_points:
            raise InputError(
                f"{name}: sweep {sweep_id} has {len(part)} readings, at least {min_points} "
                f"are needed"
            )
        t = part["true_heading_deg"].to_numpy()
        key = np.round(np.where(t >= 360.0, t - 360.0, t), 9)
        closing = t >= 360.0
        dup = pd.Series(key[~closing]).duplicated().to_numpy()
        if dup.any():
            r = int(part.index[np.flatnonzero(~closing)[np.flatnonzero(dup)[0]]])
            raise InputError(
                f"{where(path, 'true_heading_deg', r, frame)}: heading "
                f"{t[np.flatnonzero(~closing)[np.flatnonzero(dup)[0]]]:g} is repeated in "
                f"sweep {sweep_id}"
            )
    return frame


def check_follows(frame: pd.DataFrame, name: str = "data") -> None:
    """The measured heading must follow the true one (see :func:`load_sweeps`); checked when the true
    headings spread over the circle (their mean resultant length below 0.7)."""
    t = np.radians(frame["true_heading_deg"].to_numpy(float))
    m = np.radians(frame["measured_heading_deg"].to_numpy(float))
    if abs(np.mean(np.exp(1j * t))) >= 0.7:
        return
    follows = float(abs(np.mean(np.exp(1j * (m - t)))))
    if follows >= FOLLOWS_MIN:
        return
    if abs(np.mean(np.exp(1j * (m + t)))) > 0.8:
        raise InputError(
            f"{name}: column 'measured_heading_deg' falls as 'true_heading_deg' rises: the "
            f"headings run the other way (counter-clockwise?); both must be clockwise from north"
        )
    raise InputError(
        f"{name}: column 'measured_heading_deg' does not follow 'true_heading_deg' (mean "
        f"resultant length of their difference {follows:.2f}, below {FOLLOWS_MIN:g}): columns "
        f"swapped or shuffled, or another sensor's output?"
    )


def split_sweeps(frame: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(train, test) = sweep 1 and sweep 2 of a two-sweep frame, as in paper A."""
    ids = sorted(frame["sweep"].unique())
    if len(ids) < 2:
        raise InputError(f"need two sweeps (train and test), found {len(ids)}")
    return (
        frame[frame.sweep == ids[0]].reset_index(drop=True),
        frame[frame.sweep == ids[1]].reset_index(drop=True),
    )


def unwrap_measured(true_deg, measured_deg) -> np.ndarray:
    """The measured heading unwrapped along the sweep so that it runs continuously with the turntable
    (paper A feeds the measured heading to a single-input network; the wrap at 0/360 would break the
    one-to-one mapping).  The unwrapping uses only the reading order, never the true value."""
    m = np.degrees(np.unwrap(np.radians(np.asarray(measured_deg, dtype=float))))
    # start the branch within +-180 deg of the first true heading (the table starts at north)
    first = np.asarray(true_deg, dtype=float)[0]
    return m - 360.0 * np.round((m[0] - first) / 360.0)
