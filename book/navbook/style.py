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

# -- the compass chapter (paper A, document B, the real compass): the ids of
# navlib.methods.compass_methods.METHODS, and two nets of document B's small-sample test
COMPASS: dict[str, dict[str, Any]] = {
    # before compensation
    "uncompensated": {"color": "#7f7f7f"},
    # the exact error model: the noise floor
    "physical": {"color": "#000000"},
    # least squares: blues
    "ls8": {"color": "#1f77b4"},
    "ls8_planar": {"color": "#17becf"},
    "ls8_h3": {"color": "#000080"},
    # BP networks from random weights: greens
    "bp_matlab": {"color": "#2ca02c"},
    "bp_matlab_val": {"color": "#bcbd22"},
    "bp_adam": {"color": "#98df8a"},
    "bp_scipy_lm": {"color": "#556b2f"},
    # document B's over-sized BP nets (small-sample test)
    "bp_big_adam": {"color": "#006400"},
    "bp_big_lm": {"color": "#800080"},
    # DE-BP: oranges and browns
    "de_bp_pure": {"color": "#ff7f0e"},
    "de_bp_hybrid_trainlm": {"color": "#8c564b"},
    "de_bp_hybrid_trainlm_val": {"color": "#c49c94"},
    "de_bp_full_trainlm": {"color": "#ffbb78"},
    "de_bp_full_trainlm_val": {"color": "#b8860b"},
    # ADE-BP: reds, pinks and purples
    "ade_bp_pure": {"color": "#d62728"},
    "ade_bp_hybrid_trainlm": {"color": "#e377c2"},
    "ade_bp_hybrid_trainlm_val": {"color": "#9467bd"},
    "ade_bp_full_trainlm": {"color": "#8b0000"},
    "ade_bp_full_trainlm_val": {"color": "#ff9896"},
    # ADE-BP's other adaptation rules (paper A's readings of its rules)
    "ade_bp_pure_f_ind": {"color": "#f7b6d2"},
    "ade_bp_full_trainlm_f_ind": {"color": "#c5b0d5"},
    "ade_bp_pure_f_comb": {"color": "#dbdb8d"},
    "ade_bp_full_trainlm_f_comb": {"color": "#9edae5"},
    "ade_bp_pure_cr_rank": {"color": "#aec7e8"},
    "ade_bp_full_trainlm_cr_rank": {"color": "#c7c7c7"},
    "ade_bp_pure_f_ind_cr_rank": {"color": "#ff1493"},
    "ade_bp_full_trainlm_f_ind_cr_rank": {"color": "#4b0082"},
    # document B's ELM
    "elm": {"color": "#6a5acd"},
    "elm_backtuned": {"color": "#008080"},
}

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
#: Method id -> matplotlib keyword arguments, every chapter's entries in one mapping (:func:`of` reads it).
METHOD_STYLE: dict[str, dict[str, Any]] = {k: v for d in CHAPTERS.values() for k, v in d.items()}


def color(method: str) -> str:
    """The colour of ``method`` (:func:`of`), for calls that take a colour alone (a band, a fill)."""
    return of(method)["color"]


def of(method: str, **overrides: Any) -> dict[str, Any]:
    """The drawing keywords of ``method`` (a copy: ``overrides`` win), e.g. ``ax.plot(x, y, **of("elm"))``;
    an unknown id is refused with one line naming it."""
    if method not in METHOD_STYLE:
        raise InputError(f"no style for method {method!r}: add it to navbook.style")
    return {**METHOD_STYLE[method], **overrides}
