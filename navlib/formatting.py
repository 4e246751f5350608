"""Numbers for prose, tables and results files: one rounding, one way to show a missing value.

:func:`plain` turns numpy scalars into JSON-safe Python numbers (NaN becomes None) rounded to 6 significant
digits, so stored results compare within tolerance; :func:`fmt` formats a number for a sentence or a table
cell (NaN and None become an en dash).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .errors import InputError


def plain(value: Any, digits: int = 6) -> Any:
    """A JSON- and display-safe Python value: numpy scalars become Python numbers rounded to ``digits``
    significant digits, NaN becomes None; strings, bools and None pass through."""
    if value is None or isinstance(value, (str, bool)):
        return value
    if isinstance(value, (np.bool_,)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            return None
        return float(f"{v:.{digits}g}")
    raise InputError(f"cannot store a {type(value).__name__} as a result value")


def fmt(value: Any, spec: str = "{:.3g}") -> str:
    """Format a number for prose or a table cell; NaN/None become an en dash."""
    if value is None or (
        isinstance(value, (float, np.floating)) and not math.isfinite(float(value))
    ):
        return "–"
    if isinstance(value, (np.floating, np.integer)):
        value = value.item()
    return spec.format(value)
