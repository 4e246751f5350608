"""Which physical effect is missing from a model? Evidence from the residuals, with honest statistics.

:func:`diagnose` takes a fitted model (:class:`navlib.workbench.fit.Fit`) and

1. refits it with each catalogued effect that is not yet in the model and that the data can test, and
   scores each candidate by

   - variance explained: the share of the residual sum of squares the effect removes,
   - significance: the nested-model F test ``F = (dRSS / q) / (RSS_1 / (n - p_1))`` (q parameters added);
     for small linear problems (n <= 12, the drift tables) an exact or Monte-Carlo permutation test of the
     candidate's covariate instead, which does not lean on normal errors,
   - held-out improvement: leave-one-out RMS with and without the effect (exact for linear models, the
     leverage approximation for the compass);

2. looks for structure in the residuals of the current model, with the shapes its system lists
   (``System.structure``; compass: a constant offset, heading harmonics 1..6,
   offsets and one-cycle errors differing between sweeps, a trend in time; drift: curvature in each
   covariate; magnetometer: trends with time, angular rate and position).  Each shape ``X`` is first
   projected off the model's Jacobian (what the model can already absorb is not structure); what remains
   is F-tested against the residual.  The *amplitude* reported is computed on the residual itself (least
   squares of the residual on ``X``), so it can never exceed what the residual allows;
3. controls false alarms over the whole family of tests: on independent samples with Bonferroni (each
   test at ``alpha / m``, m = number of tests), on serially correlated noise with a parametric bootstrap of
   the family's smallest p-value (below), so data with nothing missing are called "consistent with noise"
   with probability at least about ``1 - alpha``.

Before any test the data are screened once (:func:`navlib.workbench.screen.screen`): outlying rows are
set aside (robust, MAD-studentised residuals of the richest model the data can test; listed in
``outliers``) and the model is refitted without them; residuals at the data's numerical precision
(RMS <= 1e-9 of the measured values) are called noise without a test; and for a time series the noise's
serial correlation is modelled (AR(p) by restricted maximum likelihood, :mod:`navlib.workbench.serial`).
With correlated noise every F test above -- candidates, structure, conditional -- is computed by
generalised least squares: on the whitened residual ``W r``, whitened Jacobians ``W J`` and whitened
shapes ``W X``, with each model's residual first freed of what its whitened Jacobian can absorb (one
Gauss-Newton step of the GLS fit from the least-squares solution; exact for a linear model), with the
estimated noise model plugged in.  Plugged-in p-values are too small: the correlation is estimated from
the same data, an estimate a little low makes a slow shape look significant, and Bonferroni cannot allow
for that.  The family is therefore calibrated by a **parametric bootstrap of its smallest p-value**
(``_bootstrap_level``; single-step minP, Westfall and Young 1993): noise from the estimated AR model
is simulated on the same series, the noise model re-estimated on it as the screen does, and every test of
the family re-run with the re-estimated model; a test is significant when its plugged-in p lies below the
level that the replicates' smallest p-values reach in a share ``alpha`` of replicates.  This keeps the
family-wise false-alarm rate near ``alpha`` including the uncertainty of the correlation, without the
power lost by maximising each p-value over an interval of the correlation (the F statistic of a constant
offset at a correlation near 1 says almost nothing).  Independent samples (``W = I``) keep the
least-squares tests and Bonferroni.

The effect to add (``missing``) is the significant candidate with the strongest evidence (smallest p) that
also improves the held-out RMS *and* explains what it claims.  If the residual shows significant structure,
the candidate is added and the structure re-tested: a structure no longer significant is *gone* (the
candidate explains it); for what *remains*, a conditional F test asks whether the candidate still lowers
the residual once the remaining structure is allowed for in both models.  A candidate that only soaks up a
little of an unexplained structure (a temperature term and a three-cycle error; a one-cycle term and the
heading-correlated part of a drift in time) fails that test and is not named; the report then says which
structure remains and that no catalogued effect explains it.  If no candidate is named and no structure is
found, the residuals are consistent with noise -- provided they are also small enough to be noise
(:mod:`navlib.workbench.noise_size`): a correlated-noise model can absorb a large slow error (a reference
attitude bad in segments), so residuals more than ``RATIO_MAX`` times the noise consecutive samples show
are reported as slow structure, and a candidate that takes out more than ``EXPLAINED_MAX`` times that
noise and lowers the held-out RMS is named although the whitened test leaves it undecided.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import asdict, dataclass, field
from itertools import permutations

import numpy as np
import pandas as pd
from scipy import special
from scipy.linalg.lapack import dpotrf, dtrtri
from scipy.special import fdtrc

from ..errors import check_param
from ..errors import InputError
from ..seeding import child
from .effects import testable
from .fit import Fit, drift_design
from .linalg import orth_basis
from .noise_size import NoiseSize, noise_size
from .screen import Screening, screen as screen_data
from .reml import _Prepared
from .serial import (
    NoiseModel,
    colour,
    select_ar1_many,
    select_bases,
    select_many,
    whiten,
    whiten_each,
    whiten_transpose,
)
from ..threads import one_blas_thread

SMALL_SAMPLE = 12
# Family-wise false-alarm level. Bonferroni keeps the false-alarm rate at or below alpha; the users' target
# is at most 5 %, so the default runs at half of it to stay under the target with margin.
DEFAULT_ALPHA = 0.025
# With correlated noise, fewer effective samples than this (for a slow shape) are said to leave small slow
# effects undecided.
FEW_EFFECTIVE = 30
# A structure shape is "already in the model" when less than this share of its norm is left after
# projecting it off the model's Jacobian.
SPANNED = 0.1
#: Parametric-bootstrap replicates of the family's smallest p-value on correlated noise (at least
#: ``2.5 / alpha - 1``: :func:`bootstrap_replicates`).
REPLICATES = 99
# The bootstrap's random stream: spawn key under the diagnosis seed (the permutation test uses the seed itself).
_BOOTSTRAP_KEY = 1
# Replicates simulated at once (the early stop is checked after each batch; fixed, so results never depend on it).
_BATCH = 20


@dataclass
class Candidate:
    effect: str
    rms: float  # residual RMS after adding the effect
    loo_rms: float  # held-out (leave-one-out) RMS after adding it
    variance_explained: float  # share of the current residual sum of squares it removes
    p_value: float
    test: str  # 'F', 'F (GLS)' (correlated noise) or 'permutation'
    significant: bool = False
    log_p: float = field(default=0.0, repr=False)
    explains: str = ""  # the structure it removes ("" if no structure was found)


@dataclass
class Finding:
    what: str
    amplitude: float  # size of the structure, in the data's unit
    p_value: float
    significant: bool = False
    log_p: float = field(default=0.0, repr=False)


@dataclass
class Diagnosis:
    system: str
    model: list
    unit: str
    n: int
    rms: float
    loo_rms: float
    missing: str | None
    consistent_with_noise: bool
    candidates: list
    structure: list
    untestable: dict
    alpha: float
    tests: int
    message: str
    screening: Screening | None = field(default=None, repr=False, compare=False)
    calibration: "Calibration | None" = field(default=None, repr=False, compare=False)
    noise_size: NoiseSize | None = field(default=None, repr=False, compare=False)

    @property
    def outliers(self) -> list[dict]:
        """The observations set aside before the tests: ``{"row", "column", "residual", "robust_z"}``."""
        return [o.to_dict() for o in self.screening.outliers] if self.screening is not None else []

    def to_dict(self) -> dict:
        d = {
            k: getattr(self, k)
            for k in (
                "system",
                "model",
                "unit",
                "n",
                "rms",
                "loo_rms",
                "missing",
                "consistent_with_noise",
            )
        }
        d["candidates"] = [asdict(c) for c in self.candidates]
        for c in d["candidates"]:
            c.pop("log_p")
            c.pop("explains")
        d["structure"] = [asdict(s) for s in self.structure]
        for s in d["structure"]:
            s.pop("log_p")
            if not np.isfinite(s["p_value"]):
                s["p_value"] = None  # the size check's finding has no p-value
        d["noise_size"] = self.noise_size.to_dict() if self.noise_size is not None else None
        d.update(
            {
                "untestable": dict(self.untestable),
                "alpha": self.alpha,
                "tests": self.tests,
                "message": self.message,
                "outliers": self.outliers,
            }
        )
        if self.calibration is not None:
            d["calibration"] = self.calibration.to_dict()
        if self.screening is not None:
            extra = self.screening.to_dict()
            extra.pop("outliers")
            d.update(extra)
        return d

    def candidate_table(self) -> pd.DataFrame:
        rows = [
            {
                "effect": c.effect,
                f"rms after ({self.unit})": c.rms,
                f"held-out rms ({self.unit})": c.loo_rms,
                "variance explained": c.variance_explained,
                "p": c.p_value,
                "test": c.test,
                "significant": c.significant,
            }
            for c in self.candidates
        ]
        return pd.DataFrame(rows).set_index("effect") if rows else pd.DataFrame()

    def structure_table(self) -> pd.DataFrame:
        rows = [
            {
                "structure": s.what,
                f"amplitude ({self.unit})": s.amplitude,
                "p": s.p_value,
                "significant": s.significant,
            }
            for s in self.structure
        ]
        return pd.DataFrame(rows).set_index("structure") if rows else pd.DataFrame()

    def _level_line(self) -> str:
        cal = self.calibration
        if cal is None or cal.method == "Bonferroni":
            return f"tests: {self.tests}, each at alpha/m = {self.alpha / max(self.tests, 1):.2g}"
        return (
            f"tests: {self.tests}, family-wise alpha = {self.alpha:g}: significant below p = {cal.level:.2g} "
            f"(parametric bootstrap of the smallest p, {cal.replicates} replicates"
            f"{', stopped early' if cal.stopped_early else ''})"
        )

    def report(self) -> str:
        """A readable multi-line report (the CLI's output without --json)."""
        used = len(self.screening.kept) if self.screening is not None else None
        size = (
            f"rows: {used}" + (f" ({self.n} observations)" if self.n != used else "")
            if used
            else f"observations: {self.n}"
        )
        lines = [
            f"system: {self.system}   model: {' + '.join(self.model) or '(none)'}   {size}",
            f"residual rms: {_fmt(self.rms)} {self.unit}   held-out rms: {_fmt(self.loo_rms)} {self.unit}",
            self._level_line(),
        ]
        if self.screening is not None and self.screening.noise.series is not None:
            lines.append("noise: " + self.screening.noise.describe())
        if self.candidates:
            lines.append("")
            lines.append(
                f"{'candidate':<20}{'rms after':>12}{'held-out':>12}{'var. expl.':>12}{'p':>11}  sig."
            )
            for c in self.candidates:
                lines.append(
                    f"{c.effect:<20}{_fmt(c.rms):>12}{_fmt(c.loo_rms):>12}{c.variance_explained:>12.3f}"
                    f"{c.p_value:>11.2g}  {'yes' if c.significant else 'no'}"
                )
        for name, why in self.untestable.items():
            lines.append(f"not testable: {name} ({why})")
        found = [s for s in self.structure if s.significant]
        if found:
            lines.append("")
            lines.append("structure no catalogued effect explains:")
            lines.extend(
                f"  {s.what}: amplitude {_fmt(s.amplitude)} {self.unit}, "
                + (f"p = {s.p_value:.2g}" if np.isfinite(s.p_value) else "by the size check")
                for s in found
            )
        lines.append("")
        lines.append(self.message)
        return "\n".join(lines)


def _fmt(x: float) -> str:
    return f"{x:.4g}" if abs(x) >= 1e-3 or x == 0 else f"{x:.3e}"


def _f_test(rss0: float, rss1: float, q: int, df2: int) -> tuple[float, float]:
    """Nested-model F test: (p, log p)."""
    if df2 <= 0 or q <= 0:
        return 1.0, 0.0
    if rss1 <= 0:
        return (0.0, -np.inf) if rss0 > 0 else (1.0, 0.0)
    f = max((rss0 - rss1) / q, 0.0) / (rss1 / df2)
    with np.errstate(divide="ignore"):
        logp = float(
            np.log(special.fdtrc(q, df2, f))
        )  # scipy.stats.f.logsf, without importing scipy.stats
    return float(math.exp(logp)), logp


def _permutation_p(
    fit: Fit, effect: str, observed_drop: float, seed: int = 0, n_random: int = 5000
) -> float:
    """Permutation test of a drift covariate: shuffle the candidate's column across rows (every
    permutation when n! <= 5040, else ``n_random`` random ones) and count how often the shuffled column
    removes at least as much RSS as the real one.  Vectorised: with ``M0 = I - Q Q'`` the residual maker
    of the current design (``Q`` an orthonormal basis of it; ``M0`` is never formed), a column ``x``
    removes ``(x' M0 y)^2 / (x' M0 x)``.  Bias (a constant) cannot be permuted: returns None and the F test
    is used."""
    col = {
        "earth_rate": "latitude_error_deg",
        "temperature": "temperature_c",
        "temperature_change": "temperature_change_c",
    }.get(effect)
    if col is None:
        return None
    data = fit.data
    y = data["drift_deg_h"].to_numpy(float)
    X0, _ = drift_design(data, fit.effects)
    x1, _ = drift_design(data, (effect,))
    x1 = x1[:, 0]
    n = len(y)
    Q = orth_basis(X0) if X0.shape[1] else np.zeros((n, 0))
    if math.factorial(n) <= 5040:
        perms = np.array(list(permutations(range(n))))
        exact = True
    else:
        rng = np.random.default_rng(seed)
        perms = np.array([rng.permutation(n) for _ in range(n_random)])
        exact = False
    Xp = x1[perms]  # (P, n) permuted columns (centring is invariant)
    Mx = Xp - (Xp @ Q) @ Q.T  # M0 x of each permuted column (M0 symmetric, idempotent)
    a = Mx @ y
    b = np.einsum("pn,pn->p", Mx, Mx)
    drops = np.where(b > 1e-300, a**2 / np.where(b > 1e-300, b, 1.0), 0.0)
    hits = np.sum(drops >= observed_drop * (1 - 1e-9))
    return float(hits / len(perms)) if exact else float((1 + hits) / (1 + len(perms)))


def _projector(J: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the model Jacobian's column space (rank-revealing SVD)."""
    return orth_basis(J)


def _gls(fit: Fit, noise: NoiseModel | None) -> tuple[np.ndarray, np.ndarray]:
    """The residual of ``fit`` as the tests see it and the orthonormal basis of its Jacobian: with
    correlated noise, ``W r`` freed of what ``W J`` absorbs (the GLS residual, to first order) and the
    basis of ``W J``; otherwise ``r`` and the basis of ``J``."""
    return _gls_of(fit.residuals, fit.jacobian, noise)


def _gls_of(
    r: np.ndarray, J: np.ndarray, noise: NoiseModel | None
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_gls` of a residual ``r`` and a Jacobian ``J``."""
    if noise is None or not noise.correlated:
        return r, _projector(J)
    e = noise.whiten(r)
    Q = _projector(noise.whiten(J))
    return e - Q @ (Q.T @ e), Q


def _shape_bases(
    Q: np.ndarray, shapes: list, noise: NoiseModel | None, n: int
) -> list[tuple[int, np.ndarray, int, int]]:
    """For each structure shape ``X0`` the part the model of (whitened) Jacobian basis ``Q`` cannot absorb:
    ``(index, u, q, df2)`` with ``u`` an orthonormal basis of it (q columns) and ``df2`` the F test's
    denominator degrees of freedom; shapes the model already spans, or with too few rows left, are
    skipped."""
    white = noise is not None and noise.correlated
    return _unspanned(Q, [noise.whiten(X0) if white else X0 for X0 in shapes], n)


def _unspanned(Q: np.ndarray, shapes: list, n: int) -> list[tuple[int, np.ndarray, int, int]]:
    """:func:`_shape_bases` of shapes already whitened (or of independent samples)."""
    out = []
    for i, X in enumerate(shapes):
        X = X / np.maximum(np.linalg.norm(X, axis=0), 1e-300)
        Xp = X - Q @ (Q.T @ X)
        # directions of the shape the model cannot absorb: singular values of Xp above SPANNED (unit columns;
        # the Gram matrix is small: a structure shape has at most a few tens of columns)
        w, V = np.linalg.eigh(Xp.T @ Xp)
        keep = w > SPANNED**2
        q = int(np.sum(keep))
        df2 = n - Q.shape[1] - q
        if q == 0 or df2 < 3:
            continue  # the model already spans this shape, or too few rows
        out.append((i, (Xp @ V[:, keep]) / np.sqrt(w[keep]), q, df2))
    return out


def _shape_tests(
    e: np.ndarray, Q: np.ndarray, shapes: list, noise: NoiseModel | None, n: int
) -> list[tuple[int, float, float]]:
    """F tests of structure shapes ``X0`` against the (whitened, projected) residual ``e`` of a model with
    (whitened) Jacobian basis ``Q``: ``(index, p, log p)`` of each shape the model does not already span."""
    rss = float(e @ e)
    out = []
    for i, u, q, df2 in _shape_bases(Q, shapes, noise, n):
        drop = float(np.sum((u.T @ e) ** 2))
        p, logp = _f_test(rss, rss - drop, q, df2)
        out.append((i, p, logp))
    return out


def _structure(fit: Fit, noise: NoiseModel | None = None) -> list[Finding]:
    """The system's structure tests on the residuals of ``fit`` (module docstring, point 2); generalised
    least squares with the whitening of ``noise`` when it is correlated."""
    r = fit.residuals
    e, Q = _gls(fit, noise)
    spec = [(what, np.asarray(X0, float), scale) for what, X0, scale in fit.spec.structure(fit)]
    out = []
    for i, p, logp in _shape_tests(e, Q, [X0 for _, X0, _ in spec], noise, len(r)):
        what, X0, scale = spec[i]
        qx = orth_basis(X0)  # amplitude: the shape fitted to the residual itself
        amp = scale * float(np.sqrt(np.mean((qx @ (qx.T @ r)) ** 2)))
        out.append(Finding(what, amp, p, log_p=logp))
    return out


def _candidate_p(fit: Fit, f1: Fit, noise: NoiseModel) -> tuple[float, float]:
    """The nested F test of ``f1`` (= ``fit`` + a candidate): least squares for independent samples;
    with correlated noise, generalised least squares with the estimated noise model."""
    q, df2 = f1.n_params - fit.n_params, f1.n - f1.n_params
    if not noise.correlated:
        return _f_test(fit.rss, f1.rss, q, df2)
    (e0, _), (e1, _) = _gls(fit, noise), _gls(f1, noise)
    return _f_test(float(e0 @ e0), float(e1 @ e1), q, df2)


def _conditional_p(
    fit: Fit, f1: Fit, found: list[Finding], noise: NoiseModel | None = None
) -> float:
    """p of the candidate's improvement when the structure ``found`` is allowed for in both models: the
    residuals of ``fit`` and of ``f1`` (= fit + candidate) are each regressed on their model's Jacobian and
    the structure shapes, and the two remaining sums of squares are F-tested (all whitened when the noise
    is correlated)."""
    shapes = {what: X for what, X, _ in fit.spec.structure(fit)}
    S = np.column_stack([shapes[s.what] for s in found if s.what in shapes])
    w = noise.whiten if noise is not None and noise.correlated else np.asarray

    def rss_p(f):
        u = orth_basis(w(np.column_stack([f.jacobian, S])))
        r = w(f.residuals)
        return float(r @ r - np.sum((u.T @ r) ** 2)), u.shape[1]

    rss0, _ = rss_p(fit)
    rss1, p1 = rss_p(f1)
    return _f_test(rss0, rss1, f1.n_params - fit.n_params, f1.n - p1)[0]


@dataclass(frozen=True)
class Calibration:
    """The per-test critical p-value of a family of tests (a test is significant when its p is below
    ``level``) and how it was found: ``method`` "Bonferroni" (``alpha / m``) or "parametric bootstrap"
    (``replicates`` simulated; ``stopped_early`` when enough of them reached the smallest observed p)."""

    level: float
    method: str
    replicates: int = 0
    stopped_early: bool = False

    def to_dict(self) -> dict:
        return {
            "level": self.level,
            "method": self.method,
            "replicates": self.replicates,
            "stopped_early": self.stopped_early,
        }


def bootstrap_replicates(alpha: float) -> int:
    """Replicates of the parametric bootstrap: :data:`REPLICATES`, or more when ``alpha`` needs them (at
    least ``2.5 / alpha - 1``, so that one replicate may reach the observed p and the test still be
    significant)."""
    return max(REPLICATES, int(math.ceil(2.5 / alpha)) - 1)


#: Noise models whose whitened bases one bootstrap keeps (replicates share the grid's correlations).
_KEEP_BASES = 4
#: The replicates' re-estimated noise models of the last bootstrap inputs (:func:`_reestimates`).
_REESTIMATES: dict = {}


def _bootstrap_level(
    fit: Fit, fits: dict, sc: Screening, alpha: float, p_min: float, seed: int
) -> Calibration:
    """The family-wise critical p-value on correlated noise, by a parametric bootstrap of the smallest
    plug-in p-value of the family (Westfall and Young 1993, *Resampling-Based Multiple Testing*, single-step
    minP; module docstring).  Each replicate: AR noise with the estimated partial autocorrelations on the
    same series (:func:`navlib.workbench.serial.colour`), the noise model re-estimated on it as the screen
    does (:func:`navlib.workbench.serial.select`: same regressors, REML; the AR order fixed at the
    data's), then every test of the family -- each candidate's
    nested GLS F test and each structure shape's -- with that re-estimated model; the replicate's smallest p
    is kept.  A test is significant when ``(1 + #{replicates whose minimum <= p}) / (B + 1) < alpha``,
    i.e. ``p`` below the K-th smallest replicate minimum, ``K = ceil(alpha (B + 1) - 1)``.  The replicates
    stop early once K minima fall at or below the smallest observed p (nothing can then be significant;
    Besag and Clifford 1991, Biometrika 78:301).

    The simulated noise and its re-estimates depend only on the screen (noise model, regressors) and the
    seed, not on the model tested: the diagnoses of one loop share them (:func:`_reestimates`)."""
    noise = sc.noise
    B = bootstrap_replicates(alpha)
    K = int(math.ceil(alpha * (B + 1) - 1 - 1e-12))  # >= 2: B >= 2.5 / alpha - 1
    family = _Family(fit, fits, noise.series, noise.order)
    rng = np.random.default_rng(child(seed, _BOOTSTRAP_KEY))
    ser = noise.series
    memo = _reestimates(sc, seed, B, fit.n)
    U = None
    minima = np.empty(0)
    # a projected noise model (:class:`navlib.workbench.serial.Projection`) re-estimates every replicate on
    # one grid of filters (each a pass over the series): all replicates in one batch
    batch = B if ser.projection is not None else _BATCH
    for start in range(0, B, batch):
        if start not in memo["batches"]:
            if U is None:
                U = rng.standard_normal((len(ser.order), B))  # every replicate's draw, made once
            E = colour(U[:, start : start + batch], noise.kappa, ser, fit.n)
            memo["batches"][start] = (E, _reestimate(E, memo["bases"], noise, sc.regressors))
        E, models = memo["batches"][start]
        minima = np.r_[minima, family.minima(E, models)]
        if np.sum(minima <= p_min) >= K:
            return Calibration(
                float(np.sort(minima)[K - 1]), "parametric bootstrap", len(minima), True
            )
    return Calibration(float(np.sort(minima)[K - 1]), "parametric bootstrap", B)


def _reestimates(sc: Screening, seed: int, B: int, n: int) -> dict:
    """What the bootstrap of :func:`_bootstrap_level` re-estimates on the screen ``sc`` with ``seed``:
    ``bases`` (:func:`navlib.workbench.serial.select_bases` of the screen's regressors, with the basis-only
    likelihood parts) and ``batches``: by the index of its first replicate, each batch's simulated noise and
    the replicates' noise models (:func:`_reestimate`), filled as batches are drawn.
    The same inputs (the same noise model and regressors, by identity: the diagnoses of one loop) give the
    same memo; it is dropped with the noise model."""
    noise = sc.noise
    key = (id(noise), id(sc.regressors), seed, B, n)
    memo = _REESTIMATES.get(key)
    if memo is None or memo["noise"]() is not noise or memo["regressors"] is not sc.regressors:
        _REESTIMATES.clear()
        memo = {
            "noise": weakref.ref(noise),
            "regressors": sc.regressors,
            "batches": {},
            "bases": select_bases(*sc.regressors, noise.series, n, order=noise.order),
        }
        _REESTIMATES[key] = memo
        weakref.finalize(noise, _REESTIMATES.pop, key, None)
    return memo


def _reestimate(E: np.ndarray, bases, noise: NoiseModel, regressors: tuple) -> list:
    """Each column's noise model of ``E`` (residual vectors in observation order), chosen as the screen chose
    the data's (:func:`navlib.workbench.serial.select` around ``regressors``, whose orthonormal ``bases`` are
    given; the AR order fixed at the data's).  AR(1): every column's correlation on the grid at once
    (:func:`navlib.workbench.serial.select_ar1_many`)."""
    if noise.order == 1:
        return [
            NoiseModel((float(k),), noise.series, len(E))
            for k in select_ar1_many(E, bases, noise.series)
        ]
    return select_many(E, *regressors, noise.series, bases, order=noise.order, start_at=noise.kappa)


class _Family:
    """The tests of one diagnosis, re-run on simulated residual vectors: each candidate's nested GLS F test
    and each structure shape's, with the noise model each vector's own estimate.

    The tests need only inner products of whitened columns: with ``F`` the columns side by side (bases of
    the model's Jacobian and of each candidate's -- the tests see only their column spaces -- and the
    structure shapes) and ``e`` a residual vector, ``H = F' R^-1 F``, ``h = F' R^-1 e`` and ``e' R^-1 e``.
    For AR noise on segments ``H`` is a weighted sum of ``F``'s lagged cross-products, computed once
    (:class:`navlib.workbench.reml._Prepared`), and ``h = F' W' (W e)``
    (:func:`navlib.workbench.serial.whiten_transpose`), so no replicate whitens ``F``.  Then, with ``T0``
    the inverse Cholesky factor of the Jacobian's block ``H_00`` and ``z0 = T0 h_0``::

        RSS_0 = e' R^-1 e - |z0|^2,   RSS_1 = e' R^-1 e - |T1 h_1|^2           (candidates)
        X' (I - P_0) X = D^-1 H_ss D^-1 - B' B,   B = T0 H_0s D^-1              (shapes: D their norms)

    the shape's unspanned directions the eigenvectors of the latter above ``SPANNED^2`` (as in
    :func:`_shape_bases`) and its drop ``|u' e_0|^2`` from ``X' (I - P_0) e = D^-1 h_s - B' z0``.  A series
    with a :class:`navlib.workbench.serial.Projection` is whitened by its filter: there each noise model
    whitens the columns (all in one call) and the tests run on them (:meth:`_min_p_whitened`)."""

    def __init__(self, fit: Fit, fits: dict, series, order: int):
        self.n = fit.n
        cands = [
            (f1.jacobian, f1.n_params - fit.n_params, f1.n - f1.n_params) for f1 in fits.values()
        ]
        cands = [c for c in cands if c[1] > 0 and c[2] > 0]
        self.tests = [(q, df2) for _, q, df2 in cands]
        shapes = [np.asarray(X0, float) for _, X0, _ in fit.spec.structure(fit)]
        jacobians = [
            np.asarray(J, float).reshape(self.n, -1)
            for J in [fit.jacobian] + [J1 for J1, _, _ in cands]
        ]
        self.series = series
        self.gram = series.projection is None
        blocks = ([orth_basis(J) for J in jacobians] if self.gram else jacobians) + shapes
        edges = np.cumsum([0] + [X.shape[1] for X in blocks])
        self.spans = [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]
        X = np.column_stack(blocks)
        self.F = X[series.order]
        self.pre = _Prepared(X, series, max(order, 1)) if self.gram else None
        self._cache: dict = {}  # by noise model: _factors (Gram path)
        self._whitened: dict = {}  # and _bases (whitened path)

    def minima(self, E: np.ndarray, models: list) -> np.ndarray:
        """The smallest p of the family on each column of ``E`` (residual vectors in observation order), each
        under its own noise model (``models``, :func:`_reestimate`); columns with the same model share it."""
        out = np.ones(E.shape[1])
        Eo = np.asarray(E, float)[self.series.order]
        orders: dict = {}
        for b, nm in enumerate(models):
            orders.setdefault(nm.order if nm.correlated else 0, []).append(b)
        for cols in orders.values():
            if self.gram:
                try:  # every column at once, each under its own model
                    out[cols] = self._min_p_many(Eo[:, cols], [models[b] for b in cols])
                    continue
                except (
                    np.linalg.LinAlgError
                ):  # a Gram block numerically singular: one model at a time
                    pass
            groups: dict = {}
            for b in cols:
                groups.setdefault(
                    tuple(models[b].kappa) if models[b].correlated else (), []
                ).append(b)
            for same in groups.values():
                run = self._min_p if self.gram else self._min_p_whitened
                out[same] = run(Eo[:, same], models[same[0]])
        return out

    def _min_p_many(self, Eo: np.ndarray, models: list) -> np.ndarray:
        """:meth:`_min_p` of every column of ``Eo`` (series order) under its own noise model ``models[b]``
        (all of one order) at once: each column whitened with its own coefficients
        (:func:`navlib.workbench.serial.whiten_each`), the Gram matrices ``H`` stacked and factored together
        (batched LAPACK); raises ``LinAlgError`` when a block is not numerically positive definite."""
        kappas = [tuple(nm.kappa) if nm.correlated else () for nm in models]
        We = whiten_each(Eo, kappas, self.series)
        c = np.einsum("ij,ij->j", We, We)  # e' R^-1 e
        h = (self.F.T @ whiten_each(We, kappas, self.series, transpose=True)).T  # F' R^-1 e: (B, m)
        m = self.F.shape[1]
        H = (np.array([self.pre.weights(k)[1] for k in kappas]) @ self.pre.Gq).reshape(-1, m, m)
        a0 = self.spans[0]
        L0, z0 = _cholesky_solve(H[:, a0, a0], h[:, a0])
        fit0 = np.einsum("bi,bi->b", z0, z0)
        rss0 = c - fit0
        best = np.ones(Eo.shape[1])
        for s, (q, df2) in zip(self.spans[1:], self.tests):
            z1 = _cholesky_solve(H[:, s, s], h[:, s])[1]
            fit1 = np.einsum("bi,bi->b", z1, z1)
            best = np.minimum(best, _f_p(fit1 - fit0, c - fit1, q, df2))
        k0 = a0.stop - a0.start
        for s in self.spans[1 + len(self.tests) :]:
            Hss = H[:, s, s]
            d = np.maximum(
                np.sqrt(np.maximum(np.diagonal(Hss, axis1=1, axis2=2), 0.0)), 1e-300
            )  # (B, q)
            Bm = _lower_solve(L0, H[:, a0, s]) / d[:, None, :]
            w, V = np.linalg.eigh(
                Hss / (d[:, :, None] * d[:, None, :]) - Bm.transpose(0, 2, 1) @ Bm
            )
            keep = w > SPANNED**2
            y = np.einsum("bsr,bs->br", V, h[:, s] / d - np.einsum("bks,bk->bs", Bm, z0))
            drop = np.sum(np.where(keep, y * y / np.where(keep, w, 1.0), 0.0), axis=1)
            q = np.sum(keep, axis=1)
            df2 = self.n - k0 - q
            ok = (q > 0) & (df2 >= 3)  # else the model spans the shape, or too few rows
            p = _f_p(drop, rss0 - drop, np.maximum(q, 1), np.maximum(df2, 1))
            best = np.minimum(best, np.where(ok, p, 1.0))
        return best

    def _factors(self, kappa: tuple) -> tuple:
        """Under the AR noise ``kappa``: ``T0`` and each candidate's ``T1`` (inverse factors of the blocks of
        ``H``) and each shape's ``(u, B, d, q, df2)`` (class docstring; ``u`` maps ``X' (I - P_0) e`` to the
        coordinates of the drop); the last few are kept, since replicates share grid correlations."""
        if kappa not in self._cache:
            _, ws, _ = self.pre.weights(kappa)
            m = self.F.shape[1]
            H = (ws @ self.pre.Gq).reshape(m, m)
            T = [_inverse_factor(H[s, s]) for s in self.spans[: 1 + len(self.tests)]]
            a0, T0 = self.spans[0], T[0]
            shapes = []
            for s in self.spans[1 + len(self.tests) :]:
                d = np.maximum(np.sqrt(np.maximum(np.diag(H[s, s]), 0.0)), 1e-300)
                Bm = (T0 @ H[a0, s]) / d
                w, V = np.linalg.eigh(H[s, s] / np.outer(d, d) - Bm.T @ Bm)
                keep = w > SPANNED**2
                q = int(np.sum(keep))
                df2 = self.n - T0.shape[0] - q
                if q == 0 or df2 < 3:
                    continue  # the model already spans this shape, or too few rows
                shapes.append((s, V[:, keep] / np.sqrt(w[keep]), Bm, d, q, df2))
            if len(self._cache) >= _KEEP_BASES:
                self._cache.pop(next(iter(self._cache)))
            self._cache[kappa] = (T, shapes)
        return self._cache[kappa]

    def _min_p(self, Eo: np.ndarray, nm: NoiseModel) -> np.ndarray:
        """The smallest p of the family on the columns ``Eo`` (series order), all under the noise model
        ``nm``, from inner products (class docstring)."""
        kappa = tuple(nm.kappa) if nm.correlated else ()
        T, shapes = self._factors(kappa)
        We = whiten(Eo, kappa, self.series, ordered=True)
        c = np.einsum("ij,ij->j", We, We)  # e' R^-1 e
        h = self.F.T @ whiten_transpose(We, kappa, self.series)  # F' R^-1 e
        z0 = T[0] @ h[self.spans[0]]
        fit0 = np.einsum("ij,ij->j", z0, z0)
        rss0 = c - fit0
        best = np.ones(Eo.shape[1])
        for T1, s, (q, df2) in zip(T[1:], self.spans[1:], self.tests):
            z1 = T1 @ h[s]
            fit1 = np.einsum("ij,ij->j", z1, z1)
            best = np.minimum(best, _f_p(fit1 - fit0, c - fit1, q, df2))
        for s, u, Bm, d, q, df2 in shapes:
            y = u.T @ (h[s] / d[:, None] - Bm.T @ z0)
            drop = np.einsum("ij,ij->j", y, y)
            best = np.minimum(best, _f_p(drop, rss0 - drop, q, df2))
        return best

    def _bases(self, nm: NoiseModel) -> tuple:
        """The whitened model's and candidates' orthonormal bases and the shapes' (:func:`_shape_bases`)
        under the noise model ``nm`` (all columns whitened in one call); the last few are kept, since
        replicates share grid correlations."""
        key = tuple(nm.kappa)
        if key not in self._whitened:
            WF = nm.whiten(self.F, ordered=True)
            blocks = [WF[:, s] for s in self.spans]
            Q0 = _projector(blocks[0])
            Q1s = [(_projector(W1), q, df2) for W1, (q, df2) in zip(blocks[1:], self.tests)]
            if len(self._whitened) >= _KEEP_BASES:
                self._whitened.pop(next(iter(self._whitened)))
            self._whitened[key] = (Q0, Q1s, _unspanned(Q0, blocks[1 + len(self.tests) :], self.n))
        return self._whitened[key]

    def _min_p_whitened(self, Eo: np.ndarray, nm: NoiseModel) -> np.ndarray:
        """:meth:`_min_p` on whitened columns (a projected series): ``Eo`` in series order."""
        W = nm.whiten(Eo, ordered=True)
        Q0, Q1s, shape_bases = self._bases(nm)
        e0 = W - Q0 @ (Q0.T @ W)
        rss0 = np.einsum("ij,ij->j", e0, e0)
        best = np.ones(Eo.shape[1])
        for Q1, q, df2 in Q1s:
            e1 = W - Q1 @ (Q1.T @ W)
            rss1 = np.einsum("ij,ij->j", e1, e1)
            best = np.minimum(best, _f_p(rss0 - rss1, rss1, q, df2))
        for _, u, q, df2 in shape_bases:
            drop = np.sum((u.T @ e0) ** 2, axis=0)
            best = np.minimum(best, _f_p(drop, rss0 - drop, q, df2))
        return best


def _lower_solve(L: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``L^-1 b`` for stacked lower-triangular ``L`` (B, k, k) and ``b`` (B, k) or (B, k, r)."""
    if not L.shape[1]:
        return np.zeros(b.shape)
    return np.linalg.solve(L, b[..., None])[..., 0] if b.ndim == 2 else np.linalg.solve(L, b)


def _cholesky_solve(G: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For stacked ``G`` (B, k, k) positive definite and ``b`` (B, k): the Cholesky factors ``L`` and
    ``z = L^-1 b`` (``|z|^2 = b' G^-1 b``); ``LinAlgError`` if a ``G`` is not numerically positive definite."""
    L = np.linalg.cholesky(G) if G.shape[1] else G
    return L, _lower_solve(L, b)


def _inverse_factor(G: np.ndarray) -> np.ndarray:
    """``T`` with ``T G T' = I`` on the range of ``G`` (``|T h|^2 = h' G^+ h``): the inverse of the Cholesky
    factor, or for a numerically singular ``G`` the eigenvectors over the roots of the eigenvalues above
    ``1e-12`` of the largest."""
    if not G.shape[0]:
        return np.zeros((0, 0))
    L, info = dpotrf(G, lower=1, clean=1)
    if info == 0:
        Ti, info = dtrtri(L, lower=1)
        if info == 0:
            return Ti
    w, V = np.linalg.eigh(G)
    keep = w > 1e-12 * max(w[-1], 1e-300)
    return (V[:, keep] / np.sqrt(w[keep])).T


def _f_p(drop: np.ndarray, rss1: np.ndarray, q: int, df2: int) -> np.ndarray:
    """p of the nested F test (:func:`_f_test`), vectorised: ``F = (drop / q) / (rss1 / df2)``."""
    f = np.maximum(drop / q, 0.0) / np.maximum(rss1 / df2, 1e-300)
    return np.where(rss1 > 0, fdtrc(q, df2, f), np.where(drop > 0, 0.0, 1.0))


@one_blas_thread
def diagnose(
    fit: Fit, alpha: float = None, seed: int = 0, *, screen: bool | Screening = True
) -> Diagnosis:
    """Rank the effects not yet in ``fit`` by the evidence that adding each explains the residuals; name the
    one to add, or say the residuals are consistent with noise, or name the structure no effect explains.

    Parameters
    ----------
    fit : Fit
        The current model (:func:`navlib.workbench.fit.fit_model`); its ``available`` effects (catalogue and
        user effects) are the candidates.
    alpha : float
        Family-wise false-alarm level (default ``DEFAULT_ALPHA``), Bonferroni over every test.
    seed : int
        Seed of the Monte-Carlo permutation test (drift tables with more than 7 rows).
    screen : bool or Screening
        ``True`` (default): screen the data first (:func:`navlib.workbench.screen.screen`: outliers set
        aside and the model refitted without them, numerical floor, serial correlation); a
        :class:`~navlib.workbench.screen.Screening` already made on these data (``fit`` must be fitted to
        its rows, as :func:`navlib.workbench.loop.loop` does); ``False``: no screen, independent samples
        (the numerical floor still applies).

    Returns
    -------
    Diagnosis
        ``missing`` (the effect to add or None), candidates, structure findings, the message, and the
        screening (``outliers``, noise model, floor).

    Raises
    ------
    InputError
        From the screen, when more than 5 % of the rows are outliers.

    Examples
    --------
    A simulated compass with hard and soft iron hidden, fitted with hard iron only: the diagnosis names
    the missing soft iron (the message gives the test, the variance it removes and the held-out error):

    >>> from navlib.workbench.fit import fit_model, simulate
    >>> data = simulate("compass", {"hard_x": 0.05, "soft_e": 0.02}, noise=0.05, seed=1)
    >>> d = diagnose(fit_model("compass", data, ["hard_iron"]))
    >>> d.missing
    'soft_iron'
    >>> d.message.split(":")[0]
    "add 'soft_iron'"

    From the command line: ``python -m navlib diagnose compass FILE --model hard_iron``.
    """
    alpha = DEFAULT_ALPHA if alpha is None else alpha
    check_param("alpha", alpha, lo=0, lo_open=True, hi=1, hi_open=True)
    reuse = None
    if isinstance(screen, Screening):
        sc = screen
    else:
        sc = screen_data(fit, outliers=bool(screen), serial=bool(screen))
        if sc.outliers:
            fit = sc.refit(fit)
        elif sc.rich is not None and sc.rich.data is fit.data:
            reuse = sc.rich  # fitted from fit.params: the same as fit.add
    noise = sc.noise
    ok, why = testable(fit.available, fit.data)
    untestable = {k: v for k, v in why.items() if k not in fit.effects}
    unit = fit.unit
    if fit.rms <= sc.floor:
        msg = (
            f"the residuals are consistent with noise: their rms {_fmt(fit.rms)} {unit} is at the data's "
            f"numerical precision (at most {sc.floor / sc.scale:.0e} of the measured values' rms "
            f"{_fmt(sc.scale)} {unit}); nothing to test"
        )
        return _finish(
            Diagnosis(
                fit.system,
                list(fit.effects),
                unit,
                fit.n,
                fit.rms,
                fit.loo_rms,
                None,
                True,
                [],
                [],
                untestable,
                alpha,
                0,
                msg,
                sc,
                Calibration(alpha, "Bonferroni"),
            )
        )
    cands = []
    fits = {}
    for effect in ok:
        if effect in fit.effects:
            continue
        try:
            if reuse is not None and set(reuse.effects) == set(fit.effects) | {effect}:
                f1 = reuse
            else:
                f1 = fit.add(effect)
        except InputError as err:  # e.g. too few rows for one more parameter
            untestable[effect] = str(err)
            continue
        fits[effect] = f1
        drop = max(fit.rss - f1.rss, 0.0)
        p, logp = _candidate_p(fit, f1, noise)
        test = "F" if not noise.correlated else "F (GLS)"
        if (
            fit.system == "drift"
            and fit.n <= SMALL_SAMPLE
            and all(e in fit.spec.catalogue for e in fit.effects + (effect,))
        ):
            pp = _permutation_p(fit, effect, drop, seed)
            if pp is not None:
                p, logp, test = pp, math.log(max(pp, 1e-300)), "permutation"
        cands.append(
            Candidate(
                effect,
                f1.rms,
                f1.loo_rms,
                drop / fit.rss if fit.rss > 0 else 0.0,
                p,
                test,
                log_p=logp,
            )
        )
    structure = _structure(fit, noise)
    m = len(cands) + len(structure)
    if noise.correlated and sc.regressors is not None and m:
        p_min = min([c.p_value for c in cands] + [s.p_value for s in structure])
        cal = _bootstrap_level(fit, fits, sc, alpha, p_min, seed)
    else:
        cal = Calibration(alpha / max(m, 1), "Bonferroni")
    level = cal.level
    for s in structure:
        s.significant = bool(s.p_value < level)
    found = [s for s in structure if s.significant]
    for c in cands:
        c.significant = bool(c.p_value < level and c.loo_rms < fit.loo_rms)
    cands.sort(key=lambda c: (not c.significant, c.log_p, -c.variance_explained))
    missing, blocked = None, []
    size = None
    for c in cands:
        if not c.significant:
            break
        if not found:
            missing = c.effect
            break
        f1 = fits[c.effect]
        # a candidate that brings the residual down to the numerical floor leaves no structure
        after = {s.what: s for s in _structure(f1, noise)} if f1.rms > sc.floor else {}
        gone = [s.what for s in found if s.what not in after or after[s.what].p_value >= level]
        remaining = [s for s in found if s.what not in gone]
        # named only if it still matters once the structure it leaves in place is allowed for
        if not remaining or _conditional_p(fit, f1, remaining, noise) < level:
            c.explains = "; ".join(gone)
            missing = c.effect
            found = remaining
            break
        blocked.append(c.effect)
    if missing is None and not found:
        # "consistent with noise" needs the residual small against the noise the data show at short lags,
        # and no candidate taking out much more than that (module noise_size)
        size = noise_size(fit, fits, unit, noise.effective_samples if noise.correlated else None)
        big = (
            None
            if size is None or size.biggest is None
            else next(c for c in cands if c.effect == size.biggest)
        )
        if (
            size is not None
            and size.problem
            and size.problem.startswith("'")
            and big.loo_rms < fit.loo_rms
        ):
            missing = big.effect  # too large to be noise, and it predicts better
        elif size is not None and size.problem:
            amp = float(np.sqrt(max(size.rms**2 - size.short**2, 0.0)))
            if size.problem.startswith("'"):
                amp = size.explained
            found = [Finding(size.problem, amp, float("nan"), significant=True)]
            structure = structure + found
    if missing and size is not None and missing == size.biggest and size.problem:
        c = next(c for c in cands if c.effect == missing)
        msg = (
            f"add '{missing}': it takes out {_fmt(size.explained)} {unit} rms, "
            f"{size.explained / size.short:.1f} times the sample-to-sample noise ({_fmt(size.short)} {unit}: "
            f"too large for noise), and lowers the held-out rms from {_fmt(fit.loo_rms)} to {_fmt(c.loo_rms)} "
            f"{unit}; the correlated-noise test alone leaves it undecided (p = {c.p_value:.2g})"
        )
    elif missing:
        c = next(c for c in cands if c.effect == missing)
        msg = (
            f"add '{missing}': it removes {100 * c.variance_explained:.1f} % of the residual variance "
            f"(p = {c.p_value:.2g}, {c.test} test) and lowers the held-out rms from {_fmt(fit.loo_rms)} to "
            f"{_fmt(c.loo_rms)} {unit}"
        )
        if c.explains:
            msg += f"; it explains the {c.explains}"
    elif found:
        msg = (
            "no catalogued effect explains the residuals, but they are not noise: "
            + "; ".join(f"{s.what} (amplitude {_fmt(s.amplitude)} {unit})" for s in found)
            + " -- look for an effect the catalogue lacks"
        )
        if blocked:
            msg += (
                f" ({', '.join(blocked)} would remove some variance but leave this structure in place, "
                f"so it is not named)"
            )
    else:
        msg = (
            f"the residuals are consistent with noise: no candidate effect and no structure is significant "
            f"at the family-wise level alpha = {alpha:g} over {m} tests"
        )
        if fit.n <= SMALL_SAMPLE:
            msg += f" (only {fit.n} rows: small effects cannot be excluded)"
        elif noise.correlated and noise.effective_samples < FEW_EFFECTIVE:
            msg += (
                f" (the noise is so correlated that a slowly varying effect sees only about "
                f"{noise.effective_samples:.0f} independent samples: small slow effects cannot be excluded)"
            )
    if missing and found:
        msg += "; structure it does not explain remains: " + "; ".join(s.what for s in found)
    if noise.correlated:
        msg += (
            f" [serially correlated noise, AR({noise.order}) with lag-1 correlation {noise.lag1:.2f}: "
            f"tests on whitened residuals]"
        )
    return _finish(
        Diagnosis(
            fit.system,
            list(fit.effects),
            unit,
            fit.n,
            fit.rms,
            fit.loo_rms,
            missing,
            missing is None and not found,
            cands,
            structure,
            untestable,
            alpha,
            m,
            msg,
            sc,
            cal,
            size,
        )
    )


def _finish(d: Diagnosis) -> Diagnosis:
    """Put the outlier line (if rows were set aside) on a line of its own before the message."""
    if d.screening is not None and d.screening.outliers:
        d.message = d.screening.outlier_line(d.unit) + "\n" + d.message
    return d
