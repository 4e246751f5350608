"""Build helpers for the book (used by the Makefile): execute notebooks, check the built HTML, write the
landing page's status table and the API page's module list, check the chapters' results files, and take
screenshots of every page.

Subcommands of ``python -m navbook``:

``execute --out book/_generated notebooks/*.ipynb``
    Execute each notebook with papermill into the book's generated folder (one progress line per notebook);
    stop with a non-zero exit at the first failing notebook.  ``--in-place`` re-executes the stored
    notebooks instead (how the outputs that nbval checks are regenerated) and also stores each chapter's
    results file as ``notebooks/results/<chapter>.json`` (the committed reference ``make test`` compares
    with).  With ``--out DIR`` the results files go to ``DIR/results/``.
``check-html DIR [--baseline FILE]``
    Fail if a built page loads anything from the network, shows an execution error, has an output block
    wider than the content column (a preformatted line over :data:`MAX_PRE_CHARS` characters), a figure
    without a caption or a visible nbval marker, or is a chapter (``_generated/``) that does not open with
    its *Results at a glance* admonition.  Also (:data:`LAYOUT_KINDS`): a code line over
    :data:`MAX_CODE_CHARS` characters that is not folded, pandas' index-name row or a snake_case column
    name in a result table, and a chapter whose glance box counts its claims differently from the landing
    page; these fail only beyond the page's count in the baseline (``book/check_html_baseline.json``).
``status RESULTS_DIR --notebooks DIR --out FILE [--toc FILE]``
    Write the top of the landing page (one row per chapter in the sidebar's order: source, a sentence and
    the counts by verdict with a bar; the box that defines the verdicts) to FILE, and its per-reading rows
    (one dropdown per chapter) to ``status_readings.md`` beside it, from the results files.
``api-modules --out FILE``
    Write the API reference: an overview to FILE and one page per layer of ``navlib`` beside it
    (``api_<layer>.md``: a summary table of its modules, then their ``automodule`` sections).
``check-results --fresh DIR --reference DIR NOTEBOOK...``
    Compare the results files a fresh run wrote with the committed references, within tolerance.
``screenshots HTML_DIR OUT_DIR``
    Render every page with headless Chromium (1400 px wide, full page height), record the page heights and
    list output blocks that overflow the content column.
"""
from __future__ import annotations

import base64
import csv
import fcntl
import html
import json
import math
import os
import pkgutil
import re
import select
import shutil
import subprocess
import sys
import tempfile
import time
from html.parser import HTMLParser
from pathlib import Path

from navlib import claims as claims_mod
from navlib import verdicts
from navlib.errors import InputError

from .report import RESULTS_ENV, read_results, reading_label
from .report import record_label as report_label

VOLATILE_NB_KEYS = ("papermill",)
VOLATILE_CELL_KEYS = ("papermill", "execution", "collapsed", "scrolled")
#: A preformatted output line longer than this does not fit the content column at 1400 px (measured in
#: headless Chromium on the built book with sphinx-book-theme 1.3; an output ``<pre>`` is 784 px wide with
#: 32 px of padding, and its 14 px monospace font is 8.43 px per character, so 89 characters fit).
MAX_PRE_CHARS = 89
#: A line of a code block shown on a page (a notebook's input cell not folded away, a command on the landing
#: page) longer than this scrolls sideways in the content column at 1400 px (the code font is the output's,
#: in a box a few pixels narrower than an output block's).
MAX_CODE_CHARS = 88
#: The presentation checks added with issue 24 (each message of :func:`check_page` of these kinds starts
#: with the kind).  Pages built before them carry such problems: ``check-html`` fails only where a page has
#: more of a kind than its entry in the baseline file (:func:`load_baseline`), and reports the rest.
LAYOUT_KINDS = ("wide code line", "index-name row", "snake_case header", "counts differ")
#: Tolerances of ``check-results`` (a number passes if ``|fresh - ref| <= ATOL + RTOL * |ref|``).
RTOL = 1e-3
ATOL = 1e-9


def strip_metadata(nb) -> None:
    """Remove timing and run-specific metadata so a re-executed notebook diffs only where outputs changed.

    Execution counts stay: nbval treats a cell without one as never run (they are sequential anyway)."""
    for key in VOLATILE_NB_KEYS:
        nb.metadata.pop(key, None)
    for cell in nb.cells:
        for key in VOLATILE_CELL_KEYS:
            cell.metadata.pop(key, None)


def missing_figures(nb) -> list[int]:
    """Indices of code cells that call ``plt.show()`` but carry no image output."""
    bad = []
    for i, cell in enumerate(nb.cells):
        if cell.cell_type == "code" and "plt.show()" in cell.source:
            if not any("image/png" in out.get("data", {}) for out in cell.get("outputs", [])):
                bad.append(i)
    return bad


_WRITE_RESULTS = re.compile(r"""write_results\(\s*(?:chapter\s*=\s*)?["']([A-Za-z_]\w*)["']""")


def results_chapter(nb_path: Path) -> str | None:
    """The chapter name a notebook passes to ``report.write_results`` (None if it never calls it)."""
    import nbformat

    nb = nbformat.read(nb_path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code":
            m = _WRITE_RESULTS.search(cell.source)
            if m:
                return m.group(1)
    return None


def execute(notebooks: list[Path], out_dir: Path | None, in_place: bool,
            parameters: dict | None = None) -> int:
    """Execute notebooks with papermill (see the module docstring); 0 on success, 1 at the first failure.

    Each notebook runs with ``NAVBOOK_RESULTS_DIR`` pointing at a fresh temporary folder; the results
    files it writes are then copied to ``notebooks/results/`` (``in_place``) or ``out_dir/results/``."""
    import nbformat
    import papermill as pm

    for i, nb_path in enumerate(notebooks, 1):
        nb_path = Path(nb_path).resolve()
        target = nb_path if in_place else (out_dir / nb_path.name)
        results_target = (nb_path.parent if in_place else Path(out_dir)) / "results"
        target.parent.mkdir(parents=True, exist_ok=True)
        print(f"[{i}/{len(notebooks)}] executing {nb_path.name} -> {target}", flush=True)
        t0 = time.perf_counter()
        old_env = os.environ.get(RESULTS_ENV)
        with tempfile.TemporaryDirectory() as tmp:
            tmp_out = Path(tmp) / nb_path.name
            tmp_results = Path(tmp) / "results"
            os.environ[RESULTS_ENV] = str(tmp_results)   # the kernel inherits the environment
            try:
                pm.execute_notebook(str(nb_path), str(tmp_out), cwd=str(nb_path.parent),
                                    parameters=parameters or {}, kernel_name="python3",
                                    progress_bar=False, log_output=False)
            except pm.PapermillExecutionError as err:
                lines = [ln for ln in str(err).strip().splitlines() if ln.strip()]
                print(f"FAILED {nb_path.name}: cell {err.exec_count}: {lines[-1] if lines else err.ename}",
                      file=sys.stderr)
                return 1
            finally:
                if old_env is None:
                    os.environ.pop(RESULTS_ENV, None)
                else:
                    os.environ[RESULTS_ENV] = old_env
            nb = nbformat.read(tmp_out, as_version=4)
            missing = missing_figures(nb)
            if missing:
                print(f"FAILED {nb_path.name}: cell {missing[0]} calls plt.show() but produced no figure "
                      f"(is MPLBACKEND set to a non-inline backend?)", file=sys.stderr)
                return 1
            strip_metadata(nb)
            nbformat.write(nb, target)
            written = sorted(tmp_results.glob("*.json")) if tmp_results.is_dir() else []
            if written:
                results_target.mkdir(parents=True, exist_ok=True)
            for f in written:
                shutil.copyfile(f, results_target / f.name)
        names = ", ".join(f.name for f in written) or "none (the chapter does not call report.write_results)"
        print(f"    done in {time.perf_counter() - t0:.1f} s; results: {names}", flush=True)
    return 0


# ------------------------------------------------------------------------------------------ HTML checks
REMOTE = re.compile(r"""(?:src|href)\s*=\s*["'](?:https?:)?//(?!localhost)""", re.I)
_VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "param", "source",
         "track", "wbr"}


class _PageScan(HTMLParser):
    """One pass over a built page: collects the problems :func:`check_page` reports."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack: list[tuple[str, set[str]]] = []
        self.heading = ""          # the last section heading seen (to say where a problem is)
        self._in_heading = False
        self._heading_buf: list[str] = []
        self.pre_stack: list[list[str]] = []   # text of output <pre> blocks being read
        self.figures: list[dict] = []          # open <figure> elements
        self.problems: list[str] = []
        self._skip = 0                         # inside <script>/<style>
        self.code_stack: list[list[str]] = []  # text of code <pre> blocks (not outputs) being read
        self.tables: list[dict] = []           # open result tables (inside cell outputs)

    # -- helpers
    def _classes(self, attrs) -> set[str]:
        return set((dict(attrs).get("class") or "").split())

    def _inside(self, cls: str) -> bool:
        return any(cls in c for _, c in self.stack)

    def _in_output(self) -> bool:
        return self._inside("cell_output") or self._inside("output")

    def _where(self) -> str:
        return f"under heading '{self.heading}'" if self.heading else "before the first heading"

    # -- parser callbacks
    def handle_starttag(self, tag, attrs):
        classes = self._classes(attrs)
        a = dict(attrs)
        if tag in ("script", "style"):
            self._skip += 1
        if tag in ("h1", "h2", "h3", "h4"):
            self._in_heading, self._heading_buf = True, []
        if tag == "img":
            if self._in_output() and not self.figures:
                alt = (a.get("alt") or "")[:60]
                self.problems.append(f"figure without a caption {self._where()} (image '{alt}'): glue it "
                                     f"with report.glue_figure and show it with a glue:figure directive "
                                     f"that has a caption")
            for fig in self.figures:
                fig["img"] = True
        if tag == "figure":
            self.figures.append({"id": a.get("id", ""), "caption": False, "img": False})
        if tag == "figcaption" and self.figures:
            self.figures[-1]["caption"] = True
        if tag == "pre" and self._in_output():
            self.pre_stack.append([])
        elif tag == "pre" and not any(t == "details" for t, _ in self.stack):
            self.code_stack.append([])
        if tag == "table" and self._in_output():
            self.tables.append({"thead": False, "row": None, "cell": None, "flagged": set()})
        if self.tables:
            t = self.tables[-1]
            if tag == "thead":
                t["thead"] = True
            elif tag == "tr" and t["thead"]:
                t["row"] = []
            elif tag in ("th", "td") and t["row"] is not None:
                t["cell"] = [("index_name" in classes), []]
        if tag not in _VOID:
            self.stack.append((tag, classes))

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)
        if tag not in _VOID and self.stack and self.stack[-1][0] == tag:
            self.handle_endtag(tag)

    def handle_endtag(self, tag):
        if tag in _VOID:
            return
        if tag in ("script", "style") and self._skip:
            self._skip -= 1
        if tag in ("h1", "h2", "h3", "h4") and self._in_heading:
            self._in_heading = False
            self.heading = re.sub(r"\s+", " ", "".join(self._heading_buf)).strip().rstrip("#").strip()
        if tag == "pre" and self.pre_stack and self._in_output():
            self._check_pre("".join(self.pre_stack.pop()))
        elif tag == "pre" and self.code_stack:
            self._check_code("".join(self.code_stack.pop()))
        if self.tables:
            t = self.tables[-1]
            if tag in ("th", "td") and t["row"] is not None and t["cell"] is not None:
                t["row"].append((t["cell"][0], re.sub(r"\s+", " ", "".join(t["cell"][1])).strip()))
                t["cell"] = None
            elif tag == "tr" and t["row"] is not None:
                self._check_header_row(t, t["row"])
                t["row"] = None
            elif tag == "thead":
                t["thead"] = False
            elif tag == "table":
                self.tables.pop()
        if tag == "figure" and self.figures:
            fig = self.figures.pop()
            if not fig["caption"]:
                name = f" '{fig['id']}'" if fig["id"] else ""
                self.problems.append(f"figure{name} without a caption {self._where()}: give the "
                                     f"glue:figure/figure directive a caption paragraph")
        # pop up to and including the matching open tag (tolerates unclosed <p> and the like)
        for k in range(len(self.stack) - 1, -1, -1):
            if self.stack[k][0] == tag:
                del self.stack[k:]
                break

    def handle_data(self, data):
        if self._skip:
            return
        if self._in_heading:
            self._heading_buf.append(data)
        if self.pre_stack:
            self.pre_stack[-1].append(data)
        if self.code_stack:
            self.code_stack[-1].append(data)
        if self.tables and self.tables[-1]["cell"] is not None:
            self.tables[-1]["cell"][1].append(data)
        if "NBVAL_" in data:
            m = re.search(r"#?\s*NBVAL_\w*", data)
            self.problems.append(f"visible nbval marker '{m.group(0).strip()}' {self._where()}: use the cell "
                                 f"tag nbval-ignore-output (or nbval-skip) instead of the comment")

    def _check_width(self, text: str, limit: int, what: str, shown: int, advice: str):
        """The first line of a block wider than ``limit`` characters, as one problem (one per block)."""
        for line in text.splitlines():
            if len(line.rstrip()) > limit:
                self.problems.append(f"{what} of {len(line.rstrip())} characters (max {limit}) {self._where()}: "
                                     f"'{line.strip()[:shown]}...': {advice}")
                return

    def _check_pre(self, text: str):
        self._check_width(text, MAX_PRE_CHARS, "output line", 70,
                          "show a report.table(...) or shorten the printed text")

    def _check_code(self, text: str):
        self._check_width(text, MAX_CODE_CHARS, "wide code line", 60,
                          "break the line (or fold the cell: tag hide-input)")

    def _check_header_row(self, table: dict, row: list[tuple[bool, str]]):
        """A header row of a result table: pandas' index-name row (the index's name alone, the column
        cells blank), and snake_case column names (``median_rms_deg``: say "median RMS (deg)")."""
        if len(row) >= 2 and "index" not in table["flagged"] and (
                row[0][0] or (row[0][1] and not any(text for _, text in row[1:]))):
            table["flagged"].add("index")
            self.problems.append(f"index-name row '{row[0][1]}' in a result table {self._where()}: reset the "
                                 f"index or set its name to None (report.table(..., index=False))")
        snake = [text for _, text in row if SNAKE.fullmatch(text)]
        if snake and "snake" not in table["flagged"]:
            table["flagged"].add("snake")
            self.problems.append(f"snake_case header '{snake[0]}' in a result table {self._where()} "
                                 f"({len(snake)} in the row): name the column in words with its unit in "
                                 f"parentheses")


#: A column name in snake_case (two or more lower-case words joined by underscores).
SNAKE = re.compile(r"[a-z][a-z0-9]*(?:_[a-z0-9]+)+")


def check_page(text: str, content: bool = True) -> list[str]:
    """Problems of one built page (HTML text): network assets and, if ``content`` (every page but the
    highlighted source listings under ``_modules/``), execution errors, output blocks wider than the
    content column, figures without captions, visible nbval markers."""
    problems = []
    for m in re.finditer(r"<(script|link|img)\b[^>]*>", text, re.I):
        if REMOTE.search(m.group(0)):
            problems.append(f"loads from the network: {m.group(0)[:120]}")
    if not content:
        return problems
    if "Traceback (most recent call last)" in text or 'class="output traceback' in text:
        problems.append("shows an execution error")
    scan = _PageScan()
    scan.feed(text)
    scan.close()
    return problems + scan.problems


GLANCE = "Results at a glance"
#: The admonition that closes every chapter (:func:`navbook.report.showed`).
SHOWED = "What this chapter showed"
#: The known problems of the :data:`LAYOUT_KINDS` per page, in the book folder (``book/``).
BASELINE_FILE = "check_html_baseline.json"


def check_chapter_opening(text: str) -> list[str]:
    """A chapter page (executed notebook) must open with the *Results at a glance* admonition: present,
    and before the first code cell."""
    m = re.search(r'<p class="admonition-title">\s*' + GLANCE, text)
    if not m:
        return [f"chapter without a '{GLANCE}' admonition: open the chapter with report.glance(claims) "
                f"glued into a ':::{{admonition}} {GLANCE}' block"]
    first_cell = text.find('<div class="cell docutils container')
    if 0 <= first_cell < m.start():
        return [f"the '{GLANCE}' admonition comes after a code cell: move it right after the title and intro"]
    return []


def check_chapter_closing(text: str) -> list[str]:
    """A chapter page must close with the *What this chapter showed* admonition, after its last code cell,
    and that box must count the same claims as the chapter's *Results at a glance* box."""
    m = None
    for m in re.finditer(r'<p class="admonition-title">\s*' + SHOWED, text):
        pass
    if m is None:
        return [f"chapter without a '{SHOWED}' admonition: close the chapter with report.showed(claims) "
                f"glued into a ':::{{admonition}} {SHOWED}' block"]
    if text.find('<div class="cell docutils container', m.end()) >= 0:
        return [f"the '{SHOWED}' admonition is not at the chapter's end: a code cell follows it"]
    shown = _box_counts(text[m.end():])
    glance = glance_counts(text)
    if glance is not None and shown != glance:
        return [f"the '{SHOWED}' box counts {shown} but the glance box {glance}: build both from the same "
                f"claims"]
    return []


_TALLY = re.compile(r"The (paper's|book's own) claims: (\d+) of (\d+) reproduced, (\d+) not reproduced, "
                    r"(\d+) cannot be judged(?:, (\d+) no difference)?")
_COUNTS_TAG = re.compile(r'<span class="navbook-counts"([^>]*)>')


def glance_counts(text: str) -> dict[str, tuple[int, int, int]] | None:
    """The counts a chapter page's *Results at a glance* box shows (its tallies "The paper's claims: k of
    n reproduced, m not reproduced, j cannot be judged"), by source; None without a glance box."""
    m = re.search(r'<p class="admonition-title">\s*' + GLANCE, text)
    if not m:
        return None
    end = text.find('<div class="cell docutils container', m.end())
    return _box_counts(text[m.end(): end if end >= 0 else len(text)])


def _box_counts(fragment: str) -> dict[str, tuple[int, int, int]]:
    """The tallies ("The paper's claims: k of n reproduced, m not reproduced, j cannot be judged") in an
    HTML fragment, by source: the first of each."""
    box = re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", fragment)))
    out = {}
    for t in _TALLY.finditer(box):
        out.setdefault("paper" if t.group(1) == "paper's" else "book", (int(t.group(2)), int(t.group(4)),
                                                                         int(t.group(5)), int(t.group(6) or 0)))
    return out


def landing_counts(text: str) -> dict[str, dict]:
    """The counts the landing page shows (:func:`status_markdown`'s ``navbook-counts`` marks), by chapter
    page: ``{"_generated/compass.html": {"chapter": ..., "paper": (r, nr, cj), "book": (r, nr, cj)}}``."""
    out = {}
    for m in _COUNTS_TAG.finditer(text):
        a = dict(re.findall(r'([\w-]+)="([^"]*)"', m.group(1)))
        if "data-page" in a:
            out[a["data-page"]] = {"chapter": a.get("data-chapter", ""),
                                   **{src: (tuple(int(v) for v in a.get(f"data-{src}", "").split())
                                            + (0, 0, 0, 0))[:4]
                                      for src in verdicts.SOURCES}}
    return out


def count_problems(landing: dict[str, dict], chapter_pages: dict[str, str]) -> list[tuple[str, str]]:
    """``(page, problem)`` where a chapter's glance box and the landing page count its claims differently
    (both must come from the chapter's results file: every claim it writes is in its glance box)."""
    out = []
    for page, want in sorted(landing.items()):
        text = chapter_pages.get(page)
        if text is None:
            out.append(("intro.html", f"counts differ: the landing page counts {page}, which was not built"))
            continue
        got = glance_counts(text) or {}
        for src in verdicts.SOURCES:
            shown = got.get(src, (0, 0, 0, 0))
            if tuple(want[src]) != tuple(shown):
                whose = "the paper's" if src == "paper" else "the book's own"
                out.append((page, f"counts differ: the glance box shows {whose} claims as {shown[0]} of "
                                  f"{sum(shown)} reproduced / {shown[1]} not / {shown[2]} cannot be judged, the "
                                  f"landing page (the results file) {want[src][0]} of {sum(want[src])} / "
                                  f"{want[src][1]} / {want[src][2]}: pass every claim written to "
                                  f"report.write_results to report.glance"))
    return out


def load_baseline(path: Path | None) -> dict[str, dict[str, int]]:
    """The known problems of the :data:`LAYOUT_KINDS` per page (``{"page": {"kind": count}}``), measured
    when the checks were added; ``check-html`` fails only where a page has more.  {} without a file."""
    if path is None or not Path(path).exists():
        return {}
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        return {page: {k: int(v) for k, v in kinds.items()} for page, kinds in data["pages"].items()}
    except (json.JSONDecodeError, KeyError, AttributeError, TypeError, ValueError) as err:
        raise InputError(f"{path}: not a check-html baseline ({{\"pages\": {{page: {{kind: count}}}}}}): "
                         f"{type(err).__name__}: {err}") from None


def _kind(problem: str) -> str | None:
    return next((k for k in LAYOUT_KINDS if problem.startswith(k)), None)


def is_chapter_page(rel: Path) -> bool:
    """A built chapter (an executed notebook under ``_generated/``; the API pages there are not)."""
    rel = Path(rel)
    return rel.parts[0] == "_generated" and not rel.name.startswith("api_")


#: Typographic characters a command copied from a page must not contain (an en or em dash for ``--``,
#: curly quotes for straight ones).
_TYPOGRAPHIC = re.compile("[\u2013\u2014\u2018\u2019\u201c\u201d]")


def check_api_page(text: str, cli_page: bool = False) -> list[str]:
    """Problems of one API page: a ``Type:`` field (napoleon split a constant's description at a colon:
    ``book/_ext/navbook_attrdoc.py``); on the command line's page (``cli_page``), an option written with a
    typographic dash or quote, or an option of a command line that the command's parser does not have
    (each line of the page that starts with a command name), or whose ``--help``, run for real, fails or
    does not show it (``_help_problems``)."""
    out = []
    n = text.count('Type<span class="colon">:</span>')
    if n:
        out.append(f"{n} description(s) split into a 'Type:' field")
    if not cli_page:
        return out
    from navlib.cli import build_parser
    sub = next(a for a in build_parser()._actions if a.dest == "command").choices
    body = html.unescape(re.sub(r"<[^>]+>", "", re.sub(r"</(?:p|dt|dd|li|pre|div)>|<br\s*/?>", "\n", text)))
    shown: dict[str, set] = {}
    for line in body.splitlines():
        words = line.split()
        if not words or words[0] not in sub:
            continue
        if _TYPOGRAPHIC.search(line):
            out.append(f"a command with a typographic dash or quote: {line.strip()[:70]!r}")
            continue
        known = {s for a in sub[words[0]]._actions for s in a.option_strings}
        for w in words[1:]:
            opt = w.strip("[]").split("=")[0]
            if opt.startswith("--") and opt not in known:
                out.append(f"'{words[0]}' has no option {opt}: {line.strip()[:70]!r}")
            elif opt.startswith("--"):
                shown.setdefault(words[0], set()).add(opt)
    return out + _help_problems(shown)


def _help_problems(shown: dict) -> list[str]:
    """Each command as a user copies it from the page: ``python -m navlib COMMAND --help`` run for real (a
    new process); a problem when it fails or its help does not show an option the page shows."""
    out = []
    for command, options in sorted(shown.items()):
        run = subprocess.run([sys.executable, "-m", "navlib", command, "--help"], capture_output=True,
                             text=True, timeout=60)
        if run.returncode != 0:
            out.append(f"'navlib {command} --help' failed (exit {run.returncode}): {run.stderr.strip()[-120:]}")
            continue
        missing = sorted(o for o in options if not re.search(re.escape(o) + r"(?![\w-])", run.stdout))
        if missing:
            out.append(f"'navlib {command} --help' does not show {', '.join(missing)}, which the page shows")
    return out


def check_html(html_dir: Path, limit: int = 60, baseline: Path | None = None) -> int:
    """Run :func:`check_page` on every built page; print each problem as ``page: problem``; 1 if any."""
    found: list[tuple[str, str]] = []
    pages = sorted(Path(html_dir).rglob("*.html"))
    chapter_pages, landing = {}, {}
    for page in pages:
        text = page.read_text(encoding="utf-8", errors="replace")
        rel = page.relative_to(html_dir)
        found += [(rel.as_posix(), p) for p in check_page(text, content=rel.parts[0] != "_modules")]
        if rel.name.startswith("api_"):
            found += [(rel.as_posix(), p) for p in check_api_page(text, cli_page=rel.name == "api_cli.html")]
        if is_chapter_page(rel):                       # the chapters (executed notebooks)
            found += [(rel.as_posix(), p) for p in check_chapter_opening(text) + check_chapter_closing(text)]
            chapter_pages[rel.as_posix()] = text
        landing.update(landing_counts(text))
    found += count_problems(landing, chapter_pages)
    known = load_baseline(baseline)
    problems, tolerated = [], {}
    by_page_kind: dict[tuple[str, str], list[str]] = {}
    for page, p in found:
        kind = _kind(p)
        if kind is None:
            problems.append(f"{page}: {p}")
        else:
            by_page_kind.setdefault((page, kind), []).append(p)
    for (page, kind), ps in sorted(by_page_kind.items()):
        allowed = known.get(page, {}).get(kind, 0)
        if len(ps) > allowed:
            problems += [f"{page}: {p}" for p in ps]
            problems.append(f"{page}: {len(ps)} problem(s) of the kind '{kind}', the baseline allows {allowed}"
                            if allowed else f"{page}: {kind}: none allowed (the page had none)")
        else:
            tolerated.setdefault(page, {})[kind] = len(ps)
    for page, kinds in sorted(tolerated.items()):
        print(f"check-html: known, to fix: {page}: " + ", ".join(f"{n} {k}" for k, n in kinds.items()),
              file=sys.stderr)
    for p in problems[:limit]:
        print(p, file=sys.stderr)
    if len(problems) > limit:
        print(f"... and {len(problems) - limit} more", file=sys.stderr)
    if problems:
        print(f"check-html: {len(problems)} problem(s) in {len(pages)} pages", file=sys.stderr)
        return 1
    print(f"check-html: {len(pages)} pages: nothing loaded from the network, no errors, no output wider than "
          f"{MAX_PRE_CHARS} characters, every figure captioned, no nbval markers, every chapter opens with "
          f"its results at a glance; code lines, table headers and glance counts no worse than the baseline")
    return 0


# ------------------------------------------------------------------------------------------ landing page
def notebook_title(nb_path: Path) -> str:
    """The first markdown heading of a notebook (its chapter title), else the file stem."""
    import nbformat

    nb = nbformat.read(nb_path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            m = re.search(r"^#\s+(.+)$", cell.source, re.M)
            if m:
                return m.group(1).strip()
    return nb_path.stem


def _md_cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


#: The three verdicts in the order the book counts them, and the colours of the landing page's bars.
COUNTED = ("reproduced", "not reproduced", "cannot be judged", "no difference")
BAR_COLOURS = {"reproduced": "#2e7d32", "not reproduced": "#c62828", "cannot be judged": "#9e9e9e",
               "no difference": "#1565c0"}
def claim_counts(results: dict[str, dict], data: str = "simulated") -> dict[str, dict[str, dict[str, int]]]:
    """The one source of the book's counts: per chapter and source (``"paper"``, ``"book"``), how many of
    the chapter's claims (every claim of its results file judged on ``data``: ``"simulated"``, the
    default, or ``"real"``, the claims judged again on real measurements, counted apart) are reproduced,
    not reproduced and cannot be judged.  The landing page shows these; each chapter's *Results at a
    glance* must show the same (``check-html`` compares them on the built pages).  A record without a
    ``data`` field (a file written before it existed) is simulated."""
    if data not in verdicts.DATA:
        raise InputError(f"claim_counts: data={data!r}: must be 'simulated' or 'real'")
    out = {}
    for chapter, res in results.items():
        counts = {src: dict.fromkeys(COUNTED, 0) for src in verdicts.SOURCES}
        for c in res.get("claims", []):
            if claims_mod.data_of(c) == data:
                counts[c.get("source", "paper")][verdicts.verdict_name(c.get("reproduced"), c.get("basis"))] += 1
        out[chapter] = counts
    return out


def real_text(counts: dict[str, int], whose: str = "paper's") -> str:
    """"paper's claims on real data: 2 of 7 reproduced, 3 not reproduced, 2 cannot be judged" ("" for
    none)."""
    n = sum(counts.values())
    if not n:
        return ""
    text = (f"{whose} claims on real data: {counts['reproduced']} of {n} reproduced, {counts['not reproduced']} "
            f"not reproduced, {counts['cannot be judged']} cannot be judged")
    return text + (f", {counts['no difference']} no difference" if counts.get("no difference") else "")


def _reason_key(c: dict) -> str | None:
    """The reason category of a stored claim: its ``reason`` field, else from its basis and why (results
    files written before the field existed)."""
    if c.get("reproduced") is not None:
        return None
    if c.get("reason"):
        return c["reason"]
    basis = c.get("basis")
    return verdicts.reason_category(basis, c.get("why") or "") if basis in verdicts.BASES else None


def _reasons_text(claims: list[dict]) -> str:
    """"12 (8 below our noise floor, 4 our interval contains the boundary)" for the claims that cannot be
    judged."""
    keys = [_reason_key(c) for c in claims if c.get("reproduced") is None]
    if not keys:
        return "0"
    found = {k: keys.count(k) for k in dict.fromkeys(keys)}
    parts = [f"{n} {verdicts.REASONS[k][0] if k else 'reason not recorded'}"
             for k, n in sorted(found.items(), key=lambda kv: -kv[1])]
    return f"{len(keys)} ({', '.join(parts)})"


def verdict_sentence(counts: dict[str, int], whose: str = "the paper's", claims: list[dict] = ()) -> str:
    """One sentence computed from a chapter's counts: "Mostly not reproduced: 25 of the paper's 45
    claims do not reproduce, 13 do, 7 cannot be judged (mostly our interval contains the boundary)."  The lead is *mostly X* when a verdict holds more than half of the claims, else *mixed*
    (saying which of reproduced and not reproduced is the more frequent); the reason is the most frequent
    case of *cannot be judged* among ``claims`` (the stored records)."""
    r, nr, cj = (counts[k] for k in COUNTED[:3])
    n = r + nr + cj + counts.get("no difference", 0)
    if n == 0:
        return "No claims judged yet."
    pct = counts
    of = f"of {whose} {n} claims"
    if 2 * r > n:
        lead, first = "Mostly reproduced", f"{pct['reproduced']} {of} reproduce, {pct['not reproduced']} do not"
    elif 2 * nr > n:
        lead, first = "Mostly not reproduced", f"{pct['not reproduced']} {of} do not reproduce, {pct['reproduced']} do"
    elif 2 * cj > n:
        lead = "Mostly cannot be judged"
        first = (f"{pct['cannot be judged']} {of} cannot be judged, {pct['reproduced']} reproduce, "
                 f"{pct['not reproduced']} do not")
    else:
        more = "more reproduced than not" if r > nr else ("more not reproduced than reproduced" if nr > r
                                                           else "as many reproduced as not")
        lead, first = f"Mixed, {more}", f"{pct['reproduced']} {of} reproduce, {pct['not reproduced']} do not"
    if cj and not lead.startswith("Mostly cannot"):
        first += f", {pct['cannot be judged']} cannot be judged"
    keys = [k for k in (_reason_key(c) for c in claims if c.get("reproduced") is None) if k]
    if keys:
        top = max(dict.fromkeys(keys), key=keys.count)
        share = "all" if keys.count(top) == len(keys) else "mostly"
        first += f" ({share} {verdicts.REASONS[top][0]})"
    return f"{lead}: {first}."


def stacked_bar(counts: dict[str, int], width_px: int = 110, height_px: int = 12) -> str:
    """A small stacked bar (inline SVG, nothing to download): reproduced, not reproduced and cannot be
    judged as shares of the claims, with the counts in its title (shown on hover) and aria label."""
    n = sum(counts.get(k, 0) for k in COUNTED)
    label = ", ".join(f"{counts[k]} {k}" for k in COUNTED if k != "no difference" or counts.get(k))
    parts, x = [], 0.0
    for k in COUNTED:
        w = width_px * counts.get(k, 0) / n if n else 0.0
        if w > 0:
            parts.append(f'<rect x="{x:.1f}" y="0" width="{w:.1f}" height="{height_px}" '
                         f'fill="{BAR_COLOURS[k]}"/>')
        x += w
    return (f'<svg class="navbook-bar" width="{width_px}" height="{height_px}" role="img" '
            f'aria-label="{label}"><title>{label}</title>{"".join(parts)}</svg>')


def _counts_cell(counts: dict[str, int]) -> str:
    n = sum(counts.values())
    nd = counts.get("no difference", 0)
    return "–" if n == 0 else (f"{counts['reproduced']} / {counts['not reproduced']} / {counts['cannot be judged']}"
                               + (f" (+ {nd} no difference)" if nd else ""))


def chapter_order(notebooks: list[Path], toc: Path | None = None) -> list[Path]:
    """The notebooks in the sidebar's order (their ``_generated/<stem>`` entries in ``_toc.yml``), the
    ones the table of contents does not list after them in name order."""
    notebooks = sorted(Path(n) for n in notebooks)
    if toc is None or not Path(toc).exists():
        return notebooks
    entries = re.findall(r"file:\s*_generated/([\w-]+)", Path(toc).read_text(encoding="utf-8"))
    rank = {stem: i for i, stem in enumerate(entries)}
    return sorted(notebooks, key=lambda nb: (rank.get(nb.stem, len(rank)), nb.stem))


def read_chapter_sources(path: Path | None) -> dict[str, tuple[str, str]]:
    """``book/chapters.csv`` (columns ``chapter`` = the notebook's stem, ``short_title``, ``source``): the
    landing page's short chapter names and sources; {} if the file is absent."""
    if path is None or not Path(path).exists():
        return {}
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    need = {"chapter", "short_title", "source"}
    if rows and not need <= set(rows[0]):
        raise InputError(f"{path}: needs the columns {sorted(need)}, has {sorted(rows[0])}")
    return {r["chapter"]: (r["short_title"].strip(), r["source"].strip()) for r in rows}


def _chapters(results: dict[str, dict], notebooks: list[Path], sources: dict | None = None):
    """(chapter, doc, title, source) per notebook; the title is the short title of ``sources`` if given."""
    for nb in notebooks:
        chapter = results_chapter(nb) or nb.stem
        short, source = (sources or {}).get(nb.stem, (notebook_title(nb), ""))
        yield chapter, f"/_generated/{nb.stem}", short, source


def verdict_box() -> str:
    """The box that defines the verdicts (one rule, :mod:`navlib.verdicts`), each *cannot be judged* case
    with its own line; glance boxes link to it."""
    lines = ["(what-the-verdicts-mean)=", ":::{admonition} What the verdicts mean", ":class: note", "",
             "Every claim, the paper's and the book's own, is judged by one rule (`navlib.verdicts`) on a "
             "statistic of our runs with its 95 % interval and the claim's boundary "
             "(a paired difference over the same seeds where two methods are compared):", ""]
    for label, text in verdicts.VERDICT_DEFINITIONS.items():
        lines.append(f"- **{label}**: {text}.")
    lines += ["", "The papers' claims and the book's own (tests the papers did not run) are counted apart, "
              "one count per claim of the source's claims register. Where a paper can be read in several "
              "ways, the chapter names the most plausible reading and why, counts the claim under it, and "
              "shows the verdict under every other reading (and on other drawn simulators) as sensitivity.",
              ":::"]
    return "\n".join(lines)


def status_markdown(results: dict[str, dict], notebooks: list[Path],
                    sources: dict[str, tuple[str, str]] | None = None) -> str:
    """The top of the landing page (MyST markdown): one row per chapter, in the order of ``notebooks``
    (the sidebar's, :func:`chapter_order`), with the chapter and its source, a sentence computed from
    the counts, the paper's claims and the book's own claims by verdict (reproduced / not reproduced /
    cannot be judged, from :func:`claim_counts`) and a stacked bar of the paper's claims; then the box
    that defines the verdicts.  The chapters that wrote no results file are listed after the table.
    ``sources`` (:func:`read_chapter_sources`) gives each notebook's short title and source.""" 
    counts = claim_counts(results)
    real = claim_counts(results, "real")
    rows = []
    missing = []
    for chapter, doc, title, source in _chapters(results, notebooks, sources):
        if chapter not in results:
            missing.append(f"{{doc}}`{_md_cell(title)} <{doc}>`")
            continue
        cnt = counts[chapter]
        claims = results[chapter].get("claims", [])
        src = "paper" if sum(cnt["paper"].values()) else "book"
        whose = "the paper's" if src == "paper" else "the book's own"
        sentence = verdict_sentence(cnt[src], whose, [c for c in claims if c.get("source", "paper") == src])
        tag = (f'<span class="navbook-counts" data-chapter="{html.escape(chapter)}" '
               f'data-page="{doc.lstrip("/")}.html" '
               f'data-paper="{" ".join(str(cnt["paper"][k]) for k in COUNTED)}" '
               f'data-book="{" ".join(str(cnt["book"][k]) for k in COUNTED)}"></span>')
        src_text = f"<br>{_md_cell(source)}" if source else ""
        on_real = "".join(f"<br>{_md_cell(real_text(real[chapter][s], w))}"
                          for s, w in (("paper", "paper's"), ("book", "book's own")) if sum(real[chapter][s].values()))
        rows += [f"* - {{doc}}`{_md_cell(title)} <{doc}>`{tag}{src_text}", f"  - {_md_cell(sentence)}",
                 f"  - {stacked_bar(cnt[src])}<br>paper's: {_counts_cell(cnt['paper'])}<br>"
                 f"book's own: {_counts_cell(cnt['book'])}{on_real}"]
    if rows:
        lines = [":::{list-table}", ":header-rows: 1", ":class: navbook-summary", ":widths: 30 45 25", "",
                 "* - chapter and source", "  - in one sentence",
                 "  - claims: reproduced / not / cannot be judged"] + rows + [":::"]
    else:
        lines = ["No chapter has written its results yet."]
    if missing:
        lines += ["", f"Not yet summarised (no results file): {', '.join(missing)}."]
    lines = sources_markdown(results) + [""] + lines
    total = {src: {k: sum(counts[c][src][k] for c in counts) for k in COUNTED} for src in verdicts.SOURCES}
    if counts:
        lines += ["", f"In all, **{total['paper']['reproduced']} of {sum(total['paper'].values())}** of the "
                  f"papers' claims reproduce, {total['paper']['not reproduced']} do not and "
                  f"{total['paper']['cannot be judged']} cannot be judged; of the book's own claims "
                  f"{total['book']['reproduced']} of {sum(total['book'].values())} hold. Counts are reproduced / "
                  f"not reproduced / cannot be judged; bars: "
                  + ", ".join(f'<span style="color:{BAR_COLOURS[k]}">&#9632;</span> {k}' for k in COUNTED)
                  + ". Each chapter's *Results at a glance* lists the same claims; the readings are "
                  "[below](status-by-reading)."]
        total_real = {src: {k: sum(real[c][src][k] for c in real) for k in COUNTED} for src in verdicts.SOURCES}
        if sum(total_real["paper"].values()) + sum(total_real["book"].values()):
            lines += ["", "Judged again on real measurements and counted apart from the claims above (the same "
                      "claims, on real data instead of our simulators): "
                      + "; ".join(real_text(total_real[s], w) for s, w in (("paper", "the papers'"),
                                                                         ("book", "the book's own"))
                                  if sum(total_real[s].values())) + "."]
    return "\n".join(lines) + "\n\n" + verdict_box() + "\n"


def sources_markdown(results: dict[str, dict]) -> list[str]:
    """The landing page's rows per source (paper A and document B apart): what the source claims in one
    line (its headline claim, in its words), the headline's verdict under the primary reading, and the
    source's claims (register entries, not readings) by verdict under their primary readings, with how
    many are judged, not yet computed and not checkable, and the contradictions noted."""
    rows, details = [], []
    order = list(claims_mod.SOURCE_NAMES)
    pairs = sorted(((name, chapter) for chapter in results for name in claims_mod.registers(chapter)),
                   key=lambda p: order.index(p[0]))
    for name, chapter in pairs:
        res = results[chapter]
        recs = [c for c in res.get("claims", []) if "sensitivity" in c]
        mine = [c for c in recs if c.get("register") == name and c.get("source") == "paper"
                and claims_mod.data_of(c) == "simulated"]
        if not mine:
            continue
        real = [c for c in recs if c.get("register") == name and c.get("source") == "paper"
                and claims_mod.data_of(c) == "real"]
        n_real = {k: sum(c["verdict"] == k for c in real) for k in COUNTED}
        head = next((c for c in mine if c.get("headline")), None)
        n = {k: sum(c["verdict"] == k for c in mine) for k in COUNTED}
        st = {k: sum(c.get("status") == k for c in mine) for k in ("judged", "open", "not checkable")}
        noted = sum(1 for x in res.get("inconsistencies") or [] if x.get("register") == name)
        verdict = report_label(head) if head else "–"
        claim = head["claim"] if head else "–"
        rows += [f"* - {_md_cell(claims_mod.SOURCE_NAMES[name])} ({chapter})", f"  - {_md_cell(claim)}",
                 f'  - <span class="navbook-headline"><b>{html.escape(verdict)}</b></span>'
                 + (f"<br>({_md_cell(head['primary_reading'])})" if head and head.get("status") == "judged"
                    else ""),
                 f"  - {stacked_bar(n, width_px=80)} {_counts_cell(n)} of {len(mine)}"
                 + (f"<br>on real data: {_counts_cell(n_real)} of {len(real)}" if real else "")]
        details.append(f"{claims_mod.SOURCE_NAMES[name]} {st['judged']} judged, {st['open']} not yet computed, "
                       f"{st['not checkable']} not checkable"
                       + (f", {noted} contradiction{'s' if noted != 1 else ''} noted" if noted else ""))
    if not rows:
        return []
    return (["", "(status-by-source)=",
             ":::{list-table}", ":header-rows: 1", ":class: navbook-summary", ":widths: 11 35 30 24", "",
             "* - source", "  - headline claim", "  - verdict (primary reading)",
             "  - claims"]
            + rows + [":::", "", "Claims: reproduced / not reproduced / cannot be judged, of all the source's "
                      "claims. Each claim of a source's claims register counts once, under the reading its "
                      "chapter finds most plausible (the others are shown there as sensitivity): "
                      + "; ".join(details) + ". The claims judged again on real data (\"on real data\") "
                      "are counted apart."])


def readings_markdown(results: dict[str, dict], notebooks: list[Path],
                      sources: dict[str, tuple[str, str]] | None = None) -> str:
    """The landing page's per-reading rows (MyST markdown): one dropdown per chapter, in the order of
    ``notebooks``, with a row per source and reading (its readable label, :func:`navbook.report.reading_label`): claims,
    reproduced, not reproduced, and cannot be judged with the cases that apply."""
    parts = ["(status-by-reading)=", "## Claims by reading", "",
             "Where a paper's method or claim can be read in more than one way, each reading is judged on its "
             "own (the chapter says why each reading is plausible). Open a chapter to see its readings.", ""]
    for chapter, doc, title, _ in _chapters(results, notebooks, sources):
        if chapter not in results:
            continue
        claims = [c for c in flat_claims(results[chapter]) if c.get("rule") != "no statistic"
                  or c.get("reason") not in ("not yet computed", "not checkable")]
        readings = list(dict.fromkeys((c.get("source", "paper"), c.get("reading", "as printed"),
                                       claims_mod.data_of(c)) for c in claims))
        parts += [f"::::{{dropdown}} {_md_cell(title)}: {len(claims)} rows (claims under readings), "
                  f"{len(readings)} readings", "",
                  f"{{doc}}`The chapter <{doc}>`.", "",
                  "| reading | claims | reproduced | not reproduced | cannot be judged |", "|---|---|---|---|---|"]
        for data in verdicts.DATA:
            for src in verdicts.SOURCES:
                for s, r, d in readings:
                    if s != src or d != data:
                        continue
                    cs = [c for c in claims if c.get("source", "paper") == s and c.get("reading", "as printed") == r
                          and claims_mod.data_of(c) == d]
                    label = (reading_label(r) + (" (the book's own claims)" if s == "book" else "")
                             + (" (on real data)" if d == "real" else ""))
                    rep = sum(c.get("reproduced") is True for c in cs)
                    nrep = sum(c.get("reproduced") is False for c in cs)
                    parts.append(f"| {_md_cell(label)} | {len(cs)} | {rep} | {nrep} | "
                                 f"{_md_cell(_reasons_text(cs))} |")
        parts += ["", "::::", ""]
    return "\n".join(parts)


def write_status(results_dir: Path, notebooks_dir: Path, out: Path, toc: Path | None = None) -> int:
    """Write :func:`status_markdown` for the results in ``results_dir`` and the executed notebooks in
    ``notebooks_dir`` to ``out``, and :func:`readings_markdown` beside it (``status_readings.md``), the
    chapters in the order of ``toc`` (default ``book/_toc.yml`` beside ``out``'s folder), with the short
    titles and sources of ``chapters.csv`` beside ``toc`` (:func:`read_chapter_sources`)."""
    results = read_results(results_dir) if Path(results_dir).is_dir() else {}
    out = Path(out)
    toc = Path(toc) if toc is not None else out.parent.parent / "_toc.yml"
    notebooks = chapter_order(list(Path(notebooks_dir).glob("*.ipynb")), toc)
    out.parent.mkdir(parents=True, exist_ok=True)
    sources = read_chapter_sources(toc.with_name("chapters.csv"))
    out.write_text(status_markdown(results, notebooks, sources), encoding="utf-8")
    by_reading = out.with_name("status_readings.md")
    by_reading.write_text(readings_markdown(results, notebooks, sources), encoding="utf-8")
    n_claims = sum(len(r.get("claims", [])) for r in results.values())
    print(f"status: {len(results)} chapter(s) with results, {n_claims} claims -> {out}, {by_reading.name}")
    no_results = [nb.name for nb in notebooks if (results_chapter(nb) or nb.stem) not in results]
    if no_results:
        print(f"status: no results file from {', '.join(no_results)} (the chapter's last cell must call "
              f"report.write_results)", file=sys.stderr)
    return 0


# ------------------------------------------------------------------------------------------ API page
def navlib_modules() -> list[str]:
    """Every module of the ``navlib`` package, then of the book's tooling ``navbook`` (``__main__``
    excluded), top-level modules first."""
    import navlib

    import navbook

    names = []
    for pkg in (navlib, navbook):
        mods = [m.name for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + ".")
                if not m.name.endswith("__main__")]
        names += sorted(mods, key=lambda n: (n.count("."), n))
    return names


def api_markdown(modules: list[str]) -> str:
    """One section per module (MyST markdown): a heading and an ``automodule`` directive, in an
    ``eval-rst`` block because autodoc emits reStructuredText."""
    parts = []
    for name in modules:
        parts += [f"## `{name}`", "", "```{eval-rst}", f".. automodule:: {name}", "   :members:", "```", ""]
    return "\n".join(parts)


#: The API reference's pages, one per layer of navlib, in the order the sidebar shows them: (page name,
#: title, module prefixes).  A module matches the longest prefix; the book's build tooling comes last.
API_LAYERS = (
    ("sensors", "Sensors: simulators and exact error models", ("navlib.sensors",)),
    ("methods", "Methods: estimators, networks, optimisers, filters", ("navlib.methods",)),
    ("workbench", "Workbench: find the missing physical effect", ("navlib.workbench",)),
    ("studies", "Studies: one module per source", ("navlib.studies",)),
    ("data", "Data: loaders with validation", ("navlib.data", "navlib.paths")),
    ("cli", "Command line", ("navlib.cli", "navlib.commands")),
    ("foundations", "Shared tools: claims, verdicts, engine, seeds, figure style",
     ("navlib.claims", "navlib.verdicts", "navlib.formatting", "navlib.plotstyle", "navlib.engine",
      "navlib.seeding", "navlib.angles", "navlib.errors", "navlib._optional")),
    ("internals", "The book's tooling (package navbook, not in navlib's wheel)", ("navbook",)),
)


def api_layer(module: str) -> str:
    """The :data:`API_LAYERS` page of a module (the longest matching prefix); ``"foundations"`` for a
    module no layer names."""
    best, length = "foundations", -1
    for name, _, prefixes in API_LAYERS:
        for pre in prefixes:
            if (module == pre or module.startswith(pre + ".")) and len(pre) > length:
                best, length = name, len(pre)
    return best


def module_summary(module: str) -> str:
    """The first sentence of a module's docstring (for the API pages' summary tables)."""
    import importlib

    try:
        doc = importlib.import_module(module).__doc__ or ""
    except ImportError as err:            # an optional extra missing: say so instead of failing the page
        return f"(not importable here: {err})"
    text = re.sub(r"\s+", " ", doc).strip()
    first = text
    for m in re.finditer(r"[.:](?=\s|$)", text):
        word = re.search(r"(\S+)$", text[:m.start()])
        if (word and word.group(1).lower() in _NOT_SENTENCE_ENDS) or text[m.start() - 1:m.start()] == ".":
            continue                       # "Yu et al. 2012", "eq. 3", "e.g. a sensor"
        first = text[:m.start()] + "."
        break
    first = re.sub(r":\w+:`~?([^`]+)`", r"``\1``", first).replace("*", "")    # roles -> literals
    first = first.replace("``", "`")                                           # RST -> MyST literal
    if len(first) > 200:                   # cut at a word, closing an open literal
        first = first[:200].rsplit(" ", 1)[0]
        first += ("`" if first.count("`") % 2 else "") + " ..."
    elif first.count("`") % 2:             # the sentence ended inside a literal
        first = first[:-1] + "`."
    return first


_NOT_SENTENCE_ENDS = {"al", "eq", "e.g", "i.e", "fig", "figs", "vs", "cf", "no", "sec"}


def api_pages(modules: list[str]) -> dict[str, str]:
    """The API reference as pages (MyST markdown), keyed by file stem: ``api_modules`` (the overview: one
    row per layer with its modules) and ``api_<layer>`` per layer of :data:`API_LAYERS` (a summary table
    of its modules, then one ``automodule`` section per module, :func:`api_markdown`)."""
    groups = {name: [m for m in modules if api_layer(m) == name] for name, _, _ in API_LAYERS}
    overview = ["| layer | modules |", "|---|---|"]
    pages = {}
    for name, title, _ in API_LAYERS:
        mods = groups[name]
        if not mods:                      # the table of contents lists every layer's page
            pages[f"api_{name}"] = f"# {title}\n\nNo module of navlib belongs here yet.\n"
            continue
        overview.append(f"| {{doc}}`{title} </_generated/api_{name}>` | "
                        + ", ".join(f"`{m}`" for m in mods) + " |")
        table = ["| module | what it holds |", "|---|---|"]
        table += [f"| {{py:mod}}`{m}` | {_md_cell(module_summary(m))} |" for m in mods]
        pages[f"api_{name}"] = "\n".join([f"# {title}", ""] + table + ["", api_markdown(mods)])
    pages["api_modules"] = "\n".join(overview) + "\n"
    return pages


def write_api(out: Path) -> int:
    """Write the API overview to ``out`` and one page per layer beside it (``api_<layer>.md``)."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    mods = navlib_modules()
    pages = api_pages(mods)
    for stem, text in pages.items():
        (out if stem == "api_modules" else out.with_name(f"{stem}.md")).write_text(text, encoding="utf-8")
    print(f"api-modules: {len(mods)} modules on {len(pages) - 1} pages -> {out.parent}")
    return 0


# ------------------------------------------------------------------------------------------ results check
def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


CLAIM_TEXT_KEYS = ("claim", "paper", "ours", "reading")


def claim_problems(c: dict) -> list[str]:
    """Schema problems of one stored claim, and whether its verdict follows from its interval, boundary,
    side, noise floor and by-construction flag by the one rule (:func:`navlib.verdicts.decide`): a
    verdict set by hand fails here."""
    p = []
    for k in CLAIM_TEXT_KEYS:
        if not isinstance(c.get(k), str) or not c.get(k).strip():
            p.append(f"{k} missing or empty")
    if c.get("source") not in verdicts.SOURCES:
        p.append(f"source {c.get('source')!r}: must be 'paper' or 'book'")
    if "data" in c and c["data"] not in verdicts.DATA:       # files written before the field have none
        p.append(f"data {c.get('data')!r}: must be 'simulated' or 'real'")
    rule = c.get("rule")
    if rule not in verdicts.RULES:
        p.append(f"rule {rule!r}: must be one of {sorted(verdicts.RULES)}")
    interval, boundary, side = c.get("interval"), c.get("boundary"), c.get("holds_when")
    if rule == "no statistic":
        if interval is not None:
            p.append("rule 'no statistic' with an interval")
    else:
        if not (isinstance(interval, list) and len(interval) == 2 and all(_is_num(v) for v in interval)
                and interval[0] <= interval[1]):
            p.append(f"interval {interval!r}: must be [lo, hi] with lo <= hi")
            interval = None
        if not _is_num(boundary):
            p.append(f"boundary {boundary!r}: must be a number")
            boundary = None
        if side not in verdicts.SIDES:
            p.append(f"holds_when {side!r}: must be 'above' or 'below'")
            side = None
        est = c.get("estimate")
        if not _is_num(est):
            p.append(f"estimate {est!r}: must be a number")
        elif interval is not None and not (interval[0] - 1e-12 * abs(est) <= est <= interval[1]
                                           + 1e-12 * abs(est)):
            p.append(f"estimate {est} lies outside its interval {interval}")
        if not isinstance(c.get("statistic"), str) or not c["statistic"].strip():
            p.append("statistic missing: say what the interval is of, with its unit")
    floor = c.get("floor")
    floor_value = None
    if floor is not None:
        fi = floor.get("interval") if isinstance(floor, dict) else None
        if not (isinstance(floor, dict) and _is_num(floor.get("value"))
                and all(isinstance(floor.get(k), str) and floor[k].strip() for k in ("assumption", "needs"))):
            p.append("floor must be null or {value, interval, assumption, needs}")
        elif fi is not None and not (isinstance(fi, list) and len(fi) == 2 and all(_is_num(v) for v in fi)
                                     and fi[0] <= floor["value"] <= fi[1]):
            p.append(f"floor interval {fi!r}: must be [lo, hi] around the floor's value")
        else:
            floor_value = tuple(fi) if fi is not None else floor["value"]
    if not isinstance(c.get("volatile", False), bool):
        p.append("volatile must be true or false")
    if not isinstance(c.get("by_construction"), bool):
        p.append("by_construction must be true or false")
    dec = c.get("decided_by")
    if not (isinstance(dec, list) and all(isinstance(d, str) and d.strip() for d in dec)):
        p.append("decided_by must be a list of texts (possibly empty)")
    if "reproduced" not in c or c["reproduced"] not in (True, False, None):
        p.append("reproduced must be true, false or null")
    elif not p:
        try:
            margin = c.get("margin")
            if margin is not None and not _is_num(margin):
                return p + [f"margin {margin!r}: a number or null"]
            want, basis = verdicts.decide(interval, boundary, side, floor_value, c["by_construction"], margin)
        except InputError as err:
            return p + [str(err)]
        if c["reproduced"] is not want:
            p.append(f"verdict {c.get('verdict')!r} does not follow from interval {interval}, boundary "
                     f"{boundary} ({side}), floor {floor_value}, margin {margin}: the rule gives "
                     f"{verdicts.verdict_name(want, basis)!r}")
        if c.get("verdict") != verdicts.verdict_name(c["reproduced"], c.get("basis")):
            p.append(f"verdict {c.get('verdict')!r} disagrees with reproduced={c['reproduced']}")
        if c.get("basis") != basis:
            p.append(f"basis {c.get('basis')!r}, the rule gives {basis!r}")
        elif "reason" in c:               # files written before the field have none
            want_reason = verdicts.reason_category(basis, c.get("why") or "")
            if c["reason"] != want_reason:
                p.append(f"reason {c['reason']!r}, the basis {basis!r} and the why give {want_reason!r}")
    if c.get("reproduced") is None and not (isinstance(c.get("why"), str) and c["why"].strip()):
        p.append("cannot be judged without a why")
    return p


REGISTER_KEYS = ("id", "quote", "where", "primary_reading")


def register_problems(c: dict) -> list[str]:
    """Problems of a claims-register record (one with ``sensitivity``, :func:`navlib.claims.evaluate`):
    the register's fields present (a paper's claim needs its words, where they are and the primary
    reading), a list of sensitivity records, a status the register knows."""
    if "sensitivity" not in c:
        return []
    p = []
    for k in REGISTER_KEYS:
        if not (isinstance(c.get(k), str) and c[k].strip()) and not (k == "quote" and c.get("source") == "book"):
            p.append(f"{k} missing or empty (the claims register)")
    if not isinstance(c.get("sensitivity"), list):
        p.append("sensitivity must be a list of claim records")
    if c.get("status") not in ("judged", "open", "not checkable"):
        p.append(f"status {c.get('status')!r}: judged, open or not checkable")
    elif (c["status"] == "judged") == (c.get("rule") == "no statistic" and c.get("reason") in
                                       ("not yet computed", "not checkable")) or (
            c.get("reason") == "not run" and c["status"] != "judged"):
        p.append(f"status {c['status']!r} disagrees with its reason {c.get('reason')!r}")
    return p


def flat_claims(res: dict) -> list[dict]:
    """Every judged row of a results file: each claim record and its sensitivity records."""
    out = []
    for c in res.get("claims") or []:
        out.append(c)
        out.extend(c.get("sensitivity") or [])
    return out


def validate_results(res: dict, name: str) -> list[str]:
    """Schema problems of one results file (see ``navbook.report.write_results``)."""
    p = []
    if not isinstance(res, dict):
        return [f"{name}: not a JSON object"]
    if res.get("chapter") != Path(name).stem:
        p.append(f"{name}: 'chapter' is {res.get('chapter')!r}, expected {Path(name).stem!r}")
    claims = res.get("claims")
    if not isinstance(claims, list) or not claims:
        p.append(f"{name}: 'claims' must be a non-empty list")
        claims = []
    for i, c in enumerate(claims):
        if not isinstance(c, dict):
            p.append(f"{name}: claims[{i}] is not an object")
            continue
        p += [f"{name}: claims[{i}] ({c.get('claim')!r}, {c.get('reading')}): {q}"
              for q in claim_problems(c) + register_problems(c)]
        for j, s in enumerate(c.get("sensitivity") or []):
            p += [f"{name}: claims[{i}].sensitivity[{j}] ({s.get('claim')!r}, {s.get('reading')}): {q}"
                  for q in (claim_problems(s) if isinstance(s, dict) else ["not an object"])]
    methods = res.get("methods")
    if methods is not None:
        unit = res.get("unit")
        if not isinstance(unit, str) or not unit:
            p.append(f"{name}: 'methods' given without a 'unit'")
            unit = "?"
        if not isinstance(methods, dict) or not methods:
            p.append(f"{name}: 'methods' must be a non-empty object")
            methods = {}
        required = [f"{k}_{unit}" for k in ("median_rms", "p10_rms", "p90_rms")] + ["n_seeds"]
        optional = {f"median_min_{unit}", f"median_max_{unit}"}
        for label, stats in methods.items():
            if not isinstance(stats, dict):
                p.append(f"{name}: methods[{label!r}] is not an object")
                continue
            for k in required:
                if k not in stats:
                    p.append(f"{name}: methods[{label!r}] lacks {k!r}")
            for k, v in stats.items():
                if k not in required and k not in optional:
                    p.append(f"{name}: methods[{label!r}] has an unknown key {k!r}")
                elif k == "n_seeds" and not (isinstance(v, int) and not isinstance(v, bool) and v > 0):
                    p.append(f"{name}: methods[{label!r}].n_seeds must be a positive integer")
                elif k != "n_seeds" and not (v is None or _is_num(v)):
                    p.append(f"{name}: methods[{label!r}].{k} must be a number or null")
    return p


def _close(a, b, rtol: float, atol: float) -> bool:
    if a is None or b is None:
        return a is b
    if not (math.isfinite(a) and math.isfinite(b)):
        return a == b
    return abs(a - b) <= atol + rtol * abs(b)


def compare_results(fresh: dict, ref: dict, name: str, rtol: float = RTOL, atol: float = ATOL) -> list[str]:
    """Differences between a fresh results file and its committed reference: the same methods and
    statistics (numbers within ``atol + rtol * |reference|``, seed counts equal), the same claims (texts,
    source, rule, side) with the same verdicts, estimates, intervals and boundaries (within the same
    tolerance; a ``volatile`` claim, a timing, is compared on its verdict, texts and boundary only), the
    same top-level tables of records (``write_results(tables=...)``, compared exactly), and the same
    ``extra`` keys (their values are free-form, timings among them, and are not compared)."""
    p = []
    fm, rm = fresh.get("methods") or {}, ref.get("methods") or {}
    if fresh.get("unit") != ref.get("unit"):
        p.append(f"{name}: unit {fresh.get('unit')!r}, reference {ref.get('unit')!r}")
    if set(fm) != set(rm):
        p.append(f"{name}: methods {sorted(fm)} differ from the reference's {sorted(rm)}")
    for label in sorted(set(fm) & set(rm)):
        for k in sorted(set(fm[label]) | set(rm[label])):
            a, b = fm[label].get(k, "missing"), rm[label].get(k, "missing")
            if k == "n_seeds" or not (_is_num(a) or a is None) or not (_is_num(b) or b is None):
                ok = a == b
            else:
                ok = _close(a, b, rtol, atol)
            if not ok:
                p.append(f"{name}: methods[{label!r}].{k} = {a}, reference {b} "
                         f"(tolerance {rtol:g} relative + {atol:g})")
    fc, rc = flat_claims(fresh), flat_claims(ref)
    def ids_of(res):       # a record judged on real data is its entry's id marked "(real)"
        return [c.get("id") if claims_mod.data_of(c) == "simulated" else f"{c.get('id')} (real)"
                for c in res.get("claims") or []]

    ids = ids_of(fresh), ids_of(ref)
    if ids[0] != ids[1]:
        p.append(f"{name}: claim ids {ids[0]} differ from the reference's {ids[1]}")
    if len(fc) != len(rc):
        p.append(f"{name}: {len(fc)} claims, reference {len(rc)}")
    for i, (a, b) in enumerate(zip(fc, rc)):
        for k in ("claim", "reading", "paper", "source", "rule", "holds_when", "by_construction"):
            if a.get(k) != b.get(k):
                p.append(f"{name}: claims[{i}].{k} {a.get(k)!r} differs from the reference {b.get(k)!r}")
        if claims_mod.data_of(a) != claims_mod.data_of(b):    # a missing field is "simulated"
            p.append(f"{name}: claims[{i}].data {claims_mod.data_of(a)!r} differs from the reference "
                     f"{claims_mod.data_of(b)!r}")
        if a.get("reproduced") != b.get("reproduced"):
            p.append(f"{name}: claim {a.get('claim')!r} ({a.get('reading')}): verdict "
                     f"{a.get('reproduced')}, reference {b.get('reproduced')}")
        if a.get("volatile") != b.get("volatile"):
            p.append(f"{name}: claims[{i}].volatile {a.get('volatile')!r} differs from the reference "
                     f"{b.get('volatile')!r}")
        if a.get("volatile") and b.get("volatile"):
            # a timing: its numbers follow this machine's clock; its verdict must still be the reference's
            x, y = a.get("boundary"), b.get("boundary")
            if not (_is_num(x) and _is_num(y) and _close(x, y, rtol, atol)):
                p.append(f"{name}: claims[{i}].boundary = {x}, reference {y}")
            continue
        for k in ("estimate", "boundary"):
            x, y = a.get(k), b.get(k)
            if (_is_num(x) and _is_num(y) and not _close(x, y, rtol, atol)) or (_is_num(x) != _is_num(y)):
                p.append(f"{name}: claims[{i}].{k} = {x}, reference {y} (tolerance {rtol:g} relative)")
        x, y = a.get("interval"), b.get("interval")
        if (x is None) != (y is None) or (x is not None and y is not None and not (
                len(x) == len(y) == 2 and all(_is_num(u) and _is_num(v) and _close(u, v, rtol, atol)
                                              for u, v in zip(x, y)))):
            p.append(f"{name}: claims[{i}].interval = {x}, reference {y} (tolerance {rtol:g} relative)")
    base = {"chapter", "unit", "methods", "claims", "extra"}
    for key in sorted((set(fresh) | set(ref)) - base):  # tables (write_results tables=), inconsistencies          # tables of records (write_results tables=)
        if fresh.get(key) != ref.get(key):
            p.append(f"{name}: table {key!r} differs from the reference's "
                     f"({len(fresh.get(key) or [])} records, reference {len(ref.get(key) or [])})")
    fe, re_ = fresh.get("extra") or {}, ref.get("extra") or {}
    if set(fe) != set(re_):
        p.append(f"{name}: extra keys {sorted(fe)} differ from the reference's {sorted(re_)}")
    # extra values are free-form (timings among them): only their presence is compared
    return p


def check_results(fresh_dir: Path, ref_dir: Path, notebooks: list[Path], rtol: float = RTOL,
                  atol: float = ATOL) -> int:
    """Check every chapter notebook's fresh results file (written by the nbval run) against its committed
    reference in ``ref_dir``; print each problem; 1 if any."""
    fresh_dir, ref_dir = Path(fresh_dir), Path(ref_dir)
    problems, checked = [], []
    chapters = {}
    for nb in notebooks:
        nb = Path(nb)
        chapter = results_chapter(nb)
        if chapter is None:
            problems.append(f"{nb}: writes no results file: its last code cell must call "
                            f"report.write_results('<chapter>', claims=...)")
            continue
        chapters[chapter] = nb
        ref_path, fresh_path = ref_dir / f"{chapter}.json", fresh_dir / f"{chapter}.json"
        if not ref_path.exists():
            problems.append(f"{ref_path}: missing reference for {nb}: regenerate it with "
                            f"'.venv/bin/python -m navbook execute --in-place {nb}' (or make "
                            f"notebooks) and commit it")
            continue
        if not fresh_path.exists():
            problems.append(f"{fresh_path}: {nb} wrote no fresh results: run the notebooks first "
                            f"(make test-notebooks)")
            continue
        try:
            ref = json.loads(ref_path.read_text(encoding="utf-8"))
            fresh = json.loads(fresh_path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as err:
            problems.append(f"{chapter}.json: not valid JSON ({err.msg}, line {err.lineno})")
            continue
        problems += [f"reference {q}" for q in validate_results(ref, f"{chapter}.json")]
        problems += [f"fresh {q}" for q in validate_results(fresh, f"{chapter}.json")]
        problems += compare_results(fresh, ref, f"{chapter}.json", rtol, atol)
        checked.append(chapter)
    for stray in sorted(ref_dir.glob("*.json")) if ref_dir.is_dir() else []:
        if stray.stem not in chapters:
            problems.append(f"{stray}: no notebook writes chapter {stray.stem!r}: delete the file or fix the "
                            f"chapter name")
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        print(f"check-results: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(f"check-results: {len(checked)} chapter(s) reproduce their stored results "
          f"({', '.join(checked)}; numbers within {rtol:g} relative + {atol:g} absolute, verdicts equal)")
    return 0


# ------------------------------------------------------------------------------------------ screenshots
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--no-first-run")
CHROMIUM_MISSING = ("chromium not found: install it with 'apt-get install -y chromium' (Debian package "
                    "chromium) or pass --chromium /path/to/chromium")

#: JavaScript run on each page: output blocks and tables wider than the article (cut or scrolling).
_OVERFLOW_JS = r"""(() => {
  const art = document.querySelector('article') || document.body;
  const right = art.getBoundingClientRect().right;
  const out = [];
  const heading = el => { let h = null;
    document.querySelectorAll('h1, h2, h3').forEach(x => {
      if (x.compareDocumentPosition(el) & Node.DOCUMENT_POSITION_FOLLOWING) h = x; });
    return h ? h.textContent.replace(/[#\s]+$/, '').trim() : ''; };
  art.querySelectorAll('.cell_output pre, .cell_output .output, .cell_output img, table').forEach(el => {
    const r = el.getBoundingClientRect();
    const over = Math.max(el.scrollWidth - el.clientWidth, r.right - right);
    if (r.width > 0 && over > 2) out.push({heading: heading(el), overflow_px: Math.round(over),
      what: el.tagName.toLowerCase() + '.' + (el.className || '').toString().split(' ').slice(0, 2).join('.'),
      text: (el.innerText || '').trim().slice(0, 60)});
  });
  return out; })()"""


# Every figure in the article: its natural width (the PNG's pixels) and the width the page shows it at.
_FIGURES_JS = r"""(() => {
  const art = document.querySelector('article') || document.body;
  const heading = el => { let h = null;
    document.querySelectorAll('h1, h2, h3').forEach(x => {
      if (x.compareDocumentPosition(el) & Node.DOCUMENT_POSITION_FOLLOWING) h = x; });
    return h ? h.textContent.replace(/[#\s]+$/, '').trim() : ''; };
  return [...art.querySelectorAll('img')].map(el => ({heading: heading(el),
    src: (el.getAttribute('src') || '').split('/').pop(), natural_px: el.naturalWidth,
    shown_px: Math.round(el.getBoundingClientRect().width)}));
})()"""


#: The first screen of a page (1400 x 900 px): each source's headline verdict must end within it.
FIRST_SCREEN_PX = 900
#: The tallest a chapter may be at 1400 px with its folds closed: 15 screens.
CHAPTER_MAX_PX = 15 * FIRST_SCREEN_PX
#: Opens every fold of a page (``<details>``: a section's evidence, captioned tables, code).
_OPEN_FOLDS_JS = "document.querySelectorAll('details').forEach(d => { d.open = true; }); "
#: Every headline verdict on a page (``.navbook-headline``): where it ends, from the top of the page.
_HEADLINES_JS = r"""(() => [...document.querySelectorAll('.navbook-headline')].map(el => ({
  bottom_px: Math.round(el.getBoundingClientRect().bottom + window.scrollY),
  text: (el.innerText || '').trim().slice(0, 80)})))()"""


#: A figure displayed below this share of its natural width is flagged (:func:`shrunk_figures`).
MIN_DISPLAY_SHARE = 0.75


def shrunk_figures(figures, min_share: float | None = None) -> list[dict]:
    """The figures displayed below ``min_share`` (default
    :data:`MIN_DISPLAY_SHARE`, 75 %) of their natural width, each
    ``{"heading", "src", "natural_px", "shown_px", "share"}``, from records of the page's images
    (``natural_px``: the image's own width; ``shown_px``: its width on the page).  Images not loaded or
    not shown (a width of 0) are not figures on the page and are skipped."""

    limit = MIN_DISPLAY_SHARE if min_share is None else float(min_share)
    if not 0 < limit <= 1:
        raise ValueError(f"min_share={min_share!r}: must be in (0, 1]")
    out = []
    for f in figures:
        natural, shown = float(f.get("natural_px") or 0), float(f.get("shown_px") or 0)
        if natural <= 0 or shown <= 0:
            continue
        share = shown / natural
        if share < limit:
            out.append({"heading": f.get("heading", ""), "src": f.get("src", ""),
                        "natural_px": int(natural), "shown_px": int(shown), "share": round(share, 3)})
    return out


class _Chrome:
    """Headless Chromium driven over the DevTools protocol on a pipe (``--remote-debugging-pipe``: the
    browser reads JSON messages from fd 3 and writes to fd 4, each ending with a NUL byte)."""

    def __init__(self, binary: str, timeout_s: float = 60.0):
        self.timeout_s = timeout_s
        self.profile = tempfile.mkdtemp(prefix="navbook-chromium-")
        to_chrome_r, self._to_chrome_w = os.pipe()
        self._from_chrome_r, from_chrome_w = os.pipe()

        def child_fds():            # runs in the child before exec: put the pipe ends on fds 3 and 4
            a = fcntl.fcntl(to_chrome_r, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_chrome_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [binary, *CHROMIUM_FLAGS, f"--user-data-dir={self.profile}", "--remote-debugging-pipe",
             "--hide-scrollbars", "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=child_fds, close_fds=False)
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self._buf = b""
        self._id = 0
        self.events: list[dict] = []

    def send(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._to_chrome_w, json.dumps(msg).encode() + b"\0")
        while True:
            m = self._read()
            if m.get("id") == self._id:
                if "error" in m:
                    raise RuntimeError(f"chromium: {method}: {m['error'].get('message')}")
                return m.get("result", {})
            self.events.append(m)

    def wait_event(self, method: str, session: str | None = None) -> dict:
        while True:
            for k, e in enumerate(self.events):
                if e.get("method") == method and (session is None or e.get("sessionId") == session):
                    return self.events.pop(k)
            self.events.append(self._read())

    def wait_loaded(self, session: str, url: str) -> None:
        """Poll until the page at ``url`` has finished loading (events of the blank page that preceded it
        must not be mistaken for its load event)."""
        deadline = time.monotonic() + self.timeout_s
        probe = {"expression": "document.readyState + ' ' + location.href", "returnByValue": True}
        while time.monotonic() < deadline:
            try:
                state = self.send("Runtime.evaluate", probe, session=session)["result"].get("value", "")
            except RuntimeError:            # the context was replaced by the navigation: ask again
                state = ""
            if state == f"complete {url}":
                self.events.clear()
                return
            time.sleep(0.1)
        raise TimeoutError(f"chromium: {url} did not load within {self.timeout_s:.0f} s")

    def _read(self) -> dict:
        deadline = time.monotonic() + self.timeout_s
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            ready, _, _ = select.select([self._from_chrome_r], [], [], max(left, 0))
            if not ready:
                raise TimeoutError(f"chromium did not answer within {self.timeout_s:.0f} s")
            chunk = os.read(self._from_chrome_r, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium exited")
            self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def close(self):
        try:
            self.send("Browser.close")
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._to_chrome_w, self._from_chrome_r):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self.profile, ignore_errors=True)


def find_chromium(explicit: str | None = None) -> str | None:
    """The Chromium binary: ``explicit``, else ``chromium`` / ``chromium-browser`` / ``google-chrome``."""
    if explicit:
        return explicit if Path(explicit).exists() or shutil.which(explicit) else None
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    return None


#: The tallest single screenshot (px): Chromium draws taller full-page captures shifted and with blank
#: blocks (seen on the 25,000 px gyro page), so a taller page is written as viewport-high tiles.
TILE_PX = 16000


def _capture(chrome, session, metrics: dict, height: int, png: Path) -> None:
    """Capture the page in ``session`` at its full ``height`` into ``png``; a page taller than
    :data:`TILE_PX` as viewport-high tiles ``png``, ``<stem>-2.png``, ... (Chromium refuses one capture taller
    than its texture limit, "Page is too large")."""
    if height <= TILE_PX:
        chrome.send("Emulation.setDeviceMetricsOverride", {**metrics, "height": height}, session=session)
        # let the theme's sidebar transitions (0.25 s) finish at the new size before the capture
        chrome.send("Runtime.evaluate", {"expression": "window.scrollTo(0, 0); new Promise(r => "
                    "setTimeout(r, 400)).then(() => 1)", "awaitPromise": True}, session=session)
        # the viewport is the whole page: no captureBeyondViewport, which lays a long chapter out again
        # without its left sidebar and shifted left (seen on every chapter page)
        shot = chrome.send("Page.captureScreenshot", {"format": "png"}, session=session)
        png.write_bytes(base64.b64decode(shot["data"]))
        return
    chrome.send("Emulation.setDeviceMetricsOverride", {**metrics, "height": TILE_PX}, session=session)
    for k, top in enumerate(range(0, height, TILE_PX)):
        chrome.send("Runtime.evaluate", {"expression": f"window.scrollTo(0, {top}); new Promise("
                    "r => setTimeout(r, 200)).then(() => 1)", "awaitPromise": True}, session=session)
        shot = chrome.send("Page.captureScreenshot", {"format": "png"}, session=session)
        tile = png if k == 0 else png.with_name(f"{png.stem}-{k + 1}.png")
        tile.write_bytes(base64.b64decode(shot["data"]))


def screenshots(html_dir: Path, out_dir: Path, width: int = 1400, chromium: str | None = None,
                settle_s: float = 0.5) -> int:
    """Render every page under ``html_dir`` at ``width`` px, full page height, into ``out_dir`` (same
    relative names, ``.png``, folds closed as a reader first sees the page, and ``-open.png`` with every fold
    open; a page taller than :data:`TILE_PX` as tiles ``-2.png``, ``-3.png``, ...); write ``heights.csv``
    (page, height with folds closed and open) and ``long.json`` (chapters taller than
    :data:`CHAPTER_MAX_PX` with their folds closed) and ``overflow.json`` (output blocks
    or tables wider than the content column, by page) and ``shrunk.json`` (figures displayed below 75 % of
    their natural width, :func:`shrunk_figures`, by page) and ``headlines.json`` (headline verdicts,
    ``.navbook-headline``, that end below the first :data:`FIRST_SCREEN_PX` px).  Returns 2 if Chromium
    is missing, 1 if a chapter is too tall, a figure is shown shrunk or a headline verdict is not on the
    first screen (the figures and overflow are checked with every fold open; every
    page is still rendered and listed), else 0."""
    binary = find_chromium(chromium)
    if binary is None:
        print(CHROMIUM_MISSING, file=sys.stderr)
        return 2
    html_dir, out_dir = Path(html_dir).resolve(), Path(out_dir)
    pages = [p for p in sorted(html_dir.rglob("*.html"))
             if p.relative_to(html_dir).parts[0] not in ("_modules", "_sources", "_static", "_images")
             and p.name not in ("search.html", "genindex.html", "py-modindex.html")
             and 'http-equiv="refresh"' not in p.read_text(encoding="utf-8", errors="replace")[:2000].lower()]
    out_dir.mkdir(parents=True, exist_ok=True)
    chrome = _Chrome(binary)
    heights, overflow, shrunk, headlines, long_pages = [], {}, {}, {}, {}
    toc = html_dir.parent.parent / "_toc.yml"
    chapters = set(read_chapter_sources(toc.with_name("chapters.csv"))) if toc.exists() else set()
    try:
        for page in pages:
            rel = page.relative_to(html_dir)
            target = chrome.send("Target.createTarget", {"url": "about:blank"})["targetId"]
            session = chrome.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
            chrome.send("Page.enable", session=session)
            metrics = {"width": width, "height": 900, "deviceScaleFactor": 1, "mobile": False}
            chrome.send("Emulation.setDeviceMetricsOverride", metrics, session=session)
            chrome.send("Page.navigate", {"url": page.as_uri()}, session=session)
            chrome.wait_loaded(session, page.as_uri())
            wait = (f"new Promise(r => setTimeout(r, {int(settle_s * 1000)}))"
                    ".then(() => (window.MathJax && MathJax.startup) ? MathJax.startup.promise : null)"
                    ".then(() => document.fonts.ready).then(() => 1)")
            chrome.send("Runtime.evaluate", {"expression": wait, "awaitPromise": True}, session=session)
            js_height = ("Math.max(document.documentElement.scrollHeight, document.body.scrollHeight, "
                         "...[...document.querySelectorAll('.bd-main, .bd-container, .bd-page-width')]"
                         ".map(e => e.scrollHeight))")
            closed_h = int(chrome.send("Runtime.evaluate", {"expression": js_height, "returnByValue": True},
                                       session=session)["result"]["value"])
            if rel.parts[0] == "_generated" and rel.stem in chapters and closed_h > CHAPTER_MAX_PX:
                long_pages[str(rel)] = closed_h
            heads = chrome.send("Runtime.evaluate", {"expression": _HEADLINES_JS, "returnByValue": True},
                                session=session)["result"].get("value") or []
            late = [hd for hd in heads if hd["bottom_px"] > FIRST_SCREEN_PX]
            if late:
                headlines[str(rel)] = late
            png = out_dir / rel.with_suffix(".png")
            png.parent.mkdir(parents=True, exist_ok=True)
            # the page as a reader first sees it (folds closed), then with every fold open: the figures and
            # tables inside the folds are checked and captured too (page-open.png)
            _capture(chrome, session, metrics, closed_h, png)
            folds = chrome.send("Runtime.evaluate", {"expression": "document.querySelectorAll('details').length",
                                                     "returnByValue": True}, session=session)["result"]["value"]
            h = closed_h
            if folds:
                h = int(chrome.send("Runtime.evaluate", {"expression": _OPEN_FOLDS_JS + js_height,
                                                         "returnByValue": True}, session=session)["result"]["value"])
                _capture(chrome, session, metrics, h, png.with_name(png.stem + "-open.png"))
            chrome.send("Emulation.setDeviceMetricsOverride", {**metrics, "height": min(h, TILE_PX)},
                        session=session)
            found = chrome.send("Runtime.evaluate", {"expression": _OVERFLOW_JS, "returnByValue": True},
                                session=session)["result"].get("value") or []
            small = shrunk_figures(chrome.send("Runtime.evaluate", {"expression": _FIGURES_JS,
                                                                    "returnByValue": True},
                                               session=session)["result"].get("value") or [])
            chrome.send("Target.closeTarget", {"targetId": target})
            heights.append((str(rel), closed_h, h))
            if found:
                overflow[str(rel)] = found
            if small:
                shrunk[str(rel)] = small
            note = f"; {len(found)} block(s) wider than the content column" if found else ""
            note += f"; {len(small)} figure(s) shown below 75 % of their width" if small else ""
            print(f"{rel}: {width} x {h} px -> {png}{note}", flush=True)
    finally:
        chrome.close()
    with open(out_dir / "heights.csv", "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["page", "height_px", "height_open_px"])
        w.writerows(heights)
    for name, found in (("overflow.json", overflow), ("shrunk.json", shrunk), ("headlines.json", headlines)):
        (out_dir / name).write_text(json.dumps(found, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    for page, items in overflow.items():
        for it in items:
            print(f"  wider than the column: {page}: {it['what']} by {it['overflow_px']} px under "
                  f"'{it['heading']}': {html.unescape(it['text'])[:50]!r}", file=sys.stderr)
    for page, items in shrunk.items():
        print(f"  figures shrunk on {page}: {len(items)}", file=sys.stderr)
        for it in items:
            print(f"    {it['src']} shown at {it['shown_px']} of {it['natural_px']} px "
                  f"({100 * it['share']:.0f} %) under '{it['heading']}'", file=sys.stderr)
    for page, items in headlines.items():
        for it in items:
            print(f"  headline verdict below the first screen ({FIRST_SCREEN_PX} px) on {page}: ends at "
                  f"{it['bottom_px']} px: {it['text'][:60]!r}", file=sys.stderr)
    print(f"screenshots: {len(heights)} pages -> {out_dir} (heights.csv, long.json, overflow.json, shrunk.json, "
          f"headlines.json)")
    for page, h in long_pages.items():
        print(f"  chapter taller than {CHAPTER_MAX_PX // FIRST_SCREEN_PX} screens with its folds closed: {page}: "
              f"{h} px (limit {CHAPTER_MAX_PX} px): put a section's evidence behind its fold ({{evidence}})",
              file=sys.stderr)
    (out_dir / "long.json").write_text(json.dumps(long_pages, indent=1) + "\n", encoding="utf-8")
    if long_pages:
        return 1
    if headlines:
        print(f"screenshots: {sum(map(len, headlines.values()))} headline verdict(s) on {len(headlines)} "
              f"page(s) are not on the first {FIRST_SCREEN_PX} px: shorten what comes before them",
              file=sys.stderr)
        return 1
    if shrunk:
        print(f"screenshots: {sum(map(len, shrunk.values()))} figure(s) on {len(shrunk)} page(s) shown below "
              f"75 % of their natural width (draw them at most 7.5 in wide: navbook.report.use_style, "
              f"report.panels)", file=sys.stderr)
        return 1
    return 0


# ------------------------------------------------------------------------------------------ CLI
def compile_kernels() -> int:
    """Compile (or load from numba's on-disk cache) every compiled kernel of :mod:`navlib.methods.jit` by
    running the chapters' methods once on a tiny problem, so the first notebook of a fresh checkout does
    not pay the one-time compilation (tens of seconds) in its execution time."""
    # Imported here, not at the top: the other commands must not pay torch's import.
    from dataclasses import replace as _replace                      # noqa: PLC0415
    import numpy as np                                                # noqa: PLC0415
    import pandas as pd                                               # noqa: PLC0415
    from navlib.methods.de import DEParams                            # noqa: PLC0415
    from navlib.studies import paper_a                                # noqa: PLC0415
    t0 = time.perf_counter()
    x = np.linspace(-10.0, 370.0, 24)
    t = np.linspace(0.0, 360.0, 24)
    sw = paper_a.Sweeps(pd.DataFrame({"true_heading_deg": t, "measured_heading_deg": x}),
                        pd.DataFrame({"true_heading_deg": t, "measured_heading_deg": x}))
    p = paper_a.StudyParams(de=DEParams(pop_size=8, max_generations=3), lm=_replace(paper_a.StudyParams().lm,
                                                                                     epochs=3))
    paper_a.seed_study(sw, p, seeds=range(2), methods=("ade_bp_pure", "ade_bp_hybrid_trainlm",
                                                         "bp_matlab_val", "elm_backtuned"))
    print(f"compiled kernels ready in {time.perf_counter() - t0:.1f} s")
    return 0
