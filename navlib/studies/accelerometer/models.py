"""The models besides the learned ones: the physical baseline (IEEE 1293 coefficient polynomials,
:class:`PolyCompensator`), the simulator's own exact model (:func:`oracle`), the swarm's fitness
(:func:`scm_objective`: the checking RMSE of ``genfis2``'s FIS) and the grid tuner (:func:`grid_search`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...errors import InputError, check_param
from ...methods.subclust import SubclustOptions, SugenoFIS, solve_consequents, subclust, unit_sqdist
from ...sensors.accelerometer import AccelCoefficients, T_REF_C, tumble_coefficients


@dataclass(frozen=True)
class PolyCompensator:
    """IEEE 1293 coefficient drift polynomials in ``dT = T - 55``: ``K(T) = K(55) + p(dT) - p(0)`` for
    ``K0`` (mg), ``K1`` (relative) and ``K2`` (mg/g^2), anchored at the coefficients measured by the 55 degC
    tumble (``ref``: k0, k1, k2).  ``__call__(X)`` maps (T, N) to the 55 degC-equivalent output: solve
    ``N = K0 + K1 (u + K2 u^2/1e6)`` for ``u = 1000 a`` (three fixed-point steps), then
    ``Nc = K0(55) + K1(55) (u + K2(55) u^2/1e6)``."""

    k0: np.ndarray
    k1: np.ndarray
    k2: np.ndarray
    ref: tuple
    reference_c: float = T_REF_C

    def coefficients(self, temperature_c):
        d = np.asarray(temperature_c, float) - self.reference_c
        return tuple(
            r + np.polyval(p, d) - np.polyval(p, 0.0)
            for r, p in zip(self.ref, (self.k0, self.k1, self.k2))
        )

    def __call__(self, X) -> np.ndarray:
        X = np.atleast_2d(np.asarray(X, float))
        k0, k1, k2 = self.coefficients(X[:, 0])
        u = (X[:, 1] - k0) / k1
        for _ in range(3):
            u = (X[:, 1] - k0) / k1 - k2 * u**2 / 1e6
        r0, r1, r2 = self.ref
        return r0 + r1 * (u + r2 * u**2 / 1e6)


def fit_physical(
    df: pd.DataFrame, degree: int = 3, reference_c: float = T_REF_C
) -> PolyCompensator:
    """Fourier coefficients of every tumble in ``df`` (one unit, training temperatures, including the
    reference) and polynomial fits of K0, K1, K2 against the mean sensor temperature of each tumble,
    anchored at the reference tumble's own coefficients."""
    c = tumble_coefficients(df)
    if len(c) < degree + 1:
        raise InputError(
            f"physical model: {len(c)} temperatures, a degree-{degree} fit needs {degree + 1}"
        )
    at_ref = np.isclose(c["set_point_c"], reference_c)
    if not at_ref.any():
        raise InputError(f"physical model: no tumble at the reference {reference_c:g} degC")
    ref = tuple(float(c.loc[at_ref, k].iloc[0]) for k in ("k0_mg", "k1", "k2_mg_g2"))
    d = c["temperature_c"].to_numpy() - reference_c
    return PolyCompensator(
        np.polyfit(d, c["k0_mg"], degree),
        np.polyfit(d, c["k1"], degree),
        np.polyfit(d, c["k2_mg_g2"], degree),
        ref,
        reference_c,
    )


def oracle(coef: AccelCoefficients, reference_c: float = T_REF_C):
    """The simulator's own K0(T), K1(T), K2(T) inverted like :class:`PolyCompensator` (cross-coupling and
    misalignment terms ignored): the best any model of (T, N) can do, up to noise."""

    def f(X):
        X = np.atleast_2d(np.asarray(X, float))
        t = X[:, 0]
        k0, k1, k2 = coef.bias_mg(t), coef.scale_factor(t), coef.second_order_mg_g2(t)
        u = (X[:, 1] - k0) / k1
        for _ in range(3):
            u = (X[:, 1] - k0) / k1 - k2 * u**2 / 1e6
        r = reference_c
        return coef.bias_mg(r) + coef.scale_factor(r) * (
            u + coef.second_order_mg_g2(r) * u**2 / 1e6
        )

    return f


# ------------------------------------------------------------------------------------------- swarm
def scm_objective(Xtr, ytr, Xck, yck, max_rules: int, fallback: float):
    """Fitness of clustering parameters ``[ra, rb/ra]`` for a whole school at once: checking RMSE (mg) of
    ``genfis2``'s FIS; ``fallback`` (the worst sensible value) where the radius yields more than
    ``max_rules`` rules."""
    d2 = unit_sqdist(np.column_stack([Xtr, ytr]))  # the same data at every candidate: once

    def obj(Z):
        out = np.empty(len(Z))
        for i, (ra, sq) in enumerate(Z):
            fis = _genfis2_capped(Xtr, ytr, ra, sq, max_rules, d2)
            out[i] = fallback if fis is None else np.sqrt(np.mean((fis(Xck) - yck) ** 2))
        return out

    return obj


def _genfis2_capped(X, y, ra, squash, max_rules, sqdist=None):
    C, sig = subclust(
        np.column_stack([X, y]),
        ra,
        options=SubclustOptions(squash=float(squash)),
        max_centers=max_rules,
        sqdist=sqdist,
    )
    if len(C) > max_rules:
        return None
    n = X.shape[1]
    centers = C[:, :n]
    sigmas = np.broadcast_to(sig[:n], centers.shape).copy()
    return SugenoFIS(centers, sigmas, solve_consequents(X, y, centers, sigmas))


def grid_search(objective, radius_bounds, squash_values, budget: int):
    """The grid tuner: ``budget // len(squash_values)`` radii evenly spaced over ``radius_bounds`` times the
    ``squash_values`` (rb/ra), all evaluated in one batch; returns ``(best [ra, rb/ra], its value, number
    of evaluations)`` (never more than ``budget``)."""
    check_param("budget", budget, lo=len(squash_values), integer=True)
    n_r = int(budget) // len(squash_values)
    r = np.linspace(radius_bounds[0], radius_bounds[1], n_r)
    Z = np.array([(ri, q) for ri in r for q in squash_values], float)
    v = np.asarray(objective(Z), float)
    k = int(np.argmin(v))
    return Z[k], float(v[k]), len(Z)
