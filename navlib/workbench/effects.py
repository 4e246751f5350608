"""Effects and systems: the two small types every workbench model is built from.

An :class:`Effect` is one named physical cause: the parameters it adds (with units), the data columns it
needs, what it means and how it shows in the residuals, and (for an effect written by a user) its
*contribution*, a function ``contribution(params, data) -> array`` that returns what the effect adds to
the system's measurement, in the system's unit, with the shape of the measurement (``(n,)`` for a heading or
a drift, ``(n, 3)`` for a 3-D field).  Catalogued effects leave ``contribution`` empty: their system's own
(often nonlinear, exact) model implements them.

A :class:`System` is one kind of measurement with its catalogue: its unit, how its files are loaded and
validated, how a model of effects is fitted (``fit(data, effects, start) -> Fit``), and which structure
tests look for what no catalogued effect explains.  The systems (``compass``, ``drift``, ``magnetometer``)
are listed in ``navlib.workbench.systems``; a new system is a module that builds one ``System`` and one
line there.

Catalogued effects of the compass and drift systems are defined here; the magnetometer's in
:mod:`navlib.workbench.magnetometer`.

``compass`` (papers A and B) -- measurement: the compass heading; residual = measured - model heading,
wrapped to (-180, 180] deg.  The model is the *exact* planar heading model of
:mod:`navlib.sensors.planar` (heading computed through the distorted field), not a truncated harmonic
series; Smith's A..E series (:mod:`navlib.methods.smith`) is its first-order harmonic approximation.

``drift`` (paper C) -- measurement: the axial gyro drift (deg/h) of a single-axis rotation INS, with the
12 h latitude error as the physical observable.  The model is linear in its parameters:

    drift = g * dL12 / K  +  b  +  c_T (T - mean T)  +  c_dT (dT - mean dT)

with ``K = (cos L / W)(1 - cos 12 h W)`` the Table 1 gain (:func:`navlib.sensors.ins.latitude_error_per_drift`).

A user effect in a few lines (a file passed with ``--effects FILE.py``; every ``Effect`` defined at the
top level of the file is loaded)::

    import numpy as np
    from navlib.workbench.effects import Effect

    quadrantal = Effect(
        "quadrantal", ("q3_sin_deg", "q3_cos_deg"), ("deg", "deg"),
        "A three-cycle heading error (e.g. a sensor nonlinearity): three maxima per revolution.",
        system="compass",
        contribution=lambda p, d: (p["q3_sin_deg"] * np.sin(np.radians(3 * d["true_heading_deg"]))
                                   + p["q3_cos_deg"] * np.cos(np.radians(3 * d["true_heading_deg"]))))
"""
from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

import numpy as np
import pandas as pd

from ..errors import InputError
from ..sensors.planar import PLANAR_EFFECTS


@dataclass(frozen=True)
class Effect:
    """One physical effect.

    Parameters
    ----------
    name : str
        Identifier used on the command line (``--model a,b``).
    params, units : tuple of str
        The parameters the effect adds and their units (same length, at least one).
    meaning : str
        What causes it and how it shows in the residuals.
    columns : tuple of str
        Data columns it needs besides the system's own (they must be present and vary).
    system : str or None
        The system a user effect belongs to (catalogued effects: their catalogue says it).
    contribution : callable or None
        ``contribution(params: dict, data: DataFrame) -> ndarray``: what the effect adds to the measurement,
        in the system's unit and the measurement's shape.  Required for user effects; catalogued effects are
        implemented by their system's model and leave it ``None``.
    """

    name: str
    params: tuple[str, ...]
    units: tuple[str, ...]
    meaning: str
    columns: tuple[str, ...] = ()
    system: str | None = None
    contribution: Callable[[Mapping[str, float], pd.DataFrame], np.ndarray] | None = field(
        default=None, compare=False, repr=False)

    def __post_init__(self):
        if not str(self.name).isidentifier():
            raise InputError(f"effect name {self.name!r}: must be an identifier (letters, digits, _)")
        object.__setattr__(self, "params", tuple(self.params))
        object.__setattr__(self, "units", tuple(self.units))
        object.__setattr__(self, "columns", tuple(self.columns))
        if not self.params or len(self.params) != len(self.units):
            raise InputError(f"effect '{self.name}': give one unit per parameter (got {len(self.params)} "
                             f"parameters, {len(self.units)} units)")
        if self.contribution is not None and not callable(self.contribution):
            raise InputError(f"effect '{self.name}': contribution must be a function (params, data) -> array")


@dataclass(frozen=True)
class System:
    """One kind of measurement and its catalogue of effects.

    Parameters
    ----------
    name, unit : str
        E.g. ``"compass"``, ``"deg"``; ``unit`` is the unit of the residuals and of every RMS reported.
    catalogue : dict of str to Effect
        The catalogued effects, in the order models list them.
    load : callable
        ``load(path) -> DataFrame``: read and validate a measurement file (bad input: one-line InputError).
    fit : callable
        ``fit(data, effects, start) -> Fit``: fit a model made of ``effects`` (Effect objects, catalogued
        ones first, user effects with a ``contribution`` after them); ``start`` holds parameter values to
        start from (the previous model's); missing ones start from the system's linearised solution.
    structure : callable
        ``structure(fit) -> list of (what, X, scale)``: structure tests. ``X`` has one row per residual and a
        few columns describing a shape no catalogued effect produces; ``scale`` converts the RMS of the
        fitted shape into the amplitude reported (``sqrt 2`` for a sinusoid, ``2`` for a step).
    meaning : str
        One sentence: what is measured and what the residual is.
    """

    name: str
    unit: str
    catalogue: Mapping[str, Effect]
    load: Callable[[object], pd.DataFrame]
    fit: Callable
    structure: Callable
    meaning: str = ""


#: Every system, by name (filled by the system modules as they are imported; the package imports them all).
SYSTEMS: dict[str, System] = {}


def register_system(system: System) -> System:
    """Add a system to :data:`SYSTEMS` (a system module calls this once, at import)."""
    SYSTEMS[system.name] = system
    return system


def get_system(name: str) -> System:
    """The registered system called ``name`` (InputError naming the known ones otherwise)."""
    if name not in SYSTEMS:
        raise InputError(f"unknown system {name!r}; known: {', '.join(SYSTEMS)}")
    return SYSTEMS[name]


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


def catalogue_frame(effects: Mapping[str, Effect]) -> pd.DataFrame:
    """Effects as a table: effect, parameters (units), needed columns, meaning."""
    return pd.DataFrame([{"effect": e.name,
                          "parameters": ", ".join(f"{p} [{u}]" for p, u in zip(e.params, e.units)),
                          "needs columns": ", ".join(e.columns) or "-",
                          "meaning": e.meaning} for e in effects.values()]).set_index("effect")


def resolve(available: Mapping[str, Effect], names, data: pd.DataFrame | None = None,
            system: str = "") -> tuple[Effect, ...]:
    """Validate effect names against ``available`` (unknown names, repeats, missing or constant columns) and
    return the Effect objects in the order of ``available`` (catalogue first, then user effects)."""
    names = tuple(n.strip() for n in names if n and n.strip())
    for n in names:
        if n not in available:
            raise InputError(f"unknown {system} effect '{n}'; known: {', '.join(available)}")
    if len(set(names)) != len(names):
        raise InputError(f"effect listed twice in the model: {', '.join(names)}")
    if data is not None:
        for n in names:
            for col in available[n].columns:
                if col not in data:
                    raise InputError(f"effect '{n}' needs the column '{col}', which the data do not have")
                if np.ptp(data[col].to_numpy(float)) == 0:
                    raise InputError(f"effect '{n}' needs '{col}' to vary, but it is constant in the data")
    return tuple(e for k, e in available.items() if k in names)


def testable(available: Mapping[str, Effect], data: pd.DataFrame) -> tuple[dict, dict]:
    """Split effects into those the data can test and those they cannot (with the reason)."""
    ok, why = {}, {}
    for name, e in available.items():
        missing = [c for c in e.columns if c not in data]
        if missing:
            why[name] = f"no column '{missing[0]}'"
        elif any(np.ptp(data[c].to_numpy(float)) == 0 for c in e.columns):
            why[name] = f"'{e.columns[0]}' is constant"
        else:
            ok[name] = e
    return ok, why


def load_effects(path, system: str, catalogue: Mapping[str, Effect]) -> tuple[Effect, ...]:
    """User effects from a Python file: every :class:`Effect` defined at its top level whose ``system`` is
    ``system``.  Each needs a ``contribution``; names must not clash with the catalogue."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such effects file")
    spec = importlib.util.spec_from_file_location(f"navlib_user_effects_{p.stem}", p)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except SyntaxError as err:
        raise InputError(f"{p.name}: line {err.lineno}: {err.msg}") from None
    found = tuple(v for v in vars(module).values() if isinstance(v, Effect) and v.system == system)
    if not found:
        raise InputError(f"{p.name}: defines no Effect with system='{system}'")
    for e in found:
        if e.name in catalogue:
            raise InputError(f"{p.name}: effect '{e.name}' is already in the {system} catalogue; rename it")
        if e.contribution is None:
            raise InputError(f"{p.name}: effect '{e.name}' has no contribution(params, data) function")
    return found


#: The catalogues of the systems that have a simulator (compass, drift), by system name.
CATALOGUES = {"compass": COMPASS_EFFECTS, "drift": DRIFT_EFFECTS}


def catalogue_table(system: str) -> pd.DataFrame:
    """The catalogue of a registered system as a table (see :func:`catalogue_frame`)."""
    return catalogue_frame(get_system(system).catalogue)


def check_effects(system: str, names, data: pd.DataFrame | None = None) -> tuple[str, ...]:
    """Validate catalogued effect names of ``system``; returns them in catalogue order."""
    return tuple(e.name for e in resolve(get_system(system).catalogue, names, data, system))
