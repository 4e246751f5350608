"""What both compass studies share: the sweeps, a compensation's error on them, and the statistics over
training seeds on which the claims of paper A, document B and the real compass rest.

- :class:`Sweeps` -- the training and test sweeps prepared once; a compensation's test-sweep error
  (:func:`test_errors`, :func:`error_stats`, :func:`rms_deg`);
- statistics over the runs of a seed study (:func:`~navlib.studies.compass.turntable.seed_study`): the value
  per seed (:func:`per_seed`), the paired difference over the same seeds (:func:`paired_by_seed`,
  :func:`paired_seed_difference`, :func:`paired_rms_difference`), the width of the error band
  (:func:`width_estimate`) and paper A's ordering (:func:`ordering_rate`, :func:`ordering_probability`);
- what every claim on the simulated compass states about its interval and its LS model
  (:data:`TRAINING_ONLY`, :func:`ls_assumption`).

Error = compensated - true heading, wrapped to (-180, 180], on the test sweep.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ... import verdicts
from ...angles import wrap_deg
from ...data.compass_sweeps import unwrap_measured
from ...errors import InputError


def error_stats(err) -> dict:
    """Minimum, maximum and RMS (deg) of an error array."""
    e = np.asarray(err, dtype=float)
    return {
        "min_deg": float(e.min()),
        "max_deg": float(e.max()),
        "rms_deg": float(np.sqrt(np.mean(e**2))),
    }


def rms_deg(predicted, true) -> float:
    """RMS of the wrapped heading error (deg)."""
    e = wrap_deg(np.asarray(predicted, dtype=float) - np.asarray(true, dtype=float))
    return float(np.sqrt(np.mean(e**2)))


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
            raise InputError(
                f"training subset: need at least 2 increasing indices within 0.."
                f"{self.t_train.size - 1}"
            )
        new = object.__new__(Sweeps)
        new.__dict__.update(self.__dict__)
        new.t_train, new.m_train = self.t_train[idx], self.m_train[idx]
        new.x_train = unwrap_measured(new.t_train, new.m_train)
        return new


def test_errors(corrected, sw: Sweeps) -> np.ndarray:
    """Wrapped test-sweep error (deg) of compensated headings."""
    return wrap_deg(np.asarray(corrected) - sw.t_test)


test_errors.__test__ = False  # not a pytest test


# ------------------------------------------------------------------------------------ statistics over seeds
def per_seed(runs: pd.DataFrame, method: str, col: str = "rms_deg") -> pd.Series:
    """``col`` of one method of :func:`~navlib.studies.compass.turntable.seed_study` ``runs`` indexed by seed (a
    deterministic method has the single seed -1); ``col`` may be ``"width_deg"`` (max - min error of the run)."""
    g = runs[runs.method == method]
    if g.empty:
        raise InputError(f"no runs of method {method!r}")
    v = (g.max_deg - g.min_deg) if col == "width_deg" else g[col]
    return pd.Series(v.to_numpy(float), index=g.seed.to_numpy(int), name=method)


def paired_by_seed(a: pd.Series, b: pd.Series) -> tuple[np.ndarray, np.ndarray]:
    """Two per-seed series (:func:`per_seed`) aligned on their common seeds.  A deterministic method (one
    value, seed -1) is paired with every seed of the other; two stochastic methods must share their seeds
    (each difference compares the runs of one seed)."""
    if list(a.index) == [-1] and list(b.index) != [-1]:
        a = pd.Series(a.iloc[0], index=b.index)
    elif list(b.index) == [-1] and list(a.index) != [-1]:
        b = pd.Series(b.iloc[0], index=a.index)
    common = a.index.intersection(b.index).sort_values()
    if common.empty:
        raise InputError(
            f"{a.name} and {b.name} share no seed: a paired comparison needs the same seeds"
        )
    return a.loc[common].to_numpy(float), b.loc[common].to_numpy(float)


def paired_seed_difference(worse: pd.Series, better: pd.Series) -> verdicts.Estimate:
    """The median over seeds of ``worse - better`` with its 95 % interval, two per-seed series paired by
    :func:`paired_by_seed`; two deterministic runs (one pair) give their exact difference."""
    w, b = paired_by_seed(worse, better)
    if w.size == 1:
        return verdicts.exact(w[0] - b[0])
    return verdicts.paired_difference(w, b)


def paired_rms_difference(
    runs: pd.DataFrame, worse: str, better: str, col: str = "rms_deg"
) -> verdicts.Estimate:
    """ "``better`` beats ``worse``" as a statistic: the median over seeds of ``col(worse) - col(better)``
    (the RMS by default) with its 95 % interval, paired by seed (:func:`paired_seed_difference`); positive
    when ``better`` has the smaller error."""
    return paired_seed_difference(per_seed(runs, worse, col), per_seed(runs, better, col))


def ordering_rate(runs: pd.DataFrame, ls: str, bp: str, de: str, ade: str) -> verdicts.Estimate:
    """The share of seeds whose runs show paper A's ordering RMS(LS) > RMS(BP) > RMS(DE-BP) > RMS(ADE-BP)
    (the runs of one seed are one independent draw of each method; a deterministic LS is the same in every
    draw), with its Wilson interval."""
    s = {m: per_seed(runs, m) for m in (ls, bp, de, ade)}
    stochastic = [set(v.index) for v in s.values() if list(v.index) != [-1]]
    seeds = sorted(set.intersection(*stochastic)) if stochastic else [-1]
    if not seeds:
        raise InputError(
            f"{bp}, {de} and {ade} share no seed: the ordering needs one run of each per seed"
        )

    def val(m):
        return (
            np.full(len(seeds), s[m].iloc[0])
            if list(s[m].index) == [-1]
            else s[m].loc[seeds].to_numpy(float)
        )

    ok = (val(ls) > val(bp)) & (val(bp) > val(de)) & (val(de) > val(ade))
    return verdicts.wilson(int(ok.sum()), int(ok.size))


def width_estimate(runs: pd.DataFrame, method: str) -> verdicts.Estimate:
    """The width of a method's test-sweep error band (max - min, deg): the median over seeds with its
    95 % interval, or the exact value of a deterministic method on the fixed sweeps."""
    w = per_seed(runs, method, "width_deg")
    return verdicts.exact(w.iloc[0]) if list(w.index) == [-1] else verdicts.median_ci(w.to_numpy())


def ordering_probability(ls: float, bp, de, ade) -> float:
    """P(ls > bp > de > ade) for one independent draw of each method (``ls`` one number, the others
    samples of the error over seeds): the chance that a paper reporting one run per method shows this
    ordering, computed exactly over the empirical distributions (all ``n_bp n_de n_ade`` combinations)."""
    bp, de, ade = (np.asarray(a, dtype=float) for a in (bp, de, ade))
    n_bp = ((bp[None, :] > de[:, None]) & (bp[None, :] < ls)).sum(axis=1)  # per DE draw
    n_ade = (ade[None, :] < de[:, None]).sum(axis=1)
    return float(np.sum(n_bp * n_ade) / (bp.size * de.size * ade.size))


# ------------------------------------------------------------------------------------ what the claims state
#: What every interval over training seeds covers (shown in each claim's ``decided_by``).
TRAINING_ONLY = (
    "one fixed simulated sweep pair: the interval covers training randomness (seeds), not "
    "sensor-noise draws"
)


def ls_assumption(ls: str | None) -> str:
    """What judging a claim against the 8-position LS ``ls`` (an id of
    :data:`~navlib.methods.compass_methods.LS_MODELS`) assumes about the model paper A does not print ("" for
    any other id)."""
    return {
        "ls8": "8-position LS as Smith's 5-term series: on our compass (hard iron a third of the "
        "horizontal field) its missing 3rd harmonic limits it",
        "ls8_planar": "8-position LS as the exact 5-parameter hard/soft-iron model (our simulator's own "
        "model on a level table)",
        "ls8_h3": "8-position LS as a harmonic series to 3rd order (7 coefficients from 8 readings)",
    }.get(ls, "")
