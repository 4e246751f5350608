"""The chapter's runs: one seed fitted by every method (:func:`run_seed`, a :class:`Run`), the seeds as
engine tasks (:func:`run_study`), the whole chapter as one batch (:func:`run_chapter`: the main study with
the other tuners, the noise levels and the random split), and the errors of the runs (:func:`metrics`,
:func:`errors_long`)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from ... import engine
from ...errors import check_param
from ...methods.anfis import anfis
from ...methods.fish_swarm import minimise
from ...methods.mlp import train_mlp
from ...methods.subclust import genfis2
from .models import _genfis2_capped, fit_physical, grid_search, oracle, scm_objective
from .parameters import METHODS, SEPARATE, TUNERS, PaperDParams
from .separate import fit_separate
from .simulation import random_split, samples, simulate, split


@dataclass
class Run:
    """One seed: the samples of both units with every method's prediction (``pred_<method>`` columns, mg),
    the split, the swarm's choice and the trained models."""

    seed: int
    a: pd.DataFrame
    b: pd.DataFrame
    ra: float
    squash: float
    n_rules: dict = field(default_factory=dict)
    swarm_history: np.ndarray | None = None
    models: dict = field(default_factory=dict)
    tuned: dict = field(default_factory=dict)


def run_seed(params: PaperDParams, seed: int, df: pd.DataFrame | None = None) -> Run:
    """Simulate (unless ``df`` is given) and fit every method on unit A's training temperatures; predict
    every sample of units A and B."""
    df = simulate(params, seed) if df is None else df
    ref = params.experiment.reference_c
    a = samples(df, "A", ref)
    a["set"] = (
        split(a, params) if params.split_mode == "temperatures" else random_split(a, params, seed)
    )
    b = samples(df, "B", ref) if (df["unit"] == "B").any() else None
    X = a[["temperature_c", "output_mg"]].to_numpy()
    y = a["target_mg"].to_numpy()
    tr, ck = (a["set"] == "train").to_numpy(), (a["set"] == "check").to_numpy()
    models = {}
    ss = np.random.SeedSequence(seed).spawn(2)
    net = train_mlp(X[tr], y[tr], params.mlp, seed=int(ss[0].generate_state(1)[0]))
    models["ANN"] = net.predict
    fis = genfis2(X[tr], y[tr], params.fis_radius)
    models["FIS"] = fis
    models["ANFIS"] = anfis(X[tr], y[tr], fis, params.anfis, check=(X[ck], y[ck])).fis
    fallback = float(np.sqrt(np.mean((X[ck, 1] - y[ck]) ** 2)))
    obj = scm_objective(X[tr], y[tr], X[ck], y[ck], params.max_rules, fallback)
    res = minimise(
        obj,
        [params.radius_bounds, params.squash_bounds],
        params.swarm,
        seed=int(ss[1].generate_state(1)[0]),
    )
    ra, sq = (float(v) for v in res.x)
    init = _genfis2_capped(X[tr], y[tr], ra, sq, params.max_rules)
    models["IAFSA-SCM-ANFIS"] = anfis(X[tr], y[tr], init, params.anfis, check=(X[ck], y[ck])).fis
    tuned = {"IAFSA-SCM-ANFIS": (ra, sq, res.n_evaluations, res.fun, init.n_rules)}
    if params.tuners:
        plain = minimise(
            obj,
            [params.radius_bounds, params.squash_bounds],
            replace(params.swarm, improved=False),
            seed=int(ss[1].generate_state(1)[0]),
        )
        grid = grid_search(obj, params.radius_bounds, params.grid_squash, res.n_evaluations)
        for name, (x, fun, n_ev) in (
            ("AFSA-SCM-ANFIS", (plain.x, plain.fun, plain.n_evaluations)),
            ("grid-SCM-ANFIS", grid),
        ):
            fis_t = _genfis2_capped(X[tr], y[tr], float(x[0]), float(x[1]), params.max_rules)
            if fis_t is None:  # every candidate had too many rules: MATLAB's default radius
                fis_t = genfis2(X[tr], y[tr], params.fis_radius)
            models[name] = anfis(X[tr], y[tr], fis_t, params.anfis, check=(X[ck], y[ck])).fis
            tuned[name] = (float(x[0]), float(x[1]), int(n_ev), float(fun), fis_t.n_rules)
    train_df = df[(df["unit"] == "A")].reset_index(drop=True)
    phys = fit_physical(train_df[(a["set"] != "test").to_numpy()], params.poly_degree, ref)
    models["physical (poly K0, K1, K2)"] = phys
    models["oracle"] = oracle(params.coefficients, ref)
    models[SEPARATE] = fit_separate(a, params)
    for name, m in models.items():
        a[f"pred_{name}"] = m(X)
        if b is not None:
            b[f"pred_{name}"] = m(b[["temperature_c", "output_mg"]].to_numpy())
    n_rules = {"FIS": fis.n_rules, "ANFIS": fis.n_rules, **{k: v[4] for k, v in tuned.items()}}
    return Run(seed, a, b, ra, sq, n_rules, res.history, models, tuned)


@dataclass
class Chapter:
    """Everything the chapter runs: the main runs (:class:`Run` per seed, with the other tuners), their
    errors, the noise study's errors (column ``noise_ug``; the default noise level is the main runs') and
    the random-split reading's errors."""

    runs: list
    err: pd.DataFrame
    noise_err: pd.DataFrame
    random_err: pd.DataFrame


def _chapter_task(kind: str, params: PaperDParams, seed: int):
    run = run_seed(params, seed)
    return run if kind == "main" else errors_long([run])


def run_chapter(
    params: PaperDParams = PaperDParams(),
    noise_levels=(),
    random_reading: bool = True,
    workers: int = 1,
    scheduler: str | None = None,
) -> Chapter:
    """The chapter's runs as one batch of engine tasks (:mod:`navlib.engine`; one task per seed and variant, the
    most expensive first): the main study at ``params`` with the other tuners (``tuners=True``), the same seeds at
    every noise level of ``noise_levels`` (ug per reading; the ``params`` level is taken from the main runs) and, if
    ``random_reading``, under the random split. Every task draws its data from its seed alone
    (:func:`~navlib.studies.accelerometer.simulation.sim_seed`), so the noise levels and the two splits are paired
    over the same seeds and nothing depends on where a task ran."""
    levels = [float(v) for v in noise_levels]
    for v in levels:
        check_param("noise_levels", v, lo=0, lo_open=True, hi=10000)
    main = replace(params, tuners=True)
    sigma = params.experiment.noise_ug
    tasks, cost = [], []
    for s in params.seeds:
        tasks.append(("main", main, s))
        cost.append(2.5)
    others = [v for v in dict.fromkeys(levels) if not np.isclose(v, sigma)]
    for v in others:
        p = replace(params, experiment=replace(params.experiment, noise_ug=v))
        tasks += [("noise", p, s) for s in params.seeds]
        cost += [1.0] * len(params.seeds)
    if random_reading:
        p = replace(params, split_mode="random")
        tasks += [("random", p, s) for s in params.seeds]
        cost += [1.0] * len(params.seeds)
    out = engine.run(
        _chapter_task,
        tasks,
        workers=workers,
        scheduler=scheduler,
        cost=cost,
        label="paper D seeds, noise levels, splits",
    )
    n = len(params.seeds)
    runs = out[:n]
    err = errors_long(runs)
    frames = []
    for v in dict.fromkeys(levels):
        if np.isclose(v, sigma):
            e = err[~err["method"].isin(TUNERS)].copy()
        else:
            i = n + others.index(v) * n
            e = pd.concat(out[i : i + n], ignore_index=True)
        e.insert(0, "noise_ug", v)
        frames.append(e)
    noise_err = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    random_err = (
        pd.concat(out[n + len(others) * n :], ignore_index=True)
        if random_reading
        else pd.DataFrame()
    )
    return Chapter(runs, err, noise_err, random_err)


def run_study(
    params: PaperDParams = PaperDParams(), workers: int = 1, scheduler: str | None = None
) -> list[Run]:
    """One :class:`Run` per seed in ``params.seeds``, each a task of :mod:`navlib.engine` (``workers``
    local processes, or the cluster at ``scheduler``); every seed draws its own data and starts, so the
    runs do not depend on where they ran."""
    return engine.run(
        run_seed,
        [(params, s) for s in params.seeds],
        workers=workers,
        scheduler=scheduler,
        label="paper D seeds",
    )


# ----------------------------------------------------------------------------------------- metrics
def metrics(err_mg, target_mg) -> dict:
    """Paper D's five indices (its eq 16 is lost in the OCR; our reading): ME = max ``|e|``, AE = mean e
    (signed), MAXE = max ``|e/Nc|``, MARE = mean ``|e/Nc|``, RMSE = sqrt(mean e^2); and the residual range
    ``max e - min e`` (section 5.2: "the residual range ... is the smallest"); e = model - target, in mg."""
    e = np.asarray(err_mg, float)
    t = np.asarray(target_mg, float)
    rel = np.abs(e / t)
    return {
        "ME_mg": float(np.max(np.abs(e))),
        "AE_mg": float(np.mean(e)),
        "MAXE": float(np.max(rel)),
        "MARE": float(np.mean(rel)),
        "RMSE_mg": float(np.sqrt(np.mean(e**2))),
        "range_mg": float(np.max(e) - np.min(e)),
    }


def errors_long(runs: list[Run]) -> pd.DataFrame:
    """Every method's metrics per seed and data set (``train``, ``check``, ``test``, ``unit B``), against
    the measured target and against the noise-free one (``vs_true``)."""
    rows = []
    for r in runs:
        parts = [(s, r.a[r.a["set"] == s]) for s in ("train", "check", "test")]
        if r.b is not None:
            parts.append(("unit B", r.b))
        extra = [t for t in (*TUNERS, SEPARATE) if f"pred_{t}" in r.a.columns]
        for name in (*METHODS, *extra, "oracle", "uncompensated"):
            for s, g in parts:
                pred = g["output_mg"] if name == "uncompensated" else g[f"pred_{name}"]
                m = metrics(pred - g["target_mg"], g["target_mg"])
                m_true = np.sqrt(np.mean((pred - g["target_true_mg"]) ** 2))
                rows.append(
                    {
                        "seed": r.seed,
                        "method": name,
                        "set": s,
                        **m,
                        "RMSE_vs_true_mg": float(m_true),
                    }
                )
    return pd.DataFrame(rows)
