"""MATLAB's ``feedforwardnet`` with several inputs and outputs (``n - H - m``), trained by ``trainlm``.

Paper E's BP networks (``45-10-3``, ``6-10-3``, ``9-10-3``) as a MATLAB user of 2019 trains them with
``train`` and its defaults (``/work/shared/notes/algorithms.md``): inputs and targets through
``removeconstantrows`` and ``mapminmax`` onto [-1, 1], hidden activation ``g``, linear output,

    h = g(W x' + b),    o' = V h + c,    o = mapminmax^-1(o')                                   (eq-ff)

with ``W (H, n)``, ``b (H)``, ``V (m, H)``, ``c (m)``: ``D = H n + H + m H + m`` weights (493 for 45-10-3,
103 for 6-10-3, 133 for 9-10-3).  Initialisation ``initnw`` (Nguyen-Widrow hidden layer, output layer
uniform in [-1, 1], :func:`navlib.methods.bpnet.nguyen_widrow`), data split ``dividerand`` 70/15/15 and
``trainlm`` with its defaults and validation stop (:func:`navlib.methods.lm.levenberg_marquardt`).  The
errors ``e`` are the de-normalised outputs minus the targets over every sample and output (MATLAB's
``mse`` with ``normalization = 'none'``), so ``J`` has ``N m`` rows: the cost of one epoch grows with
``N m D^2`` (forming ``J'J``) and ``D^3`` (solving), which is why a net with more inputs trains slower.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_choice, check_param
from .bpnet import ACTIVATIONS, TANSIG_ACTIVE, Activation, nguyen_widrow
from .lm import LMParams, dividerand, levenberg_marquardt
from .scaling import MinMax


def n_weights(n_in: int, n_hidden: int, n_out: int) -> int:
    """``D = H n + H + m H + m``."""
    return n_hidden * n_in + n_hidden + n_out * n_hidden + n_out


def unpack(theta: np.ndarray, n_in: int, n_hidden: int, n_out: int):
    """Split ``(S, D)`` into ``W (S, H, n)``, ``b (S, H)``, ``V (S, m, H)``, ``c (S, m)``."""
    s, h = theta.shape[0], n_hidden
    i = h * n_in
    return (
        theta[:, :i].reshape(s, h, n_in),
        theta[:, i : i + h],
        theta[:, i + h : i + h + n_out * h].reshape(s, n_out, h),
        theta[:, i + h + n_out * h :],
    )


def _hidden(theta, xn, n_in, n_hidden, n_out, activation):
    w, b, v, c = unpack(theta, n_in, n_hidden, n_out)
    z = np.einsum("shi,ni->snh", w, xn) + b[:, None, :]
    if activation == "logsig":
        g = 0.5 * (1.0 + np.tanh(0.5 * z))
        return g, g * (1.0 - g), v, c
    g = np.tanh(z)
    return g, 1.0 - g * g, v, c


def forward(theta, xn, n_in, n_hidden, n_out, activation: Activation = "logsig") -> np.ndarray:
    """Normalised outputs ``o' (S, N, m)`` of eq-ff for ``theta (S, D)`` and normalised inputs ``xn (N, n)``."""
    g, _, v, c = _hidden(np.atleast_2d(theta), xn, n_in, n_hidden, n_out, activation)
    return np.einsum("snh,smh->snm", g, v) + c[:, None, :]


def jacobian(theta, xn, n_in, n_hidden, n_out, activation: Activation = "logsig") -> np.ndarray:
    """``d o' / d theta``, shape ``(S, N, m, D)``: ``do'_k/dW_ji = V_kj g'_j x'_i``, ``do'_k/db_j = V_kj
    g'_j``, ``do'_k/dV_kj = g_j``, ``do'_k/dc_k = 1`` (zero for the other outputs)."""
    theta = np.atleast_2d(theta)
    g, dg, v, _ = _hidden(theta, xn, n_in, n_hidden, n_out, activation)
    s, n, h = g.shape
    vd = v[:, None, :, :] * dg[:, :, None, :]  # (S, N, m, H)
    jw = vd[..., :, None] * xn[None, :, None, None, :]  # (S, N, m, H, n)
    jv = np.zeros((s, n, n_out, n_out, h))
    jc = np.zeros((s, n, n_out, n_out))
    for k in range(n_out):
        jv[:, :, k, k, :] = g
        jc[:, :, k, k] = 1.0
    return np.concatenate(
        [jw.reshape(s, n, n_out, h * n_in), vd, jv.reshape(s, n, n_out, n_out * h), jc], axis=3
    )


@dataclass
class FFNet:
    """A trained ``n - H - m`` net with its scalers, the kept input columns (``removeconstantrows``), the
    training's wall time (whole ``train`` call: processing, initialisation, split, ``trainlm``) and its
    ``trainlm`` record (epochs, stop, best epoch)."""

    theta: np.ndarray
    n_hidden: int
    keep: np.ndarray
    x_scale: MinMax
    t_scale: MinMax
    activation: Activation
    train_time_s: float
    info: dict = field(default_factory=dict)

    def predict(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        xn = self.x_scale.transform(x[:, self.keep])
        o = forward(
            self.theta[None],
            xn,
            int(self.keep.sum()),
            self.n_hidden,
            len(self.t_scale.lo),
            self.activation,
        )[0]
        return self.t_scale.inverse(o)


def train_feedforward(
    x,
    t,
    n_hidden: int,
    rng: np.random.Generator,
    activation: Activation = "tansig",
    lm: LMParams = LMParams(),
    validation: bool = True,
) -> FFNet:
    """``train(feedforwardnet(n_hidden), x', t')`` with MATLAB's defaults (module docstring): ``x (N, n)``,
    ``t (N, m)``; ``rng`` draws the initial weights, then the ``dividerand`` split (with ``validation``;
    without it every sample trains and there is no validation stop).  ``activation``: MATLAB's default
    ``tansig`` or paper E's ``logsig``.  The returned ``train_time_s`` is the wall time of the whole call."""
    t0 = time.perf_counter()
    check_param("n_hidden", n_hidden, lo=1, integer=True)
    check_choice("activation", activation, ACTIVATIONS)
    x, t = np.asarray(x, dtype=float), np.asarray(t, dtype=float)
    if x.ndim != 2 or t.ndim != 2 or len(x) != len(t):
        raise InputError(
            f"network input and target must be 2-D with one row per sample, got {x.shape}, {t.shape}"
        )
    if len(x) < 10:
        raise InputError(f"a network needs at least 10 samples, got {len(x)}")
    keep = np.ptp(x, axis=0) > 0  # removeconstantrows
    if not keep.any():
        raise InputError("network input: every column is constant")
    xs = MinMax.fit(x[:, keep], name="network input", out=(-1, 1))
    ts = MinMax.fit(t, name="network target", out=(-1, 1))
    n_in, n_out, n = int(keep.sum()), t.shape[1], len(x)
    xn = xs.transform(x[:, keep])
    active = (
        TANSIG_ACTIVE if activation == "tansig" else (-4.0, 4.0)
    )  # logsig: MATLAB's 'active' range
    w, b = nguyen_widrow(n_hidden, rng, n_in, active)
    theta0 = np.concatenate([w.ravel(), b, rng.uniform(-1.0, 1.0, n_out * n_hidden + n_out)])[None]
    scale = ts.gain  # d o / d o' per output

    def residuals(th):
        o = forward(th, xn, n_in, n_hidden, n_out, activation)
        return ((o - ts.out_lo) * scale + ts.lo - t[None]).reshape(th.shape[0], n * n_out)

    def jac(th):
        j = jacobian(th, xn, n_in, n_hidden, n_out, activation) * scale[None, None, :, None]
        return j.reshape(th.shape[0], n * n_out, -1)

    tr_mask = val_mask = None
    if validation:
        tr, va, _ = dividerand(n, rng)
        tr_mask, val_mask = np.zeros(n, bool), np.zeros(n, bool)
        tr_mask[tr], val_mask[va] = True, True
        tr_mask, val_mask = np.repeat(tr_mask, n_out), np.repeat(val_mask, n_out)
    res = levenberg_marquardt(residuals, jac, theta0, lm, tr_mask, val_mask)
    return FFNet(
        res.theta[0].copy(),
        n_hidden,
        keep,
        xs,
        ts,
        activation,
        time.perf_counter() - t0,
        {
            "epochs": int(res.epochs[0]),
            "stop": res.stop[0],
            "best_epoch": int(res.best_epoch[0]),
            "n_weights": n_weights(n_in, n_hidden, n_out),
        },
    )
