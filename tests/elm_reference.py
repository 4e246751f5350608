"""Plain-numpy reference of the ELM back-tuning (the implementation navlib used before its loop was
compiled with numba), for tests and benchmarks only: the compiled path must agree with it up to
rounding, and the benchmark reports the speed ratio."""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import replace
from unittest.mock import patch

import numpy as np
from scipy.special import expit

from navlib.methods import elm


def act(name: str, z: np.ndarray) -> np.ndarray:
    return expit(z) if name == "sigmoid" else np.tanh(z)


def act_prime(name: str, a: np.ndarray) -> np.ndarray:
    return a * (1.0 - a) if name == "sigmoid" else 1.0 - a * a


def loss(w, b, beta, X, T, name) -> float:
    r = act(name, X @ w + b) @ beta - T
    return float(np.mean(r * r))


def loss_grad(w, b, beta, X, T, name):
    a2 = act(name, X @ w + b)
    r = a2 @ beta - T
    e = float(np.mean(r * r))
    d3 = (2.0 / r.size) * r
    d2 = (d3 @ beta.T) * act_prime(name, a2)
    return e, X.T @ d2, d2.sum(axis=0), a2.T @ d3


def back_tune(
    w, b, beta, X, T, name, steps: int, step: float, max_halvings: int = 40, armijo: float = 1e-4
):
    """Returns (w, b, beta, losses, next step), as navlib's ``_back_tune``."""
    w, b, beta = w.copy(), b.copy(), beta.copy()
    e, gw, gb, gbeta = loss_grad(w, b, beta, X, T, name)
    losses = [e]
    for _ in range(steps):
        g2 = float(np.sum(gw * gw) + np.sum(gb * gb) + np.sum(gbeta * gbeta))
        if g2 == 0.0:
            break
        for _ in range(max_halvings):
            w1, b1, beta1 = w - step * gw, b - step * gb, beta - step * gbeta
            new = loss(w1, b1, beta1, X, T, name)
            if new <= e - armijo * step * g2 and new < e:
                break
            step *= 0.5
        else:
            break
        w, b, beta = w1, b1, beta1
        e, gw, gb, gbeta = loss_grad(w, b, beta, X, T, name)
        losses.append(e)
        step *= 2.0
    return w, b, beta, losses, step


def back_tune_model(
    model, X, T, steps: int, step: float, max_halvings: int = 40, armijo: float = 1e-4
):
    """Drop-in for ``navlib.methods.elm._back_tune`` (model in, (model, losses, step) out)."""
    w, b, beta, losses, step = back_tune(
        model.w, model.b, model.beta, X, T, model.activation, steps, step, max_halvings, armijo
    )
    return replace(model, w=w, b=b, beta=beta), losses, step


@contextmanager
def numpy_reference():
    """Run navlib's ELM code with this numpy reference in place of the compiled kernels."""
    with (
        patch.object(elm, "_back_tune", back_tune_model),
        patch.object(elm, "_loss", loss),
        patch.object(elm, "_loss_grad", loss_grad),
    ):
        yield
