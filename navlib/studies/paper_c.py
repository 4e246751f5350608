"""Paper C (Yu et al. 2012): RBF identification of the axial gyro drift of a single-axis rotation INS.

Network inputs of the hot- and cold-state nets; the chapter's tables and figures are computed here.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import InputError
from ..methods.rbf import InputScaler

# ------------------------------------------------------------------------------------------ network inputs
LATITUDE_UNITS = {"deg": 1.0, "arcmin": 1 / 60.0, "arcsec": 1 / 3600.0}


def latitude_scaler(unit: str = "arcmin"):
    """Explicit input scaling of the hot-state network: latitude error (deg) expressed in ``unit``
    (``deg``, ``arcmin`` = nautical miles of latitude, or ``arcsec``), so SPREAD is measured in that unit."""
    if unit not in LATITUDE_UNITS:
        raise InputError(f"parameter INPUT_UNIT={unit!r}: must be one of {', '.join(LATITUDE_UNITS)}")
    return InputScaler.affine(0.0, LATITUDE_UNITS[unit], names=("latitude_error",), units=(unit,))


def cold_inputs(df: pd.DataFrame, temperature_change_column: str = "calib_temp_change_c") -> np.ndarray:
    """Cold-state network inputs (paper C 2.3: latitude error, temperature, temperature change) from a
    Table 4-like frame: ``[latitude_error_deg, calib_temp_max_c, <temperature_change_column>]``; the
    temperature is the one at the end of the alignment, when the drift is identified."""
    allowed = ("calib_temp_change_c", "align_temp_change_c")
    if temperature_change_column not in allowed:
        raise InputError(f"parameter COLD_DT_COLUMN={temperature_change_column!r}: must be one of "
                         f"{', '.join(allowed)}")
    return np.c_[df["latitude_error_deg"].to_numpy(float), df["calib_temp_max_c"].to_numpy(float),
                 df[temperature_change_column].to_numpy(float)]


