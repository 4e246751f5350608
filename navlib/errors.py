"""One exception type for every bad input, so callers (notebooks, CLI) can show one line and stop.

Every message names what is wrong precisely: the file, the column and the row for a table; the parameter
and the value for a parameter.  No traceback reaches a user of the command line.
"""

from __future__ import annotations

import math
from typing import Any


class InputError(ValueError):
    """Bad user input (a data file or a parameter). ``str(err)`` is a single line meant for the user."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).split()))


class UserCodeError(Exception):
    """A user's own code (an effect's ``contribution`` from an ``--effects`` file) failed or returned
    something unusable.  ``str(err)`` is one line naming the file and the effect; the user's exception, if
    any, is the ``__cause__``.  Deliberately not an :class:`InputError`: a fit that catches InputError to
    mark a candidate effect untestable must not hide a broken effect (the CLI exits 2 on it)."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).split()))


def check_param(
    name: str,
    value: Any,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
    integer: bool = False,
) -> None:
    """Raise :class:`InputError` unless ``lo <= value <= hi`` (open ends when asked), finite, and whole
    if ``integer``. ``name`` is the parameter's name as the user wrote it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"parameter {name}={value!r}: not a number") from None
    if not math.isfinite(v):
        raise InputError(f"parameter {name}={value!r}: must be finite")
    if integer and v != int(v):
        raise InputError(f"parameter {name}={value!r}: must be a whole number")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        rel = ">" if lo_open else ">="
        raise InputError(f"parameter {name}={value!r}: must be {rel} {lo:g}")
    if hi is not None and (v > hi or (hi_open and v == hi)):
        rel = "<" if hi_open else "<="
        raise InputError(f"parameter {name}={value!r}: must be {rel} {hi:g}")


def check_choice(name: str, value: Any, options) -> None:
    """Raise :class:`InputError` unless ``value`` is one of ``options`` (a ``typing.Literal``'s values)."""
    if value not in tuple(options):
        raise InputError(
            f"parameter {name}={value!r}: must be one of {', '.join(map(repr, options))}"
        )
