"""A generic one-hidden-layer BP network ``n_in - n_hidden - n_out`` in torch (float64), the shape of
MATLAB's ``feedforwardnet``: a ``tansig`` (tanh) or ``logsig`` (logistic) hidden layer and a ``purelin``
output, trained full-batch on the mean squared error of the scaled targets::

    x' = s_x(x),   h = act(W1 x' + b1),   y' = W2 h + b2,   y = s_y^-1(y')

Scaling ``s``: ``"mapminmax"`` (MATLAB's default, each column to [-1, 1]; a constant column is left
unscaled) or ``"standardize"`` (mean 0, standard deviation 1).  Initial weights: ``"nguyen_widrow"``
(hidden weight rows of norm ``0.7 H^(1/n)``, biases spread across that range, output weights
U(-0.5, 0.5); drawn from ``numpy.random.SeedSequence(seed)``) or ``"torch"`` (``torch.nn.Linear``'s
default initialisation under a torch seed drawn from ``SeedSequence(seed)``).  Trainers: ``"lbfgs"``
(L-BFGS with a strong-Wolfe line search, a quasi-Newton stand-in for ``trainlm`` on a small net) or
``"adam"`` (rate ``learning_rate``).  The time of one training pass (one epoch over the whole training
set: forward, backward, update) is measured with ``time.perf_counter``.

Used by paper D's ANN baseline (2-n-1, mapminmax, Nguyen-Widrow, L-BFGS) and paper E's BPKF networks
(9-10-3, 45-10-3, 6-10-3: logsig, standardised, torch initialisation, Adam).  Paper A's 1-M-1 network
with MATLAB's ``trainlm`` is :mod:`navlib.methods.bpnet`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._optional import require
from ..errors import InputError, check_param
from .seeding import as_int

torch = require("torch", __name__)  # the [nets] extra

_CHOICES = {
    "hidden": ("tansig", "logsig"),
    "trainer": ("lbfgs", "adam"),
    "scaling": ("mapminmax", "standardize"),
    "init": ("nguyen_widrow", "torch"),
}


@dataclass(frozen=True)
class MLPParams:
    """Layer sizes, hidden activation, input/target scaling, initialisation, trainer and its budget."""

    n_in: int = 2
    n_hidden: int = 10
    n_out: int = 1
    hidden: Literal["tansig", "logsig"] = "tansig"
    trainer: Literal["lbfgs", "adam"] = "lbfgs"
    epochs: int = 300
    learning_rate: float = 0.01
    scaling: Literal["mapminmax", "standardize"] = "mapminmax"
    init: Literal["nguyen_widrow", "torch"] = "nguyen_widrow"

    def __post_init__(self):
        check_param("n_in", self.n_in, lo=1, hi=10000, integer=True)
        check_param("n_hidden", self.n_hidden, lo=1, hi=10000, integer=True)
        check_param("n_out", self.n_out, lo=1, hi=10000, integer=True)
        check_param("epochs", self.epochs, lo=1, hi=1_000_000, integer=True)
        check_param("learning_rate", self.learning_rate, lo=0, lo_open=True, hi=10)
        for name, allowed in _CHOICES.items():
            if getattr(self, name) not in allowed:
                raise InputError(
                    f"parameter {name}={getattr(self, name)!r}: must be one of {', '.join(allowed)}"
                )


def _act(z, kind):
    return torch.tanh(z) if kind == "tansig" else torch.sigmoid(z)


@dataclass(frozen=True)
class _Scaler:
    """``s(v) = (v - offset) / scale`` column-wise (mapminmax: offset = (lo+hi)/2, scale = (hi-lo)/2)."""

    offset: np.ndarray
    scale: np.ndarray

    @classmethod
    def fit(cls, A: np.ndarray, kind: str, name: str) -> "_Scaler":
        if not np.all(np.isfinite(A)):
            raise InputError(f"MLP: {name} contain NaN or infinite values")
        if kind == "mapminmax":
            lo, hi = A.min(axis=0), A.max(axis=0)
            hi = np.where(hi > lo, hi, lo + 2.0)  # a constant column is shifted, not scaled
            return cls((lo + hi) / 2, (hi - lo) / 2)
        mu, sd = A.mean(axis=0), A.std(axis=0)
        return cls(mu, np.where(sd > 1e-12 * (1 + np.abs(mu)), sd, 1.0))

    def forward(self, A):
        return (A - self.offset) / self.scale

    def inverse(self, A):
        return A * self.scale + self.offset


class MLP:
    """A trained network.  ``predict(X)``: ``X`` of shape (..., n_in) in input units; returns (..., n_out)
    in target units, or (...,) for a single output.  ``loss_history``: training loss per epoch (scaled
    targets); ``seconds_per_pass``: mean time of one training epoch."""

    def __init__(
        self,
        params: MLPParams,
        weights: dict,
        x_scale: _Scaler,
        y_scale: _Scaler,
        loss_history,
        seconds_per_pass: float,
    ):
        self.params = params
        self.weights = weights
        self.x_scale, self.y_scale = x_scale, y_scale
        self.loss_history = np.asarray(loss_history)
        self.seconds_per_pass = float(seconds_per_pass)

    def predict(self, X) -> np.ndarray:
        X = np.asarray(X, float)
        if X.ndim == 1:
            X = X[None, :]
        if X.shape[-1] != self.params.n_in:
            raise InputError(
                f"MLP.predict: {X.shape[-1]} input columns, the net has {self.params.n_in}"
            )
        lead = X.shape[:-1]
        xs = torch.from_numpy(self.x_scale.forward(X.reshape(-1, self.params.n_in)))
        w = self.weights
        with torch.no_grad():
            y = _act(xs @ w["W1"].T + w["b1"], self.params.hidden) @ w["W2"].T + w["b2"]
        y = self.y_scale.inverse(y.numpy())
        return y.reshape(lead) if self.params.n_out == 1 else y.reshape(lead + (self.params.n_out,))


def _initial_weights(p: MLPParams, seed: int) -> dict:
    if p.init == "torch":
        torch.manual_seed(as_int(np.random.SeedSequence(seed)))
        l1 = torch.nn.Linear(p.n_in, p.n_hidden, dtype=torch.float64)
        l2 = torch.nn.Linear(p.n_hidden, p.n_out, dtype=torch.float64)
        return {
            k: v.detach().numpy().copy()
            for k, v in dict(W1=l1.weight, b1=l1.bias, W2=l2.weight, b2=l2.bias).items()
        }
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    h, n = p.n_hidden, p.n_in
    beta = 0.7 * h ** (1.0 / n)
    W1 = rng.uniform(-1, 1, (h, n))
    W1 = beta * W1 / np.linalg.norm(W1, axis=1, keepdims=True)
    b1 = beta * np.linspace(-1, 1, h) * np.sign(rng.uniform(-1, 1, h))
    return dict(
        W1=W1, b1=b1, W2=rng.uniform(-0.5, 0.5, (p.n_out, h)), b2=rng.uniform(-0.5, 0.5, p.n_out)
    )


def train_mlp(X, Y, params: MLPParams = MLPParams(), seed: int = 0) -> MLP:
    """Train an :class:`MLP` full-batch on ``X`` (..., n_in) and ``Y`` (..., n_out) (or (N,) for one output).

    Parameters
    ----------
    X, Y : array_like
        Training inputs and targets; leading dimensions are flattened into samples.
    params : MLPParams
        Sizes, activation, scaling, initialisation and trainer.
    seed : int
        Seed of the initial weights (through ``numpy.random.SeedSequence``).

    Returns
    -------
    MLP
        The trained network with its scalers, loss history and time per pass.
    """
    p = params
    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    if X.shape[-1] != p.n_in:
        raise InputError(f"MLP: inputs have {X.shape[-1]} columns, the net has n_in={p.n_in}")
    X = X.reshape(-1, p.n_in)
    Y = np.asarray(Y, float).reshape(-1, p.n_out) if np.size(Y) == len(X) * p.n_out else None
    if Y is None or len(X) < 2:
        raise InputError(
            f"MLP: {len(X)} input rows do not match the targets for a {p.n_in}-{p.n_hidden}-"
            f"{p.n_out} net (need at least 2 rows, n_out target columns each)"
        )
    xsc, ysc = _Scaler.fit(X, p.scaling, "inputs"), _Scaler.fit(Y, p.scaling, "targets")
    xs, ys = torch.from_numpy(xsc.forward(X)), torch.from_numpy(ysc.forward(Y))
    w = {
        k: torch.tensor(v, dtype=torch.float64, requires_grad=True)
        for k, v in _initial_weights(p, seed).items()
    }

    def loss_fn():
        out = _act(xs @ w["W1"].T + w["b1"], p.hidden) @ w["W2"].T + w["b2"]
        return torch.mean((out - ys) ** 2)

    hist = np.empty(p.epochs)
    t0 = time.perf_counter()
    if p.trainer == "lbfgs":
        opt = torch.optim.LBFGS(
            list(w.values()),
            lr=1.0,
            max_iter=20,
            history_size=20,
            line_search_fn="strong_wolfe",
            tolerance_grad=1e-12,
            tolerance_change=1e-15,
        )

        def closure():
            opt.zero_grad()
            loss = loss_fn()
            loss.backward()
            return loss

        for e in range(p.epochs):
            hist[e] = float(opt.step(closure).detach())
    else:
        opt = torch.optim.Adam(list(w.values()), lr=p.learning_rate)
        for e in range(p.epochs):
            opt.zero_grad()
            loss = loss_fn()
            loss.backward()
            opt.step()
            hist[e] = float(loss.detach())
    per_pass = (time.perf_counter() - t0) / p.epochs
    return MLP(p, {k: v.detach() for k, v in w.items()}, xsc, ysc, hist, per_pass)
