"""Reading measurement tables (CSV) with validation that names the file, column and row of every fault.

A table is described by a list of :class:`Column` specs.  :func:`read_table` returns a float
``pandas.DataFrame`` holding the described columns (plus any extra columns untouched) or raises
:class:`navlib.errors.InputError` with a single line such as::

    sweep.csv: column 'true_heading_deg', row 7 (file line 8): 'abc' is not a number

Rows are counted from 1 over the data rows; the file line adds the header line.
"""
from __future__ import annotations

import difflib
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError


@dataclass(frozen=True)
class Column:
    """One column of a table: its name, unit (for messages and the data dictionary), whether it must be
    present, and an optional closed range ``[lo, hi]`` the values must lie in."""

    name: str
    unit: str = ""
    required: bool = True
    lo: float | None = None
    hi: float | None = None
    integer: bool = False


def where(path: str | os.PathLike, column: str, row: int) -> str:
    """The location prefix used in messages: ``file: column 'c', row r (file line r+1)``; ``row`` is
    0-based over data rows."""
    return f"{Path(path).name}: column '{column}', row {row + 1} (file line {row + 2})"


def read_table(path: str | os.PathLike, columns: list[Column], *, min_rows: int = 1,
               kind: str = "table") -> pd.DataFrame:
    """Read and validate a CSV table.

    Checks, in order: the file exists and parses as CSV; every required column is present (a near-miss
    name is suggested); every value in a described column is a finite number (no text, empty cell or NaN),
    whole if the column is ``integer``, and within the column's range; there are at least ``min_rows``
    rows.  Optional columns that are absent are simply not in the result.
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{p}: no such file")
    if p.is_dir():
        raise InputError(f"{p}: is a folder, expected a CSV {kind}")
    try:
        raw = pd.read_csv(p, dtype=str, keep_default_na=False, skipinitialspace=True)
    except pd.errors.EmptyDataError:
        raise InputError(f"{p.name}: file is empty, expected a CSV {kind} with a header line") from None
    except (pd.errors.ParserError, UnicodeDecodeError) as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise InputError(f"{p.name}: not a readable CSV {kind} ({first})") from None
    raw.columns = [str(c).strip() for c in raw.columns]
    dup = raw.columns[raw.columns.duplicated()].tolist()
    if dup:
        raise InputError(f"{p.name}: column '{dup[0]}' appears more than once in the header")
    present = list(raw.columns)
    for col in columns:
        if col.required and col.name not in present:
            near = difflib.get_close_matches(col.name, present, n=1, cutoff=0.6)
            hint = f"; did you mean to name '{near[0]}' '{col.name}'?" if near else ""
            raise InputError(f"{p.name}: missing column '{col.name}' ({col.unit or 'no unit'}); "
                             f"found {', '.join(present) if present else 'no columns'}{hint}")
    out = raw.copy()
    for col in columns:
        if col.name not in present:
            continue
        text = raw[col.name].str.strip()
        values = pd.to_numeric(text, errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            r = int(bad[0])
            cell = text.iloc[r]
            what = ("is empty" if cell == "" else
                    f"'{cell}' is not a finite number" if cell.lower() in {"nan", "inf", "-inf", "+inf"}
                    else f"'{cell}' is not a number")
            raise InputError(f"{where(p, col.name, r)}: {what}")
        if col.integer:
            frac = np.flatnonzero(values != np.round(values))
            if frac.size:
                r = int(frac[0])
                raise InputError(f"{where(p, col.name, r)}: {text.iloc[r]} is not a whole number")
        outside = np.zeros(values.shape, bool)
        if col.lo is not None:
            outside |= values < col.lo
        if col.hi is not None:
            outside |= values > col.hi
        if outside.any():
            r = int(np.flatnonzero(outside)[0])
            rng = f"{'' if col.lo is None else f'{col.lo:g}'}..{'' if col.hi is None else f'{col.hi:g}'}"
            unit = f" {col.unit}" if col.unit else ""
            raise InputError(f"{where(p, col.name, r)}: {text.iloc[r]} is outside {rng}{unit}")
        out[col.name] = values
    if len(out) < min_rows:
        raise InputError(f"{p.name}: {len(out)} data row{'s' if len(out) != 1 else ''}, "
                         f"a {kind} needs at least {min_rows}")
    return out


def write_new_csv(frame: pd.DataFrame, path: str | os.PathLike, *, overwrite: bool = False,
                  float_format: str = "%.10g") -> Path:
    """Write ``frame`` to ``path`` but never replace an existing file unless ``overwrite`` is set:
    user data and earlier outputs are not overwritten by accident."""
    p = Path(path)
    if p.exists() and not overwrite:
        raise InputError(f"{p}: already exists; not overwritten (choose another name or pass overwrite)")
    p.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(p, index=False, float_format=float_format)
    return p
