"""Tables that fit the page (HTML with a plain-text twin for nbval, readable column labels) and the table
of a chapter's parameters.

:func:`use_style`, the chapter's first call, switches the figure style and the readable labels on
(``READABLE_TABLES``); :func:`fold_tables` folds captioned tables behind their captions (``FOLD_TABLES``).
"""

from __future__ import annotations

import ast
import hashlib
import html
import io
import json
import math
import os
import re
import tokenize
from pathlib import Path
from typing import Any, Mapping

import pandas as pd

from navlib.errors import InputError
from navlib.formatting import fmt
from navlib import plotstyle


#: Plain-text rendering width in characters; a stored output line longer than this would be cut on the page.
PLAIN_WIDTH = 92
_CSS = (
    "table-layout:auto;width:100%;max-width:100%;border-collapse:collapse;font-size:0.85em;"
    "margin-bottom:0.5em"
)
_CELL = "padding:2px 6px;border-bottom:1px solid #ddd;vertical-align:top;overflow-wrap:break-word;"


# ----------------------------------------------------------------------------------------------- tables
def _breakable(text: str) -> str:
    """HTML-escaped ``text`` with ``<wbr>`` (an optional line break) after underscores, slashes and commas."""
    return re.sub(r"([_/,])(?=\S)", r"\1<wbr>", html.escape(str(text), quote=False))


#: Set by :func:`use_style`: tables show readable labels (:func:`readable`) unless
#: asked otherwise.
READABLE_TABLES = False

#: Unit suffixes of snake_case names and how a column header shows them.
UNIT_SUFFIXES = {
    ("deg", "h"): "deg/h",
    ("mg", "g"): "mg/g",
    ("m", "s"): "m/s",
    ("deg",): "deg",
    ("rad",): "rad",
    ("arcmin",): "arcmin",
    ("arcsec",): "arcsec",
    ("nmi",): "nmi",
    ("ug",): "ug",
    ("mg",): "mg",
    ("ut",): "uT",
    ("nt",): "nT",
    ("c",): "degC",
    ("s",): "s",
    ("h",): "h",
    ("pct",): "%",
    ("ppm",): "ppm",
}
#: Words written in capitals in a header.
ACRONYMS = {"rms", "rmse", "mse", "sse", "loo", "maxe", "mare", "ins", "rbf", "ann", "fis", "anfis"}
_NEG_ZERO = re.compile(r"^[-\u2212]([+]?0(?:\.0+)?(?:e[+-]?\d+)?)$")


def _unit_suffix(words: list[str], tables) -> tuple[str, int]:
    """The longest unit suffix of ``words`` (a snake_case name split at "_") found in ``tables`` (mappings
    of word tuples to the unit shown) and its length in words; ``("", 0)`` when there is none."""
    low = [w.lower() for w in words]
    best, best_len = "", 0
    for table_ in tables:
        for suffix, shown in table_.items():
            k = len(suffix)
            if best_len < k < len(low) and tuple(low[-k:]) == suffix:
                best, best_len = shown, k
    return best, best_len


def label(name: Any) -> str:
    """A readable header for a column name: a tuple is joined with spaces; a snake_case name becomes words
    with its unit suffix in parentheses and acronyms in capitals (``median_rms_deg`` -> ``median RMS
    (deg)``, ``drift_deg_h`` -> ``drift (deg/h)``); any other text is kept as it is."""
    if isinstance(name, tuple):
        return " ".join(label(n) for n in name if str(n).strip())
    text = str(name)
    if "_" not in text or " " in text:
        return text
    words = [w for w in text.split("_") if w]
    unit, k = _unit_suffix(words, (UNIT_SUFFIXES,))
    words = words[: len(words) - k]
    words = [w.upper() if w.lower() in ACRONYMS else w for w in words]
    return " ".join(words) + (f" ({unit})" if unit else "")


def row_label(value: Any) -> str:
    """A flat row label: a tuple (from a MultiIndex or a groupby) is joined with ": "."""
    if isinstance(value, tuple):
        return ": ".join(str(v) for v in value)
    return str(value)


def no_negative_zero(text: Any) -> str:
    """``-0``, ``-0.000``, ``-0e+00`` (a value that rounds to zero) without its minus sign; a value that
    is not text yet (an index level moved into the columns by :func:`readable`) is shown as ``str``."""
    text = text if isinstance(text, str) else str(text)
    m = _NEG_ZERO.match(text)
    return m.group(1).lstrip("+") if m else text


def readable(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with readable labels: named index levels become ordinary first columns (no index-name
    row), tuple row labels are flattened (:func:`row_label`) and column names become headers with their
    units in parentheses (:func:`label`).  Values are not touched."""
    out = frame.copy()
    if any(n is not None for n in out.index.names):
        clash = [n for n in out.index.names if n is not None and n in out.columns]
        if clash:
            raise InputError(f"readable: the index name {clash[0]!r} is also a column's name")
        out = out.reset_index()
    else:
        out.index = [row_label(v) for v in out.index]
    cols = [label(c) for c in out.columns]
    if len(set(cols)) != len(cols):
        dup = next(c for c in cols if cols.count(c) > 1)
        raise InputError(f"readable: two columns would both be shown as {dup!r}")
    out.columns = cols
    return out


class Table:
    """A result table for the book: HTML (wrapping text, fitting the content column) for the page, and a
    rounded plain-text rendering no wider than :data:`PLAIN_WIDTH` characters for nbval and terminals.

    ``formats`` maps column names to format strings (``"{:.3f}"``) or callables; unformatted float
    columns get 4 significant digits.  ``caption`` is shown above the table.  ``readable`` (default: on
    after :func:`use_style`) shows the formatted table with readable labels
    (:func:`readable`: no index-name row, flat row labels, units in parentheses) and no ``-0``;
    ``formats`` still name the original columns.  ``fold`` (a summary line, or True for the caption) puts a
    secondary table in a dropdown on the page, closed until the reader opens it (the plain text is the
    same)."""

    def __init__(
        self,
        frame: pd.DataFrame,
        formats: Mapping[str, Any] | None = None,
        caption: str | None = None,
        index: bool = True,
        readable: bool | None = None,
        fold: bool | str | None = None,
    ):
        if not isinstance(frame, pd.DataFrame):
            frame = pd.DataFrame(frame)
        if fold is True and not caption:
            raise InputError(
                "report.table: fold=True needs a caption (it is the dropdown's summary)"
            )
        if fold is None:  # the chapter's default (fold_tables): evidence behind its caption
            fold = bool(FOLD_TABLES and caption)
        self.fold = (caption if fold is True else str(fold)) if fold else None
        self.frame = frame
        self.formats = dict(formats or {})
        self.caption = caption
        self.readable = READABLE_TABLES if readable is None else bool(readable)
        self.index = index and not (self.readable and any(n is not None for n in frame.index.names))

    def formatted(self) -> pd.DataFrame:
        """The table as strings, every number formatted."""
        out = self.frame.copy()
        for col in out.columns:
            f = self.formats.get(col)
            s = out[col]
            if f is None:
                if pd.api.types.is_float_dtype(s):
                    f = "{:.4g}"
                elif pd.api.types.is_bool_dtype(s):
                    f = lambda v: "yes" if v else "no"  # noqa: E731
                else:
                    out[col] = s.map(
                        lambda v: (
                            "–" if v is None or (isinstance(v, float) and math.isnan(v)) else str(v)
                        )
                    )
                    continue
            fn = f if callable(f) else (lambda v, f=f: fmt(v, f))
            out[col] = s.map(fn)
        if self.readable:
            out = readable(out).map(no_negative_zero)
        out.index = out.index.map(str)
        out.columns = [str(c) for c in out.columns]
        return out

    def _repr_html_(self) -> str:
        f = self.formatted()
        digest = hashlib.sha1((f.to_csv() + str(self.caption)).encode("utf-8")).hexdigest()[:10]
        # escaped text with line-break opportunities after "_", "/" and "," so that long identifiers
        # (column names such as temperature_change_c) wrap inside the content column instead of widening it
        f = f.map(_breakable)
        f.index = f.index.map(_breakable)
        f.columns = [_breakable(c) for c in f.columns]
        styler = f.style if self.index else f.style.hide(axis="index")
        styler = styler.set_uuid(f"t{digest}")  # stable across runs, distinct per table
        styler = styler.set_table_attributes(f'class="navbook-table" style="{_CSS}"')
        styler = styler.set_table_styles(
            [
                {"selector": "th", "props": _CELL + "text-align:left;"},
                {"selector": "td", "props": _CELL},
            ]
        )
        if self.caption and not self.fold:
            styler = styler.set_caption(self.caption)
        if self.fold:
            return (
                f'<details class="navbook-fold"><summary>{html.escape(self.fold, quote=False)}</summary>'
                f"{styler.to_html()}</details>"
            )
        return styler.to_html()

    def __repr__(self) -> str:
        f = self.formatted()
        width = PLAIN_WIDTH
        clip = f.map(lambda s: s if len(s) <= 40 else s[:37] + "...")
        text = clip.to_string(index=self.index, line_width=width)
        lines = [ln if len(ln) <= width else ln[: width - 3] + "..." for ln in text.splitlines()]
        head = [self.caption[:width]] if self.caption else []
        return "\n".join(head + lines)


#: Whether a captioned table folds behind its caption unless it says ``fold=False`` (:func:`fold_tables`).
FOLD_TABLES = False


def fold_tables(on: bool = True) -> None:
    """Answer first, evidence behind folds: from now on every captioned table of the chapter is shown
    closed behind its caption (the reader opens what they want to check), unless the table is made with
    ``fold=False``.  The plain text (what nbval compares) is the same either way."""
    global FOLD_TABLES
    FOLD_TABLES = bool(on)


def table(
    frame: pd.DataFrame,
    formats: Mapping[str, Any] | None = None,
    caption: str | None = None,
    index: bool = True,
    readable: bool | None = None,
    fold: bool | str | None = None,
) -> Table:
    """Shorthand for :class:`Table`; the last expression of a cell displays it (``fold``: in a dropdown;
    None: the chapter's default, :func:`fold_tables`)."""
    return Table(frame, formats, caption, index, readable, fold)


# ----------------------------------------------------------------------------------------------- parameters
#: Unit suffixes of parameter names beyond :data:`UNIT_SUFFIXES` (which also label table columns).
PARAMETER_UNITS = {
    ("deg", "rt", "h"): "deg/sqrt(h)",
    ("hz",): "Hz",
    ("m",): "m",
    ("ms2",): "m/s^2",
    ("dps",): "deg/s",
    ("ppm",): "ppm",
    ("g",): "g",
}


def unit_of(name: str) -> str:
    """The unit a snake_case name carries in its suffix (``noise_ut`` -> ``uT``, ``gyro_arw_deg_rt_h`` ->
    ``deg/sqrt(h)``, ``t_start_c`` -> ``degC``), or "" when it carries none (``n_seeds``)."""
    return _unit_suffix([w for w in str(name).split("_") if w], (PARAMETER_UNITS, UNIT_SUFFIXES))[0]


def _parameters_cell(notebook: str | os.PathLike) -> str:
    path = Path(notebook)
    try:
        nb = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{path}: no such notebook") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputError(f"{path}: not a notebook ({type(err).__name__})") from None
    for cell in nb.get("cells", []):
        if cell.get("cell_type") == "code" and "parameters" in cell.get("metadata", {}).get(
            "tags", []
        ):
            src = cell.get("source", "")
            return "".join(src) if isinstance(src, list) else str(src)
    raise InputError(f"{path}: no cell tagged 'parameters'")


def parameter_rows(source: str) -> list[dict]:
    """The assignments of a notebook's parameters cell, in order: ``name``, ``default`` (the literal
    assigned; a tuple assignment gives one row per name) and ``meaning`` (the comment on the
    assignment's lines, after the block of comment lines right above it; an assignment without a comment
    right under another one shares its meaning)."""

    try:
        tree = ast.parse(source)
    except SyntaxError as err:
        raise InputError(f"parameters cell, line {err.lineno}: {err.msg}") from None
    comments: dict[int, str] = {}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            comments[tok.start[0]] = tok.string.lstrip("#").strip()
    lines = source.splitlines()
    code_lines = {n for node in tree.body for n in range(node.lineno, node.end_lineno + 1)}
    rows: list[dict] = []
    prev_end = -1
    for node in tree.body:
        if not isinstance(node, ast.Assign) or len(node.targets) != 1:
            continue
        above, n = [], node.lineno - 1
        while (
            n >= 1
            and n in comments
            and n not in code_lines
            and lines[n - 1].lstrip().startswith("#")
        ):
            above.insert(0, comments[n])
            n -= 1
        beside = [comments[k] for k in range(node.lineno, node.end_lineno + 1) if k in comments]
        meaning = "; ".join(x for x in (" ".join(above), " ".join(beside)) if x)
        if not meaning and rows and prev_end == node.lineno - 1:
            meaning = rows[-1]["meaning"]  # a pair under one comment (ade_f_min, ade_f_max)
        prev_end = node.end_lineno
        target, value = node.targets[0], node.value
        if (
            isinstance(target, ast.Tuple)
            and isinstance(value, ast.Tuple)
            and len(target.elts) == len(value.elts)
        ):
            pairs = list(zip(target.elts, value.elts))
        else:
            pairs = [(target, value)]
        for t, v in pairs:
            if isinstance(t, ast.Name):
                try:
                    default = ast.literal_eval(v)
                except ValueError:
                    default = ast.get_source_segment(source, v)
                rows.append({"name": t.id, "default": default, "meaning": meaning})
    return rows


def _show_value(v: Any) -> str:
    if isinstance(v, tuple):
        v = list(v)
    return repr(v)


def parameter_table(
    notebook: str | os.PathLike,
    namespace: Mapping[str, Any],
    fold: bool | str = True,
    caption: str = "Parameters of this run",
) -> Table:
    """The parameters cell of ``notebook`` (the code cell tagged ``parameters``, which papermill and
    ``navlib grid`` override) as a table of name, value, unit and meaning: the value is this run's (from
    ``namespace``, the notebook's ``globals()``), with the cell's default beside it where the run changed
    it; the unit comes from the name's suffix (:func:`unit_of`), the meaning from the cell's comments.  In
    a dropdown unless ``fold=False``."""
    rows = []
    for r in parameter_rows(_parameters_cell(notebook)):
        name = r["name"]
        value = namespace.get(name, r["default"])
        shown = _show_value(value)
        if shown != _show_value(r["default"]):
            shown += f" (default {_show_value(r['default'])})"
        rows.append(
            {
                "parameter": name,
                "value": shown,
                "unit": unit_of(name) or "–",
                "meaning": r["meaning"],
            }
        )
    changed = sum("(default " in row["value"] for row in rows)
    summary = f"{caption}: {len(rows)} parameters" + (
        f", {changed} changed from the defaults" if changed else ", all at their defaults"
    )
    return Table(
        pd.DataFrame(rows, columns=["parameter", "value", "unit", "meaning"]),
        index=False,
        caption=summary,
        readable=False,
        fold=summary if fold is True else fold,
    )


def use_style() -> None:
    """The chapter's first call: the figure style of :mod:`navlib.plotstyle` (11-12 pt text, 100 DPI,
    7.5 in default width), and :func:`table` showing readable labels (:func:`readable`)."""
    global READABLE_TABLES
    plotstyle.use_style()
    READABLE_TABLES = True
