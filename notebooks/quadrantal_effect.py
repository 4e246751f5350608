"""A user effect for the workbench: a three-cycle ("quadrantal") heading error.

Load it with ``python -m navlib loop compass FILE.csv --model misalignment --effects quadrantal_effect.py``
or ``navlib.workbench.load_effects(path, "compass", catalogue)``.
"""
import numpy as np

from navlib.workbench.effects import Effect

quadrantal = Effect(
    "quadrantal", ("q3_sin_deg", "q3_cos_deg"), ("deg", "deg"),
    "A three-cycle heading error (three maxima per revolution), e.g. a sensor nonlinearity.",
    system="compass",
    contribution=lambda p, d: (p["q3_sin_deg"] * np.sin(np.radians(3 * d["true_heading_deg"].to_numpy(float)))
                               + p["q3_cos_deg"] * np.cos(np.radians(3 * d["true_heading_deg"].to_numpy(float)))))
