"""One rule for every verdict in the book.

A quantitative claim becomes a **statistic** of our runs with a 95 % **interval** :math:`[\\ell, u]`, a
**boundary** :math:`b` and the side of the boundary on which the claim holds (``holds_when`` = ``"above"``
or ``"below"``).  Our experiment may also have a **noise floor** :math:`f` (the best value of the statistic
that our simulator and sensor noise allow, e.g. the RMS of the exact physical model), with its own interval
:math:`[f_\\ell, f_u]` (a point where it rests on one run).  Write :math:`w` for the worse of boundary and
floor: :math:`w = f_u` when the whole floor interval lies beyond :math:`b` on the side where the claim
fails (the floor is *separated* from the boundary), else :math:`w = b`.  Then

.. math::
   :label: verdict-rule

    \\text{verdict} = \\begin{cases}
      \\text{reproduced} & [\\ell, u] \\text{ lies wholly on the claim's side of } b,\\\\
      \\text{not reproduced} & [\\ell, u] \\text{ lies wholly beyond } w
        \\text{ (beyond the boundary and beyond anything the noise excuses)},\\\\
      \\text{cannot be judged} & \\text{otherwise.}
    \\end{cases}

(:math:`f_\\ell` takes the place of :math:`f_u` for a claim that holds above its boundary.)  *Cannot be
judged* comes in cases, each with its reason: the interval contains or touches the boundary
(*straddles*); it lies beyond the boundary but not beyond a separated floor, or it straddles the boundary
while the floor is separated from it (*noise floor*: the reason names the assumption that sets the floor
and the value it would need, :class:`Floor`); the statistic is **true by construction** of our simulator
(we set it); there is **no statistic** (the paper prints nothing we can compare with).  A result on the
claim's side of the boundary is reproduced even where a floor estimate said the experiment could not show
it: the data crossed the floor, so the floor was the estimate that erred.

Comparisons ("X beats Y", "k times better") are judged on the interval of the **paired** difference or
ratio over the same seeds or runs (:func:`paired_difference`, :func:`paired_ratio`); rates on the Wilson
interval (:func:`wilson`); statistics of a real table on a bootstrap over its rows (:func:`bootstrap`); a
deterministic computation on real data (no randomness anywhere) has a zero-width interval (:func:`exact`).

:func:`decide` is the rule; the book's ``check-results`` calls it again on every stored claim, so a verdict
that does not follow from its interval, boundary, side and floor fails the test.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Literal, Sequence

import numpy as np
from scipy import special

from .errors import InputError

#: The 95 % intervals of the book.
LEVEL = 0.95
SIDES = ("above", "below")
Side = Literal["above", "below"]
SOURCES = ("paper", "book")
#: What a claim was judged on: our simulators (the default) or real measurements; the book counts the two apart.
DATA = ("simulated", "real")
VERDICTS = ("reproduced", "not reproduced", "cannot be judged", "no difference")
#: Why a claim cannot be judged (``basis`` of :func:`decide`); ``"equivalent"``: no difference at the
#: claim's equivalence margin.
BASES = ("interval", "straddles", "noise floor", "by construction", "no statistic", "equivalent")

#: The rules a claim's interval may come from (the name stored in the results file -> what it means).
RULES = {
    "median over runs": "distribution-free interval of the median over seeds or runs (order statistics)",
    "mean over runs": "Student-t interval of the mean over seeds or runs",
    "quantile over runs": "distribution-free interval of a quantile over seeds or runs (order statistics)",
    "paired difference": "interval of the median paired difference over the same seeds or runs",
    "paired ratio": "interval of the median paired ratio over the same seeds or runs",
    "wilson rate": "Wilson score interval of a rate over independent trials",
    "bootstrap over rows": "percentile bootstrap over the rows of a real table",
    "exact": "deterministic computation on fixed data: the interval is the value itself",
    "no statistic": "nothing to compute: the paper prints no number we can compare with",
}


# ------------------------------------------------------------------------------------------ intervals
@dataclass(frozen=True)
class Estimate:
    """A statistic's point value and 95 % interval ``[lo, hi]``, the rule it came from and ``n`` (runs,
    trials or rows it rests on)."""

    value: float
    lo: float
    hi: float
    rule: str
    n: int

    def __post_init__(self):
        if self.rule not in RULES:
            raise InputError(f"Estimate.rule={self.rule!r}: must be one of {sorted(RULES)}")
        for name in ("value", "lo", "hi"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or math.isnan(v):
                raise InputError(f"Estimate.{name}={v!r}: must be a number")
        if not self.lo <= self.hi:
            raise InputError(f"Estimate interval [{self.lo}, {self.hi}]: lo must not exceed hi")

    @property
    def interval(self) -> tuple[float, float]:
        return (self.lo, self.hi)


def _sample(x, name: str, min_n: int = 2) -> np.ndarray:
    a = np.asarray(x, dtype=float).ravel()
    if a.size < min_n:
        raise InputError(f"{name}: needs at least {min_n} values, got {a.size}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name}: values must be finite")
    return a


def _order_ranks(n: int, q: float, level: float) -> tuple[int, int] | None:
    """0-based ranks ``(i, j)`` of the order statistics that bracket the ``q`` quantile with coverage of at
    least ``level`` (equal tails, :math:`B \\sim \\mathrm{Bin}(n, q)`), or None when ``n`` is too small."""
    a = (1 - level) / 2
    cdf = special.bdtr(np.arange(n + 1), n, q)  # the binomial cdf (scipy.stats.binom.cdf)
    low = np.flatnonzero(cdf <= a)  # P(x_(r) > quantile) = P(B <= r - 1) <= a
    high = np.flatnonzero(cdf >= 1 - a)  # P(x_(s) < quantile) = 1 - P(B <= s - 1) <= a
    if low.size == 0 or high.size == 0 or high[0] + 1 > n:
        return None
    r, s = int(low[-1]) + 1, int(high[0]) + 1  # 1-based ranks
    return r - 1, s - 1


def quantile_ci(
    x, q: float = 0.5, level: float = LEVEL, rule: str = "quantile over runs"
) -> Estimate:
    """The ``q`` quantile of ``x`` with a distribution-free interval from its order statistics
    (:math:`x_{(r)} \\le \\xi_q \\le x_{(s)}` with :math:`P(B \\le r-1) \\le \\alpha/2` and
    :math:`P(B \\ge s) \\le \\alpha/2`, :math:`B \\sim \\mathrm{Bin}(n, q)`).  Too few runs for that coverage
    (fewer than 6 for the median, 50 for the 90th percentile) raise :class:`InputError` naming the number
    needed: give more runs or judge another statistic."""
    a = np.sort(_sample(x, "quantile_ci"))
    ranks = _order_ranks(a.size, q, level)
    if ranks is None:
        need = next(n for n in range(a.size + 1, 100000) if _order_ranks(n, q, level) is not None)
        raise InputError(
            f"quantile_ci: a {level:.0%} interval of the {q:g} quantile needs at least {need} "
            f"runs, got {a.size}"
        )
    return Estimate(
        float(np.quantile(a, q)), float(a[ranks[0]]), float(a[ranks[1]]), rule, int(a.size)
    )


def median_ci(x, level: float = LEVEL) -> Estimate:
    """The median over runs with its distribution-free (order-statistic) interval; see :func:`quantile_ci`."""
    return quantile_ci(x, 0.5, level, rule="median over runs")


def mean_ci(x, level: float = LEVEL) -> Estimate:
    """The mean over runs with its Student-t interval :math:`\\bar x \\pm t_{n-1} s / \\sqrt n`."""
    a = _sample(x, "mean_ci")
    m = float(a.mean())
    half = float(special.stdtrit(a.size - 1, 0.5 + level / 2) * a.std(ddof=1) / math.sqrt(a.size))
    return Estimate(m, m - half, m + half, "mean over runs", int(a.size))


def paired_difference(a, b, level: float = LEVEL) -> Estimate:
    """Median of the paired differences ``a - b`` over the same seeds or runs, with its order-statistic
    interval. ``a[i]`` and ``b[i]`` must come from the same seed or run."""
    x, y = _sample(a, "paired_difference a"), _sample(b, "paired_difference b")
    if x.size != y.size:
        raise InputError(
            f"paired_difference: {x.size} values against {y.size}: pairs need the same runs"
        )
    e = quantile_ci(x - y, 0.5, level)
    return Estimate(e.value, e.lo, e.hi, "paired difference", e.n)


def paired_ratio(a, b, level: float = LEVEL) -> Estimate:
    """Median of the paired ratios ``a / b`` over the same seeds or runs, with its order-statistic
    interval (``b`` must be positive)."""
    x, y = _sample(a, "paired_ratio a"), _sample(b, "paired_ratio b")
    if x.size != y.size:
        raise InputError(
            f"paired_ratio: {x.size} values against {y.size}: pairs need the same runs"
        )
    if np.any(y <= 0):
        raise InputError("paired_ratio: the denominators must be positive")
    e = quantile_ci(x / y, 0.5, level)
    return Estimate(e.value, e.lo, e.hi, "paired ratio", e.n)


def wilson(k: int, n: int, level: float = LEVEL) -> Estimate:
    """A rate ``k / n`` over independent trials with its Wilson score interval."""
    if (
        not (isinstance(k, (int, np.integer)) and isinstance(n, (int, np.integer)))
        or n < 1
        or not 0 <= k <= n
    ):
        raise InputError(
            f"wilson: k={k!r}, n={n!r}: need whole numbers with 0 <= k <= n and n >= 1"
        )
    from scipy import stats  # noqa: PLC0415  # lazy: importing scipy.stats costs every command-line start 0.3 s

    ci = stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=level, method="wilson")
    return Estimate(k / n, float(ci.low), float(ci.high), "wilson rate", int(n))


def bootstrap(
    data,
    statistic: Callable[..., float],
    *,
    seed: np.random.SeedSequence | int,
    n_resamples: int = 2000,
    level: float = LEVEL,
    paired: bool = True,
) -> Estimate:
    """A statistic of a real table with a percentile bootstrap interval over its rows.

    ``data`` is a sequence of equal-length arrays (columns; rows are resampled together when ``paired``),
    ``statistic(*columns)`` returns a number.  Unpaired (``paired=False``: independent samples, each
    resampled on its own, e.g. two tables' rows) the columns may differ in length, and ``n`` counts the
    rows of all of them.  ``seed`` is a ``numpy.random.SeedSequence`` (or an integer entropy) so that
    the interval is the same in every run."""
    cols = [np.asarray(c, dtype=float) for c in data]
    if not cols or any(c.shape[0] < 2 for c in cols):
        raise InputError("bootstrap: give at least one column, each of length >= 2")
    if paired and any(c.shape[0] != cols[0].shape[0] for c in cols):
        raise InputError("bootstrap: paired columns must have the same length")
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    from scipy import stats  # noqa: PLC0415  # lazy: as in wilson

    res = stats.bootstrap(
        tuple(cols),
        statistic,
        n_resamples=n_resamples,
        confidence_level=level,
        method="percentile",
        paired=paired,
        vectorized=False,
        rng=np.random.default_rng(ss),
    )
    value = float(statistic(*cols))
    lo, hi = float(res.confidence_interval.low), float(res.confidence_interval.high)
    n = int(cols[0].shape[0]) if paired else int(sum(c.shape[0] for c in cols))
    return Estimate(value, min(lo, value), max(hi, value), "bootstrap over rows", n)


def exact(value: float) -> Estimate:
    """A deterministic statistic of fixed data (no random draw anywhere): its interval is itself."""
    v = float(value)
    return Estimate(v, v, v, "exact", 1)


def attempt(fn: Callable[..., Estimate], *args) -> tuple[Estimate | None, str]:
    """``(fn(*args), "")``, or ``(None, reason)`` when ``fn`` refuses its data (too few runs for a 95 %
    interval, pairs from different runs): the claim built on it then has no statistic, cannot be judged,
    and says why."""
    try:
        return fn(*args), ""
    except InputError as err:
        return None, f"no 95 % interval: {err}"


# ------------------------------------------------------------------------------------------ the rule
@dataclass(frozen=True)
class Floor:
    """The best value of a claim's statistic that our experiment can resolve (its noise floor), the
    assumption that sets it, what the claim would need, and the floor's own 95 % interval.

    ``value``: the floor in the statistic's unit (for ``holds_when="below"`` the smallest value our
    experiment can show, for ``"above"`` the largest); ``assumption``: what decides it ("sensor noise
    3 ug per reading"); ``needs``: the value the assumption would need for the claim to be resolvable
    ("noise below 2.83 ug"); ``lo``, ``hi``: the floor's interval where it rests on several runs (default:
    the value itself, a floor measured once)."""

    value: float
    assumption: str
    needs: str
    lo: float | None = None
    hi: float | None = None

    def __post_init__(self):
        if not isinstance(self.value, (int, float)) or not math.isfinite(self.value):
            raise InputError(f"Floor.value={self.value!r}: must be a finite number")
        for f in ("assumption", "needs"):
            if not str(getattr(self, f)).strip():
                raise InputError(
                    f"Floor.{f} is empty: say what decides the floor and what it would need"
                )
        for f in ("lo", "hi"):
            v = getattr(self, f)
            if v is not None and (not isinstance(v, (int, float)) or not math.isfinite(v)):
                raise InputError(f"Floor.{f}={v!r}: must be a finite number or None")
        if not self.interval[0] <= self.value <= self.interval[1]:
            raise InputError(
                f"Floor interval [{self.interval[0]}, {self.interval[1]}] must contain its "
                f"value {self.value}"
            )

    @property
    def interval(self) -> tuple[float, float]:
        """``(lo, hi)``; the value itself for a floor measured once."""
        return (
            float(self.value if self.lo is None else self.lo),
            float(self.value if self.hi is None else self.hi),
        )


def on_side(value: float, boundary: float, holds_when: str) -> bool:
    """Whether ``value`` lies strictly on the claim's side of ``boundary``."""
    return value < boundary if holds_when == "below" else value > boundary


def _floor_interval(floor) -> tuple[float, float] | None:
    if floor is None:
        return None
    if isinstance(floor, Floor):
        return floor.interval
    if isinstance(floor, (int, float)):
        return (float(floor), float(floor))
    lo, hi = (float(v) for v in floor)
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        raise InputError(f"floor interval [{lo}, {hi}]: need finite numbers with lo <= hi")
    return (lo, hi)


def worse_bound(boundary: float, holds_when: str, floor=None) -> float:
    """The worse of boundary and floor (:math:`w` of the rule): the floor's far end when its whole
    interval lies beyond the boundary on the side where the claim fails, else the boundary."""
    f = _floor_interval(floor)
    other = "above" if holds_when == "below" else "below"
    if f is None or not (on_side(f[0], boundary, other) and on_side(f[1], boundary, other)):
        return float(boundary)
    return f[1] if holds_when == "below" else f[0]


def decide(
    interval: Sequence[float] | None,
    boundary: float | None,
    holds_when: str | None,
    floor=None,
    by_construction: bool = False,
    margin: float | None = None,
) -> tuple[bool | None, str]:
    """The verdict (True = reproduced, False = not reproduced, None = cannot be judged) and its basis
    (one of :data:`BASES`) from a 95 % interval, the boundary, the claim's side and the noise floor
    (``floor``: a number, an interval ``(lo, hi)`` or a :class:`Floor`).

    The rule, in order (the module's equation): true by construction of our simulator -> cannot be
    judged; no statistic -> cannot be judged; the whole interval on the claim's side of the boundary ->
    reproduced; the whole interval beyond the worse of boundary and floor (:func:`worse_bound`) -> not
    reproduced; beyond the boundary but not beyond a separated floor -> cannot be judged (noise floor);
    otherwise the interval touches or contains the boundary -> cannot be judged (noise floor where the
    floor is separated from the boundary, else straddles).  A comparison may declare an equivalence
    ``margin`` :math:`m` (from the paper's printed precision or the sensor's resolution): an interval
    wholly within :math:`[b - m, b + m]` is the fourth outcome, *no difference at margin m* (``None``,
    basis ``"equivalent"``), checked first: a difference smaller than anything the paper could have
    printed neither confirms nor refutes "X beats Y".

    >>> decide((-0.004, 0.003), 0.0, "above", margin=0.01)
    (None, 'equivalent')

    >>> decide((14.1, 20.8), 0.42, "below", floor=0.487)  # worse than the noise excuses
    (False, 'interval')
    >>> decide((0.45, 0.47), 0.42, "below", floor=0.487)  # within the floor
    (None, 'noise floor')
    >>> decide((0.40, 0.41), 0.42, "below", floor=0.487)  # crossed the floor
    (True, 'interval')
    """
    if by_construction:
        return None, "by construction"
    if interval is None or boundary is None or holds_when is None:
        return None, "no statistic"
    if holds_when not in SIDES:
        raise InputError(f"holds_when={holds_when!r}: must be 'above' or 'below'")
    lo, hi = float(interval[0]), float(interval[1])
    b = float(boundary)
    if not (math.isfinite(lo) and math.isfinite(hi) and math.isfinite(b)) or lo > hi:
        raise InputError(
            f"interval [{lo}, {hi}] and boundary {b}: need finite numbers with lo <= hi"
        )
    if margin is not None:
        m = float(margin)
        if not math.isfinite(m) or m <= 0:
            raise InputError(f"margin={margin!r}: an equivalence margin is a positive number")
        if b - m <= lo and hi <= b + m:
            return None, "equivalent"
    if on_side(lo, b, holds_when) and on_side(hi, b, holds_when):
        return True, "interval"
    w = worse_bound(b, holds_when, floor)
    other = "above" if holds_when == "below" else "below"
    if on_side(lo, w, other) and on_side(hi, w, other):
        return False, "interval"
    return None, "noise floor" if w != b else "straddles"


def verdict_name(reproduced: bool | None, basis: str | None = None) -> str:
    """The verdict's name from :func:`decide`'s pair: *no difference* for basis ``"equivalent"``."""
    if reproduced is None and basis == "equivalent":
        return "no difference"
    return {True: "reproduced", False: "not reproduced", None: "cannot be judged"}[reproduced]


# ------------------------------------------------------------------------------------------ the reasons
#: Why a claim *cannot be judged*, in the reader's words: the basis of :func:`decide` (or, for a claim
#: without a statistic, what its reason says) -> (short label shown beside the verdict, definition).
#: The book defines them once (the landing page's verdict box, the glossary) from this table.
REASONS = {
    "straddles": (
        "our interval contains the boundary",
        "the 95 % interval of our statistic contains (or touches) the claim's boundary: more runs "
        "or a less noisy experiment could decide it",
    ),
    "noise floor": (
        "within our noise floor",
        "our interval lies beyond the claim's boundary (or touches it), but not beyond the noise "
        "floor of our experiment (the best value sensor noise and the exact physical model allow), "
        "whose whole interval lies beyond the boundary: no method could show the claim in our "
        "experiment; the reason names the assumption that sets the floor and the value it would "
        "need",
    ),
    "by construction": (
        "by construction of our simulator",
        "the statistic is true because we set it in our simulator, so our runs cannot test it",
    ),
    "no statistic": (
        "the paper gives no number",
        "the paper prints nothing we can compare our statistic with",
    ),
    "too few runs": (
        "too few runs for an interval",
        "our runs are too few for a 95 % interval of the statistic",
    ),
    "not yet computed": (
        "not yet computed",
        "the claim is checkable but the book does not compute its statistic yet; the claims "
        "register says which statistic and how many runs would decide it",
    ),
    "not checkable": (
        "not checkable",
        "no experiment of ours can test the claim (the register says why)",
    ),
    "not run": (
        "its primary reading was not run",
        "the chapter ran with parameters under which the claim's primary reading does not exist, or "
        "without the real measurements it needs (../shared/realdata); the readings that were run are "
        "shown as its sensitivity",
    ),
}
#: The first words of a register entry's reason for the last two cases (written by :mod:`navlib.claims`).
REGISTER_REASONS = {
    "not yet computed": "not yet computed: ",
    "not checkable": "not checkable: ",
    "not run": "not run: ",
}
#: The verdict labels of the book in order, each with its definition (the three verdicts of
#: ``VERDICTS``, *cannot be judged* split by :data:`REASONS`).
VERDICT_DEFINITIONS = {
    "reproduced": "the whole 95 % interval of our statistic lies on the claim's side of its boundary",
    "not reproduced": "the whole 95 % interval lies beyond the boundary and beyond the noise floor of our "
    "experiment where that floor lies beyond the boundary",
    **{f"cannot be judged: {label}": text for label, text in REASONS.values()},
    "no difference": "a comparison whose whole 95 % interval lies within its stated equivalence margin of "
    "the boundary (from the paper's printed precision or the sensor's resolution): the two "
    "do not differ by anything the paper could have shown",
}


def reason_category(basis: str | None, why: str = "") -> str | None:
    """The key of :data:`REASONS` for a claim that cannot be judged (None for a decided claim, basis
    ``"interval"``).  A claim without a statistic because :func:`attempt` found too few runs (its reason
    starts with "no 95 % interval") is *too few runs*; any other claim without a statistic is *the paper
    gives no number*."""
    if basis in (None, "interval", "equivalent"):
        return None
    if basis not in BASES:
        raise InputError(f"basis={basis!r}: must be one of {list(BASES)}")
    if basis == "no statistic" and "no 95 % interval" in (why or ""):
        return "too few runs"
    for cat, lead in REGISTER_REASONS.items():
        if basis == "no statistic" and (why or "").startswith(lead):
            return cat
    return basis


def verdict_label(reproduced: bool | None, basis: str | None = None, why: str = "") -> str:
    """The verdict as the book shows it: *reproduced*, *not reproduced*, or *cannot be judged: <reason>*
    (:data:`REASONS`; plain *cannot be judged* when the basis is unknown)."""
    name = verdict_name(reproduced, basis)
    if reproduced is not None or basis == "equivalent":
        return name
    cat = reason_category(basis, why) if basis is not None else None
    return f"{name}: {REASONS[cat][0]}" if cat else name
