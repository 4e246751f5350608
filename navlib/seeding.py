"""navlib's seeding helpers: every random stream is a child of a ``numpy.random.SeedSequence``, addressed
by spawn keys, never derived by arithmetic on integers.

Run ``k`` of a study seeded ``base`` draws from ``default_rng(SeedSequence(base).spawn(k + 1)[k])``
(:func:`generators`, :func:`generator`): a ``SeedSequence`` child is keyed by its index, so run ``k`` gets
the same stream whether it is trained alone or in a batch with other runs.

A task of a Monte Carlo study (:mod:`navlib.engine`) is seeded by its coordinates in the study:
:func:`sequence` ``(entropy, *key)`` is ``SeedSequence(entropy, spawn_key=key)``, and :func:`child` gives
the named parts of a task (its data, its training, ...) streams of their own.  Different keys give
independent streams; where a task ran never changes its seed.

Not every module goes through these helpers: a few simulators spawn their children in place with the same
rule (``SeedSequence(seed).spawn(n)`` in :mod:`navlib.sensors.compass`, :mod:`navlib.sensors.strapdown`,
:mod:`navlib.sensors.trajectory`; ``SeedSequence(entropy, spawn_key=...)`` in :mod:`navlib.sensors.ins` and
some studies).  Rewriting them through :func:`sequence` would give the same streams only where the keys
agree, and the book's stored numbers depend on them, so they are left as they are and documented where
they are drawn.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np

from .errors import InputError, check_param


def sequence(entropy: int, *key: int) -> np.random.SeedSequence:
    """``SeedSequence(entropy, spawn_key=key)``: the seed of the task at coordinates ``key`` (whole numbers
    >= 0, e.g. the indices of its noise level, effect and seed number) of a study seeded ``entropy``."""
    check_param("seed", entropy, lo=0, integer=True)
    k = tuple(int(c) for c in key)
    if any(c < 0 for c in k):
        raise InputError(f"seed key {key!r}: coordinates must be whole numbers >= 0")
    return np.random.SeedSequence(int(entropy), spawn_key=k)


def child(seed: int | np.random.SeedSequence, *key: int) -> np.random.SeedSequence:
    """The stream of part ``key`` of a task seeded ``seed`` (an integer entropy or a ``SeedSequence``):
    the ``SeedSequence`` with the same entropy and ``seed``'s spawn key extended by ``key``.  Independent
    of ``seed``'s own stream and of every other part; unlike ``SeedSequence.spawn`` it has no state, so
    asking twice gives the same stream.  Without ``key`` it is ``seed``'s own stream (``SeedSequence(seed)``
    for an integer)."""
    ss = seed if isinstance(seed, np.random.SeedSequence) else sequence(int(seed))
    return sequence(ss.entropy, *ss.spawn_key, *key)


def as_int(seed: np.random.SeedSequence) -> int:
    """A 32-bit integer drawn from ``seed``, ``seed.generate_state(1)[0]`` (for a function that takes an
    integer seed: paper E's nets, torch's generator)."""
    return int(seed.generate_state(1)[0])


def generators(seeds: Iterable[int], base: int = 0) -> list[np.random.Generator]:
    """One independent generator per run index in ``seeds`` (non-negative integers), children of
    ``SeedSequence(base)``."""
    seeds = [int(s) for s in seeds]
    if not seeds:
        raise InputError("seeds: need at least one seed")
    for s in seeds:
        check_param("seed", s, lo=0, integer=True)
    check_param("base seed", base, lo=0, integer=True)
    children = np.random.SeedSequence(int(base)).spawn(max(seeds) + 1)
    return [np.random.default_rng(children[s]) for s in seeds]


def generator(seed: int, base: int = 0) -> np.random.Generator:
    """The generator of run ``seed`` (same stream as ``generators([seed], base)[0]``)."""
    return generators([seed], base)[0]
