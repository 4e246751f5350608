"""How far to trust the loop on your own set-up: the workbench's detection, false-alarm and
out-of-catalogue rates for one system at your noise level and effect sizes (``python -m navlib rates``).

Every rate is a share of independent simulated trials (each its own seed, a ``numpy.random.SeedSequence``
spawn key of the trial's coordinates: :func:`navlib.workbench.trials.trial_seed`) with its 95 % Wilson
interval (:func:`navlib.verdicts.wilson`, scipy's ``binomtest``):

- *detection*: data with every catalogued effect, one of them (the hidden one) left out of the model and
  scaled to ``ratio`` x the noise: the share of trials in which the loop names exactly that effect;
- *false alarms*: data from a random subset of the catalogue, fitted with exactly that subset: the share
  of trials in which anything other than "consistent with noise" is reported;
- *out of catalogue* (compass): an error no catalogued effect describes (three- and four-cycle heading
  errors, a step between sweeps, a drift in time) at ``ratio`` x the noise: the share in which no
  catalogued effect is named (quiet), and the share reported as not noise (detected).

The trials run on :mod:`navlib.engine` (``workers`` local processes or the cluster at ``scheduler``); the
rates do not depend on where they ran.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import verdicts
from ..errors import InputError, check_param
from . import accelerometer, free_simulation
from .effects import get_system
from .trials import TRIAL_SYSTEMS, hidden_effect_study, out_of_catalogue_study

#: Systems whose simulated data the rate trials draw.
RATE_SYSTEMS = TRIAL_SYSTEMS + ("accelerometer", "magnetometer_free")
#: Default noise (1 sigma, in the system's unit): the book's chapters' levels.
DEFAULT_NOISE = {
    "compass": 0.1,
    "drift": 1e-4,
    "magnetometer": 0.3,
    "accelerometer": 0.003,
    "magnetometer_free": 0.3,
}
#: Default effect sizes, as multiples of the noise.
DEFAULT_RATIOS = (3.0, 10.0)
#: Trials a command may ask for per case (a guard against a typo of a few zeros).
MAX_TRIALS = 100_000


@dataclass
class Rates:
    """The rates of one system: ``detection`` (hidden effect, size, noise), ``false_alarms`` (noise),
    ``out_of_catalogue`` (kind, size, noise; None for systems other than the compass); every rate with
    ``trials``, ``rate``, ``low``, ``high`` (95 % Wilson interval)."""

    system: str
    unit: str
    noises: tuple
    ratios: tuple
    trials: int
    null_trials: int
    detection: pd.DataFrame
    false_alarms: pd.DataFrame
    out_of_catalogue: pd.DataFrame | None

    def to_dict(self) -> dict:
        """Plain JSON-ready dictionary (the CLI's ``--json``)."""

        def records(df):
            return (
                None
                if df is None
                else [
                    {
                        str(k).replace(" ", "_"): (v.item() if isinstance(v, np.generic) else v)
                        for k, v in r.items()
                    }
                    for r in df.to_dict("records")
                ]
            )

        return {
            "system": self.system,
            "unit": self.unit,
            "noise": list(self.noises),
            "ratios": list(self.ratios),
            "trials_per_case": self.trials,
            "null_trials_per_noise": self.null_trials,
            "interval": "95 % Wilson (scipy.stats.binomtest)",
            "detection": records(self.detection),
            "false_alarms": records(self.false_alarms),
            "out_of_catalogue": records(self.out_of_catalogue),
        }

    def text(self) -> str:
        """The rates as plain-text tables."""
        fmt = {
            "noise": "{:g}".format,
            "ratio": "{:g}".format,
            "rate": "{:.3f}".format,
            "low": "{:.3f}".format,
            "high": "{:.3f}".format,
        }
        parts = [
            f"{self.system}: noise {', '.join(f'{n:g}' for n in self.noises)} {self.unit} (1 sigma); "
            f"effect sizes {', '.join(f'{r:g}' for r in self.ratios)} x noise; 95 % Wilson intervals",
            "",
            "hidden effect named (detection):",
            self.detection.to_string(index=False, formatters=fmt),
            "",
            "false alarms (nothing hidden; anything but 'consistent with noise'):",
            self.false_alarms.to_string(index=False, formatters=fmt),
        ]
        if self.out_of_catalogue is not None:
            f2 = dict(
                fmt,
                **{
                    c: "{:.3f}".format
                    for c in self.out_of_catalogue.columns
                    if c.endswith(("rate", "low", "high"))
                },
            )
            parts += [
                "",
                "errors outside the catalogue (quiet: no catalogued effect named; detected: not noise):",
                self.out_of_catalogue.to_string(index=False, formatters=f2),
            ]
        return "\n".join(parts)


def _rate(k: int, n: int) -> dict:
    e = verdicts.wilson(int(k), int(n))
    return {"rate": e.value, "low": e.lo, "high": e.hi}


def rates(
    system: str,
    trials: int = 20,
    noises=None,
    ratios=DEFAULT_RATIOS,
    null_trials: int | None = None,
    workers: int = 1,
    scheduler: str | None = None,
) -> Rates:
    """Detection, false-alarm and out-of-catalogue rates of the workbench for ``system``.

    Parameters
    ----------
    system : str
        ``compass``, ``drift``, ``magnetometer``, ``accelerometer`` or ``magnetometer_free``.
    trials : int
        Trials per (hidden effect, size, noise) and per (out-of-catalogue kind, size, noise).
    noises : sequence of float, optional
        Noise levels (1 sigma) in the system's unit (compass deg of heading, drift deg/h, magnetometer
        uT, accelerometer mg); default :data:`DEFAULT_NOISE`.
    ratios : sequence of float
        Effect sizes: RMS of the hidden (or out-of-catalogue) effect as a multiple of the noise.
    null_trials : int, optional
        Nothing-hidden trials per noise level (default ``2 * trials``).
    workers, scheduler
        Where the trials run (:mod:`navlib.engine`).

    Returns
    -------
    Rates
    """
    if system not in RATE_SYSTEMS:
        raise InputError(f"rates: unknown system {system!r}; known: {', '.join(RATE_SYSTEMS)}")
    check_param("trials", trials, lo=1, hi=MAX_TRIALS, integer=True)
    trials = int(trials)
    null_trials = 2 * trials if null_trials is None else null_trials
    check_param("null_trials", null_trials, lo=0, hi=MAX_TRIALS, integer=True)
    noises = (DEFAULT_NOISE[system],) if noises is None else tuple(float(v) for v in noises)
    ratios = tuple(float(v) for v in ratios)
    if not noises or not ratios:
        raise InputError("rates: give at least one noise level and one effect size")
    for v in noises:
        check_param("noise", v, lo=0, lo_open=True, hi=1e6)
    for v in ratios:
        check_param("ratio", v, lo=0, lo_open=True, hi=1e3)
    if len(set(noises)) != len(noises) or len(set(ratios)) != len(ratios):
        raise InputError("rates: a noise level or effect size is given twice")
    seeds, none_seeds = range(trials), range(int(null_trials))
    if system == "accelerometer":
        study = accelerometer.hidden_effect_study(
            ratios,
            tuple(1000.0 * v for v in noises),
            seeds,
            none_seeds,
            workers=workers,
            scheduler=scheduler,
        )
        study["noise"] = study.pop("noise_ug") / 1000.0
    elif system == "magnetometer_free":
        study = free_simulation.hidden_effect_study(
            ratios, noises, seeds, none_seeds, workers=workers, scheduler=scheduler
        )
    else:
        study = hidden_effect_study(
            system,
            ratios=ratios,
            noises=noises,
            seeds=seeds,
            none_seeds=none_seeds,
            workers=workers,
            scheduler=scheduler,
        )
    det, fa = [], []
    hidden = study[study.hidden != "(none)"]
    for (h, r, n), g in hidden.groupby(["hidden", "ratio", "noise"], sort=False):
        det.append(
            {
                "effect": h,
                "ratio": float(r),
                "noise": float(n),
                "trials": len(g),
                "named": int(g.correct.astype(bool).sum()),
                **_rate(g.correct.astype(bool).sum(), len(g)),
            }
        )
    for n, g in study[study.hidden == "(none)"].groupby("noise", sort=False):
        alarms = int((~g.correct.astype(bool)).sum())
        fa.append({"noise": float(n), "trials": len(g), "alarms": alarms, **_rate(alarms, len(g))})
    ooc = None
    if system == "compass":
        o = out_of_catalogue_study(
            ratios=ratios, noises=noises, seeds=seeds, workers=workers, scheduler=scheduler
        )
        rows = []
        for (kind, r, n), g in o.groupby(["kind", "ratio", "noise"], sort=False):
            q, d = _rate(g.quiet.sum(), len(g)), _rate(g.detected.sum(), len(g))
            rows.append(
                {
                    "kind": kind,
                    "ratio": float(r),
                    "noise": float(n),
                    "trials": len(g),
                    "quiet rate": q["rate"],
                    "quiet low": q["low"],
                    "quiet high": q["high"],
                    "detected rate": d["rate"],
                    "detected low": d["low"],
                    "detected high": d["high"],
                }
            )
        ooc = pd.DataFrame(rows)
    return Rates(
        system,
        get_system(system).unit,
        noises,
        ratios,
        trials,
        int(null_trials),
        pd.DataFrame(
            det, columns=["effect", "ratio", "noise", "trials", "named", "rate", "low", "high"]
        ),
        pd.DataFrame(fa, columns=["noise", "trials", "alarms", "rate", "low", "high"]),
        ooc,
    )
