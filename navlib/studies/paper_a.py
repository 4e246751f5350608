"""Paper A's comparison under every plausible reading of its training, as one reusable study: every
compensation method trained on sweep 1 and scored on sweep 2, repeated over seeds for the stochastic ones.

Methods are registered in ``METHODS`` under stable ids (labels are for display only):

- ``uncompensated``; ``ls8`` (Smith's A..E fitted at 0, 45, ..., 315 deg, :mod:`navlib.methods.smith`);
  ``physical`` (the exact planar model fitted to all of sweep 1, our noise floor);
- reading 1, pure DE training: ``de_bp_pure``, ``ade_bp_pure`` (:func:`navlib.methods.bpnet.train_de_many`;
  the paper's target 0.2 read in deg^2, where it never fires);
- reading 2, DE-initialised BP: ``de_bp_hybrid_trainlm``, ``ade_bp_hybrid_trainlm`` and the ``_val``
  variants with MATLAB's dividerand split and validation stop
  (:func:`navlib.methods.bpnet.train_hybrid_many`; the target 0.2 read as a sum of squares of the
  normalised errors, which ends the DE stage early);
- reading 3, the paper's "BP" as MATLAB creates it: ``bp_matlab``, ``bp_matlab_val``
  (:func:`navlib.methods.bpnet.train_matlab_bp_many`);
- extras: ``bp_adam`` (Adam from U(-1, 1)), ``bp_scipy_lm`` (MINPACK LM from U(-1, 1));
- document B: ``elm``, ``elm_backtuned`` (:mod:`navlib.methods.elm`).

Error = compensated - true heading, wrapped to (-180, 180], on the test sweep.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Callable, Literal

import numpy as np
import pandas as pd
from scipy.stats import mannwhitneyu

from ..angles import wrap_deg
from ..data.compass_sweeps import unwrap_measured
from ..errors import InputError, check_choice, check_param
from ..methods.bpnet import (AdamParams, train_adam_many, train_de_many, train_hybrid_many,
                             train_least_squares, train_matlab_bp_many)
from ..methods.compensator import (HeadingTarget, MethodBase, ModelCompensator, NetworkCompensator,
                                   ScaledRegressor)
from ..methods.de import DEParams
from ..methods.elm import ELMParams, IncrementalELMParams, fit_elm, fit_incremental_elm
from ..methods.lm import LMParams
from ..methods.seeding import generators
from ..methods.smith import eight_position_indices, fit_smith
from ..report import Claim, method_stats
from ..sensors.compass import CompassErrors, simulate_train_test
from ..data.compass_sweeps import split_sweeps
from ..sensors.planar import fit_planar_model
from .parallel import run_tasks


@dataclass(frozen=True)
class StudyParams:
    """Everything a reader may change in the compass chapter. Defaults are paper A's settings (DE, ADE)
    and MATLAB's defaults (``trainlm``).

    ``de``: the DE settings of both DE-BP and ADE-BP (``adaptive`` is set per method);
    ``pure_target``/``hybrid_target``: how the paper's stopping value ``de.target_fitness`` is read in
    readings 1 and 2 (``'deg2'`` or ``'normalised'``, see :func:`navlib.methods.bpnet.train_hybrid_many`);
    ``lm``: ``trainlm`` settings; ``adam``: the Adam extra row; ``network_target``: what the networks learn
    (:class:`navlib.methods.compensator.HeadingTarget`).  The ``elm_*`` fields are our a-priori choices for
    document B (the patent gives no numbers)."""

    n_hidden: int = 6
    de: DEParams = DEParams()
    pure_target: Literal["deg2", "normalised"] = "deg2"
    hybrid_target: Literal["deg2", "normalised"] = "normalised"
    lm: LMParams = LMParams()
    adam: AdamParams = AdamParams()
    network_target: Literal["heading", "error"] = "heading"
    elm_nodes: int = 19          # plain ELM: 19 trained output weights = the 19 weights of the 1-6-1 net
    elm_range: float = 5.0       # input weights and biases ~ U(-elm_range, elm_range) (Huang 2006: 1)
    elm_max_nodes: int = 30      # incremental ELM: cap on the hidden-node count
    elm_goal_deg: float = 0.1    # incremental ELM: stop when the training RMS error (deg) is <= this
    elm_max_iter: int = 200      # incremental ELM: the patent's k (ELM and tuning stages together)

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

    @property
    def target(self) -> HeadingTarget:
        return HeadingTarget(self.network_target)

    def elm_params(self) -> ELMParams:
        return ELMParams(n_hidden=self.elm_nodes, weight_range=self.elm_range, bias_range=self.elm_range)

    def incremental_params(self, target_span_deg: float) -> IncrementalELMParams:
        """The incremental ELM's settings; the goal in degrees becomes a normalised MSE through the span of
        the training target (360 deg for the heading, about 47 deg for the error of the default compass)."""
        return IncrementalELMParams(max_nodes=self.elm_max_nodes,
                                    loss_goal=(self.elm_goal_deg / float(target_span_deg)) ** 2,
                                    max_iter=self.elm_max_iter, weight_range=self.elm_range,
                                    bias_range=self.elm_range)


def error_stats(err) -> dict:
    """Minimum, maximum and RMS (deg) of an error array."""
    e = np.asarray(err, dtype=float)
    return {"min_deg": float(e.min()), "max_deg": float(e.max()), "rms_deg": float(np.sqrt(np.mean(e ** 2)))}


def rms_deg(predicted, true) -> float:
    """RMS of the wrapped heading error (deg)."""
    e = wrap_deg(np.asarray(predicted, dtype=float) - np.asarray(true, dtype=float))
    return float(np.sqrt(np.mean(e ** 2)))


class Sweeps:
    """Training and test sweeps prepared once: true headings, measured headings (raw and unwrapped)."""

    def __init__(self, train: pd.DataFrame, test: pd.DataFrame):
        self.t_train = train["true_heading_deg"].to_numpy(float)
        self.m_train = train["measured_heading_deg"].to_numpy(float)
        self.t_test = test["true_heading_deg"].to_numpy(float)
        self.m_test = test["measured_heading_deg"].to_numpy(float)
        self.x_train = unwrap_measured(self.t_train, self.m_train)
        self.x_test = unwrap_measured(self.t_test, self.m_test)

    def subset(self, idx) -> "Sweeps":
        """The same test sweep with only the training readings ``idx`` (the measured heading is unwrapped
        again over the subset, as if only those readings had been taken)."""
        idx = np.asarray(idx, dtype=int)
        if idx.size < 2 or np.any(np.diff(idx) <= 0) or idx[0] < 0 or idx[-1] >= self.t_train.size:
            raise InputError(f"training subset: need at least 2 increasing indices within 0.."
                             f"{self.t_train.size - 1}")
        new = object.__new__(Sweeps)
        new.__dict__.update(self.__dict__)
        new.t_train, new.m_train = self.t_train[idx], self.m_train[idx]
        new.x_train = unwrap_measured(new.t_train, new.m_train)
        return new


def test_errors(corrected, sw: Sweeps) -> np.ndarray:
    """Wrapped test-sweep error (deg) of compensated headings."""
    return wrap_deg(np.asarray(corrected) - sw.t_test)


test_errors.__test__ = False     # not a pytest test


# ----------------------------------------------------------------------------------------------- methods
class _Uncompensated(MethodBase):
    def fit(self, measured_deg, reference_deg, rng=None):
        return ModelCompensator(None)


class _Smith8(MethodBase):
    def fit(self, measured_deg, reference_deg, rng=None):
        m, t = np.asarray(measured_deg, float), np.asarray(reference_deg, float)
        idx = eight_position_indices(t)
        return ModelCompensator(fit_smith(np.mod(m[idx], 360.0), t[idx]))


class _Planar(MethodBase):
    def fit(self, measured_deg, reference_deg, rng=None):
        return ModelCompensator(fit_planar_model(reference_deg, np.mod(measured_deg, 360.0)))


@dataclass
class _Network(MethodBase):
    """A network method: ``train(x, target, rngs) -> list of nets`` on the target chosen by ``target``."""

    train: Callable
    target: HeadingTarget

    def fit_many(self, measured_deg, reference_deg, rngs):
        x = np.asarray(measured_deg, dtype=float)
        nets = self.train(x, self.target.target(x, reference_deg), list(rngs))
        return [NetworkCompensator(n, self.target, dict(getattr(n, "info", {}))) for n in nets]


def _elm_train(params: StudyParams, back_tuned: bool):
    """Plain ELM or the patent's back-tuned incremental ELM on min-max normalised data; ``info`` has
    ``n_nodes`` and, for the back-tuned ELM, the stage ``history`` of :func:`fit_incremental_elm`."""
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
    factory: Callable[[StudyParams], MethodBase]
    stochastic: bool
    paper_row: str | None = None
    reading: str = ""


def _de(p: StudyParams, adaptive: bool) -> DEParams:
    return replace(p.de, adaptive=adaptive)


def _pure(adaptive):
    def make(p):
        d = _de(p, adaptive)
        if p.pure_target == "normalised":
            return _Network(lambda x, t, g: train_hybrid_many(x, t, p.n_hidden, d, g,
                                                              replace(p.lm, epochs=0)), p.target)
        return _Network(lambda x, t, g: train_de_many(x, t, p.n_hidden, d, g)[0], p.target)
    return make


def _hybrid(adaptive, validation):
    def make(p):
        d = _de(p, adaptive)
        return _Network(lambda x, t, g: train_hybrid_many(x, t, p.n_hidden, d, g, p.lm, validation,
                                                          p.hybrid_target), p.target)
    return make


def _matlab(validation):
    return lambda p: _Network(lambda x, t, g: train_matlab_bp_many(x, t, p.n_hidden, g, p.lm, validation),
                              p.target)


R1, R2, R2V = "1: pure DE", "2: DE + trainlm", "2: DE + trainlm, val. stop"
R3, R3V, RA = "3: MATLAB BP", "3: MATLAB BP, val. stop", "extra: Adam"

METHODS: dict[str, MethodSpec] = {
    "uncompensated": MethodSpec("uncompensated", lambda p: _Uncompensated(), False, "uncompensated"),
    "ls8": MethodSpec("LS 8-position", lambda p: _Smith8(), False, "8-position least squares"),
    "physical": MethodSpec("physical model", lambda p: _Planar(), False),
    "bp_matlab": MethodSpec("BP MATLAB (trainlm)", _matlab(False), True, "BP network", R3),
    "bp_matlab_val": MethodSpec("BP MATLAB (trainlm, val. stop)", _matlab(True), True, "BP network", R3V),
    "bp_adam": MethodSpec("BP (Adam)", lambda p: _Network(
        lambda x, t, g: train_adam_many(x, t, p.n_hidden, p.adam, g), p.target), True, "BP network", RA),
    "bp_scipy_lm": MethodSpec("BP (scipy LM)", lambda p: _Network(
        lambda x, t, g: [train_least_squares(x, t, p.n_hidden, r) for r in g], p.target), True),
    "de_bp_pure": MethodSpec("DE-BP pure", _pure(False), True, "DE-BP", R1),
    "ade_bp_pure": MethodSpec("ADE-BP pure", _pure(True), True, "ADE-BP", R1),
    "de_bp_hybrid_trainlm": MethodSpec("DE-BP hybrid (trainlm)", _hybrid(False, False), True, "DE-BP", R2),
    "ade_bp_hybrid_trainlm": MethodSpec("ADE-BP hybrid (trainlm)", _hybrid(True, False), True, "ADE-BP", R2),
    "de_bp_hybrid_trainlm_val": MethodSpec("DE-BP hybrid (trainlm, val. stop)", _hybrid(False, True), True,
                                           "DE-BP", R2V),
    "ade_bp_hybrid_trainlm_val": MethodSpec("ADE-BP hybrid (trainlm, val. stop)", _hybrid(True, True), True,
                                            "ADE-BP", R2V),
    "elm": MethodSpec("ELM", lambda p: _Network(_elm_train(p, False), p.target), True, None, "document B"),
    "elm_backtuned": MethodSpec("ELM back-tuned", lambda p: _Network(_elm_train(p, True), p.target), True,
                                None, "document B"),
}

#: The methods of the chapter's main table, in display order.
MAIN_METHODS = ("uncompensated", "ls8", "bp_matlab", "bp_matlab_val", "bp_adam", "de_bp_pure", "ade_bp_pure",
                "de_bp_hybrid_trainlm", "ade_bp_hybrid_trainlm", "de_bp_hybrid_trainlm_val",
                "ade_bp_hybrid_trainlm_val", "elm", "elm_backtuned", "physical")
ELM_METHODS = ("elm", "elm_backtuned")

#: Each reading of paper A's four methods: (LS, BP, DE-BP, ADE-BP) ids.
READINGS: dict[str, tuple[str, str, str, str]] = {
    R1: ("ls8", "bp_matlab", "de_bp_pure", "ade_bp_pure"),
    R2: ("ls8", "bp_matlab", "de_bp_hybrid_trainlm", "ade_bp_hybrid_trainlm"),
    R2V: ("ls8", "bp_matlab_val", "de_bp_hybrid_trainlm_val", "ade_bp_hybrid_trainlm_val"),
}
#: The same with the Adam extra as the "BP" (for the ordering probabilities).
BP_VARIANTS = ("bp_matlab", "bp_matlab_val", "bp_adam")

#: The chapter's former display names, accepted by :func:`method_id` (the workbench notebook used them).
LEGACY_NAMES = {"ADE-BP": "ade_bp_pure", "DE-BP": "de_bp_pure", "BP (Adam)": "bp_adam",
                "BP (LM)": "bp_scipy_lm", "LS 8-position": "ls8", "physical model": "physical",
                "ELM": "elm", "ELM back-tuned": "elm_backtuned"}


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


def fit_method(method: str, x, reference, params: StudyParams = StudyParams(), seeds=(0,), base_seed: int = 0):
    """Fit ``method`` (an id of ``METHODS``) on measured headings ``x`` (unwrapped) and true headings,
    one run per seed (run ``k`` uses generator ``k`` of :func:`navlib.methods.seeding.generators`).
    Returns the fitted compensators (one for a deterministic method)."""
    spec = METHODS[method_id(method)]
    rngs = generators(seeds if spec.stochastic else [0], base_seed)
    return spec.factory(params).fit_many(x, reference, rngs)


def compensate(method: str, sw: Sweeps, params: StudyParams = StudyParams(), seed: int = 0):
    """Train ``method`` (an id of ``METHODS``) on the training sweep and return ``(compensated test
    headings, info)``; ``info`` has ``train_time_s``, ``model`` (the fitted compensator) and what the
    trainer reports (``history``, ``n_nodes``, ``epochs``, ...)."""
    t0 = time.perf_counter()
    fitted = fit_method(method, sw.x_train, sw.t_train, params, [seed])[0]
    info = dict(fitted.info)
    net = getattr(fitted, "net", None)
    if net is not None and getattr(net, "history", None) is not None:
        info["history"] = net.history
    info.update(train_time_s=time.perf_counter() - t0, model=fitted)
    return fitted.correct(sw.x_test), info


#: CPU seconds per run of each method at the chapter's defaults (measured; for ordering parallel tasks,
#: most expensive first).  Methods not listed count as cheap.
RUN_COST_S = {"de_bp_pure": 0.3, "ade_bp_pure": 0.3, "de_bp_hybrid_trainlm": 0.14,
              "ade_bp_hybrid_trainlm": 0.07, "de_bp_hybrid_trainlm_val": 0.1, "ade_bp_hybrid_trainlm_val": 0.03,
              "bp_adam": 0.05, "bp_matlab": 0.06, "bp_matlab_val": 0.02, "elm_backtuned": 0.1}


def _method_runs(sw: Sweeps, params: StudyParams, mid: str, seeds: list, base_seed: int,
                 keep_errors: bool) -> list[dict]:
    """The rows of :func:`seed_study` for one method and the given seeds (one batch)."""
    spec = METHODS[mid]
    t0 = time.perf_counter()
    fitted = fit_method(mid, sw.x_train, sw.t_train, params, seeds, base_seed)
    per = (time.perf_counter() - t0) / len(fitted)
    rows = []
    for s, f in zip(seeds if spec.stochastic else [-1], fitted):
        err = test_errors(f.correct(sw.x_test), sw)
        row = {"method": mid, "label": spec.label, "seed": s, **error_stats(err), "train_time_s": per,
               "n_nodes": f.info.get("n_nodes", np.nan), "epochs": f.info.get("epochs", np.nan),
               "stop": f.info.get("stop", "")}
        if keep_errors:
            net = getattr(f, "net", None)
            row.update(error_deg=err, history=getattr(net, "history", None),
                       de_history=f.info.get("de_history"))
        rows.append(row)
    return rows


def _tasks(sw, params, seeds, methods, base_seed, keep_errors, workers):
    """One task per method, the seeds of a stochastic method cut into ``workers`` batches when parallel."""
    tasks, cost = [], []
    for m in methods:
        mid = method_id(m)
        chunks = [seeds]
        if METHODS[mid].stochastic and workers > 1 and len(seeds) >= 2 * workers:
            chunks = [list(c) for c in np.array_split(np.asarray(seeds), workers)]
        for c in chunks:
            tasks.append((sw, params, mid, [int(v) for v in c], base_seed, keep_errors))
            cost.append(RUN_COST_S.get(mid, 0.001) * len(c) * params.de.max_generations / 3000
                        if METHODS[mid].stochastic else 0.001)
    return tasks, cost


def seed_study(sw: Sweeps, params: StudyParams = StudyParams(), seeds=range(20), methods=MAIN_METHODS,
               base_seed: int = 0, keep_errors: bool = False, workers: int = 1) -> pd.DataFrame:
    """One row per (method, seed): ``method`` (id), ``label``, test-sweep error ``min_deg``, ``max_deg``,
    ``rms_deg``, ``train_time_s`` (per run; runs of one batch train together), ``n_nodes`` (ELMs),
    ``epochs`` and ``stop`` (``trainlm``), and with ``keep_errors`` the error curve ``error_deg`` (an
    array over the test sweep) and the training ``history``.  Deterministic methods get one row with
    seed -1.  ``workers`` > 1 runs the methods (and batches of seeds) in that many processes
    (:mod:`navlib.studies.parallel`); the numbers do not depend on it."""
    return seed_studies([(sw, params, seeds, methods)], base_seed, keep_errors, workers)[0]


def seed_studies(studies, base_seed: int = 0, keep_errors: bool = False, workers: int = 1) -> list[pd.DataFrame]:
    """Several :func:`seed_study` at once, ``studies`` a list of ``(sweeps, params, seeds, methods)``: all
    their tasks share the worker processes (the expensive ones start first), one frame per study."""
    tasks, cost, owner = [], [], []
    for k, (sw, params, seeds, methods) in enumerate(studies):
        t, c = _tasks(sw, params, [int(v) for v in seeds], methods, base_seed, keep_errors, workers)
        tasks += t
        cost += c
        owner += [k] * len(t)
    parts = run_tasks(_method_runs, tasks, workers, cost)
    return [pd.DataFrame([row for o, part in zip(owner, parts) if o == k for row in part])
            for k in range(len(studies))]


def summarize(runs: pd.DataFrame) -> pd.DataFrame:
    """Per method id (in order of appearance): label, runs, median min/max/RMS error, RMS spread (10th..90th
    percentile), median training time, and the hidden-node count of the ELMs (median, min, max)."""
    g = runs.groupby("method", sort=False)
    out = pd.DataFrame({
        "label": g["label"].first() if "label" in runs else g.size().index.map(label),
        "runs": g.size(),
        "median_min_deg": g["min_deg"].median(),
        "median_max_deg": g["max_deg"].median(),
        "median_rms_deg": g["rms_deg"].median(),
        "rms_p10_deg": g["rms_deg"].quantile(0.1),
        "rms_p90_deg": g["rms_deg"].quantile(0.9),
        "median_time_s": g["train_time_s"].median(),
    })
    if "n_nodes" in runs:
        out["median_nodes"] = g["n_nodes"].median()
        out["min_nodes"] = g["n_nodes"].min()
        out["max_nodes"] = g["n_nodes"].max()
    return out


def side_by_side(summary: pd.DataFrame, paper: pd.DataFrame, single: pd.DataFrame | None = None) -> pd.DataFrame:
    """Paper's range beside ours, one row per method of ``summary``: reading, paper's min..max (the row of
    ``paper`` the method answers), ours for one run (``single``, indexed by method id, optional), our
    median range and median RMS over seeds."""
    pidx = paper.set_index("method")
    rows = []
    for mid in summary.index:
        spec = METHODS[mid]
        p = pidx.loc[spec.paper_row] if spec.paper_row in pidx.index else None
        row = {"method": spec.label, "reading": spec.reading or "-",
               "paper (deg)": f"{p.error_min_deg:+.2f} .. {p.error_max_deg:+.2f}" if p is not None else "-"}
        if single is not None:
            s = single.loc[mid]
            row["one run (deg)"] = f"{s.min_deg:+.2f} .. {s.max_deg:+.2f}"
        row["median range (deg)"] = (f"{summary.loc[mid, 'median_min_deg']:+.2f} .. "
                                     f"{summary.loc[mid, 'median_max_deg']:+.2f}")
        row["median rms (deg)"] = summary.loc[mid, "median_rms_deg"]
        rows.append(row)
    return pd.DataFrame(rows).set_index("method")


# ----------------------------------------------------------------------------------------------- ordering
def ordering_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Probability that one draw of each method shows paper A's ordering (LS worse than BP worse than
    DE-BP worse than ADE-BP), per DE reading and per BP variant, judged by the RMS error and by the
    largest absolute error."""
    rows = []
    by = {m: g for m, g in runs.groupby("method")}
    for reading, (ls, _, de, ade) in READINGS.items():
        if not all(k in by for k in (ls, de, ade)):
            continue
        for bp in BP_VARIANTS:
            if bp not in by:
                continue
            row = {"DE reading": reading, "BP": METHODS[bp].label}
            for metric, col in (("rms", "rms_deg"), ("max |e|", None)):
                def vals(m):
                    g = by[m]
                    return (g[col] if col else np.maximum(-g.min_deg, g.max_deg)).to_numpy(float)
                p = ordering_probability(vals(ls)[0], vals(bp), vals(de), vals(ade))
                row[f"P(order), {metric}"] = p
            rows.append(row)
    return pd.DataFrame(rows)


def ordering_probability(ls: float, bp, de, ade) -> float:
    """P(ls > bp > de > ade) for one independent draw of each method (``ls`` one number, the others
    samples of the error over seeds): the chance that a paper reporting one run per method shows this
    ordering, computed exactly over the empirical distributions (all ``n_bp n_de n_ade`` combinations)."""
    bp, de, ade = (np.asarray(a, dtype=float) for a in (bp, de, ade))
    n_bp = ((bp[None, :] > de[:, None]) & (bp[None, :] < ls)).sum(axis=1)       # per DE draw
    n_ade = (ade[None, :] < de[:, None]).sum(axis=1)
    return float(np.sum(n_bp * n_ade) / (bp.size * de.size * ade.size))


# ----------------------------------------------------------------------------------------------- noise
def implied_noise_ut(paper_min_deg: float, paper_max_deg: float, errors: CompassErrors = CompassErrors(),
                     sim_seed: int = 2024, grid_ut=np.linspace(0.0025, 0.1, 40)) -> float:
    """The largest magnetometer noise (uT, on ``grid_ut``) at which the exact physical model, fitted to
    sweep 1, keeps its test-sweep error within the paper's best range ``[paper_min, paper_max]``: no
    compensation beats the model that generated the data, so a method that reached the paper's range
    implies the noise was at most this.  NaN if even the lowest noise on the grid does not fit."""
    best = np.nan
    for noise in np.asarray(grid_ut, dtype=float):
        sw = Sweeps(*split_sweeps(simulate_train_test(replace(errors, noise_ut=float(noise)), seed=sim_seed)))
        e = test_errors(_Planar().fit(sw.x_train, sw.t_train).correct(sw.x_test), sw)
        if e.min() >= paper_min_deg and e.max() <= paper_max_deg:
            best = float(noise)
        else:
            break
    return best


def noise_study(levels_ut, params: StudyParams = StudyParams(), seeds=range(5), methods=MAIN_METHODS,
                errors: CompassErrors = CompassErrors(), sim_seed: int = 2024, workers: int = 1) -> pd.DataFrame:
    """:func:`seed_study` on sweeps simulated with each magnetometer noise in ``levels_ut`` (the same
    compass and simulation seed, only the noise changes); one row per (noise_ut, method, seed).  With
    ``workers`` > 1 the (level, method) tasks run in that many processes (results identical: every run
    has its own generator)."""
    levels = [float(v) for v in levels_ut]
    for noise in levels:
        check_param("noise level", noise, lo=0)
    check_param("workers", workers, lo=1, integer=True)
    studies = [(Sweeps(*split_sweeps(simulate_train_test(replace(errors, noise_ut=noise), seed=sim_seed))),
                params, seeds, methods) for noise in levels]
    frames = seed_studies(studies, workers=workers)
    return pd.concat([f.assign(noise_ut=noise) for noise, f in zip(levels, frames)], ignore_index=True)


def noise_summary(noise_runs: pd.DataFrame) -> pd.DataFrame:
    """Per (noise_ut, method): label, median RMS and median min / max error (deg)."""
    g = noise_runs.groupby(["noise_ut", "method"], sort=False)
    return pd.DataFrame({"label": g["label"].first(), "median_rms_deg": g["rms_deg"].median(),
                         "median_min_deg": g["min_deg"].median(),
                         "median_max_deg": g["max_deg"].median()}).reset_index()


# ----------------------------------------------------------------------------------------------- verdict
def _better(a: pd.Series, b: pd.Series, floor: float):
    """Is ``a`` (RMS over seeds, or one value) smaller than ``b``?  True/False by a one-sided Mann-Whitney
    test at 5 % (a deterministic method is one sample); None when neither is significantly smaller and
    both medians are within 1.5x the noise floor (the sweeps cannot separate them)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.size > 1 or b.size > 1:
        less = mannwhitneyu(a, b, alternative="less").pvalue < 0.05 if min(a.size, b.size) > 1 else (
            np.mean(a[:, None] < b[None, :]) >= 0.9)
    else:
        less = bool(a[0] < b[0])
    if less:
        return True
    if np.median(a) <= 1.5 * floor and np.median(b) <= 1.5 * floor:
        return None
    return False


def _range_verdict(lo: float, hi: float, ours_lo: float, ours_hi: float, floor_lo: float, floor_hi: float):
    if floor_lo < lo or floor_hi > hi:
        return None, "the noise floor alone is wider than the paper's range"
    ok = bool(ours_lo >= lo and ours_hi <= hi)
    return ok, "" if ok else "our median range is wider"


def claims(runs: pd.DataFrame, paper: pd.DataFrame, noise_runs: pd.DataFrame | None = None,
           implied_ut: float | None = None, default_ut: float | None = None) -> list[Claim]:
    """Paper A's claims, one :class:`navlib.report.Claim` per (claim, reading): the comparisons (by RMS
    over seeds), the ordering probability (reproduced if at least 0.5), and the error ranges at the
    default noise (from ``runs``) and at the implied noise ``implied_ut`` (rows of ``noise_runs`` at that
    level).  A range claim cannot be judged where the physical model's own range (the noise floor) is
    wider than the paper's."""
    pr = paper.set_index("method")
    rms = {m: g.rms_deg for m, g in runs.groupby("method")}
    summ = summarize(runs)
    floor = float(summ.loc["physical", "median_rms_deg"])

    def rng(r):
        return f"{r.error_min_deg:+.2f}..{r.error_max_deg:+.2f}"

    out = []
    for reading, (ls, bp, de, ade) in READINGS.items():
        pairs = [("ADE-BP beats DE-BP", ade, de, "ADE-BP", "DE-BP"),
                 ("DE-BP beats BP", de, bp, "DE-BP", "BP network"),
                 ("BP beats 8-position LS", bp, ls, "BP network", "8-position least squares"),
                 ("ADE-BP beats 8-position LS", ade, ls, "ADE-BP", "8-position least squares")]
        for text, a, b, pa, pb in pairs:
            v = _better(rms[a], rms[b], floor)
            why = "both at the noise floor" if v is None else ""
            out.append(Claim(text, f"{rng(pr.loc[pa])} vs {rng(pr.loc[pb])} deg",
                             f"{np.median(rms[a]):.3f} vs {np.median(rms[b]):.3f} deg rms (median)", v, reading,
                             why))
        p = ordering_probability(rms[ls].iloc[0], rms[bp], rms[de], rms[ade])
        out.append(Claim("one run shows LS > BP > DE-BP > ADE-BP", "one run per method",
                         f"P = {p:.2f} (rms, one draw each)", p >= 0.5, reading))
        for level_name, frame, noise in (("default", runs, default_ut), ("implied", None, implied_ut)):
            if frame is None:
                if noise_runs is None or implied_ut is None or not np.isfinite(implied_ut):
                    continue
                frame = noise_runs[np.isclose(noise_runs.noise_ut, implied_ut)]
                if frame.empty:
                    continue
            s = summarize(frame)
            fl = s.loc["physical"]
            nz = f" ({noise:.3g} uT)" if noise is not None else ""
            for mid, prow, name in ((ade, "ADE-BP", "ADE-BP"), (de, "DE-BP", "DE-BP"), (bp, "BP network", "BP"),
                                    (ls, "8-position least squares", "LS")):
                if mid not in s.index:
                    continue
                r, p_ = s.loc[mid], pr.loc[prow]
                v, why = _range_verdict(p_.error_min_deg, p_.error_max_deg, r.median_min_deg, r.median_max_deg,
                                        fl.median_min_deg, fl.median_max_deg)
                out.append(Claim(f"{name} error within the paper's range, {level_name} noise{nz}",
                                 rng(p_) + " deg", f"{r.median_min_deg:+.2f}..{r.median_max_deg:+.2f} deg (median)",
                                 v, reading, why))
    return out


def headline_claims(claim_list) -> list:
    """The claims for the Results-at-a-glance table: comparisons, ordering and ADE-BP's range (the other
    range claims stay in the verdict table and the results file)."""
    return [c for c in claim_list if "error within" not in c.claim or c.claim.startswith("ADE-BP")]


def verdict_table(claim_list) -> pd.DataFrame:
    """Claims x readings: the verdict of each claim under each reading (from :func:`claims`)."""
    short = {True: "reproduced", False: "not reproduced", None: "cannot be judged"}
    rows = [{"claim": c.claim, "reading": c.reading, "verdict": short[c.reproduced]} for c in claim_list]
    df = pd.DataFrame(rows)
    order = list(dict.fromkeys(df.claim))
    return df.pivot(index="claim", columns="reading", values="verdict").loc[order, list(dict.fromkeys(df.reading))]


def results_methods(runs: pd.DataFrame) -> dict:
    """``{label: method_stats}`` for :func:`navlib.report.write_results` (one label per reading and
    trainer)."""
    return {METHODS[m].label: method_stats(g.rms_deg, g.min_deg, g.max_deg) for m, g in
            runs.groupby("method", sort=False)}
