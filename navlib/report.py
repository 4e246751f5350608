"""How the book shows results: HTML tables that fit the page, numbers glued into the prose, captioned
figures, the chapter's claims with their verdicts, and the headline results file of each chapter.

A chapter notebook uses it like this::

    from navlib import report
    report.style()                                        # figure fonts readable at the displayed size
    report.table(df, formats={"rms (deg)": "{:.3f}"})     # an HTML table (text/plain kept for nbval)
    report.glue_number("ade_rms", 4.23, "{:.2f}")         # prose: {glue:text}`ade_rms`
    report.glue_figure("fig-compass-errors", fig)         # markdown: ```{glue:figure} fig-compass-errors
    claims = [report.Claim("ADE-BP beats DE-BP", "-0.22..0.20 vs -0.31..0.25", "4.2 vs 10.4 deg RMS",
                           True, reading="pure DE")]
    report.glue_table("glance", report.glance(claims))    # Results at a glance (top of the chapter)
    report.write_results("compass", methods=summary_frame, claims=claims)

Every number shown comes from the code that ran; nothing is typed in.  Rounding happens here, so stored
notebook outputs compare within tolerance (nbval).
"""
from __future__ import annotations

import json
import math
import zlib
import os
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np
import pandas as pd

from .errors import InputError
from .paths import ROOT

#: Where each chapter's headline results are written during a build (git-ignored).
RESULTS_DIR = ROOT / "book" / "_generated" / "results"
#: Plain-text rendering width (characters): a stored output line longer than this would be cut on the page.
PLAIN_WIDTH = 92
METHOD_KEYS = ("median_rms", "p10_rms", "p90_rms", "median_min", "median_max")

_CSS = ("table-layout:auto;width:100%;max-width:100%;border-collapse:collapse;font-size:0.85em;"
        "margin-bottom:0.5em")
_CELL = "padding:2px 6px;border-bottom:1px solid #ddd;vertical-align:top;overflow-wrap:anywhere;"


def results_dir() -> Path:
    """The folder results files go to: ``$NAVBOOK_RESULTS_DIR`` if set, else :data:`RESULTS_DIR`."""
    env = os.environ.get("NAVBOOK_RESULTS_DIR")
    return Path(env) if env else RESULTS_DIR


# ----------------------------------------------------------------------------------------------- numbers
def plain(value: Any, digits: int = 6) -> Any:
    """A JSON- and display-safe Python value: numpy scalars become Python numbers rounded to ``digits``
    significant digits, NaN becomes None; strings, bools and None pass through."""
    if value is None or isinstance(value, (str, bool)):
        return value
    if isinstance(value, (np.bool_,)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            return None
        return float(f"{v:.{digits}g}")
    raise InputError(f"cannot store a {type(value).__name__} as a result value")


def fmt(value: Any, spec: str = "{:.3g}") -> str:
    """Format a number for prose or a table cell; NaN/None become an en dash."""
    if value is None or (isinstance(value, (float, np.floating)) and not math.isfinite(float(value))):
        return "–"
    if isinstance(value, (np.floating, np.integer)):
        value = value.item()
    return spec.format(value)


# ----------------------------------------------------------------------------------------------- tables
class Table:
    """A result table for the book: HTML (wrapping text, fitting the content column) for the page, and a
    rounded plain-text rendering no wider than :data:`PLAIN_WIDTH` characters for nbval and terminals.

    ``formats`` maps column names to format strings (``"{:.3f}"``) or callables; unformatted float
    columns get 4 significant digits.  ``caption`` is shown above the table."""

    def __init__(self, frame: pd.DataFrame, formats: Mapping[str, Any] | None = None,
                 caption: str | None = None, index: bool = True):
        if not isinstance(frame, pd.DataFrame):
            frame = pd.DataFrame(frame)
        self.frame = frame
        self.formats = dict(formats or {})
        self.caption = caption
        self.index = index

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
        out.index = out.index.map(str)
        out.columns = [str(c) for c in out.columns]
        return out

    def _repr_html_(self) -> str:
        f = self.formatted()
        styler = f.style if self.index else f.style.hide(axis="index")
        styler = styler.set_uuid(f"t{zlib.crc32('|'.join(f.columns).encode()) % 10**8}")   # stable across runs
        styler = styler.set_table_attributes(f'class="navbook-table" style="{_CSS}"')
        styler = styler.set_table_styles([{"selector": "th", "props": _CELL + "text-align:left;"},
                                          {"selector": "td", "props": _CELL}])
        if self.caption:
            styler = styler.set_caption(self.caption)
        return styler.to_html()

    def __repr__(self) -> str:
        f = self.formatted()
        width = PLAIN_WIDTH
        clip = f.map(lambda s: s if len(s) <= 40 else s[:37] + "...")
        text = clip.to_string(index=self.index, line_width=width)
        lines = [ln if len(ln) <= width else ln[:width - 3] + "..." for ln in text.splitlines()]
        head = [self.caption[:width]] if self.caption else []
        return "\n".join(head + lines)


def table(frame: pd.DataFrame, formats: Mapping[str, Any] | None = None, caption: str | None = None,
          index: bool = True) -> Table:
    """Shorthand for :class:`Table`; the last expression of a cell displays it."""
    return Table(frame, formats, caption, index)


# ----------------------------------------------------------------------------------------------- glue
def _glue(name: str, obj: Any) -> None:
    from myst_nb import glue

    glue(name, obj, display=False)


def glue_number(name: str, value: Any, spec: str = "{:.3g}") -> str:
    """Glue a number (formatted by ``spec``) for ``{glue:text}`name``` in the prose; returns the text."""
    text = fmt(value, spec)
    _glue(name, text)
    return text


def glue_text(name: str, text: str) -> str:
    """Glue a short text (a verdict, a method name) for ``{glue:text}`name```."""
    _glue(name, str(text))
    return str(text)


def glue_table(name: str, tab: Table | pd.DataFrame) -> None:
    """Glue a table for ```{glue:} name``` (e.g. inside the Results-at-a-glance admonition)."""
    _glue(name, tab if isinstance(tab, Table) else Table(tab))


def glue_figure(name: str, fig) -> None:
    """Glue a matplotlib figure for ```{glue:figure} name``` (numbered, captioned, with alt text in the
    directive), then close it so it is not shown a second time."""
    import matplotlib.pyplot as plt

    _glue(name, fig)
    plt.close(fig)


def style() -> None:
    """Matplotlib defaults for the book: figures are shown at about 700 px, so fonts of at least 9 pt at
    that size; tight layouts; PNG output."""
    import matplotlib as mpl

    mpl.rcParams.update({"figure.dpi": 100, "savefig.dpi": 110, "font.size": 10, "axes.titlesize": 10,
                         "axes.labelsize": 10, "legend.fontsize": 9, "xtick.labelsize": 9,
                         "ytick.labelsize": 9, "figure.autolayout": False, "axes.grid": True,
                         "grid.alpha": 0.3})


# ----------------------------------------------------------------------------------------------- claims
@dataclass(frozen=True)
class Claim:
    """One claim of a paper and our verdict on it, under one reading of the paper's method.

    ``reproduced``: True, False, or None when it cannot be judged (``why`` says why); ``paper`` and
    ``ours`` are short texts with units."""

    claim: str
    paper: str
    ours: str
    reproduced: bool | None
    reading: str = "as printed"
    why: str = ""

    def __post_init__(self):
        if self.reproduced not in (True, False, None):
            raise InputError(f"Claim.reproduced={self.reproduced!r}: must be True, False or None")
        for f in ("claim", "paper", "ours", "reading"):
            if not str(getattr(self, f)).strip():
                raise InputError(f"Claim.{f} is empty")

    @property
    def verdict(self) -> str:
        return {True: "reproduced", False: "not reproduced", None: "cannot be judged"}[self.reproduced]


def glance(claims: Iterable[Claim]) -> Table:
    """The Results-at-a-glance table: claim | reading | paper | ours | verdict (with the reason)."""
    rows = [{"claim": c.claim, "reading": c.reading, "paper": c.paper, "ours": c.ours,
             "verdict": c.verdict + (f": {c.why}" if c.why else "")} for c in claims]
    return Table(pd.DataFrame(rows, columns=["claim", "reading", "paper", "ours", "verdict"]), index=False)


# ----------------------------------------------------------------------------------------------- results
def method_stats(rms, min_err=None, max_err=None) -> dict:
    """Headline statistics of one method over seeds: median, 10th and 90th percentile of the RMS error,
    median of the per-run minimum and maximum error, and the number of seeds (runs)."""
    r = np.asarray(rms, float)
    out = {"median_rms": float(np.median(r)), "p10_rms": float(np.quantile(r, 0.1)),
           "p90_rms": float(np.quantile(r, 0.9)), "n_seeds": int(r.size)}
    if min_err is not None:
        out["median_min"] = float(np.median(np.asarray(min_err, float)))
    if max_err is not None:
        out["median_max"] = float(np.median(np.asarray(max_err, float)))
    return out


def write_results(chapter: str, *, claims: Iterable[Claim], unit: str | None = None,
                  methods: Mapping[str, Mapping[str, Any]] | None = None,
                  extra: Mapping[str, Any] | None = None, folder: str | os.PathLike | None = None) -> Path:
    """Write ``<results dir>/<chapter>.json``::

        {"chapter": ..., "unit": ..., "methods": {label: {"median_rms_<unit>", "p10_rms_<unit>",
         "p90_rms_<unit>", "median_min_<unit>", "median_max_<unit>", "n_seeds"}},
         "claims": [{"claim", "paper", "ours", "reproduced", "verdict", "reading", "why"}], "extra": {...}}

    ``methods`` maps a display label to :func:`method_stats`-style keys (without unit suffix); the unit
    (e.g. ``deg``, ``mg``, ``arcsec``) is appended to each statistic's name.  Values are rounded to 6
    significant digits.  Returns the path written (this is a build output; it is rewritten each run)."""
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
    out["claims"] = [{**{k: plain(v) for k, v in asdict(c).items()}, "verdict": c.verdict} for c in claims]
    if extra:
        out["extra"] = {str(k): plain(v) if not isinstance(v, (list, tuple)) else [plain(x) for x in v]
                        for k, v in extra.items()}
    d = Path(folder) if folder is not None else results_dir()
    d.mkdir(parents=True, exist_ok=True)
    path = d / f"{chapter}.json"
    path.write_text(json.dumps(out, indent=1, ensure_ascii=False, allow_nan=False) + "\n", encoding="utf-8")
    return path


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


def claims_summary(results: Mapping[str, dict]) -> pd.DataFrame:
    """Per chapter and reading: claims reproduced, not reproduced, not judged (for the landing page)."""
    rows = []
    for chapter, res in results.items():
        for c in res.get("claims", []):
            rows.append({"chapter": chapter, "reading": c.get("reading", "as printed"),
                         "reproduced": c.get("reproduced")})
    if not rows:
        return pd.DataFrame(columns=["chapter", "reading", "claims", "reproduced", "not reproduced",
                                     "cannot be judged"])
    df = pd.DataFrame(rows)
    g = df.groupby(["chapter", "reading"], sort=False)["reproduced"]
    return pd.DataFrame({"claims": g.size(),
                         "reproduced": g.apply(lambda s: int((s == True).sum())),  # noqa: E712
                         "not reproduced": g.apply(lambda s: int((s == False).sum())),  # noqa: E712
                         "cannot be judged": g.apply(lambda s: int(s.isna().sum()))}).reset_index()
