"""Paper C's measured Tables 2-5 as the chapter reads them, their printed precision, and the error summaries.

- the tables: :func:`measured_tables` (loaders :mod:`navlib.data.gyro_tables`) with the display headers
  :data:`SHORT_HEADERS`;
- the printed text: :func:`printed_decimals` (a value printed with ``d`` decimals stands for every value within
  half a unit of its last digit) and :func:`temperature_spans`;
- the summaries every experiment uses: RMS, largest ``|error|``, a ``quantity -> value, unit`` table.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from navlib.data.gyro_tables import (
    TABLE_FILES,
    load_cold_test,
    load_cold_train,
    load_hot_test,
    load_hot_train,
)
from navlib.errors import InputError
from navlib.paths import data_path


# -------------------------------------------------------------------------------------------- measured tables
#: Short column headers (with units) for showing the measured tables in the book.
SHORT_HEADERS = {
    "sample": "sample",
    "test": "test",
    "latitude_deg": "latitude (deg)",
    "latitude_error_deg": "dL (deg)",
    "temperature_min_c": "T min (C)",
    "temperature_max_c": "T max (C)",
    "drift_deg_h": "drift (deg/h)",
    "paper_rbf_drift_deg_h": "paper RBF (deg/h)",
    "true_drift_deg_h": "true drift (deg/h)",
    "paper_error_deg_h": "paper error (deg/h)",
    "paper_pos_error_before_nmi_72h": "paper before (nmi)",
    "paper_pos_error_after_nmi_72h": "paper after (nmi)",
    "align_temp_min_c": "align T min (C)",
    "align_temp_max_c": "align T max (C)",
    "align_temp_change_c": "align dT (C)",
    "calib_temp_min_c": "calib T min (C)",
    "calib_temp_max_c": "calib T max (C)",
    "calib_temp_change_c": "calib dT (C)",
    "paper_hot_rbf_drift_deg_h": "paper hot RBF (deg/h)",
    "paper_pos_error_hot_net_nmi_72h": "paper, hot net (nmi)",
    "paper_pos_error_cold_net_nmi_72h": "paper, cold net (nmi)",
}


@dataclass(frozen=True)
class MeasuredTables:
    """Paper C's Tables 2-5 as loaded (``table2`` ... ``table5``, see ``data/gyro_tables.md``)."""

    table2: pd.DataFrame
    table3: pd.DataFrame
    table4: pd.DataFrame
    table5: pd.DataFrame

    def short_headers(self, number: int, derived: bool = False) -> pd.DataFrame:
        """Table ``number`` (2-5) with the short headers of :data:`SHORT_HEADERS` (for display); the
        loader's derived ``latitude_error_deg`` only if ``derived``."""
        if number not in (2, 3, 4, 5):
            raise InputError(
                f"parameter number={number!r}: paper C's measured tables are 2, 3, 4 and 5"
            )
        t = getattr(self, f"table{number}")
        if not derived:
            t = t.drop(columns=["latitude_error_deg"], errors="ignore")
        return t.rename(columns=SHORT_HEADERS)


def measured_tables() -> MeasuredTables:
    """Paper C's Tables 2-5, validated, with ``latitude_error_deg = latitude_deg - 28.222`` added.

    Source: paper C Tables 2-5 (real measurements), ``data/gyro_table*.csv``.

    Returns
    -------
    MeasuredTables
    """
    return MeasuredTables(load_hot_train(), load_hot_test(), load_cold_train(), load_cold_test())


def _hot_xy():
    t2, t3 = load_hot_train(), load_hot_test()
    return (
        t2["latitude_error_deg"].to_numpy(float),
        t2["drift_deg_h"].to_numpy(float),
        t3["latitude_error_deg"].to_numpy(float),
        t3["true_drift_deg_h"].to_numpy(float),
    )


# ----------------------------------------------------------------------------------------------- printed text
def _printed(table: int, column: str) -> list[str]:
    """The text of ``column`` of measured table ``table`` (2-5) as printed in ``data/`` (``0.0020`` stays
    ``0.0020``)."""
    if table not in TABLE_FILES:
        raise InputError(f"parameter table={table!r}: paper C's measured tables are 2, 3, 4 and 5")
    raw = pd.read_csv(data_path(TABLE_FILES[table]), dtype=str)
    if column not in raw:
        raise InputError(f"{TABLE_FILES[table]}: no column '{column}'")
    return [v.strip() for v in raw[column]]


def printed_decimals(table: int, column: str) -> np.ndarray:
    """How many decimals each row of a measured table prints in ``column``: the paper's printed precision.

    A value printed with ``d`` decimals stands for every value within half a unit of its last digit,
    ``0.5 * 10**-d``.  Read from the CSV text, so a printed trailing zero counts (``0.0020``: 4 decimals).

    Parameters
    ----------
    table : int
        2, 3, 4 or 5.
    column : str
        A column of that table's CSV file.

    Returns
    -------
    numpy.ndarray
        Decimals per row.
    """
    return np.array([len(v.split(".", 1)[1]) if "." in v else 0 for v in _printed(table, column)])


def temperature_spans(df: pd.DataFrame) -> np.ndarray:
    """Per row, the span of the printed temperature range, ``temperature_max_c - temperature_min_c`` (C)."""
    return df["temperature_max_c"].to_numpy(float) - df["temperature_min_c"].to_numpy(float)


# -------------------------------------------------------------------------------------------- error summaries
def _rms(e) -> float:
    return float(np.sqrt(np.mean(np.square(e))))


def _maxabs(e) -> float:
    return float(np.max(np.abs(e)))


def _quantities(rows) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=["quantity", "value", "unit"]).set_index("quantity")
