"""Paper A's single-input single-output BP network (1-M-1) and its three trainers.

Network (Yue et al., eqs 1-4): input = measured heading x, output = true heading; both min-max normalised
(:class:`navlib.methods.scaling.MinMax`), ``M`` sigmoid hidden neurons, linear (purelin) output:

    x' = (x - x_min)/(x_max - x_min),   y_j = sigmoid(w_j x' + b_j),   o' = sum_j v_j y_j + c,
    o = d_min + o' (d_max - d_min)

One parameter vector ``theta = [w (M), b (M), v (M), c]`` has ``D = 3M + 1`` entries (19 for M = 6).
Fitness (paper eq 5-6, equation image lost in the OCR): ``J = sum_k (d_k - o_k)^2`` over the training
points, in deg^2, on the de-normalised output.

Trainers:

- :func:`train_gradient`: back-propagation by full-batch gradient descent in torch. The paper does not
  say which optimiser its "BP network" used; we use Adam (lr 0.01, 3000 epochs) on the normalised MSE.
  ``method="lm"`` instead uses Levenberg-Marquardt (scipy ``least_squares(method='lm')``), the trainer of
  the paper's reference [8]; with fewer readings than weights (LM cannot run) the same least-squares
  problem is solved by scipy's trust-region reflective method.
- :func:`train_de` with ``DEParams(adaptive=False)`` = DE-BP, ``adaptive=True`` = ADE-BP
  (:mod:`navlib.methods.de`); the whole population is evaluated in one vectorised call.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import torch
from scipy.optimize import least_squares

from .de import DEParams, DEResult, evolve
from ..errors import InputError, check_param
from .scaling import MinMax


def n_params(n_hidden: int) -> int:
    return 3 * n_hidden + 1


def unpack(theta: np.ndarray, n_hidden: int):
    """Split ``(..., 3M+1)`` parameter arrays into ``w, b, v, c``."""
    m = n_hidden
    return theta[..., :m], theta[..., m:2 * m], theta[..., 2 * m:3 * m], theta[..., 3 * m]


def forward_population(thetas: np.ndarray, xn: np.ndarray, n_hidden: int,
                       dtype=np.float64) -> np.ndarray:
    """Normalised outputs of many networks at once: ``thetas (P, D)``, ``xn (N,)`` -> ``(P, N)`` (float64).

    Uses ``sigmoid(z) = (1 + tanh(z/2))/2`` (overflow-free) with the hidden layer laid out ``(P, M, N)`` so
    the innermost loop runs over the N points. ``dtype=np.float32`` computes the hidden layer in single
    precision (twice as fast; output error ~3e-6 of the normalised span)."""
    w, b, v, c = unpack(np.atleast_2d(thetas), n_hidden)
    hw, hb, hv = (0.5 * w).astype(dtype), (0.5 * b).astype(dtype), (0.5 * v).astype(dtype)
    z = np.multiply(hw[:, :, None], np.asarray(xn, dtype=dtype)[None, None, :])
    z += hb[:, :, None]
    np.tanh(z, out=z)
    out = np.matmul(hv[:, None, :], z)[:, 0, :].astype(np.float64)
    out += (0.5 * v.sum(axis=1) + c)[:, None]
    return out


@dataclass
class BPNet:
    """A trained 1-M-1 network with its input and output scalers."""

    theta: np.ndarray
    n_hidden: int
    x_scale: MinMax
    t_scale: MinMax
    method: str = ""
    train_time_s: float = 0.0
    history: np.ndarray = field(default=None, repr=False)   # training loss per epoch / generation
    info: dict = field(default_factory=dict)

    def predict(self, x) -> np.ndarray:
        xn = self.x_scale.transform(np.asarray(x, dtype=float))
        return self.t_scale.inverse(forward_population(self.theta[None, :], xn, self.n_hidden)[0])


def sse_objective(x, t, n_hidden: int, dtype=np.float32):
    """Vectorised fitness ``J(theta) = sum_k (d_k - o_k)^2`` (deg^2) over the training set, plus the scalers.

    The hidden layer runs in ``dtype`` (float32 by default during evolution: output error ~1e-3 deg per
    point, far below the 0.1 deg noise floor); the final network is re-scored in float64.  Layout: one
    GEMM ``[w b] @ [x'; 1]`` gives all ``P*M`` pre-activations at once, one batched matmul the outputs."""
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
    xn = xs.transform(np.asarray(x, dtype=float))
    t = np.asarray(t, dtype=float)
    lo, span = float(ts.lo[0]), float(ts.span[0])
    m, n = n_hidden, len(xn)
    X = (0.5 * np.stack([xn, np.ones_like(xn)])).astype(dtype)            # sigmoid(z) = (1 + tanh(z/2))/2

    def objective(thetas: np.ndarray) -> np.ndarray:
        thetas = np.atleast_2d(thetas)
        p = thetas.shape[0]
        wb = np.empty((p, m, 2), dtype=dtype)
        wb[..., 0] = thetas[:, :m]
        wb[..., 1] = thetas[:, m:2 * m]
        z = wb.reshape(p * m, 2) @ X
        np.tanh(z, out=z)
        hv = (0.5 * span) * thetas[:, 2 * m:3 * m]
        o = np.matmul(hv.astype(dtype)[:, None, :], z.reshape(p, m, n))[:, 0, :].astype(np.float64)
        o += (lo + span * (0.5 * thetas[:, 2 * m:3 * m].sum(axis=1) + thetas[:, 3 * m]))[:, None]
        o -= t
        return np.einsum("pn,pn->p", o, o)

    return objective, xs, ts


def _check_xy(x, t, n_hidden):
    check_param("n_hidden", n_hidden, lo=1, integer=True)
    x, t = np.asarray(x, dtype=float), np.asarray(t, dtype=float)
    if x.ndim != 1 or x.shape != t.shape:
        raise InputError(f"network input and target must be 1-D and of equal length, got {x.shape}, {t.shape}")
    if len(x) < 2:
        raise InputError("a network needs at least 2 training points")
    return x, t


def train_de(x, t, n_hidden: int = 6, params: DEParams = DEParams()) -> tuple[BPNet, DEResult]:
    """DE-BP / ADE-BP: evolve all weights and thresholds of the 1-M-1 net (paper A)."""
    x, t = _check_xy(x, t, n_hidden)
    objective, xs, ts = sse_objective(x, t, n_hidden)
    res = evolve(objective, n_params(n_hidden), params)
    name = "ADE-BP" if params.adaptive else "DE-BP"
    exact, _, _ = sse_objective(x, t, n_hidden, np.float64)
    return BPNet(res.x, n_hidden, xs, ts, name, res.elapsed_s, res.history,
                 {"generations": res.generations, "fitness": float(exact(res.x[None, :])[0])}), res


@dataclass(frozen=True)
class GradientParams:
    """Gradient back-propagation settings. ``method``: 'adam' (default) or 'lm' (Levenberg-Marquardt)."""

    method: str = "adam"
    epochs: int = 3000
    lr: float = 0.01
    init_bound: float = 1.0     # initial weights uniform in [-init_bound, init_bound]
    seed: int = 0

    def validate(self) -> "GradientParams":
        if self.method not in ("adam", "lm"):
            raise InputError(f"parameter method={self.method!r}: must be 'adam' or 'lm'")
        check_param("epochs", self.epochs, lo=1, integer=True)
        check_param("lr", self.lr, lo=0, lo_open=True)
        check_param("init_bound", self.init_bound, lo=0, lo_open=True)
        return self


def train_gradient(x, t, n_hidden: int = 6, params: GradientParams = GradientParams()) -> BPNet:
    """Plain BP: minimise the normalised MSE by Adam (torch, full batch) or by Levenberg-Marquardt."""
    x, t = _check_xy(x, t, n_hidden)
    params.validate()
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
    xn, tn = xs.transform(x), ts.transform(t)
    rng = np.random.default_rng(params.seed)
    theta0 = rng.uniform(-params.init_bound, params.init_bound, n_params(n_hidden))
    t0 = time.perf_counter()
    if params.method == "lm":
        m = n_hidden

        def jac(th):                     # d o'/d[w, b, v, c] with sigma' = sigma (1 - sigma)
            s = 1.0 / (1.0 + np.exp(-np.clip(xn[:, None] * th[:m] + th[m:2 * m], -500, 500)))
            ds = s * (1 - s) * th[2 * m:3 * m]
            return np.hstack([ds * xn[:, None], ds, s, np.ones((len(xn), 1))])

        # MINPACK's Levenberg-Marquardt needs at least as many residuals as weights; an over-sized net on
        # few readings is solved by scipy's trust-region reflective method, same problem and Jacobian.
        solver = "lm" if len(xn) >= n_params(n_hidden) else "trf"
        sol = least_squares(lambda th: forward_population(th[None, :], xn, n_hidden)[0] - tn, theta0,
                            jac=jac, method=solver, max_nfev=params.epochs)
        theta, history = sol.x, np.array([2 * sol.cost / len(x)])
        name = "BP (LM)" if solver == "lm" else "BP (TRF)"
    else:
        with torch.random.fork_rng():
            torch.manual_seed(params.seed)
            th = torch.tensor(theta0, dtype=torch.float64, requires_grad=True)
            X = torch.tensor(xn, dtype=torch.float64)
            T = torch.tensor(tn, dtype=torch.float64)
            opt = torch.optim.Adam([th], lr=params.lr)
            m = n_hidden
            history = np.empty(params.epochs)
            for k in range(params.epochs):
                opt.zero_grad()
                h = torch.sigmoid(X[:, None] * th[:m] + th[m:2 * m])
                loss = torch.mean((h @ th[2 * m:3 * m] + th[3 * m] - T) ** 2)
                loss.backward()
                opt.step()
                history[k] = loss.item()
            theta = th.detach().numpy().copy()
        name = "BP (Adam)"
    return BPNet(theta, n_hidden, xs, ts, name, time.perf_counter() - t0, history)


def train_adam_many(x, t, n_hidden: int, params: GradientParams = GradientParams(),
                    seeds=range(20)) -> list[BPNet]:
    """:func:`train_gradient` with Adam for several seeds at once: one torch graph holds one independent
    1-M-1 net per seed (initial weights drawn exactly as in :func:`train_gradient`).  The summed loss has
    each net's own MSE as its only term in that net's weights, and Adam's update is element-wise, so every
    net follows the same trajectory as when trained alone (up to floating-point rounding); the batch only
    saves the per-epoch overhead, which dominates for small nets.  Returns one :class:`BPNet` per seed;
    ``train_time_s`` is the batch time divided by the number of seeds."""
    x, t = _check_xy(x, t, n_hidden)
    params.validate()
    if params.method != "adam":
        raise InputError(f"parameter method={params.method!r}: train_adam_many trains with 'adam' only")
    seeds = [int(s) for s in seeds]
    if not seeds:
        raise InputError("seeds: need at least one seed")
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
    xn, tn = xs.transform(x), ts.transform(t)
    theta0 = np.stack([np.random.default_rng(s).uniform(-params.init_bound, params.init_bound,
                                                        n_params(n_hidden)) for s in seeds])
    m = n_hidden
    t0 = time.perf_counter()
    th = torch.tensor(theta0, dtype=torch.float64, requires_grad=True)
    X = torch.tensor(xn, dtype=torch.float64)
    T = torch.tensor(tn, dtype=torch.float64)
    opt = torch.optim.Adam([th], lr=params.lr)
    history = np.empty((len(seeds), params.epochs))
    for k in range(params.epochs):
        opt.zero_grad()
        h = torch.sigmoid(X[None, :, None] * th[:, None, :m] + th[:, None, m:2 * m])     # (P, N, M)
        out = torch.einsum("pnm,pm->pn", h, th[:, 2 * m:3 * m]) + th[:, 3 * m:3 * m + 1]
        loss = torch.mean((out - T) ** 2, dim=1)                                          # (P,)
        loss.sum().backward()
        opt.step()
        history[:, k] = loss.detach().numpy()
    theta = th.detach().numpy().copy()
    per_net = (time.perf_counter() - t0) / len(seeds)
    return [BPNet(theta[i], n_hidden, xs, ts, "BP (Adam)", per_net, history[i]) for i in range(len(seeds))]
