"""One figure style for navlib's pictures (the book's chapters and the workbench's ``--report`` pages):
figures drawn for a 756 px content column, legends outside the data, multi-panel strips stacked when side
by side they would shrink below a readable size, and the workbench loop drawn as a staircase.

Applied with one call (the book's chapters call it through their own tooling)::

    from navlib import plotstyle
    plotstyle.use_style()                      # fonts, sizes and DPI below

and figures drawn with::

    fig, axes = plotstyle.panels(3)            # one row if three panels fit the column,
                                               # else stacked
    plotstyle.legend_below(axes[0])   # the legend under the axes, never over the data

**Sizes.**  The book's content column is :data:`COLUMN_PX` = 756 px wide at 1400 px; a figure is shown at
its natural size when it is at most that wide, so figures are at most :data:`MAX_WIDTH_IN` = 7.5 in at
:data:`DPI` = 100 (750 px) and their text is 11-12 pt at the size the reader sees.  A panel narrower than
:data:`MIN_PANEL_IN` (3.4 in: about 25 characters of 11 pt tick labels and a y label) is not readable, so
:func:`panel_grid` stacks panels that would be narrower side by side.

Matplotlib only: nothing here is imported by the CLI's loop unless a figure is asked for.
"""

from __future__ import annotations

import math
import re
from typing import Sequence

import numpy as np

from .errors import InputError, check_param

#: Width of the book's content column at a 1400 px window (px).
COLUMN_PX = 756
#: Figure resolution: 1 in = 100 px on the page.
DPI = 100
#: Widest figure (in): 750 px, inside the column, so it is never scaled down.
MAX_WIDTH_IN = 7.5
#: Narrowest readable panel (in) at 11 pt.
MIN_PANEL_IN = 3.4
#: Height of one panel (in) when panels are stacked or in one row.
PANEL_HEIGHT_IN = 3.2

#: The matplotlib settings of the style (rcParams).
RC = {
    "figure.dpi": DPI,
    "savefig.dpi": DPI,
    "figure.figsize": (MAX_WIDTH_IN, 3.6),
    "font.size": 11,
    "axes.titlesize": 12,
    "axes.labelsize": 11,
    "legend.fontsize": 11,
    "legend.title_fontsize": 11,
    "xtick.labelsize": 11,
    "ytick.labelsize": 11,
    "figure.titlesize": 12,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "legend.frameon": False,
    "figure.autolayout": False,
    "savefig.pad_inches": 0.02,
}


def use_style() -> None:
    """Apply the figure style (:data:`RC`: 11-12 pt text, 100 DPI, 7.5 in default width) to matplotlib."""
    import matplotlib as mpl  # noqa: PLC0415  # lazy: the command line imports this module without drawing

    mpl.rcParams.update(RC)


def panel_grid(
    n_panels: int, width_in: float = MAX_WIDTH_IN, min_panel_in: float = MIN_PANEL_IN
) -> tuple[int, int]:
    """``(rows, cols)`` for ``n_panels`` panels in a figure ``width_in`` wide: one row when every panel is
    at least ``min_panel_in`` wide side by side (``n * min_panel_in <= width_in``); else two columns when
    the panels pair up evenly and two fit; else one column (the panels stacked)."""
    check_param("n_panels", n_panels, lo=1, integer=True)
    check_param("width_in", width_in, lo=0, lo_open=True)
    check_param("min_panel_in", min_panel_in, lo=0, lo_open=True)
    if n_panels * min_panel_in <= width_in:
        return 1, int(n_panels)
    if n_panels % 2 == 0 and 2 * min_panel_in <= width_in:
        return n_panels // 2, 2
    return int(n_panels), 1


def panels(
    n_panels: int = 1,
    *,
    width_in: float = MAX_WIDTH_IN,
    panel_height_in: float = PANEL_HEIGHT_IN,
    stack: bool = False,
    sharex: bool = False,
    sharey: bool = False,
):
    """A figure of ``n_panels`` axes laid out by :func:`panel_grid` (``stack=True``: one column whatever
    the width, e.g. curves over a shared time axis), ``width_in`` wide (at most :data:`MAX_WIDTH_IN`), each
    row ``panel_height_in`` high, with a constrained layout (room is kept for legends placed by
    :func:`legend_below`).  Returns ``(fig, axes)``: one Axes for one panel, else a flat list in reading
    order."""
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: as above

    check_param("width_in", width_in, lo=0, lo_open=True, hi=MAX_WIDTH_IN)
    check_param("panel_height_in", panel_height_in, lo=0, lo_open=True, hi=12)
    rows, cols = (int(n_panels), 1) if stack else panel_grid(n_panels, width_in)
    fig, axes = plt.subplots(
        rows,
        cols,
        figsize=(width_in, panel_height_in * rows),
        layout="constrained",
        sharex=sharex,
        sharey=sharey,
        squeeze=False,
    )
    flat = list(axes.ravel())
    return fig, (flat[0] if n_panels == 1 else flat)


def legend_below(
    ax,
    *,
    ncol: int | None = None,
    title: str | None = None,
    handles=None,
    labels=None,
    markerscale: float = 1.0,
):
    """Place ``ax``'s legend below the axes and their x tick labels and x label (outside the data),
    centred, in as many columns as fit the axes' width (at most four); with a constrained layout the
    figure keeps room for it.  Returns the Legend (None when nothing is labelled)."""
    from matplotlib.transforms import ScaledTranslation  # noqa: PLC0415  # lazy: as above

    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    fig = ax.get_figure(root=True)
    if ncol is None:
        fig_w = fig.get_size_inches()[0] * ax.get_position().width
        longest = max(len(str(t)) for t in labels)
        per_col = 0.5 + 0.075 * longest  # marker + text at 11 pt, in inches
        ncol = max(1, min(4, len(labels), int(fig_w // per_col)))
    # below what hangs under the axes (tick labels, however many lines or slanted, and the x label),
    # measured on a draw without rendering
    fig.draw_without_rendering()
    below = ax.get_tightbbox()
    drop = max(0.0, (ax.bbox.y0 - below.y0) / fig.dpi * 72.0) + 6.0 if below is not None else 30.0
    anchor = ax.transAxes + ScaledTranslation(0, -drop / 72.0, fig.dpi_scale_trans)
    return ax.legend(
        handles,
        labels,
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        bbox_transform=anchor,
        ncol=ncol,
        title=title,
        borderaxespad=0.0,
        markerscale=markerscale,
    )


def legend_right(ax, *, title: str | None = None):
    """Place ``ax``'s legend right of the axes (outside the data); with a constrained layout the axes
    shrink so the figure keeps its width.  Returns the Legend (None when nothing is labelled)."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    return ax.legend(
        handles,
        labels,
        loc="upper left",
        bbox_to_anchor=(1.02, 1.0),
        title=title,
        borderaxespad=0.0,
    )


# ------------------------------------------------------------------------------------- the loop staircase
def wrap_label(text: str, width: int) -> str:
    """``text`` on lines of at most ``width`` characters where it can be broken: after spaces and after the
    underscores of effect names (``scale_factor_temperature`` -> ``scale_factor_`` / ``temperature``); a
    piece longer than ``width`` stays whole."""
    pieces = [p for p in re.split(r"(?<=[ _])", text) if p]
    lines, cur = [], ""
    for p in pieces:
        if cur and len((cur + p).rstrip()) > width:
            lines.append(cur.rstrip())
            cur = p
        else:
            cur += p
    lines.append(cur.rstrip())
    return "\n".join(lines)


def staircase(
    ax,
    labels: Sequence[str],
    rms: Sequence[float],
    held_out: Sequence[float] | None = None,
    *,
    floor: tuple[float, float] | None = None,
    floor_label: str = "noise floor",
    unit: str = "",
    title: str | None = None,
):
    """Draw one workbench loop on ``ax`` as a staircase: step ``i`` (x from i to i + 1) at the error
    ``rms[i]`` of the model after adding the effect ``labels[i]`` (written on the step), log error axis,
    the held-out error of each step as a marker, and the noise ``floor`` ``(low, high)`` as a band."""
    rms = np.asarray(rms, float)
    n = rms.size
    if n == 0 or len(labels) != n:
        raise InputError(
            f"staircase: labels ({len(labels)}) and rms ({n}) must be as many, at least one"
        )
    if np.any(~np.isfinite(rms)) or np.any(rms <= 0):
        raise InputError("staircase: rms must be finite and positive (log axis)")
    x = np.arange(n + 1)
    ax.stairs(rms, x, color="k", lw=2, baseline=None, label="rms")
    if held_out is not None:
        ho = np.asarray(held_out, float)
        if ho.size != n:
            raise InputError(f"staircase: held_out ({ho.size}) and rms ({n}) must be as many")
        ok = np.isfinite(ho) & (ho > 0)
        ax.plot(
            x[:-1][ok] + 0.5, ho[ok], "o", mfc="white", mec="C0", mew=2, ms=8, label="held-out rms"
        )
    if floor is not None:
        lo, hi = (float(v) for v in floor)
        if not (0 < lo <= hi and math.isfinite(hi)):
            raise InputError(f"staircase: floor={floor!r}: needs 0 < low <= high")
        ax.axhspan(lo, hi, color="C2", alpha=0.25, lw=0, label=floor_label)
    ax.set_yscale("log")
    ax.set_xlim(0, n)
    # labels wrapped to the step's width (about 6.1 pt a character at 11 pt); when a word is longer than
    # the step, the labels are written unwrapped at a slant instead of running into their neighbours
    step_in = ax.get_figure(root=True).get_size_inches()[0] * ax.get_position().width / n
    width = max(4, int(step_in * 72 / 6.1))
    texts = [wrap_label(str(t), width) for t in labels]
    if max(len(line) for t in texts for line in t.split("\n")) <= width:
        ax.set_xticks(x[:-1] + 0.5, texts)
    else:
        ax.set_xticks(
            x[:-1] + 0.5, [str(t) for t in labels], rotation=30, ha="right", rotation_mode="anchor"
        )
    ax.tick_params(axis="x", length=0)
    ax.grid(axis="x", visible=False)
    for i, (v, t) in enumerate(zip(rms, labels)):
        ax.annotate(
            f"{v:.3g}",
            (i + 0.5, v),
            xytext=(0, 4),
            textcoords="offset points",
            ha="center",
            va="bottom",
        )
    ax.set_ylabel(f"error ({unit})" if unit else "error")
    ax.set_xlabel("model after each step")
    if title:
        ax.set_title(title)
    lo_y, hi_y = ax.get_ylim()
    ax.set_ylim(lo_y, hi_y * 1.6)  # room for the value written above the first step
    return ax
