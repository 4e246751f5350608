"""A user effect for the workbench: a three-cycle ("quadrantal") heading error.

Use it with ``python -m navlib loop compass FILE.csv --effects quadrantal_effect.py``
or ``navlib.workbench.load_effects(path, "compass", catalogue)``.
"""
import numpy as np

from navlib.workbench.effects import Effect


def three_cycle(p, data):
    """What the effect adds to the measured heading, deg."""
    h = np.radians(data["true_heading_deg"].to_numpy(float))
    return p["q3_sin_deg"] * np.sin(3 * h) + p["q3_cos_deg"] * np.cos(3 * h)


quadrantal = Effect("quadrantal", ("q3_sin_deg", "q3_cos_deg"), ("deg", "deg"),
                    "A three-cycle heading error (three maxima per revolution).",
                    system="compass", contribution=three_cycle)
