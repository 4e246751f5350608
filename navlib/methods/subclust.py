"""Chiu's subtractive clustering as MATLAB ``subclust``, the first-order Sugeno FIS it generates as MATLAB
``genfis2``, and Sugeno inference as MATLAB ``evalfis`` (paper D's rule base).

``subclust`` (Chiu 1994; MATLAB Fuzzy Logic Toolbox):

1. scale every column to the unit box by its min and max (values outside given bounds are clipped);
2. potential of every point ``P_i = sum_j exp(-4 ||(x_i - x_j)/r||^2)`` (its own term included; ``r`` the
   radii, one per dimension or shared);
3. take the highest potential as the first centre, ``P_ref`` = its potential;
4. repeat with the current maximum ``P*`` at ``x*``: ratio ``P*/P_ref``

   - ``> accept`` (0.5): accept;
   - ``<= reject`` (0.15): stop;
   - in between: accept if ``ratio + d_min >= 1`` (``d_min`` the radius-scaled distance to the nearest
     accepted centre), otherwise set ``P*`` to 0 and try the next maximum;

   after accepting, ``P <- P - P* exp(-4 ||(x - x*)/(squash r)||^2)``, clipped at 0 (squash 1.25 = rb/ra);
   the loop also ends when the maximum potential is 0;
5. centres mapped back to data units, ``sigma = r (max - min)/sqrt(8)``.

``genfis2``: cluster inputs and output jointly; one rule per centre; one Gaussian MF per input per rule with
the input's sigma and the centre's coordinate; product AND; consequents ``f_r = p_r . x + r_r`` from one
global least-squares solve on the normalised firing strengths.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_param


@dataclass(frozen=True)
class SubclustOptions:
    """MATLAB ``subclust`` options: squash factor (rb = squash ra), accept and reject ratios."""

    squash: float = 1.25
    accept: float = 0.5
    reject: float = 0.15

    def __post_init__(self):
        check_param("squash", self.squash, lo=0, lo_open=True, hi=100)
        check_param("accept", self.accept, lo=0, hi=1)
        check_param("reject", self.reject, lo=0, hi=1)
        if self.reject > self.accept:
            raise InputError(
                f"parameter reject={self.reject!r}: must not exceed accept={self.accept!r}"
            )


def _radii(radii, n_dim: int) -> np.ndarray:
    r = np.atleast_1d(np.asarray(radii, float))
    if r.size == 1:
        r = np.full(n_dim, r[0])
    if r.size != n_dim:
        raise InputError(f"parameter radii: {r.size} values for {n_dim} data columns")
    for v in r:
        check_param("radii", v, lo=0, lo_open=True, hi=10)
    return r


def _bounds(X: np.ndarray, bounds):
    if bounds is None:
        lo, hi = X.min(axis=0), X.max(axis=0)
    else:
        b = np.asarray(bounds, float)
        if b.shape != (2, X.shape[1]):
            raise InputError(f"parameter bounds: shape {b.shape}, expected (2, {X.shape[1]})")
        lo, hi = b[0], b[1]
    span = hi - lo
    if np.any(span <= 0):
        k = int(np.flatnonzero(span <= 0)[0])
        raise InputError(
            f"subclust: data column {k} has no spread (min = max = {lo[k]:g}); drop it"
        )
    return lo, hi


def unit_sqdist(X, bounds=None) -> np.ndarray:
    """Squared distances ``||z_i - z_j||^2`` (N, N) between the rows of ``X`` scaled to the unit box (as
    :func:`subclust` scales them), for :func:`subclust`'s ``sqdist``: a search over radii that clusters the
    same data many times computes them once."""
    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    lo, hi = _bounds(X, bounds)
    Z = np.clip((X - lo) / (hi - lo), 0.0, 1.0)
    return np.sum((Z[:, None, :] - Z[None, :, :]) ** 2, axis=2)


def subclust(
    X,
    radii,
    bounds=None,
    options: SubclustOptions = SubclustOptions(),
    *,
    return_trace: bool = False,
    max_centers: int | None = None,
    sqdist=None,
):
    """Subtractive clustering exactly as MATLAB ``subclust`` (see the module docstring).

    Parameters
    ----------
    X : (N, D) array
        Data, one row per point.
    radii : float or (D,) array
        Cluster radius in the unit box, in (0, 10].
    bounds : (2, D) array, optional
        ``[min; max]`` used for the normalisation instead of the data's own.
    options : SubclustOptions
    max_centers : int, optional
        Stop as soon as more than this many centres are accepted (not in MATLAB; lets a search discard
        radii that give too many rules without finishing the clustering); the result then has
        ``max_centers + 1`` centres and the trace ends with ``"too-many"``.
    sqdist : (N, N) array, optional
        :func:`unit_sqdist` of the same ``X`` and ``bounds`` (one shared radius only): the potentials are
        then ``exp(-4 d^2/r^2)`` of these distances instead of recomputing them (equal up to rounding).
    return_trace : bool
        Also return the list of decisions (``"accept"``, ``"grey-accept"``, ``"grey-reject"``, ``"stop"``,
        ``"exhausted"``) for tests.

    Returns
    -------
    centers : (C, D) array in data units
    sigmas : (D,) array, ``r (max - min)/sqrt(8)``
    """
    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    if X.ndim != 2 or X.shape[0] < 1:
        raise InputError(f"subclust: data of shape {X.shape}, expected (points, dimensions)")
    if not np.all(np.isfinite(X)):
        raise InputError("subclust: data contain NaN or infinite values")
    n, d = X.shape
    r = _radii(radii, d)
    lo, hi = _bounds(X, bounds)
    Z = np.clip((X - lo) / (hi - lo), 0.0, 1.0)
    shared = sqdist is not None and np.all(r == r[0])
    if sqdist is not None:
        sqdist = np.asarray(sqdist, float)
        if sqdist.shape != (n, n):
            raise InputError(f"subclust: sqdist of shape {sqdist.shape}, expected ({n}, {n})")
    if shared:
        pot = np.exp((-4.0 / r[0] ** 2) * sqdist).sum(axis=1)
    else:
        Zs = Z / r
        sq = np.sum(Zs**2, axis=1)
        d2 = np.maximum(sq[:, None] + sq[None, :] - 2.0 * Zs @ Zs.T, 0.0)
        pot = np.exp(-4.0 * d2).sum(axis=1)
    centres = np.empty((0, d))
    trace: list[str] = []
    k = int(np.argmax(pot))
    pmax = pot[k]
    pref = pmax
    while pmax > 0:
        x = Z[k]
        ratio = pmax / pref
        if ratio > options.accept:
            take = True
            trace.append("accept")
        elif ratio > options.reject:
            dmin = (
                np.sqrt(np.min(np.sum(((x - centres) / r) ** 2, axis=1)))
                if len(centres)
                else np.inf
            )
            take = bool(ratio + dmin >= 1.0)
            trace.append("grey-accept" if take else "grey-reject")
        else:
            trace.append("stop")
            break
        if take:
            centres = np.vstack([centres, x])
            if max_centers is not None and len(centres) > max_centers:
                trace.append("too-many")
                break
            if shared:
                e = np.exp((-4.0 / (options.squash * r[0]) ** 2) * sqdist[k])
            else:
                dz = (Z - x) / (options.squash * r)
                e = np.exp(-4.0 * np.sum(dz**2, axis=1))
            pot = np.maximum(pot - pmax * e, 0.0)
        else:
            pot[k] = 0.0
        k = int(np.argmax(pot))
        pmax = pot[k]
    else:
        trace.append("exhausted")
    C = centres * (hi - lo) + lo
    sig = r * (hi - lo) / np.sqrt(8.0)
    return (C, sig, trace) if return_trace else (C, sig)


# ------------------------------------------------------------------------------------------ Sugeno FIS
@dataclass(frozen=True)
class SugenoFIS:
    """First-order Takagi-Sugeno FIS with one Gaussian MF per input per rule (``gaussmf``:
    ``exp(-(x - c)^2 / (2 sigma^2))``), product AND, weighted-average defuzzification::

        w_r = prod_i exp(-(x_i - c_ri)^2/(2 s_ri^2)),   y = sum_r w_r f_r / sum_r w_r,
        f_r = sum_i p_ri x_i + q_r

    ``centers`` and ``sigmas`` are (R, n), ``consequents`` (R, n + 1) with the constant last."""

    centers: np.ndarray
    sigmas: np.ndarray
    consequents: np.ndarray

    def __post_init__(self):
        c, s, p = (np.asarray(a, float) for a in (self.centers, self.sigmas, self.consequents))
        if c.ndim != 2 or s.shape != c.shape or p.shape != (c.shape[0], c.shape[1] + 1):
            raise InputError(
                f"SugenoFIS: centers {c.shape}, sigmas {s.shape}, consequents {p.shape} "
                "do not fit (R, n), (R, n), (R, n + 1)"
            )
        if np.any(s <= 0):
            raise InputError("SugenoFIS: sigmas must be > 0")
        object.__setattr__(self, "centers", c)
        object.__setattr__(self, "sigmas", s)
        object.__setattr__(self, "consequents", p)

    @property
    def n_rules(self) -> int:
        return self.centers.shape[0]

    def firing(self, X) -> np.ndarray:
        """Rule firing strengths ``w`` (N, R)."""
        X = np.atleast_2d(np.asarray(X, float))
        z = (X[:, None, :] - self.centers[None]) / self.sigmas[None]
        return np.exp(-0.5 * np.sum(z**2, axis=2))

    def __call__(self, X) -> np.ndarray:
        """Outputs (N,) as MATLAB ``evalfis`` (weighted average; 0 where no rule fires, as MATLAB's
        default output for an input outside every MF's support)."""
        X = np.atleast_2d(np.asarray(X, float))
        w = self.firing(X)
        s = w.sum(axis=1)
        f = X @ self.consequents[:, :-1].T + self.consequents[:, -1]
        with np.errstate(invalid="ignore", divide="ignore"):
            y = np.sum(w * f, axis=1) / s
        return np.where(s > 0, y, 0.0)


def consequent_design(X: np.ndarray, wbar: np.ndarray) -> np.ndarray:
    """Regressors of the global least squares: for rule r the block ``wbar_r [x, 1]`` (N, R (n + 1))."""
    Xa = np.column_stack([X, np.ones(len(X))])
    return (wbar[:, :, None] * Xa[:, None, :]).reshape(len(X), -1)


def solve_consequents(X, y, centers, sigmas) -> np.ndarray:
    """Least-squares consequents (R, n + 1) for given premises (as ``genfis2`` and ANFIS's forward pass)."""
    X = np.asarray(X, float)
    probe = SugenoFIS(centers, sigmas, np.zeros((centers.shape[0], centers.shape[1] + 1)))
    w = probe.firing(X)
    s = w.sum(axis=1, keepdims=True)
    wbar = np.divide(w, s, out=np.zeros_like(w), where=s > 0)
    A = consequent_design(X, wbar)
    theta, *_ = np.linalg.lstsq(A, np.asarray(y, float), rcond=None)
    return theta.reshape(centers.shape[0], centers.shape[1] + 1)


def genfis2(X, y, radii, bounds=None, options: SubclustOptions = SubclustOptions()) -> SugenoFIS:
    """MATLAB ``genfis2(Xin, Xout, radii)``: subtractive clustering of ``[X y]`` (radii for the inputs and
    the output, or one shared), one rule per centre, Gaussian MFs from the input coordinates, consequents
    by least squares.  Returns a :class:`SugenoFIS`."""
    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    y = np.asarray(y, float).ravel()
    if len(y) != len(X):
        raise InputError(f"genfis2: {len(X)} input rows but {len(y)} outputs")
    C, sig = subclust(np.column_stack([X, y]), radii, bounds, options)
    n = X.shape[1]
    centers = C[:, :n]
    sigmas = np.broadcast_to(sig[:n], centers.shape).copy()
    return SugenoFIS(centers, sigmas, solve_consequents(X, y, centers, sigmas))
