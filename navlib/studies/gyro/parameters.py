"""The gyro chapter's parameters: paper C's printed facts, the settings dataclasses and the seeds.

- the facts: :func:`paper_facts` (``data/paper_c_facts.csv``) and :func:`fact`, one printed number;
- the settings: :class:`HotNetSettings`, :class:`ColdNetSettings`, :class:`SimulationSettings`, the thermal
  worlds (:class:`ThermalWorld`, :data:`THERMAL_WORLDS`, :class:`ColdStudySettings`) and the chapter's top
  dataclass :class:`StudyParams`, whose :meth:`StudyParams.from_notebook` turns the flat parameters of the
  notebook's ``parameters`` cell (:data:`NOTEBOOK_PARAMETERS`) into these dataclasses in one call;
- the seeds: :func:`experiment_seeds` (one ``SeedSequence`` child per experiment) and :func:`bootstrap_seed`
  (one per bootstrap interval over the rows of a real table, :data:`BOOTSTRAPS`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Literal, get_args

import numpy as np
import pandas as pd

from navlib.data.tables import Column, read_table
from navlib.errors import InputError, check_param
from navlib.methods.rbf import spread_from_gaussian_width
from navlib.paths import data_path
from navlib.sensors import ins, thermal_gyro


InputUnit = Literal["deg", "arcmin", "arcsec"]
WidthReading = Literal["matlab", "gaussian"]
GoalKind = Literal["mse", "sse"]
ColdDtColumn = Literal["calib_temp_change_c", "align_temp_change_c"]


# ------------------------------------------------------------------------------------------------ paper facts
FACTS_FILE = "paper_c_facts.csv"
FACT_KEYS = (
    "claimed_accuracy",
    "required_accuracy",
    "position_goal",
    "training_goal",
    "spread",
    "local_latitude",
    "align_h",
    "identify_h",
    "navigate_h",
    "hot_state_max_temp_change",
    "cold_state_min_temp_change",
    "cold_hot_net_drift_error_min",
    "cold_hot_net_drift_error_max",
    "cold_hot_net_pos_error_min",
    "cold_hot_net_pos_error_max",
)


def paper_facts(path=None) -> pd.DataFrame:
    """Paper C's printed settings and claims (``data/paper_c_facts.csv``), indexed by ``key``.

    Columns ``value`` (float), ``unit``, ``kind`` (``claim`` or ``setting``), ``source``, ``quote``; see
    ``data/paper_c_facts.md``.  Every key of ``FACT_KEYS`` must be present exactly once.

    Parameters
    ----------
    path : path-like, optional
        Another facts file with the same columns (default: the one in ``data/``).

    Returns
    -------
    pandas.DataFrame
        One row per fact.
    """
    p = data_path(FACTS_FILE) if path is None else path
    df = read_table(p, [Column("value", lo=-1e6, hi=1e6)], kind="facts table")
    for c in ("key", "unit", "kind", "source", "quote"):
        if c not in df:
            raise InputError(f"{getattr(p, 'name', p)}: missing column '{c}'")
    dup = df["key"][df["key"].duplicated()]
    if len(dup):
        raise InputError(f"{getattr(p, 'name', p)}: key '{dup.iloc[0]}' appears twice")
    missing = [k for k in FACT_KEYS if k not in set(df["key"])]
    if missing:
        raise InputError(f"{getattr(p, 'name', p)}: no row for key '{missing[0]}'")
    bad = df.loc[~df["kind"].isin(["claim", "setting"]), "kind"]
    if len(bad):
        raise InputError(
            f"{getattr(p, 'name', p)}: kind '{bad.iloc[0]}' must be 'claim' or 'setting'"
        )
    return df.set_index("key")


@lru_cache(maxsize=1)
def _default_facts() -> pd.DataFrame:
    return paper_facts()


def fact(key: str) -> float:
    """One printed number of paper C (:func:`paper_facts`), e.g. ``fact("claimed_accuracy")`` = 0.0003 deg/h.

    Parameters
    ----------
    key : str
        One of ``FACT_KEYS``.

    Returns
    -------
    float
        The value in the unit of the facts file.
    """
    if key not in FACT_KEYS:
        raise InputError(
            f"parameter key={key!r}: paper C has no such fact; one of {', '.join(FACT_KEYS)}"
        )
    return float(_default_facts().loc[key, "value"])


# --------------------------------------------------------------------------------------------------- settings
def _check_choice(name: str, value, options) -> None:
    if value not in options:
        raise InputError(
            f"parameter {name}={value!r}: must be one of {', '.join(map(repr, options))}"
        )


@dataclass(frozen=True)
class HotNetSettings:
    """The hot-state network (paper C Sec. 2.2): MATLAB ``newrb`` on Table 2.

    ``spread`` (in units of the scaled input) and ``goal`` (as printed, in the ``goal_kind`` semantics):
    ``None`` takes the paper's value from ``data/paper_c_facts.csv`` (2 and 0.0003).  ``goal_kind``:
    ``"mse"`` (current MATLAB) or ``"sse"`` (older toolbox).  ``input_unit``: the unit the 12 h latitude
    error enters the network in.  ``width``: ``"matlab"`` (``radbas``, ``b = 0.8326 / SPREAD``) or
    ``"gaussian"`` (the paper's eq. 1, ``exp(-u^2 / delta^2)`` with ``delta`` = SPREAD, i.e. MATLAB's SPREAD
    times 0.8326, :func:`navlib.methods.rbf.spread_from_gaussian_width`)."""

    spread: float | None = None
    goal: float | None = None
    goal_kind: GoalKind = "mse"
    input_unit: InputUnit = "arcmin"
    width: WidthReading = "matlab"

    def __post_init__(self):
        if self.spread is None:
            object.__setattr__(self, "spread", fact("spread"))
        if self.goal is None:
            object.__setattr__(self, "goal", fact("training_goal"))
        check_param("spread", self.spread, lo=0, lo_open=True)
        check_param("goal", self.goal, lo=0)
        _check_choice("goal_kind", self.goal_kind, get_args(GoalKind))
        _check_choice("input_unit", self.input_unit, get_args(InputUnit))
        _check_choice("width", self.width, get_args(WidthReading))

    @property
    def matlab_spread(self) -> float:
        """The SPREAD given to ``newrb`` under this width reading."""
        return self.spread if self.width == "matlab" else spread_from_gaussian_width(self.spread)


@dataclass(frozen=True)
class ColdNetSettings:
    """The cold-state network (paper C Sec. 2.3): ``newrb`` on Table 4's three inputs, z-scored on the
    training rows (``InputScaler.standardize``), so ``spread_sd`` is in standard deviations of each input;
    ``dt_column`` is the temperature-change input (calibration window or whole alignment)."""

    spread_sd: float = 2.0
    dt_column: ColdDtColumn = "calib_temp_change_c"

    def __post_init__(self):
        check_param("cold_spread", self.spread_sd, lo=0, lo_open=True)
        _check_choice("cold_dt_column", self.dt_column, get_args(ColdDtColumn))


@dataclass(frozen=True)
class SimulationSettings:
    """Simulated tests (:mod:`navlib.sensors.ins`): number of Fig 1 tests, draws per case, base seed,
    simulator step, and the 1-sigma residual errors after alignment each test draws.
    ``cold_drift_half_range_deg_h``: Table 5's simulated final drifts are uniform in +-this (a book choice
    covering Table 2's drifts, -0.00339..0.0034 deg/h; the paper prints no drifts for Table 5)."""

    n_tests: int = 6
    n_seeds: int = 5
    seed: int = 2012
    step_s: float = 60.0
    gyro_arw_deg_rt_h: float = 0.0003
    gyro_bias_sd_deg_h: float = 0.002
    accel_bias_sd_ug: float = 20.0
    tilt_sd_arcsec: float = 1.0
    azimuth_sd_arcsec: float = 10.0
    cold_drift_half_range_deg_h: float = 0.0035

    def __post_init__(self):
        check_param("n_sim_tests", self.n_tests, lo=1, hi=50, integer=True)
        check_param("n_seeds", self.n_seeds, lo=1, hi=50, integer=True)
        check_param("sim_seed", self.seed, lo=0, integer=True)
        check_param("sim_step_s", self.step_s, lo=1, hi=300)
        if 300 % self.step_s:
            raise InputError(
                f"parameter sim_step_s={self.step_s!r}: must divide the 300 s indexing dwell"
            )
        for name in (
            "gyro_arw_deg_rt_h",
            "gyro_bias_sd_deg_h",
            "accel_bias_sd_ug",
            "tilt_sd_arcsec",
            "azimuth_sd_arcsec",
        ):
            check_param(f"sim_{name}", getattr(self, name), lo=0)
        check_param("cold_drift_half_range_deg_h", self.cold_drift_half_range_deg_h, lo=0, hi=0.1)

    def error_sd(self) -> dict:
        """Keyword arguments of :func:`navlib.sensors.ins.random_test`."""
        return dict(
            gyro_arw_deg_rt_h=self.gyro_arw_deg_rt_h,
            gyro_bias_sd_deg_h=self.gyro_bias_sd_deg_h,
            accel_bias_sd_ug=self.accel_bias_sd_ug,
            tilt_sd_arcsec=self.tilt_sd_arcsec,
            azimuth_sd_arcsec=self.azimuth_sd_arcsec,
        )

    def procedure(self) -> ins.Procedure:
        """Paper C's procedure (alignment, identification and navigation hours from the facts file)."""
        return ins.Procedure(
            align_h=fact("align_h"),
            identify_h=fact("identify_h"),
            navigate_h=fact("navigate_h"),
            step_s=float(self.step_s),
        )


@dataclass(frozen=True)
class ThermalWorld:
    """One simulated world of cold starts (:class:`navlib.sensors.thermal_gyro.ThermalGyro`): each draw takes
    a gyro with ``k_T`` uniform in ``temp_coeff_deg_h_per_c``, the steady-ramp coefficient ``k_G tau`` uniform in
    ``rate_coeff_in_k_r`` times ``k_R`` (the rate coefficient fitted on the real Table 4,
    :func:`~navlib.studies.gyro.networks.rate_coefficient`) and the lag ``tau`` uniform in ``lag_h``."""

    name: str
    temp_coeff_deg_h_per_c: tuple[float, float] = (0.0, 0.0)
    rate_coeff_in_k_r: tuple[float, float] = (0.5, 1.5)
    lag_h: tuple[float, float] = (0.25, 1.0)

    def __post_init__(self):
        if not str(self.name).strip():
            raise InputError("parameter ThermalWorld.name: must not be empty")
        for f, lo, hi in (
            ("temp_coeff_deg_h_per_c", -0.01, 0.01),
            ("rate_coeff_in_k_r", -10.0, 10.0),
            ("lag_h", 0.01, 24.0),
        ):
            v = getattr(self, f)
            if len(v) != 2 or not v[0] <= v[1]:
                raise InputError(f"parameter {f}={v!r}: a (low, high) range")
            for x in v:
                check_param(f, x, lo=lo, hi=hi)

    def draw(self, rng: np.random.Generator, k_r: float) -> thermal_gyro.ThermalGyro:
        """One gyro of this world."""
        kt = rng.uniform(*self.temp_coeff_deg_h_per_c)
        kr = rng.uniform(*self.rate_coeff_in_k_r) * k_r
        tau = rng.uniform(*self.lag_h)
        return thermal_gyro.ThermalGyro(
            temp_coeff_deg_h_per_c=float(kt),
            gradient_coeff_deg_h_per_c=float(kr / tau),
            lag_h=float(tau),
        )


#: The worlds of :func:`~navlib.studies.gyro.thermal_worlds.cold_thermal_study` (ranges stated in the chapter): the rate
#: limit (``tau`` -> 0, the world the rate-corrected hot net is made for), a short and a long thermal lag, a temperature
#: coefficient alone, and both terms together.
THERMAL_WORLDS = (
    ThermalWorld("rate limit (tau 0.05 h)", lag_h=(0.05, 0.05)),
    ThermalWorld("gradient, short lag", lag_h=(0.25, 1.0)),
    ThermalWorld("gradient, long lag", lag_h=(2.0, 6.0)),
    ThermalWorld(
        "temperature coefficient only",
        temp_coeff_deg_h_per_c=(-2e-4, 2e-4),
        rate_coeff_in_k_r=(0.0, 0.0),
        lag_h=(0.25, 6.0),
    ),
    ThermalWorld(
        "gradient + temperature coefficient",
        temp_coeff_deg_h_per_c=(-2e-4, 2e-4),
        lag_h=(0.25, 6.0),
    ),
)


@dataclass(frozen=True)
class ColdStudySettings:
    """The cold-start study of :func:`~navlib.studies.gyro.thermal_worlds.cold_thermal_study`: ``n_draws`` per world
    (each a gyro, residual errors for every test, and test drifts), seeds batched ``batch_size`` draws per engine task;
    the raw-unit cold-net SPREAD (inputs in arcmin, C, C); the worlds."""

    n_draws: int = 100
    batch_size: int = 25
    raw_spread: float = 2.0
    worlds: tuple = THERMAL_WORLDS

    def __post_init__(self):
        check_param("n_cold_draws", self.n_draws, lo=7, hi=100000, integer=True)
        check_param("cold_batch_size", self.batch_size, lo=1, integer=True)
        check_param("raw_spread", self.raw_spread, lo=0, lo_open=True)
        if not self.worlds or not all(isinstance(w, ThermalWorld) for w in self.worlds):
            raise InputError("parameter worlds: one or more ThermalWorld")


@dataclass(frozen=True)
class BpSettings:
    """The BP network set against the hot net (register entry C12, "RBF is better than a BP network"):
    MATLAB's ``feedforwardnet(n_hidden)`` trained by ``train`` (tansig hidden layer, ``mapminmax``,
    Nguyen-Widrow initialisation, ``trainlm`` with its defaults; :func:`navlib.methods.bpnet.train_matlab_bp_many`).

    ``n_hidden``: the primary size, 10, ``feedforwardnet``'s default ``hiddenSizes`` (paper C names no BP
    network, so a MATLAB user who names no size gets this); ``sizes``: the sizes of the sensitivity rows;
    ``n_inits``: initialisations per leave-one-out fold; ``n_inits_converged``: initialisations per fold of
    the reading trained to convergence (``min_grad`` 0: up to 1,000 epochs each, hence fewer)."""

    n_hidden: int = 10
    sizes: tuple = tuple(range(2, 11))
    n_inits: int = 20
    n_inits_converged: int = 5

    def __post_init__(self):
        check_param("bp_hidden", self.n_hidden, lo=1, hi=50, integer=True)
        if not self.sizes or not all(
            isinstance(m, int) and 1 <= m <= 50 and not isinstance(m, bool) for m in self.sizes
        ):
            raise InputError(
                f"parameter bp_sizes={self.sizes!r}: whole numbers of hidden neurons 1-50"
            )
        if len(set(self.sizes)) != len(self.sizes):
            raise InputError(f"parameter bp_sizes={self.sizes!r}: each size once")
        # the interquartile range over initialisations needs a few of them
        check_param("n_bp_inits", self.n_inits, lo=4, hi=1000, integer=True)
        check_param("n_bp_inits_converged", self.n_inits_converged, lo=4, hi=1000, integer=True)


@dataclass(frozen=True)
class StudyParams:
    """Everything the gyro chapter can vary; nested settings of the hot net, the cold net, the
    simulations, the cold-start thermal worlds (:class:`ColdStudySettings`) and the BP network of the
    comparison C12 (:class:`BpSettings`, not in the notebook's parameters cell).  The site is paper C's (``navlib.sensors.ins.LOCAL_LATITUDE_DEG``)."""

    hot: HotNetSettings = field(default_factory=HotNetSettings)
    cold: ColdNetSettings = field(default_factory=ColdNetSettings)
    sim: SimulationSettings = field(default_factory=SimulationSettings)
    thermal: ColdStudySettings = field(default_factory=ColdStudySettings)
    bp: BpSettings = field(default_factory=BpSettings)

    def __post_init__(self):
        for name, cls in (
            ("hot", HotNetSettings),
            ("cold", ColdNetSettings),
            ("sim", SimulationSettings),
            ("thermal", ColdStudySettings),
            ("bp", BpSettings),
        ):
            if not isinstance(getattr(self, name), cls):
                raise InputError(f"parameter {name}: must be a {cls.__name__}")

    @property
    def earth(self) -> ins.Earth:
        return ins.Earth(latitude_deg=ins.LOCAL_LATITUDE_DEG)

    @classmethod
    def from_notebook(cls, **cell) -> StudyParams:
        """The chapter's parameters from the flat parameters of the gyro notebook's ``parameters`` cell
        (:data:`NOTEBOOK_PARAMETERS`): the dataclasses the notebook's mapping cell builds, in one call.

        A parameter left out takes its dataclass default (the same as the cell's).  ``n_workers`` is
        accepted and set aside: it says where the thermal worlds run, not what they compute (pass it to
        :func:`~navlib.studies.gyro.thermal_worlds.cold_thermal_study`).

        Parameters
        ----------
        **cell
            Names and values of the ``parameters`` cell, e.g. ``spread=None, n_seeds=5``.

        Returns
        -------
        StudyParams

        Raises
        ------
        navlib.errors.InputError
            A name that is not a parameter of the cell (the message names it).
        """
        unknown = [k for k in cell if k not in NOTEBOOK_PARAMETERS]
        if unknown:
            raise InputError(
                f"parameter {unknown[0]}: the gyro notebook has no such parameter; one of "
                f"{', '.join(NOTEBOOK_PARAMETERS)}"
            )
        groups: dict[str, dict] = {"hot": {}, "cold": {}, "sim": {}, "thermal": {}}
        for key, value in cell.items():
            target = NOTEBOOK_PARAMETERS[key]
            if target is not None:
                group, name = target
                groups[group][name] = value
        return cls(
            hot=HotNetSettings(**groups["hot"]),
            cold=ColdNetSettings(**groups["cold"]),
            sim=SimulationSettings(**groups["sim"]),
            thermal=ColdStudySettings(**groups["thermal"]),
        )


# ---------------------------------------------------------------------------------- the notebook's parameters
#: The parameters of the gyro notebook's ``parameters`` cell (``notebooks/gyro.ipynb``) -> (settings of
#: :class:`StudyParams`, field) they set; ``None``: not a study setting (``n_workers``, the engine's worker
#: processes for the thermal worlds: the results do not depend on it).
NOTEBOOK_PARAMETERS = {
    "spread": ("hot", "spread"),
    "goal": ("hot", "goal"),
    "goal_kind": ("hot", "goal_kind"),
    "input_unit": ("hot", "input_unit"),
    "cold_spread": ("cold", "spread_sd"),
    "cold_dt_column": ("cold", "dt_column"),
    "n_sim_tests": ("sim", "n_tests"),
    "n_seeds": ("sim", "n_seeds"),
    "sim_seed": ("sim", "seed"),
    "sim_step_s": ("sim", "step_s"),
    "sim_gyro_arw_deg_rt_h": ("sim", "gyro_arw_deg_rt_h"),
    "sim_gyro_bias_sd_deg_h": ("sim", "gyro_bias_sd_deg_h"),
    "sim_accel_bias_sd_ug": ("sim", "accel_bias_sd_ug"),
    "sim_tilt_sd_arcsec": ("sim", "tilt_sd_arcsec"),
    "sim_azimuth_sd_arcsec": ("sim", "azimuth_sd_arcsec"),
    "n_cold_draws": ("thermal", "n_draws"),
    "cold_raw_spread": ("thermal", "raw_spread"),
    "n_workers": None,
}


# ------------------------------------------------------------------------------------------------------ seeds
_EXPERIMENTS = (
    "fig1",
    "hot_reference",
    "cold_training",
    "fig3",
    "table5",
    "table5_drifts",
    "rounding",
    "bootstrap",
    "bp_inits",
    "centre_subsets",
    "rotation_share",
)
#: The bootstrap intervals over rows of the real tables, one seed each (:func:`bootstrap_seed`).
BOOTSTRAPS = (
    "loo_arcmin",
    "loo_deg",
    "table4_range",
    "table4_cold_vs_hot",
    "nonlinear",
    "rbf_vs_bp",
    "cold_worse_than_hot",
    "error_with_temperature_change",
    "rate_compensation",
    "centres_vs_basis",
    "latitude_share",
)


def _experiment_children(seed: int, experiment: str, n: int) -> list[np.random.SeedSequence]:
    if experiment not in _EXPERIMENTS:
        raise InputError(f"parameter experiment={experiment!r}: one of {', '.join(_EXPERIMENTS)}")
    check_param("n", n, lo=1, integer=True)
    child = np.random.SeedSequence(int(seed)).spawn(len(_EXPERIMENTS))[
        _EXPERIMENTS.index(experiment)
    ]
    return child.spawn(int(n))


def experiment_seeds(seed: int, experiment: str, n: int) -> list[int]:
    """``n`` integer seeds for one random experiment of the chapter.

    ``numpy.random.SeedSequence(seed).spawn(11)[k].spawn(n)``, ``k`` the experiment's place in
    ``("fig1", "hot_reference", "cold_training", "fig3", "table5", "table5_drifts", "rounding",
    "bootstrap", "bp_inits", "centre_subsets", "rotation_share")`` (a child's seed depends only on its place, so adding an experiment at the end changes no
    other); each child gives one 32-bit integer (``generate_state(1)``), passed to
    :func:`navlib.sensors.ins.simulated_tests`.

    Parameters
    ----------
    seed : int
        The chapter's base seed.
    experiment : str
    n : int

    Returns
    -------
    list of int
    """
    return [int(c.generate_state(1)[0]) for c in _experiment_children(seed, experiment, n)]


def bootstrap_seed(seed: int, statistic: str) -> np.random.SeedSequence:
    """The :class:`numpy.random.SeedSequence` of one bootstrap interval over the rows of a real table:
    child ``k`` of the ``"bootstrap"`` experiment (:func:`experiment_seeds`), ``k`` the statistic's place in
    :data:`BOOTSTRAPS`.

    Parameters
    ----------
    seed : int
        The chapter's base seed.
    statistic : str
        One of :data:`BOOTSTRAPS`.

    Returns
    -------
    numpy.random.SeedSequence
    """
    if statistic not in BOOTSTRAPS:
        raise InputError(f"parameter statistic={statistic!r}: one of {', '.join(BOOTSTRAPS)}")
    return _experiment_children(seed, "bootstrap", len(BOOTSTRAPS))[BOOTSTRAPS.index(statistic)]
