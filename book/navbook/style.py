"""How the book draws each method: one colour and marker per method id, the same in every figure.

:data:`METHOD_STYLE` maps a method's id (the key of :data:`navlib.methods.compass_methods.METHODS`, or a
chapter's method name) to matplotlib keyword arguments (``color``, ``marker``, ``linestyle``); a chapter
draws with ``ax.plot(x, y, **style.of("ade_bp_pure"))`` instead of typing colours, so two methods never
share a colour by accident (``tests`` check that no two ids of a chapter share one).  The chapters' own
dictionaries are kept apart below and merged into :data:`METHOD_STYLE`.
"""

from __future__ import annotations

from typing import Any

from navlib.errors import InputError

# -- the compass chapter (paper A, document B, the real compass): ids of navlib.methods.compass_methods
COMPASS: dict[str, dict[str, Any]] = {}

# -- the gyro chapter (paper C)
GYRO: dict[str, dict[str, Any]] = {}

# -- the accelerometer chapter (paper D)
ACCELEROMETER: dict[str, dict[str, Any]] = {}

# -- the celestial chapter (paper E)
CELESTIAL: dict[str, dict[str, Any]] = {}

# -- the workbench chapter
WORKBENCH: dict[str, dict[str, Any]] = {}

#: Every chapter's styles: method id -> matplotlib keyword arguments.
CHAPTERS = {
    "compass": COMPASS,
    "gyro": GYRO,
    "accelerometer": ACCELEROMETER,
    "celestial": CELESTIAL,
    "workbench": WORKBENCH,
}
METHOD_STYLE: dict[str, dict[str, Any]] = {k: v for d in CHAPTERS.values() for k, v in d.items()}


def of(method: str, **overrides: Any) -> dict[str, Any]:
    """The drawing keywords of ``method`` (a copy: ``overrides`` win), e.g. ``ax.plot(x, y, **of("elm"))``;
    an unknown id is refused with one line naming it."""
    if method not in METHOD_STYLE:
        raise InputError(f"no style for method {method!r}: add it to navbook.style")
    return {**METHOD_STYLE[method], **overrides}
