"""navbook.style: one colour per method id, never shared within a chapter, every compass method covered."""

from __future__ import annotations

import matplotlib.colors as mcolors
import pytest

from navbook import style
from navlib.errors import InputError
from navlib.methods.compass_methods import METHODS


@pytest.mark.parametrize("chapter", sorted(style.CHAPTERS))
def test_no_two_methods_of_a_chapter_share_a_colour(chapter):
    entries = style.CHAPTERS[chapter]
    colours = [mcolors.to_hex(kw["color"]) for kw in entries.values()]
    assert all(mcolors.is_color_like(kw["color"]) for kw in entries.values())
    shared = {c for c in colours if colours.count(c) > 1}
    assert not shared, {m: kw for m, kw in entries.items() if mcolors.to_hex(kw["color"]) in shared}


def test_every_compass_method_has_a_style():
    assert set(METHODS) <= set(style.COMPASS)


def test_an_id_belongs_to_one_chapter():
    ids = [m for d in style.CHAPTERS.values() for m in d]
    assert len(ids) == len(set(ids)) == len(style.METHOD_STYLE)


def test_of_copies_and_overrides_and_refuses_an_unknown_id():
    kw = style.of("ls8", lw=2)
    assert kw == {"color": style.COMPASS["ls8"]["color"], "lw": 2}
    kw["color"] = "red"
    assert style.color("ls8") != "red"
    with pytest.raises(InputError, match="no style for method 'nope'"):
        style.of("nope")
