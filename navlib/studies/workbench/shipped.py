"""The loop on the measurements shipped in ``data/``: paper C's drift tables (Tables 2-4) and the
accelerometer tumble test.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...data.gyro_tables import drift_measurements
from ...data.tumble import TUMBLE_FILE
from ...workbench.accelerometer import load_accelerometer
from ...workbench.diagnose import diagnose
from ...workbench.fit import fit_model
from ...workbench.loop import LoopResult, loop


@dataclass
class DriftStudy:
    """Paper C's measured drift tables in the workbench: the hot fit, the diagnoses, the held-out table."""

    hot: pd.DataFrame
    cold: pd.DataFrame
    hot_fit: object
    hot_diagnosis: object
    diagnoses: dict  # "cold tests only" / "hot and cold tests" -> Diagnosis (earth_rate + bias)
    loo: pd.DataFrame  # held-out rms (1e-4 deg/h) of cold and hot tests per model
    temperature_change_coef: float
    loop: LoopResult | None = None  # the loop on every test (hot and cold) from no effect


def drift_study(alpha: float | None = None) -> DriftStudy:
    """The loop on paper C's Tables 2-4 (``data/gyro_drift_measurements.csv``): the Table 1 Earth-rate
    model fitted on the hot tests, diagnoses of the cold and pooled tests from ``earth_rate + bias``, the
    exact leave-one-out RMS of cold and hot tests as effects are added, and the whole loop on all tests
    from no effect (``loop``, drawn as a staircase by the chapter)."""
    allrows = drift_measurements()
    hot, cold = allrows[allrows.state == "hot"], allrows[allrows.state == "cold"]
    hot_fit = fit_model("drift", hot, ["earth_rate"])
    diags = {
        name: diagnose(fit_model("drift", frame, ["earth_rate", "bias"]), alpha=alpha)
        for name, frame in (("cold tests only", cold), ("hot and cold tests", allrows))
    }
    is_cold = allrows.state.to_numpy() == "cold"
    loo = {}
    for effects in (
        ["earth_rate"],
        ["earth_rate", "bias"],
        ["earth_rate", "bias", "temperature_change"],
    ):
        r = fit_model("drift", allrows, effects).loo_residuals
        loo[" + ".join(effects)] = {
            "cold tests, held-out rms (1e-4 deg/h)": np.sqrt(np.mean(r[is_cold] ** 2)) * 1e4,
            "hot tests, held-out rms (1e-4 deg/h)": np.sqrt(np.mean(r[~is_cold] ** 2)) * 1e4,
        }
    full = fit_model("drift", allrows, ["earth_rate", "bias", "temperature_change"])
    return DriftStudy(
        hot,
        cold,
        hot_fit,
        diagnose(hot_fit, alpha=alpha),
        diags,
        pd.DataFrame(loo).T,
        full.params["temperature_change_coef_deg_h_per_c"],
        loop("drift", allrows, [], alpha=alpha),
    )


def accelerometer_loop(unit: str = "A", start=("bias",), alpha: float | None = None) -> LoopResult:
    """The workbench loop on one accelerometer of the shipped tumble file ``data/accel_tumble.csv``
    (:func:`navlib.workbench.accelerometer.load_accelerometer` with ``unit``), from the model ``start``: what
    ``python -m navlib loop accelerometer FILE --unit A --model bias`` does."""
    return loop(
        "accelerometer", load_accelerometer(TUMBLE_FILE, unit=unit), list(start), alpha=alpha
    )
