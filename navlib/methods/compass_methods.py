"""The compass's compensation methods of paper A and document B, as one registry: stable ids, display
labels, factories and their settings, for every study and tool that fits them (the compass chapter's
:mod:`navlib.studies.compass`, the workbench's ``navlib compare``).

Every method follows :mod:`navlib.methods.compensator`'s protocol (``fit`` or ``fit_many`` -> a fitted
compensator with ``correct``).  Registered in :data:`METHODS` (labels are for display only):

- ``uncompensated``; ``ls8``, ``ls8_planar``, ``ls8_h3`` (paper A's 8-position least squares at 0, 45, ...,
  315 deg true heading under Smith's A..E, the exact planar model and the 3rd-order harmonic series,
  :class:`EightPosition`); ``physical`` (the exact planar model fitted to every training reading,
  :class:`PlanarFit`);
- reading 1, pure DE training: ``de_bp_pure``, ``ade_bp_pure`` (:func:`navlib.methods.bpnet.train_de_many`;
  the paper's target 0.2 read in deg^2, where it never fires);
- reading 2, DE-initialised BP: ``de_bp_hybrid_trainlm``, ``ade_bp_hybrid_trainlm`` and the ``_val``
  variants with MATLAB's dividerand split and validation stop
  (:func:`navlib.methods.bpnet.train_hybrid_many`; the target 0.2 read as a sum of squares of the
  normalised errors, which ends the DE stage early);
- reading 4, the full DE stage then ``trainlm``: ``de_bp_full_trainlm``, ``ade_bp_full_trainlm`` (and
  ``_val``), the primary reading of paper A's claims register (``data/claims_paper_a.csv``);
- reading 3, the paper's "BP" as MATLAB creates it: ``bp_matlab``, ``bp_matlab_val``
  (:func:`navlib.methods.bpnet.train_matlab_bp_many`);
- the readings of ADE's adaptive rules (:data:`ADE_RULE_READINGS`) in pure DE and in full DE + trainlm;
- extras: ``bp_adam`` (Adam from U(-1, 1)), ``bp_scipy_lm`` (MINPACK LM from U(-1, 1));
- document B: ``elm`` (:func:`navlib.methods.elm.fit_elm`), ``elm_backtuned`` (the patent's back-tuned
  incremental ELM, :func:`navlib.methods.elm.fit_incremental_elm`).

Sources: paper A (Yue et al., the 1-M-1 BP net, DE-BP and ADE-BP, eqs 1-6; 8-position least squares),
document B (the ELM with back-tuning); the readings and why reading 4 is the primary one are in
``data/claims_paper_a.csv``.  The measured heading handed to ``fit`` and ``correct`` may be unwrapped (the
networks need a continuous input; the explicit models are periodic and do not mind).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Literal

import numpy as np

from ..errors import InputError, check_choice, check_param
from .bpnet import (
    AdamParams,
    train_adam_many,
    train_de_family,
    train_de_many,
    train_hybrid_many,
    train_least_squares,
    train_matlab_bp_many,
)
from .compensator import (
    HeadingTarget,
    MethodBase,
    ModelCompensator,
    NetworkCompensator,
    ScaledRegressor,
)
from .de import DEParams
from .elm import ELMParams, IncrementalELMParams, fit_elm, fit_incremental_elm
from .lm import LMParams
from .seeding import generators
from .smith import eight_position_indices, fit_smith
from ..sensors.planar import fit_planar_model


@dataclass(frozen=True)
class MethodParams:
    """Everything a reader may change in the compass chapter. Defaults are paper A's settings (DE, ADE)
    and MATLAB's defaults (``trainlm``).

    ``de``: the DE settings of both DE-BP and ADE-BP (``adaptive`` is set per method);
    ``pure_target``/``hybrid_target``: how the paper's stopping value ``de.target_fitness`` is read in
    readings 1 and 2 (``'deg2'`` or ``'normalised'``, see :func:`navlib.methods.bpnet.train_hybrid_many`);
    ``lm``: ``trainlm`` settings; ``adam``: the Adam extra row; ``network_target``: what the networks learn
    (:class:`navlib.methods.compensator.HeadingTarget`).  The ``elm_*`` fields are our a-priori choices for
    document B (the patent gives no numbers).  ``ls_tol_deg``: how far from each of the 8 positions the
    reading the 8-position LS uses may lie (default: at the position, paper A's turntable; at most 22.5 deg,
    half the spacing, so that no reading serves two positions)."""

    n_hidden: int = 6
    de: DEParams = DEParams()
    pure_target: Literal["deg2", "normalised"] = "deg2"
    hybrid_target: Literal["deg2", "normalised"] = "normalised"
    lm: LMParams = LMParams()
    adam: AdamParams = AdamParams()
    network_target: Literal["heading", "error"] = "heading"
    elm_nodes: int = 19  # plain ELM: 19 trained output weights = the 19 weights of the 1-6-1 net
    elm_range: float = 5.0  # input weights and biases ~ U(-elm_range, elm_range) (Huang 2006: 1)
    elm_max_nodes: int = 30  # incremental ELM: cap on the hidden-node count
    elm_goal_deg: float = 0.1  # incremental ELM: stop when the training RMS error (deg) is <= this
    elm_max_iter: int = 200  # incremental ELM: the patent's k (ELM and tuning stages together)
    #: incremental ELM: prune nodes with max ``|beta_j|`` <= this after each ELM solve (the library default)
    elm_prune_tol: float = IncrementalELMParams.prune_tol
    ls_tol_deg: float = (
        1e-6  # 8-position LS: the reading used for a position lies within this of it
    )

    def __post_init__(self):
        check_param("n_hidden", self.n_hidden, lo=1, integer=True)
        for name, cls in (("de", DEParams), ("lm", LMParams), ("adam", AdamParams)):
            if not isinstance(getattr(self, name), cls):
                raise InputError(f"parameter {name}: must be a {cls.__name__}")
        check_choice("pure_target", self.pure_target, ("deg2", "normalised"))
        check_choice("hybrid_target", self.hybrid_target, ("deg2", "normalised"))
        check_choice("network_target", self.network_target, ("heading", "error"))
        check_param("elm_nodes", self.elm_nodes, lo=1, integer=True)
        check_param("elm_range", self.elm_range, lo=0, lo_open=True)
        check_param("elm_max_nodes", self.elm_max_nodes, lo=1, integer=True)
        check_param("elm_goal_deg", self.elm_goal_deg, lo=0)
        check_param("elm_max_iter", self.elm_max_iter, lo=1, integer=True)
        check_param("elm_prune_tol", self.elm_prune_tol, lo=0)
        check_param("ls_tol_deg", self.ls_tol_deg, lo=0, hi=22.5)

    @property
    def target(self) -> HeadingTarget:
        return HeadingTarget(self.network_target)

    def elm_params(self) -> ELMParams:
        return ELMParams(
            n_hidden=self.elm_nodes, weight_range=self.elm_range, bias_range=self.elm_range
        )

    def incremental_params(self, target_span_deg: float) -> IncrementalELMParams:
        """The incremental ELM's settings; the goal in degrees becomes a normalised MSE through the span of
        the training target (360 deg for the heading, about 47 deg for the error of the default compass)."""
        return IncrementalELMParams(
            max_nodes=self.elm_max_nodes,
            loss_goal=(self.elm_goal_deg / float(target_span_deg)) ** 2,
            max_iter=self.elm_max_iter,
            prune_tol=self.elm_prune_tol,
            weight_range=self.elm_range,
            bias_range=self.elm_range,
        )


# ----------------------------------------------------------------------------------------------- methods
class Uncompensated(MethodBase):
    """No compensation: the measured heading as it is."""

    def fit(self, measured_deg, reference_deg, rng=None):
        return ModelCompensator(None)


@dataclass
class EightPosition(MethodBase):
    """Paper A's 8-position least squares (readings at 0, 45, ..., 315 deg true heading) under one model:
    ``'smith'`` (Smith's A..E, 5 terms), ``'harmonic3'`` (the harmonic series to 3rd order, 7 terms) or
    ``'planar'`` (the exact 5-parameter hard/soft-iron model of :mod:`navlib.sensors.planar`).  ``step_deg``:
    the spacing of the positions (45 deg: paper A's 8; the compass chapter varies it); ``tol_deg``: how far
    the reading used for a position may lie from it (:func:`navlib.methods.smith.eight_position_indices`:
    the nearest reading, which must lie within ``tol_deg``; the default asks for a reading at the position
    itself, as on paper A's turntable).  Smith's model is fitted by linear least squares on the 8 readings
    (:func:`navlib.methods.smith.fit_smith`), the planar one by nonlinear least squares
    (:func:`navlib.sensors.planar.fit_planar_model`)."""

    model: str = "smith"
    step_deg: float = 45.0
    tol_deg: float = 1e-6

    def __post_init__(self):
        check_choice("8-position model", self.model, ("smith", "harmonic3", "planar"))
        check_param("step_deg", self.step_deg, lo=0, lo_open=True, hi=180)
        check_param("tol_deg", self.tol_deg, lo=0)

    def fit(self, measured_deg, reference_deg, rng=None):
        m, t = np.asarray(measured_deg, float), np.asarray(reference_deg, float)
        idx = eight_position_indices(t, self.step_deg, self.tol_deg)
        if self.model == "planar":
            return ModelCompensator(fit_planar_model(t[idx], np.mod(m[idx], 360.0)))
        return ModelCompensator(
            fit_smith(np.mod(m[idx], 360.0), t[idx], 3 if self.model == "harmonic3" else 2)
        )


class PlanarFit(MethodBase):
    """The exact planar model (:func:`navlib.sensors.planar.fit_planar_model`) fitted to every training
    reading: the noise floor of a simulated compass, whose errors are that model."""

    def fit(self, measured_deg, reference_deg, rng=None):
        return ModelCompensator(fit_planar_model(reference_deg, np.mod(measured_deg, 360.0)))


@dataclass
class NetworkMethod(MethodBase):
    """A network method: ``train(x, target, rngs) -> list of nets`` on the target chosen by ``target``."""

    train: Callable
    target: HeadingTarget

    def fit_many(self, measured_deg, reference_deg, rngs):
        x = np.asarray(measured_deg, dtype=float)
        nets = self.train(x, self.target.target(x, reference_deg), list(rngs))
        return [NetworkCompensator(n, self.target, dict(getattr(n, "info", {}))) for n in nets]


def elm_trainer(params: MethodParams, back_tuned: bool):
    """Plain ELM or the patent's back-tuned incremental ELM on min-max normalised data; ``info`` has
    ``n_nodes`` and, for the back-tuned ELM, the stage ``history`` of
    :func:`navlib.methods.elm.fit_incremental_elm`."""

    def train(x, t, rngs):
        out = []
        for g in rngs:
            info = {}
            if back_tuned:
                goal = params.incremental_params(float(np.ptp(t)))

                def fit(xn, tn):
                    model, info["history"] = fit_incremental_elm(xn, tn, goal, rng=g)
                    return model
            else:

                def fit(xn, tn):
                    return fit_elm(xn, tn, params.elm_params(), rng=g)

            reg = ScaledRegressor.fit(x, t, fit)
            reg.info = dict(info, n_nodes=reg.n_hidden)
            out.append(reg)
        return out

    return train


@dataclass(frozen=True)
class MethodSpec:
    """A registered method: display ``label``, ``factory(params) -> method``, whether it is stochastic,
    the row of ``data/paper_a_error_ranges.csv`` it answers (or None), and its ``reading``."""

    label: str
    factory: Callable[[MethodParams], MethodBase]
    stochastic: bool
    paper_row: str | None = None
    reading: str = ""
    #: runs sharing one DE stage: ``((adaptive, f_rule, cr_rule), variant)`` for the full stage,
    #: ``((adaptive, f_rule, cr_rule, "hybrid"), variant)`` for reading 2's stage (``hybrid_target``)
    family: tuple | None = None


def _reading2_stage(family_key: tuple) -> bool:
    """Whether a ``family`` key names reading 2's DE stage (the stop read by ``hybrid_target``)."""
    return family_key[3:] == ("hybrid",)


#: ADE's default rules (:class:`navlib.methods.de.DEParams`): F by generation, CR by value.
ADE_DEFAULT_RULES = ("generation", "value")
#: The other readings of ADE's rules in section 1.2, as (f_rule, cr_rule, id suffix, label part).
ADE_RULE_READINGS = (
    ("individual", "value", "f_ind", "F per individual"),
    ("combined", "value", "f_comb", "F combined"),
    ("generation", "rank", "cr_rank", "CR by rank"),
    ("individual", "rank", "f_ind_cr_rank", "F per individual, CR by rank"),
)


def _de(p: MethodParams, adaptive: bool, rules=ADE_DEFAULT_RULES) -> DEParams:
    return replace(p.de, adaptive=adaptive, f_rule=rules[0], cr_rule=rules[1])


def _pure(adaptive, rules=ADE_DEFAULT_RULES):
    def make(p):
        d = _de(p, adaptive, rules)
        if p.pure_target == "normalised":
            return NetworkMethod(
                lambda x, t, g: train_hybrid_many(x, t, p.n_hidden, d, g, replace(p.lm, epochs=0)),
                p.target,
            )
        return NetworkMethod(lambda x, t, g: train_de_many(x, t, p.n_hidden, d, g)[0], p.target)

    return make


def _hybrid(adaptive, validation):
    def make(p):
        d = _de(p, adaptive)
        return NetworkMethod(
            lambda x, t, g: train_hybrid_many(
                x, t, p.n_hidden, d, g, p.lm, validation, p.hybrid_target
            ),
            p.target,
        )

    return make


def _full(adaptive, validation, rules=ADE_DEFAULT_RULES):
    """The full DE stage (the paper's target read in deg^2, so all ``max_generations``), then trainlm."""

    def make(p):
        d = _de(p, adaptive, rules)
        return NetworkMethod(
            lambda x, t, g: train_hybrid_many(x, t, p.n_hidden, d, g, p.lm, validation, "deg2"),
            p.target,
        )

    return make


def _matlab(validation):
    return lambda p: NetworkMethod(
        lambda x, t, g: train_matlab_bp_many(x, t, p.n_hidden, g, p.lm, validation), p.target
    )


R1, R2, R2V = "1: pure DE", "2: DE + trainlm", "2: DE + trainlm, val. stop"
R4, R4V = "4: full DE + trainlm", "4: full DE + trainlm, val. stop"
R3, R3V, RA = "3: MATLAB BP", "3: MATLAB BP, val. stop", "extra: Adam"
_DE0, _ADE0 = (False,) + ADE_DEFAULT_RULES, (True,) + ADE_DEFAULT_RULES


def _eight(model: str):
    return lambda p: EightPosition(model, tol_deg=p.ls_tol_deg)


def rule_reading(base: str, label: str) -> str:
    """The name of the reading ``base`` (``R1`` or ``R4``) run with ADE's rules ``label`` (a label of
    :data:`ADE_RULE_READINGS`)."""
    return f"{base}, ADE {label}"


#: Every method by stable id: display label, factory, whether it is stochastic, the paper's row it answers,
#: its reading and its DE family (:class:`MethodSpec`).
METHODS: dict[str, MethodSpec] = {
    "uncompensated": MethodSpec("uncompensated", lambda p: Uncompensated(), False, "uncompensated"),
    "ls8": MethodSpec(
        "LS 8-position (Smith, 5 terms)", _eight("smith"), False, "8-position least squares"
    ),
    "ls8_planar": MethodSpec(
        "LS 8-position (planar, 5 par.)", _eight("planar"), False, "8-position least squares"
    ),
    "ls8_h3": MethodSpec(
        "LS 8-position (harmonic, 3rd order)",
        _eight("harmonic3"),
        False,
        "8-position least squares",
    ),
    "physical": MethodSpec("physical model", lambda p: PlanarFit(), False),
    "bp_matlab": MethodSpec("BP MATLAB (trainlm)", _matlab(False), True, "BP network", R3),
    "bp_matlab_val": MethodSpec(
        "BP MATLAB (trainlm, val. stop)", _matlab(True), True, "BP network", R3V
    ),
    "bp_adam": MethodSpec(
        "BP (Adam)",
        lambda p: NetworkMethod(
            lambda x, t, g: train_adam_many(x, t, p.n_hidden, p.adam, g), p.target
        ),
        True,
        "BP network",
        RA,
    ),
    "bp_scipy_lm": MethodSpec(
        "BP (scipy LM)",
        lambda p: NetworkMethod(
            lambda x, t, g: [train_least_squares(x, t, p.n_hidden, r) for r in g], p.target
        ),
        True,
    ),
    "de_bp_pure": MethodSpec("DE-BP pure", _pure(False), True, "DE-BP", R1, (_DE0, "pure")),
    "ade_bp_pure": MethodSpec("ADE-BP pure", _pure(True), True, "ADE-BP", R1, (_ADE0, "pure")),
    "de_bp_hybrid_trainlm": MethodSpec(
        "DE-BP hybrid (trainlm)",
        _hybrid(False, False),
        True,
        "DE-BP",
        R2,
        (_DE0 + ("hybrid",), "trainlm"),
    ),
    "ade_bp_hybrid_trainlm": MethodSpec(
        "ADE-BP hybrid (trainlm)",
        _hybrid(True, False),
        True,
        "ADE-BP",
        R2,
        (_ADE0 + ("hybrid",), "trainlm"),
    ),
    "de_bp_hybrid_trainlm_val": MethodSpec(
        "DE-BP hybrid (trainlm, val. stop)",
        _hybrid(False, True),
        True,
        "DE-BP",
        R2V,
        (_DE0 + ("hybrid",), "trainlm_val"),
    ),
    "ade_bp_hybrid_trainlm_val": MethodSpec(
        "ADE-BP hybrid (trainlm, val. stop)",
        _hybrid(True, True),
        True,
        "ADE-BP",
        R2V,
        (_ADE0 + ("hybrid",), "trainlm_val"),
    ),
    "de_bp_full_trainlm": MethodSpec(
        "DE-BP full DE + trainlm", _full(False, False), True, "DE-BP", R4, (_DE0, "trainlm")
    ),
    "ade_bp_full_trainlm": MethodSpec(
        "ADE-BP full DE + trainlm", _full(True, False), True, "ADE-BP", R4, (_ADE0, "trainlm")
    ),
    "de_bp_full_trainlm_val": MethodSpec(
        "DE-BP full DE + trainlm, val. stop",
        _full(False, True),
        True,
        "DE-BP",
        R4V,
        (_DE0, "trainlm_val"),
    ),
    "ade_bp_full_trainlm_val": MethodSpec(
        "ADE-BP full DE + trainlm, val. stop",
        _full(True, True),
        True,
        "ADE-BP",
        R4V,
        (_ADE0, "trainlm_val"),
    ),
    "elm": MethodSpec(
        "ELM", lambda p: NetworkMethod(elm_trainer(p, False), p.target), True, None, "document B"
    ),
    "elm_backtuned": MethodSpec(
        "ELM back-tuned",
        lambda p: NetworkMethod(elm_trainer(p, True), p.target),
        True,
        None,
        "document B",
    ),
}
#: Each reading of ADE's rules (:data:`ADE_RULE_READINGS`), in pure DE and in full DE + trainlm: the ADE-BP
#: of that reading (DE-BP is unchanged).
RULE_READINGS: dict[str, str] = {}
for _f, _c, _sfx, _lab in ADE_RULE_READINGS:
    _key = (True, _f, _c)
    METHODS[f"ade_bp_pure_{_sfx}"] = MethodSpec(
        f"ADE-BP {_lab}",
        _pure(True, (_f, _c)),
        True,
        "ADE-BP",
        rule_reading(R1, _lab),
        (_key, "pure"),
    )
    METHODS[f"ade_bp_full_trainlm_{_sfx}"] = MethodSpec(
        f"ADE-BP {_lab}, full DE + trainlm",
        _full(True, False, (_f, _c)),
        True,
        "ADE-BP",
        rule_reading(R4, _lab),
        (_key, "trainlm"),
    )
    RULE_READINGS[rule_reading(R1, _lab)] = f"ade_bp_pure_{_sfx}"
    RULE_READINGS[rule_reading(R4, _lab)] = f"ade_bp_full_trainlm_{_sfx}"

#: The 8-position least squares under each model (paper A does not print its model): id -> short name.
LS_MODELS = {"ls8": "Smith 5 terms", "ls8_planar": "planar 5 par.", "ls8_h3": "harmonic 3rd order"}
#: Document B's two ELMs.
ELM_METHODS = ("elm", "elm_backtuned")

#: Each reading of paper A's four methods: (LS, BP, DE-BP, ADE-BP) ids (LS: Smith's; every LS claim is
#: judged once per model of :data:`LS_MODELS`).  The readings of ADE's rules change only ADE-BP: their
#: claims are those that involve ADE-BP (:data:`RULE_READINGS`).
READINGS: dict[str, tuple[str, str, str, str]] = {
    R1: ("ls8", "bp_matlab", "de_bp_pure", "ade_bp_pure"),
    R2: ("ls8", "bp_matlab", "de_bp_hybrid_trainlm", "ade_bp_hybrid_trainlm"),
    R2V: ("ls8", "bp_matlab_val", "de_bp_hybrid_trainlm_val", "ade_bp_hybrid_trainlm_val"),
    R4: ("ls8", "bp_matlab", "de_bp_full_trainlm", "ade_bp_full_trainlm"),
    R4V: ("ls8", "bp_matlab_val", "de_bp_full_trainlm_val", "ade_bp_full_trainlm_val"),
}
for _r, _ade in RULE_READINGS.items():
    _base = READINGS[R1 if _r.startswith(R1) else R4]
    READINGS[_r] = _base[:3] + (_ade,)

#: The chapter's former display names, accepted by :func:`method_id` (the workbench notebook used them).
LEGACY_NAMES = {
    "ADE-BP": "ade_bp_pure",
    "DE-BP": "de_bp_pure",
    "BP (Adam)": "bp_adam",
    "BP (LM)": "bp_scipy_lm",
    "LS 8-position": "ls8",
    "physical model": "physical",
    "ELM": "elm",
    "ELM back-tuned": "elm_backtuned",
}


def method_id(name: str) -> str:
    """The registry id of ``name`` (an id, or one of :data:`LEGACY_NAMES`)."""
    if name in METHODS:
        return name
    if name in LEGACY_NAMES:
        return LEGACY_NAMES[name]
    raise InputError(f"unknown method {name!r}; known: {', '.join(METHODS)}")


def label(mid: str) -> str:
    """Display label of a method id."""
    return METHODS[method_id(mid)].label


def fit_method(
    method: str,
    x,
    reference,
    params: MethodParams = MethodParams(),
    seeds=(0,),
    base_seed: int = 0,
    rngs=None,
):
    """Fit ``method`` (an id of ``METHODS``) on measured headings ``x`` (unwrapped) and true headings,
    one run per seed (run ``k`` uses generator ``k`` of :func:`navlib.seeding.generators`), or one run per
    generator of ``rngs`` when given (a study that seeds its runs by spawn keys, :func:`navlib.seeding.sequence`).
    Returns the fitted compensators (one for a deterministic method)."""
    spec = METHODS[method_id(method)]
    if rngs is None:
        rngs = generators(seeds if spec.stochastic else [0], base_seed)
    elif not spec.stochastic:
        rngs = list(rngs)[:1]
    return spec.factory(params).fit_many(x, reference, list(rngs))


def fit_family(
    methods, x, reference, params: MethodParams = MethodParams(), seeds=(0,), base_seed: int = 0
) -> dict[str, list]:
    """Fit methods that share one DE stage (the same ``family`` key of :class:`MethodSpec`: pure DE and
    full DE + trainlm, with and without the validation stop, of one DE / ADE rule; or reading 2's DE +
    trainlm with and without the validation stop) from one stage per seed
    (:func:`navlib.methods.bpnet.train_de_family`): the same fitted compensators as
    :func:`fit_method` gives for each method alone, at the cost of one stage.  ``{method id: fitted}``."""
    mids = [method_id(m) for m in methods]
    fams = [METHODS[m].family for m in mids]
    if any(f is None for f in fams) or len({f[0] for f in fams}) != 1:
        raise InputError(f"fit_family: {', '.join(mids)} do not share one DE stage")
    if params.pure_target != "deg2" and any(f[1] == "pure" for f in fams):
        raise InputError("fit_family: pure DE shares the full stage only with pure_target='deg2'")
    adaptive, f_rule, cr_rule = fams[0][0][:3]
    d = replace(params.de, adaptive=adaptive, f_rule=f_rule, cr_rule=cr_rule)
    xx = np.asarray(x, dtype=float)
    tgt = params.target
    nets = train_de_family(
        xx,
        tgt.target(xx, reference),
        params.n_hidden,
        d,
        generators(seeds, base_seed),
        params.lm,
        [f[1] for f in fams],
        params.hybrid_target if _reading2_stage(fams[0][0]) else "deg2",
    )
    return {
        m: [NetworkCompensator(n, tgt, dict(getattr(n, "info", {}))) for n in nets[f[1]]]
        for m, f in zip(mids, fams)
    }


#: CPU seconds per run of each method at the chapter's defaults (measured; for ordering parallel tasks,
#: most expensive first).  Methods not listed count as cheap; a family of methods sharing one DE stage
#: costs the stage (``"de_stage"``) plus ``"trainlm"`` per trainlm variant.
RUN_COST_S = {
    "de_bp_pure": 0.3,
    "ade_bp_pure": 0.3,
    "de_bp_hybrid_trainlm": 0.14,
    "ade_bp_hybrid_trainlm": 0.07,
    "de_bp_hybrid_trainlm_val": 0.1,
    "ade_bp_hybrid_trainlm_val": 0.03,
    "bp_adam": 0.05,
    "bp_matlab": 0.06,
    "bp_matlab_val": 0.02,
    "elm_backtuned": 0.1,
    "de_stage": 0.3,
    "trainlm": 0.04,
}


def fitting_units(params: MethodParams, methods) -> list[tuple[str, ...]]:
    """The methods grouped into fitting units: the methods sharing one DE stage (``family``: the full
    stage, pure DE only with ``pure_target='deg2'``; or reading 2's stage) form one unit, every other
    method its own."""
    units, at = [], {}
    for m in methods:
        mid = method_id(m)
        fam = METHODS[mid].family
        if fam is not None and (fam[1] != "pure" or params.pure_target == "deg2"):
            if fam[0] in at:
                units[at[fam[0]]].append(mid)
                continue
            at[fam[0]] = len(units)
        units.append([mid])
    return [tuple(u) for u in units]


def unit_cost(unit, params: MethodParams) -> float:
    """Estimated CPU seconds per seed of a fitting unit (:data:`RUN_COST_S`)."""
    fams = [METHODS[m].family for m in unit]
    if len(unit) > 1 and _reading2_stage(fams[0][0]):  # reading 2's stage: the costliest member's
        c = max(RUN_COST_S.get(m, 0.001) for m in unit) + RUN_COST_S["trainlm"] * (len(unit) - 1)
    elif all(f is not None for f in fams) and (len(unit) > 1 or unit[0] not in RUN_COST_S):
        c = RUN_COST_S["de_stage"] + RUN_COST_S["trainlm"] * sum(f[1] != "pure" for f in fams)
    else:
        c = RUN_COST_S.get(unit[0], 0.001)
    return c * params.de.max_generations / 3000
