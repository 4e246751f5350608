"""Extreme learning machine (ELM) and the patent's point-incremental ELM with autonomous back-tuning.

Network (patent B, Fig. 1; Huang, Zhu & Siew, "Extreme learning machine: theory and applications",
Neurocomputing 70 (2006) 489-501): one hidden layer of L nodes, no output bias,

    a1 = X                         (N x d, the normalised inputs)
    Z  = a1 W + 1 b^T              (W: d x L input weights w_ij, b: L hidden biases b_i)
    a2 = H = g(Z)                  (N x L hidden-layer output matrix, g = sigmoid)
    a3 = Y = H beta                (beta: L x m output weights beta_ki; linear output, no bias)

ELM stage (patent s701 / eqs (3)-(7); Huang 2006): W and b are drawn at random and not adjusted, and
the output weights are the minimum-norm least-squares solution of H beta = T,

    beta = H^+ T                   (H^+ the Moore-Penrose generalised inverse; see
                                    :func:`solve_output_weights` for how it is computed).

Back-tuning stage (patent s702 / s1001-s1104, "borrowing deep learning's backward fine-tuning"): from the
ELM solution, the residual err = Y - T is propagated back through the 3-layer net and *all* weights
(W, b, beta) are moved down the gradient of the training loss.  Our loss is the mean squared error over
the N samples and m outputs (the patent's loss equation is lost in the OCR),

    E = 1/(N m) sum_n sum_k (Y_nk - T_nk)^2,

with the layer residuals ("deltas") and gradients

    delta3 = 2/(N m) (Y - T)                       (N x m, output layer)
    delta2 = (delta3 beta^T) * g'(Z)               (N x L, hidden layer; sigmoid: g' = a2 (1 - a2))
    dE/dbeta = a2^T delta3,   dE/dW = a1^T delta2,   dE/db = 1^T delta2.

The patent gives no learning rate.  Each gradient step uses a backtracking (Armijo) line search: the
step is accepted only if the loss drops by at least 1e-4 * step * ||grad||^2, otherwise it is halved;
so back-tuning can never increase the training loss (a property of the code, tested, not of a lucky
learning rate).

Speed: the loss, its gradients and the whole line-search loop are compiled with numba
(:mod:`navlib.methods.jit`, ``cache=True``: compiled once, then loaded from ``__pycache__``).  The kernels
evaluate the numpy expressions above in numpy's order (the same BLAS call for every matrix product,
numpy's pairwise sums, no fast-math), so they agree with the plain-numpy loop up to rounding; with the
sigmoid and contiguous inputs they give the same bits on our machine.  The plain ELM (:func:`fit_elm`, :meth:`ELMModel.loss`) stays in numpy.

Point-incremental scheme (patent "fourth step" and Fig. 2): the hidden layer starts with one node and
grows by one random node per ELM stage; ELM solve and back-tuning alternate; nodes whose output weight
is negligible contribute little and are pruned; training stops when the loss is below the goal or the
iteration count exceeds k.  See :func:`fit_incremental_elm` for the choices we made where the patent is
ambiguous.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
import pandas as pd
from scipy.special import expit

from ..errors import InputError, check_choice, check_param
from .arrays import as_2d
from .jit import elm_back_tune, elm_loss, elm_loss_grad
from .seeding import generator

__all__ = [
    "ACTIVATIONS",
    "SCHEDULES",
    "NodeDraw",
    "ELMParams",
    "ELMModel",
    "IncrementalELMParams",
    "random_nodes",
    "solve_output_weights",
    "fit_elm",
    "loss_and_gradients",
    "back_tune",
    "prune_nodes",
    "fit_incremental_elm",
]

ACTIVATIONS = ("sigmoid", "tanh")
SCHEDULES = ("alternate", "odd_nodes")


def _act(name: str, z: np.ndarray) -> np.ndarray:
    return expit(z) if name == "sigmoid" else np.tanh(z)


def _act_prime(name: str, a: np.ndarray) -> np.ndarray:
    """Derivative g'(z) written with the activation a = g(z)."""
    return a * (1.0 - a) if name == "sigmoid" else 1.0 - a * a


def _check_activation(name: str) -> None:
    if name not in ACTIVATIONS:
        raise InputError(f"parameter activation={name!r}: must be one of {', '.join(ACTIVATIONS)}")


def _check_seed(seed) -> None:
    if seed is not None:
        check_param("seed", seed, lo=0, integer=True)


def _as_rng(rng) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        return np.random.default_rng()
    _check_seed(rng)
    return generator(int(rng))


def _xt(x, t) -> tuple[np.ndarray, np.ndarray, bool]:
    X, T = as_2d(x, "x"), as_2d(t, "t")
    if X.shape[0] != T.shape[0]:
        raise InputError(f"x has {X.shape[0]} samples but t has {T.shape[0]}")
    return X, T, np.ndim(t) == 1


# --------------------------------------------------------------------------------------------------
# Plain ELM


@dataclass(frozen=True)
class NodeDraw:
    """How hidden nodes are drawn, shared by :class:`ELMParams` and :class:`IncrementalELMParams`:
    ``activation``, input weights w_ij ~ U(-weight_range, weight_range), hidden biases
    b_i ~ U(-bias_range, bias_range) (Huang 2006 uses 1 and 1 for inputs normalised to [0, 1]; a wider
    range gives steeper, more local sigmoids and a better-conditioned H), and ``seed`` (a run index of
    :mod:`navlib.methods.seeding`; ``None``: unseeded)."""

    activation: Literal["sigmoid", "tanh"] = "sigmoid"
    weight_range: float = 1.0
    bias_range: float = 1.0
    seed: int | None = 0

    def __post_init__(self):
        _check_activation(self.activation)
        check_param("weight_range", self.weight_range, lo=0, lo_open=True)
        check_param("bias_range", self.bias_range, lo=0)
        _check_seed(self.seed)


@dataclass(frozen=True)
class ELMParams(NodeDraw):
    """Plain ELM (Huang 2006; patent stage s701): ``n_hidden`` random nodes (drawn as :class:`NodeDraw`)."""

    n_hidden: int = 10

    def __post_init__(self):
        check_param("n_hidden", self.n_hidden, lo=1, integer=True)
        super().__post_init__()


@dataclass
class ELMModel:
    """A single-hidden-layer network without output bias: ``y = g(x W + b) beta``.

    ``w`` is (d, L), ``b`` (L,), ``beta`` (L, m).  ``squeeze_output``: :meth:`predict` returns a 1-D
    array (the model was fitted on a 1-D target)."""

    w: np.ndarray
    b: np.ndarray
    beta: np.ndarray
    activation: str = "sigmoid"
    squeeze_output: bool = True

    @property
    def n_hidden(self) -> int:
        return int(self.b.size)

    @property
    def n_inputs(self) -> int:
        return int(self.w.shape[0])

    @property
    def n_outputs(self) -> int:
        return int(self.beta.shape[1])

    @property
    def n_weights(self) -> int:
        """Number of trainable numbers: d L + L + L m."""
        return int(self.w.size + self.b.size + self.beta.size)

    def hidden(self, x) -> np.ndarray:
        """Hidden-layer output matrix H = g(x W + b), shape (N, L)."""
        X = as_2d(x, "x")
        if X.shape[1] != self.n_inputs:
            raise InputError(f"x: model has {self.n_inputs} input(s), got {X.shape[1]}")
        return _act(self.activation, X @ self.w + self.b)

    def predict(self, x) -> np.ndarray:
        """Network output H beta; 1-D when the model was fitted on a 1-D target."""
        y = self.hidden(x) @ self.beta
        return y[:, 0] if self.squeeze_output and y.shape[1] == 1 else y

    def loss(self, x, t) -> float:
        """Mean squared error E = mean((H beta - T)^2) over samples and outputs."""
        X, T, _ = _xt(x, t)
        r = self.hidden(X) @ self.beta - T
        return float(np.mean(r * r))

    def copy(self) -> "ELMModel":
        return replace(self, w=self.w.copy(), b=self.b.copy(), beta=self.beta.copy())


def random_nodes(
    n_inputs: int, n_nodes: int, rng, *, weight_range: float = 1.0, bias_range: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Random input weights W ~ U(-weight_range, weight_range), shape (n_inputs, n_nodes), and biases
    b ~ U(-bias_range, bias_range), shape (n_nodes,) (patent s701: "randomly initialise w_ij and b_i").
    W is drawn before b, column by column in node order."""
    rng = _as_rng(rng)
    w = rng.uniform(-weight_range, weight_range, size=(n_nodes, n_inputs)).T.copy()
    b = rng.uniform(-bias_range, bias_range, size=n_nodes)
    return w, b


def solve_output_weights(h: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Minimum-norm least-squares output weights beta = H^+ T (patent eq. (7); Huang 2006, Sec. 2-3).

    Computed with ``numpy.linalg.lstsq`` (LAPACK gelsd, SVD; singular values below eps max(N, L) times
    the largest count as zero), which returns the minimum-norm solution H^+ T without forming H^+.
    With random sigmoid nodes H becomes very ill-conditioned as L grows (cond(H) > 1e14 beyond about
    15 nodes on a 1-D input) and ``pinv(H) @ T`` then lost up to two orders of magnitude in the
    residual on a synthetic compass sweep, where ``lstsq`` did not.  Beyond cond(H) ~ 1/eps the
    truncation makes the residual depend on rounding, so adding a node can raise the loss by a hair."""
    beta, *_ = np.linalg.lstsq(h, t, rcond=None)
    return beta


def fit_elm(
    x, t, params: ELMParams | None = None, *, n_hidden: int | None = None, rng=None
) -> ELMModel:
    """Fit a plain ELM: random W, b (not trained), then beta = H^+ T (:func:`solve_output_weights`).

    ``x``: (N,) or (N, d) normalised inputs; ``t``: (N,) or (N, m) targets.  ``n_hidden`` overrides
    ``params.n_hidden``; ``rng`` (a ``numpy.random.Generator`` or an int seed) overrides
    ``params.seed`` — handy for loops over seeds and node counts.

    With n_hidden = N distinct samples H is square and (generically) invertible, so the ELM interpolates
    the training data exactly (Huang 2006, Theorem 2.1)."""
    p = params or ELMParams()
    if n_hidden is not None:
        p = replace(p, n_hidden=n_hidden)
    X, T, squeeze = _xt(x, t)
    gen = _as_rng(p.seed if rng is None else rng)
    w, b = random_nodes(
        X.shape[1], int(p.n_hidden), gen, weight_range=p.weight_range, bias_range=p.bias_range
    )
    H = _act(p.activation, X @ w + b)
    return ELMModel(
        w=w, b=b, beta=solve_output_weights(H, T), activation=p.activation, squeeze_output=squeeze
    )


# --------------------------------------------------------------------------------------------------
# Back-tuning (patent s702, s1001-s1104)


def loss_and_gradients(model: ELMModel, x, t) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Training loss E = mean((Y - T)^2) and its analytic gradients (dE/dW, dE/db, dE/dbeta).

    delta3 = 2 (Y - T)/(N m); delta2 = (delta3 beta^T) * g'(Z);
    dE/dbeta = a2^T delta3; dE/dW = a1^T delta2; dE/db = sum_n delta2.

    Computed by a compiled kernel (numba), equal to the numpy expressions up to rounding."""
    X, T, _ = _xt(x, t)
    return _loss_grad(model.w, model.b, model.beta, X, T, model.activation)


def _f64(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def _loss(w, b, beta, X, T, act) -> float:
    """Training MSE of the net (W, b, beta) on (X, T) (compiled: :func:`navlib.methods.jit.elm_loss`)."""
    return float(elm_loss(_f64(w), _f64(b), _f64(beta), _f64(X), _f64(T), act == "sigmoid"))


def _loss_grad(w, b, beta, X, T, act):
    """Loss and gradients (dE/dW, dE/db, dE/dbeta) as :func:`loss_and_gradients` (compiled:
    :func:`navlib.methods.jit.elm_loss_grad`)."""
    loss, gw, gb, gbeta = elm_loss_grad(
        _f64(w), _f64(b), _f64(beta), _f64(X), _f64(T), act == "sigmoid"
    )
    return float(loss), gw, gb, gbeta


def _back_tune(
    model: ELMModel, X, T, steps: int, step: float, max_halvings: int = 40, armijo: float = 1e-4
) -> tuple[ELMModel, list[float], float]:
    """Gradient descent with backtracking; returns the tuned copy, the loss after each accepted step
    (the first entry is the starting loss) and the trial step for the next call.  The whole loop runs
    in one compiled call (:func:`navlib.methods.jit.elm_back_tune`)."""
    w, b, beta, losses, step = elm_back_tune(
        _f64(model.w),
        _f64(model.b),
        _f64(model.beta),
        _f64(X),
        _f64(T),
        model.activation == "sigmoid",
        int(steps),
        float(step),
        int(max_halvings),
        float(armijo),
    )
    return replace(model, w=w, b=b, beta=beta), losses.tolist(), float(step)


def back_tune(
    model: ELMModel, x, t, *, steps: int = 20, lr: float = 0.1, max_halvings: int = 40
) -> tuple[ELMModel, np.ndarray]:
    """Back-tune all weights (W, b, beta) of ``model`` by ``steps`` gradient-descent steps on the
    training MSE (patent s1004/s1104; gradients in :func:`loss_and_gradients`).

    ``lr`` is the first trial step; each step is halved (at most ``max_halvings`` times) until the Armijo
    condition E_new <= E - 1e-4 step ||grad||^2 holds, and doubled after an accepted step.  A step that
    does not decrease the loss is never taken, so the returned losses are strictly decreasing.
    Returns a new model (``model`` is not modified) and the losses: the starting loss, then one per
    accepted step (fewer than ``steps`` + 1 if the search stalls).

    The loop runs in one compiled call (numba; the module docstring says how it matches numpy).  A
    trial step too small to change any weight is rejected without evaluating the loss (it would give
    exactly the current loss), so a stalled search costs next to nothing.

    Observed on the compass sweeps: tuning lowers the loss a lot for 1-3 nodes, but beyond that the
    least-squares beta is large (``|beta|`` ~ 1e2..1e9 as cond(H) grows), the loss surface is extremely
    curved along W and b, and the accepted steps become tiny: back-tuning then changes little."""
    check_param("steps", steps, lo=0, integer=True)
    check_param("lr", lr, lo=0, lo_open=True)
    check_param("max_halvings", max_halvings, lo=1, integer=True)
    X, T, _ = _xt(x, t)
    tuned, losses, _ = _back_tune(model, X, T, int(steps), float(lr), int(max_halvings))
    return tuned, np.asarray(losses)


# --------------------------------------------------------------------------------------------------
# Pruning


def prune_nodes(model: ELMModel, tol: float) -> tuple[ELMModel, np.ndarray]:
    """Remove hidden nodes whose output weights are negligible: ``max_k |beta_jk| <= tol``.

    Since ``|g| <= 1`` for sigmoid and tanh, such a node changes the (normalised) output by at most ``tol``
    (patent, Fig. 1 text: "neurons whose output weight is small have little influence on the output;
    removing these useless neurons ...").  At least one node (the largest ``|beta|``) is always kept.
    Returns the pruned copy (beta not re-solved: the caller decides) and the removed node indices."""
    check_param("tol", tol, lo=0)
    size = np.max(np.abs(model.beta), axis=1)
    drop = size <= tol
    if drop.all():
        drop[int(np.argmax(size))] = False
    keep = ~drop
    pruned = replace(
        model, w=model.w[:, keep].copy(), b=model.b[keep].copy(), beta=model.beta[keep].copy()
    )
    return pruned, np.flatnonzero(drop)


# --------------------------------------------------------------------------------------------------
# Point-incremental ELM with autonomous back-tuning


@dataclass(frozen=True)
class IncrementalELMParams(NodeDraw):
    """Parameters of :func:`fit_incremental_elm` (patent B, Fig. 2 and "fourth step").

    - ``max_nodes``: cap on the hidden-node count (growth stops there; ELM stages then only re-solve).
    - ``loss_goal``: stop when the training MSE (normalised units) is <= this (patent: "expected value").
    - ``max_iter``: stop after this many iterations (patent: "iteration count exceeds k").
    - ``lr``: first trial step of the back-tuning line search (then adapted, see :func:`back_tune`).
    - ``tune_steps``: gradient steps per back-tuning stage.
    - ``prune_tol``: prune nodes with ``max |beta_j| <= prune_tol`` after each ELM solve (0: only exact
      zeros; the bound on a pruned node's contribution to the normalised output).
    - ``schedule``: which stage runs at iteration n (the patent is ambiguous, see
      :func:`fit_incremental_elm`): ``'alternate'`` (default) or ``'odd_nodes'``.
    - ``activation``, ``weight_range``, ``bias_range``, ``seed``: as in :class:`NodeDraw`."""

    max_nodes: int = 30
    loss_goal: float = 1e-7
    max_iter: int = 200
    lr: float = 0.1
    tune_steps: int = 50
    prune_tol: float = 1e-4
    schedule: Literal["alternate", "odd_nodes"] = "alternate"

    def __post_init__(self):
        check_param("max_nodes", self.max_nodes, lo=1, integer=True)
        check_param("loss_goal", self.loss_goal, lo=0)
        check_param("max_iter", self.max_iter, lo=1, integer=True)
        check_param("lr", self.lr, lo=0, lo_open=True)
        check_param("tune_steps", self.tune_steps, lo=0, integer=True)
        check_param("prune_tol", self.prune_tol, lo=0)
        check_choice("schedule", self.schedule, SCHEDULES)
        super().__post_init__()


HISTORY_COLUMNS = ["iteration", "stage", "n_nodes", "loss", "val_loss"]


@dataclass
class _Recorder:
    X_val: np.ndarray | None
    T_val: np.ndarray | None
    rows: list = field(default_factory=list)

    def add(self, it: int, stage: str, model: ELMModel, loss: float) -> None:
        val = np.nan
        if self.X_val is not None:
            val = _loss(model.w, model.b, model.beta, self.X_val, self.T_val, model.activation)
        self.rows.append((it, stage, model.n_hidden, loss, val))

    def frame(self) -> pd.DataFrame:
        return pd.DataFrame(self.rows, columns=HISTORY_COLUMNS)


def fit_incremental_elm(
    x, t, params: IncrementalELMParams | None = None, *, rng=None, x_val=None, t_val=None
) -> tuple[ELMModel, pd.DataFrame]:
    """Point-incremental ELM with autonomous back-tuning (patent B).

    Iterations n = 1, 2, ... run stages on the current network:

    - ``'elm'``: add one random node (unless ``max_nodes`` is reached; the existing, possibly tuned,
      nodes are kept) and re-solve all output weights, beta = H^+ T.  Adding a column to a
      least-squares problem cannot raise its optimum, so this stage does not raise the loss (up to
      rounding once cond(H) nears 1/eps, see :func:`solve_output_weights`).
    - ``'prune'`` (right after an ELM solve, only when some node has ``max |beta_j| <= prune_tol``):
      drop those nodes and re-solve beta.  This may raise the loss slightly (by design, bounded by the
      dropped contributions before the re-solve).
    - ``'tune'``: ``tune_steps`` monotone gradient steps on W, b and beta (:func:`back_tune`); the
      line-search step carries over from one tuning stage to the next.

    Speed: the tuning loop is compiled (see :func:`back_tune`), and an ELM stage whose nodes are
    exactly those of one of the last two solves (tuning stalled at ``max_nodes``) reuses that solve
    instead of repeating it; neither changes a result.

    Which stage runs when (``params.schedule``) — the patent's text disagrees with itself:

    - ``'alternate'`` (default, the claims: "when n is odd run stage one (s701), when n is even run
      stage two (s702)"): odd n -> ELM (+ prune), even n -> tune.  The claims also use n for the
      sample count; we read this n as the iteration counter (the only reading that alternates).
    - ``'odd_nodes'`` (the Fig. 2 description: "if the node count l is odd, back-derive and tune"):
      every n -> ELM (+ prune), then tune if the node count is odd.

    The "fourth step" of the description (ELM train, back-tune, then nodes and iterations + 1, repeat)
    gives the same sequence of stages as ``'alternate'``, with k counting ELM+tune pairs: use
    ``max_iter = 2 k`` for that reading.

    Stop after the iteration in which the training MSE first is <= ``loss_goal``, or after
    ``max_iter`` iterations (patent: "if smaller than the expected value, or the iteration count exceeds
    the preset k, training ends").  The returned model is the final network (the loss never rises
    except in prune stages, so it is also the best apart from pruning).

    ``rng`` (Generator or int) overrides ``params.seed``.  ``x_val``/``t_val`` (optional) are evaluated
    after every stage into the history's ``val_loss`` column (NaN without them) — for plots of test
    error against node count.

    Returns ``(model, history)``; history has one row per stage: ``iteration``, ``stage``
    ('elm'/'prune'/'tune'), ``n_nodes`` and ``loss`` (training MSE) after the stage, ``val_loss``.
    """
    p = params or IncrementalELMParams()
    X, T, squeeze = _xt(x, t)
    if (x_val is None) != (t_val is None):
        raise InputError("give both x_val and t_val, or neither")
    Xv = Tv = None
    if x_val is not None:
        Xv, Tv, _ = _xt(x_val, t_val)
        if Xv.shape[1] != X.shape[1] or Tv.shape[1] != T.shape[1]:
            raise InputError("x_val/t_val: column counts differ from x/t")
    gen = _as_rng(p.seed if rng is None else rng)
    rec = _Recorder(Xv, Tv)
    d, m = X.shape[1], T.shape[1]
    model = ELMModel(
        w=np.empty((d, 0)),
        b=np.empty(0),
        beta=np.empty((0, m)),
        activation=p.activation,
        squeeze_output=squeeze,
    )
    step = float(p.lr)
    solved: list = []  # the last two (w, b, beta) of solve()

    def solve(w: np.ndarray, b: np.ndarray) -> np.ndarray:
        """beta = H^+ T for the hidden nodes (w, b).  Once tuning has stalled at the node cap, the ELM
        stages re-solve the very same nodes again and again: the solve is deterministic, so the last
        result for these nodes is reused (bit for bit what solving again gives)."""
        for w0, b0, beta0 in solved:
            if np.array_equal(w0, w) and np.array_equal(b0, b):
                return beta0.copy()
        beta = solve_output_weights(_act(p.activation, X @ w + b), T)
        solved[:] = [*solved[-1:], (w.copy(), b.copy(), beta.copy())]
        return beta

    def elm_stage(it: int, model: ELMModel) -> tuple[ELMModel, float]:
        if model.n_hidden < p.max_nodes:
            w1, b1 = random_nodes(d, 1, gen, weight_range=p.weight_range, bias_range=p.bias_range)
            model = replace(model, w=np.hstack([model.w, w1]), b=np.concatenate([model.b, b1]))
        model = replace(model, beta=solve(model.w, model.b))
        loss = _loss(model.w, model.b, model.beta, X, T, p.activation)
        rec.add(it, "elm", model, loss)
        if np.any(np.max(np.abs(model.beta), axis=1) <= p.prune_tol):  # some node is negligible
            pruned, removed = prune_nodes(model, p.prune_tol)
            if removed.size:
                model = replace(pruned, beta=solve(pruned.w, pruned.b))
                loss = _loss(model.w, model.b, model.beta, X, T, p.activation)
                rec.add(it, "prune", model, loss)
        return model, loss

    def tune_stage(it: int, model: ELMModel, step: float) -> tuple[ELMModel, float, float]:
        model, losses, step = _back_tune(model, X, T, int(p.tune_steps), step)
        rec.add(it, "tune", model, losses[-1])
        return model, losses[-1], step

    for it in range(1, int(p.max_iter) + 1):
        if p.schedule == "alternate":
            if it % 2 == 1:
                model, loss = elm_stage(it, model)
            else:
                model, loss, step = tune_stage(it, model, step)
        else:
            model, loss = elm_stage(it, model)
            if model.n_hidden % 2 == 1:
                model, loss, step = tune_stage(it, model, step)
        if loss <= p.loss_goal:
            break
    return model, rec.frame()
