"""The seeding convention of :mod:`navlib.seeding`, under the name the methods and the studies import it by
(the helpers live in the base layer so that the simulators of :mod:`navlib.sensors` use them too)."""

from __future__ import annotations

from ..seeding import as_int, child, generator, generators, sequence  # noqa: F401  (re-exported)
