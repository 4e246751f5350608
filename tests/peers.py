"""Peer libraries built from our objects, for tests and benchmarks only (the peers are not library
dependencies): a ``simpful`` Sugeno system with the same rules as a :class:`navlib.methods.subclust.SugenoFIS`,
and paper A's net trained by torch autograd and torch's default Adam (the reference of our Adam trainer)."""

from __future__ import annotations

import numpy as np
import torch
from simpful import FuzzySet, FuzzySystem, Gaussian_MF, LinguisticVariable


def simpful_system(fis):
    """``simpful`` system equal to ``fis``: one Gaussian set per rule and input, product AND, first-order
    Sugeno outputs. Returns ``(system, input names)``."""
    fs = FuzzySystem(show_banner=False, operators=["AND_PRODUCT"])
    R, n = fis.centers.shape
    names = [f"x{i}" for i in range(n)]
    for i, nm in enumerate(names):
        sets = [
            FuzzySet(
                function=Gaussian_MF(mu=float(fis.centers[r, i]), sigma=float(fis.sigmas[r, i])),
                term=f"m{r}",
            )
            for r in range(R)
        ]
        fs.add_linguistic_variable(nm, LinguisticVariable(sets, universe_of_discourse=[-1e4, 1e4]))
    rules = []
    for r in range(R):
        terms = "+".join(f"{float(fis.consequents[r, i])!r}*{names[i]}" for i in range(n))
        fs.set_output_function(f"f{r}", f"{terms}+{float(fis.consequents[r, -1])!r}")
        rules.append("IF " + " AND ".join(f"({nm} IS m{r})" for nm in names) + f" THEN (y IS f{r})")
    fs.add_rules(rules)
    return fs, names


def autograd_adam(theta0, xn, tn, m, epochs, lr):
    """The reference: the same nets trained by autograd back-propagation and torch's default Adam."""
    th = torch.tensor(theta0, dtype=torch.float64, requires_grad=True)
    X, T = torch.tensor(xn), torch.tensor(tn)
    opt = torch.optim.Adam([th], lr=lr)
    history = np.empty((theta0.shape[0], epochs))
    for k in range(epochs):
        opt.zero_grad()
        h = torch.sigmoid(X[None, :, None] * th[:, None, :m] + th[:, None, m : 2 * m])
        out = torch.einsum("pnm,pm->pn", h, th[:, 2 * m : 3 * m]) + th[:, 3 * m : 3 * m + 1]
        loss = torch.mean((out - T) ** 2, dim=1)
        loss.sum().backward()
        opt.step()
        history[:, k] = loss.detach().numpy()
    return th.detach().numpy(), history
