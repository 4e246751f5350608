"""The workbench chapter's comparison of ``navlib calibrate`` with a dedicated calibrator's fit
(navlib.studies.workbench.calibrations.calibration_beside_peer)."""

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from navlib.errors import InputError
from navlib.studies import workbench as wb


def test_held_out_errors_are_zero_for_a_perfect_calibration():
    q = Rotation.random(50, random_state=2)
    world = np.array([20.0, 1.0, 40.0])
    body = q.inv().apply(world)  # body frame readings of one world field
    ang, spread = wb.held_out_field_errors(body, q.as_quat()[:, [3, 0, 1, 2]])
    assert ang == pytest.approx(0.0, abs=1e-6) and spread == pytest.approx(0.0, abs=1e-9)


def test_the_summary_counts_what_the_table_says():
    acc = pd.DataFrame(
        {
            "raw direction (deg)": [1.0, 1.0, 2.0],
            "peer direction (deg)": [0.9, 3.0, np.nan],
            "navlib direction (deg)": [0.8, 4.0, np.nan],
            "peer": ["fitted", "fitted", "no ellipsoid"],
            "navlib": ["calibrated", "warned", "refused"],
        },
        index=["a", "b", "c"],
    )
    times = pd.DataFrame(
        {"navlib (s)": [1.0, 2.0, 0.5], "peer (s)": [0.01, 0.01, 0.01]}, index=acc.index
    )
    s = wb.PeerComparison(acc, times).summary()
    assert s == {
        "trials": 3,
        "calibrated": 2,
        "warned": 1,
        "peer_failed": 1,
        "refused": 1,
        "navlib_worse": 1,
        "navlib_worse_warned": 1,
        "peer_worse": 1,
        "time_ratio": 100.0,
    }


@pytest.mark.skipif(
    not wb.MAG_DIR.exists(), reason="BROAD 3-D recordings absent (../shared/realdata)"
)
def test_the_comparison_runs_on_a_real_recording():
    r = wb.calibration_beside_peer([wb.MAG_DIR / wb.CALIBRATION_TRIAL])
    a = r.accuracy.iloc[0]
    assert a["navlib"] == "calibrated" and a["peer"] == "fitted"
    assert a["navlib direction (deg)"] < a["raw direction (deg)"] + 0.5
    assert list(r.times.columns) == ["navlib (s)", "peer (s)"]
    with pytest.raises(InputError, match="train_share"):
        wb.calibration_beside_peer([wb.MAG_DIR / wb.CALIBRATION_TRIAL], train_share=1.5)
