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
        "A three-cycle heading error (e.g. a sensor nonlinearity): "
        "three maxima per revolution.",
        system="compass",
        contribution=lambda p, d: (
            p["q3_sin_deg"] * np.sin(np.radians(3 * d["true_heading_deg"]))
            + p["q3_cos_deg"] * np.cos(np.radians(3 * d["true_heading_deg"]))))
"""

from __future__ import annotations

import contextlib
import importlib.machinery
import importlib.util
import sys
import traceback
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Mapping

import numpy as np
import pandas as pd

from ..data.tables import schema_table, show
from ..errors import InputError, UserCodeError
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
        implemented by their system's model and leave it ``None``.  It is called through
        :func:`call_contribution`: it gets a read-only copy of the data, and anything it raises or returns
        that is not a finite array of the measurement's shape stops the run with one line naming
        ``source`` and the effect.
    source : str
        Where a user effect was defined (the effects file's name, set by :func:`load_effects`), for messages.
    """

    name: str
    params: tuple[str, ...]
    units: tuple[str, ...]
    meaning: str
    columns: tuple[str, ...] = ()
    system: str | None = None
    contribution: Callable[[Mapping[str, float], pd.DataFrame], np.ndarray] | None = field(
        default=None, compare=False, repr=False
    )
    source: str = field(default="", compare=False, repr=False)

    def __post_init__(self):
        if not str(self.name).isidentifier():
            raise InputError(
                f"effect name {self.name!r}: must be an identifier (letters, digits, _)"
            )
        for attr in ("params", "units", "columns"):  # a lone name, not its letters
            value = getattr(self, attr)
            object.__setattr__(self, attr, (value,) if isinstance(value, str) else tuple(value))
            if not all(isinstance(v, str) and v for v in getattr(self, attr)):
                raise InputError(f"effect '{self.name}': {attr} must be names (non-empty text)")
        if len(set(self.params)) != len(self.params):
            raise InputError(f"effect '{self.name}': a parameter is named twice in {self.params}")
        if not self.params or len(self.params) != len(self.units):
            raise InputError(
                f"effect '{self.name}': give one unit per parameter (got {len(self.params)} "
                f"parameters, {len(self.units)} units)"
            )
        if self.contribution is not None and not callable(self.contribution):
            raise InputError(
                f"effect '{self.name}': contribution must be a function (params, data) -> array"
            )


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
    noise_directions : callable or None
        ``noise_directions(fit) -> (n_obs, 3)``: for residuals that are scalars computed from a 3-axis
        sensor along a direction that turns with it (the reference-free magnetometer's invariants), each
        residual's gradient with respect to the raw axes; the screen then models the noise on the sensor's
        axes, seen through these directions (:class:`navlib.workbench.serial.Projection`).  None: the
        residuals are the sensor's own axes (an AR model of the residuals).
    final_check : callable or None
        ``final_check(loop_result, site, date) -> (dict, list of str)``: what the system reports at the end
        of a loop besides the diagnosis (the reference-free magnetometer: the estimated local field against
        the Earth-field model at the site, ``site`` = ``(lat, lon[, height_m])`` and ``date`` from the
        command line or None); the CLI prints the lines and puts the dict under ``"field"`` in ``--json``.
        None: nothing more (and ``--site``/``--date`` are refused).
    remaining : callable or None
        ``remaining(fit) -> (DataFrame, str)``: what the residuals of a final model still hold, broken down
        by the factors the system knows (the reference-free magnetometer: time, turn rate, orientation,
        acceleration; :mod:`navlib.workbench.free_breakdown`), and one sentence reading it.  None: no
        breakdown.
    refit : callable or None
        ``refit(fit, data, effects) -> Fit or None``: the model ``effects`` (``fit``'s, or ``fit``'s with more
        effects) on ``data`` (rows of the same recording, e.g. without the screen's outliers) started from
        ``fit``'s parameters, a cheap path to the minimum ``fit(data, effects, fit.params)`` finds (the
        reference-free magnetometer: Gauss-Newton steps with the analytic Jacobian); None when it cannot
        (the caller then fits in full).  None: always fitted in full.
    columns : tuple of Column
        The file schema ``load`` reads (:class:`navlib.data.tables.Column`: name, unit, required, limits,
        meaning); :func:`columns_table` derives the system's data dictionary from it.
    """

    name: str
    unit: str
    catalogue: Mapping[str, Effect]
    load: Callable[[object], pd.DataFrame]
    fit: Callable
    structure: Callable
    meaning: str = ""
    noise_directions: Callable | None = None
    final_check: Callable | None = None
    columns: tuple = ()
    remaining: Callable | None = None
    refit: Callable | None = None


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
        "misalignment",
        PLANAR_EFFECTS["misalignment"],
        ("deg",),
        "The sensor's axes are turned about the vertical relative to the carrier's datum (mounting yaw). "
        "Every heading reads too high or too low by the same amount: a constant residual.",
    ),
    "hard_iron": Effect(
        "hard_iron",
        PLANAR_EFFECTS["hard_iron"],
        ("H", "H"),
        "Permanent magnetisation of the carrier (steel, magnets, DC currents) adds a field fixed to the "
        "carrier. It shows as a one-cycle residual (one maximum and one minimum per revolution).",
    ),
    "soft_iron": Effect(
        "soft_iron",
        PLANAR_EFFECTS["soft_iron"],
        ("-", "-"),
        "Soft steel near the sensor is magnetised by the Earth field itself and distorts it symmetrically "
        "(with per-axis scale mismatch). It shows as a two-cycle residual (two maxima per revolution).",
    ),
    "temperature": Effect(
        "temperature",
        PLANAR_EFFECTS["temperature"],
        ("H/degC", "H/degC"),
        "The hard-iron field (magnet and sensor offsets) drifts as the carrier warms. The one-cycle residual "
        "changes with temperature: repeated sweeps at different temperatures disagree.",
        ("temperature_c",),
    ),
}

DRIFT_EFFECTS = {
    "earth_rate": Effect(
        "earth_rate",
        ("earth_rate_gain",),
        ("-",),
        "An axial gyro drift tilts the azimuth reference; through the Earth rate it builds a latitude error "
        "that after 12 h is 2 cos L / w_ie times the drift (paper C, Table 1). Gain 1 is the textbook "
        "formula. Missing, the residual follows the 12 h latitude error.",
    ),
    "bias": Effect(
        "bias",
        ("bias_deg_h",),
        ("deg/h",),
        "A constant part of the drift not seen in the latitude error (e.g. a calibration offset of the "
        "identification procedure). Missing, the residuals have a non-zero mean.",
    ),
    "temperature": Effect(
        "temperature",
        ("temperature_coef_deg_h_per_c",),
        ("deg/h/degC",),
        "The gyro's drift depends on its temperature (thermal gradients in the laser block, bias "
        "temperature coefficient). Missing, the residual trends with the mean temperature of the test.",
        ("temperature_c",),
    ),
    "temperature_change": Effect(
        "temperature_change",
        ("temperature_change_coef_deg_h_per_c",),
        ("deg/h/degC",),
        "A cold start: while the system warms during alignment, transient thermal gradients shift the drift "
        "that the 12 h identification sees. Missing, the residual trends with the temperature change.",
        ("temperature_change_c",),
    ),
}


def catalogue_frame(effects: Mapping[str, Effect]) -> pd.DataFrame:
    """Effects as a table: effect, parameters (units), needed columns, meaning."""
    return pd.DataFrame(
        [
            {
                "effect": e.name,
                "parameters": ", ".join(f"{p} [{u}]" for p, u in zip(e.params, e.units)),
                "needs columns": ", ".join(e.columns) or "-",
                "meaning": e.meaning,
            }
            for e in effects.values()
        ]
    ).set_index("effect")


def resolve(
    available: Mapping[str, Effect], names, data: pd.DataFrame | None = None, system: str = ""
) -> tuple[Effect, ...]:
    """Validate effect names against ``available`` (unknown names, repeats, needed columns absent, not
    numbers or constant) and return the Effect objects in the order of ``available`` (catalogue first, then
    user effects)."""
    names = tuple(n.strip() for n in names if n and n.strip())
    for n in names:
        if n not in available:
            raise InputError(f"unknown {system} effect '{n}'; known: {', '.join(available)}")
    if len(set(names)) != len(names):
        raise InputError(f"effect listed twice in the model: {', '.join(names)}")
    if data is not None:
        for n in names:
            problem = column_problem(available[n], data)
            if problem:
                raise InputError(f"effect '{n}' needs {problem[1]}")
    return tuple(e for k, e in available.items() if k in names)


def column_problem(effect: Effect, data: pd.DataFrame) -> tuple[str, str] | None:
    """Why ``data`` cannot serve the columns ``effect`` needs, as ``(short, long)`` reasons, or None: a
    column absent, holding something that is not a finite number in some row (an extra column no loader
    checked), or constant."""
    for col in effect.columns:
        if col not in data:
            return f"no column '{col}'", f"the column '{col}', which the data do not have"
        column = data[col]
        values = (
            column.to_numpy(dtype=float)  # already numbers: the same values, without the conversion
            if column.dtype == np.float64
            else pd.to_numeric(column, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
        )
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            cell = show(data[col].iloc[bad[0]])
            return (
                f"'{col}' row {bad[0] + 1} is '{cell}', not a number",
                f"the column '{col}' to hold finite numbers, but row {bad[0] + 1} holds '{cell}'",
            )
        if np.ptp(values) == 0:
            return f"'{col}' is constant", f"'{col}' to vary, but it is constant in the data"
    return None


def testable(available: Mapping[str, Effect], data: pd.DataFrame) -> tuple[dict, dict]:
    """Split effects into those the data can test and those they cannot (with the reason: a needed column
    absent, not a finite number in some row, or constant)."""
    ok, why = {}, {}
    for name, e in available.items():
        problem = column_problem(e, data)
        if problem:
            why[name] = problem[0]
        else:
            ok[name] = e
    return ok, why


# ------------------------------------------------------------------------------------ users' own code
def _copy_on_write() -> bool:
    """pandas copies a frame's data before any write to a shallow copy (default from pandas 3)."""
    return int(pd.__version__.split(".")[0]) >= 3 or pd.get_option("mode.copy_on_write") is True


_SHALLOW = _copy_on_write()


def _first_line(err: BaseException) -> str:
    text = str(err).strip()
    return f"{type(err).__name__}: {show(text.splitlines()[0])}" if text else type(err).__name__


def call_contribution(
    effect: Effect, params: Mapping[str, float], data: pd.DataFrame, shape
) -> np.ndarray:
    """``effect.contribution(params, data)`` as a float array of ``shape``, with the user's code fenced.

    The contribution gets its own dictionary of parameters and a read-only copy of ``data`` (a shallow
    copy under pandas' copy-on-write, so that assigning to it changes only the copy, and arrays taken from
    it are read-only; a deep copy with older pandas): whatever it does to them cannot change the data the
    fit and the other effects see.  Anything it prints goes to stderr (stdout may carry ``--json``).
    Every failure -- an exception (``sys.exit`` included), a result that is not numbers (text, None), a
    shape other than ``shape``, a NaN or an infinity -- raises :class:`navlib.errors.UserCodeError`, one
    line naming the effect's file, the effect and, for a bad value, the row and the parameters."""
    who = f"{effect.source or 'user effects'}: effect '{effect.name}'"
    frame = data.copy(deep=not _SHALLOW)
    try:
        with contextlib.redirect_stdout(sys.stderr):
            out = effect.contribution(dict(params), frame)
    except SystemExit as err:
        raise UserCodeError(f"{who}: contribution called sys.exit({err.code!r})") from err
    except Exception as err:  # the user's code: any failure of it is theirs, named
        hint = (
            " (contributions get a read-only copy of the data)" if "read-only" in str(err) else ""
        )
        raise UserCodeError(f"{who}: contribution raised {_first_line(err)}{hint}") from err
    if out is None:
        raise UserCodeError(f"{who}: contribution returned None (a missing return?)")
    arr = np.asarray(out)
    if arr.dtype.kind not in "biuf":
        kind = {
            "U": "text",
            "S": "bytes",
            "c": "complex numbers",
            "M": "dates",
            "m": "time spans",
        }.get(arr.dtype.kind, f"{type(arr.flat[0]).__name__ if arr.size else 'empty'} objects")
        v = arr.flat[0] if arr.size else None
        first = show(repr(v.item() if isinstance(v, np.generic) else v))[:40] if arr.size else ""
        raise UserCodeError(
            f"{who}: contribution returned {kind}{f' ({first}, ...)' if first else ''}, "
            f"not real numbers"
        )
    arr = arr.astype(float, copy=False)
    if arr.shape != tuple(shape):
        raise UserCodeError(
            f"{who}: contribution returned shape {arr.shape}, the measurement has shape "
            f"{tuple(shape)} (one value{' per axis' if len(shape) > 1 else ''} per row)"
        )
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        r = int(bad[0][0])
        values = ", ".join(f"{k}={v:.6g}" for k, v in params.items())
        raise UserCodeError(
            f"{who}: contribution returned {arr[tuple(bad[0])]} at row {r + 1} "
            f"(parameters {values})"
        )
    return arr


def _user_line(err: BaseException, path: Path) -> str:
    """The line of ``path`` the exception came from (the deepest frame in that file), or ''."""
    lines = [
        f.lineno
        for f in traceback.extract_tb(err.__traceback__)
        if Path(f.filename).resolve() == path
    ]
    return f"line {lines[-1]}: " if lines else ""


def load_effects(path, system: str, catalogue: Mapping[str, Effect]) -> tuple[Effect, ...]:
    """User effects from a Python file: every :class:`Effect` defined at its top level whose ``system`` is
    ``system``, each with its ``source`` set to the file's name.

    Refused in one line naming the file (and the effect): a file that cannot be imported (a syntax error,
    an exception or an ImportError at import -- with the line -- or a call of ``sys.exit``); no effect for
    ``system``; two effects with one name; a name or a parameter name already in the catalogue or in
    another effect of the file; an effect without a ``contribution``.  Anything the file prints while it is
    imported goes to stderr."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such effects file")
    module_name = "navlib_user_effects_" + "".join(c if c.isalnum() else "_" for c in p.stem)
    loader = importlib.machinery.SourceFileLoader(module_name, str(p))
    spec = importlib.util.spec_from_loader(module_name, loader)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module  # dataclasses and pickling look their module up
    try:
        with contextlib.redirect_stdout(sys.stderr):
            loader.exec_module(module)
    except SyntaxError as err:
        raise InputError(f"{p.name}: line {err.lineno}: {err.msg}") from None
    except SystemExit as err:
        raise InputError(
            f"{p.name}: calls sys.exit({err.code!r}) while it is loaded; an effects file "
            f"should only define effects"
        ) from None
    except Exception as err:  # the user's file: any failure of it is theirs, named
        raise InputError(f"{p.name}: {_user_line(err, p.resolve())}{_first_line(err)}") from err
    finally:
        sys.modules.pop(module_name, None)
    named = {}  # each Effect object once, with its first variable name
    for var, v in vars(module).items():
        if isinstance(v, Effect) and id(v) not in named:
            named[id(v)] = (var, v)
    everything = list(named.values())
    found = [(var, e) for var, e in everything if e.system == system]
    if not found:
        others = sorted({str(e.system) for _, e in everything})
        what = (
            f"its effects are for system {', '.join(map(repr, others))}"
            if others
            else "it defines no Effect at top level"
        )
        raise InputError(f"{p.name}: defines no Effect with system='{system}' ({what})")
    taken = {q: f"the catalogue's '{e.name}'" for e in catalogue.values() for q in e.params}
    names = {}
    for var, e in found:
        if e.name in catalogue:
            raise InputError(
                f"{p.name}: effect '{e.name}' is already in the {system} catalogue; rename it"
            )
        if e.name in names:
            raise InputError(
                f"{p.name}: two effects are named '{e.name}' (variables '{names[e.name]}' and "
                f"'{var}'); give each its own name"
            )
        names[e.name] = var
        if e.contribution is None:
            raise InputError(
                f"{p.name}: effect '{e.name}' has no contribution(params, data) function"
            )
        for q in e.params:
            if q in taken:
                raise InputError(
                    f"{p.name}: effect '{e.name}': parameter '{q}' is already a parameter of "
                    f"{taken[q]}; rename it"
                )
            taken[q] = f"effect '{e.name}'"
    return tuple(replace(e, source=p.name) for _, e in found)


#: The catalogues of the systems that have a simulator (compass, drift), by system name.
CATALOGUES = {"compass": COMPASS_EFFECTS, "drift": DRIFT_EFFECTS}


def catalogue_table(system: str) -> pd.DataFrame:
    """The catalogue of a registered system as a table (see :func:`catalogue_frame`)."""
    return catalogue_frame(get_system(system).catalogue)


def columns_table(system: str) -> pd.DataFrame:
    """The columns a file of ``system`` must or may have: ``column``, ``unit``, ``required`` (yes/no),
    ``limits`` and ``meaning``, one row per column, derived from the schema the system's loader reads
    (``System.columns``, :func:`navlib.data.tables.schema_table`): a required column listed here is one
    the loader refuses a file without."""
    s = get_system(system)
    if not s.columns:
        raise InputError(f"system {s.name!r} declares no file schema (System.columns)")
    return schema_table(s.columns)


def check_effects(system: str, names, data: pd.DataFrame | None = None) -> tuple[str, ...]:
    """Validate catalogued effect names of ``system``; returns them in catalogue order."""
    return tuple(e.name for e in resolve(get_system(system).catalogue, names, data, system))
