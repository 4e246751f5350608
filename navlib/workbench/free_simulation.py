"""Simulated recordings of the reference-free magnetometer (:mod:`navlib.workbench.magnetometer_free`) and
its hidden-effect trials: :func:`simulate_free` turns a magnetometer (and accelerometer) by hand through a
known distortion; :func:`hidden_effect_trial` and :func:`hidden_effect_study` hide one catalogued effect
in such recordings and ask whether the workbench's loop names it (the rates of :mod:`navlib.workbench.rates`).
"""

from __future__ import annotations


import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ..errors import InputError, check_param
from ..seeding import child
from .diagnose import diagnose
from .fit import fit_model
from .magnetometer import (
    GYR,
    MAG,
    simulate_hand_turned,
    body_from_nav,
)
from .serial import ar1_noise
from .trials import SYSTEM_KEYS, _seed_label, run_trials, trial_seed
from .magnetometer_free import (
    ACC,
    FREE_EFFECTS,
    G0,
    MIN_ORIENTATIONS,
    SYSTEM,
    check_orientations,
    correction_matrix,
    full_params,
    invariant_residuals,
    offset,
    with_invariants,
    SIM_FIELD_UT,
    SIM_DIP_DEG,
)


# ------------------------------------------------------------------------------------------- simulation
def simulate_free(
    params: dict,
    *,
    duration_s: float = 40.0,
    rate_hz: float = 10.0,
    noise_ut: float = 0.3,
    noise_correlation: float = 0.0,
    field_ut: float = SIM_FIELD_UT,
    dip_deg: float = SIM_DIP_DEG,
    acc_noise_ms2: float = 0.0,
    temperatures_c: tuple = (20.0, 35.0),
    seed=0,
) -> pd.DataFrame:
    """A magnetometer (and accelerometer) turned by hand without reference: the attitude of
    :func:`navlib.workbench.magnetometer.simulate_hand_turned`; the true field of intensity ``field_ut`` and
    dip ``dip_deg``; the sensor's raw field ``m = M^-1 R^T v + b + k (T - T_c)`` plus AR(1) noise (marginal
    ``noise_ut``, lag-1 ``noise_correlation``) with ``params`` as in the catalogue (absent = 0; ``R`` the
    misalignment); the specific force ``-g`` in body axes (plus white ``acc_noise_ms2``); the temperature
    rising linearly from ``temperatures_c[0]`` to ``[1]`` (``T_c`` their mean)."""
    check_param("field_ut", field_ut, lo=0, lo_open=True, hi=1e6)
    check_param("dip_deg", dip_deg, lo=-90, hi=90)
    check_param("noise_ut", noise_ut, lo=0)
    check_param("acc_noise_ms2", acc_noise_ms2, lo=0)
    rng = np.random.default_rng(seed)
    frame = simulate_hand_turned({}, duration_s=duration_s, rate_hz=rate_hz, noise_ut=0.0, seed=rng)
    n = len(frame)
    C = body_from_nav(frame)
    dip = np.radians(dip_deg)
    v = C @ (field_ut * np.array([np.cos(dip), 0.0, np.sin(dip)]))
    f = C @ np.array([0.0, 0.0, -G0])
    p = full_params(params)
    R = Rotation.from_rotvec(
        np.radians([p["mis_x_deg"], p["mis_y_deg"], p["mis_z_deg"]])
    ).as_matrix()
    t0, t1 = temperatures_c
    temp = np.linspace(t0, t1, n)
    frame["temperature_c"] = temp
    raw = (v @ R) @ np.linalg.inv(correction_matrix(p)).T + offset(p, frame, 0.5 * (t0 + t1))
    frame[list(MAG)] = raw + ar1_noise(rng, (n, 3), noise_ut, noise_correlation)
    frame[list(ACC)] = f + acc_noise_ms2 * rng.standard_normal((n, 3))
    keep = ["time_s", *GYR, *MAG, *ACC, "temperature_c"]
    return with_invariants(frame[keep])


#: Half-widths of the uniform draws of each effect's parameters in the trials.
PARAM_HALF = {
    "hard_iron": 10.0,
    "scale": 0.03,
    "soft_iron": 0.03,
    "misalignment": 2.0,
    "temperature": 0.1,
}


def effect_rms(
    data: pd.DataFrame,
    params: dict,
    effect: str,
    field_ut: float = SIM_FIELD_UT,
    dip_deg: float = SIM_DIP_DEG,
) -> float:
    """RMS (uT) of what ``effect`` does to the invariants' residual on the noiseless ``data``: the true
    parameters fitted with ``effect`` left out (its parameters at zero, field strength kept)."""
    p = {**params, "field_ut": field_ut, "field_down_ut": -field_ut * np.sin(np.radians(dip_deg))}
    t_c = float(data["temperature_c"].mean())
    without = {k: v for k, v in p.items() if k not in FREE_EFFECTS[effect].params}
    return float(
        np.sqrt(
            np.mean(
                (invariant_residuals(without, data, t_c) - invariant_residuals(p, data, t_c)) ** 2
            )
        )
    )


# ------------------------------------------------------------------------------------------------ trials
def hidden_effect_trial(
    hidden: str | None,
    ratio: float,
    noise_ut: float,
    seed,
    correlation: float = 0.0,
    duration_s: float = 40.0,
) -> dict:
    """One trial (as :func:`navlib.workbench.trials.hidden_effect_trial`): with ``hidden`` set the data
    hold every effect (uniform draws within :data:`PARAM_HALF`), ``hidden`` rescaled so that its
    :func:`effect_rms` is ``ratio`` x ``noise_ut``, and the model is the catalogue without it; with ``None``
    the data hold a random subset and the model is exactly that subset.  The parameters and the recording
    come from streams of their own (spawn children 0 and 1 of ``seed``), so the noise-free probe that
    scales the hidden effect sees the same motion as the data; a motion that does not turn the sensor
    through enough directions for the catalogue (the loader would refuse the file) is drawn again from
    child ``(1, k)``, k = 1, 2, ... (``redraws`` in the result)."""
    cat = tuple(FREE_EFFECTS)
    if hidden is not None and hidden not in cat:
        raise InputError(f"unknown magnetometer_free effect '{hidden}'; known: {', '.join(cat)}")
    if not isinstance(seed, np.random.SeedSequence):
        seed = np.random.SeedSequence(seed)
    rng = np.random.default_rng(child(seed, 0))
    if hidden is None:
        k = int(rng.integers(1, len(cat)))
        present = tuple(cat[i] for i in sorted(rng.choice(len(cat), size=k, replace=False)))
    else:
        present = cat
    base = {}
    for e in present:
        base.update(
            zip(
                FREE_EFFECTS[e].params,
                rng.uniform(-PARAM_HALF[e], PARAM_HALF[e], len(FREE_EFFECTS[e].params)),
            )
        )
    model = tuple(e for e in cat if e != hidden) if hidden is not None else present
    # the recording: the first hand-turned motion (stream child 1, then 1/1, 1/2, ...) whose data turn the
    # sensor through enough directions for the whole catalogue (:func:`check_orientations`; a file that
    # fails it is refused by the loader, so it is no trial of the tests)
    need = max(MIN_ORIENTATIONS, 2 + sum(len(e.params) for e in FREE_EFFECTS.values()))
    for redraw in range(20):
        stream = child(seed, 1) if redraw == 0 else child(seed, 1, redraw)

        def draw(p, noise):
            return simulate_free(
                p,
                duration_s=duration_s,
                noise_ut=noise,
                noise_correlation=correlation,
                seed=np.random.default_rng(stream),
            )

        params = dict(base)
        if hidden is not None:
            probe = draw(params, 0.0)
            for _ in range(3):
                now = effect_rms(probe, params, hidden)
                for q in FREE_EFFECTS[hidden].params:
                    params[q] *= ratio * noise_ut / now
        data = draw(params, noise_ut)
        try:
            check_orientations(data, "simulated", need)
            break
        except InputError:
            continue
    d = diagnose(fit_model(SYSTEM, data, model))
    return {
        "hidden": hidden or "(none)",
        "ratio": ratio if hidden else 0.0,
        "noise": noise_ut,
        "correlation": correlation,
        "seed": _seed_label(seed),
        "redraws": redraw,
        "named": d.missing or "(none)",
        "correct": (d.missing == hidden) if hidden else d.consistent_with_noise,
        "consistent_with_noise": d.consistent_with_noise,
    }


def hidden_effect_study(
    ratios=(3.0, 10.0),
    noises=(0.3,),
    seeds=range(10),
    none_seeds=None,
    correlation: float = 0.0,
    duration_s: float = 40.0,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Detection and false-alarm trials for the reference-free system over hidden effects, sizes, noise
    levels and seeds (nothing-hidden: twice as many seeds by default); each trial's seed is
    :func:`navlib.workbench.trials.trial_seed` of its coordinates (study "hidden effect", or "correlated
    noise" when ``correlation`` is not 0, then this system, the recording's length in s, noise level, effect,
    size, seed number)."""
    check_param("correlation", correlation, lo=-1, hi=1, lo_open=True, hi_open=True)
    seeds = list(seeds)
    none_seeds = list(none_seeds) if none_seeds is not None else list(range(2 * len(seeds)))
    study = "hidden effect" if correlation == 0 else "correlated noise"
    check_param("duration_s", duration_s, lo=3.0, hi=1e5)
    base = (SYSTEM_KEYS[SYSTEM.name], int(round(duration_s)))
    args = []
    for j, noise in enumerate(noises):
        args += [
            (
                h,
                r,
                float(noise),
                trial_seed(study, *base, j, i, k, s),
                correlation,
                float(duration_s),
            )
            for i, h in enumerate(FREE_EFFECTS, start=1)
            for k, r in enumerate(ratios)
            for s in seeds
        ]
        args += [
            (
                None,
                0.0,
                float(noise),
                trial_seed(study, *base, j, 0, 0, s),
                correlation,
                float(duration_s),
            )
            for s in none_seeds
        ]
    return pd.DataFrame(
        run_trials(hidden_effect_trial, args, workers, scheduler, "magnetometer_free trials")
    )
