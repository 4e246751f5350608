"""Paper A's comparison, as one reusable study: every compensation method trained on sweep 1 and scored on
sweep 2, repeated over seeds for the stochastic ones.

Methods (names as in the tables):

- ``uncompensated``: the measured heading.
- ``LS 8-position``: Smith's A..E fitted to the readings at 0, 45, ..., 315 deg (:mod:`navlib.methods.smith`).
- ``BP (Adam)``: the 1-6-1 net trained by back-propagation with Adam (:func:`navlib.methods.bpnet.train_gradient`).
- ``BP (LM)``: the same net trained by Levenberg-Marquardt (paper A's reference [8]); not in paper A's
  table, shown because it is the strongest gradient trainer for a net this small.
- ``DE-BP`` / ``ADE-BP``: :func:`navlib.methods.bpnet.train_de`.
- ``physical model``: the exact planar model fitted to all of sweep 1 (:func:`navlib.sensors.planar.fit_planar_model`),
  our reference for the noise floor.
- ``ELM``: patent B's network without its training scheme: a plain extreme learning machine (Huang 2006,
  :func:`navlib.methods.elm.fit_elm`) with ``StudyParams.elm_nodes`` random sigmoid nodes, beta = H^+ T.
- ``ELM back-tuned``: patent B's scheme, the point-incremental ELM with autonomous back-tuning and pruning
  (:func:`navlib.methods.elm.fit_incremental_elm`); ``info['n_nodes']`` is the hidden-node count it settles on.

Both ELMs use the BP nets' convention: input = unwrapped measured heading, output = true heading (or the
heading error, ``StudyParams.network_target``), both min-max normalised on the training sweep.

Patent B's data preparation (median filter, dot-product screen, min-max, random 90/10 split) is
:func:`.prepare_patent_data`; :func:`.glitch_study` measures what it buys on sweeps with glitches and
:func:`.small_sample_study` tests the patent's claim of less overfitting on small samples.

Error = compensated - true heading, wrapped to (-180, 180], on the test sweep.
"""

import time
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from tqdm import tqdm

from ..angles import wrap_deg
from ..data.compass_sweeps import unwrap_measured
from ..errors import InputError, check_param
from ..methods.bpnet import GradientParams, train_de, train_gradient
from ..methods.de import DEParams
from ..methods.elm import ELMParams, IncrementalELMParams, fit_elm, fit_incremental_elm
from ..methods.scaling import MinMax
from ..methods.smith import eight_position_indices, fit_smith
from ..sensors.planar import fit_planar_model

ELM_METHODS = ("ELM", "ELM back-tuned")
STOCHASTIC = ("BP (Adam)", "BP (LM)", "DE-BP", "ADE-BP") + ELM_METHODS
DETERMINISTIC = ("uncompensated", "LS 8-position", "physical model")
ALL_METHODS = ("uncompensated", "LS 8-position", "BP (Adam)", "BP (LM)", "DE-BP", "ADE-BP",
               "ELM", "ELM back-tuned", "physical model")


@dataclass(frozen=True)
class StudyParams:
    """Everything a reader may change in the compass chapter. Defaults are paper A's settings."""

    n_hidden: int = 6
    pop_size: int = 95
    max_generations: int = 3000
    target_fitness: float = 0.2
    de_f: float = 0.5
    de_cr: float = 0.6
    ade_f_min: float = 0.3
    ade_f_max: float = 0.9
    ade_cr_min: float = 0.1
    ade_cr_max: float = 0.9
    weight_bound: float = 10.0
    bp_epochs: int = 3000
    bp_lr: float = 0.01
    network_target: str = "heading"   # 'heading' (paper's body text) or 'error' (the abstract's wording)
    # patent B (ELM).  The patent gives no numbers; these are our a-priori choices (see the chapter).
    elm_nodes: int = 19          # plain ELM: 19 trained output weights = the 19 weights of the 1-6-1 net
    elm_range: float = 5.0       # input weights and biases ~ U(-elm_range, elm_range) (Huang 2006: 1)
    elm_max_nodes: int = 30      # incremental ELM: cap on the hidden-node count
    elm_goal_deg: float = 0.1    # incremental ELM: stop when the training RMS error (deg) is <= this
    elm_max_iter: int = 200      # incremental ELM: the patent's k (ELM and tuning stages together)

    def validate(self) -> "StudyParams":
        check_param("n_hidden", self.n_hidden, lo=1, integer=True)
        check_param("elm_nodes", self.elm_nodes, lo=1, integer=True)
        check_param("elm_range", self.elm_range, lo=0, lo_open=True)
        check_param("elm_max_nodes", self.elm_max_nodes, lo=1, integer=True)
        check_param("elm_goal_deg", self.elm_goal_deg, lo=0)
        check_param("elm_max_iter", self.elm_max_iter, lo=1, integer=True)
        check_param("bp_epochs", self.bp_epochs, lo=1, integer=True)
        check_param("bp_lr", self.bp_lr, lo=0, lo_open=True)
        if self.network_target not in ("heading", "error"):
            raise InputError(f"parameter network_target={self.network_target!r}: must be 'heading' or 'error'")
        self.de_params(False, 0).validate()
        self.de_params(True, 0).validate()
        return self

    def de_params(self, adaptive: bool, seed: int) -> DEParams:
        return DEParams(pop_size=self.pop_size, max_generations=self.max_generations,
                        target_fitness=self.target_fitness, f=self.de_f, cr=self.de_cr, adaptive=adaptive,
                        f_min=self.ade_f_min, f_max=self.ade_f_max, cr_min=self.ade_cr_min,
                        cr_max=self.ade_cr_max, bound=self.weight_bound, seed=seed)

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
    e = np.asarray(err, dtype=float)
    return {"min_deg": float(e.min()), "max_deg": float(e.max()), "rms_deg": float(np.sqrt(np.mean(e ** 2)))}


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


class ELMPredictor:
    """A trained ELM with its min-max scalers: ``predict`` maps raw inputs (deg) to raw outputs (deg)."""

    def __init__(self, model, x_scale: MinMax, t_scale: MinMax):
        self.model, self.x_scale, self.t_scale = model, x_scale, t_scale

    @property
    def n_hidden(self) -> int:
        return self.model.n_hidden

    def predict(self, x) -> np.ndarray:
        return self.t_scale.inverse(self.model.predict(self.x_scale.transform(np.asarray(x, dtype=float))))


def fit_elm_method(method: str, x, target, params: StudyParams = StudyParams(), seed: int = 0):
    """Train ``'ELM'`` or ``'ELM back-tuned'`` on raw inputs ``x`` and targets (deg), min-max normalised
    here.  Returns ``(predictor, info)``; info has ``n_nodes`` and, for the back-tuned ELM, the stage
    ``history`` of :func:`navlib.methods.elm.fit_incremental_elm`."""
    if method not in ELM_METHODS:
        raise InputError(f"unknown ELM method {method!r}; known: {', '.join(ELM_METHODS)}")
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(target, name="network target")
    xn, tn = xs.transform(np.asarray(x, dtype=float)), ts.transform(np.asarray(target, dtype=float))
    if method == "ELM":
        model, info = fit_elm(xn, tn, params.elm_params(), rng=seed), {}
    else:
        model, hist = fit_incremental_elm(xn, tn, params.incremental_params(ts.span[0]), rng=seed)
        info = {"history": hist}
    info["n_nodes"] = model.n_hidden
    return ELMPredictor(model, xs, ts), info


def compensate(method: str, sw: Sweeps, params: StudyParams = StudyParams(), seed: int = 0):
    """Train ``method`` on the training sweep and return ``(compensated test headings, info)``; ``info`` has
    ``train_time_s`` and method-specific entries (the trained object under ``model``; ``n_nodes`` for the
    ELMs)."""
    params.validate()
    t0 = time.perf_counter()
    if method == "uncompensated":
        return sw.m_test.copy(), {"train_time_s": 0.0, "model": None}
    if method == "LS 8-position":
        idx = eight_position_indices(sw.t_train)
        model = fit_smith(sw.m_train[idx], sw.t_train[idx])
        return model.correct(sw.m_test), {"train_time_s": time.perf_counter() - t0, "model": model}
    if method == "physical model":
        model = fit_planar_model(sw.t_train, sw.m_train)
        return model.correct(sw.m_test), {"train_time_s": time.perf_counter() - t0, "model": model}
    if method not in STOCHASTIC:
        raise InputError(f"unknown method {method!r}; known: {', '.join(ALL_METHODS)}")
    as_error = params.network_target == "error"
    target = sw.t_train - sw.x_train if as_error else sw.t_train
    if method in ELM_METHODS:
        net, info = fit_elm_method(method, sw.x_train, target, params, seed)
    elif method in ("DE-BP", "ADE-BP"):
        net, res = train_de(sw.x_train, target, params.n_hidden, params.de_params(method == "ADE-BP", seed))
        info = {"generations": res.generations, "fitness": net.info["fitness"], "history": res.history}
    else:
        gp = GradientParams(method="lm" if method == "BP (LM)" else "adam", epochs=params.bp_epochs,
                            lr=params.bp_lr, seed=seed)
        net = train_gradient(sw.x_train, target, params.n_hidden, gp)
        info = {"history": net.history}
    out = net.predict(sw.x_test)
    corrected = sw.x_test + out if as_error else out
    info.update(train_time_s=time.perf_counter() - t0, model=net)
    return np.mod(corrected, 360.0), info


def test_errors(corrected, sw: Sweeps) -> np.ndarray:
    return wrap_deg(np.asarray(corrected) - sw.t_test)


def seed_study(sw: Sweeps, params: StudyParams = StudyParams(), seeds=range(20),
               methods=ALL_METHODS, progress: bool = False) -> pd.DataFrame:
    """One row per (method, seed): test-sweep error min, max, RMS (deg), training time (s) and the
    hidden-node count of the ELMs (``n_nodes``; NaN for the other methods).  Deterministic methods get
    one row with seed -1."""
    rows = []
    jobs = [(m, -1) for m in methods if m in DETERMINISTIC]
    jobs += [(m, s) for s in seeds for m in methods if m in STOCHASTIC]
    for method, seed in tqdm(jobs, disable=not progress, desc="training", leave=False):
        corrected, info = compensate(method, sw, params, max(seed, 0))
        rows.append({"method": method, "seed": seed, **error_stats(test_errors(corrected, sw)),
                     "train_time_s": info["train_time_s"], "n_nodes": info.get("n_nodes", np.nan)})
    return pd.DataFrame(rows)


def summarize(runs: pd.DataFrame) -> pd.DataFrame:
    """Per method: number of runs, median min/max/RMS error, the RMS spread (10th..90th percentile), the
    median training time and, when ``runs`` has an ``n_nodes`` column, the median, minimum and maximum
    hidden-node count over the runs (NaN for methods without one)."""
    g = runs.groupby("method", sort=False)
    out = pd.DataFrame({
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


def side_by_side(summary: pd.DataFrame, paper: pd.DataFrame, single: pd.DataFrame) -> pd.DataFrame:
    """Paper's range beside ours: for each method, the paper's min..max, ours for the chapter's headline
    seed (``single``: one row per method with min_deg, max_deg, rms_deg), and our median over seeds."""
    paper_names = {"uncompensated": "uncompensated", "LS 8-position": "8-position least squares",
                   "BP (Adam)": "BP network", "DE-BP": "DE-BP", "ADE-BP": "ADE-BP"}
    pidx = paper.set_index("method")
    rows = []
    for method in summary.index:
        pn = paper_names.get(method)
        p = pidx.loc[pn] if pn in pidx.index else None
        s = single.set_index("method").loc[method]
        rows.append({
            "method": method,
            "paper range (deg)": f"{p.error_min_deg:+.2f} .. {p.error_max_deg:+.2f}" if p is not None else "-",
            "ours, one run (deg)": f"{s.min_deg:+.2f} .. {s.max_deg:+.2f}",
            "ours, median over seeds (deg)": (f"{summary.loc[method, 'median_min_deg']:+.2f} .. "
                                              f"{summary.loc[method, 'median_max_deg']:+.2f}"),
            "ours, median RMS (deg)": f"{summary.loc[method, 'median_rms_deg']:.3f}",
        })
    return pd.DataFrame(rows).set_index("method")


def _target(params: StudyParams, x, t):
    return np.asarray(t) - np.asarray(x) if params.network_target == "error" else np.asarray(t)


def _output(params: StudyParams, x, out):
    return np.asarray(x) + out if params.network_target == "error" else out


def rms_deg(predicted, true) -> float:
    """RMS of the wrapped heading error (deg)."""
    e = wrap_deg(np.asarray(predicted, dtype=float) - np.asarray(true, dtype=float))
    return float(np.sqrt(np.mean(e ** 2)))


