"""Does the loop name the right effect? Simulated data with a hidden effect, and the detection and
false-alarm rates of :func:`navlib.workbench.diagnose.diagnose` over many trials."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .diagnose import diagnose
from .effects import CATALOGUES
from .fit import effect_rms, fit_model, simulate

def random_params(system: str, rng: np.random.Generator, effects) -> dict:
    """Plausible random parameters for the given effects (used to build data with hidden effects)."""
    p = {}
    for e in effects:
        if system == "compass":
            if e == "misalignment":
                p["yaw_deg"] = rng.uniform(-3, 3)
            elif e == "hard_iron":
                p["hard_x"], p["hard_y"] = rng.uniform(-0.3, 0.3, 2)
            elif e == "soft_iron":
                p["soft_e"], p["soft_f"] = rng.uniform(-0.08, 0.08, 2)
            elif e == "temperature":
                p["temp_x_per_c"], p["temp_y_per_c"] = rng.uniform(-0.004, 0.004, 2)
        else:
            if e == "earth_rate":
                p["earth_rate_gain"] = rng.uniform(0.8, 1.1)
            elif e == "bias":
                p["bias_deg_h"] = rng.uniform(-0.001, 0.001)
            elif e == "temperature":
                p["temperature_coef_deg_h_per_c"] = rng.uniform(-3e-5, 3e-5)
            elif e == "temperature_change":
                p["temperature_change_coef_deg_h_per_c"] = rng.uniform(-5e-5, 5e-5)
    return p


def scale_effect(system: str, data: pd.DataFrame, params: dict, effect: str, target_rms: float) -> dict:
    """Rescale ``effect``'s parameters so that its contribution has RMS ``target_rms`` on ``data``."""
    names = CATALOGUES[system][effect].params
    p = dict(params)
    for _ in range(3):                       # compass: nearly linear for small effects; iterate
        now = effect_rms(system, data, p, effect)
        if now == 0:
            break
        for k in names:
            p[k] = p[k] * target_rms / now
    return p


def hidden_effect_trial(system: str, hidden: str | None, ratio: float, noise: float, seed: int,
                        n: int | None = None) -> dict:
    """One trial: data from a random model, with ``hidden`` (or nothing) left out of the fitted model.

    With ``hidden`` set: the data contain every catalogue effect, ``hidden`` scaled so that its RMS is
    ``ratio * noise``; the model under test is the catalogue without ``hidden``.  With ``hidden=None`` the
    data contain a random subset of the effects and the model is exactly that subset."""
    cat = tuple(CATALOGUES[system])
    rng = np.random.default_rng(seed)
    if hidden is None:
        k = int(rng.integers(1, len(cat)))
        present = tuple(sorted(rng.choice(len(cat), size=k, replace=False)))
        present = tuple(cat[i] for i in present)
        params = random_params(system, rng, present)
        data = simulate(system, params, n=n, noise=noise, seed=rng)
        model = present
    else:
        params = random_params(system, rng, cat)
        probe = simulate(system, params, n=n, noise=0.0, seed=np.random.default_rng(seed))
        params = scale_effect(system, probe, params, hidden, ratio * noise)
        data = simulate(system, params, n=n, noise=noise, seed=np.random.default_rng(seed))
        model = tuple(e for e in cat if e != hidden)
    d = diagnose(fit_model(system, data, model))
    return {"system": system, "hidden": hidden or "(none)", "ratio": ratio if hidden else 0.0, "noise": noise,
            "n": len(data), "seed": seed, "named": d.missing or "(none)",
            "correct": (d.missing == hidden) if hidden else d.consistent_with_noise,
            "consistent_with_noise": d.consistent_with_noise}


def hidden_effect_study(system: str, ratios=(3.0, 10.0), noises=(0.1,), seeds=range(10), n=None,
                        include_none: bool = True, none_seeds=None) -> pd.DataFrame:
    """Detection and false-alarm trials over hidden effects, effect sizes, noise levels and seeds.
    Every (noise level, seed) pair draws its own data, so trials at different noise levels are
    independent; nothing-hidden trials use seeds of their own (default: twice as many as ``seeds``)."""
    rows = []
    seeds = list(seeds)
    none_seeds = list(none_seeds) if none_seeds is not None else list(range(2 * len(seeds)))
    for j, noise in enumerate(noises):
        for hidden in CATALOGUES[system]:
            for ratio in ratios:
                for seed in seeds:
                    rows.append(hidden_effect_trial(system, hidden, ratio, noise, 100_000 * j + seed, n))
        if include_none:
            for seed in none_seeds:
                rows.append(hidden_effect_trial(system, None, 0.0, noise, 100_000 * j + 50_000 + seed, n))
    return pd.DataFrame(rows)


def detection_rates(study: pd.DataFrame) -> pd.DataFrame:
    """Per hidden effect: trials and the share named correctly; for data with nothing hidden: trials and the
    share of false alarms (anything reported other than "consistent with noise"), with a 95 % Wilson
    interval for every rate."""
    def wilson(k, n, z=1.96):
        if n == 0:
            return (np.nan, np.nan)
        p = k / n
        c = (p + z * z / (2 * n)) / (1 + z * z / n)
        h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
        return (c - h, c + h)

    rows = []
    for h, g in study[study.hidden != "(none)"].groupby("hidden", sort=False):
        k = int(g.correct.sum())
        lo, hi = wilson(k, len(g))
        rows.append({"hidden effect": h, "rate": "correctly named", "trials": len(g), "value": k / len(g),
                     "95% low": lo, "95% high": hi})
    none = study[study.hidden == "(none)"]
    if len(none):
        k = int((~none.correct).sum())
        lo, hi = wilson(k, len(none))
        rows.append({"hidden effect": "(none)", "rate": "false alarms", "trials": len(none),
                     "value": k / len(none), "95% low": lo, "95% high": hi})
    return pd.DataFrame(rows).set_index("hidden effect")
