"""A small generic multilayer perceptron ``n_in - n_hidden - n_out`` as MATLAB's default BP network:
``mapminmax`` scaling of inputs and targets to [-1, 1], one hidden layer ``tansig`` (tanh) or ``logsig``
(logistic), ``purelin`` output, trained full-batch in torch (float64)::

    x' = mapminmax(x),   h = act(W1 x' + b1),   y' = W2 h + b2,   y = mapminmax^-1(y')

Trainers: ``"lbfgs"`` (torch L-BFGS with strong-Wolfe line search, a quasi-Newton stand-in for MATLAB's
``trainlm``) or ``"adam"`` (lr ``learning_rate``).  Loss: mean squared error in the scaled target space.
Initial weights: Nguyen-Widrow-like uniform draws from ``np.random.SeedSequence(seed)``.
Used by paper D's ANN baseline (2-n-1); written generic for other papers' nets (e.g. 9-10-3).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import torch

from ..errors import InputError, check_param


@dataclass(frozen=True)
class MLPParams:
    """Layer sizes, hidden activation, trainer and its budget."""

    n_in: int = 2
    n_hidden: int = 10
    n_out: int = 1
    hidden: Literal["tansig", "logsig"] = "tansig"
    trainer: Literal["lbfgs", "adam"] = "lbfgs"
    epochs: int = 300
    learning_rate: float = 0.01

    def __post_init__(self):
        check_param("n_in", self.n_in, lo=1, hi=10000, integer=True)
        check_param("n_hidden", self.n_hidden, lo=1, hi=10000, integer=True)
        check_param("n_out", self.n_out, lo=1, hi=10000, integer=True)
        check_param("epochs", self.epochs, lo=1, hi=1_000_000, integer=True)
        check_param("learning_rate", self.learning_rate, lo=0, lo_open=True, hi=10)
        if self.hidden not in ("tansig", "logsig"):
            raise InputError(f"parameter hidden={self.hidden!r}: must be 'tansig' or 'logsig'")
        if self.trainer not in ("lbfgs", "adam"):
            raise InputError(f"parameter trainer={self.trainer!r}: must be 'lbfgs' or 'adam'")


class MLP:
    """A trained network: ``predict(X)`` returns (N, n_out) (or (N,) for one output) in target units."""

    def __init__(self, params: MLPParams, weights: dict, x_range, y_range, loss_history):
        self.params = params
        self.weights = weights
        self.x_lo, self.x_hi = x_range
        self.y_lo, self.y_hi = y_range
        self.loss_history = np.asarray(loss_history)

    @staticmethod
    def _act(z, kind):
        return torch.tanh(z) if kind == "tansig" else torch.sigmoid(z)

    def predict(self, X) -> np.ndarray:
        X = np.atleast_2d(np.asarray(X, float))
        if X.shape[1] != self.params.n_in:
            raise InputError(f"MLP.predict: {X.shape[1]} input columns, the net has {self.params.n_in}")
        xs = torch.from_numpy(2 * (X - self.x_lo) / (self.x_hi - self.x_lo) - 1)
        w = self.weights
        with torch.no_grad():
            y = self._act(xs @ w["W1"].T + w["b1"], self.params.hidden) @ w["W2"].T + w["b2"]
        y = (y.numpy() + 1) / 2 * (self.y_hi - self.y_lo) + self.y_lo
        return y[:, 0] if self.params.n_out == 1 else y


def _range(A, name):
    lo, hi = A.min(axis=0), A.max(axis=0)
    hi = np.where(hi > lo, hi, lo + 1.0)        # mapminmax leaves constant rows unscaled
    if not np.all(np.isfinite(A)):
        raise InputError(f"MLP: {name} contain NaN or infinite values")
    return lo, hi


def train(X, Y, params: MLPParams = MLPParams(), seed: int = 0) -> MLP:
    """Train an :class:`MLP` full-batch on ``X`` (N, n_in) and ``Y`` (N,) or (N, n_out)."""
    X = np.atleast_2d(np.asarray(X, float))
    Y = np.asarray(Y, float).reshape(len(X), -1)
    if X.shape[1] != params.n_in or Y.shape[1] != params.n_out:
        raise InputError(f"MLP: data {X.shape} -> {Y.shape} do not fit {params.n_in}-{params.n_hidden}-"
                         f"{params.n_out}")
    xr, yr = _range(X, "inputs"), _range(Y, "targets")
    xs = torch.from_numpy(2 * (X - xr[0]) / (xr[1] - xr[0]) - 1)
    ys = torch.from_numpy(2 * (Y - yr[0]) / (yr[1] - yr[0]) - 1)
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    h, n = params.n_hidden, params.n_in
    beta = 0.7 * h ** (1.0 / n)
    W1 = rng.uniform(-1, 1, (h, n))
    W1 = beta * W1 / np.linalg.norm(W1, axis=1, keepdims=True)
    b1 = beta * np.linspace(-1, 1, h) * np.sign(rng.uniform(-1, 1, h))
    W2 = rng.uniform(-0.5, 0.5, (params.n_out, h))
    b2 = rng.uniform(-0.5, 0.5, params.n_out)
    w = {k: torch.tensor(v, dtype=torch.float64, requires_grad=True)
         for k, v in dict(W1=W1, b1=b1, W2=W2, b2=b2).items()}
    act = MLP._act

    def loss_fn():
        out = act(xs @ w["W1"].T + w["b1"], params.hidden) @ w["W2"].T + w["b2"]
        return torch.mean((out - ys) ** 2)

    hist = []
    if params.trainer == "lbfgs":
        opt = torch.optim.LBFGS(list(w.values()), lr=1.0, max_iter=20, history_size=20,
                                line_search_fn="strong_wolfe", tolerance_grad=1e-12, tolerance_change=1e-15)

        def closure():
            opt.zero_grad()
            loss = loss_fn()
            loss.backward()
            return loss

        for _ in range(params.epochs):
            hist.append(float(opt.step(closure).detach()))
    else:
        opt = torch.optim.Adam(list(w.values()), lr=params.learning_rate)
        for _ in range(params.epochs):
            opt.zero_grad()
            loss = loss_fn()
            loss.backward()
            opt.step()
            hist.append(float(loss))
    return MLP(params, {k: v.detach() for k, v in w.items()}, xr, yr, hist)
