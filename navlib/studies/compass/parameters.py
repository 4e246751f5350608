"""The compass chapter's settings: the methods' settings (:data:`StudyParams`), the method lists and
constants of its studies, how the robustness study draws its compasses (:class:`CompassDrawRule`), and
:func:`params_from_notebook`, which turns the notebook's flat papermill parameters into these objects.

The methods, their ids, labels, readings and settings are registered in
:mod:`navlib.methods.compass_methods` (``METHODS``, ``READINGS``, ``MethodParams``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ...errors import InputError, check_param
from ...methods.bpnet import AdamParams
from ...methods.compass_methods import (
    ADE_RULE_READINGS,
    LS_MODELS,
    R1,
    R2,
    R2V,
    R4,
    R4V,
    READINGS,
    RULE_READINGS,
    MethodParams,
)
from ...methods.de import DEParams
from ...methods.lm import LMParams
from ...sensors.compass import CompassErrors

#: The chapter's name for the methods' settings (:class:`navlib.methods.compass_methods.MethodParams`).
StudyParams = MethodParams


#: The methods of the chapter's main table, in display order.
MAIN_METHODS = (
    (
        "uncompensated",
        "ls8",
        "ls8_planar",
        "ls8_h3",
        "bp_matlab",
        "bp_matlab_val",
        "bp_adam",
        "de_bp_pure",
        "ade_bp_pure",
        "de_bp_hybrid_trainlm",
        "ade_bp_hybrid_trainlm",
        "de_bp_hybrid_trainlm_val",
        "ade_bp_hybrid_trainlm_val",
        "de_bp_full_trainlm",
        "ade_bp_full_trainlm",
        "de_bp_full_trainlm_val",
        "ade_bp_full_trainlm_val",
    )
    + tuple(
        f"ade_bp_{v}_{sfx}" for _, _, sfx, _ in ADE_RULE_READINGS for v in ("pure", "full_trainlm")
    )
    + ("elm", "elm_backtuned", "physical")
)
#: The same with the Adam extra as the "BP" (for the ordering probabilities).
BP_VARIANTS = ("bp_matlab", "bp_matlab_val", "bp_adam")


#: The magnetometer noise levels (uT) on which the physical model's floor is scanned.
FLOOR_GRID_UT = np.linspace(0.0025, 0.1, 40)


#: The reading of the rows that train no network (the uncompensated compass, least squares): they do not
#: depend on how paper A trained its nets.
R_ANY = "any reading (no network trained)"
#: Numbers of equally spaced positions of sweep 1 the least squares is fitted on (paper A's "LS accuracy
#: depends on the sample size"): divisors of the 120 distinct headings of a 3-deg sweep, from 5 (the fewest
#: that determine Smith's five terms) to 120 (every reading).
LS_POSITIONS = (5, 6, 8, 12, 24, 40, 120)
#: The reference count: at 24 positions 15 deg apart only harmonics of order 22 and above alias onto the
#: fitted ones (negligible on our compass), so the fit is as good as the model allows.
LS_REF_POSITIONS = 24


#: The readings whose columns form the chapter's main verdict table (ADE's rule readings have their own).
BASE_READINGS = (R1, R2, R2V, R4, R4V)
#: The methods of the noise study: the base readings' methods, the LS models, the extras and the floor
#: (ADE's rule readings are judged at the default noise only).
NOISE_METHODS = tuple(
    m for m in MAIN_METHODS if not any(m == ade for ade in RULE_READINGS.values())
)


#: Training-error levels (RMS over the training sweep, deg) whose fitness J = N rms^2 the convergence study
#: times: chosen before the runs, a decade apart from a coarse fit to the noise-floor region.
CONVERGENCE_RMS_DEG = (10.0, 3.0, 1.0)
#: Where the convergence study also compares the curves at a fixed generation, as fractions of the DE budget
#: G (a decade apart, like the levels): at G/10 and at G (the late stage, where the paper puts ADE's gain).
#: A level that no run reaches within G times nothing (every run counts G + 1); the training RMS at a fixed
#: generation is never censored.
CONVERGENCE_AT_FRACTIONS = (0.1, 1.0)


#: The DE search boxes of :func:`~navlib.studies.compass.turntable.choices_study` (the paper gives none; the
#: chapter's default is 10).
BOX_BOUNDS = (2.0, 5.0, 10.0, 20.0)


# ----------------------------------------------------------------------------------------------- robustness
@dataclass(frozen=True)
class CompassDrawRule:
    """How the robustness study draws its simulated compasses: every error source of
    :class:`navlib.sensors.compass.CompassErrors` uniform in a stated range (hard iron: horizontal
    magnitude a fraction ``hard_frac`` of H at a uniform angle, vertical ``hard_z_ut``; soft iron: every
    entry of S in ``(-soft, soft)``; scale and non-orthogonality per axis; tilt (roll, pitch) and yaw
    misalignment), draw ``k`` from ``SeedSequence(seed, spawn_key=(k,))``.  A draw is kept when its
    noiseless uncompensated error envelope lies within ``tolerance_deg`` of the paper's (both ends); the
    first ``n_compasses`` kept, in draw order, are the study's compasses (at most ``max_draws`` tried).
    Ranges chosen before any run: a carrier a decimetre from steel (hard iron up to 0.6 H, soft iron up to
    10 %), a few degrees of mounting tilt and yaw, 3 % scale and half a degree of non-orthogonality."""

    n_compasses: int = 5
    hard_frac: tuple[float, float] = (0.2, 0.6)
    hard_z_ut: float = 5.0
    soft: float = 0.10
    scale: float = 0.03
    nonorth_deg: float = 0.5
    tilt_deg: float = 3.0
    yaw_deg: float = 5.0
    tolerance_deg: float = 2.0
    seed: int = 7
    max_draws: int = 20000

    def __post_init__(self):
        check_param("n_compasses", self.n_compasses, lo=1, integer=True)
        if not 0 <= self.hard_frac[0] < self.hard_frac[1] < 1:
            raise InputError(f"parameter hard_frac={self.hard_frac}: need 0 <= low < high < 1")
        for name in ("hard_z_ut", "nonorth_deg", "tilt_deg", "yaw_deg"):
            check_param(name, getattr(self, name), lo=0)
        check_param("soft", self.soft, lo=0, hi=0.5)
        check_param("scale", self.scale, lo=0, hi=0.4)
        check_param("tolerance_deg", self.tolerance_deg, lo=0, lo_open=True)
        check_param("seed", self.seed, lo=0, integer=True)
        check_param("max_draws", self.max_draws, lo=1, integer=True)


#: The methods of the robustness study: every reading's methods (ADE's rule readings included), the LS
#: models and the floor.
ROBUST_METHODS = tuple(
    dict.fromkeys([i for ids in READINGS.values() for i in ids] + list(LS_MODELS) + ["physical"])
)


# ------------------------------------------------------------------------------------- the notebook's parameters
#: The widest tolerance of the 8-position LS on the real sweeps (half the 45-deg spacing: no reading serves two
#: positions; :func:`navlib.studies.compass.real.real_compass_study`).
LS_TOLERANCE_MAX_DEG = 22.5

#: The compass notebook's papermill parameters (its ``parameters`` cell) and their defaults: the keys
#: :func:`params_from_notebook` takes.
NOTEBOOK_DEFAULTS = {
    "sweep_csv": "../data/compass_sweeps.csv",
    "simulate": False,
    "noise_ut": 0.04,
    "error_scale": 1.0,
    "sim_seed": 2024,
    "headline_seed": 0,
    "n_seeds": 20,
    "n_hidden": 6,
    "pop_size": 95,
    "max_generations": 3000,
    "target_fitness": 0.2,
    "pure_target": "deg2",
    "hybrid_target": "normalised",
    "de_f": 0.5,
    "de_cr": 0.6,
    "ade_f_min": 0.3,
    "ade_f_max": 0.9,
    "ade_cr_min": 0.1,
    "ade_cr_max": 0.9,
    "weight_bound": 10.0,
    "lm_epochs": 1000,
    "lm_max_fail": 6,
    "bp_epochs": 3000,
    "bp_lr": 0.01,
    "noise_levels_ut": [0.005, 0.02, 0.1],
    "n_noise_seeds": 4,
    "n_implied_seeds": 8,
    "n_robust_seeds": 6,
    "n_box_seeds": 4,
    "n_budget_seeds": 3,
    "n_target_seeds": 5,
    "n_compasses": 5,
    "robust_tolerance_deg": 2.0,
    "robust_seed": 7,
    "n_workers": 2,
    "scheduler": None,
    "elm_nodes": 19,
    "elm_range": 5.0,
    "elm_max_nodes": 30,
    "elm_goal_deg": 0.1,
    "elm_max_iter": 200,
    "glitch_prob": 0.05,
    "glitch_ut": 15.0,
    "median_window": 3,
    "dot_threshold": 4.0,
    "small_sizes": [8, 15, 30, 60],
    "big_hidden": 50,
    "n_real_seeds": 10,
    "real_ls_tolerance_deg": 22.5,
}


class ChapterParams(NamedTuple):
    """What the compass notebook builds from its flat parameters (:func:`params_from_notebook`): the simulated
    compass (``errors``, :class:`navlib.sensors.compass.CompassErrors`), the methods' settings (``params``,
    :data:`StudyParams`) and how the robustness study draws its compasses (``draw_rule``,
    :class:`CompassDrawRule`)."""

    errors: CompassErrors
    params: StudyParams
    draw_rule: CompassDrawRule


def params_from_notebook(**cell) -> ChapterParams:
    """The compass notebook's papermill parameters (keys of :data:`NOTEBOOK_DEFAULTS`; a key left out takes
    its default) checked and turned into the chapter's objects, as the notebook's own cells did: the
    compass's deterministic errors scaled by ``error_scale`` with white noise ``noise_ut``, the network, DE,
    ``trainlm``, Adam and ELM settings, and the robustness study's draw rule.  The run counts, the
    tolerance of the LS on real sweeps, ``error_scale`` and the small-sample sizes are checked here;
    the other parameters are read by the notebook's cells as they are.

    Raises :class:`navlib.errors.InputError` naming the parameter: an unknown key, or a value out of range.
    """
    unknown = [k for k in cell if k not in NOTEBOOK_DEFAULTS]
    if unknown:
        raise InputError(
            f"compass notebook: unknown parameter {unknown[0]!r} (not in the notebook's parameters "
            f"cell)"
        )
    p = {**NOTEBOOK_DEFAULTS, **cell}
    check_param("n_seeds", p["n_seeds"], lo=2, integer=True)
    check_param("n_noise_seeds", p["n_noise_seeds"], lo=1, integer=True)
    check_param("n_implied_seeds", p["n_implied_seeds"], lo=1, integer=True)
    check_param("n_robust_seeds", p["n_robust_seeds"], lo=2, integer=True)
    check_param("n_real_seeds", p["n_real_seeds"], lo=2, integer=True)
    check_param("real_ls_tolerance_deg", p["real_ls_tolerance_deg"], lo=0, hi=LS_TOLERANCE_MAX_DEG)
    for name in ("n_box_seeds", "n_budget_seeds", "n_target_seeds"):
        check_param(name, p[name], lo=1, hi=p["n_seeds"], integer=True)
    check_param("error_scale", p["error_scale"], lo=0)
    for n in p["small_sizes"]:
        check_param("small_sizes", n, lo=6, hi=121, integer=True)
    errors = replace(CompassErrors().scaled(p["error_scale"]), noise_ut=p["noise_ut"])
    params = StudyParams(
        n_hidden=p["n_hidden"],
        de=DEParams(
            pop_size=p["pop_size"],
            max_generations=p["max_generations"],
            target_fitness=p["target_fitness"],
            f=p["de_f"],
            cr=p["de_cr"],
            f_min=p["ade_f_min"],
            f_max=p["ade_f_max"],
            cr_min=p["ade_cr_min"],
            cr_max=p["ade_cr_max"],
            bound=p["weight_bound"],
        ),
        pure_target=p["pure_target"],
        hybrid_target=p["hybrid_target"],
        lm=LMParams(epochs=p["lm_epochs"], max_fail=p["lm_max_fail"]),
        adam=AdamParams(epochs=p["bp_epochs"], lr=p["bp_lr"]),
        elm_nodes=p["elm_nodes"],
        elm_range=p["elm_range"],
        elm_max_nodes=p["elm_max_nodes"],
        elm_goal_deg=p["elm_goal_deg"],
        elm_max_iter=p["elm_max_iter"],
    )
    draw_rule = CompassDrawRule(
        n_compasses=p["n_compasses"], tolerance_deg=p["robust_tolerance_deg"], seed=p["robust_seed"]
    )
    return ChapterParams(errors, params, draw_rule)
