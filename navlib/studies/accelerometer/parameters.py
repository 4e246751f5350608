"""The accelerometer chapter's parameters: the methods and tuners it compares, the constants of its claims
and draws, :class:`PaperDParams` (everything a reader may change, with
:meth:`PaperDParams.from_notebook` for the chapter's papermill parameters) and paper D's printed numbers
(:func:`paper_numbers`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...data.tables import Column, read_table
from ...errors import InputError, check_param
from ...methods.anfis import AnfisOptions
from ...methods.fish_swarm import FishSwarmParams
from ...methods.mlp import MLPParams
from ...paths import data_path
from ...sensors.accelerometer import AccelCoefficients, TumbleExperiment

METHODS = ("ANN", "FIS", "ANFIS", "IAFSA-SCM-ANFIS", "physical (poly K0, K1, K2)")
#: The other tuners of the clustering radii (``PaperDParams.tuners``): plain AFSA and a grid, same budget.
TUNERS = ("AFSA-SCM-ANFIS", "grid-SCM-ANFIS")
#: The separate bias and scale-factor compensator the paper's integrated model is argued against (section 2,
#: register entry D11; :mod:`~navlib.studies.accelerometer.separate`), fitted like ``ANFIS``.
SEPARATE = "separate K0, K1 (ANFIS)"
#: Readings with a smaller input than this (g) give no scale-factor point ``(U - K0) / a`` (eq 3 is
#: undefined at ``a = 0`` and amplifies the noise near it); the value of the chapter's Fig 4.
K1_MIN_INPUT_G = 0.25
#: "Nearly two orders of magnitude" better than the single models (section 5.2): two defensible
#: boundaries on the RMSE ratio, 50x (within a factor 2 of 100) and 10^1.5 = 31.6x (nearer to two
#: orders than to one on a log scale).
NEARLY_TWO_ORDERS = (50.0, 10**1.5)
SPLIT_MODES = ("temperatures", "random")
#: "1-2 orders of magnitude" more accurate than the neural network and the FIS (section 5.2, conclusion 3):
#: the claim holds when the RMSE ratio is above one order of magnitude.
ORDER_OF_MAGNITUDE = 10.0
#: The 95 % median interval over seeds needs at least this many seeds (:func:`navlib.verdicts.median_ci`).
MIN_SEEDS_FOR_CLAIMS = 6
PAPER_FILE = data_path("paper_d_results.csv")
#: Entropy of the chapter's simulated draws: seed ``s`` draws unit A's noise from
#: ``SeedSequence(SIM_ENTROPY, spawn_key=(s, 0))``, unit B's from ``(s, 1)`` and the bias test's from
#: ``(s, 2)`` (spawn keys, no arithmetic: no two seeds or parts share a draw).
SIM_ENTROPY = 1000
#: Parts of a seed's draws (the second element of the spawn key): unit A's and B's noise, the bias test, the
#: random split of the readings and unit B's batch deviation.
SIM_PARTS = {"noise_a": 0, "noise_b": 1, "bias_test": 2, "split": 3, "batch_b": 4}
#: Unit B's batch spreads swept by :func:`~navlib.studies.accelerometer.batch_spread.unit_b_spread` and
#: :func:`~navlib.studies.accelerometer.batch_spread.spread_needed`.
BATCH_SPREADS = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.25)

#: The accelerometer notebook's papermill parameters that build :class:`PaperDParams`, by the part they
#: feed (notebook name -> field name): the experiment, the first unit's coefficients, the fish swarm,
#: ANFIS's epochs, and the fields taken as they are (sequences as tuples).
NOTEBOOK_EXPERIMENT = {
    "t_start_c": "t_start_c",
    "t_stop_c": "t_stop_c",
    "t_step_c": "t_step_c",
    "noise_ug": "noise_ug",
}
NOTEBOOK_COEFFICIENTS = {"bias_step_mg": "bias_step_mg"}
NOTEBOOK_SWARM = {
    "n_fish": "n_fish",
    "generations": "generations",
    "try_number": "try_number",
    "visual": "visual",
    "step": "step",
    "crowd_delta": "delta",
    "improved": "improved",
}
NOTEBOOK_ANFIS = {"anfis_epochs": "epochs"}
NOTEBOOK_FIELDS = ("batch_spread_rel", "fis_radius", "max_rules")
NOTEBOOK_TUPLES = ("held_out_c", "check_c", "seeds", "grid_squash")
#: The notebook's other parameters (the noise study, unit B's sweep, the workbench trials, the workers):
#: :meth:`PaperDParams.from_notebook` checks the first four as the notebook does and builds nothing from
#: them.
NOTEBOOK_OTHER = (
    "noise_levels",
    "batch_spreads",
    "unit_b_draws",
    "trial_ratios",
    "trial_seeds",
    "n_workers",
    "scheduler",
)
#: Every parameter of the accelerometer notebook's ``parameters`` cell.
NOTEBOOK_KEYS = (
    *NOTEBOOK_EXPERIMENT,
    *NOTEBOOK_COEFFICIENTS,
    *NOTEBOOK_SWARM,
    *NOTEBOOK_ANFIS,
    *NOTEBOOK_FIELDS,
    *NOTEBOOK_TUPLES,
    *NOTEBOOK_OTHER,
)


@dataclass(frozen=True)
class PaperDParams:
    """Everything a reader may change in the accelerometer chapter (see the chapter for the story)."""

    experiment: TumbleExperiment = TumbleExperiment()
    coefficients: AccelCoefficients = AccelCoefficients()
    batch_spread_rel: float = 0.25
    held_out_c: tuple = (-30.0, 5.0, 40.0)
    check_c: tuple = (-15.0, 20.0, 65.0)
    fis_radius: float = 0.5
    anfis: AnfisOptions = AnfisOptions(epochs=40)
    swarm: FishSwarmParams = FishSwarmParams()
    radius_bounds: tuple = (0.08, 1.0)
    squash_bounds: tuple = (1.0, 2.0)
    max_rules: int = 40
    mlp: MLPParams = MLPParams(n_in=2, n_hidden=8, n_out=1, epochs=40)
    poly_degree: int = 3
    seeds: tuple = (0, 1, 2, 3, 4, 5)
    split_mode: str = "temperatures"
    tuners: bool = False
    grid_squash: tuple = (1.0, 1.25, 1.5, 2.0)

    def __post_init__(self):
        if self.split_mode not in SPLIT_MODES:
            raise InputError(
                f"parameter split_mode={self.split_mode!r}: must be one of {SPLIT_MODES}"
            )
        if not isinstance(self.tuners, (bool, np.bool_)):
            raise InputError(f"parameter tuners={self.tuners!r}: must be True or False")
        if len(self.grid_squash) < 1:
            raise InputError("parameter grid_squash: give at least one rb/ra value")
        for q in self.grid_squash:
            check_param("grid_squash", q, lo=self.squash_bounds[0], hi=self.squash_bounds[1])
        sp = self.experiment.set_points_c
        for name in ("held_out_c", "check_c"):
            for t in getattr(self, name):
                check_param(name, t, lo=-60, hi=130)
                if not np.any(np.isclose(sp, t)):
                    raise InputError(
                        f"parameter {name}: {t:g} degC is not a set point of the experiment "
                        f"({sp[0]:g}..{sp[-1]:g} step {self.experiment.t_step_c:g})"
                    )
                if np.isclose(t, self.experiment.reference_c):
                    raise InputError(
                        f"parameter {name}: {t:g} degC is the reference temperature; keep it "
                        "for training"
                    )
        if set(np.round(self.held_out_c, 6)) & set(np.round(self.check_c, 6)):
            raise InputError("parameters held_out_c and check_c share a temperature")
        n_train = sp.size - len(self.held_out_c) - len(self.check_c)
        check_param("batch_spread_rel", self.batch_spread_rel, lo=0, hi=1)
        check_param("fis_radius", self.fis_radius, lo=0.01, hi=10)
        check_param("max_rules", self.max_rules, lo=1, hi=500, integer=True)
        check_param("poly_degree", self.poly_degree, lo=0, hi=6, integer=True)
        if n_train < self.poly_degree + 1:
            raise InputError(
                f"parameters held_out_c/check_c: {n_train} training temperatures left, the "
                f"degree-{self.poly_degree} polynomials need at least {self.poly_degree + 1}"
            )
        for name in ("radius_bounds", "squash_bounds"):
            lo, hi = getattr(self, name)
            check_param(name, lo, lo=0.01, hi=10)
            check_param(name, hi, lo=0.01, hi=10)
            if hi <= lo:
                raise InputError(
                    f"parameter {name}={getattr(self, name)!r}: low must be below high"
                )
        if self.squash_bounds[0] < 1.0:
            raise InputError(
                f"parameter squash_bounds={self.squash_bounds!r}: rb >= ra (squash >= 1)"
            )
        if len(self.seeds) < 1:
            raise InputError("parameter seeds: give at least one seed")
        for s in self.seeds:
            check_param("seeds", s, lo=0, integer=True)
        if self.mlp.n_in != 2 or self.mlp.n_out != 1:
            raise InputError("parameter mlp: the ANN baseline is a 2-n-1 net (n_in=2, n_out=1)")

    @classmethod
    def from_notebook(cls, **cell) -> PaperDParams:
        """The chapter's parameters from the accelerometer notebook's flat papermill parameters
        (:data:`NOTEBOOK_KEYS`), built as the notebook's mapping cell builds them: ``noise_ug`` and the
        ``t_*_c`` set points make the :class:`~navlib.sensors.accelerometer.TumbleExperiment`,
        ``bias_step_mg`` the :class:`~navlib.sensors.accelerometer.AccelCoefficients`, ``n_fish``,
        ``generations``, ``try_number``, ``visual``, ``step``, ``crowd_delta`` and ``improved`` the
        :class:`~navlib.methods.fish_swarm.FishSwarmParams`, ``anfis_epochs`` the
        :class:`~navlib.methods.anfis.AnfisOptions`; the rest are fields (sequences as tuples).  A part whose
        parameters are all absent keeps its default; ``trial_ratios``, ``trial_seeds``, ``noise_levels`` and
        ``batch_spreads`` are checked as the notebook checks them; ``unit_b_draws``, ``n_workers`` and
        ``scheduler`` are accepted and not used.  An unknown name raises :class:`~navlib.errors.InputError`.
        """
        unknown = [k for k in cell if k not in NOTEBOOK_KEYS]
        if unknown:
            raise InputError(
                f"parameter {unknown[0]!r}: not a parameter of the accelerometer notebook "
                f"(those are {', '.join(NOTEBOOK_KEYS)})"
            )
        kw = {}
        for field_name, make, names in (
            ("coefficients", AccelCoefficients, NOTEBOOK_COEFFICIENTS),
            ("experiment", TumbleExperiment, NOTEBOOK_EXPERIMENT),
            ("anfis", AnfisOptions, NOTEBOOK_ANFIS),
            ("swarm", FishSwarmParams, NOTEBOOK_SWARM),
        ):
            given = {names[k]: cell[k] for k in names if k in cell}
            if given:
                kw[field_name] = make(**given)
        for k in NOTEBOOK_TUPLES:
            if k in cell:
                kw[k] = tuple(cell[k])
        kw.update({k: cell[k] for k in NOTEBOOK_FIELDS if k in cell})
        params = cls(**kw)
        for r in cell.get("trial_ratios", ()):
            check_param("trial_ratios", r, lo=0, lo_open=True, hi=100)
        if "trial_seeds" in cell:
            check_param("trial_seeds", cell["trial_seeds"], lo=1, hi=200, integer=True)
        if "noise_levels" in cell:  # how many levels: at least one
            check_param("noise_levels", len(cell["noise_levels"]), lo=1, integer=True)
        for s in cell.get("batch_spreads", ()):
            check_param("batch_spreads", s, lo=0, lo_open=True, hi=1)
        return params


# ------------------------------------------------------------------------------ the paper's printed numbers
def paper_numbers(path=PAPER_FILE) -> pd.DataFrame:
    """Paper D's printed numbers (``data/paper_d_results.csv``: key, method, value_mg, printed, source)."""
    df = read_table(path, [Column("value_mg", "mg")], kind="paper results table")
    return df


def _paper_value(paper: pd.DataFrame, key: str, method: str = "") -> float:
    g = paper[(paper["key"] == key) & (paper["method"].fillna("") == method)]
    if len(g) != 1:
        raise InputError(
            f"{PAPER_FILE.name}: expected one row key={key!r} method={method!r}, found {len(g)}"
        )
    return float(g["value_mg"].iloc[0])
