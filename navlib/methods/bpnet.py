"""Paper A's single-input single-output BP network (1-M-1), MATLAB's default BP network, and their trainers.

Network (Yue et al., eqs 1-4): input = measured heading x, output = true heading; both min-max normalised
(:class:`navlib.methods.scaling.MinMax`), ``M`` hidden neurons with activation ``g``, linear output:

    x' = scale(x),   y_j = g(w_j x' + b_j),   o' = sum_j v_j y_j + c,   o = scale^-1(o')          (eq-bp)

- paper A's net: ``g = logsig`` (sigmoid), ``scale`` onto [0, 1];
- MATLAB's ``feedforwardnet`` (what a MATLAB user of 2015 gets from ``train``): ``g = tansig`` (tanh),
  ``scale`` = ``mapminmax`` onto [-1, 1], Nguyen-Widrow initialisation (:func:`nguyen_widrow`),
  Levenberg-Marquardt training (:mod:`navlib.methods.lm`).

One parameter vector ``theta = [w (M), b (M), v (M), c]`` has ``D = 3M + 1`` entries (19 for M = 6).
Fitness of the DE trainers (paper eq 5-6, equation image lost in the OCR): ``J = sum_k (d_k - o_k)^2``
over the training points, in deg^2 on the de-normalised output (:func:`sse_objective`).

Trainers (each trains several runs at once, one generator per run, :mod:`navlib.methods.seeding`):

- :func:`train_de_many`: DE-BP / ADE-BP, every weight and threshold evolved (paper A, first reading);
- :func:`train_hybrid_many`: the DE / ADE stage, then ``trainlm`` from its best individual (second
  reading: DE chooses the initial weights of an ordinary BP training);
- :func:`train_matlab_bp_many`: MATLAB's default BP (third reading);
- :func:`train_adam_many`: back-propagation with Adam from U(-1, 1) weights (an extra row);
- :func:`train_least_squares`: scipy's MINPACK LM (or TRF with fewer readings than weights) to
  convergence from U(-1, 1) weights (the ``bp_scipy_lm`` extra of :mod:`navlib.studies.compass.turntable`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from scipy.optimize import least_squares

from .._optional import require
from ..errors import InputError, check_choice, check_param
from .de import DEParams, DEResult, evolve_many
from .jit import LM_STOPS, hidden_accept, lm_1m1, logsig_sse, logsig_sse_keep, logsig_sse_trials
from .lm import LMParams, LMResult, dividerand, levenberg_marquardt
from .scaling import MinMax

torch = require("torch", __name__)  # the [nets] extra
from torch.optim.adam import adam as adam_step  # noqa: E402

Activation = Literal["logsig", "tansig"]
ACTIVATIONS = ("logsig", "tansig")
#: tansig's active input region (MATLAB ``tansig('active')``), used by the Nguyen-Widrow rule.
TANSIG_ACTIVE = (-2.0, 2.0)


def n_params(n_hidden: int) -> int:
    return 3 * n_hidden + 1


def unpack(theta: np.ndarray, n_hidden: int):
    """Split ``(..., 3M+1)`` parameter arrays into ``w, b, v, c``."""
    m = n_hidden
    return theta[..., :m], theta[..., m : 2 * m], theta[..., 2 * m : 3 * m], theta[..., 3 * m]


def forward_population(
    thetas: np.ndarray,
    xn: np.ndarray,
    n_hidden: int,
    dtype=np.float64,
    activation: Activation = "logsig",
) -> np.ndarray:
    """Normalised outputs of many networks at once: ``thetas (P, D)``, ``xn (N,)`` -> ``(P, N)`` (float64).

    ``logsig`` is computed as ``(1 + tanh(z/2))/2`` (overflow-free) with the hidden layer laid out
    ``(P, M, N)``.  ``dtype=np.float32`` computes the hidden layer in single precision."""
    w, b, v, c = unpack(np.atleast_2d(thetas), n_hidden)
    half = activation == "logsig"
    k = 0.5 if half else 1.0
    hw, hb = (k * w).astype(dtype), (k * b).astype(dtype)
    z = np.multiply(hw[:, :, None], np.asarray(xn, dtype=dtype)[None, None, :])
    z += hb[:, :, None]
    np.tanh(z, out=z)
    out = np.matmul((k * v).astype(dtype)[:, None, :], z)[:, 0, :].astype(np.float64)
    out += ((0.5 * v.sum(axis=1) if half else 0.0) + c)[:, None]
    return out


def output_jacobian(
    thetas: np.ndarray, xn: np.ndarray, n_hidden: int, activation: Activation = "logsig"
):
    """``(o', do'/dtheta)`` of many networks: shapes ``(P, N)`` and ``(P, N, D)`` (float64).

    ``do'/dw_j = v_j g'(z_j) x'``, ``do'/db_j = v_j g'(z_j)``, ``do'/dv_j = g(z_j)``, ``do'/dc = 1``, with
    ``g' = g (1 - g)`` for logsig and ``1 - g^2`` for tansig."""
    w, b, v, c = unpack(np.atleast_2d(thetas), n_hidden)
    z = w[:, None, :] * xn[None, :, None] + b[:, None, :]  # (P, N, M)
    if activation == "logsig":
        g = 0.5 * (1.0 + np.tanh(0.5 * z))
        dg = g * (1.0 - g)
    else:
        g = np.tanh(z)
        dg = 1.0 - g * g
    out = np.einsum("pnm,pm->pn", g, v) + c[:, None]
    vd = dg * v[:, None, :]
    jac = np.concatenate([vd * xn[None, :, None], vd, g, np.ones(g.shape[:2] + (1,))], axis=2)
    return out, jac


@dataclass
class BPNet:
    """A trained 1-M-1 network with its input and output scalers (the equation in the module docstring)."""

    theta: np.ndarray
    n_hidden: int
    x_scale: MinMax
    t_scale: MinMax
    method: str = ""
    train_time_s: float = 0.0
    history: np.ndarray = field(default=None, repr=False)  # training loss per epoch / generation
    info: dict = field(default_factory=dict)
    activation: Activation = "logsig"

    def predict(self, x) -> np.ndarray:
        xn = self.x_scale.transform(np.asarray(x, dtype=float))
        return self.t_scale.inverse(
            forward_population(self.theta[None, :], xn, self.n_hidden, activation=self.activation)[
                0
            ]
        )


class LogsigSSE:
    """The float32 fitness of :func:`sse_objective` (:func:`navlib.methods.jit.logsig_sse`): call it on
    ``(K, 3M+1)`` parameter vectors.  It also offers :func:`navlib.methods.de.evolve_many`'s parent-cache
    protocol (``start``, ``trials``, ``accept``, ``keep``): it keeps the current population's hidden-layer
    outputs and evaluates each trial from its parent's, recomputing only the hidden units whose weights the
    trial changed (:func:`navlib.methods.jit.logsig_sse_trials`); every fitness is the call's, bit for bit."""

    def __init__(self, xn, t, lo: float, span: float, n_hidden: int):
        self.xn, self.t, self.lo, self.span, self.m = xn, t, lo, span, int(n_hidden)
        self._hidden = self._trial_hidden = self._changed = None

    def __call__(self, thetas: np.ndarray) -> np.ndarray:
        return logsig_sse(
            np.ascontiguousarray(np.atleast_2d(thetas), dtype=float),
            self.xn,
            self.t,
            self.lo,
            self.span,
            self.m,
        )

    def start(self, pop: np.ndarray) -> np.ndarray:
        """Fitness of a population ``(K, 3M+1)``, keeping its hidden layers."""
        pop = np.ascontiguousarray(pop, dtype=float)
        self._hidden = np.empty((pop.shape[0], self.m, len(self.xn)), np.float32)
        self._trial_hidden = np.empty_like(self._hidden)
        self._changed = np.zeros((pop.shape[0], self.m), np.bool_)
        return logsig_sse_keep(pop, self.xn, self.t, self.lo, self.span, self.m, self._hidden)

    def trials(self, trial: np.ndarray, pop: np.ndarray) -> np.ndarray:
        """Fitness of trial ``k`` made from individual ``k`` of the population last passed to ``start`` (as
        updated by ``accept`` and ``keep``); ``pop`` is that population."""
        return logsig_sse_trials(
            np.ascontiguousarray(trial, dtype=float),
            np.ascontiguousarray(pop, dtype=float),
            self._hidden,
            self.xn,
            self.t,
            self.lo,
            self.span,
            self.m,
            self._trial_hidden,
            self._changed,
        )

    def accept(self, accepted: np.ndarray) -> None:
        """Trials ``accepted (K,)`` replaced their parents."""
        hidden_accept(
            self._hidden, self._trial_hidden, self._changed, np.asarray(accepted, dtype=np.bool_)
        )

    def keep(self, rows: np.ndarray) -> None:
        """Only the individuals ``rows (K,)`` (bool) stay in the population."""
        rows = np.asarray(rows, dtype=np.bool_)
        self._hidden = np.ascontiguousarray(self._hidden[rows])
        self._trial_hidden = np.ascontiguousarray(self._trial_hidden[rows])
        self._changed = np.ascontiguousarray(self._changed[rows])


def sse_objective(x, t, n_hidden: int, dtype=np.float32):
    """Vectorised fitness ``J(theta) = sum_k (d_k - o_k)^2`` (deg^2) of paper A's net over the training set,
    plus the scalers.

    ``dtype=np.float32`` (the default, used during evolution): :class:`LogsigSSE`, the compiled kernel
    :func:`navlib.methods.jit.logsig_sse`, hidden layer in single precision (output error ~1e-3 deg per
    point, far below the 0.1 deg noise floor; about 5x faster than numpy's float32 ``tanh``).
    ``dtype=np.float64``: numpy in double precision, for re-scoring final networks and as the reference
    the kernel is tested against."""
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
    xn = np.ascontiguousarray(xs.transform(np.asarray(x, dtype=float)), dtype=float)
    t = np.ascontiguousarray(t, dtype=float)
    lo, span = float(ts.lo[0]), float(ts.span[0])
    m, n = int(n_hidden), len(xn)
    if dtype == np.float32:
        return LogsigSSE(xn, t, lo, span, m), xs, ts
    X = 0.5 * np.stack([xn, np.ones_like(xn)])  # sigmoid(z) = (1 + tanh(z/2))/2

    def objective(thetas: np.ndarray) -> np.ndarray:
        thetas = np.atleast_2d(thetas)
        p = thetas.shape[0]
        wb = np.stack([thetas[:, :m], thetas[:, m : 2 * m]], axis=2)
        z = np.tanh(wb.reshape(p * m, 2) @ X)
        hv = (0.5 * span) * thetas[:, 2 * m : 3 * m]
        o = np.matmul(hv[:, None, :], z.reshape(p, m, n))[:, 0, :]
        o += (lo + span * (0.5 * thetas[:, 2 * m : 3 * m].sum(axis=1) + thetas[:, 3 * m]))[:, None]
        o -= t
        return np.einsum("pn,pn->p", o, o)

    return objective, xs, ts


def _check_xy(x, t, n_hidden):
    check_param("n_hidden", n_hidden, lo=1, integer=True)
    x, t = np.asarray(x, dtype=float), np.asarray(t, dtype=float)
    if x.ndim != 1 or x.shape != t.shape:
        raise InputError(
            f"network input and target must be 1-D and of equal length, got {x.shape}, {t.shape}"
        )
    if len(x) < 2:
        raise InputError("a network needs at least 2 training points")
    return x, t


# ------------------------------------------------------------------------------------------ initialisation
def nguyen_widrow(
    n_hidden: int,
    rng: np.random.Generator,
    n_inputs: int = 1,
    active: tuple[float, float] = TANSIG_ACTIVE,
) -> tuple[np.ndarray, np.ndarray]:
    """MATLAB's ``initnw`` for a hidden layer whose inputs lie in [-1, 1] (after ``mapminmax``).

    Weight magnitude ``0.7 H^(1/n)`` along a random unit direction per unit, biases
    ``0.7 H^(1/n) linspace(-1, 1, H) sign(w_1)``, both then stretched from [-1, 1] to the activation's
    active region (``[-2, 2]`` for tansig).  For one input the units' active regions
    ``|w x + b| <= 2`` are centred at ``-linspace(-1, 1, H)`` (in random order of sign) and together span
    the input range.  Returns ``w (H, n)`` and ``b (H,)``."""
    check_param("n_hidden", n_hidden, lo=1, integer=True)
    check_param("n_inputs", n_inputs, lo=1, integer=True)
    mag = 0.7 * n_hidden ** (1.0 / n_inputs)
    d = rng.standard_normal((n_hidden, n_inputs))
    w = mag * d / np.linalg.norm(d, axis=1, keepdims=True)
    b = (
        np.zeros(n_hidden)
        if n_hidden == 1
        else mag * np.linspace(-1, 1, n_hidden) * np.sign(w[:, 0])
    )
    half, mid = 0.5 * (active[1] - active[0]), 0.5 * (active[1] + active[0])
    return half * w, half * b + mid


def matlab_initial_weights(n_hidden: int, rng: np.random.Generator) -> np.ndarray:
    """Initial ``theta`` of ``feedforwardnet(n_hidden)`` on one input: Nguyen-Widrow hidden layer
    (:func:`nguyen_widrow`); the purelin output layer has an unbounded active region, so ``initnw`` falls
    back to ``rands``: output weights and bias uniform in [-1, 1]."""
    w, b = nguyen_widrow(n_hidden, rng)
    vc = rng.uniform(-1.0, 1.0, n_hidden + 1)
    return np.concatenate([w[:, 0], b, vc])


# ------------------------------------------------------------------------------------------ trainers
@dataclass(frozen=True)
class AdamParams:
    """Back-propagation by full-batch Adam on the normalised MSE; weights start uniform in
    [-init_bound, init_bound]."""

    epochs: int = 3000
    lr: float = 0.01
    init_bound: float = 1.0

    def __post_init__(self):
        check_param("epochs", self.epochs, lo=1, integer=True)
        check_param("lr", self.lr, lo=0, lo_open=True)
        check_param("init_bound", self.init_bound, lo=0, lo_open=True)


def _rngs(rngs) -> list:
    rngs = list(rngs)
    if not rngs or not all(isinstance(g, np.random.Generator) for g in rngs):
        raise InputError("rngs: need at least one numpy Generator (see navlib.methods.seeding)")
    return rngs


def _adam_trajectories(
    theta0: np.ndarray, xn: np.ndarray, tn: np.ndarray, n_hidden: int, params: AdamParams
):
    """Full-batch Adam on the normalised MSE of ``P`` logsig nets at once (:func:`train_adam_many`).

    The gradient is written out with torch operations, without an autograd graph (an epoch of the
    autograd version costs several times as much on these tiny tensors).  With ``e = o' - t'`` over the
    ``N`` readings, ``h_j = sigmoid(w_j x' + b_j)`` and ``g = 2 e / N``:

        dL/dv_j = sum_k g_k h_jk,   dL/dc = sum_k g_k,   dL/db_j = sum_k g_k v_j h_jk (1 - h_jk),
        dL/dw_j = sum_k g_k v_j h_jk (1 - h_jk) x'_k                                           (eq-adam-grad)

    and torch's fused Adam kernel (the fastest of its CPU implementations for one ``(P, D)`` tensor) takes
    the step, through the functional ``torch.optim.adam.adam`` with the state ``torch.optim.Adam`` keeps
    (moments, a float32 step count): the same update, bit for bit, as ``torch.optim.Adam(fused=True)``,
    without the optimizer object's per-step bookkeeping, which costs more than the kernel on these
    tensors.  Runs single-threaded (restoring the caller's thread count), so the result does not depend on
    ``torch.set_num_threads``.  Returns the final ``theta (P, D)`` and the loss history ``(P, epochs)``
    (the loss before each step)."""
    m, n = n_hidden, xn.size
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        th = torch.tensor(theta0, dtype=torch.float64)
        grad, exp_avg, exp_avg_sq = torch.zeros_like(th), torch.zeros_like(th), torch.zeros_like(th)
        step = torch.zeros((), dtype=torch.float32)
        X = torch.tensor(xn, dtype=torch.float64)
        T = torch.tensor(tn, dtype=torch.float64)
        w, b = th[:, :m, None], th[:, m : 2 * m, None]  # (P, M, 1)
        v, c = th[:, None, 2 * m : 3 * m], th[:, 3 * m :, None]  # (P, 1, M), (P, 1, 1)
        xr, scale = X[None, None, :], 2.0 / n
        sigmoid_backward = torch.ops.aten.sigmoid_backward  # dy * y (1 - y), as autograd
        history = torch.empty(
            (params.epochs, th.shape[0], 1), dtype=torch.float64
        )  # rows contiguous
        with torch.no_grad():
            for k in range(params.epochs):
                h = torch.addcmul(b, w, xr).sigmoid_()  # (P, M, N)
                e = torch.baddbmm(c, v, h).sub_(T)  # o' - t', (P, 1, N)
                torch.mean(e * e, dim=2, out=history[k])
                g = e.mul_(scale)
                dz = sigmoid_backward(v.transpose(1, 2) * g, h)  # dL/dz, (P, M, N)
                torch.cat(
                    [dz @ X, dz.sum(dim=2), (h * g).sum(dim=2), g.sum(dim=2)], dim=1, out=grad
                )
                adam_step(
                    [th],
                    [grad],
                    [exp_avg],
                    [exp_avg_sq],
                    [],
                    [step],
                    fused=True,
                    amsgrad=False,
                    beta1=0.9,
                    beta2=0.999,
                    lr=params.lr,
                    weight_decay=0.0,
                    eps=1e-8,
                    maximize=False,
                )
        return th.numpy().copy(), history[:, :, 0].T.numpy().copy()
    finally:
        torch.set_num_threads(threads)


def train_adam_many(x, t, n_hidden: int, params: AdamParams, rngs) -> list[BPNet]:
    """Paper A's net trained by Adam, one independent net per generator in ``rngs``, all in one batch.

    Each net's loss is its own normalised MSE and Adam's update is element-wise, so every net follows the
    trajectory it would follow alone (up to rounding); the batch saves the per-epoch overhead.  The
    gradient is analytic (``_adam_trajectories``), the same as back-propagation by autograd up to
    rounding.  ``train_time_s`` is the batch time divided by the number of nets."""
    x, t = _check_xy(x, t, n_hidden)
    rngs = _rngs(rngs)
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
    xn, tn = xs.transform(x), ts.transform(t)
    theta0 = np.stack(
        [g.uniform(-params.init_bound, params.init_bound, n_params(n_hidden)) for g in rngs]
    )
    t0 = time.perf_counter()
    theta, history = _adam_trajectories(theta0, xn, tn, n_hidden, params)
    per_net = (time.perf_counter() - t0) / len(rngs)
    return [
        BPNet(theta[i], n_hidden, xs, ts, "BP (Adam)", per_net, history[i])
        for i in range(len(rngs))
    ]


def train_least_squares(
    x, t, n_hidden: int, rng: np.random.Generator, max_nfev: int = 3000, init_bound: float = 1.0
) -> BPNet:
    """Paper A's net fitted to convergence by scipy ``least_squares`` on the normalised residuals from
    U(-init_bound, init_bound) weights: MINPACK's Levenberg-Marquardt, or trust-region reflective when
    there are fewer readings than weights (MINPACK's LM cannot run then)."""
    x, t = _check_xy(x, t, n_hidden)
    check_param("max_nfev", max_nfev, lo=1, integer=True)
    xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
    xn, tn = xs.transform(x), ts.transform(t)
    theta0 = rng.uniform(-init_bound, init_bound, n_params(n_hidden))
    t0 = time.perf_counter()
    solver = "lm" if len(xn) >= n_params(n_hidden) else "trf"
    sol = least_squares(
        lambda th: output_jacobian(th[None], xn, n_hidden)[0][0] - tn,
        theta0,
        jac=lambda th: output_jacobian(th[None], xn, n_hidden)[1][0],
        method=solver,
        max_nfev=max_nfev,
    )
    name = "BP (LM)" if solver == "lm" else "BP (TRF)"
    return BPNet(
        sol.x, n_hidden, xs, ts, name, time.perf_counter() - t0, np.array([2 * sol.cost / len(x)])
    )


def _lm_functions(x, t, n_hidden, xs: MinMax, ts: MinMax, activation: Activation):
    """Residuals (deg) and their Jacobian for :func:`navlib.methods.lm.levenberg_marquardt`: MATLAB scores
    the de-normalised output (``performParam.normalization = 'none'``)."""
    xn = xs.transform(x)
    gain, lo, out_lo = float(ts.gain[0]), float(ts.lo[0]), ts.out_lo

    def residuals(th):
        return (
            lo + (forward_population(th, xn, n_hidden, activation=activation) - out_lo) * gain - t
        )

    def jacobian(th):
        return gain * output_jacobian(th, xn, n_hidden, activation)[1]

    return residuals, jacobian


def train_lm_many(
    x,
    t,
    n_hidden: int,
    theta0: np.ndarray,
    xs: MinMax,
    ts: MinMax,
    activation: Activation = "logsig",
    lm: LMParams = LMParams(),
    splits=None,
    method: str = "BP (trainlm)",
    compiled: bool = True,
) -> list[BPNet]:
    """``trainlm`` from ``theta0 (S, D)`` for S nets.  ``splits``: None (every reading trains, no validation
    stop) or one ``(train, val, test)`` index triple per net (MATLAB's ``dividerand``; the test part is
    held out and unused).

    ``compiled`` (default): :func:`navlib.methods.jit.lm_1m1`, the algorithm of
    :func:`navlib.methods.lm.levenberg_marquardt` compiled for this network (no per-epoch Python: about
    5-20x faster, most for small batches); ``False``: the generic batched numpy version itself."""
    x, t = _check_xy(x, t, n_hidden)
    check_choice("activation", activation, ACTIVATIONS)
    theta0 = np.atleast_2d(np.asarray(theta0, dtype=float))
    res_fn, jac_fn = _lm_functions(x, t, n_hidden, xs, ts, activation)
    tr_mask = val_mask = None
    if splits is not None:
        if len(splits) != theta0.shape[0]:
            raise InputError(f"splits: one per net, got {len(splits)} for {theta0.shape[0]} nets")
        tr_mask = np.zeros((len(splits), len(x)), bool)
        val_mask = np.zeros_like(tr_mask)
        for i, (tr, va, _) in enumerate(splits):
            tr_mask[i, tr], val_mask[i, va] = True, True
    t0 = time.perf_counter()
    if compiled:
        n_nets, n = theta0.shape[0], len(x)
        wt = np.ones((n_nets, n)) if tr_mask is None else tr_mask.astype(float)
        wv = np.zeros((n_nets, n)) if val_mask is None else val_mask.astype(float)
        th, ep, codes, perf, vperf, best = lm_1m1(
            theta0,
            np.ascontiguousarray(xs.transform(x)),
            t,
            int(n_hidden),
            activation == "tansig",
            float(ts.lo[0]),
            float(ts.out_lo),
            float(ts.gain[0]),
            wt,
            wv,
            val_mask is not None,
            int(lm.epochs),
            float(lm.goal),
            float(lm.mu),
            float(lm.mu_dec),
            float(lm.mu_inc),
            float(lm.mu_max),
            float(lm.min_grad),
            int(lm.max_fail),
        )
        res = LMResult(
            theta=th,
            epochs=ep,
            stop=[LM_STOPS[c] for c in codes],
            perf=perf,
            val_perf=vperf,
            best_epoch=best,
        )
    else:
        res = levenberg_marquardt(res_fn, jac_fn, theta0, lm, tr_mask, val_mask)
    per_net = (time.perf_counter() - t0) / theta0.shape[0]
    nets = []
    for i in range(theta0.shape[0]):
        h = res.perf[i]
        nets.append(
            BPNet(
                res.theta[i].copy(),
                n_hidden,
                xs,
                ts,
                method,
                per_net,
                h[np.isfinite(h)],
                {
                    "epochs": int(res.epochs[i]),
                    "stop": res.stop[i],
                    "best_epoch": int(res.best_epoch[i]),
                    "val_history": res.val_perf[i][np.isfinite(res.val_perf[i])],
                },
                activation,
            )
        )
    return nets


def train_matlab_bp_many(
    x, t, n_hidden: int, rngs, lm: LMParams = LMParams(), validation: bool = False
) -> list[BPNet]:
    """MATLAB's default BP net, one per generator: ``feedforwardnet(n_hidden)`` (tansig hidden, purelin
    output, ``mapminmax`` of input and target onto [-1, 1] computed on all readings, Nguyen-Widrow
    initialisation) trained by ``trainlm``; with ``validation`` the readings are split by ``dividerand``
    70/15/15 and training stops after ``max_fail`` validation failures (MATLAB's default), without it every
    reading trains.  Each generator draws the initial weights, then the split."""
    x, t = _check_xy(x, t, n_hidden)
    rngs = _rngs(rngs)
    xs, ts = (
        MinMax.fit(x, name="network input", out=(-1, 1)),
        MinMax.fit(t, name="network target", out=(-1, 1)),
    )
    theta0 = np.stack([matlab_initial_weights(n_hidden, g) for g in rngs])
    splits = [dividerand(len(x), g) for g in rngs] if validation else None
    label = "BP MATLAB (trainlm" + (", val. stop)" if validation else ")")
    return train_lm_many(x, t, n_hidden, theta0, xs, ts, "tansig", lm, splits, label)


def train_de_many(
    x, t, n_hidden: int, params: DEParams, rngs
) -> tuple[list[BPNet], list[DEResult]]:
    """DE-BP / ADE-BP (paper A, first reading): every weight and threshold of paper A's net evolved by
    :func:`navlib.methods.de.evolve_many` on the fitness :func:`sse_objective`, one run per generator,
    all runs' populations in one array per generation.  ``info['fitness']`` is re-scored in float64."""
    x, t = _check_xy(x, t, n_hidden)
    rngs = _rngs(rngs)
    objective, xs, ts = sse_objective(x, t, n_hidden)
    results = evolve_many(objective, n_params(n_hidden), params, rngs)
    exact, _, _ = sse_objective(x, t, n_hidden, np.float64)
    name = "ADE-BP" if params.adaptive else "DE-BP"
    nets = [
        BPNet(
            r.x,
            n_hidden,
            xs,
            ts,
            name,
            r.elapsed_s / len(rngs),
            r.history,
            {"generations": r.generations, "fitness": float(exact(r.x[None, :])[0])},
        )
        for r in results
    ]
    return nets, results


#: The trainings that share one full DE stage (:func:`train_de_family`).
FAMILY_VARIANTS = ("pure", "trainlm", "trainlm_val")


def train_de_family(
    x,
    t,
    n_hidden: int,
    params: DEParams,
    rngs,
    lm: LMParams = LMParams(),
    variants=FAMILY_VARIANTS,
    target: Literal["deg2", "normalised"] = "deg2",
) -> dict[str, list[BPNet]]:
    """One DE / ADE stage run to its own stop (``target='deg2'``: the paper's target read in deg^2, in
    practice the full ``max_generations``; ``'normalised'``: read as :func:`train_hybrid_many` reads it,
    reached early), and from it every training in ``variants``:

    - ``'pure'``: the stage's best individual (:func:`train_de_many`, paper A's first reading);
    - ``'trainlm'``: ``trainlm`` from it on all readings (:func:`train_hybrid_many` with
      ``target='deg2'``);
    - ``'trainlm_val'``: the same with the ``dividerand`` split and validation stop, the split drawn from
      each run's generator after the stage.

    Each variant equals what its own trainer gives with the same generators (the stage draws first, only
    ``'trainlm_val'`` draws after it), at the cost of one DE stage (with ``target='normalised'``, the
    trainlm variants equal :func:`train_hybrid_many`'s, pure DE is not offered).  Returns
    ``{variant: nets}``."""
    variants = tuple(variants)
    for v in variants:
        check_choice("variant", v, FAMILY_VARIANTS)
    check_choice("target", target, ("deg2", "normalised"))
    if target == "normalised" and "pure" in variants:
        raise InputError("train_de_family: pure DE shares only the full stage (target='deg2')")
    x, t = _check_xy(x, t, n_hidden)
    rngs = _rngs(rngs)
    de_nets, _ = train_de_many(x, t, n_hidden, _stage(params, t, target), rngs)
    out: dict[str, list[BPNet]] = {}
    if "pure" in variants:
        out["pure"] = de_nets
    name = "ADE-BP" if params.adaptive else "DE-BP"
    for v in ("trainlm", "trainlm_val"):
        if v in variants:
            validation = v == "trainlm_val"
            out[v] = _trainlm_from_stage(
                x,
                t,
                n_hidden,
                de_nets,
                rngs,
                lm,
                validation,
                _hybrid_name(name, validation)
                if target == "normalised"
                else name + " full DE + trainlm" + (", val. stop" if validation else ""),
            )
    return out


def _stage(params: DEParams, t, target: str) -> DEParams:
    """The DE stage's settings under a reading of the paper's target (:func:`train_hybrid_many`)."""
    if target == "deg2":
        return params
    return replace(params, target_fitness=params.target_fitness * float(np.ptp(t)) ** 2)


def _hybrid_name(name: str, validation: bool) -> str:
    return name + " hybrid (trainlm" + (", val. stop)" if validation else ")")


def _trainlm_from_stage(
    x, t, n_hidden: int, de_nets: list, rngs, lm: LMParams, validation: bool, name: str
) -> list[BPNet]:
    """``trainlm`` (:func:`train_lm_many`) from each DE stage's best individual ``de_nets``, with a
    ``dividerand`` split drawn from each run's generator if ``validation``; ``info`` keeps the stage's
    ``de_generations``, ``de_fitness``, ``de_theta``, ``de_history`` and the time includes the stage's."""
    theta0 = np.stack([n.theta for n in de_nets])
    splits = [dividerand(len(x), g) for g in rngs] if validation else None
    nets = train_lm_many(
        x, t, n_hidden, theta0, de_nets[0].x_scale, de_nets[0].t_scale, "logsig", lm, splits, name
    )
    for net, de in zip(nets, de_nets):
        net.info.update(
            de_generations=de.info["generations"],
            de_fitness=de.info["fitness"],
            de_theta=de.theta,
            de_history=de.history,
        )
        net.train_time_s += de.train_time_s
    return nets


def train_hybrid_many(
    x,
    t,
    n_hidden: int,
    params: DEParams,
    rngs,
    lm: LMParams = LMParams(),
    validation: bool = False,
    target: Literal["deg2", "normalised"] = "normalised",
) -> list[BPNet]:
    """DE / ADE-initialised BP (paper A, second reading): the DE stage of :func:`train_de_many` with the
    paper's settings, then ``trainlm`` on the same net (logsig, [0, 1] scaling) from the stage's best
    individual (:func:`train_lm_many`; with ``validation`` on a ``dividerand`` 70/15/15 split drawn from
    the run's generator after the DE stage).

    ``target`` says how the paper's stopping value ``params.target_fitness`` is read: ``'deg2'`` (a sum of
    squares in deg^2, never reached) or ``'normalised'`` (a sum of squares of the [0, 1]-normalised
    errors, i.e. ``target_fitness span^2`` in deg^2: reached early, the DE stage then only picks initial
    weights).  ``info`` keeps the stage's ``de_generations``, ``de_fitness`` (deg^2), ``de_theta``."""
    check_choice("target", target, ("deg2", "normalised"))
    x, t = _check_xy(x, t, n_hidden)
    rngs = _rngs(rngs)
    de_nets, _ = train_de_many(x, t, n_hidden, _stage(params, t, target), rngs)
    name = _hybrid_name("ADE-BP" if params.adaptive else "DE-BP", validation)
    return _trainlm_from_stage(x, t, n_hidden, de_nets, rngs, lm, validation, name)
