"""The loop on a simulated compass: two sweeps with a catalogue effect hidden at a chosen size, an error
outside the catalogue added, and paper A's networks beside the physical model on the same sweeps.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...angles import wrap_deg
from ...errors import check_param
from ...workbench.effects import CATALOGUES
from ...workbench.fit import effect_rms, fit_model, simulate
from ...workbench.trials import random_params, scale_effect
from ..compass import Sweeps, compensate, error_stats, test_errors


def simulated_compass(
    hidden_effect: str, hidden_ratio: float, noise_deg: float, seed: int
) -> tuple[pd.DataFrame, float]:
    """Two simulated compass sweeps with every catalogue effect, ``hidden_effect`` scaled so that its RMS
    is ``hidden_ratio * noise_deg``.  Returns the data and the hidden effect's RMS (deg)."""
    check_param("hidden_ratio", hidden_ratio, lo=0)
    check_param("noise_deg", noise_deg, lo=0, lo_open=True)
    rng = np.random.default_rng(seed)
    params = random_params("compass", rng, CATALOGUES["compass"])
    probe = simulate("compass", params, noise=0.0)
    params = scale_effect("compass", probe, params, hidden_effect, hidden_ratio * noise_deg)
    data = simulate("compass", params, noise=noise_deg, seed=seed)
    return data, effect_rms("compass", probe, params, hidden_effect)


def with_three_cycle(
    data: pd.DataFrame, amplitude_deg: float, phase_deg: float = 30.0
) -> pd.DataFrame:
    """``data`` with a three-cycle heading error added (an effect outside the catalogue)."""
    out = data.copy()
    h = np.radians(out["true_heading_deg"].to_numpy(float))
    out["measured_heading_deg"] = np.mod(
        out["measured_heading_deg"] + amplitude_deg * np.sin(3 * h + np.radians(phase_deg)), 360.0
    )
    return out


def network_vs_physics(
    data: pd.DataFrame, effects, methods=("BP (LM)",), seed: int = 0
) -> pd.DataFrame:
    """Train on sweep 1, test on sweep 2 (paper A's protocol): each of paper A's networks (``methods``, run
    by the compass chapter's ``compensate``) sees only the measured heading; the physical model (``effects``
    fitted on sweep 1, with the temperature of each reading) is inverted on sweep 2.  Test error min, max,
    rms (deg) per compensation."""
    train = data[data.sweep == 1].reset_index(drop=True)
    test = data[data.sweep == 2].reset_index(drop=True)
    sw = Sweeps(train, test)
    rows = []
    for method in methods:
        corrected, _ = compensate(method, sw, seed=seed)
        rows.append({"compensation": method, **error_stats(test_errors(corrected, sw))})
    phys = fit_model("compass", train, list(effects)).model
    corrected = phys.correct(test.measured_heading_deg, test.temperature_c)
    rows.append(
        {
            "compensation": "physical model (" + " + ".join(effects) + ")",
            **error_stats(wrap_deg(corrected - test.true_heading_deg)),
        }
    )
    return (
        pd.DataFrame(rows)
        .set_index("compensation")
        .rename(columns={"min_deg": "min (deg)", "max_deg": "max (deg)", "rms_deg": "rms (deg)"})
    )
