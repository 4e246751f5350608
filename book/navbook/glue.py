"""Glue for the prose (numbers, texts, tables, figures and the claims' verdicts), each shown where a MyST
``{glue:...}`` role or directive with the same name stands."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

import pandas as pd

from navlib import claims as registry
from navlib.claims import Claim
from navlib.formatting import fmt

from .claim_boxes import Answer, Glance, Showed
from .tables import Table


def _glue(name: str, obj: Any) -> None:
    from myst_nb import glue  # noqa: PLC0415  # lazy: myst_nb loads sphinx (~1 s); only notebooks glue

    glue(name, obj, display=False)


def glue_number(name: str, value: Any, spec: str = "{:.3g}") -> str:
    """Glue a number (formatted by ``spec``) for the prose, where the MyST role ``{glue:text}`` with the
    same ``name`` shows it; returns the text."""
    text = fmt(value, spec)
    _glue(name, text)
    return text


def glue_text(name: str, text: str) -> str:
    """Glue a short text (a verdict, a method name) for the MyST role ``{glue:text}`` in the prose."""
    _glue(name, str(text))
    return str(text)


def glue_table(name: str, tab: "Table | Glance | Answer | Showed | pd.DataFrame") -> None:
    """Glue a table for a MyST ``{glue:}`` directive (e.g. inside the Results-at-a-glance admonition)."""
    _glue(name, tab if isinstance(tab, (Table, Glance, Answer, Showed)) else Table(tab))


def glue_figure(name: str, fig) -> None:
    """Glue a matplotlib figure for a MyST ``{glue:figure}`` directive (numbered, captioned, with alt text in the
    directive), then close it so it is not shown a second time."""
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: matplotlib only where a figure is glued

    _glue(name, fig)
    plt.close(fig)


def glue_png(name: str, path) -> None:
    """Glue a PNG file (e.g. the figure ``navlib loop --report`` wrote) for a MyST ``{glue:figure}``
    directive; the image is read now, so the file may be removed afterwards."""
    from IPython.display import Image  # noqa: PLC0415  # lazy: IPython only inside a notebook

    _glue(name, Image(data=Path(path).read_bytes(), format="png"))


def glue_claims(claims: Iterable[Claim]) -> None:
    """Glue, for every claim with a ``key``, its verdict (``{glue:text}`key```) and a sentence with the
    interval and the boundary (``{glue:text}`key_detail```), so prose that states a verdict comes from the
    claim itself."""
    for c in claims:
        if not c.key:
            continue
        c = registry.with_register_margin(c)  # as navlib.claims.evaluate judges the row
        glue_text(c.key, c.verdict)
        detail = f"{c.verdict}: ours {c.interval_text}, boundary {c.boundary_text}"
        glue_text(f"{c.key}_detail", detail + (f" ({c.reason})" if c.reason else ""))
