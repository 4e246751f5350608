"""The accelerometer as a workbench system (paper D's tumble tests): IEEE Std 1293 effects, linear in their
parameters, fitted to tumble files (:mod:`navlib.data.tumble`).

Measurement: ``output_mg`` (output divided by the nominal scale factor) of one accelerometer on a dividing
head, ``a = cos q`` along the input axis and ``a_p = sin q`` across it (g), ``dT = T - T_c`` with ``T_c`` the
mean temperature of the data.  The model is the nominal ``1000 a`` plus the effects::

    bias                         k0                                  mg
    scale_factor                 k1 a                                mg/g
    bias_temperature             b1 dT + b2 dT^2                     mg/degC, mg/degC^2
    scale_factor_temperature     (s1 dT + s2 dT^2) a                 mg/g/degC, mg/g/degC^2
    second_order                 k2 a^2                              mg/g^2
    second_order_temperature     k2t dT a^2                          mg/g^2/degC
    cross_coupling               kip a a_p                           mg/g^2
    misalignment                 delta_o a_p                         mg/g (= mrad)

residual = measured - model, mg.  Products of small terms (scale-factor error times K2 ...) are below a
microgravity for the sensors of paper D and are left out, so every fit is one linear least-squares solve.
Structure tests: a third harmonic in position (a ``K3 a^3`` term or a dividing-head error), a cubic in
temperature, and a position-dependent temperature step (thermal lag during the tumble).
"""

from __future__ import annotations

import os

import numpy as np
import pandas as pd

from ..data.tables import require_variation
from ..data.tumble import COLUMNS as TUMBLE_COLUMNS, read_tumble, require_levels
from ..errors import InputError
from .effects import Effect, System, register_system
from .fit import MEASURED, Fit, fit_linear, fit_model, user_columns
from .loop import known_noise_band, loop
from .diagnose import diagnose
from .trials import SYSTEM_KEYS, _seed_label, run_trials, trial_seed, wilson

ACCELEROMETER_EFFECTS = {
    "bias": Effect(
        "bias",
        ("k0_mg",),
        ("mg",),
        "Output at zero input (pick-off null, servo offset): a constant offset in every position.",
    ),
    "scale_factor": Effect(
        "scale_factor",
        ("k1_mg_g",),
        ("mg/g",),
        "Scale-factor error (magnet, coil, readout resistor): an error proportional to "
        "the input a = cos q, i.e. a one-cycle cosine in position.",
    ),
    "bias_temperature": Effect(
        "bias_temperature",
        ("bias_t1_mg_c", "bias_t2_mg_c2"),
        ("mg/degC", "mg/degC^2"),
        "Bias drift with temperature (head deformation, pick-off and capacitance "
        "gain, gap change): an offset that follows T (needs 3 temperatures).",
        columns=("temperature_c",),
    ),
    "scale_factor_temperature": Effect(
        "scale_factor_temperature",
        ("sf_t1_mg_g_c", "sf_t2_mg_g_c2"),
        ("mg/g/degC", "mg/g/degC^2"),
        "Scale-factor drift with temperature (magnet and coil temperature "
        "coefficients): a cos q error whose size follows T (needs 3 "
        "temperatures).",
        columns=("temperature_c",),
    ),
    "second_order": Effect(
        "second_order",
        ("k2_mg_g2",),
        ("mg/g^2",),
        "Second-order nonlinearity K2 a^2: a two-cycle cosine in position plus an offset.",
    ),
    "second_order_temperature": Effect(
        "second_order_temperature",
        ("k2_t_mg_g2_c",),
        ("mg/g^2/degC",),
        "K2 changing with temperature: the two-cycle error grows with T; makes "
        "the apparent scale factor depend on the input (paper D, Fig 4).",
        columns=("temperature_c",),
    ),
    "cross_coupling": Effect(
        "cross_coupling",
        ("kip_mg_g2",),
        ("mg/g^2",),
        "Cross-coupling Kip a a_p between input and pendulum axes: a two-cycle sine.",
    ),
    "misalignment": Effect(
        "misalignment",
        ("delta_o_mg",),
        ("mg/g",),
        "Input-axis misalignment about the output axis (mrad): a one-cycle sine, the "
        "pendulum-axis acceleration leaking in.",
    ),
}


#: The output must change by 1000 mg per g of input within this factor (paper D's units: 1001.7 and
#: 1002.2 mg/g); outside it the output is in another unit or the input axis is reversed.
SCALE_BAND = (0.5, 2.0)
#: Units an output may have been written in by mistake, with the factor that converts them to mg.
OUTPUT_UNITS = (
    ("g", 1000.0),
    ("m/s^2", 1000.0 / 9.80665),
    ("ft/s^2", 1000.0 / 32.174),
    ("ug", 1e-3),
)


def output_slope(df: pd.DataFrame) -> float:
    """Least-squares slope (mg/g) of ``output_mg`` against the input ``a = cos q``, with a constant; rows
    farther than 5 median absolute residuals from the line are set aside and the line refitted (up to four
    times, never more than half of the rows), so that a few spikes do not pass for a unit."""
    a = np.cos(np.deg2rad(df["position_deg"].to_numpy(float)))
    y = df["output_mg"].to_numpy(float)
    keep = np.ones(len(y), bool)
    for _ in range(4):
        coef = np.polyfit(a[keep], y[keep], 1)
        e = np.abs(y - np.polyval(coef, a))
        inside = e <= 5.0 * np.median(e[keep])
        if np.array_equal(inside, keep) or inside.sum() < max(len(y) // 2, 3):
            break
        keep = inside
    return float(coef[0])


def load_accelerometer(path: str | os.PathLike, unit: str | None = None) -> pd.DataFrame:
    """A tumble file of ONE accelerometer (:func:`navlib.data.tumble.read_tumble`: temperature -60..130
    degC, position on the 15-deg grid, output within +-5000 mg; at least 5 positions), or the rows of the
    accelerometer ``unit`` (the ``unit`` column) of a file that holds several, with plausibility
    checks of the output: it must vary (a stuck sensor), and its slope against the input ``a = cos q``
    (:func:`output_slope`) must be 1000 mg/g within a factor of 2 (``SCALE_BAND``): a slope near 1 names g, near 9.8
    m/s^2, near 31 ft/s^2, a negative one a reversed input axis."""
    df = read_tumble(path)
    name = os.path.basename(str(path))
    units = list(dict.fromkeys(df["unit"]))
    if unit is not None:
        if str(unit) not in units:
            raise InputError(
                f"{name}: no rows of unit {str(unit)!r} in column 'unit' (it names "
                f"{', '.join(units)})"
            )
        df = df[df["unit"] == str(unit)].reset_index(drop=True)
    elif len(units) != 1:
        raise InputError(
            f"{name}: column 'unit' names {len(units)} accelerometers "
            f"({', '.join(units)}); the workbench fits one: choose it with --unit "
            f"(python: unit=...)"
        )
    require_levels(df, positions=5, what="the accelerometer model", name=name)
    require_variation(df, ["output_mg"], path, "a tumble test")
    slope = output_slope(df)
    lo, hi = SCALE_BAND
    if not lo * 1000.0 <= slope <= hi * 1000.0:
        if slope < 0:
            look = (
                "the output falls as the input rises: the input axis is reversed, or position_deg "
                "counts the other way (the input is a = cos q)"
            )
        else:
            near = [(u, f) for u, f in OUTPUT_UNITS if lo * 1000.0 <= slope * f <= hi * 1000.0]
            look = (
                f"the output looks like {near[0][0]} (multiply by {near[0][1]:.6g} for mg)"
                if near
                else "the output is not in mg (output divided by the nominal scale factor)"
            )
        raise InputError(
            f"{name}: column 'output_mg' changes by {slope:.4g} mg per g of input, where 1000 "
            f"is expected ({lo * 1000:g}..{hi * 1000:g} accepted): {look}"
        )
    return df


def _columns(data: pd.DataFrame, name: str, t_c: float) -> list[np.ndarray]:
    q = np.deg2rad(data["position_deg"].to_numpy(float))
    a, ap = np.cos(q), np.sin(q)
    dt = (
        (data["temperature_c"].to_numpy(float) - t_c)
        if "temperature_c" in data
        else np.zeros_like(a)
    )
    return {
        "bias": [np.ones_like(a)],
        "scale_factor": [a],
        "bias_temperature": [dt, dt**2],
        "scale_factor_temperature": [a * dt, a * dt**2],
        "second_order": [a**2],
        "second_order_temperature": [a**2 * dt],
        "cross_coupling": [a * ap],
        "misalignment": [ap],
    }[name]


def design(data: pd.DataFrame, effects, t_c: float) -> np.ndarray:
    """Design matrix of the catalogued effects (columns in the order of their parameters)."""
    cols = [c for e in effects for c in _columns(data, e, t_c)]
    return np.column_stack(cols) if cols else np.zeros((len(data), 0))


def nominal_mg(data: pd.DataFrame) -> np.ndarray:
    return 1000.0 * np.cos(np.deg2rad(data["position_deg"].to_numpy(float)))


def _fit_accelerometer(data: pd.DataFrame, effects: tuple[Effect, ...], start) -> Fit:
    y = data["output_mg"].to_numpy(float) - nominal_mg(data)
    cat = tuple(e.name for e in effects if e.contribution is None)
    users = tuple(e for e in effects if e.contribution is not None)
    for name in cat:
        if "temperature_c" in ACCELEROMETER_EFFECTS[name].columns:
            need = 3 if len(ACCELEROMETER_EFFECTS[name].params) == 2 else 2
            require_levels(data, temperatures=need, what=f"effect '{name}'", name="tumble data")
    t_c = float(data["temperature_c"].mean())
    X = design(data, cat, t_c)
    beta, jac, names = fit_linear(
        y,
        X,
        [p for e in cat for p in ACCELEROMETER_EFFECTS[e].params],
        users,
        data,
        start,
        what="readings",
        model=" + ".join(e.name for e in effects),
    )
    nc = X.shape[1]
    params = dict(zip(names, map(float, beta)))

    def predict(frame):
        return (
            nominal_mg(frame)
            + design(frame, cat, t_c) @ beta[:nc]
            + user_columns(users, params, frame, (len(frame),))
        )

    return Fit(
        SYSTEM,
        tuple(e.name for e in effects),
        params,
        data,
        data["output_mg"].to_numpy(float) - predict(data),
        jac,
        predict,
        {"temperature_centre_c": t_c},
    )


def accelerometer_structure(fit: Fit) -> list[tuple[str, np.ndarray, float]]:
    """Third harmonic in position; cubic in temperature; a temperature offset that changes along each
    tumble (first vs second half of the positions, times the input)."""
    d = fit.data
    q = np.deg2rad(d["position_deg"].to_numpy(float))
    out = [("third harmonic in position", np.c_[np.cos(3 * q), np.sin(3 * q)], np.sqrt(2.0))]
    if d["set_point_c"].nunique() >= 4:
        x = d["temperature_c"].to_numpy(float)
        x = (x - x.mean()) / (np.std(x) or 1.0)
        out.append(("cubic in temperature", (x**3 - 3 * x)[:, None], 1.0))
    return out


MEASURED["accelerometer"] = (("output_mg",), False)
SYSTEM = register_system(
    System(
        "accelerometer",
        "mg",
        ACCELEROMETER_EFFECTS,
        load_accelerometer,
        _fit_accelerometer,
        accelerometer_structure,
        "accelerometer tumble test (output / nominal scale factor); residual = measured - model output, mg",
        columns=tuple(TUMBLE_COLUMNS),
    )
)


# ------------------------------------------------------------------------------------------ trials
def simulate_catalogue(
    params: dict, *, temperatures_c=None, positions: int = 24, noise_ug: float = 3.0, seed=0
) -> pd.DataFrame:
    """Tumble data from the catalogue model (effects absent = 0) on the paper's grid (-40..70 degC every
    5 degC, 24 positions) plus white noise ``noise_ug``."""
    t = np.arange(-40.0, 70.1, 5.0) if temperatures_c is None else np.asarray(temperatures_c, float)
    q = np.arange(positions) * 360.0 / positions
    T, Q = np.meshgrid(t, q, indexing="ij")
    frame = pd.DataFrame(
        {
            "set_point_c": T.ravel(),
            "temperature_c": T.ravel(),
            "position_deg": Q.ravel(),
            "unit": "sim",
        }
    )
    X = design(frame, tuple(ACCELEROMETER_EFFECTS), float(frame["temperature_c"].mean()))
    beta = np.array([params.get(p, 0.0) for e in ACCELEROMETER_EFFECTS.values() for p in e.params])
    rng = np.random.default_rng(seed)
    frame["output_mg"] = (
        nominal_mg(frame) + X @ beta + 1e-3 * noise_ug * rng.standard_normal(len(frame))
    )
    return frame


#: Typical sizes of each parameter for random draws (paper D's sensor: bias ~1 mg, 1.7 mg bias drift ...).
PARAM_SCALE = {
    "k0_mg": 1.0,
    "k1_mg_g": 1.0,
    "bias_t1_mg_c": 0.015,
    "bias_t2_mg_c2": 1e-4,
    "sf_t1_mg_g_c": 0.04,
    "sf_t2_mg_g_c2": 2e-4,
    "k2_mg_g2": 0.02,
    "k2_t_mg_g2_c": 0.002,
    "kip_mg_g2": 0.03,
    "delta_o_mg": 0.2,
}


def hidden_effect_trial(
    hidden: str | None, ratio: float, noise_ug: float, seed: int | np.random.SeedSequence
) -> dict:
    """One trial: with ``hidden`` set, data contain every effect (random, ``hidden`` rescaled so that its
    RMS is ``ratio`` x noise) and the model is the catalogue without ``hidden``; with ``None`` the data
    contain a random subset and the model is exactly that subset (a correct answer is "consistent with
    noise").  ``seed``: an integer entropy or a ``numpy.random.SeedSequence``."""
    cat = tuple(ACCELEROMETER_EFFECTS)
    rng = np.random.default_rng(seed)
    if hidden is None:
        k = int(rng.integers(1, len(cat)))
        present = tuple(cat[i] for i in sorted(rng.choice(len(cat), size=k, replace=False)))
    else:
        if hidden not in cat:
            raise InputError(f"unknown accelerometer effect '{hidden}'; known: {', '.join(cat)}")
        present = cat
    params = {
        p: PARAM_SCALE[p] * rng.uniform(-1, 1)
        for e in present
        for p in ACCELEROMETER_EFFECTS[e].params
    }
    if hidden is not None:
        probe = simulate_catalogue(params, noise_ug=0.0)
        x = design(probe, (hidden,), float(probe["temperature_c"].mean())) @ np.array(
            [params[p] for p in ACCELEROMETER_EFFECTS[hidden].params]
        )
        s = ratio * 1e-3 * noise_ug / np.sqrt(np.mean(x**2))
        for p in ACCELEROMETER_EFFECTS[hidden].params:
            params[p] *= s
        model = tuple(e for e in cat if e != hidden)
    else:
        model = present
    data = simulate_catalogue(params, noise_ug=noise_ug, seed=rng)
    d = diagnose(fit_model("accelerometer", data, model))
    return {
        "hidden": hidden or "(none)",
        "ratio": ratio if hidden else 0.0,
        "noise_ug": noise_ug,
        "seed": _seed_label(seed),
        "named": d.missing or "(none)",
        "correct": (d.missing == hidden) if hidden else d.consistent_with_noise,
        "consistent_with_noise": d.consistent_with_noise,
    }


def hidden_effect_study(
    ratios=(3.0, 10.0),
    noise_ug=3.0,
    seeds=range(10),
    none_seeds=None,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Detection trials for every hidden effect, size and seed, plus nothing-hidden trials (false alarms;
    default twice as many seeds), at the noise ``noise_ug`` (ug, one level or a sequence of levels).  Each
    trial's seed is :func:`navlib.workbench.trials.trial_seed` of its coordinates (the accelerometer, noise
    level, hidden effect, size, seed number; nothing hidden: effect 0), as in
    :func:`navlib.workbench.trials.hidden_effect_study`: every trial draws its own data.  ``workers``,
    ``scheduler``: where the trials run (:func:`navlib.workbench.trials.run_trials`)."""
    seeds = list(seeds)
    none_seeds = list(none_seeds) if none_seeds is not None else list(range(2 * len(seeds)))
    noises = [float(noise_ug)] if np.ndim(noise_ug) == 0 else [float(v) for v in noise_ug]
    base = (SYSTEM_KEYS[SYSTEM.name], 0)  # system, table size (the fixed grid)
    args = []
    for k, noise in enumerate(noises):
        args += [
            (h, r, noise, trial_seed("hidden effect", *base, k, i, j, s))
            for i, h in enumerate(ACCELEROMETER_EFFECTS, start=1)
            for j, r in enumerate(ratios)
            for s in seeds
        ]
        args += [
            (None, 0.0, noise, trial_seed("hidden effect", *base, k, 0, 0, s)) for s in none_seeds
        ]
    return pd.DataFrame(
        run_trials(hidden_effect_trial, args, workers, scheduler, "accelerometer trials")
    )


def detection_table(study: pd.DataFrame) -> pd.DataFrame:
    """Per hidden effect and size: trials and share named correctly; nothing hidden: the false-alarm share;
    95 % Wilson intervals."""
    rows = []
    for (h, r), g in study[study["hidden"] != "(none)"].groupby(["hidden", "ratio"], sort=False):
        k = int(g["correct"].sum())
        lo, hi = wilson(k, len(g))
        rows.append(
            {
                "hidden effect": h,
                "size (x noise)": r,
                "rate": "correctly named",
                "trials": len(g),
                "value": k / len(g),
                "95% low": lo,
                "95% high": hi,
            }
        )
    none = study[study["hidden"] == "(none)"]
    if len(none):
        k = int((~none["correct"].astype(bool)).sum())
        lo, hi = wilson(k, len(none))
        rows.append(
            {
                "hidden effect": "(none)",
                "size (x noise)": 0.0,
                "rate": "false alarms",
                "trials": len(none),
                "value": k / len(none),
                "95% low": lo,
                "95% high": hi,
            }
        )
    return pd.DataFrame(rows)


def unit_loop(data: pd.DataFrame, unit: str = "A", start=("bias",), noise_ug: float | None = None):
    """The workbench loop (:func:`navlib.workbench.loop.loop`) on one accelerometer of a tumble frame (its
    rows, ``unit == unit``), from the model ``start``; with ``noise_ug`` (the noise per reading the data
    were simulated with) also the band where a correct model's rms would lie
    (:func:`navlib.workbench.loop.known_noise_band`, in mg).  Returns ``(LoopResult, band or None)``."""

    if "unit" in data and unit not in set(data["unit"]):
        raise InputError(
            f"unit={unit!r}: the tumble frame holds {', '.join(map(str, dict.fromkeys(data['unit'])))}"
        )
    rows = data[data["unit"] == unit].reset_index(drop=True) if "unit" in data else data
    result = loop(SYSTEM.name, rows, list(start))
    band = None
    if noise_ug is not None:
        band = known_noise_band(float(noise_ug) / 1000.0, result.final.n, result.final.n_params)
    return result, band
