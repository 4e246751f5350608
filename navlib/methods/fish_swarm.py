"""Artificial fish swarm algorithm (AFSA, Li Xiaolei 2002) and an improved variant (IAFSA), minimising an
objective that takes the whole school at once (paper D tunes the subtractive-clustering radii with IAFSA).

The search runs in the unit box (every dimension scaled by its bounds; Visual and Step are fractions of
the box).  Per generation, for every fish ``x_i`` with value ``Y_i`` (lower is better):

- **swarm**: the ``n_f`` other fish within Visual have centre ``x_c``; if ``Y(x_c) < Y_i`` and the
  neighbourhood is not crowded (``n_f / P < delta``), move a random fraction of Step toward ``x_c``;
- **follow**: the best neighbour ``x_b`` within Visual; if ``Y_b < Y_i`` and not crowded, move toward it;
- **prey** (when a behaviour's condition fails): up to ``try_number`` random points within Visual; move
  toward the first better one, else a random move within Step (AFSA) or a move toward the bulletin board's
  best fish (IAFSA);
- each fish takes the better of its swarm and follow results; the bulletin board keeps the best fish ever.

IAFSA (``improved=True``): Visual and Step shrink with the generation ``k`` of ``G``,
``v_k = v_0 (v_min + (1 - v_min) exp(-a (k/G)^2))`` with ``a = 3`` and floor fraction ``v_min`` (wide search
first, fine moves at the end), and a failed prey moves toward the board instead of randomly.

Each generation makes exactly two objective calls, each with all fish's candidates as one batch: (1) the
swarm centres and all prey trial points, (2) the resulting moves.  Every candidate is clipped to the bounds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_param


@dataclass(frozen=True)
class FishSwarmParams:
    """School size, generations, try number, Visual and Step (fractions of the unit box), crowd factor
    ``delta`` and the improved variant's switch and floor fraction."""

    n_fish: int = 8
    generations: int = 8
    try_number: int = 2
    visual: float = 0.3
    step: float = 0.15
    delta: float = 0.618
    improved: bool = True
    shrink_floor: float = 0.1

    def __post_init__(self):
        check_param("n_fish", self.n_fish, lo=2, hi=10000, integer=True)
        check_param("generations", self.generations, lo=1, hi=10000, integer=True)
        check_param("try_number", self.try_number, lo=1, hi=1000, integer=True)
        check_param("visual", self.visual, lo=0, lo_open=True, hi=2)
        check_param("step", self.step, lo=0, lo_open=True, hi=2)
        check_param("delta", self.delta, lo=0, lo_open=True, hi=1)
        check_param("shrink_floor", self.shrink_floor, lo=0, lo_open=True, hi=1)
        if not isinstance(self.improved, (bool, np.bool_)):
            raise InputError(f"parameter improved={self.improved!r}: must be True or False")


@dataclass(frozen=True)
class FishSwarmResult:
    x: np.ndarray  # best point (original units)
    fun: float  # its value
    history: np.ndarray  # bulletin-board value after each generation
    n_evaluations: int
    n_calls: int


def _toward(x, target, step, rng):
    d = target - x
    n = np.linalg.norm(d, axis=-1, keepdims=True)
    u = np.divide(d, n, out=np.zeros_like(d), where=n > 0)
    return x + u * step * rng.random((x.shape[0], 1))


def minimise(
    objective, bounds, params: FishSwarmParams = FishSwarmParams(), seed: int = 0, init=None
) -> FishSwarmResult:
    """Minimise ``objective`` over the box ``bounds`` ((D, 2) array of [low, high]) with (I)AFSA.

    Parameters
    ----------
    objective : callable
        ``objective(X)`` with ``X`` of shape (P, D) in original units returns P values (lower is better).
    bounds : (D, 2) array
    params : FishSwarmParams
    seed : int
        ``np.random.SeedSequence(seed)`` drives every random draw.
    init : (n_fish, D) array, optional
        Initial school (original units); default uniform in the box.

    Returns
    -------
    FishSwarmResult
    """
    b = np.asarray(bounds, float)
    if b.ndim != 2 or b.shape[1] != 2 or np.any(b[:, 1] <= b[:, 0]) or not np.all(np.isfinite(b)):
        raise InputError(
            f"parameter bounds={bounds!r}: expected finite (D, 2) rows [low, high] with low < high"
        )
    lo, span = b[:, 0], b[:, 1] - b[:, 0]
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    P, D, T = int(params.n_fish), b.shape[0], int(params.try_number)
    calls = [0, 0]

    def f(Z):
        calls[0] += 1
        calls[1] += len(Z)
        y = np.asarray(objective(lo + Z * span), float).ravel()
        if y.shape != (len(Z),):
            raise InputError(f"fish swarm objective returned {y.shape} values for {len(Z)} fish")
        return np.where(np.isfinite(y), y, np.inf)

    if init is None:
        Z = rng.random((P, D))
    else:
        Z = np.clip((np.asarray(init, float) - lo) / span, 0, 1)
        if Z.shape != (P, D):
            raise InputError(f"parameter init: shape {Z.shape}, expected ({P}, {D})")
    Y = f(Z)
    kb = int(np.argmin(Y))
    board_x, board_y = Z[kb].copy(), float(Y[kb])
    hist = []
    G = int(params.generations)
    for k in range(G):
        if params.improved:
            shrink = params.shrink_floor + (1 - params.shrink_floor) * np.exp(-3.0 * (k / G) ** 2)
        else:
            shrink = 1.0
        vis, stp = params.visual * shrink, params.step * shrink
        # neighbourhoods
        dist = np.linalg.norm(Z[:, None] - Z[None], axis=2)
        nb = (dist < vis) & ~np.eye(P, dtype=bool)
        nf = nb.sum(axis=1)
        crowd_ok = (nf / P) < params.delta
        centre = np.where(nf[:, None] > 0, (nb @ Z) / np.maximum(nf, 1)[:, None], Z)
        yb = np.where(nb, Y[None, :], np.inf)
        jb = np.argmin(yb, axis=1)
        best_nb_y = yb[np.arange(P), jb]
        # batch 1: swarm centres and prey trials
        trials = np.clip(Z[:, None] + vis * rng.uniform(-1, 1, (P, T, D)), 0, 1)
        y1 = f(np.vstack([centre, trials.reshape(P * T, D)]))
        yc, yt = y1[:P], y1[P:].reshape(P, T)
        better = yt < Y[:, None]
        first = np.argmax(better, axis=1)
        has = better.any(axis=1)
        prey_target = trials[np.arange(P), first]
        prey = np.where(has[:, None], _toward(Z, prey_target, stp, rng), 0.0)
        if params.improved:
            fallback = _toward(Z, np.broadcast_to(board_x, Z.shape), stp, rng)
        else:
            fallback = Z + stp * rng.uniform(-1, 1, (P, D))
        prey = np.clip(np.where(has[:, None], prey, fallback), 0, 1)
        swarm_ok = (nf > 0) & (yc < Y) & crowd_ok
        follow_ok = (nf > 0) & (best_nb_y < Y) & crowd_ok
        swarm = np.clip(np.where(swarm_ok[:, None], _toward(Z, centre, stp, rng), prey), 0, 1)
        follow = np.clip(np.where(follow_ok[:, None], _toward(Z, Z[jb], stp, rng), prey), 0, 1)
        # batch 2: the moves
        y2 = f(np.vstack([swarm, follow]))
        ys, yf = y2[:P], y2[P:]
        pick_f = yf < ys
        Z = np.where(pick_f[:, None], follow, swarm)
        Y = np.where(pick_f, yf, ys)
        allz = np.vstack([centre, trials.reshape(P * T, D), swarm, follow])
        ally = np.concatenate([y1, y2])
        kb = int(np.argmin(ally))
        if ally[kb] < board_y:
            board_x, board_y = allz[kb].copy(), float(ally[kb])
        hist.append(board_y)
    return FishSwarmResult(lo + board_x * span, board_y, np.array(hist), calls[1], calls[0])
