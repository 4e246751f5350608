"""Does the loop name the right effect? Simulated data with a hidden effect, and the detection and
false-alarm rates of :func:`navlib.workbench.diagnose.diagnose` over many trials; data with an effect
*outside* the catalogue (three- and four-cycle heading errors, a step between sweeps, a drift in time),
where the right answer names no catalogued effect and says the residuals are not noise; and the same
hidden-effect trials on time series with serially correlated (AR(1)) noise: compass sweeps read every 5 s
and magnetometers turned by hand and sampled at 10 Hz
(:func:`navlib.workbench.magnetometer.simulate_hand_turned`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import engine, verdicts
from ..errors import InputError, check_param
from ..methods.seeding import child, sequence
from .diagnose import diagnose
from .effects import CATALOGUES, get_system
from .fit import effect_rms, fit_model, simulate
from .magnetometer import effect_rms as magnetometer_effect_rms, simulate_hand_turned

#: Entropy of every trial study's seeds: a trial's seed is ``SeedSequence(TRIAL_ENTROPY, spawn_key=...)``
#: with the trial's coordinates in its study as the spawn key (:func:`trial_seed`), so no two trials of a
#: study share a draw and the rates' Wilson intervals rest on independent trials.
TRIAL_ENTROPY = 0
#: First element of the spawn key: which study the trial belongs to.
STUDY_KEYS = {"hidden effect": 1, "out of catalogue": 2, "correlated noise": 3}
SYSTEM_KEYS = {
    "compass": 0,
    "drift": 1,
    "magnetometer": 2,
    "accelerometer": 3,
    "magnetometer_free": 4,
}
#: The systems whose simulated data the hidden-effect trials can draw.
TRIAL_SYSTEMS = ("compass", "drift", "magnetometer")
#: Length of a simulated hand-turned magnetometer recording (s, at 10 Hz) in the trials.
MAG_DURATION_S = 40.0


def trial_seed(study: str, *coords: int) -> np.random.SeedSequence:
    """The seed of one trial: a ``numpy.random.SeedSequence`` whose spawn key is the study
    (``STUDY_KEYS``) and the trial's coordinates in it (whole numbers >= 0, e.g. the indices of its
    noise level, hidden effect, effect size and its seed number): different coordinates give independent
    streams, with no arithmetic that could make two trials collide."""
    if study not in STUDY_KEYS:
        raise InputError(f"trial_seed: unknown study {study!r}; known: {', '.join(STUDY_KEYS)}")
    key = tuple(int(c) for c in coords)
    if any(c < 0 for c in key):
        raise InputError(f"trial_seed: coordinates must be whole numbers >= 0, got {coords!r}")
    return sequence(TRIAL_ENTROPY, STUDY_KEYS[study], *key)


def _seed_label(seed):
    """How a trial's seed is stored in a study's table: a SeedSequence's spawn key as text ("1/0/16/..."),
    an integer seed as itself."""
    return "/".join(map(str, seed.spawn_key)) if isinstance(seed, np.random.SeedSequence) else seed


def catalogue(system: str):
    """The catalogue of a system the trials simulate (:data:`TRIAL_SYSTEMS`)."""
    if system not in TRIAL_SYSTEMS:
        raise InputError(f"trials: unknown system {system!r}; known: {', '.join(TRIAL_SYSTEMS)}")
    return CATALOGUES.get(system) or get_system(system).catalogue


def random_params(system: str, rng: np.random.Generator, effects) -> dict:
    """Plausible random parameters for the given effects (used to build data with hidden effects);
    magnetometer: hard iron within +-10 uT per axis, soft iron +-0.03, misalignment +-2 deg per axis, a time
    lag within +-30 ms."""
    p = {}
    for e in effects:
        if system == "magnetometer":
            names = catalogue("magnetometer")[e].params
            half = {"hard_iron": 10.0, "soft_iron": 0.03, "misalignment": 2.0, "time_lag": 0.03}[e]
            p.update(zip(names, rng.uniform(-half, half, len(names))))
        elif system == "compass":
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


def scale_effect(
    system: str, data: pd.DataFrame, params: dict, effect: str, target_rms: float
) -> dict:
    """Rescale ``effect``'s parameters so that its contribution has RMS ``target_rms`` on ``data``."""
    names = catalogue(system)[effect].params
    p = dict(params)
    for _ in range(3):  # compass: nearly linear for small effects; iterate
        now = (
            magnetometer_effect_rms(data, p, effect)
            if system == "magnetometer"
            else effect_rms(system, data, p, effect)
        )
        if now == 0:
            break
        for k in names:
            p[k] = p[k] * target_rms / now
    return p


def _simulate(
    system: str, params: dict, n: int | None, noise: float, correlation: float, seed
) -> pd.DataFrame:
    """Simulated data of a trial: :func:`navlib.workbench.fit.simulate` (compass, drift; ``n`` rows of a
    drift table) or a hand-turned magnetometer recording of :data:`MAG_DURATION_S` s (``n`` = its length
    in s when given), with AR(1) noise of lag-1 correlation ``correlation``."""
    if system == "magnetometer":
        return simulate_hand_turned(
            params,
            duration_s=MAG_DURATION_S if n is None else float(n),
            noise_ut=noise,
            noise_correlation=correlation,
            seed=seed,
        )
    return simulate(system, params, n=n, noise=noise, seed=seed, noise_correlation=correlation)


def hidden_effect_trial(
    system: str,
    hidden: str | None,
    ratio: float,
    noise: float,
    seed: int | np.random.SeedSequence,
    n: int | None = None,
    correlation: float = 0.0,
) -> dict:
    """One trial: data from a random model, with ``hidden`` (or nothing) left out of the fitted model.

    With ``hidden`` set: the data contain every catalogue effect, ``hidden`` scaled so that its RMS is
    ``ratio * noise``; the model under test is the catalogue without ``hidden``.  With ``hidden=None`` the
    data contain a random subset of the effects and the model is exactly that subset.  ``correlation``:
    lag-1 correlation of AR(1) noise along the time series (compass, magnetometer; ``noise`` is its marginal
    standard deviation)."""
    cat = tuple(catalogue(system))
    rng = np.random.default_rng(seed)
    if hidden is None:
        k = int(rng.integers(1, len(cat)))
        present = tuple(sorted(rng.choice(len(cat), size=k, replace=False)))
        present = tuple(cat[i] for i in present)
        params = random_params(system, rng, present)
        data = _simulate(system, params, n, noise, correlation, rng)
        model = present
    else:
        # parameters and data from streams of their own (child 0, child 1): the noise-free probe that scales
        # the hidden effect sees the same rows (the same hand-turned motion) as the data
        params = random_params(system, np.random.default_rng(child(seed, 0)), cat)
        probe = _simulate(
            system, params, n, 0.0, correlation, np.random.default_rng(child(seed, 1))
        )
        params = scale_effect(system, probe, params, hidden, ratio * noise)
        data = _simulate(
            system, params, n, noise, correlation, np.random.default_rng(child(seed, 1))
        )
        model = tuple(e for e in cat if e != hidden)
    d = diagnose(fit_model(system, data, model))
    return {
        "system": system,
        "hidden": hidden or "(none)",
        "ratio": ratio if hidden else 0.0,
        "noise": noise,
        "correlation": correlation,
        "n": len(data),
        "seed": _seed_label(seed),
        "named": d.missing or "(none)",
        "correct": (d.missing == hidden) if hidden else d.consistent_with_noise,
        "consistent_with_noise": d.consistent_with_noise,
        "ar_order": d.screening.noise.order,
        "lag1": d.screening.noise.lag1,
    }


#: Trials per engine task (fixed, so the batches never depend on the number of workers).
TRIAL_BATCH = 8


def run_trials(
    fn, args: list, workers: int = 1, scheduler: str | None = None, label: str = "trials"
) -> list:
    """``[fn(*a) for a in args]`` on :mod:`navlib.engine` (``workers`` local processes, or the cluster at
    ``scheduler``), in batches of :data:`TRIAL_BATCH` trials; every trial carries its own seed, so the
    results do not depend on where they ran."""
    return engine.run_batches(
        fn, args, TRIAL_BATCH, workers=workers, scheduler=scheduler, label=label
    )


def hidden_effect_study(
    system: str,
    ratios=(3.0, 10.0),
    noises=(0.1,),
    seeds=range(10),
    n=None,
    include_none: bool = True,
    none_seeds=None,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Detection and false-alarm trials over hidden effects, effect sizes, noise levels and seeds.

    Every trial draws its own data: its seed is :func:`trial_seed` of its coordinates (system, table size
    ``n``, noise level, hidden effect, effect size, seed number), so trials of different hidden effects,
    sizes, noise levels and table sizes are independent; nothing-hidden trials have coordinates of their
    own (default: twice as many seeds as ``seeds``).  ``workers``, ``scheduler``: where the trials run
    (:func:`run_trials`)."""
    args = []
    seeds = list(seeds)
    none_seeds = list(none_seeds) if none_seeds is not None else list(range(2 * len(seeds)))
    base = (SYSTEM_KEYS[system], 0 if n is None else int(n))
    for j, noise in enumerate(noises):
        for h, hidden in enumerate(CATALOGUES[system], start=1):
            for r, ratio in enumerate(ratios):
                for seed in seeds:
                    args.append(
                        (
                            system,
                            hidden,
                            ratio,
                            noise,
                            trial_seed("hidden effect", *base, j, h, r, seed),
                            n,
                        )
                    )
        if include_none:
            for seed in none_seeds:
                args.append(
                    (system, None, 0.0, noise, trial_seed("hidden effect", *base, j, 0, 0, seed), n)
                )
    return pd.DataFrame(
        run_trials(hidden_effect_trial, args, workers, scheduler, "hidden-effect trials")
    )


#: Compass errors outside the catalogue (name -> shape of unit RMS before scaling, from (data, rng)).
OUT_OF_CATALOGUE = {
    "three-cycle error": lambda d, rng: np.sin(
        3 * np.radians(d.true_heading_deg.to_numpy()) + rng.uniform(0, 2 * np.pi)
    ),
    "four-cycle error": lambda d, rng: np.sin(
        4 * np.radians(d.true_heading_deg.to_numpy()) + rng.uniform(0, 2 * np.pi)
    ),
    "step between sweeps": lambda d, rng: (
        (d.sweep.to_numpy() == 2).astype(float) * rng.choice([-1.0, 1.0])
    ),
    "drift in time": lambda d, rng: d.time_s.to_numpy() / d.time_s.max() * rng.choice([-1.0, 1.0]),
}


def out_of_catalogue_trial(
    kind: str, ratio: float, noise: float, seed: int | np.random.SeedSequence
) -> dict:
    """One trial: compass sweeps from a random subset of the catalogue plus an error of kind ``kind``
    (:data:`OUT_OF_CATALOGUE`) whose RMS about its mean is ``ratio * noise``; the model is exactly the
    catalogued effects present, plus misalignment (every model has a heading offset, which also takes the
    added error's mean).  ``quiet`` = no catalogued effect named; ``detected`` = reported as not noise."""
    if kind not in OUT_OF_CATALOGUE:
        raise InputError(
            f"unknown out-of-catalogue error {kind!r}; known: {', '.join(OUT_OF_CATALOGUE)}"
        )
    cat = tuple(CATALOGUES["compass"])
    rng = np.random.default_rng(seed)
    k = int(rng.integers(1, len(cat)))
    present = tuple(cat[i] for i in sorted(rng.choice(len(cat), size=k, replace=False)))
    params = random_params("compass", rng, present)
    data = simulate("compass", params, noise=noise, seed=rng)
    shape = OUT_OF_CATALOGUE[kind](data, rng)
    shape = shape - shape.mean()
    extra = ratio * noise * shape / np.sqrt(np.mean(shape**2))
    data["measured_heading_deg"] = np.mod(data["measured_heading_deg"] + extra, 360.0)
    model = tuple(e for e in cat if e in present or e == "misalignment")
    d = diagnose(fit_model("compass", data, model))
    return {
        "kind": kind,
        "ratio": ratio,
        "noise": noise,
        "seed": _seed_label(seed),
        "model": " + ".join(model),
        "named": d.missing or "(none)",
        "quiet": d.missing is None,
        "detected": not d.consistent_with_noise,
    }


def out_of_catalogue_study(
    ratios=(5.0, 8.0),
    noises=(0.05, 0.2),
    seeds=range(10),
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """:func:`out_of_catalogue_trial` over every kind, size, noise level and seed; each trial's seed is
    :func:`trial_seed` of its coordinates (kind, noise level, size, seed number): independent draws.
    ``workers``, ``scheduler``: where the trials run (:func:`run_trials`)."""
    args = []
    for j, noise in enumerate(noises):
        for i, kind in enumerate(OUT_OF_CATALOGUE):
            for r, ratio in enumerate(ratios):
                for seed in seeds:
                    args.append((kind, ratio, noise, trial_seed("out of catalogue", i, j, r, seed)))
    return pd.DataFrame(
        run_trials(out_of_catalogue_trial, args, workers, scheduler, "out-of-catalogue trials")
    )


def correlated_noise_study(
    system: str,
    correlations=(0.0, 0.9),
    ratio: float = 3.0,
    noise: float | None = None,
    seeds=range(100),
    none_seeds=None,
    n: int | None = None,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Hidden-effect and nothing-hidden trials (:func:`hidden_effect_trial`) on time series with AR(1)
    noise of each lag-1 correlation in ``correlations``: every catalogued effect hidden at ``ratio`` x the
    noise, ``seeds`` trials each; nothing hidden, ``none_seeds`` trials (default: as many as ``seeds``).
    ``noise``: marginal standard deviation (default 0.3 uT for the magnetometer, as BROAD's residuals;
    0.1 deg for the compass).  Seeds: :func:`trial_seed` of the study "correlated noise" and the trial's
    coordinates (system, correlation, hidden effect, seed number).  ``workers``, ``scheduler``: where the
    trials run (:func:`run_trials`)."""
    if system not in ("compass", "magnetometer"):
        raise InputError(
            f"correlated_noise_study: system {system!r} is no time series; use compass or magnetometer"
        )
    check_param("ratio", ratio, lo=0, lo_open=True)
    noise = {"magnetometer": 0.3, "compass": 0.1}[system] if noise is None else noise
    check_param("noise", noise, lo=0, lo_open=True)
    seeds = list(seeds)
    none_seeds = list(none_seeds) if none_seeds is not None else seeds
    args = []
    for j, rho in enumerate(correlations):
        check_param("correlations", rho, lo=0, hi=1, hi_open=True)
        for h, hidden in enumerate(catalogue(system), start=1):
            for seed in seeds:
                args.append(
                    (
                        system,
                        hidden,
                        ratio,
                        noise,
                        trial_seed("correlated noise", SYSTEM_KEYS[system], j, h, seed),
                        n,
                        rho,
                    )
                )
        for seed in none_seeds:
            args.append(
                (
                    system,
                    None,
                    0.0,
                    noise,
                    trial_seed("correlated noise", SYSTEM_KEYS[system], j, 0, seed),
                    n,
                    rho,
                )
            )
    return pd.DataFrame(
        run_trials(hidden_effect_trial, args, workers, scheduler, "correlated-noise trials")
    )


def correlated_noise_rates(study: pd.DataFrame) -> pd.DataFrame:
    """Per noise correlation and hidden effect: trials, the share named correctly; nothing hidden: the
    share ending "consistent with noise"; each with its 95 % Wilson interval (:func:`navlib.verdicts.wilson`)."""
    rows = []
    for (rho, hidden), g in study.groupby(["correlation", "hidden"], sort=False):
        k = int(g.correct.astype(bool).sum())
        e = verdicts.wilson(k, len(g))
        rows.append(
            {
                "noise correlation": rho,
                "hidden effect": hidden,
                "rate": "consistent with noise" if hidden == "(none)" else "correctly named",
                "trials": len(g),
                "value": e.value,
                "95% low": e.lo,
                "95% high": e.hi,
            }
        )
    return pd.DataFrame(rows).set_index(["noise correlation", "hidden effect"])


def wilson(k: int, n: int) -> tuple[float, float]:
    """95 % Wilson score interval ``(low, high)`` of a rate k/n (:func:`navlib.verdicts.wilson`, the
    interval the book's verdicts use); NaNs for no trials."""
    if n == 0:
        return (np.nan, np.nan)
    e = verdicts.wilson(int(k), int(n))
    return (e.lo, e.hi)


def out_of_catalogue_rates(study: pd.DataFrame) -> pd.DataFrame:
    """Per kind: trials, the share where no catalogued effect was named (quiet), and the share reported as
    not noise (detected), with 95 % Wilson intervals; the last row pools every kind."""
    rows = []
    for kind, g in list(study.groupby("kind", sort=False)) + [("all kinds", study)]:
        q, det = int(g.quiet.sum()), int(g.detected.sum())
        (ql, qh), (dl, dh) = wilson(q, len(g)), wilson(det, len(g))
        rows.append(
            {
                "error outside the catalogue": kind,
                "trials": len(g),
                "no catalogued effect named": q / len(g),
                "95% low": ql,
                "95% high": qh,
                "reported as not noise": det / len(g),
                "95% low ": dl,
                "95% high ": dh,
            }
        )
    return pd.DataFrame(rows).set_index("error outside the catalogue")


def detection_rates(study: pd.DataFrame) -> pd.DataFrame:
    """Per hidden effect: trials and the share named correctly; for data with nothing hidden: trials and the
    share of false alarms (anything reported other than "consistent with noise"), with a 95 % Wilson
    interval for every rate."""
    rows = []
    for h, g in study[study.hidden != "(none)"].groupby("hidden", sort=False):
        k = int(g.correct.sum())
        lo, hi = wilson(k, len(g))
        rows.append(
            {
                "hidden effect": h,
                "rate": "correctly named",
                "trials": len(g),
                "value": k / len(g),
                "95% low": lo,
                "95% high": hi,
            }
        )
    none = study[study.hidden == "(none)"]
    if len(none):
        k = int((~none.correct).sum())
        lo, hi = wilson(k, len(none))
        rows.append(
            {
                "hidden effect": "(none)",
                "rate": "false alarms",
                "trials": len(none),
                "value": k / len(none),
                "95% low": lo,
                "95% high": hi,
            }
        )
    return pd.DataFrame(rows).set_index("hidden effect")
