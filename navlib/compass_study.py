"""Paper A's comparison, as one reusable study: every compensation method trained on sweep 1 and scored on
sweep 2, repeated over seeds for the stochastic ones.

Methods (names as in the tables):
- ``uncompensated``: the measured heading.
- ``LS 8-position``: Smith's A..E fitted to the readings at 0, 45, ..., 315 deg (:mod:`navlib.smith`).
- ``BP (Adam)``: the 1-6-1 net trained by back-propagation with Adam (:func:`navlib.bpnet.train_gradient`).
- ``BP (LM)``: the same net trained by Levenberg-Marquardt (paper A's reference [8]); not in paper A's
  table, shown because it is the strongest gradient trainer for a net this small.
- ``DE-BP`` / ``ADE-BP``: :func:`navlib.bpnet.train_de`.
- ``physical model``: the exact planar model fitted to all of sweep 1 (:func:`navlib.compass.fit_planar_model`),
  our reference for the noise floor.

Error = compensated - true heading, wrapped to (-180, 180], on the test sweep.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from .bpnet import GradientParams, train_de, train_gradient
from .compass import fit_planar_model, unwrap_measured, wrap_deg
from .de import DEParams
from .errors import InputError, check_param
from .smith import eight_position_indices, fit_smith

STOCHASTIC = ("BP (Adam)", "BP (LM)", "DE-BP", "ADE-BP")
DETERMINISTIC = ("uncompensated", "LS 8-position", "physical model")
ALL_METHODS = ("uncompensated", "LS 8-position", "BP (Adam)", "BP (LM)", "DE-BP", "ADE-BP",
               "physical model")


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

    def validate(self) -> "StudyParams":
        check_param("n_hidden", self.n_hidden, lo=1, integer=True)
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


def compensate(method: str, sw: Sweeps, params: StudyParams = StudyParams(), seed: int = 0):
    """Train ``method`` on the training sweep and return ``(compensated test headings, info)``; ``info`` has
    ``train_time_s`` and method-specific entries (the trained object under ``model``)."""
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
    if method in ("DE-BP", "ADE-BP"):
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
    """One row per (method, seed): test-sweep error min, max, RMS (deg) and training time (s).
    Deterministic methods get one row with seed -1."""
    from tqdm import tqdm

    rows = []
    jobs = [(m, -1) for m in methods if m in DETERMINISTIC]
    jobs += [(m, s) for s in seeds for m in methods if m in STOCHASTIC]
    for method, seed in tqdm(jobs, disable=not progress, desc="training", leave=False):
        corrected, info = compensate(method, sw, params, max(seed, 0))
        rows.append({"method": method, "seed": seed, **error_stats(test_errors(corrected, sw)),
                     "train_time_s": info["train_time_s"]})
    return pd.DataFrame(rows)


def summarize(runs: pd.DataFrame) -> pd.DataFrame:
    """Per method: number of runs, median min/max/RMS error, the RMS spread (10th..90th percentile) and
    the median training time."""
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


def with_params(params: StudyParams, **changes) -> StudyParams:
    return replace(params, **changes).validate()
