"""Paper A's comparison on the turntable sweeps under every plausible reading of its training: every
compensation method trained on sweep 1 and scored on sweep 2, repeated over seeds for the stochastic ones
(:func:`seed_study`), and the side studies that run it again: the noise floor and the noise study, the LS
against its number of positions, the DE stage's convergence, and our own choices (search box, DE budget,
network target).

The methods are those of :mod:`navlib.methods.compass_methods`; the runs go to :mod:`navlib.engine`.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Iterable, Mapping

import numpy as np
import pandas as pd

from ... import engine
from ...data.compass_sweeps import split_sweeps
from ...errors import InputError, check_param
from ...methods.compass_methods import (
    LS_MODELS,
    METHODS,
    EightPosition,
    PlanarFit,
    fit_family,
    fit_method,
    fitting_units,
    label,
    method_id,
    unit_cost,
)
from ...sensors.compass import PAPER_A_EARTH, CompassErrors, simulate_train_test
from .parameters import (
    BOX_BOUNDS,
    CONVERGENCE_AT_FRACTIONS,
    CONVERGENCE_RMS_DEG,
    FLOOR_GRID_UT,
    LS_POSITIONS,
    MAIN_METHODS,
    StudyParams,
)
from .sweeps import Sweeps, error_stats, test_errors


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


def _method_runs(
    sw: Sweeps, params: StudyParams, mids, seeds: list, base_seed: int, keep_errors: bool
) -> list[dict]:
    """The rows of :func:`seed_study` for one method (or one family sharing a DE stage,
    :func:`~navlib.methods.compass_methods.fit_family`) and the given seeds (one batch).  A family's
    ``train_time_s`` is the family's time per seed."""
    mids = (mids,) if isinstance(mids, str) else tuple(mids)
    t0 = time.perf_counter()
    if len(mids) > 1:
        fitted_by = fit_family(mids, sw.x_train, sw.t_train, params, seeds, base_seed)
    else:
        fitted_by = {mids[0]: fit_method(mids[0], sw.x_train, sw.t_train, params, seeds, base_seed)}
    per = (time.perf_counter() - t0) / len(next(iter(fitted_by.values())))
    rows = []
    for mid in mids:
        spec = METHODS[mid]
        for s, f in zip(seeds if spec.stochastic else [-1], fitted_by[mid]):
            err = test_errors(f.correct(sw.x_test), sw)
            row = {
                "method": mid,
                "label": spec.label,
                "seed": s,
                **error_stats(err),
                "train_time_s": per,
                "n_nodes": f.info.get("n_nodes", np.nan),
                "epochs": f.info.get("epochs", np.nan),
                "stop": f.info.get("stop", ""),
            }
            if keep_errors:
                net = getattr(f, "net", None)
                hist = getattr(net, "history", None)
                row.update(
                    error_deg=err,
                    history=hist,
                    de_history=f.info.get(
                        "de_history", hist if spec.family and spec.family[1] == "pure" else None
                    ),
                )
            rows.append(row)
    return rows


#: Runs of a stochastic method per task (a fixed size: the batches, and so the numbers, never depend on the
#: number of workers; nor on the batch: every run draws from its own generator).
SEED_BATCH = 4
#: A task's estimated CPU seconds at most: seeds of a costly unit (e.g. ten times the DE budget) go in
#: smaller batches, so the engine's workers finish together.
MAX_TASK_S = 2.0


def _tasks(sw, params, seeds, methods, base_seed, keep_errors):
    """One task per deterministic method and per batch of :data:`SEED_BATCH` seeds of a stochastic one (or
    of a family sharing a DE stage, :func:`~navlib.methods.compass_methods.fitting_units`; fewer seeds when
    a batch would cost more than :data:`MAX_TASK_S`), with its estimated cost (CPU seconds)."""
    tasks, cost = [], []
    for unit in fitting_units(params, methods):
        stochastic = METHODS[unit[0]].stochastic
        size = max(1, min(SEED_BATCH, int(MAX_TASK_S // max(unit_cost(unit, params), 1e-9))))
        chunks = (
            [seeds[i : i + size] for i in range(0, len(seeds), size)] if stochastic else [seeds]
        )
        for c in chunks:
            tasks.append(
                (
                    sw,
                    params,
                    unit if len(unit) > 1 else unit[0],
                    [int(v) for v in c],
                    base_seed,
                    keep_errors,
                )
            )
            cost.append(unit_cost(unit, params) * len(c) if stochastic else 0.001)
    return tasks, cost


def seed_study(
    sw: Sweeps,
    params: StudyParams = StudyParams(),
    seeds=range(20),
    methods=MAIN_METHODS,
    base_seed: int = 0,
    keep_errors: bool = False,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """One row per (method, seed): ``method`` (id), ``label``, test-sweep error ``min_deg``, ``max_deg``,
    ``rms_deg``, ``train_time_s`` (per run; runs of one batch train together), ``n_nodes`` (ELMs),
    ``epochs`` and ``stop`` (``trainlm``), and with ``keep_errors`` the error curve ``error_deg`` (an
    array over the test sweep) and the training ``history``.  Deterministic methods get one row with
    seed -1.  The runs go to :mod:`navlib.engine` (``workers`` local processes, or the cluster at
    ``scheduler``) in batches of :data:`SEED_BATCH` seeds; the numbers do not depend on where they ran."""
    return seed_studies([(sw, params, seeds, methods)], base_seed, keep_errors, workers, scheduler)[
        0
    ]


def seed_studies(
    studies,
    base_seed: int = 0,
    keep_errors: bool = False,
    workers: int = 1,
    scheduler: str | None = None,
) -> list[pd.DataFrame]:
    """Several :func:`seed_study` at once, ``studies`` a list of ``(sweeps, params, seeds, methods)``: all
    their tasks share the engine's workers (the expensive ones start first), one frame per study, its rows
    in the order of ``methods`` (and of the seeds within a method)."""
    tasks, cost, owner = [], [], []
    for k, (sw, params, seeds, methods) in enumerate(studies):
        t, c = _tasks(sw, params, [int(v) for v in seeds], methods, base_seed, keep_errors)
        tasks += t
        cost += c
        owner += [k] * len(t)
    parts = engine.run(
        _method_runs,
        tasks,
        workers=workers,
        scheduler=scheduler,
        cost=cost,
        label="seed study",
        weight=[len(t[3]) * (1 if isinstance(t[2], str) else len(t[2])) for t in tasks],
    )
    frames = []
    for k, (_, _, _, methods) in enumerate(studies):
        rows = [row for o, part in zip(owner, parts) if o == k for row in part]
        at = {m: i for i, m in enumerate(dict.fromkeys(method_id(m) for m in methods))}
        frames.append(
            pd.DataFrame(sorted(rows, key=lambda r: at[r["method"]]))
        )  # stable: seeds stay in order
    return frames


# ---------------------------------------------------------------------------------------------------- noise
def floor_curve(
    errors: CompassErrors = CompassErrors(), sim_seed: int = 2024, grid_ut=FLOOR_GRID_UT
) -> pd.DataFrame:
    """The noise floor against magnetometer noise: the exact physical model fitted to sweep 1 of sweeps
    simulated with each noise in ``grid_ut`` (the same compass and simulation seed), scored on sweep 2.
    One row per level: ``noise_ut``, ``min_deg``, ``max_deg``, ``width_deg`` (= max - min, the statistic
    of the range claims) and ``rms_deg``.  No compensation beats the model that generated the data, so
    this is the best our experiment can show at each noise."""
    rows = []
    for noise in np.asarray(grid_ut, dtype=float):
        check_param("noise level", noise, lo=0)
        sw = Sweeps(
            *split_sweeps(
                simulate_train_test(
                    replace(errors, noise_ut=float(noise)), PAPER_A_EARTH, seed=sim_seed
                )
            )
        )
        e = test_errors(PlanarFit().fit(sw.x_train, sw.t_train).correct(sw.x_test), sw)
        rows.append(
            {"noise_ut": float(noise), **error_stats(e), "width_deg": float(e.max() - e.min())}
        )
    return pd.DataFrame(rows, columns=["noise_ut", "min_deg", "max_deg", "rms_deg", "width_deg"])


def largest_noise(curve: pd.DataFrame, width_deg: float) -> float:
    """The largest noise (uT) of :func:`floor_curve` ``curve`` up to which the physical model's error width
    stays strictly below ``width_deg`` (scanning from the lowest level; NaN if not even there)."""
    best = np.nan
    for noise, w in zip(curve.noise_ut, curve.width_deg):
        if not w < width_deg:
            break
        best = float(noise)
    return best


def implied_noise_ut(
    paper_min_deg: float,
    paper_max_deg: float,
    errors: CompassErrors = CompassErrors(),
    sim_seed: int = 2024,
    grid_ut=FLOOR_GRID_UT,
) -> float:
    """The largest magnetometer noise (uT, on ``grid_ut``) at which the exact physical model, fitted to
    sweep 1, keeps the width of its test-sweep error (max - min) below the paper's best range's width ``paper_max -
    paper_min``: no compensation beats the model that generated the data, so a method that reached the paper's range
    implies the noise was at most this (the same statistic as the range claims of
    :func:`~navlib.studies.compass.turntable_claims.claims`).  NaN if even the lowest noise on the grid does not
    fit."""
    return largest_noise(
        floor_curve(errors, sim_seed, grid_ut), float(paper_max_deg) - float(paper_min_deg)
    )


def noise_study(
    levels_ut,
    params: StudyParams = StudyParams(),
    seeds=range(5),
    methods=MAIN_METHODS,
    errors: CompassErrors = CompassErrors(),
    sim_seed: int = 2024,
    workers: int = 1,
    seeds_at: Mapping[float, Iterable[int]] | None = None,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """:func:`seed_study` on sweeps simulated with each magnetometer noise in ``levels_ut`` (the same
    compass and simulation seed, only the noise changes); one row per (noise_ut, method, seed).
    ``seeds_at`` maps a level to its own seeds (e.g. more runs at the level whose claims are judged, so
    that their median has a 95 % interval: at least 6 runs).  Every (level, method, batch of seeds) is a
    task of :mod:`navlib.engine` (``workers``, ``scheduler``; results identical: every run has its own
    generator)."""
    levels = [float(v) for v in levels_ut]
    for noise in levels:
        check_param("noise level", noise, lo=0)
    check_param("workers", workers, lo=1, integer=True)
    own = {float(k): list(v) for k, v in (seeds_at or {}).items()}
    for k in own:
        if not any(np.isclose(k, lv) for lv in levels):
            raise InputError(
                f"noise_study seeds_at: level {k:g} uT is not among the levels {levels}"
            )

    def level_seeds(noise):
        return next((v for k, v in own.items() if np.isclose(k, noise)), seeds)

    studies = [
        (
            Sweeps(
                *split_sweeps(
                    simulate_train_test(
                        replace(errors, noise_ut=noise), PAPER_A_EARTH, seed=sim_seed
                    )
                )
            ),
            params,
            level_seeds(noise),
            methods,
        )
        for noise in levels
    ]
    frames = seed_studies(studies, workers=workers, scheduler=scheduler)
    return pd.concat(
        [f.assign(noise_ut=noise) for noise, f in zip(levels, frames)], ignore_index=True
    )


# ---------------------------------------------------------------------- least squares against its positions
def ls_positions_rms(sw: Sweeps, counts=LS_POSITIONS, models=tuple(LS_MODELS)) -> pd.DataFrame:
    """Test-sweep RMS (deg) of each 8-position LS model of :data:`~navlib.methods.compass_methods.LS_MODELS`
    (the chapter's fit, :class:`~navlib.methods.compass_methods.EightPosition`) fitted on ``n`` equally spaced
    positions of sweep 1 (0, 360/n, ... deg true heading) for every ``n`` of ``counts``, scored on sweep 2: one row
    per (``model`` id, ``name``, ``n_positions``, ``test_rms_deg``).  A count that cannot determine the model (fewer
    readings than it needs) or whose headings are not on the sweep is left out.  Deterministic (no random draw)."""
    rows = []
    for mid in models:
        for n in counts:
            check_param("positions", n, lo=2, integer=True)
            try:
                comp = EightPosition(METHODS[mid].factory(StudyParams()).model, 360.0 / n).fit(
                    sw.x_train, sw.t_train
                )
            except InputError:
                continue
            rows.append(
                {
                    "model": mid,
                    "name": LS_MODELS[mid],
                    "n_positions": int(n),
                    "test_rms_deg": float(
                        np.sqrt(np.mean(test_errors(comp.correct(sw.x_test), sw) ** 2))
                    ),
                }
            )
    return pd.DataFrame(rows, columns=["model", "name", "n_positions", "test_rms_deg"])


# ---------------------------------------------------------------------------------------------- convergence
def convergence_curves(runs: pd.DataFrame, methods=("de_bp_pure", "ade_bp_pure")) -> pd.DataFrame:
    """Best fitness J (deg^2) against generation over the seeds of each DE method of a
    :func:`seed_study` run with ``keep_errors=True`` (its ``de_history``): one row per (method, generation)
    with the 10th, 50th and 90th percentiles over the seeds."""
    rows = []
    for mid in methods:
        h = _histories(runs, mid)
        q = np.percentile(h, [10, 50, 90], axis=0)
        rows.append(
            pd.DataFrame(
                {
                    "method": mid,
                    "label": METHODS[mid].label,
                    "generation": np.arange(h.shape[1]),
                    "j_p10": q[0],
                    "j_median": q[1],
                    "j_p90": q[2],
                }
            )
        )
    return pd.concat(rows, ignore_index=True)


def _histories(runs: pd.DataFrame, mid: str) -> np.ndarray:
    """``(seeds, generations)`` best-J histories of a DE method (seed order), padded with the last value."""
    g = runs[runs.method == mid].sort_values("seed")
    if g.empty or "de_history" not in g or g.de_history.isna().any():
        raise InputError(
            f"convergence: no DE histories of {mid!r} (run the seed study with keep_errors=True)"
        )
    hs = [np.asarray(h, dtype=float) for h in g.de_history]
    n = max(len(h) for h in hs)
    return np.stack([np.concatenate([h, np.full(n - len(h), h[-1])]) for h in hs])


def convergence_generations(n_generations: int, fractions=CONVERGENCE_AT_FRACTIONS) -> list[int]:
    """The fixed generations (1-based) of :data:`~navlib.studies.compass.parameters.CONVERGENCE_AT_FRACTIONS` in a
    budget of ``n_generations``."""
    check_param("n_generations", n_generations, lo=1, integer=True)
    return sorted({min(n_generations, max(1, int(round(f * n_generations)))) for f in fractions})


def generations_to_reach(
    runs: pd.DataFrame,
    methods=("de_bp_pure", "ade_bp_pure"),
    rms_levels=CONVERGENCE_RMS_DEG,
    n_train: int = 121,
    at_fractions=CONVERGENCE_AT_FRACTIONS,
) -> pd.DataFrame:
    """Per (method, seed, level): the first generation (1-based) whose best J is at most
    ``n_train rms^2`` (the training RMS ``rms`` in deg), or ``G + 1`` if never (``reached`` False), and the
    final J; and, the same in every level's row, the training RMS of the best individual,
    ``sqrt(J / n_train)`` (deg), at each fixed generation ``g`` of :func:`convergence_generations`
    (columns ``train_rms_at_<g>``)."""
    rows = []
    for mid in methods:
        h = _histories(runs, mid)
        seeds = np.sort(runs[runs.method == mid].seed.to_numpy(int))
        at = {
            f"train_rms_at_{g}": np.sqrt(h[:, g - 1] / n_train)
            for g in convergence_generations(h.shape[1], at_fractions)
        }
        for rms in rms_levels:
            hit = h <= n_train * rms**2
            first = np.where(hit.any(axis=1), hit.argmax(axis=1) + 1, h.shape[1] + 1)
            for i, (s, f, ok, jf) in enumerate(zip(seeds, first, hit.any(axis=1), h[:, -1])):
                rows.append(
                    {
                        "method": mid,
                        "label": METHODS[mid].label,
                        "seed": int(s),
                        "rms_level_deg": rms,
                        "j_level": n_train * rms**2,
                        "generations": int(f),
                        "reached": bool(ok),
                        "final_j": float(jf),
                    }
                    | {k: float(v[i]) for k, v in at.items()}
                )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------------------- our choices
def choices_study(
    sw: Sweeps,
    params: StudyParams,
    runs: pd.DataFrame,
    box_bounds=BOX_BOUNDS,
    box_seeds=range(4),
    budget_factor: int = 10,
    budget_seeds=range(3),
    target_seeds=range(5),
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Is it our choices?  Pure DE-BP and ADE-BP with each DE search box ``[-b, b]`` of ``box_bounds``
    (``box_seeds``), pure ADE-BP with ``budget_factor`` times ``max_generations`` (``budget_seeds``), and
    pure ADE-BP and the Adam row with the heading *error* as the network's target (``target_seeds``), all
    on the engine at once.  Settings equal to the chapter's (the default box, budget and target) are taken
    from ``runs`` (:func:`seed_study`) at the same seeds, not run again.

    One row per (choice, setting, method): ``choice`` (``'search box'``, ``'DE budget'``,
    ``'network target'``), ``setting``, ``method`` (label), ``runs``, the test RMS ``median_rms_deg``,
    ``min_rms_deg`` and ``max_rms_deg`` over the seeds, and ``default`` (True for the chapter's setting).
    Over a few seeds: the spread (min..max) is shown, not an interval, and no verdict rests on it."""
    check_param("budget_factor", budget_factor, lo=2, integer=True)
    box_seeds, budget_seeds, target_seeds = (
        list(map(int, s)) for s in (box_seeds, budget_seeds, target_seeds)
    )
    for name, s in (
        ("box_seeds", box_seeds),
        ("budget_seeds", budget_seeds),
        ("target_seeds", target_seeds),
    ):
        if not s:
            raise InputError(f"choices_study: parameter {name} is empty")
    pure = ("de_bp_pure", "ade_bp_pure")
    base_bound, gmax = float(params.de.bound), int(params.de.max_generations)
    studies, keys = [], []
    for b in box_bounds:
        if float(b) != base_bound:
            studies.append(
                (sw, replace(params, de=replace(params.de, bound=float(b))), box_seeds, pure)
            )
            keys.append(("search box", float(b)))
    studies.append(
        (
            sw,
            replace(params, de=replace(params.de, max_generations=budget_factor * gmax)),
            budget_seeds,
            ("ade_bp_pure",),
        )
    )
    keys.append(("DE budget", budget_factor * gmax))
    other = "error" if params.network_target == "heading" else "heading"
    studies.append(
        (sw, replace(params, network_target=other), target_seeds, ("bp_adam", "ade_bp_pure"))
    )
    keys.append(("network target", other))
    frames = dict(zip(keys, seed_studies(studies, workers=workers, scheduler=scheduler)))

    def base(mids, seeds):
        part = runs[runs.method.isin(mids) & runs.seed.isin(seeds)]
        missing = {(m, s) for m in mids for s in seeds} - set(zip(part.method, part.seed))
        if missing:
            m, s = sorted(missing)[0]
            raise InputError(
                f"choices_study: runs has no run of {m} with seed {s} (run seed_study with it)"
            )
        return part

    parts = []
    for b in box_bounds:
        key = ("search box", float(b))
        f = frames[key] if key in frames else base(pure, box_seeds)
        parts.append(
            f.assign(choice="search box", setting=f"[-{b:g}, {b:g}]", default=key not in frames)
        )
    for g, f in (
        (gmax, base(("ade_bp_pure",), budget_seeds)),
        (budget_factor * gmax, frames[("DE budget", budget_factor * gmax)]),
    ):
        parts.append(f.assign(choice="DE budget", setting=f"{g} generations", default=g == gmax))
    for t, f in (
        (params.network_target, base(("bp_adam", "ade_bp_pure"), target_seeds)),
        (other, frames[("network target", other)]),
    ):
        parts.append(
            f.assign(choice="network target", setting=t, default=t == params.network_target)
        )
    df = pd.concat([f.assign(part=k) for k, f in enumerate(parts)], ignore_index=True)
    df["method"] = df.method.map(label)
    order = {m: k for k, m in enumerate(map(label, ("de_bp_pure", "ade_bp_pure", "bp_adam")))}
    df = df.assign(rank=df.method.map(order)).sort_values(["part", "rank"], kind="stable")
    g = df.groupby(["part", "choice", "setting", "method"], sort=False)
    return (
        pd.DataFrame(
            {
                "runs": g.size(),
                "median_rms_deg": g.rms_deg.median(),
                "min_rms_deg": g.rms_deg.min(),
                "max_rms_deg": g.rms_deg.max(),
                "default": g["default"].first(),
            }
        )
        .reset_index()
        .drop(columns="part")
    )
