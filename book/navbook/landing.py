"""The landing page's status from the chapters' results files (``python -m navbook status``).

``status RESULTS_DIR --notebooks DIR --out FILE [--toc FILE]``
    Write the top of the landing page (one row per chapter in the sidebar's order: source, a sentence and
    the counts by verdict with a bar; the box that defines the verdicts) to FILE, and its per-reading rows
    (one dropdown per chapter) to ``status_readings.md`` beside it, from the results files.
"""

from __future__ import annotations

import csv
import html
import re
import sys
from pathlib import Path

import nbformat

from navlib import claims as claims_mod
from navlib import verdicts
from navlib.errors import InputError

from .claim_boxes import reading_label
from .claim_boxes import record_label as report_label
from .execute import results_chapter
from .results import read_results
from .results_check import flat_claims


def notebook_title(nb_path: Path) -> str:
    """The first markdown heading of a notebook (its chapter title), else the file stem."""
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
BAR_COLOURS = {
    "reproduced": "#2e7d32",
    "not reproduced": "#c62828",
    "cannot be judged": "#9e9e9e",
    "no difference": "#1565c0",
}


def claim_counts(
    results: dict[str, dict], data: str = "simulated"
) -> dict[str, dict[str, dict[str, int]]]:
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
                counts[c.get("source", "paper")][
                    verdicts.verdict_name(c.get("reproduced"), c.get("basis"))
                ] += 1
        out[chapter] = counts
    return out


def real_text(counts: dict[str, int], whose: str = "paper's") -> str:
    """ "paper's claims on real data: 2 of 7 reproduced, 3 not reproduced, 2 cannot be judged" ("" for
    none)."""
    n = sum(counts.values())
    if not n:
        return ""
    text = (
        f"{whose} claims on real data: {counts['reproduced']} of {n} reproduced, {counts['not reproduced']} "
        f"not reproduced, {counts['cannot be judged']} cannot be judged"
    )
    return text + (
        f", {counts['no difference']} no difference" if counts.get("no difference") else ""
    )


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
    """ "12 (8 below our noise floor, 4 our interval contains the boundary)" for the claims that cannot be
    judged."""
    keys = [_reason_key(c) for c in claims if c.get("reproduced") is None]
    if not keys:
        return "0"
    found = {k: keys.count(k) for k in dict.fromkeys(keys)}
    parts = [
        f"{n} {verdicts.REASONS[k][0] if k else 'reason not recorded'}"
        for k, n in sorted(found.items(), key=lambda kv: -kv[1])
    ]
    return f"{len(keys)} ({', '.join(parts)})"


def verdict_sentence(
    counts: dict[str, int], whose: str = "the paper's", claims: list[dict] = ()
) -> str:
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
        lead, first = (
            "Mostly reproduced",
            f"{pct['reproduced']} {of} reproduce, {pct['not reproduced']} do not",
        )
    elif 2 * nr > n:
        lead, first = (
            "Mostly not reproduced",
            f"{pct['not reproduced']} {of} do not reproduce, {pct['reproduced']} do",
        )
    elif 2 * cj > n:
        lead = "Mostly cannot be judged"
        first = (
            f"{pct['cannot be judged']} {of} cannot be judged, {pct['reproduced']} reproduce, "
            f"{pct['not reproduced']} do not"
        )
    else:
        more = (
            "more reproduced than not"
            if r > nr
            else ("more not reproduced than reproduced" if nr > r else "as many reproduced as not")
        )
        lead, first = (
            f"Mixed, {more}",
            f"{pct['reproduced']} {of} reproduce, {pct['not reproduced']} do not",
        )
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
            parts.append(
                f'<rect x="{x:.1f}" y="0" width="{w:.1f}" height="{height_px}" '
                f'fill="{BAR_COLOURS[k]}"/>'
            )
        x += w
    return (
        f'<svg class="navbook-bar" width="{width_px}" height="{height_px}" role="img" '
        f'aria-label="{label}"><title>{label}</title>{"".join(parts)}</svg>'
    )


def _counts_cell(counts: dict[str, int]) -> str:
    n = sum(counts.values())
    nd = counts.get("no difference", 0)
    return (
        "–"
        if n == 0
        else (
            f"{counts['reproduced']} / {counts['not reproduced']} / {counts['cannot be judged']}"
            + (f" (+ {nd} no difference)" if nd else "")
        )
    )


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
    lines = [
        "(what-the-verdicts-mean)=",
        ":::{admonition} What the verdicts mean",
        ":class: note",
        "",
        "Every claim, the paper's and the book's own, is judged by one rule (`navlib.verdicts`) on a "
        "statistic of our runs with its 95 % interval and the claim's boundary "
        "(a paired difference over the same seeds where two methods are compared):",
        "",
    ]
    for label, text in verdicts.VERDICT_DEFINITIONS.items():
        lines.append(f"- **{label}**: {text}.")
    lines += [
        "",
        "The papers' claims and the book's own (tests the papers did not run) are counted apart, "
        "one count per claim of the source's claims register. Where a paper can be read in several "
        "ways, the chapter names the most plausible reading and why, counts the claim under it, and "
        "shows the verdict under every other reading (and on other drawn simulators) as sensitivity.",
        ":::",
    ]
    return "\n".join(lines)


def status_markdown(
    results: dict[str, dict],
    notebooks: list[Path],
    sources: dict[str, tuple[str, str]] | None = None,
) -> str:
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
        sentence = verdict_sentence(
            cnt[src], whose, [c for c in claims if c.get("source", "paper") == src]
        )
        tag = (
            f'<span class="navbook-counts" data-chapter="{html.escape(chapter)}" '
            f'data-page="{doc.lstrip("/")}.html" '
            f'data-paper="{" ".join(str(cnt["paper"][k]) for k in COUNTED)}" '
            f'data-book="{" ".join(str(cnt["book"][k]) for k in COUNTED)}"></span>'
        )
        src_text = f"<br>{_md_cell(source)}" if source else ""
        on_real = "".join(
            f"<br>{_md_cell(real_text(real[chapter][s], w))}"
            for s, w in (("paper", "paper's"), ("book", "book's own"))
            if sum(real[chapter][s].values())
        )
        rows += [
            f"* - {{doc}}`{_md_cell(title)} <{doc}>`{tag}{src_text}",
            f"  - {_md_cell(sentence)}",
            f"  - {stacked_bar(cnt[src])}<br>paper's: {_counts_cell(cnt['paper'])}<br>"
            f"book's own: {_counts_cell(cnt['book'])}{on_real}",
        ]
    if rows:
        lines = (
            [
                ":::{list-table}",
                ":header-rows: 1",
                ":class: navbook-summary",
                ":widths: 30 45 25",
                "",
                "* - chapter and source",
                "  - in one sentence",
                "  - claims: reproduced / not / cannot be judged",
            ]
            + rows
            + [":::"]
        )
    else:
        lines = ["No chapter has written its results yet."]
    if missing:
        lines += ["", f"Not yet summarised (no results file): {', '.join(missing)}."]
    lines = sources_markdown(results) + [""] + lines
    total = {
        src: {k: sum(counts[c][src][k] for c in counts) for k in COUNTED}
        for src in verdicts.SOURCES
    }
    if counts:
        lines += [
            "",
            f"In all, **{total['paper']['reproduced']} of {sum(total['paper'].values())}** of the "
            f"papers' claims reproduce, {total['paper']['not reproduced']} do not and "
            f"{total['paper']['cannot be judged']} cannot be judged; of the book's own claims "
            f"{total['book']['reproduced']} of {sum(total['book'].values())} hold. Counts are reproduced / "
            f"not reproduced / cannot be judged; bars: "
            + ", ".join(f'<span style="color:{BAR_COLOURS[k]}">&#9632;</span> {k}' for k in COUNTED)
            + ". Each chapter's *Results at a glance* lists the same claims; the readings are "
            "[below](status-by-reading).",
        ]
        total_real = {
            src: {k: sum(real[c][src][k] for c in real) for k in COUNTED}
            for src in verdicts.SOURCES
        }
        if sum(total_real["paper"].values()) + sum(total_real["book"].values()):
            lines += [
                "",
                "Judged again on real measurements and counted apart from the claims above (the same "
                "claims, on real data instead of our simulators): "
                + "; ".join(
                    real_text(total_real[s], w)
                    for s, w in (("paper", "the papers'"), ("book", "the book's own"))
                    if sum(total_real[s].values())
                )
                + ".",
            ]
    return "\n".join(lines) + "\n\n" + verdict_box() + "\n"


def sources_markdown(results: dict[str, dict]) -> list[str]:
    """The landing page's rows per source (paper A and document B apart): what the source claims in one
    line (its headline claim, in its words), the headline's verdict under the primary reading, and the
    source's claims (register entries, not readings) by verdict under their primary readings, with how
    many are judged, not yet computed and not checkable, and the contradictions noted."""
    rows, details = [], []
    order = list(claims_mod.SOURCE_NAMES)
    pairs = sorted(
        ((name, chapter) for chapter in results for name in claims_mod.registers(chapter)),
        key=lambda p: order.index(p[0]),
    )
    for name, chapter in pairs:
        res = results[chapter]
        recs = [c for c in res.get("claims", []) if "sensitivity" in c]
        mine = [
            c
            for c in recs
            if c.get("register") == name
            and c.get("source") == "paper"
            and claims_mod.data_of(c) == "simulated"
        ]
        if not mine:
            continue
        real = [
            c
            for c in recs
            if c.get("register") == name
            and c.get("source") == "paper"
            and claims_mod.data_of(c) == "real"
        ]
        n_real = {k: sum(c["verdict"] == k for c in real) for k in COUNTED}
        head = next((c for c in mine if c.get("headline")), None)
        n = {k: sum(c["verdict"] == k for c in mine) for k in COUNTED}
        st = {
            k: sum(c.get("status") == k for c in mine) for k in ("judged", "open", "not checkable")
        }
        noted = sum(1 for x in res.get("inconsistencies") or [] if x.get("register") == name)
        verdict = report_label(head) if head else "–"
        claim = head["claim"] if head else "–"
        rows += [
            f"* - {_md_cell(claims_mod.SOURCE_NAMES[name])} ({chapter})",
            f"  - {_md_cell(claim)}",
            f'  - <span class="navbook-headline"><b>{html.escape(verdict)}</b></span>'
            + (
                f"<br>({_md_cell(head['primary_reading'])})"
                if head and head.get("status") == "judged"
                else ""
            ),
            f"  - {stacked_bar(n, width_px=80)} {_counts_cell(n)} of {len(mine)}"
            + (f"<br>on real data: {_counts_cell(n_real)} of {len(real)}" if real else ""),
        ]
        details.append(
            f"{claims_mod.SOURCE_NAMES[name]} {st['judged']} judged, {st['open']} not yet computed, "
            f"{st['not checkable']} not checkable"
            + (f", {noted} contradiction{'s' if noted != 1 else ''} noted" if noted else "")
        )
    if not rows:
        return []
    return (
        [
            "",
            "(status-by-source)=",
            ":::{list-table}",
            ":header-rows: 1",
            ":class: navbook-summary",
            ":widths: 11 35 30 24",
            "",
            "* - source",
            "  - headline claim",
            "  - verdict (primary reading)",
            "  - claims",
        ]
        + rows
        + [
            ":::",
            "",
            "Claims: reproduced / not reproduced / cannot be judged, of all the source's "
            "claims. Each claim of a source's claims register counts once, under the reading its "
            "chapter finds most plausible (the others are shown there as sensitivity): "
            + "; ".join(details)
            + '. The claims judged again on real data ("on real data") '
            "are counted apart.",
        ]
    )


def readings_markdown(
    results: dict[str, dict],
    notebooks: list[Path],
    sources: dict[str, tuple[str, str]] | None = None,
) -> str:
    """The landing page's per-reading rows (MyST markdown): one dropdown per chapter, in the order of
    ``notebooks``, with a row per source and reading (its readable label, :func:`navbook.claim_boxes.reading_label`): claims,
    reproduced, not reproduced, and cannot be judged with the cases that apply."""
    parts = [
        "(status-by-reading)=",
        "## Claims by reading",
        "",
        "Where a paper's method or claim can be read in more than one way, each reading is judged on its "
        "own (the chapter says why each reading is plausible). Open a chapter to see its readings.",
        "",
    ]
    for chapter, doc, title, _ in _chapters(results, notebooks, sources):
        if chapter not in results:
            continue
        claims = [
            c
            for c in flat_claims(results[chapter])
            if c.get("rule") != "no statistic"
            or c.get("reason") not in ("not yet computed", "not checkable")
        ]
        readings = list(
            dict.fromkeys(
                (c.get("source", "paper"), c.get("reading", "as printed"), claims_mod.data_of(c))
                for c in claims
            )
        )
        parts += [
            f"::::{{dropdown}} {_md_cell(title)}: {len(claims)} rows (claims under readings), "
            f"{len(readings)} readings",
            "",
            f"{{doc}}`The chapter <{doc}>`.",
            "",
            "| reading | claims | reproduced | not reproduced | cannot be judged |",
            "|---|---|---|---|---|",
        ]
        for data in verdicts.DATA:
            for src in verdicts.SOURCES:
                for s, r, d in readings:
                    if s != src or d != data:
                        continue
                    cs = [
                        c
                        for c in claims
                        if c.get("source", "paper") == s
                        and c.get("reading", "as printed") == r
                        and claims_mod.data_of(c) == d
                    ]
                    label = (
                        reading_label(r)
                        + (" (the book's own claims)" if s == "book" else "")
                        + (" (on real data)" if d == "real" else "")
                    )
                    rep = sum(c.get("reproduced") is True for c in cs)
                    nrep = sum(c.get("reproduced") is False for c in cs)
                    parts.append(
                        f"| {_md_cell(label)} | {len(cs)} | {rep} | {nrep} | "
                        f"{_md_cell(_reasons_text(cs))} |"
                    )
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
    print(
        f"status: {len(results)} chapter(s) with results, {n_claims} claims -> {out}, {by_reading.name}"
    )
    no_results = [nb.name for nb in notebooks if (results_chapter(nb) or nb.stem) not in results]
    if no_results:
        print(
            f"status: no results file from {', '.join(no_results)} (the chapter's last cell must call "
            f"report.write_results)",
            file=sys.stderr,
        )
    return 0
