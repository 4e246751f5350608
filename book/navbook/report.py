"""How the book shows results: HTML tables that fit the page, numbers glued into the prose, captioned
figures, the chapter's claims with their verdicts, and the headline results file of each chapter.

A chapter notebook uses it like this::

    from navbook import report
    report.use_style()      # figures for the 756 px column, 11-12 pt;
                            # tables with readable labels
    # an HTML table (text/plain kept for nbval)
    report.table(df, formats={"rms (deg)": "{:.3f}"})
    # prose: {glue:text}`ade_rms`
    report.glue_number("ade_rms", 4.23, "{:.2f}")
    # markdown: ```{glue:figure} fig-compass-errors
    report.glue_figure("fig-compass-errors", fig)
    d = verdicts.paired_difference(rms_de, rms_ade)       # the same seeds
    claims = [report.Claim(
        "ADE-BP beats DE-BP", "-0.22..0.20 vs -0.31..0.25 deg", reading="pure DE",
        statistic="RMS DE-BP - RMS ADE-BP, deg", estimate=d, boundary=0.0,
        holds_when="above", unit="deg")]
    # Results at a glance (chapter top)
    report.glue_table("compass_glance", report.glance(claims))
    report.write_results("compass", claims=claims, unit="deg",
                         methods={"ADE-BP": report.method_stats(rms, mins, maxs)})

Every verdict follows from the claim's interval by the one rule of :mod:`navlib.verdicts`.  Every number
shown comes from the code that ran; nothing is typed in.  Rounding happens here, so stored
notebook outputs compare within tolerance (nbval).
"""
from __future__ import annotations

import hashlib
import html
import json
import math
import os
import re
import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping

import pandas as pd

from navlib import claims as registry
from navlib import verdicts
from navlib.claims import Claim, method_stats  # noqa: F401  (the chapters' API: report.Claim, report.method_stats)
from navlib.data.tables import write_new
from navlib.errors import InputError
from navlib.formatting import fmt, plain  # noqa: F401  (report.fmt, report.plain)
from navlib import plotstyle
# The figure style, for the chapters as report.panels(...), report.legend_below(...):
from navlib.plotstyle import legend_below, legend_right, panel_grid, panels, staircase  # noqa: F401

#: The environment variable that says where results files go (the book's build sets it to its own folder).
RESULTS_ENV = "NAVBOOK_RESULTS_DIR"
#: Plain-text rendering width in characters; a stored output line longer than this would be cut on the page.
PLAIN_WIDTH = 92
METHOD_KEYS = ("median_rms", "p10_rms", "p90_rms", "median_min", "median_max")

_CSS = ("table-layout:auto;width:100%;max-width:100%;border-collapse:collapse;font-size:0.85em;"
        "margin-bottom:0.5em")
_CELL = "padding:2px 6px;border-bottom:1px solid #ddd;vertical-align:top;overflow-wrap:break-word;"


def results_dir() -> Path:
    """The folder results files go to: ``$NAVBOOK_RESULTS_DIR`` if it is set and not empty, else ``results/``
    in the current directory (library use; never a folder of the installed package).  ``make test``
    sets the variable to ``book/_generated/results``; ``python -m navbook execute`` (``make book``,
    ``make notebooks``) sets it to a temporary folder for each notebook and copies the files written there
    to ``book/_generated/results`` (or ``notebooks/results``)."""
    env = os.environ.get(RESULTS_ENV)
    return Path(env) if env else Path.cwd() / "results"


# ----------------------------------------------------------------------------------------------- tables
def _breakable(text: str) -> str:
    """HTML-escaped ``text`` with ``<wbr>`` (an optional line break) after underscores, slashes and commas."""
    return re.sub(r"([_/,])(?=\S)", r"\1<wbr>", html.escape(str(text), quote=False))


#: Set by :func:`use_style`: tables show readable labels (:func:`readable`) unless
#: asked otherwise.
READABLE_TABLES = False

#: Unit suffixes of snake_case names and how a column header shows them.
UNIT_SUFFIXES = {("deg", "h"): "deg/h", ("mg", "g"): "mg/g", ("m", "s"): "m/s", ("deg",): "deg",
                 ("rad",): "rad", ("arcmin",): "arcmin", ("arcsec",): "arcsec", ("nmi",): "nmi",
                 ("ug",): "ug", ("mg",): "mg", ("ut",): "uT", ("nt",): "nT", ("c",): "degC",
                 ("s",): "s", ("h",): "h", ("pct",): "%", ("ppm",): "ppm"}
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
    words = words[:len(words) - k]
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

    def __init__(self, frame: pd.DataFrame, formats: Mapping[str, Any] | None = None,
                 caption: str | None = None, index: bool = True, readable: bool | None = None,
                 fold: bool | str | None = None):
        if not isinstance(frame, pd.DataFrame):
            frame = pd.DataFrame(frame)
        if fold is True and not caption:
            raise InputError("report.table: fold=True needs a caption (it is the dropdown's summary)")
        if fold is None:                    # the chapter's default (fold_tables): evidence behind its caption
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
                    out[col] = s.map(lambda v: "–" if v is None or (isinstance(v, float) and math.isnan(v))
                                     else str(v))
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
        styler = styler.set_uuid(f"t{digest}")      # stable across runs, distinct per table
        styler = styler.set_table_attributes(f'class="navbook-table" style="{_CSS}"')
        styler = styler.set_table_styles([{"selector": "th", "props": _CELL + "text-align:left;"},
                                          {"selector": "td", "props": _CELL}])
        if self.caption and not self.fold:
            styler = styler.set_caption(self.caption)
        if self.fold:
            return (f'<details class="navbook-fold"><summary>{html.escape(self.fold, quote=False)}</summary>'
                    f"{styler.to_html()}</details>")
        return styler.to_html()

    def __repr__(self) -> str:
        f = self.formatted()
        width = PLAIN_WIDTH
        clip = f.map(lambda s: s if len(s) <= 40 else s[:37] + "...")
        text = clip.to_string(index=self.index, line_width=width)
        lines = [ln if len(ln) <= width else ln[:width - 3] + "..." for ln in text.splitlines()]
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


def table(frame: pd.DataFrame, formats: Mapping[str, Any] | None = None, caption: str | None = None,
          index: bool = True, readable: bool | None = None, fold: bool | str | None = None) -> Table:
    """Shorthand for :class:`Table`; the last expression of a cell displays it (``fold``: in a dropdown;
    None: the chapter's default, :func:`fold_tables`)."""
    return Table(frame, formats, caption, index, readable, fold)


# ----------------------------------------------------------------------------------------------- parameters
#: Unit suffixes of parameter names beyond :data:`UNIT_SUFFIXES` (which also label table columns).
PARAMETER_UNITS = {("deg", "rt", "h"): "deg/sqrt(h)", ("hz",): "Hz", ("m",): "m", ("ms2",): "m/s^2",
                   ("dps",): "deg/s", ("ppm",): "ppm", ("g",): "g"}


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
        if cell.get("cell_type") == "code" and "parameters" in cell.get("metadata", {}).get("tags", []):
            src = cell.get("source", "")
            return "".join(src) if isinstance(src, list) else str(src)
    raise InputError(f"{path}: no cell tagged 'parameters'")


def parameter_rows(source: str) -> list[dict]:
    """The assignments of a notebook's parameters cell, in order: ``name``, ``default`` (the literal
    assigned; a tuple assignment gives one row per name) and ``meaning`` (the comment on the
    assignment's lines, after the block of comment lines right above it; an assignment without a comment
    right under another one shares its meaning)."""
    import ast
    import io
    import tokenize

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
        while n >= 1 and n in comments and n not in code_lines and lines[n - 1].lstrip().startswith("#"):
            above.insert(0, comments[n])
            n -= 1
        beside = [comments[k] for k in range(node.lineno, node.end_lineno + 1) if k in comments]
        meaning = "; ".join(x for x in (" ".join(above), " ".join(beside)) if x)
        if not meaning and rows and prev_end == node.lineno - 1:
            meaning = rows[-1]["meaning"]          # a pair under one comment (ade_f_min, ade_f_max)
        prev_end = node.end_lineno
        target, value = node.targets[0], node.value
        if isinstance(target, ast.Tuple) and isinstance(value, ast.Tuple) and len(target.elts) == len(value.elts):
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


def parameter_table(notebook: str | os.PathLike, namespace: Mapping[str, Any], fold: bool | str = True,
                    caption: str = "Parameters of this run") -> Table:
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
        rows.append({"parameter": name, "value": shown, "unit": unit_of(name) or "–", "meaning": r["meaning"]})
    changed = sum("(default " in row["value"] for row in rows)
    summary = f"{caption}: {len(rows)} parameters" + (f", {changed} changed from the defaults" if changed else
                                                      ", all at their defaults")
    return Table(pd.DataFrame(rows, columns=["parameter", "value", "unit", "meaning"]), index=False,
                 caption=summary, readable=False, fold=summary if fold is True else fold)


# ----------------------------------------------------------------------------------------------- glue
def _glue(name: str, obj: Any) -> None:
    from myst_nb import glue

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
    import matplotlib.pyplot as plt

    _glue(name, fig)
    plt.close(fig)


def glue_png(name: str, path) -> None:
    """Glue a PNG file (e.g. the figure ``navlib loop --report`` wrote) for a MyST ``{glue:figure}``
    directive; the image is read now, so the file may be removed afterwards."""
    from IPython.display import Image

    _glue(name, Image(data=Path(path).read_bytes(), format="png"))


def use_style() -> None:
    """The chapter's first call: the figure style of :mod:`navlib.plotstyle` (11-12 pt text, 100 DPI,
    7.5 in default width), and :func:`table` showing readable labels (:func:`readable`)."""
    global READABLE_TABLES
    plotstyle.use_style()
    READABLE_TABLES = True


GLANCE_COLUMNS = ["claim", "reading", "paper", "ours: value [95 % interval]", "boundary", "verdict"]
#: How the book names the claims judged on real measurements (``Claim.data == "real"``), counted apart.
ON_REAL = "on real data"


def _glance_frame(claims: list[Claim]) -> pd.DataFrame:
    rows = [{"claim": c.claim, "reading": c.reading, "paper": c.paper, GLANCE_COLUMNS[3]: c.ours_text,
             "boundary": c.boundary_text, "verdict": c.verdict + (f": {c.reason}" if c.reason else "")}
            for c in claims]
    return pd.DataFrame(rows, columns=GLANCE_COLUMNS)


def tally_of(v: list[str]) -> str:
    """"k of n reproduced, m not reproduced, j cannot be judged" (", e no difference" where a claim's
    equivalence margin decided it) for a list of verdict names."""
    text = (f"{v.count('reproduced')} of {len(v)} reproduced, {v.count('not reproduced')} not reproduced, "
            f"{v.count('cannot be judged')} cannot be judged")
    return text + (f", {v.count('no difference')} no difference" if v.count("no difference") else "")


def tally(claims: Iterable[Claim]) -> str:
    """"k of n reproduced, m not reproduced, j cannot be judged" (:func:`tally_of`)."""
    return tally_of([c.verdict for c in claims])


#: Abbreviations of the results files' reading labels, spelled out on the landing page and in the glance
#: boxes' folds (the glossary
#: explains the methods' names).
READING_WORDS = {r"\bval\. stop\b": "validation stop", r"\bsd\b": "standard deviations",
                 r"\bKF\b": "Kalman filter", r"\bLOO\b": "leave-one-out"}


def reading_label(reading: str) -> str:
    """A reading's label as the landing page shows it: a leading number ("2: DE + trainlm, val. stop")
    moves to the end ("DE + trainlm, validation stop (reading 2)"), abbreviations are spelled out
    (:data:`READING_WORDS`) and the first letter is a capital."""
    text = str(reading).strip()
    m = re.match(r"^(\d+)\s*:\s*(.+)$", text)
    if m:
        text = f"{m.group(2)} (reading {m.group(1)})"
    for pattern, words in READING_WORDS.items():
        text = re.sub(pattern, words, text)
    return text[:1].upper() + text[1:]


#: The (claim, reading) pairs shown in a glance box in this process (:func:`write_results` warns about the
#: claims it writes that none showed: the landing page counts them, the chapter's glance box would not).
_GLANCED: set[tuple[str, str, str]] = set()
#: A glance table with more rows than this is folded by reading on the page (one dropdown per reading).
GLANCE_OPEN_ROWS = 12
#: Where a chapter page's glance box links the definitions of the verdicts (the landing page's box).
VERDICTS_HREF = "../intro.html#what-the-verdicts-mean"


def _glance_html(claims: list[Claim], caption: str) -> str:
    """One glance table in HTML: the verdict with the case that applies (*cannot be judged: below our
    noise floor*, ...); more than :data:`GLANCE_OPEN_ROWS` claims are folded by reading, each reading a
    ``<details>`` whose summary gives its counts."""
    def frame(cs, with_reading=True):
        rows = [{"claim": c.claim, "reading": c.reading, "paper": c.paper, GLANCE_COLUMNS[3]: c.ours_text,
                 "boundary": c.boundary_text,
                 "verdict": c.verdict_label + (f" ({c.reason})" if c.reason else "")} for c in cs]
        cols = GLANCE_COLUMNS if with_reading else [k for k in GLANCE_COLUMNS if k != "reading"]
        return pd.DataFrame(rows, columns=GLANCE_COLUMNS)[cols]

    link = (f'<p class="navbook-glance-note">{html.escape(caption, quote=False)} (<a href="{VERDICTS_HREF}">what the '
            f'verdicts mean</a>)</p>')
    if len(claims) <= GLANCE_OPEN_ROWS:
        return link + Table(frame(claims), index=False)._repr_html_()
    readings = list(dict.fromkeys(c.reading for c in claims))
    parts = [link]
    for r in readings:
        cs = [c for c in claims if c.reading == r]
        parts.append(f"<details><summary>{html.escape(reading_label(r))}: {html.escape(tally(cs))}</summary>"
                     + Table(frame(cs, with_reading=False), index=False)._repr_html_() + "</details>")
    return "\n".join(parts)


def register_records(claims: Iterable["Claim | Mapping[str, Any]"], chapter: str | None,
                     worlds: list[Mapping[str, Any]] | None = None) -> list[dict] | None:
    """The chapter's rows folded into one record per claims-register entry (:func:`navlib.claims.evaluate`),
    or None for a chapter without a register."""
    if not chapter or not registry.registers(chapter):
        return None
    rows = [c.record() if isinstance(c, Claim) else dict(c) for c in claims]
    return registry.evaluate(chapter, rows, worlds)


def record_label(r: Mapping[str, Any]) -> str:
    """A stored record's verdict as the book shows it (*cannot be judged: within our noise floor*)."""
    if r.get("reproduced") is not None:
        return str(r["verdict"])
    if r.get("basis") == "equivalent":
        return f"no difference at margin {fmt(r.get('margin'), '{:.4g}')}" + (f" {r['unit']}" if r.get("unit") else "")
    cat = r.get("reason")
    return f"{r['verdict']}: {verdicts.REASONS[cat][0]}" if cat in verdicts.REASONS else str(r["verdict"])


def _rec_ours(r: Mapping[str, Any]) -> str:
    if r.get("rule") == "no statistic":
        return "–"
    b = r.get("boundary")
    side = "< " if r.get("holds_when") == "below" else "> "
    unit = f" {r['unit']}" if r.get("unit") else ""
    return f"{r.get('ours') or '–'} (boundary {side}{fmt(b, '{:.4g}')}{unit})"


def headline_sentence(r: Mapping[str, Any]) -> str:
    """One sentence: a source's headline claim (the register's words for it, and where the paper makes
    it) and its verdict under the primary reading, with our interval and how the verdict moves across the
    other readings."""
    who = registry.SOURCE_NAMES.get(r.get("register", ""), "The source")
    where = str(r["where"]).split(";")[0].strip()
    text = f"{who}'s headline claim: {r['claim']} ({where}). **{record_label(r)}**"
    if r.get("status") == "judged" and r.get("row_claim"):
        text += (f" under the primary reading ({r['primary_reading']}): ours {_rec_ours(r)}; "
                 f"{registry.across_text(r)}.")
    else:
        text += "."
    return text


def _rec_tally(records: list[Mapping[str, Any]]) -> str:
    return tally_of([r["verdict"] for r in records])


ANSWER_COLUMNS = ["id", "claim", "ours: value [95 % interval]", "verdict (primary reading)", "across readings"]


def _answer_frame(records: list[Mapping[str, Any]]) -> pd.DataFrame:
    """One row per claim: the register's short words for it (the paper's own words, where they are and
    why the primary reading is the most plausible are in the claim's fold below the table)."""
    rows = [{"id": r["id"], "claim": r["claim"], ANSWER_COLUMNS[2]: _rec_ours(r),
             ANSWER_COLUMNS[3]: record_label(r) + (f" ({r['primary_reading']})" if r.get("status") == "judged"
                                                 and r.get("row_claim") else ""),
             "across readings": registry.across_text(r) if r.get("status") == "judged" and r.get("row_claim")
             else "–"}
            for r in records]
    return pd.DataFrame(rows, columns=ANSWER_COLUMNS)


def _claim_fold(r: Mapping[str, Any]) -> str:
    """One claim's fold: the paper's words and where, the primary reading and why, the dimensions, and
    every row (the primary first) with its verdict and reason."""
    head = (f"<p><b>{html.escape(r['id'])}</b> \u201c{html.escape(r.get('quote') or r['claim'])}\u201d "
            f"({html.escape(r['where'])})")
    if r.get("quote_zh"):
        head += f' <span lang="zh">{html.escape(r["quote_zh"])}</span>'
    head += "</p>"
    if r.get("why_primary"):
        head += (f"<p>Primary reading: {html.escape(r['primary_reading'])}. "
                 f"{html.escape(r['why_primary'])}</p>")
    if r.get("dimensions"):
        head += f"<p>Shown across: {html.escape(r['dimensions'])}.</p>"
    if r.get("status") != "judged" or not r.get("row_claim"):
        return head + f"<p>{html.escape(r.get('why') or '')}</p>"
    rows = [{**r, "claim": r["row_claim"]}] + list(r["sensitivity"])
    frame = pd.DataFrame([{"claim": x["claim"], "reading": x["reading"] + (" (primary)" if x is rows[0] else ""),
                           "ours: value [95 % interval]": x.get("ours") or "–",
                           "verdict": record_label(x) + (f" ({x['why']})" if x.get("why") else "")}
                          for x in rows])
    return head + Table(frame, index=False, readable=False)._repr_html_()


class Answer:
    """A chapter's opening for a chapter with a claims register (:mod:`navlib.claims`): each source's
    headline claim and its verdict under the primary reading, then one row per claim (the paper's words
    and where, ours with its interval and boundary, the verdict under the primary reading, how it moves
    across the other readings and drawn worlds), the paper's own contradictions, and the per-reading
    tables of every row behind a fold.  The tallies count claims (register entries), not readings: the
    landing page counts the same from the results file."""

    def __init__(self, records: list[dict], chapter: str):
        self.records, self.chapter = records, chapter
        self.noted = registry.inconsistencies(chapter)

    def _groups(self):
        """(source, title, records) per source, the records on real data (``"data": "real"``) after the
        simulated ones and counted apart."""
        for data, suffix in (("simulated", ""), ("real", f" {ON_REAL}")):
            for src, title in (("paper", "The paper's claims"), ("book", "The book's own claims")):
                recs = [r for r in self.records if r["source"] == src and registry.data_of(r) == data]
                if recs:
                    yield src, title + suffix, recs

    def tables(self) -> list[Table]:
        out = []
        for src, title, recs in self._groups():
            for name in registry.registers(self.chapter):
                mine = [r for r in recs if r["register"] == name]
                if mine:
                    out.append(Table(_answer_frame(mine), index=False, readable=False,
                                     caption=f"{title}: {_rec_tally(recs)}; "
                                             f"{registry.SOURCE_NAMES[name]}: {_rec_tally(mine)}"))
        if self.noted:
            out.append(Table(pd.DataFrame([{"id": n["id"], "the paper says": n["claim"], "where": n["where"],
                                            "its own numbers": n["numbers"]} for n in self.noted]),
                             index=False, readable=False, caption="Where the paper contradicts itself"))
        return out

    def _repr_html_(self) -> str:
        parts = []
        for r in registry.headlines(self.records):
            parts.append(f'<p class="navbook-headline">{_inline_md(headline_sentence(r))}</p>')
        for src, title, recs in self._groups():
            real = registry.data_of(recs[0]) == "real"
            note = (f'{html.escape(title)}: {_rec_tally(recs)} (one row per claim, judged under its primary '
                    f'reading; <a href="{VERDICTS_HREF}">what the verdicts mean</a>)')
            # the claims judged again on real data: counted apart, their tables behind a fold
            parts.append(f'<details class="navbook-real"><summary class="navbook-glance-note">{note}</summary>'
                         if real else f'<p class="navbook-glance-note">{note}</p>')
            for name in registry.registers(self.chapter):
                mine = [r for r in recs if r["register"] == name]
                if mine:
                    if len(registry.registers(self.chapter)) > 1:
                        parts.append(f"<p><b>{html.escape(registry.SOURCE_NAMES[name])}</b>: "
                                     f"{_rec_tally(mine)}</p>")
                    parts.append(Table(_answer_frame(mine), index=False, readable=False)._repr_html_())
            if real:
                parts.append("</details>")
        if self.noted:
            parts.append(f"<details><summary>Where the paper contradicts itself ({len(self.noted)})</summary>"
                         + Table(self.tables()[-1].frame, index=False, readable=False)._repr_html_()
                         + "</details>")
        parts.append(self._readings_html())
        return "\n".join(parts)

    def _readings_html(self) -> str:
        """Every claim behind one fold, a dropdown per claim: the paper's words and where, the primary
        reading and why, and every row (each reading, noise level, split; the primary first)."""
        n = sum(1 + len(r["sensitivity"]) for r in self.records if r.get("row_claim"))
        inner = [f"<details><summary>{html.escape(r['id'])} {html.escape(r['claim'])}"
                 f"{' (' + ON_REAL + ')' if registry.data_of(r) == 'real' else ''}: "
                 f"{html.escape(registry.across_text(r) if r.get('row_claim') else record_label(r))}</summary>"
                 + _claim_fold(r) + "</details>" for r in self.records]
        return (f'<details><summary>The paper\'s words, the primary reading and why, and every claim under '
                f'every reading ({n} rows)</summary>' + "\n".join(inner) + "</details>")

    def __repr__(self) -> str:
        out = ["\n".join(textwrap.wrap(headline_sentence(r).replace("**", ""), PLAIN_WIDTH))
               for r in registry.headlines(self.records)]
        out += [repr(t) for t in self.tables()]
        return "\n\n".join(out)


def _inline_md(text: str) -> str:
    """HTML of a sentence with **bold** marks."""
    return re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", html.escape(text, quote=False))


class Glance:
    """The Results-at-a-glance tables: the paper's claims and the book's own claims apart, each row with
    the claim, the reading, the paper's number, ours with its 95 % interval, the boundary and the verdict
    with its reason.  Give it every claim of the chapter (the list passed to :func:`write_results`): the
    landing page counts that list, and a glance that shows fewer claims disagrees with it (``navbook
    check-html`` compares the two).  On the page, a long list is folded by reading and each verdict says
    which case applies (:func:`navlib.verdicts.verdict_label`); the plain text (what nbval compares) is
    one table per source."""

    def __init__(self, claims: Iterable[Claim]):
        claims = list(claims)
        sim = [c for c in claims if c.data == "simulated"]
        self.paper = [c for c in sim if c.source == "paper"]
        self.book = [c for c in sim if c.source == "book"]
        self.real = {src: [c for c in claims if c.data == "real" and c.source == src] for src in verdicts.SOURCES}
        _GLANCED.update((c.claim, c.reading, c.data) for c in claims)

    def _groups(self):
        """(caption, claims) per source, the claims on real data after the simulated ones, each apart."""
        for cs, title in ((self.paper, "The paper's claims"), (self.book, "The book's own claims"),
                          (self.real["paper"], f"The paper's claims {ON_REAL}"),
                          (self.real["book"], f"The book's own claims {ON_REAL}")):
            if cs:
                yield f"{title}: {tally(cs)}", cs

    def tables(self) -> list[Table]:
        return [Table(_glance_frame(cs), index=False, caption=caption) for caption, cs in self._groups()]

    def _repr_html_(self) -> str:
        return "\n".join(_glance_html(cs, caption) for caption, cs in self._groups())

    def __repr__(self) -> str:
        return "\n\n".join(repr(t) for t in self.tables())


def glance(claims: Iterable[Claim], chapter: str | None = None,
           worlds: list[Mapping[str, Any]] | None = None) -> "Glance | Answer":
    """The Results-at-a-glance box: for a chapter with a claims register (``chapter`` given,
    :mod:`navlib.claims`) the answer first (:class:`Answer`: one row per claim under its primary
    reading, ``worlds`` the drawn-world verdicts of the rows), else one row per claim and reading
    (:class:`Glance`)."""
    claims = list(claims)
    records = register_records(claims, chapter, worlds)
    if records is None:
        return Glance(claims)
    _GLANCED.update((c.claim, c.reading, c.data) for c in claims)
    return Answer(records, chapter)


@dataclass(frozen=True)
class _Outcome:
    claim: str
    reading: str
    source: str
    verdict: str
    category: str | None      # the key of verdicts.REASONS of a claim that cannot be judged
    data: str = "simulated"   # what it was judged on (Claim.data)


def _outcome(c: "Claim | Mapping[str, Any]") -> _Outcome:
    """A claim or a results file's claim record, reduced to what the summary boxes need."""
    if isinstance(c, Claim):
        c = c.record()
    try:
        return _Outcome(str(c["claim"]), str(c.get("reading", "")), str(c["source"]), str(c["verdict"]),
                        c.get("reason") if c["verdict"] == "cannot be judged" else None,
                        registry.data_of(c))
    except (KeyError, TypeError, AttributeError):
        raise InputError(f"a claim record without claim, source and verdict: {str(c)[:80]}") from None


def _reason_counts(cs: list[_Outcome]) -> str:
    cats = [c.category for c in cs if c.verdict == "cannot be judged"]
    counts = {k: cats.count(k) for k in dict.fromkeys(cats) if k in verdicts.REASONS}
    return ", ".join(f"{n} {verdicts.REASONS[k][0]}" for k, n in counts.items())


def _claim_outcome(cs: list[_Outcome]) -> str:
    """One claim's verdicts over its readings in words: the verdict when there is one reading or every
    reading agrees, else how many readings give each verdict."""
    v = [c.verdict for c in cs]
    if len(set(v)) == 1:
        head = v[0] if len(v) == 1 else f"{v[0]} in all {len(v)} readings"
        if v[0] == "cannot be judged":
            why = _reason_counts(cs)
            head += f" ({why})" if why else ""
        return head
    parts = [f"{name} in {v.count(name)}" for name in verdicts.VERDICTS if v.count(name)]
    return ", ".join(parts) + f" of {len(v)} readings"


class Showed:
    """The *What this chapter showed* box at a chapter's end, built from the same claims as the glance box
    and the landing page (:class:`Claim` objects or the claim records of a results file): per source (the
    paper's claims, the book's own), the tally with the reasons of the claims that cannot be judged, and
    one line per claim with its verdicts over the readings."""

    def __init__(self, claims: Iterable["Claim | Mapping[str, Any]"], found: Mapping[Any, str] | None = None):
        outs = [_outcome(c) for c in claims]
        parts = [(title + suffix, [c for c in outs if c.source == src and c.data == data])
                 for data, suffix in (("simulated", ""), ("real", f" {ON_REAL}"))
                 for src, title in (("paper", "The paper's claims"), ("book", "The book's own claims"))]
        self.parts = [(t, cs) for t, cs in parts if cs]
        self.found = dict(found or {})

    def _rows(self, cs: list[_Outcome]) -> pd.DataFrame:
        """One row per claim; ``found`` is looked up by ``(claim, data)``, then by the claim alone."""
        names = list(dict.fromkeys(c.claim for c in cs))
        data = cs[0].data if cs else "simulated"
        return pd.DataFrame([{"claim": n, "what we found": self.found.get((n, data)) or self.found.get(n) or
                              _claim_outcome([c for c in cs if c.claim == n])}
                             for n in names], columns=["claim", "what we found"])

    @staticmethod
    def _lead(title: str, cs: list[_Outcome]) -> str:
        why = _reason_counts(cs)
        return f"{title}: {tally(cs)}" + (f" ({why})" if why else "")

    def _repr_html_(self) -> str:
        out = []
        for title, cs in self.parts:
            out.append(f'<p class="navbook-showed">{html.escape(self._lead(title, cs), quote=False)}</p>')
            out.append("<details><summary>Claim by claim</summary>"
                       + Table(self._rows(cs), index=False, readable=False)._repr_html_() + "</details>")
        return "\n".join(out)

    def __repr__(self) -> str:
        out = []
        for title, cs in self.parts:
            out.extend(textwrap.wrap(self._lead(title, cs), PLAIN_WIDTH))
            out.append(repr(Table(self._rows(cs), index=False, readable=False)))
        return "\n".join(out)


def showed(claims: Iterable[Claim], chapter: str | None = None,
           worlds: list[Mapping[str, Any]] | None = None) -> Showed:
    """The *What this chapter showed* box (see :class:`Showed`); glue it into a ``:::{admonition} What
    this chapter showed`` block at the chapter's end.  With ``chapter`` (a chapter with a claims
    register) it counts claims, one per register entry, with the verdict under the primary reading."""
    claims = list(claims)
    records = register_records(claims, chapter, worlds)
    if records is None:
        return Showed(claims)
    found = {(r["claim"], registry.data_of(r)): record_label(r) + (
        f" (primary reading; {registry.across_text(r)})" if r.get("status") == "judged" and r.get("row_claim")
        else "") for r in records}
    return Showed([{**r, "reading": "primary"} for r in records], found)


def glue_claims(claims: Iterable[Claim]) -> None:
    """Glue, for every claim with a ``key``, its verdict (``{glue:text}`key```) and a sentence with the
    interval and the boundary (``{glue:text}`key_detail```), so prose that states a verdict comes from the
    claim itself."""
    for c in claims:
        if not c.key:
            continue
        glue_text(c.key, c.verdict)
        detail = f"{c.verdict}: ours {c.interval_text}, boundary {c.boundary_text}"
        glue_text(f"{c.key}_detail", detail + (f" ({c.reason})" if c.reason else ""))


# ----------------------------------------------------------------------------------------------- results
def write_results(chapter: str, *, claims: Iterable[Claim], unit: str | None = None,
                  methods: Mapping[str, Mapping[str, Any]] | None = None,
                  extra: Mapping[str, Any] | None = None, folder: str | os.PathLike | None = None,
                  overwrite: bool = False, tables: Mapping[str, Iterable[Mapping[str, Any]]] | None = None,
                  register: bool = False, worlds: list[Mapping[str, Any]] | None = None) -> Path:
    """Write ``<folder>/<chapter>.json`` (``folder`` defaults to :func:`results_dir`)::

        {"chapter": ..., "unit": ..., "methods": {label: {"median_rms_<unit>", "p10_rms_<unit>",
         "p90_rms_<unit>", "median_min_<unit>", "median_max_<unit>", "n_seeds"}},
         "claims": [{"claim", "paper", "ours", "reproduced", "verdict", "reading",
                     "why"}],
         "extra": {...}}

    ``methods`` maps a display label to :func:`method_stats`-style keys (without unit suffix); the unit
    (e.g. ``deg``, ``mg``, ``arcsec``) is appended to each statistic's name.  Values are rounded to 6
    significant digits.  ``tables`` adds top-level lists of records (e.g. ``"robustness"``: one
    ``{"compass", "claim", "reading", "verdict"}`` per simulated compass, claim and reading); their names
    must not be one of the keys above.  ``register=True`` (a chapter with a claims register,
    :mod:`navlib.claims`) stores one record per register entry instead of one per claim and reading: the
    primary row's fields, the register's words and place, the other rows as its ``sensitivity`` list
    (``worlds``: the rows' verdicts on other drawn simulators, ``{"compass", "claim", "reading",
    "verdict"}``, summarised in each record's ``across``), and the paper's contradictions as
    ``inconsistencies``.  An existing file (an earlier run's) is never replaced unless
    ``overwrite=True``: the call stops with one line naming it.  Returns the path written; it displays as ``results written:
    <chapter>.json``, the same in every run, so a notebook cell that ends with this call shows no
    run-specific folder."""
    if not chapter.isidentifier():
        raise InputError(f"chapter name {chapter!r}: use letters, digits and underscores")
    out: dict[str, Any] = {"chapter": chapter}
    if methods:
        if not unit:
            raise InputError("write_results: methods need a unit (e.g. unit='deg')")
        out["unit"] = unit
        out["methods"] = {}
        for label, stats in methods.items():
            entry = {}
            for k, v in stats.items():
                key = k if k == "n_seeds" or k.endswith(f"_{unit}") else f"{k}_{unit}"
                entry[key] = plain(v)
            out["methods"][str(label)] = entry
    claims = list(claims)
    if not claims:
        raise InputError(f"write_results({chapter!r}): a chapter states at least one claim")
    if not all(isinstance(c, Claim) for c in claims):
        raise InputError(f"write_results({chapter!r}): claims must be navlib.claims.Claim objects")
    keys = [(c.claim, c.reading) for c in claims]
    both = [(c.claim, c.reading, c.data) for c in claims]
    if len(set(both)) != len(both):
        dup = next(k for k in both if both.count(k) > 1)
        raise InputError(f"write_results({chapter!r}): claim {dup[0]!r} appears twice under reading {dup[1]!r}"
                         + (" on real data" if dup[2] == "real" else ""))
    records = register_records(claims, chapter if register else None, worlds)
    out["claims"] = records if records is not None else [c.record() for c in claims]
    if records is not None:
        out["inconsistencies"] = registry.inconsistencies(chapter)
    unseen = [k for k in both if k not in _GLANCED]
    if _GLANCED and unseen:                 # a chapter that shows a glance box, but not all of its claims
        import warnings
        warnings.warn(f"write_results({chapter!r}): {len(unseen)} of the {len(keys)} claims are in no glance "
                      f"box (first: {unseen[0][0]!r}, {unseen[0][1]!r}); the landing page counts every claim "
                      f"written: pass them all to report.glance", stacklevel=2)
    if extra:
        out["extra"] = {str(k): plain(v) if not isinstance(v, (list, tuple)) else [plain(x) for x in v]
                        for k, v in extra.items()}
    for name, table_rows in (tables or {}).items():
        if name in ("chapter", "unit", "methods", "claims", "extra", "inconsistencies") or not str(name).isidentifier():
            raise InputError(f"write_results({chapter!r}): table name {name!r} is reserved or not an identifier")
        out[str(name)] = [{str(k): plain(v) for k, v in dict(r).items()} for r in table_rows]
    d = Path(folder) if folder is not None else results_dir()
    text = json.dumps(out, indent=1, ensure_ascii=False, allow_nan=False) + "\n"
    path = d / f"{chapter}.json"
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InputError(f"{d}: cannot create the results folder ({err.strerror})") from None
    try:
        write_new(path, lambda fh: fh.write(text), overwrite=overwrite,
                  exists=f"a results file is already there (an earlier run's); remove it, write elsewhere "
                         f"(folder=... or ${RESULTS_ENV}) or pass overwrite=True")
    except OSError as err:
        raise InputError(f"{path}: cannot write the results file ({err.strerror})") from None
    return _WrittenPath(path)


class _WrittenPath(type(Path())):
    """A :class:`pathlib.Path` whose display names only the file (stable across runs and machines)."""

    def __repr__(self) -> str:
        return f"results written: {self.name}"


def read_results(folder: str | os.PathLike | None = None) -> dict[str, dict]:
    """Every results file in ``folder`` (default :func:`results_dir`), keyed by chapter."""
    d = Path(folder) if folder is not None else results_dir()
    out = {}
    for p in sorted(d.glob("*.json")):
        try:
            out[p.stem] = json.loads(p.read_text(encoding="utf-8"))
        except json.JSONDecodeError as err:
            raise InputError(f"{p.name}: not valid JSON ({err.msg}, line {err.lineno})") from None
    return out


def read_result(path: str | os.PathLike) -> dict:
    """One results file (:func:`write_results`), e.g. to build a chapter's tables from what it wrote."""
    p = Path(path)
    try:
        return json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{p}: no results file there") from None
    except json.JSONDecodeError as err:
        raise InputError(f"{p.name}: not valid JSON ({err.msg}, line {err.lineno})") from None


def claims_summary(results: Mapping[str, dict]) -> pd.DataFrame:
    """Per chapter, source (the paper's claims or the book's own), data (``simulated`` or ``real``: the
    claims judged on real measurements apart) and reading: claims reproduced, not reproduced, cannot be
    judged (for the landing page)."""
    rows = []
    for chapter, res in results.items():
        for c in res.get("claims", []):
            rows.append({"chapter": chapter, "source": c.get("source", "paper"), "data": registry.data_of(c),
                         "reading": c.get("reading", "as printed"), "reproduced": c.get("reproduced")})
    cols = ["chapter", "source", "data", "reading", "claims", "reproduced", "not reproduced", "cannot be judged"]
    if not rows:
        return pd.DataFrame(columns=cols)
    df = pd.DataFrame(rows)
    g = df.groupby(["chapter", "source", "data", "reading"], sort=False)["reproduced"]
    return pd.DataFrame({"claims": g.size(),
                         "reproduced": g.apply(lambda s: int((s == True).sum())),  # noqa: E712
                         "not reproduced": g.apply(lambda s: int((s == False).sum())),  # noqa: E712
                         "cannot be judged": g.apply(lambda s: int(s.isna().sum()))}).reset_index()[cols]
