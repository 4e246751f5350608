"""Huang's point-incremental extreme learning machine (I-ELM), the baseline of patent B's iterations claim.

Huang, Chen & Siew, "Universal approximation using incremental constructive feedforward networks with
random hidden nodes", IEEE Trans. Neural Networks 17 (2006) 879-892, Sec. III (algorithm "I-ELM"): the
network ``y = sum_j beta_j g(x w_j + b_j)`` (one hidden layer, no output bias, as
:class:`navlib.methods.elm.ELMModel`) grows by one random hidden node per iteration, and only the new
node's output weight is fitted, to the current residual; the earlier nodes and output weights stay frozen.
With the residual ``e_0 = T`` and, at iteration L, the new node's output column ``h_L = g(X w_L + b_L)``::

    beta_L = <e_{L-1}, h_L> / <h_L, h_L>    (per output column: the 1-D least-squares fit
                                             of the residual on h_L, Huang et al. eq. (8))
    e_L    = e_{L-1} - h_L beta_L,

so ``||e_L|| <= ||e_{L-1}||`` (the fit of one column can only lower the residual; Huang et al. Lemma 1)
and the training error never rises.  Training stops when the training MSE ``mean(e_L^2)`` is at most the
goal or after ``max_nodes`` iterations (Huang et al.: ``L < L_max`` and ``||E|| > epsilon``).

Nodes are drawn one at a time by :func:`navlib.methods.elm.random_nodes` (w_L before b_L), the draw of the
patent's own incremental scheme (:func:`navlib.methods.elm.fit_incremental_elm`), so with the same
generator both methods see the same random nodes in the same order.  Patent B (description, Fig. 1
paragraph) compares its back-tuned scheme with this one: "reduces the iterations and guarantees the
training accuracy".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.special import expit

from ..errors import InputError, check_param
from .arrays import as_2d
from .elm import ELMModel, NodeDraw, random_nodes
from .seeding import generator

__all__ = ["IELMParams", "IELM_HISTORY_COLUMNS", "fit_ielm", "first_nodes"]

#: The history's columns: one row per iteration (node added).
IELM_HISTORY_COLUMNS = ["iteration", "n_nodes", "loss", "val_loss"]


@dataclass(frozen=True)
class IELMParams(NodeDraw):
    """Parameters of :func:`fit_ielm`: ``max_nodes`` (Huang's L_max: the iteration cap, one node per
    iteration), ``loss_goal`` (stop once the training MSE, in the units of the targets, is <= this; 0:
    run to the cap), and the node draw of :class:`navlib.methods.elm.NodeDraw` (``activation``,
    ``weight_range``, ``bias_range``, ``seed``)."""

    max_nodes: int = 100
    loss_goal: float = 0.0

    def __post_init__(self):
        check_param("max_nodes", self.max_nodes, lo=1, integer=True)
        check_param("loss_goal", self.loss_goal, lo=0)
        super().__post_init__()


def _act(name: str, z: np.ndarray) -> np.ndarray:
    return expit(z) if name == "sigmoid" else np.tanh(z)


def fit_ielm(
    x, t, params: IELMParams | None = None, *, rng=None, x_val=None, t_val=None
) -> tuple[ELMModel, pd.DataFrame]:
    """Fit Huang's I-ELM (module docstring): one random node per iteration, only its output weight
    fitted to the residual, earlier nodes frozen.

    ``x``: (N,) or (N, d) normalised inputs; ``t``: (N,) or (N, m) targets; ``rng`` (a Generator or an
    int run index of :mod:`navlib.methods.seeding`) overrides ``params.seed``.  ``x_val``/``t_val``
    (optional) are scored after every iteration into the history's ``val_loss`` (NaN without them).

    Returns ``(model, history)``: the final network (:class:`navlib.methods.elm.ELMModel`; its first
    ``n`` nodes are exactly the network the I-ELM has after ``n`` iterations, since earlier output
    weights never change) and one history row per iteration: ``iteration`` (= ``n_nodes``), the training
    MSE ``loss`` after it and ``val_loss``."""
    p = params or IELMParams()
    X, T = as_2d(x, "x"), as_2d(t, "t")
    if X.shape[0] != T.shape[0]:
        raise InputError(f"x has {X.shape[0]} samples but t has {T.shape[0]}")
    if (x_val is None) != (t_val is None):
        raise InputError("give both x_val and t_val, or neither")
    Xv = Ev = None
    if x_val is not None:
        Xv, Ev = as_2d(x_val, "x_val"), as_2d(t_val, "t_val").copy()
        if Xv.shape[1] != X.shape[1] or Ev.shape[1] != T.shape[1] or Xv.shape[0] != Ev.shape[0]:
            raise InputError("x_val/t_val: shapes do not match x/t")
    if rng is None:
        gen = generator(int(p.seed)) if p.seed is not None else np.random.default_rng()
    elif isinstance(rng, np.random.Generator):
        gen = rng
    else:
        check_param("rng", rng, lo=0, integer=True)
        gen = generator(int(rng))
    d, m = X.shape[1], T.shape[1]
    e = T.copy()  # the residual e_0 = T
    ws, bs, betas, rows = [], [], [], []
    for n in range(1, int(p.max_nodes) + 1):
        w1, b1 = random_nodes(d, 1, gen, weight_range=p.weight_range, bias_range=p.bias_range)
        h = _act(p.activation, X @ w1 + b1)[:, 0]
        hh = float(h @ h)
        beta = (h @ e) / hh if hh > 0.0 else np.zeros(m)  # (m,): the 1-D least-squares fit
        e -= np.outer(h, beta)
        loss = float(np.mean(e * e))
        val = np.nan
        if Xv is not None:
            Ev -= np.outer(_act(p.activation, Xv @ w1 + b1)[:, 0], beta)
            val = float(np.mean(Ev * Ev))
        ws.append(w1)
        bs.append(b1)
        betas.append(beta)
        rows.append((n, n, loss, val))
        if loss <= p.loss_goal:
            break
    model = ELMModel(
        w=np.hstack(ws),
        b=np.concatenate(bs),
        beta=np.vstack(betas).reshape(len(betas), m),
        activation=p.activation,
        squeeze_output=np.ndim(t) == 1,
    )
    return model, pd.DataFrame(rows, columns=IELM_HISTORY_COLUMNS)


def first_nodes(model: ELMModel, n: int) -> ELMModel:
    """The I-ELM network after ``n`` iterations: the first ``n`` nodes of ``model`` and their output
    weights (exact, since :func:`fit_ielm` never changes an earlier output weight)."""
    check_param("n", n, lo=1, hi=model.n_hidden, integer=True)
    return ELMModel(
        w=model.w[:, :n].copy(),
        b=model.b[:n].copy(),
        beta=model.beta[:n].copy(),
        activation=model.activation,
        squeeze_output=model.squeeze_output,
    )
