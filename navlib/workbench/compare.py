"""Which of the papers' compensation methods works best on *your* measurements (``navlib compare SYSTEM
FILE``): every method fitted on one part of the file and scored on the rest, over seeds, ranked by held-out
error with 95 % intervals and judged against the best by the book's one verdict rule.

The file is cut into **folds** by a split rule; in each fold every method is fitted on the training rows
and corrects the test rows, and every row is a test row in exactly one fold:

- ``sweep``: one fold per sweep (column ``sweep``): train on the other sweeps, test on it (two sweeps:
  train on one, test on the other, both ways);
- ``heading`` (the compass): alternate bins of ``bin_deg`` of true heading (bin ``k = floor(psi / w)``):
  fold 1 trains on the even bins and tests on the odd ones, fold 2 the other way round;
- ``random``: the rows in a random order (seeded), cut in two halves: fold 1 tests on the first half,
  fold 2 on the second.

A method's held-out error for run ``k`` pools the test rows of every fold (error ``e_i`` of row ``i``, in
the system's unit, from the fold in which ``i`` is a test row):

    RMS_k = sqrt( (1/n) sum_i e_i^2 )                                                      (eq-compare-rms)

Run ``k`` of every stochastic method in fold ``f`` draws from the generator of the spawn key
``(1, f, k)`` of ``SeedSequence(seed)`` (:func:`navlib.seeding.sequence`): every method over the same
seeds.  Per method the median of ``RMS_k`` over the seeds with its distribution-free 95 % interval
(:func:`navlib.verdicts.median_ci`; a deterministic method is one exact value); against the best method
(the smallest median) the paired differences ``RMS_k(method) - RMS_k(best)`` over the same seeds
(:func:`navlib.verdicts.paired_difference`), judged by :func:`navlib.verdicts.decide` for the claim "the
best method has the smaller held-out error" (boundary 0, or ``margin``).  The intervals cover the
training randomness (seeds), not the sampling of the measurements: another recording of the same compass
could rank close methods differently.

Systems register a :class:`Comparison` (:func:`register_comparison`): its loader, methods, default list,
split rules and fitting.  The compass's (:data:`COMPASS`) fits paper A's and document B's methods from
:mod:`navlib.methods.compass_methods`; drift and accelerometer can follow with their papers' methods.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np
import pandas as pd

from .. import engine, verdicts
from ..angles import wrap_deg
from ..data.compass_sweeps import load_sweeps
from ..errors import InputError, check_param
from ..methods import compass_methods as cm
from ..methods.seeding import sequence
from ..methods.smith import nearest_positions
from ..plotstyle import DPI, legend_below, panels

SPLITS = ("sweep", "heading", "random")
#: Runs of a stochastic method per engine task (a fixed size: the numbers never depend on the workers).
SEED_BATCH = 4
#: Rows a fold must train on (a network of paper A has 19 weights; fewer rows than that still fit, but
#: fewer than 8 cannot even place the 8-position least squares).
MIN_TRAIN_ROWS = 8


# ------------------------------------------------------------------------------------------ folds
@dataclass(frozen=True)
class Fold:
    """One fold of a split: ``train`` and ``test`` row positions (0-based, into the loaded frame) and
    what each part is (``train_what``, ``test_what``: e.g. "sweep 1", "odd 15-deg heading bins")."""

    train: np.ndarray
    test: np.ndarray
    train_what: str
    test_what: str

    def to_dict(self, k: int) -> dict:
        return {
            "fold": k + 1,
            "train": self.train_what,
            "test": self.test_what,
            "train_rows": int(self.train.size),
            "test_rows": int(self.test.size),
        }


def sweep_folds(frame: pd.DataFrame, name: str = "data") -> list[Fold]:
    """One fold per sweep: test on it, train on the others (column ``sweep``; at least two sweeps)."""
    ids = sorted(int(v) for v in pd.unique(frame["sweep"])) if "sweep" in frame else []
    if len(ids) < 2:
        raise InputError(
            f"{name}: --split sweep needs at least 2 sweeps in column 'sweep', the file has "
            f"{len(ids)} (no 'sweep' column, or one value in it); use --split heading or random"
        )
    s = frame["sweep"].to_numpy()
    folds = []
    for i in ids:
        others = [j for j in ids if j != i]
        what = f"sweep {others[0]}" if len(others) == 1 else "sweeps " + ", ".join(map(str, others))
        folds.append(Fold(np.flatnonzero(s != i), np.flatnonzero(s == i), what, f"sweep {i}"))
    return folds


def check_bin_deg(bin_deg: float) -> float:
    """``bin_deg`` must cut the circle into an even number of bins (so that the bins alternate all round)."""
    check_param("--bin-deg", bin_deg, lo=0, lo_open=True, hi=180)
    n = 360.0 / float(bin_deg)
    if abs(n - round(n)) > 1e-9 or round(n) % 2:
        raise InputError(
            f"parameter --bin-deg={bin_deg:g}: must cut 360 deg into an even number of bins "
            f"(e.g. 5, 10, 15, 30, 45, 90)"
        )
    return float(bin_deg)


def bin_folds(angle_deg, bin_deg: float, what: str = "heading") -> list[Fold]:
    """Two folds from alternate bins of ``bin_deg`` of an angle (deg): bin ``floor(mod(a, 360) / w)``;
    fold 1 trains on the even bins and tests on the odd ones, fold 2 the reverse."""
    w = check_bin_deg(bin_deg)
    k = np.floor(np.mod(np.asarray(angle_deg, dtype=float), 360.0) / w).astype(int) % int(
        round(360.0 / w)
    )
    odd = k % 2 == 1
    even_name, odd_name = f"even {w:g}-deg {what} bins", f"odd {w:g}-deg {what} bins"
    return [
        Fold(np.flatnonzero(~odd), np.flatnonzero(odd), even_name, odd_name),
        Fold(np.flatnonzero(odd), np.flatnonzero(~odd), odd_name, even_name),
    ]


def random_folds(n_rows: int, seed: int) -> list[Fold]:
    """Two folds from the rows in a random order (generator of spawn key ``(0,)`` of ``SeedSequence(seed)``)
    cut in two halves: fold 1 tests on the first half, fold 2 on the second."""
    order = np.random.default_rng(sequence(seed, 0)).permutation(int(n_rows))
    a, b = np.sort(order[: n_rows // 2]), np.sort(order[n_rows // 2 :])
    return [
        Fold(b, a, "random half 2", "random half 1"),
        Fold(a, b, "random half 1", "random half 2"),
    ]


def check_folds(folds: Sequence[Fold], name: str, n_rows: int) -> None:
    """Every fold trains on at least :data:`MIN_TRAIN_ROWS` rows and tests on at least one; the test parts
    are disjoint from their training parts and together hold every row once."""
    for k, f in enumerate(folds):
        if f.train.size < MIN_TRAIN_ROWS or f.test.size < 1:
            raise InputError(
                f"{name}: fold {k + 1} (train {f.train_what}, test {f.test_what}) has "
                f"{f.train.size} training and {f.test.size} test rows; at least {MIN_TRAIN_ROWS} "
                f"and 1 are needed (choose another --split)"
            )
    tested = np.sort(np.concatenate([f.test for f in folds]))
    if not np.array_equal(tested, np.arange(n_rows)) or any(
        np.intersect1d(f.train, f.test).size for f in folds
    ):
        raise AssertionError(
            "split: every row must be a test row exactly once, never in its own training part"
        )


# ------------------------------------------------------------------------------------------ systems
@dataclass(frozen=True)
class Comparison:
    """What ``navlib compare`` needs of a system.

    ``system``, ``unit``: the workbench's name and unit; ``load(path) -> DataFrame`` (validated, one-line
    errors); ``methods``: method id -> display label; ``default``: the ids run when none are named;
    ``stochastic(id)``: whether a method draws from its generator; ``splits``: the rules it offers;
    ``folds(frame, rule, settings, name, seed)`` -> the folds; ``settings(**options)`` -> the fitting
    settings (checked; ``settings.to_dict()`` shows them);
    ``cannot_fit(id, train, settings, part)`` -> None, or why the method cannot be fitted on the training
    rows ``train`` (e.g. too few headings; ``part`` names them in the message); ``run(id, settings, train,
    test, rngs)`` -> one array of test-row errors per run (``train``/``test``: dicts of column arrays);
    ``cost(id, settings)`` -> CPU seconds per run; ``columns``: the columns the fits read; ``x_column``,
    ``x_label``: what the report's figure draws the error against."""

    system: str
    unit: str
    load: Callable[[str], pd.DataFrame]
    methods: Mapping[str, str]
    default: tuple[str, ...]
    stochastic: Callable[[str], bool]
    splits: tuple[str, ...]
    folds: Callable[..., list[Fold]]
    settings: Callable[..., object]
    cannot_fit: Callable[[str, pd.DataFrame, object, str], str | None]
    run: Callable[..., list[np.ndarray]]
    cost: Callable[[str, object], float]
    columns: tuple[str, ...]
    x_column: str
    x_label: str
    error_label: str = "held-out error"


#: The systems ``navlib compare`` knows, by name.
COMPARISONS: dict[str, Comparison] = {}


def register_comparison(c: Comparison) -> Comparison:
    """Add a system's :class:`Comparison` to :data:`COMPARISONS`."""
    if set(c.default) - set(c.methods):
        raise InputError(f"comparison {c.system}: default methods not in its methods")
    COMPARISONS[c.system] = c
    return c


def get_comparison(system: str) -> Comparison:
    if system not in COMPARISONS:
        raise InputError(
            f"compare: unknown system {system!r}; known: {', '.join(sorted(COMPARISONS))}"
        )
    return COMPARISONS[system]


def resolve_methods(c: Comparison, names: str | Sequence[str] | None) -> tuple[list[str], bool]:
    """The method ids asked for (comma-separated text or a list; None: the system's default) and whether
    they were named explicitly.  An unknown name: one line listing the known ones."""
    if names is None:
        return list(c.default), False
    items = [n.strip() for n in (names.split(",") if isinstance(names, str) else names)]
    items = [n for n in items if n]
    if not items:
        raise InputError("parameter --methods: empty; give method ids separated by commas")
    unknown = [n for n in items if n not in c.methods]
    if unknown:
        raise InputError(
            f"parameter --methods: unknown method {unknown[0]!r} for {c.system}; known: "
            f"{', '.join(c.methods)}"
        )
    return list(dict.fromkeys(items)), True


# ------------------------------------------------------------------------------------------ the compass
@dataclass(frozen=True)
class CompassSettings:
    """The compass's fitting settings: the methods' (:class:`navlib.methods.compass_methods.MethodParams`,
    paper A's and document B's defaults) with the 8-position tolerance ``ls_tolerance_deg``, and the
    heading split's ``bin_deg``."""

    params: cm.MethodParams = cm.MethodParams()
    bin_deg: float = 15.0

    def to_dict(self) -> dict:
        return {"ls_tolerance_deg": self.params.ls_tol_deg, "bin_deg": self.bin_deg}


def compass_settings(
    ls_tolerance_deg: float = 5.0, bin_deg: float = 15.0, params: cm.MethodParams | None = None
) -> CompassSettings:
    """Paper A's and document B's settings (``params``, default
    :class:`navlib.methods.compass_methods.MethodParams`), the 8-position least squares taking the nearest
    reading within ``ls_tolerance_deg`` of each position, the heading split's bins ``bin_deg`` wide."""
    check_param("--ls-tolerance", ls_tolerance_deg, lo=0, hi=22.5)
    if params is not None and not isinstance(params, cm.MethodParams):
        raise InputError("parameter params: must be a navlib.methods.compass_methods.MethodParams")
    return CompassSettings(
        replace(params or cm.MethodParams(), ls_tol_deg=float(ls_tolerance_deg)),
        check_bin_deg(bin_deg),
    )


def _compass_folds(
    frame: pd.DataFrame, rule: str, settings: CompassSettings, name: str, seed: int
) -> list[Fold]:
    if rule == "sweep":
        return sweep_folds(frame, name)
    if rule == "heading":
        return bin_folds(frame["true_heading_deg"].to_numpy(float), settings.bin_deg, "heading")
    return random_folds(len(frame), seed)


#: The 8-position least squares' ids: they need a reading near each of the 8 positions.
EIGHT_POSITION = tuple(cm.LS_MODELS)


def _compass_cannot_fit(
    mid: str, train: pd.DataFrame, settings: CompassSettings, part: str
) -> str | None:
    """Why ``mid`` cannot be fitted on the training rows ``train`` (named ``part``): the 8-position LS needs
    a reading within the tolerance of each of 0, 45, ..., 315 deg true heading (the nearest one is used)."""
    if mid not in EIGHT_POSITION:
        return None
    tol = settings.params.ls_tol_deg
    idx = nearest_positions(train["true_heading_deg"].to_numpy(float), 45.0, tol)
    if (idx >= 0).all():
        return None
    missing = ", ".join(f"{45 * k:g}" for k in np.flatnonzero(idx < 0))
    return (
        f"needs 8 headings (a reading within {tol:g} deg of each of 0, 45, ..., 315 deg true heading, the "
        f"nearest one is used; --ls-tolerance widens it) and {part} has {int((idx >= 0).sum())} (none near "
        f"{missing} deg)"
    )


def network_input(measured_train, measured) -> np.ndarray:
    """The measured heading on one continuous branch for a single-input network: ``c + mod(m - c, 360)``,
    the cut ``c`` in the middle of the *narrowest* gap between the training part's measured headings (read
    in any order).  Every gap of the training headings then lies inside the branch, so a test heading in a
    gap is interpolated between training readings, and one near the cut lies at most half the narrowest gap
    beyond the training range.  On paper A's turntable sweep (readings at 0 and 360 deg) the cut is at 0 deg,
    as its unwrapping along the sweep gives; this rule also holds for rows in any order and for a test part
    taken from between the training headings."""
    s = np.sort(np.mod(np.asarray(measured_train, dtype=float), 360.0))
    gaps = np.diff(np.concatenate([s, [s[0] + 360.0]]))
    j = int(np.argmin(gaps))
    cut = s[j] + gaps[j] / 2.0
    return cut + np.mod(np.asarray(measured, dtype=float) - cut, 360.0)


def compass_errors(
    mid: str, settings: CompassSettings, train: dict, test: dict, rngs
) -> list[np.ndarray]:
    """Fit method ``mid`` on the training rows (one run per generator) and return each run's wrapped error
    ``wrap(compensated - true)`` (deg) on the test rows.  The network input is :func:`network_input`, its
    reference heading unwrapped next to it (``x + wrap(psi - x)``: the target is continuous too)."""
    x_train = network_input(train["measured_heading_deg"], train["measured_heading_deg"])
    x_test = network_input(train["measured_heading_deg"], test["measured_heading_deg"])
    ref = x_train + wrap_deg(np.asarray(train["true_heading_deg"], dtype=float) - x_train)
    fitted = cm.fit_method(mid, x_train, ref, settings.params, rngs=rngs)
    return [
        wrap_deg(f.correct(x_test) - np.asarray(test["true_heading_deg"], dtype=float))
        for f in fitted
    ]


#: The default methods of ``navlib compare compass``: uncompensated; paper A's 8-position LS under the
#: three models; the exact planar model fitted to every training reading; MATLAB's BP (trainlm); DE-BP and
#: ADE-BP in the primary reading of paper A's claims register (reading 4: the full DE stage, then
#: trainlm); document B's plain and back-tuned ELM.
COMPASS_DEFAULT = (
    ("uncompensated", "ls8", "ls8_planar", "ls8_h3", "physical", "bp_matlab")
    + cm.READINGS[cm.R4][2:]
    + cm.ELM_METHODS
)

#: The compass's comparison: paper A's and document B's methods (:mod:`navlib.methods.compass_methods`) on a
#: compass sweep file (:func:`navlib.data.compass_sweeps.load_sweeps`).
COMPASS = register_comparison(
    Comparison(
        system="compass",
        unit="deg",
        load=load_sweeps,
        methods={mid: spec.label for mid, spec in cm.METHODS.items()},
        default=COMPASS_DEFAULT,
        stochastic=lambda mid: cm.METHODS[mid].stochastic,
        splits=SPLITS,
        folds=_compass_folds,
        settings=compass_settings,
        cannot_fit=_compass_cannot_fit,
        run=compass_errors,
        cost=lambda mid, s: cm.unit_cost((mid,), s.params),
        columns=("true_heading_deg", "measured_heading_deg"),
        x_column="true_heading_deg",
        x_label="true heading (deg)",
    )
)


# ------------------------------------------------------------------------------------------ the runs
def _task(
    system: str, mid: str, settings, train: dict, test: dict, fold: int, seeds: tuple, seed: int
) -> list:
    """One engine task: method ``mid`` in fold ``fold`` for the runs ``seeds`` (each from the generator of
    spawn key ``(1, fold, k)`` of ``SeedSequence(seed)``).  Module level: workers import it."""
    c = COMPARISONS[system]
    rngs = [np.random.default_rng(sequence(seed, 1, fold, k)) for k in seeds]
    return [np.asarray(e, dtype=float) for e in c.run(mid, settings, train, test, rngs)]


@dataclass
class CompareResult:
    """The outcome of :func:`compare`: per method its pooled test-row errors per run (``errors[id]``, an
    array ``(runs, rows)`` in the file's row order, each row's error from the fold that held it out), the
    folds, and the default methods that were not run and why (``not_run``).  :meth:`table`, :meth:`text`,
    :meth:`to_dict` present it; :func:`write_report` writes it."""

    system: str
    unit: str
    source: str
    frame: pd.DataFrame
    rule: str
    folds: list[Fold]
    seeds: int
    seed: int
    methods: list[str]
    labels: dict[str, str]
    stochastic: dict[str, bool]
    errors: dict[str, np.ndarray]
    not_run: list[dict] = field(default_factory=list)
    settings: dict = field(default_factory=dict)
    margin: float | None = None
    x_column: str = ""
    x_label: str = ""
    _table: pd.DataFrame | None = field(default=None, repr=False)

    # ------------------------------------------------------------------ statistics
    def rms(self, mid: str) -> np.ndarray:
        """Held-out RMS per run (eq-compare-rms), one value for a deterministic method."""
        e = self.errors[mid]
        return np.sqrt(np.mean(e**2, axis=1))

    def estimate(self, mid: str) -> tuple[verdicts.Estimate | None, str]:
        """Median held-out RMS over the runs with its 95 % interval (exact for one deterministic run)."""
        r = self.rms(mid)
        if not self.stochastic[mid]:
            return verdicts.exact(float(r[0])), ""
        return verdicts.attempt(verdicts.median_ci, r)

    @property
    def best(self) -> str:
        """The method with the smallest median held-out RMS (the first of equals)."""
        med = {m: float(np.median(self.rms(m))) for m in self.methods}
        return min(self.methods, key=lambda m: med[m])

    def versus_best(self, mid: str) -> dict:
        """``RMS(mid) - RMS(best)`` paired over the same seeds (a deterministic method pairs its one value
        with every seed) and the verdict on "the best method has the smaller held-out error"."""
        a, b = self.rms(mid), self.rms(self.best)
        if a.size != b.size:
            a, b = np.broadcast_arrays(a, b)
        if a.size == 1:
            est, why = verdicts.exact(float(a[0] - b[0])), ""
        else:
            est, why = verdicts.attempt(verdicts.paired_difference, a, b)
        reproduced, basis = verdicts.decide(
            est.interval if est else None, 0.0, "above", margin=self.margin
        )
        if est is None:
            basis = "no statistic"
        finding = {
            True: "best is better",
            False: f"{self.labels[mid]} is better",
            None: "not told apart",
        }[reproduced]
        if basis == "equivalent":
            finding = f"no difference at {self.margin:g} {self.unit}"
        elif basis == "no statistic":
            finding = "too few seeds for an interval"
        return {
            "difference": est,
            "verdict": verdicts.verdict_name(reproduced, basis),
            "basis": basis,
            "finding": finding,
            "why": why,
        }

    def median_run(self, mid: str) -> int:
        """The run whose RMS is the median (the lower middle for an even count): the one the figure draws."""
        r = self.rms(mid)
        return int(np.argsort(r, kind="stable")[(r.size - 1) // 2])

    def table(self) -> pd.DataFrame:
        """One row per method, best first: label, runs, median RMS with interval, median of each run's
        smallest and largest error, difference to the best with interval, the verdict."""
        if self._table is not None:
            return self._table
        rows = []
        best = self.best
        for mid in self.methods:
            est, why = self.estimate(mid)
            e = self.errors[mid]
            vs = None if mid == best else self.versus_best(mid)
            d = vs["difference"] if vs else None
            rows.append(
                {
                    "method": mid,
                    "label": self.labels[mid],
                    "runs": int(e.shape[0]),
                    "rms": float(np.median(self.rms(mid))),
                    "rms_lo": est.lo if est else np.nan,
                    "rms_hi": est.hi if est else np.nan,
                    "rms_why": why,
                    "min_error": float(np.median(e.min(axis=1))),
                    "max_error": float(np.median(e.max(axis=1))),
                    "vs_best": d.value if d else (0.0 if mid == best else np.nan),
                    "vs_best_lo": d.lo if d else np.nan,
                    "vs_best_hi": d.hi if d else np.nan,
                    "verdict": vs["verdict"] if vs else "",
                    "basis": vs["basis"] if vs else "",
                    "finding": vs["finding"] if vs else "best",
                }
            )
        t = pd.DataFrame(rows)
        order = np.lexsort((np.arange(len(t)), t["rms"].to_numpy()))
        self._table = t.iloc[order].reset_index(drop=True)
        return self._table

    # ------------------------------------------------------------------ output
    def not_run_lines(self) -> list[str]:
        """One line per reason a default method was left out, naming the methods it applies to."""
        by: dict[str, list[str]] = {}
        for r in self.not_run:
            by.setdefault(r["why"], []).append(r["method"])
        return [
            f"not run: {', '.join(ms)}: {why}" if len(ms) > 1 else f"not run: {ms[0]} {why}"
            for why, ms in by.items()
        ]

    def to_dict(self) -> dict:
        """The result as JSON-ready data (snake_case keys, no NaN: a missing interval is null)."""

        def est(e):
            return (
                None
                if e is None
                else {"value": e.value, "lo": e.lo, "hi": e.hi, "rule": e.rule, "n": e.n}
            )

        methods = []
        best = self.best
        for rank, row in enumerate(self.table().itertuples(), start=1):
            mid = row.method
            e, why = self.estimate(mid)
            vs = None if mid == best else self.versus_best(mid)
            methods.append(
                {
                    "method": mid,
                    "label": row.label,
                    "rank": rank,
                    "stochastic": self.stochastic[mid],
                    "runs": row.runs,
                    "rms": est(e),
                    "rms_why": why or None,
                    "rms_per_run": [float(v) for v in self.rms(mid)],
                    "median_min_error": row.min_error,
                    "median_max_error": row.max_error,
                    "versus_best": None
                    if vs is None
                    else {
                        "difference": est(vs["difference"]),
                        "verdict": vs["verdict"],
                        "basis": vs["basis"],
                        "finding": vs["finding"],
                        "why": vs["why"] or None,
                    },
                }
            )
        return {
            "system": self.system,
            "file": self.source,
            "unit": self.unit,
            "rows": int(len(self.frame)),
            "split": {"rule": self.rule, "folds": [f.to_dict(k) for k, f in enumerate(self.folds)]},
            "seeds": self.seeds,
            "seed": self.seed,
            "margin": self.margin,
            "settings": self.settings,
            "best": best,
            "claim": "the best method has the smaller held-out rms (paired over the same seeds)",
            "methods": methods,
            "not_run": list(self.not_run),
        }

    def text(self) -> str:
        """The comparison as text: what was split how, the table, what was not run."""
        u = self.unit
        lines = [
            f"{self.system}: {os.path.basename(self.source) or self.source}, {len(self.frame)} rows; "
            f"split by {self.rule}, {len(self.folds)} folds; {self.seeds} seeds (seed {self.seed})"
        ]
        for k, f in enumerate(self.folds):
            lines.append(
                f"  fold {k + 1}: train {f.train_what} ({f.train.size} rows), test {f.test_what} "
                f"({f.test.size} rows)"
            )
        lines.append(
            f"held-out rms over every test row, median over seeds [95 % interval], {u}; "
            f"best: {self.labels[self.best]}"
        )
        t = self.table()

        def iv(v, lo, hi, spec):
            if not np.isfinite(v):
                return "-"
            if not (np.isfinite(lo) and np.isfinite(hi)):
                return spec.format(v)
            return f"{spec.format(v)} [{spec.format(lo)}, {spec.format(hi)}]"

        show = pd.DataFrame(
            {
                "method": t["label"],
                "runs": t["runs"],
                f"rms ({u}) [95 %]": [iv(*v, "{:.3f}") for v in zip(t.rms, t.rms_lo, t.rms_hi)],
                f"range ({u})": [f"{a:+.2f}..{b:+.2f}" for a, b in zip(t.min_error, t.max_error)],
                f"minus best ({u}) [95 %]": [
                    iv(*v, "{:+.3f}") if m != self.best else "-"
                    for m, *v in zip(t.method, t.vs_best, t.vs_best_lo, t.vs_best_hi)
                ],
                "verdict": t["finding"],
            }
        )
        lines += ["", show.to_string(index=False)]
        lines += self.not_run_lines()
        lines.append(
            "verdict: the book's rule (navlib.verdicts.decide) on the paired difference to the best over "
            "the same seeds; the intervals cover training randomness, not another recording"
        )
        return "\n".join(lines)


# ------------------------------------------------------------------------------------------ the study
def compare(
    system: str,
    source,
    methods: str | Sequence[str] | None = None,
    split: str | None = None,
    seeds: int = 10,
    seed: int = 0,
    margin: float | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    frame: pd.DataFrame | None = None,
    **options,
) -> CompareResult:
    """Fit ``methods`` (ids of the system's :class:`Comparison`; None: its default) on the folds of
    ``split`` (``sweep``, ``heading``, ``random``; None: ``sweep`` when the file has two sweeps or more,
    else ``heading``) of the file ``source`` and score them on the held-out rows (module docstring, eq.
    eq-compare-rms), ``seeds`` runs of each stochastic method, on :mod:`navlib.engine` (``workers`` local
    processes or the cluster at ``scheduler``; the numbers do not depend on where a task ran).

    Parameters
    ----------
    system : str
        A system of :data:`COMPARISONS` (``"compass"``).
    source : str or path
        The measurement file (read with the system's validating loader unless ``frame`` is given).
    methods : str or sequence of str, optional
        Method ids, comma-separated or a list; unknown ids raise one line listing the known ones.  A method
        named explicitly that cannot be fitted on a fold (the 8-position LS without its 8 headings) is
        refused; one of the default list is left out and listed in ``not_run``.
    split : str, optional
        The split rule.
    seeds : int
        Runs of every stochastic method (the same seeds for all; 6 or more give a 95 % interval).
    seed : int
        Entropy of every random draw: the random split and the runs' generators.
    margin : float, optional
        Equivalence margin (the system's unit) of the verdict against the best method.
    workers, scheduler
        Where the runs go (:func:`navlib.engine.run`).
    frame : pandas.DataFrame, optional
        The data, already loaded and checked by the caller (``source`` then only names it in messages).
    options
        The system's settings (compass: ``ls_tolerance_deg`` = 5, ``bin_deg`` = 15).

    Returns
    -------
    CompareResult
    """
    c = get_comparison(system)
    check_param("--seeds", seeds, lo=1, hi=10000, integer=True)
    check_param("--seed", seed, lo=0, integer=True)
    if margin is not None:
        check_param("--margin", margin, lo=0, lo_open=True)
    if split is not None and split not in c.splits:
        raise InputError(f"parameter --split={split!r}: must be one of {', '.join(c.splits)}")
    mids, explicit = resolve_methods(c, methods)
    settings = c.settings(**options)
    name = Path(str(source)).name
    data = c.load(source) if frame is None else frame.reset_index(drop=True)
    if split is None:
        split = "sweep" if "sweep" in data and data["sweep"].nunique() >= 2 else "heading"
    folds = c.folds(data, split, settings, name, seed)
    check_folds(folds, name, len(data))
    not_run, run = [], []
    for mid in mids:
        why = next(
            (
                w
                for k, f in enumerate(folds)
                if (
                    w := c.cannot_fit(
                        mid,
                        data.iloc[f.train],
                        settings,
                        f"the training part of fold {k + 1} ({f.train_what})",
                    )
                )
            ),
            None,
        )
        if why is None:
            run.append(mid)
        elif explicit:
            raise InputError(
                f"{name}: method {mid} ({c.methods[mid]}) {why}; leave it out of --methods"
            )
        else:
            not_run.append({"method": mid, "label": c.methods[mid], "why": why})
    if not run:
        raise InputError(
            f"{name}: none of the methods can be fitted on this split ({not_run[0]['why']})"
        )
    arrays = {col: data[col].to_numpy(float) for col in c.columns}
    tasks, cost, owner = [], [], []
    for mid in run:
        stochastic = c.stochastic(mid)
        ks = list(range(seeds)) if stochastic else [0]
        chunks = [tuple(ks[i : i + SEED_BATCH]) for i in range(0, len(ks), SEED_BATCH)]
        for k, f in enumerate(folds):
            train = {col: a[f.train] for col, a in arrays.items()}
            test = {col: a[f.test] for col, a in arrays.items()}
            for ch in chunks:
                tasks.append((c.system, mid, settings, train, test, k, ch, int(seed)))
                cost.append(c.cost(mid, settings) * len(ch))
                owner.append((mid, k))
    parts = engine.run(
        _task,
        tasks,
        workers=workers,
        scheduler=scheduler,
        cost=cost,
        label=f"compare {system}",
        weight=[len(t[6]) for t in tasks],
    )
    errors = {}
    for mid in run:
        n_runs = seeds if c.stochastic(mid) else 1
        e = np.empty((n_runs, len(data)))
        for k, f in enumerate(folds):
            runs = [r for (m, kk), part in zip(owner, parts) if m == mid and kk == k for r in part]
            e[:, f.test] = np.asarray(runs)
        errors[mid] = e
    return CompareResult(
        c.system,
        c.unit,
        str(source),
        data,
        split,
        folds,
        int(seeds),
        int(seed),
        run,
        {m: c.methods[m] for m in run},
        {m: bool(c.stochastic(m)) for m in run},
        errors,
        not_run,
        settings=settings.to_dict(),
        margin=margin,
        x_column=c.x_column,
        x_label=c.x_label,
    )


# ------------------------------------------------------------------------------------------ the report
REPORT_FILES = ("compare.md", "compare.png")


@contextmanager
def claimed_report(folder):
    """Claim ``folder``'s report files before the work: ``compare.md`` and ``compare.png`` are created
    empty in one step each (``open(..., "x")``: never over an existing file, nor one that appears in the
    meantime); if the work then fails, the empty files this call created are removed again.  Yields the two
    paths."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder}: is a file, expected a folder for the report")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InputError(
            f"{folder}: cannot create the report folder ({err.strerror or err})"
        ) from None
    made = []
    try:
        for name in REPORT_FILES:
            p = folder / name
            try:
                with open(p, "x"):
                    pass
            except FileExistsError:
                raise InputError(
                    f"{p}: already exists; not overwritten (choose another --report folder)"
                ) from None
            except OSError as err:
                raise InputError(
                    f"{p}: cannot write the report there ({err.strerror or err})"
                ) from None
            made.append(p)
        yield tuple(made)
    except BaseException:
        for p in made:
            if p.exists() and p.stat().st_size == 0:
                p.unlink()
        raise


#: The figure's curves break where the test rows leave a gap wider than this (deg of heading).
GAP_DEG = 15.0


def _broken(x, y, gap: float):
    """``x`` (sorted) and ``y`` with a NaN between neighbours more than ``gap`` apart: no line across a gap."""
    cut = np.flatnonzero(np.diff(x) > gap) + 1
    return np.insert(x.astype(float), cut, np.nan), np.insert(y.astype(float), cut, np.nan)


def report_figure(result: CompareResult):
    """Error against the x column (the compass: true heading) per method, one panel each (best first, two
    columns), the run of median RMS, the test rows of each fold in their own colour and no line across a gap
    wider than :data:`GAP_DEG`: paper A's Figs 3 and 4 drawn for the user's file."""
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: matplotlib only for figures; the CLI's loop runs without it

    t = result.table()
    n = len(t) + (len(t) % 2 if len(t) > 1 else 0)  # an even count: two columns
    fig, axes = panels(n, panel_height_in=2.0, sharex=True)
    axes = [axes] if n == 1 else list(axes)
    for ax in axes[len(t) :]:
        ax.set_visible(False)
    axes = axes[: len(t)]
    x = result.frame[result.x_column].to_numpy(float)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, row in zip(axes, t.itertuples()):
        e = result.errors[row.method][result.median_run(row.method)]
        for k, f in enumerate(result.folds):
            o = f.test[np.argsort(x[f.test], kind="stable")]
            ax.plot(
                *_broken(x[o], e[o], GAP_DEG),
                ".-",
                ms=3,
                lw=0.6,
                color=colours[k % len(colours)],
                label=f"test {f.test_what}",
            )
        ax.axhline(0.0, color="0.4", lw=0.6)
        ax.set_title(f"{row.label}: rms {row.rms:.3g} {result.unit}", fontsize=10)
        ax.set_ylabel(f"error ({result.unit})")
        if result.x_column == "true_heading_deg":
            ax.set_xticks(np.arange(0, 361, 90))
    for ax in axes[-2:]:
        ax.set_xlabel(result.x_label)
        ax.xaxis.set_tick_params(labelbottom=True)
    legend_below(axes[-1], ncol=min(len(result.folds), 3))
    return fig


def write_report(result: CompareResult, paths) -> tuple[Path, Path]:
    """Write the claimed files (:func:`claimed_report`): ``compare.md`` (the folds, the table, what was not
    run, the verdict rule) and ``compare.png`` (:func:`report_figure`)."""
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: matplotlib only for figures; the CLI's loop runs without it

    md, png = (Path(p) for p in paths)
    fig = report_figure(result)
    with open(png, "wb") as fh:  # the file this run claimed
        fig.savefig(fh, dpi=DPI, format="png")
    plt.close(fig)
    u = result.unit
    lines = [
        f"# navlib compare {result.system}: `{result.source}`",
        "",
        f"{len(result.frame)} rows, split by {result.rule} into {len(result.folds)} folds "
        f"(every row a test row once); {result.seeds} seeds per stochastic method (seed {result.seed}).",
        "",
    ]
    lines += [
        f"- fold {k + 1}: train {f.train_what} ({f.train.size} rows), test {f.test_what} ({f.test.size} rows)"
        for k, f in enumerate(result.folds)
    ]
    lines += [
        "",
        f"| method | runs | held-out rms ({u}) | 95 % interval | error range ({u}) | minus best ({u}) "
        f"| 95 % interval | verdict |",
        "|---|---|---|---|---|---|---|---|",
    ]

    def iv(lo, hi, spec):
        return (
            "-"
            if not (np.isfinite(lo) and np.isfinite(hi))
            else f"{spec.format(lo)} .. {spec.format(hi)}"
        )

    for r in result.table().itertuples():
        lines.append(
            f"| {r.label} | {r.runs} | {r.rms:.3f} | {iv(r.rms_lo, r.rms_hi, '{:.3f}')} | "
            f"{r.min_error:+.2f} .. {r.max_error:+.2f} | "
            f"{'-' if r.method == result.best else f'{r.vs_best:+.3f}'} | "
            f"{iv(r.vs_best_lo, r.vs_best_hi, '{:+.3f}')} | {r.finding} |"
        )
    lines += [""] + [f"{line[0].upper()}{line[1:]}." for line in result.not_run_lines()]
    lines += [
        "",
        "Held-out rms: every test row once, median over the seeds with its distribution-free 95 % "
        "interval (one exact value for a deterministic method). Verdict: the book's rule "
        "(`navlib.verdicts.decide`) on the median paired difference to the best method over the same "
        "seeds. The intervals cover the training randomness, not another recording of the compass.",
        "",
        f"![error against {result.x_label} per method]({png.name})",
        "",
    ]
    md.write_text("\n".join(lines), encoding="utf-8")
    return md, png
