"""Radial-basis-function networks compatible with MATLAB ``newrb`` / ``newrbe`` (paper C, Yu et al. 2012).

Network (paper C eq. 1-2, MATLAB Neural Network Toolbox)::

    y(x) = w0 + sum_i w_i * radbas(b * ||s(x) - c_i||),   radbas(n) = exp(-n^2),
    b = sqrt(-ln 0.5) / SPREAD                                                     (so a neuron gives 0.5
                                                                                    at distance SPREAD)

``s`` is an explicit :class:`InputScaler` (``(x - offset) / scale`` per input column): SPREAD is measured in
the scaled units, so the scaler is part of the model and is stored in the result.  The default scaler is the
identity, exactly what MATLAB does with the numbers it is given.

:func:`newrb` follows MATLAB's ``designrb`` (Chen, Cowan & Grant 1991 orthogonal least squares):

1. candidate matrix ``P`` (Q x Q), column j = a neuron centred on training input j evaluated at all inputs;
2. score of column j: ``(p_j' d)^2 / (d'd * p_j' p_j)`` summed over outputs (targets not mean-centred);
   the first maximum wins;
3. the remaining candidates are orthogonalised against the chosen (orthogonalised) column (Gram-Schmidt,
   no bias column in this step);
4. after each addition the output layer ``[W2 b2]`` is re-solved from scratch by linear least squares on
   ``[A1; ones]``;
5. stop after neuron k (k >= 2: MATLAB does not test the goal after the first neuron) when the training
   error is strictly below the goal, or when ``max_neurons`` (default Q) is reached.

Goal semantics (``goal_kind``): ``"mse"`` -- mean squared error over all targets, as in current MATLAB
(``mse(t - a2) < goal``); ``"sse"`` -- sum of squared errors, as in older toolbox versions.  With the same
numeric goal the two differ by a factor Q in effective strictness.

Deviations from MATLAB, both only for degenerate data: a candidate whose orthogonalised column has
collapsed to round-off (a duplicated input) is never picked, instead of being scored by a random-looking
ratio of two round-off numbers, and when only such candidates are left the design stops early
(``stop_reason = "no independent candidate"``).  The least-squares solve is numpy's ``lstsq`` (minimum-norm
solution when rank-deficient), MATLAB's ``/`` returns a basic solution instead; on the training points both
fit equally well.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from .arrays import as_2d

LN2_SQRT = math.sqrt(-math.log(0.5))  # 0.8326


def width_from_spread(spread: float) -> float:
    """MATLAB's neuron width parameter ``b = sqrt(-ln 0.5) / SPREAD``."""
    _check_spread(spread)
    return LN2_SQRT / float(spread)


def spread_from_gaussian_width(delta: float) -> float:
    """The MATLAB SPREAD whose neurons are ``exp(-u^2 / delta^2)`` (a Gaussian of width ``delta``, the form
    papers often print): ``radbas(b u) = exp(-(b u)^2)`` with ``b = sqrt(-ln 0.5) / SPREAD`` equals it when
    ``b = 1 / delta``, i.e. ``SPREAD = sqrt(ln 2) delta`` (0.8326 ``delta``)."""
    if not (
        isinstance(delta, (int, float, np.integer, np.floating))
        and math.isfinite(delta)
        and delta > 0
    ):
        raise InputError(f"parameter delta={delta!r}: the Gaussian width must be a positive number")
    return LN2_SQRT * float(delta)


def radbas(n: np.ndarray) -> np.ndarray:
    """MATLAB ``radbas``: ``exp(-n^2)``."""
    n = np.asarray(n, dtype=float)
    return np.exp(-n * n)


# ----------------------------------------------------------------------------------------------- scaling
@dataclass(frozen=True)
class InputScaler:
    """Explicit input scaling ``s(x) = (x - offset) / scale`` applied column-wise before the network.

    ``names`` and ``units`` document what each input column is (e.g. ``latitude_error``, ``arcmin``)."""

    offset: tuple[float, ...]
    scale: tuple[float, ...]
    names: tuple[str, ...] = ()
    units: tuple[str, ...] = ()

    def __post_init__(self):
        if len(self.offset) != len(self.scale):
            raise InputError(
                f"InputScaler: offset has {len(self.offset)} entries, scale {len(self.scale)}"
            )
        for i, s in enumerate(self.scale):
            if not (math.isfinite(s) and s != 0):
                raise InputError(f"parameter scale[{i}]={s!r}: must be finite and non-zero")

    @property
    def n_inputs(self) -> int:
        return len(self.offset)

    @classmethod
    def identity(cls, n_inputs: int = 1, names=(), units=()) -> "InputScaler":
        return cls((0.0,) * n_inputs, (1.0,) * n_inputs, tuple(names), tuple(units))

    @classmethod
    def affine(cls, offset, scale, names=(), units=()) -> "InputScaler":
        off = tuple(float(v) for v in np.atleast_1d(offset))
        sc = tuple(float(v) for v in np.atleast_1d(scale))
        if len(sc) == 1 and len(off) > 1:
            sc = sc * len(off)
        return cls(off, sc, tuple(names), tuple(units))

    @classmethod
    def standardize(cls, x, names=(), units=()) -> "InputScaler":
        """z-score each column with the mean and (population) standard deviation of ``x``; a constant
        column gets scale 1."""
        x = as_2d(x, "x")
        sd = x.std(axis=0)
        sd = np.where(sd > 0, sd, 1.0)
        return cls(tuple(x.mean(axis=0).tolist()), tuple(sd.tolist()), tuple(names), tuple(units))

    def transform(self, x) -> np.ndarray:
        x = as_2d(x, "x")
        if x.shape[1] != self.n_inputs:
            raise InputError(
                f"input has {x.shape[1]} column(s), the scaler expects {self.n_inputs}"
            )
        return (x - np.asarray(self.offset)) / np.asarray(self.scale)


# ----------------------------------------------------------------------------------------------- result
@dataclass
class RBFNet:
    """A designed RBF network.  ``centers`` are in scaled units (rows = neurons, in the order they were
    added); ``center_index`` gives the training row each centre came from; ``perf_mse[k]`` / ``perf_sse[k]``
    are the training errors with k neurons (k = 0: the mean of the targets, MATLAB's ``tr.perf(1)``)."""

    centers: np.ndarray
    b: float
    weights: np.ndarray  # (m, s)
    bias: np.ndarray  # (s,)
    scaler: InputScaler
    spread: float
    center_index: np.ndarray
    perf_mse: np.ndarray = field(default_factory=lambda: np.zeros(0))
    perf_sse: np.ndarray = field(default_factory=lambda: np.zeros(0))
    goal: float = 0.0
    goal_kind: str = "mse"
    stop_reason: str = ""
    single_output: bool = True

    @property
    def n_neurons(self) -> int:
        return int(self.centers.shape[0])

    def hidden(self, x) -> np.ndarray:
        """Hidden-layer outputs (Q x m)."""
        xs = self.scaler.transform(x)
        return radbas(self.b * _dist(xs, self.centers))

    def predict(self, x) -> np.ndarray:
        """Network output for raw (unscaled) inputs ``x`` (Q,) or (Q, n)."""
        y = self.hidden(x) @ self.weights + self.bias
        return y[:, 0] if self.single_output else y


# ----------------------------------------------------------------------------------------------- helpers
def _dist(a: np.ndarray, c: np.ndarray) -> np.ndarray:
    d2 = ((a[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
    return np.sqrt(d2)


def _check_spread(spread) -> None:
    try:
        s = float(spread)
    except (TypeError, ValueError):
        raise InputError(f"parameter SPREAD={spread!r}: not a number") from None
    if not (math.isfinite(s) and s > 0):
        raise InputError(f"parameter SPREAD={spread!r}: must be > 0 and finite")


def _prepare(x, t, spread, scaler):
    _check_spread(spread)
    X = as_2d(x, "x")
    T = as_2d(t, "t")
    single = np.asarray(t).ndim == 1
    q, n = X.shape
    if T.shape[0] != q:
        raise InputError(f"x has {q} rows but t has {T.shape[0]}: one target row per input row")
    if q < 1:
        raise InputError("no training rows")
    if q < n:
        raise InputError(
            f"{q} training row(s) for {n} inputs: need at least as many rows as inputs"
        )
    for name, a in (("x", X), ("t", T)):
        bad = np.argwhere(~np.isfinite(a))
        if bad.size:
            r, c = bad[0]
            raise InputError(f"{name}: row {r + 1}, column {c + 1} is not a finite number")
    if scaler is None:
        scaler = InputScaler.identity(n)
    Xs = scaler.transform(X)
    return X, Xs, T, single, scaler


def _solve_output(a1: np.ndarray, T: np.ndarray):
    """Least squares for ``[W2 b2]`` on ``[A1 ones]`` (Q x (m+1)); returns weights (m, s), bias (s,)."""
    M = np.hstack([a1, np.ones((a1.shape[0], 1))])
    sol, *_ = np.linalg.lstsq(M, T, rcond=None)
    return sol[:-1], sol[-1]


def _errors(a1, w, bias, T):
    e = T - (a1 @ w + bias)
    return float(np.mean(e * e)), float(np.sum(e * e))


# ----------------------------------------------------------------------------------------------- design
def newrb(
    x,
    t,
    *,
    goal: float = 0.0,
    spread: float = 1.0,
    max_neurons: int | None = None,
    goal_kind: str = "mse",
    scaler: InputScaler | None = None,
    degenerate_tol: float = 1e-11,
) -> RBFNet:
    """MATLAB ``newrb(P, T, goal, spread, MN)`` by orthogonal least squares (see module docstring).

    ``x``: (Q,) or (Q, n) raw inputs; ``t``: (Q,) or (Q, s) targets; ``goal`` in the units of
    ``goal_kind`` (``"mse"``: mean squared error, ``"sse"``: sum of squared errors, target units squared);
    ``scaler`` maps raw inputs to the space in which ``spread`` is measured (identity by default).
    ``degenerate_tol``: a candidate whose orthogonalised norm is below this fraction of its original norm
    counts as linearly dependent (score 0).
    """
    try:
        g = float(goal)
    except (TypeError, ValueError):
        raise InputError(f"parameter goal={goal!r}: not a number") from None
    if not (math.isfinite(g) and g >= 0):
        raise InputError(f"parameter goal={goal!r}: must be >= 0 and finite")
    if goal_kind not in ("mse", "sse"):
        raise InputError(f"parameter goal_kind={goal_kind!r}: must be 'mse' or 'sse'")
    X, Xs, T, single, scaler = _prepare(x, t, spread, scaler)
    q = Xs.shape[0]
    if max_neurons is None:
        max_neurons = q
    if not (isinstance(max_neurons, (int, np.integer)) and max_neurons >= 1):
        raise InputError(f"parameter max_neurons={max_neurons!r}: must be a whole number >= 1")
    b = width_from_spread(spread)

    P = radbas(b * _dist(Xs, Xs))  # column j: neuron centred on sample j, at every sample
    norm0 = np.sqrt((P * P).sum(axis=0))
    d = T
    dd = (d * d).sum(axis=0)  # (s,)
    dd = np.where(dd > 0, dd, 1.0)  # all-zero targets: every score is 0, avoid 0/0

    def scores(Pm):
        """OLS error-reduction score per remaining candidate; -1 for a candidate whose orthogonalised
        column has collapsed to round-off (linearly dependent on the chosen ones)."""
        pp = (Pm * Pm).sum(axis=0)
        pd = Pm.T @ d  # (cand, s)
        with np.errstate(divide="ignore", invalid="ignore"):
            e = pd**2 / (pp[:, None] * dd[None, :])
        e[~np.isfinite(e)] = 0.0
        sc = (e**2).sum(axis=1)  # MATLAB findLargeColumn: sum of squares over outputs
        sc[np.sqrt(pp) <= degenerate_tol * norm0[left]] = -1.0
        return sc

    left = np.arange(q)
    used: list[int] = []
    W_orth: list[np.ndarray] = []
    mean_err = T - T.mean(axis=0)
    perf_mse = [float(np.mean(mean_err**2))]
    perf_sse = [float(np.sum(mean_err**2))]
    stop = "max_neurons reached"
    w2 = np.zeros((0, T.shape[1]))
    b2 = T.mean(axis=0)
    Pm = P.copy()
    for k in range(1, min(max_neurons, q) + 1):
        if k > 1:
            wj = W_orth[-1]
            a = (wj @ Pm) / (wj @ wj)
            Pm = Pm - np.outer(wj, a)
        sc = scores(Pm)
        if not np.any(sc >= 0):
            stop = "no independent candidate"
            break
        pick = int(np.argmax(sc))  # first maximum wins
        W_orth.append(Pm[:, pick].copy())
        used.append(int(left[pick]))
        Pm = np.delete(Pm, pick, axis=1)
        left = np.delete(left, pick)
        a1 = radbas(b * _dist(Xs, Xs[used]))
        w2, b2 = _solve_output(a1, T)
        mse, sse = _errors(a1, w2, b2, T)
        perf_mse.append(mse)
        perf_sse.append(sse)
        err = mse if goal_kind == "mse" else sse
        if k >= 2 and err < g:
            stop = "goal met"
            break
    return RBFNet(
        centers=Xs[used].copy(),
        b=b,
        weights=np.asarray(w2),
        bias=np.asarray(b2),
        scaler=scaler,
        spread=float(spread),
        center_index=np.asarray(used, dtype=int),
        perf_mse=np.asarray(perf_mse),
        perf_sse=np.asarray(perf_sse),
        goal=g,
        goal_kind=goal_kind,
        stop_reason=stop,
        single_output=single,
    )


def newrbe(x, t, *, spread: float = 1.0, scaler: InputScaler | None = None) -> RBFNet:
    """MATLAB ``newrbe``: one neuron on every training input, ``[W2 b2] = t / [A1; ones]`` (Q equations,
    Q + 1 unknowns; numpy's minimum-norm least-squares solution, MATLAB's ``/`` gives a basic one, so the
    two differ off the training points)."""
    X, Xs, T, single, scaler = _prepare(x, t, spread, scaler)
    b = width_from_spread(spread)
    a1 = radbas(b * _dist(Xs, Xs))
    w2, b2 = _solve_output(a1, T)
    mse, sse = _errors(a1, w2, b2, T)
    mean_err = T - T.mean(axis=0)
    return RBFNet(
        centers=Xs.copy(),
        b=b,
        weights=w2,
        bias=b2,
        scaler=scaler,
        spread=float(spread),
        center_index=np.arange(Xs.shape[0]),
        perf_mse=np.array([np.mean(mean_err**2), mse]),
        perf_sse=np.array([np.sum(mean_err**2), sse]),
        goal=0.0,
        goal_kind="mse",
        stop_reason="exact design",
        single_output=single,
    )


def leave_one_out(x, t, fit) -> np.ndarray:
    """Leave-one-out predictions: for each row i, ``fit(x_without_i, t_without_i)`` must return a predictor
    (a callable on raw inputs, or an object with ``.predict``) that is applied to row i.  Any scaler must be
    built inside ``fit`` from the rows it is given, so the held-out row never influences its own model."""
    X = as_2d(x, "x")
    T = np.asarray(t, dtype=float)
    q = X.shape[0]
    if q < 2:
        raise InputError(f"leave-one-out needs at least 2 rows, got {q}")
    out = np.empty(q)
    for i in range(q):
        keep = np.arange(q) != i
        model = fit(X[keep], T[keep])
        f = model.predict if hasattr(model, "predict") else model
        out[i] = float(np.ravel(f(X[i : i + 1]))[0])
    return out
