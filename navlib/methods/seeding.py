"""The one seeding convention of navlib: run ``k`` of a study seeded ``base`` draws from
``numpy.random.default_rng(np.random.SeedSequence(base).spawn(k + 1)[k])``.

A ``SeedSequence`` child is keyed by its index, so run ``k`` gets the same stream whether it is trained
alone or in a batch with other runs (:func:`generators` builds the batch).  Every stochastic method takes
its generator from here; nothing derives seeds by arithmetic.
"""
from __future__ import annotations

from typing import Iterable

import numpy as np

from ..errors import InputError, check_param


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
