"""The claims registers and their one evaluator: every checkable statement of a source, judged once.

A source's register (``data/claims_<source>.csv``, dictionary in ``data/claims.md``) lists each checkable
statement of the paper once: its words and where they are, the statistic, boundary and side that test it,
and, where the paper can be read several ways, the **primary reading** (the most plausible one, with a
sentence on why) and the dimensions along which the verdict is shown to move.  A chapter's study code
judges each statement under every reading, noise level or split it runs (one results row each, a
:class:`Claim`); :func:`evaluate` folds those rows into **one record per register entry**:
the primary row's statistic, interval, boundary, floor and verdict (by the book's one rule,
:func:`navlib.verdicts.decide`), the other rows as its ``sensitivity`` list, and a summary of how the
verdict moves across them (and across drawn worlds, e.g. the compass chapter's five drawn compasses).
Entries without results rows are kept as *not yet computed* (checkable: the register says what would
decide them) or *not checkable* (it says why); a paper's contradictions of itself are listed apart
(:func:`inconsistencies`).

Every results row must belong to exactly one entry: a chapter that writes a row the register does not
know stops with one line naming both (:class:`navlib.errors.InputError`).  The register holds each
claim's boundary, side and unit once: an entry's primary row that uses others stops the same way, naming
the entry, the field and both values (:func:`check_primary`).  A rerun with other parameters
may not run an entry's primary reading (or any of its rows: other parameters, or no real measurements):
the entry is then kept as *cannot be judged: its primary reading was not run*, with the rows that were
run as its sensitivity, and the run finishes.
"""

from __future__ import annotations

import csv
import functools
import math
import re
from dataclasses import dataclass, replace
from typing import Iterable, Mapping

import numpy as np

from . import verdicts
from .errors import InputError
from .formatting import fmt, plain
from .paths import data_path


# ------------------------------------------------------------------------------------- one results row
@dataclass(frozen=True)
class Claim:
    """One claim (the paper's or the book's own) and our verdict on it, under one reading of the paper.

    The verdict is never set by hand: it follows from the statistic's 95 % interval, the ``boundary``
    and the side on which the claim holds (``holds_when``), the noise ``floor`` of our experiment and
    whether the statistic is true ``by_construction`` of our simulator, by the one rule of
    :func:`navlib.verdicts.decide`.

    ``claim``: the claim in a few words; ``paper``: what the paper prints (text with units, or "(not in
    the paper)" for the book's own claims); ``source``: ``"paper"`` or ``"book"``; ``statistic``: what the
    interval is of, with its unit; ``estimate``: a :class:`navlib.verdicts.Estimate` (value, interval,
    rule), None when there is no statistic; ``unit``: the unit shown beside numbers; ``decided_by``: the
    simulator or method assumptions the verdict depends on; ``why``: the reason in words (required when
    the claim cannot be judged for lack of a statistic or by construction; otherwise added to the
    generated reason); ``ours``: an optional short text shown before the interval (e.g. "4.21 vs 9.58
    deg"); ``key``: a name for the prose (the book's ``glue_claims``); ``volatile``: the statistic is measured on
    this machine's clock (a timing), so a rerun reproduces its verdict but not its numbers (the results
    check then compares the verdict and the texts only); ``data``: what the statistic was computed on,
    ``"simulated"`` (our simulators, the default) or ``"real"`` (real measurements): the book counts
    claims on real data apart (the glance box, the landing page), with the same wording as the simulated
    row so the two can be compared."""

    claim: str
    paper: str
    reading: str = "as printed"
    source: str = "paper"
    statistic: str = ""
    estimate: verdicts.Estimate | None = None
    boundary: float | None = None
    holds_when: str | None = None
    unit: str = ""
    floor: verdicts.Floor | None = None
    by_construction: bool = False
    decided_by: tuple[str, ...] = ()
    why: str = ""
    ours: str = ""
    key: str = ""
    spec: str = "{:.3g}"
    volatile: bool = False
    margin: float | None = None
    data: str = "simulated"

    def __post_init__(self):
        for f in ("claim", "paper", "reading"):
            if not str(getattr(self, f)).strip():
                raise InputError(f"Claim.{f} is empty")
        if self.source not in verdicts.SOURCES:
            raise InputError(f"Claim.source={self.source!r}: must be 'paper' or 'book'")
        if self.data not in verdicts.DATA:
            raise InputError(f"Claim.data={self.data!r}: must be 'simulated' or 'real'")
        if not isinstance(self.decided_by, tuple) or not all(
            isinstance(d, str) and d.strip() for d in self.decided_by
        ):
            raise InputError(
                f"Claim.decided_by={self.decided_by!r}: must be a tuple of non-empty texts"
            )
        if self.estimate is not None:
            if not isinstance(self.estimate, verdicts.Estimate):
                raise InputError(
                    f"Claim.estimate: a navlib.verdicts.Estimate, got "
                    f"{type(self.estimate).__name__}"
                )
            if not str(self.statistic).strip():
                raise InputError(f"Claim {self.claim!r}: say what the statistic is (with its unit)")
            if self.boundary is None or not math.isfinite(float(self.boundary)):
                raise InputError(f"Claim {self.claim!r}: a statistic needs a finite boundary")
            if self.holds_when not in verdicts.SIDES:
                raise InputError(
                    f"Claim {self.claim!r}: holds_when={self.holds_when!r}: must be 'above' "
                    f"or 'below'"
                )
        elif not self.why.strip():
            raise InputError(f"Claim {self.claim!r}: without a statistic, 'why' must say why")
        if self.by_construction and not self.why.strip():
            raise InputError(
                f"Claim {self.claim!r}: true by construction: 'why' must say which setting"
            )
        if self.floor is not None and not isinstance(self.floor, verdicts.Floor):
            raise InputError("Claim.floor: a navlib.verdicts.Floor")
        if self.key and not self.key.isidentifier():
            raise InputError(f"Claim.key={self.key!r}: use letters, digits and underscores")

    @classmethod
    def of(cls, entry_id: str, claim: str, paper: str, **fields) -> Claim:
        """A results row of register entry ``entry_id`` judged against the register's ``boundary``,
        ``holds_when`` and ``unit`` (the register holds them once; :func:`evaluate` refuses a primary
        row that uses others).  ``claim`` must be one of the entry's ``rows``; the other fields are
        :class:`Claim`'s.  A ``boundary``, ``holds_when`` or ``unit`` given as well must agree with the
        register's (the boundary within a relative 1e-9), else :class:`navlib.errors.InputError`
        names both; a row judged against another boundary (a margin, another threshold) is built with
        :class:`Claim` itself.  Where the register lists several units (``ug or %``) the row's
        ``unit`` must be given, one of them.

        Examples
        --------
        >>> row = "the relation is nonlinear: a network beats a straight line"
        >>> c = Claim.of("C06", row, "nonlinear", statistic="s, deg/h",
        ...              estimate=verdicts.exact(-1e-5))
        >>> (c.boundary, c.holds_when, c.unit)
        (0.0, 'below', 'deg/h')
        """
        e = entry(entry_id)
        if claim not in e.rows:
            raise InputError(
                f"claims_{e.register}.csv, {e.id}: row {claim!r} is not one of its rows "
                f"{list(e.rows)}"
            )
        given = {k: fields[k] for k in ("boundary", "holds_when", "unit") if k in fields}
        units = units_of(e)
        if "unit" not in given and len(units) > 1:
            raise InputError(
                f"claims_{e.register}.csv, {e.id}: the register lists the units {e.unit!r}: "
                f"give the row's unit, one of them"
            )
        kw = {"boundary": e.boundary, "holds_when": e.holds_when, "unit": units[0], **fields}
        bad = _disagreement(e, {"estimate": 0.0, **kw})
        if bad is not None:
            field, want, got = bad
            raise InputError(
                f"claims_{e.register}.csv, {e.id}: {field}={got!r} given for row {claim!r} "
                f"({kw.get('reading', 'as printed')}), the register's is {want!r}: leave it out, or "
                f"build a row judged against another {field} with Claim"
            )
        return cls(claim, paper, **kw)

    # -- the rule
    @property
    def interval(self) -> tuple[float, float] | None:
        return None if self.estimate is None else self.estimate.interval

    @property
    def rule(self) -> str:
        return "no statistic" if self.estimate is None else self.estimate.rule

    def _decision(self) -> tuple[bool | None, str]:
        return verdicts.decide(
            self.interval,
            self.boundary,
            self.holds_when,
            self.floor,
            self.by_construction,
            self.margin,
        )

    @property
    def reproduced(self) -> bool | None:
        return self._decision()[0]

    @property
    def basis(self) -> str:
        return self._decision()[1]

    @property
    def verdict(self) -> str:
        return verdicts.verdict_name(*self._decision())

    @property
    def verdict_label(self) -> str:
        """The verdict with the case that applies: *cannot be judged: below our noise floor* and the like
        (:func:`navlib.verdicts.verdict_label`)."""
        return verdicts.verdict_label(self.reproduced, self.basis, self.reason)

    # -- display
    def _num(self, v) -> str:
        return fmt(v, self.spec) + (f" {self.unit}" if self.unit else "")

    def _bound(self) -> str:
        return fmt(self.boundary, "{:.4g}") + (f" {self.unit}" if self.unit else "")

    @property
    def boundary_text(self) -> str:
        if self.boundary is None:
            return "–"
        return ("< " if self.holds_when == "below" else "> ") + self._bound()

    @property
    def interval_text(self) -> str:
        """``value [lo, hi] unit`` (the 95 % interval), or "–" without a statistic."""
        e = self.estimate
        if e is None:
            return "–"
        if e.rule == "exact":
            return self._num(e.value) + " (exact)"
        unit = f" {self.unit}" if self.unit else ""
        return f"{fmt(e.value, self.spec)} [{fmt(e.lo, self.spec)}, {fmt(e.hi, self.spec)}]{unit}"

    @property
    def ours_text(self) -> str:
        return (
            f"{self.ours}; {self.interval_text}"
            if self.ours and self.estimate is not None
            else (self.ours or self.interval_text)
        )

    @property
    def reason(self) -> str:
        """Why the verdict is what it is, in words (never empty for *cannot be judged*)."""
        basis, extra = self.basis, self.why.strip()
        if basis == "straddles":
            lo, hi = self.interval
            text = (
                f"the 95 % interval [{fmt(lo, self.spec)}, {fmt(hi, self.spec)}] contains the boundary "
                f"{self._bound()}"
            )
        elif basis == "noise floor":
            f = self.floor
            flo, fhi = f.interval
            ftext = self._num(f.value) + (
                "" if flo == fhi else f" [{fmt(flo, self.spec)}, {fmt(fhi, self.spec)}]"
            )
            lo, hi = self.interval
            text = (
                f"our interval [{fmt(lo, self.spec)}, {fmt(hi, self.spec)}] does not lie beyond our "
                f"noise floor {ftext}, which is not {self.holds_when} the boundary {self._bound()} "
                f"(set by {f.assumption}); it would need {f.needs}"
            )
        elif basis == "equivalent":
            lo, hi = self.interval
            text = (
                f"the 95 % interval [{fmt(lo, self.spec)}, {fmt(hi, self.spec)}] lies within the "
                f"equivalence margin {self._bound()} +- {fmt(self.margin, '{:.4g}')}"
            )
        else:
            text = ""
        return "; ".join(t for t in (text, extra) if t)

    def record(self) -> dict:
        """The claim as stored in a results file (the book's ``write_results``)."""
        e = self.estimate
        return {
            "claim": self.claim,
            "reading": self.reading,
            "source": self.source,
            "paper": self.paper,
            "ours": self.ours_text,
            "statistic": self.statistic or None,
            "unit": self.unit,
            "rule": self.rule,
            "estimate": None if e is None else plain(e.value),
            "interval": None if e is None else [plain(e.lo), plain(e.hi)],
            "n": None if e is None else int(e.n),
            "boundary": None if self.boundary is None else plain(self.boundary),
            "holds_when": self.holds_when,
            "floor": None
            if self.floor is None
            else {
                "value": plain(self.floor.value),
                "interval": [plain(v) for v in self.floor.interval],
                "assumption": self.floor.assumption,
                "needs": self.floor.needs,
            },
            "by_construction": bool(self.by_construction),
            "decided_by": list(self.decided_by),
            "reproduced": self.reproduced,
            "verdict": self.verdict,
            "basis": self.basis,
            "reason": verdicts.reason_category(self.basis, self.reason),
            "why": self.reason,
            "key": self.key or None,
            "volatile": bool(self.volatile),
            "margin": None if self.margin is None else plain(self.margin),
            "data": self.data,
        }


def method_stats(rms, min_err=None, max_err=None) -> dict:
    """Headline statistics of one method over seeds: median, 10th and 90th percentile of the RMS error,
    median of the per-run minimum and maximum error, and the number of seeds (runs)."""
    r = np.asarray(rms, float)
    out = {
        "median_rms": float(np.median(r)),
        "p10_rms": float(np.quantile(r, 0.1)),
        "p90_rms": float(np.quantile(r, 0.9)),
        "n_seeds": int(r.size),
    }
    if min_err is not None:
        out["median_min"] = float(np.median(np.asarray(min_err, float)))
    if max_err is not None:
        out["median_max"] = float(np.median(np.asarray(max_err, float)))
    return out


# ------------------------------------------------------------------------------------------- registers
#: The registers each chapter's rows are judged against (file ``data/claims_<name>.csv``).
REGISTERS = {
    "compass": ("paper_a", "patent_b"),
    "gyro": ("paper_c",),
    "accelerometer": ("paper_d",),
    "celestial": ("paper_e",),
    "workbench": ("workbench",),
}
#: How the book names each register's source.
SOURCE_NAMES = {
    "paper_a": "Paper A",
    "patent_b": "Document B",
    "paper_c": "Paper C",
    "paper_d": "Paper D",
    "paper_e": "Paper E",
    "workbench": "The workbench",
}
KINDS = ("value", "comparison", "order", "rate", "qualitative", "inconsistency")
STATUSES = ("judged", "open", "not checkable", "noted")
COLUMNS = (
    "id",
    "origin",
    "headline",
    "kind",
    "status",
    "claim",
    "quote",
    "quote_zh",
    "where",
    "statistic",
    "boundary",
    "holds_when",
    "unit",
    "rows",
    "primary_claim",
    "primary_reading",
    "why_primary",
    "sensitivity",
    "needs",
    "margin",
    "margin_why",
)
_ID = re.compile(r"^[A-Z]\d{2,3}$")


@dataclass(frozen=True)
class Entry:
    """One register entry (one checkable statement of a source; the columns of ``data/claims.md``)."""

    id: str
    origin: str
    headline: bool
    kind: str
    status: str
    claim: str
    quote: str
    quote_zh: str
    where: str
    statistic: str
    boundary: float | None
    holds_when: str | None
    unit: str
    rows: tuple[str, ...]
    primary_claim: str
    primary_reading: str
    why_primary: str
    sensitivity: str
    needs: str
    margin: float | None
    margin_why: str
    register: str = ""


def _number(text: str, where: str) -> float | None:
    text = text.strip()
    if not text:
        return None
    try:
        return float(text)
    except ValueError:
        raise InputError(f"{where}: {text!r} is not a number") from None


def parse_register(lines: Iterable[str], name: str) -> tuple[Entry, ...]:
    """The entries of one register file's text (``name`` names it in messages), validated: one line
    naming file, row, entry and column for the first problem."""
    reader = csv.DictReader(lines)
    cols = tuple(reader.fieldnames or ())
    if set(cols) != set(COLUMNS):
        missing, extra = sorted(set(COLUMNS) - set(cols)), sorted(set(cols) - set(COLUMNS))
        raise InputError(
            f"{name}: columns differ from data/claims.md (missing {missing}, unknown {extra})"
        )
    out, seen = [], set()
    for i, raw in enumerate(reader, start=2):
        r = {k: (v or "").strip() for k, v in raw.items() if k is not None}
        at = f"{name}, row {i} ({r.get('id') or 'no id'})"

        def bad(col: str, why: str):
            raise InputError(f"{at}, column '{col}': {why}")

        if not _ID.match(r["id"]):
            bad("id", f"{r['id']!r}: a capital letter and 2-3 digits (A01)")
        if r["id"] in seen:
            bad("id", f"{r['id']} appears twice")
        seen.add(r["id"])
        if r["origin"] not in verdicts.SOURCES:
            bad("origin", f"{r['origin']!r}: 'paper' or 'book'")
        if r["headline"] not in ("", "yes"):
            bad("headline", f"{r['headline']!r}: 'yes' or empty")
        if r["kind"] not in KINDS:
            bad("kind", f"{r['kind']!r}: one of {list(KINDS)}")
        if r["status"] not in STATUSES:
            bad("status", f"{r['status']!r}: one of {list(STATUSES)}")
        for col in ("claim", "where"):
            if not r[col]:
                bad(col, "empty")
        if r["origin"] == "paper" and not r["quote"]:
            bad("quote", "empty: give the paper's words")
        if r["holds_when"] not in ("",) + verdicts.SIDES:
            bad("holds_when", f"{r['holds_when']!r}: 'above', 'below' or empty")
        rows = tuple(t.strip() for t in r["rows"].split(" ; ") if t.strip())
        if r["status"] == "judged":
            if not rows:
                bad("rows", "a judged entry names the results rows that test it")
            if r["primary_claim"] not in rows:
                bad("primary_claim", f"{r['primary_claim']!r} is not one of its rows")
            if not r["primary_reading"]:
                bad("primary_reading", "empty")
            if r["origin"] == "paper" and not r["why_primary"]:
                bad("why_primary", "say why the primary reading is the most plausible")
        else:
            if rows:
                bad("rows", f"a {r['status']!r} entry has no results rows")
            if not r["needs"]:
                bad(
                    "needs",
                    f"a {r['status']!r} entry says what would decide it or why it cannot be",
                )
        if r["margin"] and not r["margin_why"]:
            bad("margin_why", "say where the equivalence margin comes from")
        if (r["kind"] == "inconsistency") != (r["status"] == "noted"):
            bad("status", "an inconsistency is 'noted', and only an inconsistency is")
        out.append(
            Entry(
                id=r["id"],
                origin=r["origin"],
                headline=r["headline"] == "yes",
                kind=r["kind"],
                status=r["status"],
                claim=r["claim"],
                quote=r["quote"],
                quote_zh=r["quote_zh"],
                where=r["where"],
                statistic=r["statistic"],
                boundary=_number(r["boundary"], f"{at}, column 'boundary'"),
                holds_when=r["holds_when"] or None,
                unit=r["unit"],
                rows=rows,
                primary_claim=r["primary_claim"],
                primary_reading=r["primary_reading"],
                why_primary=r["why_primary"],
                sensitivity=r["sensitivity"],
                needs=r["needs"],
                margin=_number(r["margin"], f"{at}, column 'margin'"),
                margin_why=r["margin_why"],
                register=name.removeprefix("claims_").removesuffix(".csv"),
            )
        )
    heads = [e.id for e in out if e.headline]
    if any(e.headline and e.origin != "paper" for e in out):
        raise InputError(f"{name}: a headline is the source's own claim (origin 'paper')")
    if any(e.origin == "paper" for e in out) and len(heads) != 1:
        raise InputError(
            f"{name}: exactly one headline entry (headline = yes) is needed, found {heads}"
        )
    return tuple(out)


@functools.lru_cache(maxsize=None)
def load_register(name: str) -> tuple[Entry, ...]:
    """The entries of ``data/claims_<name>.csv`` (:func:`parse_register`)."""
    fname = f"claims_{name}.csv"
    try:
        with open(data_path(fname), newline="", encoding="utf-8") as fh:
            return parse_register(fh, fname)
    except FileNotFoundError:
        raise InputError(f"{fname}: no such claims register in navlib's data") from None


def entry(entry_id: str) -> Entry:
    """The register entry ``entry_id`` (ids are unique over every register)."""
    found = [
        e
        for names in REGISTERS.values()
        for n in names
        for e in load_register(n)
        if e.id == entry_id
    ]
    if len(found) != 1:
        raise InputError(
            f"entry {entry_id!r}: found {len(found)} times in the claims registers "
            f"(navlib.claims.REGISTERS), expected once"
        )
    return found[0]


def registers(chapter: str) -> tuple[str, ...]:
    """The register names a chapter is judged against (empty for a chapter without one)."""
    return REGISTERS.get(chapter, ())


def entries(chapter: str) -> tuple[Entry, ...]:
    """Every entry of the chapter's registers, in register order."""
    return tuple(e for name in registers(chapter) for e in load_register(name))


def row_margin(claim_text: str) -> float | None:
    """The equivalence margin of the register entry whose ``rows`` list ``claim_text`` (a results row's
    ``claim``), over every register; None when no entry (or entries with different margins) lists it.
    :func:`evaluate` judges a row with its entry's margin; prose glued from the row itself
    (``navbook.glue.glue_claims``) uses this so the two cannot disagree."""
    margins = {
        e.margin
        for names in REGISTERS.values()
        for name in names
        for e in load_register(name)
        if claim_text in e.rows
    }
    return margins.pop() if len(margins) == 1 else None


def with_register_margin(c: Claim) -> Claim:
    """``c`` judged with its register entry's equivalence margin (:func:`row_margin`), as
    :func:`evaluate` judges its row; ``c`` itself when it has a margin, no statistic or no entry with one."""
    if c.margin is not None or c.estimate is None:
        return c
    m = row_margin(c.claim)
    return c if m is None else replace(c, margin=m)


def _across(primary: Mapping, others: list[Mapping], worlds: list[Mapping] | None) -> dict:
    """How the primary verdict moves: across the other rows (readings, noise levels, splits) and across
    drawn worlds (records ``{"compass"|"world", "claim", "reading", "verdict"}`` of the primary row)."""
    v = primary["verdict"]
    out = {
        "rows": 1 + len(others),
        "same": 1 + sum(o["verdict"] == v for o in others),
        "verdicts": {
            k: sum(o["verdict"] == k for o in [primary, *others]) for k in verdicts.VERDICTS
        },
    }
    if worlds:
        mine = [
            w
            for w in worlds
            if w.get("claim") == primary["row_claim"] and w.get("reading") == primary["reading"]
        ]
        if mine:
            out["worlds"] = len(mine)
            out["worlds_same"] = sum(w.get("verdict") == v for w in mine)
    return out


def across_text(record: Mapping) -> str:
    """ "same in 4 of 5 readings; flips on 2 of 5 drawn compasses" (or "one reading") from a record's
    ``across`` summary."""
    a = record.get("across") or {}
    n = int(a.get("rows", 1))
    parts = [
        "one reading"
        if n == 1
        else (
            f"same in all {n} readings"
            if a.get("same") == n
            else f"same in {a.get('same')} of {n} readings"
        )
    ]
    if "worlds" in a:
        flips = a["worlds"] - a["worlds_same"]
        parts.append(
            f"same on all {a['worlds']} drawn compasses"
            if flips == 0
            else f"differs on {flips} of {a['worlds']} drawn compasses"
        )
    return "; ".join(parts)


def verdict_counts_text(record: Mapping) -> str:
    """ "13 rows: 5 reproduced, 7 cannot be judged, 1 no difference" from a record's ``across`` summary:
    how the verdict is spread over the entry's rows (the primary and its sensitivity), in the order of
    ``navlib.verdicts.VERDICTS``; empty for an entry without rows."""
    a = record.get("across") or {}
    n = int(a.get("rows") or 0)
    if n == 0:
        return ""
    counts = a.get("verdicts") or {}
    parts = [f"{counts[k]} {k}" for k in verdicts.VERDICTS if counts.get(k)]
    return f"{n} row{'s' if n != 1 else ''}: " + ", ".join(parts)


def _with_margin(r: dict, e: Entry) -> dict:
    """A row record judged again with the entry's equivalence margin (:func:`navlib.verdicts.decide`):
    only a row whose interval lies within the margin changes, to *no difference*."""
    if e.margin is None or r.get("interval") is None:
        return r
    f = r.get("floor")
    floor = None if f is None else tuple(f.get("interval") or (f["value"], f["value"]))
    rep, basis = verdicts.decide(
        r["interval"], r["boundary"], r["holds_when"], floor, r["by_construction"], e.margin
    )
    out = {**r, "margin": e.margin}
    if basis == "equivalent":
        lo, hi = r["interval"]
        out.update(
            reproduced=rep,
            basis=basis,
            verdict=verdicts.verdict_name(rep, basis),
            reason=None,
            why=f"the 95 % interval [{lo:.4g}, {hi:.4g}] lies within the equivalence margin "
            f"{r['boundary']:.4g} +- {e.margin:g} {e.unit}".rstrip()
            + f" ({e.margin_why})",
        )
    return out


def _unjudged(e: Entry, cat: str | None = None) -> dict:
    cat = cat or ("not yet computed" if e.status == "open" else "not checkable")
    return {
        "claim": e.claim,
        "reading": "as printed",
        "source": e.origin,
        "paper": e.quote or e.claim,
        "ours": "–",
        "statistic": e.statistic or None,
        "unit": e.unit,
        "rule": "no statistic",
        "estimate": None,
        "interval": None,
        "n": None,
        "boundary": None,
        "holds_when": None,
        "floor": None,
        "by_construction": False,
        "decided_by": [],
        "reproduced": None,
        "verdict": "cannot be judged",
        "basis": "no statistic",
        "reason": cat,
        "why": verdicts.REGISTER_REASONS[cat] + e.needs,
        "key": None,
        "volatile": False,
        "row_claim": None,
        "primary_reading": e.primary_reading if cat == "not run" else f"none ({cat})",
    }


def data_of(record: Mapping) -> str:
    """What a row or record was judged on: ``"simulated"`` or ``"real"`` (a record written before the
    field existed is ``"simulated"``)."""
    return record.get("data") or "simulated"


def units_of(e: Entry) -> tuple[str, ...]:
    """The units a row of entry ``e`` may carry: the register's ``unit``, or, where it lists several
    joined by the word *or* (a worst case chosen over cases in different units, D13's ``ug or %``),
    any of them."""
    return tuple(u.strip() for u in e.unit.split(" or ")) if e.unit else ("",)


def _disagreement(e: Entry, row: Mapping) -> tuple[str, object, object] | None:
    """The first of ``boundary``, ``holds_when`` and ``unit`` on which the results row ``row`` disagrees
    with its register entry ``e`` (field, register's value, row's value), or None.  The boundary agrees
    within a relative 1e-9::

        |b_row - b_register| <= 1e-9 max(|b_row|, |b_register|)

    A row with neither a statistic nor a boundary (a row that says why it was not run) carries nothing
    to compare."""
    if row.get("estimate") is None and row.get("boundary") is None:
        return None
    b = row.get("boundary")
    if (b is None) != (e.boundary is None) or (
        b is not None and not math.isclose(float(b), e.boundary, rel_tol=1e-9, abs_tol=0.0)
    ):
        return "boundary", e.boundary, b
    if row.get("holds_when") != e.holds_when:
        return "holds_when", e.holds_when, row.get("holds_when")
    if (row.get("unit") or "") not in units_of(e):
        return "unit", e.unit, row.get("unit") or ""
    return None


def check_primary(e: Entry, row: Mapping) -> None:
    """Refuse a primary row whose boundary, side or unit is not its register entry's: the register holds
    each claim's boundary once, and the row that judges it must use it.  One line naming the register
    file, the entry, the field and both values (:class:`navlib.errors.InputError`)."""
    bad = _disagreement(e, row)
    if bad is not None:
        field, want, got = bad
        raise InputError(
            f"claims_{e.register}.csv, {e.id}: {field} is {want!r} in the register but "
            f"{got!r} in its primary row {row.get('claim')!r} ({row.get('reading')})"
        )


def _judged(e: Entry, mine: list[dict], base: dict, worlds: list[Mapping] | None) -> dict:
    """The record of a judged entry from its rows ``mine`` (all on one kind of data): the primary row's
    fields, the other rows as ``sensitivity``; "not run" when the primary row (or every row) is missing."""
    if not mine:  # none of its rows run: other parameters, or no real measurements
        rec = _unjudged(e, "not run")
        rec["why"] = (
            "not run: the chapter wrote none of its rows (" + "; ".join(e.rows) + "): with these "
            "parameters, or without the real measurements they need (../shared/realdata), they "
            "are not computed"
        )
        return {**rec, **base, "sensitivity": [], "across": {"rows": 0, "same": 0, "verdicts": {}}}
    prim = [r for r in mine if r["claim"] == e.primary_claim and r["reading"] == e.primary_reading]
    if len(prim) > 1:
        raise InputError(
            f"claims_{e.register}.csv, {e.id}: two results rows {e.primary_claim!r} under the "
            f"primary reading {e.primary_reading!r}"
            + (" on real data" if base.get("data") == "real" else "")
        )
    if not prim:  # a rerun with other parameters: the primary reading was not run
        rec = _unjudged(e, "not run")
        rec["why"] = (
            f"not run: the primary reading {e.primary_reading!r} of {e.primary_claim!r} was not "
            f"run with these parameters; the {len(mine)} row(s) that were are its sensitivity"
        )
        return {
            **rec,
            **base,
            "sensitivity": [{**r, "source": e.origin} for r in mine],
            "across": {"rows": 0, "same": 0, "verdicts": {}},
        }
    p = prim[0]
    check_primary(e, p)
    others = [{**r, "source": e.origin} for r in mine if r is not p]
    rec = {
        **p,
        **base,
        "claim": e.claim,
        "row_claim": p["claim"],
        "source": e.origin,
        "primary_reading": p["reading"],
        "sensitivity": others,
    }
    rec["across"] = _across(rec, others, worlds)
    return rec


def evaluate(
    chapter: str, rows: Iterable[Mapping], worlds: list[Mapping] | None = None
) -> list[dict]:
    """One record per register entry of ``chapter`` (except inconsistencies): for a judged entry its
    primary row's fields (``claim`` is the register's wording, ``row_claim`` the row's), the register's
    ``id``, ``quote``, ``quote_zh``, ``where``, ``kind``, ``status``, ``headline``, ``primary_reading``,
    ``why_primary``, ``dimensions`` (the register's sensitivity column), ``source`` (the register's
    origin), the other rows as ``sensitivity`` (each a row record with the same fields) and ``across``
    (:func:`across_text`); an open or not-checkable entry has no statistic and says why.  ``rows`` are
    :meth:`Claim.record` dicts; ``worlds`` the drawn-world verdicts of the rows, if any.

    Rows judged on real measurements (``"data": "real"``) are kept apart: each judged entry with such
    rows gets a second record, ``"data": "real"``, after every record of simulated rows (which carry
    ``"data": "simulated"`` and are what they would be without the real rows).  Its primary row is the
    real row of the entry's primary claim under its primary reading, the entry's other real rows are its
    sensitivity, and no drawn world applies to it.  The real rows use the simulated rows' wording, so a
    reader can set the two verdicts side by side; the book counts the real records apart."""
    rows = [dict(r) for r in rows]
    for r in rows:
        if data_of(r) not in verdicts.DATA:
            raise InputError(
                f"chapter {chapter!r}: results row {r.get('claim')!r}: data={r.get('data')!r} "
                f"must be 'simulated' or 'real'"
            )
    es = entries(chapter)
    if not es:
        raise InputError(f"chapter {chapter!r} has no claims register (navlib.claims.REGISTERS)")
    owner: dict[str, Entry] = {}
    for e in es:
        for text in e.rows:
            if text in owner:
                raise InputError(
                    f"claims_{e.register}.csv, {e.id}: row {text!r} already belongs to "
                    f"{owner[text].id}"
                )
            owner[text] = e
    files = ", ".join(f"data/claims_{n}.csv" for n in registers(chapter))
    by_entry: dict[tuple[str, str], list[dict]] = {}
    for r in rows:
        e = owner.get(r["claim"])
        if e is None:
            raise InputError(
                f"chapter {chapter!r}: results row {r['claim']!r} ({r['reading']}) belongs to no "
                f"entry of {files}: add it to an entry's rows"
            )
        by_entry.setdefault((e.id, data_of(r)), []).append(_with_margin(r, e))
    out, real = [], []
    for e in es:
        if e.status == "noted":
            continue
        base = {
            "id": e.id,
            "register": e.register,
            "kind": e.kind,
            "status": e.status,
            "headline": e.headline,
            "quote": e.quote,
            "quote_zh": e.quote_zh,
            "where": e.where,
            "why_primary": e.why_primary,
            "dimensions": e.sensitivity,
            "needs": e.needs,
            "data": "simulated",
        }
        if e.status != "judged":
            out.append(
                {
                    **_unjudged(e),
                    **base,
                    "sensitivity": [],
                    "across": {"rows": 0, "same": 0, "verdicts": {}},
                }
            )
            continue
        out.append(_judged(e, by_entry.get((e.id, "simulated"), []), base, worlds))
        if (e.id, "real") in by_entry:
            real.append(_judged(e, by_entry[(e.id, "real")], {**base, "data": "real"}, None))
    return out + real


def inconsistencies(chapter: str) -> list[dict]:
    """The register's ``noted`` entries of a chapter: where a paper contradicts itself."""
    return [
        {
            "id": e.id,
            "register": e.register,
            "claim": e.claim,
            "quote": e.quote,
            "where": e.where,
            "numbers": e.needs,
        }
        for e in entries(chapter)
        if e.status == "noted"
    ]


def headlines(records: Iterable[Mapping]) -> list[dict]:
    """The headline record of each register among ``records`` (:func:`evaluate`'s), in order."""
    return [r for r in records if r.get("headline") and data_of(r) == "simulated"]


def tally(records: Iterable[Mapping]) -> dict[str, int]:
    """Counts of register records by status and, for judged ones, by primary verdict."""
    recs = list(records)
    out = {
        k: sum(r["verdict"] == k and r.get("status") == "judged" for r in recs)
        for k in verdicts.VERDICTS
    }
    out.update(
        {s: sum(r.get("status") == s for r in recs) for s in ("judged", "open", "not checkable")}
    )
    return out


__all__ = [
    "Claim",
    "Entry",
    "REGISTERS",
    "SOURCE_NAMES",
    "across_text",
    "check_primary",
    "data_of",
    "entries",
    "entry",
    "evaluate",
    "headlines",
    "inconsistencies",
    "load_register",
    "method_stats",
    "parse_register",
    "registers",
    "row_margin",
    "tally",
    "units_of",
    "verdict_counts_text",
    "with_register_margin",
]
