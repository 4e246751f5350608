"""A generic one-hidden-layer BP network ``n_in - n_hidden - n_out`` in torch (MATLAB's ``feedforwardnet``
shape: ``logsig`` or ``tansig`` hidden layer, ``purelin`` output), trained full-batch with Adam on the mean
squared error, inputs and targets standardised with the training set's mean and spread.

    y = W2 sigma(W1 (x - mu_x)/sd_x + b1) + b2,   output rescaled by sd_y, mu_y

Used by paper E's BPKF (9-10-3, 45-10-3, 6-10-3).  Training time per pass (one epoch over the whole
training set: forward, backward, update) is measured with ``time.perf_counter``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
import torch

from ..errors import InputError, check_param


@dataclass(frozen=True)
class MLPSpec:
    """Network size and training settings."""

    n_in: int
    n_hidden: int = 10
    n_out: int = 3
    hidden: Literal["logsig", "tansig"] = "logsig"
    epochs: int = 300
    learning_rate: float = 0.01

    def __post_init__(self):
        check_param("n_in", self.n_in, lo=1, hi=10000, integer=True)
        check_param("n_hidden", self.n_hidden, lo=1, hi=10000, integer=True)
        check_param("n_out", self.n_out, lo=1, hi=10000, integer=True)
        check_param("epochs", self.epochs, lo=1, hi=1e6, integer=True)
        check_param("learning_rate", self.learning_rate, lo=0.0, lo_open=True, hi=10.0)
        if self.hidden not in ("logsig", "tansig"):
            raise InputError(f"parameter hidden={self.hidden!r}: must be 'logsig' or 'tansig'")


class _Net(torch.nn.Module):
    def __init__(self, spec: MLPSpec):
        super().__init__()
        self.l1 = torch.nn.Linear(spec.n_in, spec.n_hidden, dtype=torch.float64)
        self.l2 = torch.nn.Linear(spec.n_hidden, spec.n_out, dtype=torch.float64)
        self.act = torch.sigmoid if spec.hidden == "logsig" else torch.tanh

    def forward(self, x):
        return self.l2(self.act(self.l1(x)))


@dataclass
class TrainedMLP:
    """A trained network with its scalers; ``predict(X)`` works on raw (unscaled) inputs."""

    spec: MLPSpec
    net: _Net
    mu_x: np.ndarray
    sd_x: np.ndarray
    mu_y: np.ndarray
    sd_y: np.ndarray
    loss: np.ndarray
    seconds_per_pass: float

    def predict(self, x) -> np.ndarray:
        x = np.asarray(x, float)
        shape = x.shape[:-1]
        xs = (x.reshape(-1, self.spec.n_in) - self.mu_x) / self.sd_x
        with torch.no_grad():
            y = self.net(torch.from_numpy(xs)).numpy()
        return (y * self.sd_y + self.mu_y).reshape(shape + (self.spec.n_out,))


def train_mlp(x, y, spec: MLPSpec, seed: int = 0) -> TrainedMLP:
    """Train an ``n_in - n_hidden - n_out`` network on ``x`` (..., n_in) -> ``y`` (..., n_out).

    Weights start from torch's default initialisation under ``torch.manual_seed`` drawn from
    ``SeedSequence(seed)``; constant input columns get unit spread (they then carry no information).

    Returns
    -------
    TrainedMLP
    """
    x = np.asarray(x, float)
    if x.shape[-1] != spec.n_in:
        raise InputError(f"train_mlp: inputs have {x.shape[-1]} columns, n_in={spec.n_in}")
    x = x.reshape(-1, spec.n_in)
    y = np.asarray(y, float).reshape(-1, spec.n_out)
    if len(x) != len(y) or len(x) < 2:
        raise InputError(f"train_mlp: {len(x)} input rows against {len(y)} targets")
    mu_x, sd_x = x.mean(0), x.std(0)
    sd_x = np.where(sd_x > 1e-12 * (1 + np.abs(mu_x)), sd_x, 1.0)
    mu_y, sd_y = y.mean(0), y.std(0)
    sd_y = np.where(sd_y > 0, sd_y, 1.0)
    torch.manual_seed(int(np.random.SeedSequence(seed).generate_state(1)[0]))
    net = _Net(spec)
    xt = torch.from_numpy((x - mu_x) / sd_x)
    yt = torch.from_numpy((y - mu_y) / sd_y)
    opt = torch.optim.Adam(net.parameters(), lr=spec.learning_rate)
    loss_fn = torch.nn.MSELoss()
    losses = np.empty(spec.epochs)
    t0 = time.perf_counter()
    for e in range(spec.epochs):
        opt.zero_grad()
        loss = loss_fn(net(xt), yt)
        loss.backward()
        opt.step()
        losses[e] = loss.item()
    per_pass = (time.perf_counter() - t0) / spec.epochs
    return TrainedMLP(spec, net, mu_x, sd_x, mu_y, sd_y, losses, per_pass)
