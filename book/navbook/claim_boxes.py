"""A chapter's claims in boxes (the *Results at a glance* box that opens the chapter, the answers per
claims-register entry, the *What this chapter showed* box that closes it), each verdict with its reason."""

from __future__ import annotations

import html
import re
import textwrap
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

import pandas as pd

from navlib import claims as registry
from navlib import verdicts
from navlib.claims import Claim
from navlib.errors import InputError
from navlib.formatting import fmt

from .tables import PLAIN_WIDTH, Table


GLANCE_COLUMNS = ["claim", "reading", "paper", "ours: value [95 % interval]", "boundary", "verdict"]
#: How the book names the claims judged on real measurements (``Claim.data == "real"``), counted apart.
ON_REAL = "on real data"


def _glance_frame(claims: list[Claim]) -> pd.DataFrame:
    rows = [
        {
            "claim": c.claim,
            "reading": c.reading,
            "paper": c.paper,
            GLANCE_COLUMNS[3]: c.ours_text,
            "boundary": c.boundary_text,
            "verdict": c.verdict + (f": {c.reason}" if c.reason else ""),
        }
        for c in claims
    ]
    return pd.DataFrame(rows, columns=GLANCE_COLUMNS)


def claim_table(claims: Iterable[Claim], extra: tuple[str, ...] = ()) -> pd.DataFrame:
    """One row per claim: its words, the fields named in ``extra`` (e.g. ``"reading"``, ``"source"``),
    ours with its 95 % interval, the boundary and the verdict, judged with the register entry's
    equivalence margin as the results file judges it (:func:`navlib.claims.with_register_margin`)."""
    rows = []
    for c in map(registry.with_register_margin, claims):
        row = {"claim": c.claim} | {f: getattr(c, f) for f in extra}
        row |= {
            "ours: value [95 % interval]": c.interval_text,
            "boundary": c.boundary_text,
            "verdict": c.verdict,
        }
        rows.append(row)
    return pd.DataFrame(rows)


def tally_of(v: list[str]) -> str:
    """ "k of n reproduced, m not reproduced, j cannot be judged" (", e no difference" where a claim's
    equivalence margin decided it) for a list of verdict names."""
    text = (
        f"{v.count('reproduced')} of {len(v)} reproduced, {v.count('not reproduced')} not reproduced, "
        f"{v.count('cannot be judged')} cannot be judged"
    )
    return text + (
        f", {v.count('no difference')} no difference" if v.count("no difference") else ""
    )


def tally(claims: Iterable[Claim]) -> str:
    """ "k of n reproduced, m not reproduced, j cannot be judged" (:func:`tally_of`)."""
    return tally_of([c.verdict for c in claims])


#: Abbreviations of the results files' reading labels, spelled out on the landing page and in the glance
#: boxes' folds (the glossary
#: explains the methods' names).
READING_WORDS = {
    r"\bval\. stop\b": "validation stop",
    r"\bsd\b": "standard deviations",
    r"\bKF\b": "Kalman filter",
    r"\bLOO\b": "leave-one-out",
}


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


#: The (claim, reading) pairs shown in a glance box in this process (:func:`navbook.results.write_results` warns about the
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
        rows = [
            {
                "claim": c.claim,
                "reading": c.reading,
                "paper": c.paper,
                GLANCE_COLUMNS[3]: c.ours_text,
                "boundary": c.boundary_text,
                "verdict": c.verdict_label + (f" ({c.reason})" if c.reason else ""),
            }
            for c in cs
        ]
        cols = GLANCE_COLUMNS if with_reading else [k for k in GLANCE_COLUMNS if k != "reading"]
        return pd.DataFrame(rows, columns=GLANCE_COLUMNS)[cols]

    link = (
        f'<p class="navbook-glance-note">{html.escape(caption, quote=False)} (<a href="{VERDICTS_HREF}">what the '
        f"verdicts mean</a>)</p>"
    )
    if len(claims) <= GLANCE_OPEN_ROWS:
        return link + Table(frame(claims), index=False)._repr_html_()
    readings = list(dict.fromkeys(c.reading for c in claims))
    parts = [link]
    for r in readings:
        cs = [c for c in claims if c.reading == r]
        parts.append(
            f"<details><summary>{html.escape(reading_label(r))}: {html.escape(tally(cs))}</summary>"
            + Table(frame(cs, with_reading=False), index=False)._repr_html_()
            + "</details>"
        )
    return "\n".join(parts)


def register_records(
    claims: Iterable["Claim | Mapping[str, Any]"],
    chapter: str | None,
    worlds: list[Mapping[str, Any]] | None = None,
) -> list[dict] | None:
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
        return f"no difference at margin {fmt(r.get('margin'), '{:.4g}')}" + (
            f" {r['unit']}" if r.get("unit") else ""
        )
    cat = r.get("reason")
    return (
        f"{r['verdict']}: {verdicts.REASONS[cat][0]}"
        if cat in verdicts.REASONS
        else str(r["verdict"])
    )


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
        text += (
            f" under the primary reading ({r['primary_reading']}): ours {_rec_ours(r)}; "
            f"{registry.across_text(r)}."
        )
    else:
        text += "."
    return text


def _rec_tally(records: list[Mapping[str, Any]]) -> str:
    return tally_of([r["verdict"] for r in records])


ANSWER_COLUMNS = [
    "id",
    "claim",
    "ours: value [95 % interval]",
    "verdict (primary reading)",
    "across readings",
]


def _answer_frame(records: list[Mapping[str, Any]]) -> pd.DataFrame:
    """One row per claim: the register's short words for it (the paper's own words, where they are and
    why the primary reading is the most plausible are in the claim's fold below the table)."""
    rows = [
        {
            "id": r["id"],
            "claim": r["claim"],
            ANSWER_COLUMNS[2]: _rec_ours(r),
            ANSWER_COLUMNS[3]: record_label(r)
            + (
                f" ({r['primary_reading']})"
                if r.get("status") == "judged" and r.get("row_claim")
                else ""
            ),
            "across readings": registry.across_text(r)
            if r.get("status") == "judged" and r.get("row_claim")
            else "–",
        }
        for r in records
    ]
    return pd.DataFrame(rows, columns=ANSWER_COLUMNS)


def _claim_fold(r: Mapping[str, Any]) -> str:
    """One claim's fold: the paper's words and where, the primary reading and why, the dimensions, and
    every row (the primary first) with its verdict and reason."""
    head = (
        f"<p><b>{html.escape(r['id'])}</b> \u201c{html.escape(r.get('quote') or r['claim'])}\u201d "
        f"({html.escape(r['where'])})"
    )
    if r.get("quote_zh"):
        head += f' <span lang="zh">{html.escape(r["quote_zh"])}</span>'
    head += "</p>"
    if r.get("why_primary"):
        head += (
            f"<p>Primary reading: {html.escape(r['primary_reading'])}. "
            f"{html.escape(r['why_primary'])}</p>"
        )
    if r.get("dimensions"):
        head += f"<p>Shown across: {html.escape(r['dimensions'].rstrip('.'))}.</p>"
    counts = registry.verdict_counts_text(r) if r.get("row_claim") else ""
    if counts:
        head += f"<p>Verdicts over its {html.escape(counts)}"
        head += f" ({html.escape(registry.across_text(r))}).</p>"
    if r.get("status") != "judged" or not r.get("row_claim"):
        return head + f"<p>{html.escape(r.get('why') or '')}</p>"
    rows = [{**r, "claim": r["row_claim"]}] + list(r["sensitivity"])
    frame = pd.DataFrame(
        [
            {
                "claim": x["claim"],
                "reading": x["reading"] + (" (primary)" if x is rows[0] else ""),
                "ours: value [95 % interval]": x.get("ours") or "–",
                "verdict": record_label(x) + (f" ({x['why']})" if x.get("why") else ""),
            }
            for x in rows
        ]
    )
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
                recs = [
                    r for r in self.records if r["source"] == src and registry.data_of(r) == data
                ]
                if recs:
                    yield src, title + suffix, recs

    def tables(self) -> list[Table]:
        out = []
        for src, title, recs in self._groups():
            for name in registry.registers(self.chapter):
                mine = [r for r in recs if r["register"] == name]
                if mine:
                    out.append(
                        Table(
                            _answer_frame(mine),
                            index=False,
                            readable=False,
                            caption=f"{title}: {_rec_tally(recs)}; "
                            f"{registry.SOURCE_NAMES[name]}: {_rec_tally(mine)}",
                        )
                    )
        if self.noted:
            out.append(
                Table(
                    pd.DataFrame(
                        [
                            {
                                "id": n["id"],
                                "the paper says": n["claim"],
                                "where": n["where"],
                                "its own numbers": n["numbers"],
                            }
                            for n in self.noted
                        ]
                    ),
                    index=False,
                    readable=False,
                    caption="Where the paper contradicts itself",
                )
            )
        return out

    def _repr_html_(self) -> str:
        parts = []
        for r in registry.headlines(self.records):
            parts.append(f'<p class="navbook-headline">{_inline_md(headline_sentence(r))}</p>')
        for src, title, recs in self._groups():
            real = registry.data_of(recs[0]) == "real"
            note = (
                f"{html.escape(title)}: {_rec_tally(recs)} (one row per claim, judged under its primary "
                f'reading; <a href="{VERDICTS_HREF}">what the verdicts mean</a>)'
            )
            # the claims judged again on real data: counted apart, their tables behind a fold
            parts.append(
                f'<details class="navbook-real"><summary class="navbook-glance-note">{note}</summary>'
                if real
                else f'<p class="navbook-glance-note">{note}</p>'
            )
            for name in registry.registers(self.chapter):
                mine = [r for r in recs if r["register"] == name]
                if mine:
                    if len(registry.registers(self.chapter)) > 1:
                        parts.append(
                            f"<p><b>{html.escape(registry.SOURCE_NAMES[name])}</b>: "
                            f"{_rec_tally(mine)}</p>"
                        )
                    parts.append(
                        Table(_answer_frame(mine), index=False, readable=False)._repr_html_()
                    )
            if real:
                parts.append("</details>")
        if self.noted:
            parts.append(
                f"<details><summary>Where the paper contradicts itself ({len(self.noted)})</summary>"
                + Table(self.tables()[-1].frame, index=False, readable=False)._repr_html_()
                + "</details>"
            )
        parts.append(self._readings_html())
        return "\n".join(parts)

    def _readings_html(self) -> str:
        """Every claim behind one fold, a dropdown per claim: the paper's words and where, the primary
        reading and why, and every row (each reading, noise level, split; the primary first)."""
        n = sum(1 + len(r["sensitivity"]) for r in self.records if r.get("row_claim"))
        inner = [
            f"<details><summary>{html.escape(r['id'])} {html.escape(r['claim'])}"
            f"{' (' + ON_REAL + ')' if registry.data_of(r) == 'real' else ''}: "
            f"{html.escape(registry.across_text(r) if r.get('row_claim') else record_label(r))}</summary>"
            + _claim_fold(r)
            + "</details>"
            for r in self.records
        ]
        return (
            f"<details><summary>The paper's words, the primary reading and why, and every claim under "
            f"every reading ({n} rows)</summary>" + "\n".join(inner) + "</details>"
        )

    def __repr__(self) -> str:
        out = [
            "\n".join(textwrap.wrap(headline_sentence(r).replace("**", ""), PLAIN_WIDTH))
            for r in registry.headlines(self.records)
        ]
        out += [repr(t) for t in self.tables()]
        return "\n\n".join(out)


def _inline_md(text: str) -> str:
    """HTML of a sentence with **bold** marks."""
    return re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", html.escape(text, quote=False))


class Glance:
    """The Results-at-a-glance tables: the paper's claims and the book's own claims apart, each row with
    the claim, the reading, the paper's number, ours with its 95 % interval, the boundary and the verdict
    with its reason.  Give it every claim of the chapter (the list passed to :func:`~navbook.results.write_results`): the
    landing page counts that list, and a glance that shows fewer claims disagrees with it (``navbook
    check-html`` compares the two).  On the page, a long list is folded by reading and each verdict says
    which case applies (:func:`navlib.verdicts.verdict_label`); the plain text (what nbval compares) is
    one table per source."""

    def __init__(self, claims: Iterable[Claim]):
        claims = list(claims)
        sim = [c for c in claims if c.data == "simulated"]
        self.paper = [c for c in sim if c.source == "paper"]
        self.book = [c for c in sim if c.source == "book"]
        self.real = {
            src: [c for c in claims if c.data == "real" and c.source == src]
            for src in verdicts.SOURCES
        }
        _GLANCED.update((c.claim, c.reading, c.data) for c in claims)

    def _groups(self):
        """(caption, claims) per source, the claims on real data after the simulated ones, each apart."""
        for cs, title in (
            (self.paper, "The paper's claims"),
            (self.book, "The book's own claims"),
            (self.real["paper"], f"The paper's claims {ON_REAL}"),
            (self.real["book"], f"The book's own claims {ON_REAL}"),
        ):
            if cs:
                yield f"{title}: {tally(cs)}", cs

    def tables(self) -> list[Table]:
        return [
            Table(_glance_frame(cs), index=False, caption=caption) for caption, cs in self._groups()
        ]

    def _repr_html_(self) -> str:
        return "\n".join(_glance_html(cs, caption) for caption, cs in self._groups())

    def __repr__(self) -> str:
        return "\n\n".join(repr(t) for t in self.tables())


def glance(
    claims: Iterable[Claim],
    chapter: str | None = None,
    worlds: list[Mapping[str, Any]] | None = None,
) -> "Glance | Answer":
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
    category: str | None  # the key of verdicts.REASONS of a claim that cannot be judged
    data: str = "simulated"  # what it was judged on (Claim.data)


def _outcome(c: "Claim | Mapping[str, Any]") -> _Outcome:
    """A claim or a results file's claim record, reduced to what the summary boxes need."""
    if isinstance(c, Claim):
        c = c.record()
    try:
        return _Outcome(
            str(c["claim"]),
            str(c.get("reading", "")),
            str(c["source"]),
            str(c["verdict"]),
            c.get("reason") if c["verdict"] == "cannot be judged" else None,
            registry.data_of(c),
        )
    except (KeyError, TypeError, AttributeError):
        raise InputError(
            f"a claim record without claim, source and verdict: {str(c)[:80]}"
        ) from None


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
    and the landing page (:class:`~navlib.claims.Claim` objects or the claim records of a results file): per source (the
    paper's claims, the book's own), the tally with the reasons of the claims that cannot be judged, and
    one line per claim with its verdicts over the readings."""

    def __init__(
        self, claims: Iterable["Claim | Mapping[str, Any]"], found: Mapping[Any, str] | None = None
    ):
        outs = [_outcome(c) for c in claims]
        parts = [
            (title + suffix, [c for c in outs if c.source == src and c.data == data])
            for data, suffix in (("simulated", ""), ("real", f" {ON_REAL}"))
            for src, title in (("paper", "The paper's claims"), ("book", "The book's own claims"))
        ]
        self.parts = [(t, cs) for t, cs in parts if cs]
        self.found = dict(found or {})

    def _rows(self, cs: list[_Outcome]) -> pd.DataFrame:
        """One row per claim; ``found`` is looked up by ``(claim, data)``, then by the claim alone."""
        names = list(dict.fromkeys(c.claim for c in cs))
        data = cs[0].data if cs else "simulated"
        return pd.DataFrame(
            [
                {
                    "claim": n,
                    "what we found": self.found.get((n, data))
                    or self.found.get(n)
                    or _claim_outcome([c for c in cs if c.claim == n]),
                }
                for n in names
            ],
            columns=["claim", "what we found"],
        )

    @staticmethod
    def _lead(title: str, cs: list[_Outcome]) -> str:
        why = _reason_counts(cs)
        return f"{title}: {tally(cs)}" + (f" ({why})" if why else "")

    def _repr_html_(self) -> str:
        out = []
        for title, cs in self.parts:
            out.append(
                f'<p class="navbook-showed">{html.escape(self._lead(title, cs), quote=False)}</p>'
            )
            out.append(
                "<details><summary>Claim by claim</summary>"
                + Table(self._rows(cs), index=False, readable=False)._repr_html_()
                + "</details>"
            )
        return "\n".join(out)

    def __repr__(self) -> str:
        out = []
        for title, cs in self.parts:
            out.extend(textwrap.wrap(self._lead(title, cs), PLAIN_WIDTH))
            out.append(repr(Table(self._rows(cs), index=False, readable=False)))
        return "\n".join(out)


def showed(
    claims: Iterable[Claim],
    chapter: str | None = None,
    worlds: list[Mapping[str, Any]] | None = None,
) -> Showed:
    """The *What this chapter showed* box (see :class:`Showed`); glue it into a ``:::{admonition} What
    this chapter showed`` block at the chapter's end.  With ``chapter`` (a chapter with a claims
    register) it counts claims, one per register entry, with the verdict under the primary reading."""
    claims = list(claims)
    records = register_records(claims, chapter, worlds)
    if records is None:
        return Showed(claims)
    found = {
        (r["claim"], registry.data_of(r)): record_label(r)
        + (
            f" (primary reading; {registry.across_text(r)})"
            if r.get("status") == "judged" and r.get("row_claim")
            else ""
        )
        for r in records
    }
    return Showed([{**r, "reading": "primary"} for r in records], found)
