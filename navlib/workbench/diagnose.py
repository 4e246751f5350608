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
(``bootstrap_level``; single-step minP, Westfall and Young 1993): noise from the estimated AR model
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
from dataclasses import asdict, dataclass, field
from itertools import permutations

import numpy as np
import pandas as pd

from ..errors import check_param
from ..errors import InputError
from .effects import testable
from .fit import Fit, drift_design
from .linalg import orth_basis
from .noise_size import NoiseSize, noise_size
from .bootstrap import Calibration, bootstrap_level
from .ftests import f_test, gls, shape_tests
from .screen import Screening, screen as screen_data
from .serial import (
    NoiseModel,
)
from ..threads import one_blas_thread

SMALL_SAMPLE = 12
# Family-wise false-alarm level. Bonferroni keeps the false-alarm rate at or below alpha; the users' target
# is at most 5 %, so the default runs at half of it to stay under the target with margin.
DEFAULT_ALPHA = 0.025
# With correlated noise, fewer effective samples than this (for a slow shape) are said to leave small slow
# effects undecided.
FEW_EFFECTIVE = 30


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


def _structure(fit: Fit, noise: NoiseModel | None = None) -> list[Finding]:
    """The system's structure tests on the residuals of ``fit`` (module docstring, point 2); generalised
    least squares with the whitening of ``noise`` when it is correlated."""
    r = fit.residuals
    e, Q = gls(fit, noise)
    spec = [(what, np.asarray(X0, float), scale) for what, X0, scale in fit.spec.structure(fit)]
    out = []
    for i, p, logp in shape_tests(e, Q, [X0 for _, X0, _ in spec], noise, len(r)):
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
        return f_test(fit.rss, f1.rss, q, df2)
    (e0, _), (e1, _) = gls(fit, noise), gls(f1, noise)
    return f_test(float(e0 @ e0), float(e1 @ e1), q, df2)


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
    return f_test(rss0, rss1, f1.n_params - fit.n_params, f1.n - p1)[0]


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
        cal = bootstrap_level(fit, fits, sc, alpha, p_min, seed)
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
