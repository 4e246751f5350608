"""Artificial fish swarm: bounds, seeding, batching, and that it minimises."""

import numpy as np
import pytest

from navlib.errors import InputError
from navlib.methods.fish_swarm import FishSwarmParams, minimise

BOUNDS = [(-2.0, 3.0), (10.0, 20.0)]


def _sphere(log):
    def f(X):
        log.append(np.array(X))
        return (X[:, 0] - 1.0) ** 2 + ((X[:, 1] - 12.0) / 5) ** 2

    return f


@pytest.mark.parametrize("improved", [False, True])
def test_every_candidate_inside_the_bounds_and_two_batches_per_generation(improved):
    log = []
    p = FishSwarmParams(
        n_fish=12, generations=15, try_number=3, visual=0.9, step=0.8, improved=improved
    )
    res = minimise(_sphere(log), BOUNDS, p, seed=1)
    allx = np.vstack(log)
    lo, hi = np.array(BOUNDS).T
    assert np.all(allx >= lo) and np.all(allx <= hi)
    assert res.n_calls == 1 + 2 * p.generations == len(log)
    assert [len(x) for x in log[1:3]] == [p.n_fish * (1 + p.try_number), 2 * p.n_fish]
    assert np.all(np.diff(res.history) <= 0)  # the bulletin board never gets worse


@pytest.mark.parametrize("improved", [False, True])
def test_minimises_a_bowl(improved):
    res = minimise(
        _sphere([]), BOUNDS, FishSwarmParams(n_fish=15, generations=40, improved=improved), seed=2
    )
    assert res.x[0] == pytest.approx(1.0, abs=0.15) and res.x[1] == pytest.approx(12.0, abs=0.75)


def test_seeding():
    p = FishSwarmParams()
    a = minimise(_sphere([]), BOUNDS, p, seed=5)
    b = minimise(_sphere([]), BOUNDS, p, seed=5)
    c = minimise(_sphere([]), BOUNDS, p, seed=6)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.history, b.history)
    assert not np.array_equal(a.x, c.x)


def test_initial_school_is_used():
    init = np.tile([1.0, 12.0], (8, 1))
    res = minimise(_sphere([]), BOUNDS, FishSwarmParams(generations=1), seed=0, init=init)
    assert res.fun == pytest.approx(0.0)


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(n_fish=1), "n_fish"),
        (dict(generations=0), "generations"),
        (dict(try_number=1.5), "try_number"),
        (dict(visual=0), "visual"),
        (dict(delta=1.5), "delta"),
        (dict(improved="yes"), "improved"),
    ],
)
def test_bad_params(kw, word):
    with pytest.raises(InputError, match=word):
        FishSwarmParams(**kw)


def test_bad_bounds_and_objective():
    with pytest.raises(InputError, match="bounds"):
        minimise(_sphere([]), [(1.0, 1.0)])
    with pytest.raises(InputError, match="returned"):
        minimise(lambda X: np.zeros(3), BOUNDS, FishSwarmParams(n_fish=4), seed=0)
