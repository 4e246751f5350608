"""What the reference-free magnetometer's residuals still hold after the loop, broken down by time, turn
rate, orientation and acceleration (issue 34: on real hand-held recordings the loop ends "field changing in
time" and a user needs to know what that structure is, and whether the magnetometer or the accelerometer's
gravity direction is to blame).

For each invariant (the magnitude ``|u| - F``; with an accelerometer the dip invariant) and each factor the
rows are grouped into cells and the residual's variance is split into between-cell and within-cell parts::

    share = sum_c n_c (rbar_c - rbar)^2 / sum_i (r_i - rbar)^2     (eta squared)
    amplitude = sqrt(sum_c n_c (rbar_c - rbar)^2 / n)       (rms of the cell means, uT)

Factors: **time** (ten cells of equal count over ``time_s``); **turn rate** (four cells over ``|omega|``,
from the gyro columns, or where there are none the turn of the corrected field's direction between
consecutive samples divided by their time step: a lower bound of the rate); **orientation** (six cells: the
sensor axis, with its sign, closest to the corrected field); **acceleration** (four cells over
``||a| - g|``, ``g`` the median ``|a|``: how far the accelerometer is from measuring gravity alone).

This is a description, not a test: with serially correlated noise every slow factor (time above all) takes
a share by chance; the loop's diagnosis made the tests.  :func:`reading` turns the table into one
sentence naming the factor that holds the most and what it points at.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

FACTORS = ("time", "turn rate", "orientation", "acceleration")
TIME_CELLS = 10
QUARTILES = 4
#: Share of the residual variance above which a factor is said to hold the structure.
CLEAR_SHARE = 0.10
_AXES = ("+x", "-x", "+y", "-y", "+z", "-z")


def _quantile_cells(x: np.ndarray, k: int) -> np.ndarray:
    """Cell index 0..k-1 of each value: ``k`` cells of (nearly) equal count."""
    edges = np.quantile(x, np.linspace(0, 1, k + 1)[1:-1])
    return np.searchsorted(edges, x, side="right")


def _cell_labels(x: np.ndarray, cell: np.ndarray, unit: str) -> dict:
    return {
        int(c): f"{np.min(x[cell == c]):.3g}-{np.max(x[cell == c]):.3g} {unit}"
        for c in np.unique(cell)
    }


def factors(time_s=None, rate_dps=None, u=None, acc=None) -> dict:
    """The cells of each factor available: ``{factor: (cell index per row, {cell: label})}``.
    ``time_s`` (n,), ``rate_dps`` (n,) or None, ``u`` (n, 3) the corrected field, ``acc`` (n, 3) or None."""
    out = {}
    if time_s is not None and np.ptp(time_s) > 0:
        c = _quantile_cells(time_s, TIME_CELLS)
        out["time"] = (c, _cell_labels(time_s, c, "s"))
    if rate_dps is None and time_s is not None and u is not None and len(u) > 2:
        un = u / np.linalg.norm(u, axis=1, keepdims=True)
        ang = np.degrees(np.arccos(np.clip(np.sum(un[1:] * un[:-1], axis=1), -1.0, 1.0)))
        dt = np.diff(time_s)
        step = np.where(dt > 0, ang / np.where(dt > 0, dt, 1.0), np.nan)
        rate_dps = np.r_[step[0], step] if np.all(np.isfinite(step)) else None
    if rate_dps is not None and np.ptp(rate_dps) > 0:
        c = _quantile_cells(rate_dps, QUARTILES)
        out["turn rate"] = (c, _cell_labels(rate_dps, c, "deg/s"))
    if u is not None:
        j = np.argmax(np.abs(u), axis=1)
        c = 2 * j + (u[np.arange(len(u)), j] < 0)
        out["orientation"] = (c, {k: f"field along {_AXES[k]}" for k in range(6)})
    if acc is not None:
        na = np.linalg.norm(acc, axis=1)
        excess = np.abs(na - np.median(na))
        if np.ptp(excess) > 0:
            c = _quantile_cells(excess, QUARTILES)
            out["acceleration"] = (c, _cell_labels(excess, c, "m/s^2 off gravity"))
    return out


def breakdown(residuals: np.ndarray, invariants, cells: dict) -> pd.DataFrame:
    """One row per invariant and factor: ``invariant, factor, cells, share, amplitude_ut, largest_cell,
    largest_mean_ut`` (module docstring).  ``residuals``: (n, k), one column per name in ``invariants``."""
    rows = []
    r = np.asarray(residuals, float).reshape(len(residuals), -1)
    for j, name in enumerate(invariants):
        x = r[:, j] - r[:, j].mean()
        total = float(x @ x)
        for factor in FACTORS:
            if factor not in cells:
                continue
            cell, labels = cells[factor]
            ids, inv, counts = np.unique(cell, return_inverse=True, return_counts=True)
            means = np.bincount(inv, weights=x) / counts
            between = float(np.sum(counts * means**2))
            big = int(np.argmax(np.abs(means)))
            rows.append(
                {
                    "invariant": name,
                    "factor": factor,
                    "cells": int(len(ids)),
                    "share": between / total if total > 0 else 0.0,
                    "amplitude_ut": float(np.sqrt(between / len(x))),
                    "largest_cell": labels[int(ids[big])],
                    "largest_mean_ut": float(means[big]),
                }
            )
    return pd.DataFrame(
        rows,
        columns=[
            "invariant",
            "factor",
            "cells",
            "share",
            "amplitude_ut",
            "largest_cell",
            "largest_mean_ut",
        ],
    )


_POINTS_AT = {
    (
        "magnitude",
        "time",
    ): "the field strength itself changes along the recording: a disturbance the sensor "
    "passed (iron, a magnet, a current) or an offset drifting with temperature",
    (
        "magnitude",
        "turn rate",
    ): "the error grows with the turn rate: a lag between the axes' samples, or "
    "filtering inside the sensor",
    (
        "magnitude",
        "orientation",
    ): "the strength depends on the direction beyond an ellipsoid: a magnet or "
    "iron close to the sensor, or a non-linear axis",
    (
        "magnitude",
        "acceleration",
    ): "the strength changes when the sensor is moved hard: something moving "
    "with the hand (a cable, a magnet) or a loose mount",
    (
        "dip",
        "acceleration",
    ): "the dip is wrong while the sensor accelerates: the accelerometer then measures "
    "more than gravity, so the reference direction (not the magnetometer) is off",
    (
        "dip",
        "turn rate",
    ): "the dip is wrong while the sensor turns: a lag between the magnetometer's and the "
    "accelerometer's samples, or acceleration of a sensor off the turn axis",
    (
        "dip",
        "time",
    ): "the angle between field and gravity changes along the recording: a disturbance the "
    "sensor passed, or the accelerometer's bias drifting",
    (
        "dip",
        "orientation",
    ): "the dip depends on the orientation: a misalignment or scale error of the "
    "accelerometer, which the magnetometer's model cannot take up",
}


def reading(table: pd.DataFrame) -> str:
    """One sentence: the factor with the largest share (if any holds more than :data:`CLEAR_SHARE`), its
    amplitude and largest cell, and what it points at."""
    if table.empty:
        return "no factor to break the residuals down by (no time, rate, accelerometer or field columns)"
    top = table.loc[table["share"].idxmax()]
    if top["share"] < CLEAR_SHARE:
        return (
            f"no single factor holds the residuals (largest: {top['factor']} of the {top['invariant']} "
            f"invariant, {100 * top['share']:.0f} % of its variance)"
        )
    return (
        f"{top['factor']} holds {100 * top['share']:.0f} % of the {top['invariant']} invariant's residual "
        f"variance (rms of the cell means {top['amplitude_ut']:.2g} uT; largest in {top['largest_cell']}, "
        f"{top['largest_mean_ut']:+.2g} uT): {_POINTS_AT[(top['invariant'], top['factor'])]}"
    )
