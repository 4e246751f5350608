"""Check the built HTML pages (``python -m navbook check-html``).

``check-html DIR [--baseline FILE]``
    Fail if a built page loads anything from the network, shows an execution error, has an output block
    wider than the content column (a preformatted line over :data:`MAX_PRE_CHARS` characters), a figure
    without a caption or a visible nbval marker, or is a chapter (``_generated/``) that does not open with
    its *Results at a glance* admonition.  Also (:data:`LAYOUT_KINDS`): a code line over
    :data:`MAX_CODE_CHARS` characters that is not folded, pandas' index-name row or a snake_case column
    name in a result table, and a chapter whose glance box counts its claims differently from the landing
    page; these fail only beyond the page's count in the baseline (``book/check_html_baseline.json``).
"""

from __future__ import annotations

import html
import json
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

from navlib import verdicts
from navlib.cli import build_parser
from navlib.errors import InputError

#: A preformatted output line longer than this does not fit the content column at 1400 px (measured in
#: headless Chromium on the built book with sphinx-book-theme 1.3; an output ``<pre>`` is 784 px wide with
#: 32 px of padding, and its 14 px monospace font is 8.43 px per character, so 89 characters fit).
MAX_PRE_CHARS = 89
#: A line of a code block shown on a page (a notebook's input cell not folded away, a command on the landing
#: page) longer than this scrolls sideways in the content column at 1400 px (the code font is the output's,
#: in a box a few pixels narrower than an output block's).
MAX_CODE_CHARS = 88
#: The layout checks (each message of :func:`check_page` of these kinds starts
#: with the kind).  Pages built before them carry such problems: ``check-html`` fails only where a page has
#: more of a kind than its entry in the baseline file (:func:`load_baseline`), and reports the rest.
LAYOUT_KINDS = ("wide code line", "index-name row", "snake_case header", "counts differ")


REMOTE = re.compile(r"""(?:src|href)\s*=\s*["'](?:https?:)?//(?!localhost)""", re.I)
_VOID = {
    "area",
    "base",
    "br",
    "col",
    "embed",
    "hr",
    "img",
    "input",
    "link",
    "meta",
    "param",
    "source",
    "track",
    "wbr",
}


class _PageScan(HTMLParser):
    """One pass over a built page: collects the problems :func:`check_page` reports."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack: list[tuple[str, set[str]]] = []
        self.heading = ""  # the last section heading seen (to say where a problem is)
        self._in_heading = False
        self._heading_buf: list[str] = []
        self.pre_stack: list[list[str]] = []  # text of output <pre> blocks being read
        self.figures: list[dict] = []  # open <figure> elements
        self.problems: list[str] = []
        self._skip = 0  # inside <script>/<style>
        self.code_stack: list[list[str]] = []  # text of code <pre> blocks (not outputs) being read
        self.tables: list[dict] = []  # open result tables (inside cell outputs)

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
                self.problems.append(
                    f"figure without a caption {self._where()} (image '{alt}'): glue it "
                    f"with report.glue_figure and show it with a glue:figure directive "
                    f"that has a caption"
                )
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
            self.heading = (
                re.sub(r"\s+", " ", "".join(self._heading_buf)).strip().rstrip("#").strip()
            )
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
                self.problems.append(
                    f"figure{name} without a caption {self._where()}: give the "
                    f"glue:figure/figure directive a caption paragraph"
                )
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
            self.problems.append(
                f"visible nbval marker '{m.group(0).strip()}' {self._where()}: use the cell "
                f"tag nbval-ignore-output (or nbval-skip) instead of the comment"
            )

    def _check_width(self, text: str, limit: int, what: str, shown: int, advice: str):
        """The first line of a block wider than ``limit`` characters, as one problem (one per block)."""
        for line in text.splitlines():
            if len(line.rstrip()) > limit:
                self.problems.append(
                    f"{what} of {len(line.rstrip())} characters (max {limit}) {self._where()}: "
                    f"'{line.strip()[:shown]}...': {advice}"
                )
                return

    def _check_pre(self, text: str):
        self._check_width(
            text,
            MAX_PRE_CHARS,
            "output line",
            70,
            "show a report.table(...) or shorten the printed text",
        )

    def _check_code(self, text: str):
        self._check_width(
            text,
            MAX_CODE_CHARS,
            "wide code line",
            60,
            "break the line (or fold the cell: tag hide-input)",
        )

    def _check_header_row(self, table: dict, row: list[tuple[bool, str]]):
        """A header row of a result table: pandas' index-name row (the index's name alone, the column
        cells blank), and snake_case column names (``median_rms_deg``: say "median RMS (deg)")."""
        if (
            len(row) >= 2
            and "index" not in table["flagged"]
            and (row[0][0] or (row[0][1] and not any(text for _, text in row[1:])))
        ):
            table["flagged"].add("index")
            self.problems.append(
                f"index-name row '{row[0][1]}' in a result table {self._where()}: reset the "
                f"index or set its name to None (report.table(..., index=False))"
            )
        snake = [text for _, text in row if SNAKE.fullmatch(text)]
        if snake and "snake" not in table["flagged"]:
            table["flagged"].add("snake")
            self.problems.append(
                f"snake_case header '{snake[0]}' in a result table {self._where()} "
                f"({len(snake)} in the row): name the column in words with its unit in "
                f"parentheses"
            )


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
#: The admonition that closes every chapter (:func:`navbook.claim_boxes.showed`).
SHOWED = "What this chapter showed"
#: The known problems of the :data:`LAYOUT_KINDS` per page, in the book folder (``book/``).
BASELINE_FILE = "check_html_baseline.json"


def check_chapter_opening(text: str) -> list[str]:
    """A chapter page (executed notebook) must open with the *Results at a glance* admonition: present,
    and before the first code cell."""
    m = re.search(r'<p class="admonition-title">\s*' + GLANCE, text)
    if not m:
        return [
            f"chapter without a '{GLANCE}' admonition: open the chapter with report.glance(claims) "
            f"glued into a ':::{{admonition}} {GLANCE}' block"
        ]
    first_cell = text.find('<div class="cell docutils container')
    if 0 <= first_cell < m.start():
        return [
            f"the '{GLANCE}' admonition comes after a code cell: move it right after the title and intro"
        ]
    return []


def check_chapter_closing(text: str) -> list[str]:
    """A chapter page must close with the *What this chapter showed* admonition, after its last code cell,
    and that box must count the same claims as the chapter's *Results at a glance* box."""
    m = None
    for m in re.finditer(r'<p class="admonition-title">\s*' + SHOWED, text):
        pass
    if m is None:
        return [
            f"chapter without a '{SHOWED}' admonition: close the chapter with report.showed(claims) "
            f"glued into a ':::{{admonition}} {SHOWED}' block"
        ]
    if text.find('<div class="cell docutils container', m.end()) >= 0:
        return [f"the '{SHOWED}' admonition is not at the chapter's end: a code cell follows it"]
    shown = _box_counts(text[m.end() :])
    glance = glance_counts(text)
    if glance is not None and shown != glance:
        return [
            f"the '{SHOWED}' box counts {shown} but the glance box {glance}: build both from the same "
            f"claims"
        ]
    return []


_TALLY = re.compile(
    r"The (paper's|book's own) claims: (\d+) of (\d+) reproduced, (\d+) not reproduced, "
    r"(\d+) cannot be judged(?:, (\d+) no difference)?"
)
_COUNTS_TAG = re.compile(r'<span class="navbook-counts"([^>]*)>')


def glance_counts(text: str) -> dict[str, tuple[int, int, int]] | None:
    """The counts a chapter page's *Results at a glance* box shows (its tallies "The paper's claims: k of
    n reproduced, m not reproduced, j cannot be judged"), by source; None without a glance box."""
    m = re.search(r'<p class="admonition-title">\s*' + GLANCE, text)
    if not m:
        return None
    end = text.find('<div class="cell docutils container', m.end())
    return _box_counts(text[m.end() : end if end >= 0 else len(text)])


def _box_counts(fragment: str) -> dict[str, tuple[int, int, int]]:
    """The tallies ("The paper's claims: k of n reproduced, m not reproduced, j cannot be judged") in an
    HTML fragment, by source: the first of each."""
    box = re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", fragment)))
    out = {}
    for t in _TALLY.finditer(box):
        out.setdefault(
            "paper" if t.group(1) == "paper's" else "book",
            (int(t.group(2)), int(t.group(4)), int(t.group(5)), int(t.group(6) or 0)),
        )
    return out


def landing_counts(text: str) -> dict[str, dict]:
    """The counts the landing page shows (:func:`navbook.landing.status_markdown`'s ``navbook-counts``
    marks), by chapter page: ``{"_generated/compass.html": {"chapter": ..., "paper": (r, nr, cj), "book": (r, nr, cj)}}``."""
    out = {}
    for m in _COUNTS_TAG.finditer(text):
        a = dict(re.findall(r'([\w-]+)="([^"]*)"', m.group(1)))
        if "data-page" in a:
            out[a["data-page"]] = {
                "chapter": a.get("data-chapter", ""),
                **{
                    src: (tuple(int(v) for v in a.get(f"data-{src}", "").split()) + (0, 0, 0, 0))[
                        :4
                    ]
                    for src in verdicts.SOURCES
                },
            }
    return out


def count_problems(
    landing: dict[str, dict], chapter_pages: dict[str, str]
) -> list[tuple[str, str]]:
    """``(page, problem)`` where a chapter's glance box and the landing page count its claims differently
    (both must come from the chapter's results file: every claim it writes is in its glance box)."""
    out = []
    for page, want in sorted(landing.items()):
        text = chapter_pages.get(page)
        if text is None:
            out.append(
                (
                    "intro.html",
                    f"counts differ: the landing page counts {page}, which was not built",
                )
            )
            continue
        got = glance_counts(text) or {}
        for src in verdicts.SOURCES:
            shown = got.get(src, (0, 0, 0, 0))
            if tuple(want[src]) != tuple(shown):
                whose = "the paper's" if src == "paper" else "the book's own"
                out.append(
                    (
                        page,
                        f"counts differ: the glance box shows {whose} claims as {shown[0]} of "
                        f"{sum(shown)} reproduced / {shown[1]} not / {shown[2]} cannot be judged, the "
                        f"landing page (the results file) {want[src][0]} of {sum(want[src])} / "
                        f"{want[src][1]} / {want[src][2]}: pass every claim written to "
                        f"report.write_results to report.glance",
                    )
                )
    return out


def load_baseline(path: Path | None) -> dict[str, dict[str, int]]:
    """The known problems of the :data:`LAYOUT_KINDS` per page (``{"page": {"kind": count}}``), measured
    when the checks were added; ``check-html`` fails only where a page has more.  {} without a file."""
    if path is None or not Path(path).exists():
        return {}
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        return {
            page: {k: int(v) for k, v in kinds.items()} for page, kinds in data["pages"].items()
        }
    except (json.JSONDecodeError, KeyError, AttributeError, TypeError, ValueError) as err:
        raise InputError(
            f'{path}: not a check-html baseline ({{"pages": {{page: {{kind: count}}}}}}): '
            f"{type(err).__name__}: {err}"
        ) from None


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
    sub = next(a for a in build_parser()._actions if a.dest == "command").choices
    body = html.unescape(
        re.sub(r"<[^>]+>", "", re.sub(r"</(?:p|dt|dd|li|pre|div)>|<br\s*/?>", "\n", text))
    )
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
        run = subprocess.run(
            [sys.executable, "-m", "navlib", command, "--help"],
            capture_output=True,
            text=True,
            timeout=60,
        )
        if run.returncode != 0:
            out.append(
                f"'navlib {command} --help' failed (exit {run.returncode}): {run.stderr.strip()[-120:]}"
            )
            continue
        missing = sorted(
            o for o in options if not re.search(re.escape(o) + r"(?![\w-])", run.stdout)
        )
        if missing:
            out.append(
                f"'navlib {command} --help' does not show {', '.join(missing)}, which the page shows"
            )
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
            found += [
                (rel.as_posix(), p)
                for p in check_api_page(text, cli_page=rel.name == "api_cli.html")
            ]
        if is_chapter_page(rel):  # the chapters (executed notebooks)
            found += [
                (rel.as_posix(), p)
                for p in check_chapter_opening(text) + check_chapter_closing(text)
            ]
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
            problems.append(
                f"{page}: {len(ps)} problem(s) of the kind '{kind}', the baseline allows {allowed}"
                if allowed
                else f"{page}: {kind}: none allowed (the page had none)"
            )
        else:
            tolerated.setdefault(page, {})[kind] = len(ps)
    for page, kinds in sorted(tolerated.items()):
        print(
            f"check-html: known, to fix: {page}: "
            + ", ".join(f"{n} {k}" for k, n in kinds.items()),
            file=sys.stderr,
        )
    for p in problems[:limit]:
        print(p, file=sys.stderr)
    if len(problems) > limit:
        print(f"... and {len(problems) - limit} more", file=sys.stderr)
    if problems:
        print(f"check-html: {len(problems)} problem(s) in {len(pages)} pages", file=sys.stderr)
        return 1
    print(
        f"check-html: {len(pages)} pages: nothing loaded from the network, no errors, no output wider than "
        f"{MAX_PRE_CHARS} characters, every figure captioned, no nbval markers, every chapter opens with "
        f"its results at a glance; code lines, table headers and glance counts no worse than the baseline"
    )
    return 0
