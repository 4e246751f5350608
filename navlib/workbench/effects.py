"""Physical models built from named effects: fit them to measurements, look at the residuals, add an effect.

Two systems, each with a catalogue of effects (``CATALOGUES``):

``compass`` (papers A and B) — measurement: the compass heading; residual = measured - model heading,
wrapped to (-180, 180] deg.  The model is the *exact* planar heading model of :mod:`navlib.sensors.compass`
(heading computed through the distorted field), not a truncated harmonic series; Smith's A..E series
(:mod:`navlib.methods.smith`) is its first-order harmonic approximation and is offered separately.

``drift`` (paper C) — measurement: the axial gyro drift (deg/h) of a single-axis rotation INS, with the
12 h latitude error as the physical observable.  The model is linear in its parameters:

    drift = g * dL12 / K  +  b  +  c_T (T - mean T)  +  c_dT (dT - mean dT)

with ``K = (cos L / W)(1 - cos 12 h W)`` the Table 1 gain (:func:`navlib.sensors.ins.latitude_error_per_drift`).
``earth_rate`` adds only ``g`` (no constant: that is ``bias``); the temperature terms are centred, so they
add no constant either.  Effects in one model are identifiable together.

Usage::

    fit = fit_model("compass", frame, ["misalignment", "hard_iron"])
    fit.rms, fit.residuals                 # how well the model explains the data
    fit2 = fit.add("soft_iron")            # adding an effect is one call
    compare(fit, fit2)                     # before/after table (RMS, range, held-out RMS)
    diagnose(fit)                          # which effect is missing (see navlib.diagnose)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import InputError
from ..sensors.planar import PLANAR_EFFECTS

@dataclass(frozen=True)
class Effect:
    """One physical effect: its name, the parameters it adds (with units), what causes it and how it shows
    in the residuals, and the data columns it needs besides the system's own."""

    name: str
    params: tuple[str, ...]
    units: tuple[str, ...]
    meaning: str
    columns: tuple[str, ...] = ()


COMPASS_EFFECTS = {
    "misalignment": Effect(
        "misalignment", PLANAR_EFFECTS["misalignment"], ("deg",),
        "The sensor's axes are turned about the vertical relative to the carrier's datum (mounting yaw). "
        "Every heading reads too high or too low by the same amount: a constant residual."),
    "hard_iron": Effect(
        "hard_iron", PLANAR_EFFECTS["hard_iron"], ("H", "H"),
        "Permanent magnetisation of the carrier (steel, magnets, DC currents) adds a field fixed to the "
        "carrier. It shows as a one-cycle residual (one maximum and one minimum per revolution)."),
    "soft_iron": Effect(
        "soft_iron", PLANAR_EFFECTS["soft_iron"], ("-", "-"),
        "Soft steel near the sensor is magnetised by the Earth field itself and distorts it symmetrically "
        "(with per-axis scale mismatch). It shows as a two-cycle residual (two maxima per revolution)."),
    "temperature": Effect(
        "temperature", PLANAR_EFFECTS["temperature"], ("H/degC", "H/degC"),
        "The hard-iron field (magnet and sensor offsets) drifts as the carrier warms. The one-cycle residual "
        "changes with temperature: repeated sweeps at different temperatures disagree.",
        ("temperature_c",)),
}

DRIFT_EFFECTS = {
    "earth_rate": Effect(
        "earth_rate", ("earth_rate_gain",), ("-",),
        "An axial gyro drift tilts the azimuth reference; through the Earth rate it builds a latitude error "
        "that after 12 h is 2 cos L / w_ie times the drift (paper C, Table 1). Gain 1 is the textbook "
        "formula. Missing, the residual follows the 12 h latitude error."),
    "bias": Effect(
        "bias", ("bias_deg_h",), ("deg/h",),
        "A constant part of the drift not seen in the latitude error (e.g. a calibration offset of the "
        "identification procedure). Missing, the residuals have a non-zero mean."),
    "temperature": Effect(
        "temperature", ("temperature_coef_deg_h_per_c",), ("deg/h/degC",),
        "The gyro's drift depends on its temperature (thermal gradients in the laser block, bias "
        "temperature coefficient). Missing, the residual trends with the mean temperature of the test.",
        ("temperature_c",)),
    "temperature_change": Effect(
        "temperature_change", ("temperature_change_coef_deg_h_per_c",), ("deg/h/degC",),
        "A cold start: while the system warms during alignment, transient thermal gradients shift the drift "
        "that the 12 h identification sees. Missing, the residual trends with the temperature change.",
        ("temperature_change_c",)),
}

CATALOGUES = {"compass": COMPASS_EFFECTS, "drift": DRIFT_EFFECTS}
UNITS = {"compass": "deg", "drift": "deg/h"}


def catalogue_table(system: str) -> pd.DataFrame:
    """The catalogue of a system as a table: effect, parameters (units), needed columns, meaning."""
    cat = _catalogue(system)
    return pd.DataFrame([{"effect": e.name,
                          "parameters": ", ".join(f"{p} [{u}]" for p, u in zip(e.params, e.units)),
                          "needs columns": ", ".join(e.columns) or "-",
                          "meaning": e.meaning} for e in cat.values()]).set_index("effect")


def _catalogue(system: str) -> dict:
    if system not in CATALOGUES:
        raise InputError(f"unknown system {system!r}; known: {', '.join(CATALOGUES)}")
    return CATALOGUES[system]


def check_effects(system: str, effects, data: pd.DataFrame | None = None) -> tuple[str, ...]:
    """Validate a list of effect names (unknown names, repeats, missing or constant columns)."""
    cat = _catalogue(system)
    effects = tuple(e.strip() for e in effects if e and e.strip())
    for e in effects:
        if e not in cat:
            raise InputError(f"unknown {system} effect '{e}'; known: {', '.join(cat)}")
    if len(set(effects)) != len(effects):
        raise InputError(f"effect listed twice in the model: {', '.join(effects)}")
    if data is not None:
        for e in effects:
            for col in cat[e].columns:
                if col not in data:
                    raise InputError(f"effect '{e}' needs the column '{col}', which the data do not have")
                if np.ptp(data[col].to_numpy(float)) == 0:
                    raise InputError(f"effect '{e}' needs '{col}' to vary, but it is constant in the data")
    return tuple(e for e in cat if e in effects)   # catalogue order


def testable(system: str, data: pd.DataFrame) -> tuple[dict, dict]:
    """Split the catalogue into effects the data can test and those it cannot (with the reason)."""
    ok, why = {}, {}
    for name, e in _catalogue(system).items():
        missing = [c for c in e.columns if c not in data]
        if missing:
            why[name] = f"no column '{missing[0]}'"
        elif any(np.ptp(data[c].to_numpy(float)) == 0 for c in e.columns):
            why[name] = f"'{e.columns[0]}' is constant"
        else:
            ok[name] = e
    return ok, why

