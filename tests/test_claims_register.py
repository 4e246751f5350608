"""navlib.claims: the claims registers (data/claims_*.csv) and their one evaluator.

Every register entry must appear in its chapter: once as a record of the chapter's results file (judged,
not yet computed, not checkable) or in its list of the paper's contradictions, and by its id in the
chapter's opening table as the executed notebook stores it."""

import csv
import io
import json
import re
from pathlib import Path

import pytest

from navlib import claims, verdicts
from navbook.results_check import claim_problems, register_problems
from navlib.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
HEADER = ",".join(claims.COLUMNS)


def _row(**kw):
    base = dict.fromkeys(claims.COLUMNS, "")
    base.update(
        id="A01",
        origin="paper",
        headline="yes",
        kind="comparison",
        status="judged",
        claim="X beats Y",
        quote="X is better than Y",
        where="Sec. 1",
        statistic="rms Y - rms X, deg",
        boundary="0",
        holds_when="above",
        unit="deg",
        rows="X beats Y",
        primary_claim="X beats Y",
        primary_reading="r1",
        why_primary="the paper says r1",
    )
    base.update(kw)
    out = io.StringIO()
    w = csv.DictWriter(out, fieldnames=claims.COLUMNS)
    w.writerow(base)
    return out.getvalue()


def _parse(*rows):
    return claims.parse_register(io.StringIO(HEADER + "\n" + "".join(rows)), "claims_test.csv")


# ------------------------------------------------------------------ the register files
#: An estimate with its interval, "4.57 [3.82, 5.10]": a result of the book's own runs.
OUR_INTERVAL = re.compile(r"\d[\d.]*\s*x?\s*\[\d[\d.]*, \d[\d.]*\]")


@pytest.mark.parametrize("name", sorted({n for ns in claims.REGISTERS.values() for n in ns}))
def test_register_prose_types_in_none_of_our_results(name):
    """The register holds the paper's words and our reasons; the results come from the runs (a typed-in
    interval goes stale the day a number moves, as D's did when the kernels were pinned)."""
    text = (ROOT / "data" / f"claims_{name}.csv").read_text(encoding="utf-8")
    rows = list(csv.DictReader(io.StringIO(text)))
    found = [
        (r["id"], col, m.group(0))
        for r in rows
        for col in ("why_primary", "sensitivity", "needs", "margin_why")
        for m in OUR_INTERVAL.finditer(r.get(col) or "")
    ]
    assert not found, found


#: A verdict in words ("reproduced", "cannot be judged", "no difference", "flips"): the evaluator derives
#: every verdict, and the chapter shows how it moves across the rows (``across``) from the results.
OUR_VERDICT = re.compile(
    r"\breproduc|\bcannot be judged\b|\bno difference\b|\bflips?\b|\bverdicts?\b", re.IGNORECASE
)


@pytest.mark.parametrize("name", sorted({n for ns in claims.REGISTERS.values() for n in ns}))
def test_register_prose_states_no_verdict(name):
    """The register names the dimensions a verdict is shown across and why a reading is primary; a verdict
    typed there goes stale when a row moves (A06's said "cannot be judged at the default noise" where the
    rows said "not reproduced")."""
    text = (ROOT / "data" / f"claims_{name}.csv").read_text(encoding="utf-8")
    found = [
        (r["id"], col, m.group(0))
        for r in csv.DictReader(io.StringIO(text))
        for col in ("why_primary", "sensitivity", "needs", "margin_why")
        for m in OUR_VERDICT.finditer(r.get(col) or "")
    ]
    assert not found, found


def test_the_verdict_pattern_finds_a_typed_in_verdict():
    assert OUR_VERDICT.search("Reproduced in all five readings")
    assert OUR_VERDICT.search("on C1-C5 some rows flip to cannot be judged")
    assert OUR_VERDICT.search("so either verdict checks our simulator")
    assert not OUR_VERDICT.search("the reading x the LS model; the drawn compasses C1-C5")


def test_the_interval_pattern_finds_a_typed_in_result():
    assert OUR_INTERVAL.search("the ratio 26.2 [19.0, 32.7] x straddles 31.6x")
    assert OUR_INTERVAL.search("a median 7.8 [3.1, 14.0]x")
    assert not OUR_INTERVAL.search("the paper's own 8.5x against 31.6x (10^1.5)")


@pytest.mark.parametrize("name", sorted({n for ns in claims.REGISTERS.values() for n in ns}))
def test_every_register_parses(name):
    es = claims.load_register(name)
    assert es and len({e.id for e in es}) == len(es)
    if name != "workbench":
        assert sum(e.headline for e in es) == 1


def test_ids_are_unique_over_all_registers():
    ids = [e.id for ns in claims.REGISTERS.values() for n in ns for e in claims.load_register(n)]
    assert len(ids) == len(set(ids))


@pytest.mark.parametrize(
    "row,match",
    [
        (dict(status="guess"), "column 'status'"),
        (dict(kind="vibe"), "column 'kind'"),
        (dict(origin="blog"), "column 'origin'"),
        (dict(primary_claim="Z beats Y"), "column 'primary_claim'"),
        (dict(rows=""), "column 'rows'"),
        (dict(why_primary=""), "column 'why_primary'"),
        (dict(status="open"), "column 'rows'"),
        (dict(status="open", rows="", needs=""), "column 'needs'"),
        (dict(kind="inconsistency"), "column 'status'"),
        (dict(boundary="zero"), "column 'boundary'"),
        (dict(holds_when="left"), "column 'holds_when'"),
        (dict(id="a1"), "column 'id'"),
        (dict(quote=""), "column 'quote'"),
    ],
)
def test_a_bad_register_row_is_refused_in_one_line_naming_row_and_column(row, match):
    with pytest.raises(InputError, match=match) as err:
        _parse(_row(**row))
    assert "claims_test.csv, row 2 (" in str(err.value) and "\n" not in str(err.value)


def test_a_register_needs_one_headline_and_its_columns():
    with pytest.raises(InputError, match="exactly one headline"):
        _parse(_row(), _row(id="A02"))
    with pytest.raises(InputError, match="exactly one headline"):
        _parse(_row(headline=""))
    with pytest.raises(InputError, match="appears twice"):
        _parse(_row(), _row(headline=""))
    with pytest.raises(InputError, match="columns differ"):
        claims.parse_register(io.StringIO("id,claim\nA01,x\n"), "claims_test.csv")


# ------------------------------------------------------------------ the evaluator
def _rec(claim, reading, interval, boundary=0.0, side="above"):
    rep, basis = verdicts.decide(interval, boundary, side)
    return {
        "claim": claim,
        "reading": reading,
        "source": "paper",
        "paper": "p",
        "ours": "o",
        "statistic": "s",
        "unit": "deg",
        "rule": "paired difference",
        "estimate": sum(interval) / 2,
        "interval": list(interval),
        "n": 20,
        "boundary": boundary,
        "holds_when": side,
        "floor": None,
        "by_construction": False,
        "decided_by": [],
        "reproduced": rep,
        "verdict": verdicts.verdict_name(rep),
        "basis": basis,
        "reason": verdicts.reason_category(basis, ""),
        "why": "" if rep is not None else "w",
        "key": None,
        "volatile": False,
    }


@pytest.fixture
def reg(monkeypatch):
    es = _parse(
        _row(rows="X beats Y ; X beats Y [variant]"),
        _row(
            id="A02", headline="", status="open", rows="", primary_claim="", needs="20 seeds of Z"
        ),
        _row(
            id="A03",
            headline="",
            kind="inconsistency",
            status="noted",
            rows="",
            primary_claim="",
            needs="8.5x beside 'two orders'",
        ),
        _row(
            id="A04",
            headline="",
            origin="book",
            rows="ours",
            primary_claim="ours",
            primary_reading="real",
        ),
    )
    monkeypatch.setitem(claims.REGISTERS, "testch", ("test",))
    monkeypatch.setattr(claims, "load_register", lambda name: es)
    return es


def test_evaluate_folds_rows_into_one_record_per_entry(reg):
    rows = [
        _rec("X beats Y", "r1", (1, 2)),
        _rec("X beats Y", "r2", (-1, 1)),
        _rec("X beats Y [variant]", "r1", (-3, -2)),
        _rec("ours", "real", (1, 3)),
    ]
    recs = claims.evaluate(
        "testch",
        rows,
        worlds=[
            {"compass": "C1", "claim": "X beats Y", "reading": "r1", "verdict": "reproduced"},
            {"compass": "C2", "claim": "X beats Y", "reading": "r1", "verdict": "not reproduced"},
        ],
    )
    assert [r["id"] for r in recs] == ["A01", "A02", "A04"]
    a1, a2, a4 = recs
    assert (
        a1["verdict"] == "reproduced"
        and a1["primary_reading"] == "r1"
        and a1["claim"] == "X beats Y"
    )
    assert [(s["claim"], s["reading"]) for s in a1["sensitivity"]] == [
        ("X beats Y", "r2"),
        ("X beats Y [variant]", "r1"),
    ]
    assert claims.across_text(a1) == "same in 1 of 3 readings; differs on 1 of 2 drawn compasses"
    assert a2["reason"] == "not yet computed" and a2["why"] == "not yet computed: 20 seeds of Z"
    assert a4["source"] == "book"
    for r in recs:  # what check-results checks, including the nesting
        assert claim_problems(r) == [] and register_problems(r) == []
        assert all(claim_problems(s) == [] for s in r["sensitivity"])
    assert claims.tally(recs)["open"] == 1
    assert [n["id"] for n in claims.inconsistencies("testch")] == ["A03"]


def test_a_register_margin_turns_a_tiny_difference_into_no_difference(monkeypatch):
    es = _parse(_row(margin="0.01", margin_why="the paper prints 0.01 deg"))
    monkeypatch.setitem(claims.REGISTERS, "testch", ("test",))
    monkeypatch.setattr(claims, "load_register", lambda name: es)
    (rec,) = claims.evaluate("testch", [_rec("X beats Y", "r1", (-0.004, 0.006))])
    assert (
        rec["verdict"] == "no difference" and rec["basis"] == "equivalent" and rec["margin"] == 0.01
    )
    assert "the paper prints 0.01 deg" in rec["why"]
    assert claim_problems(rec) == []
    assert claim_problems(dict(rec, margin=None))  # without its margin the verdict does not follow
    with pytest.raises(InputError, match="column 'margin_why'"):
        _parse(_row(margin="0.01"))


def test_evaluate_refuses_rows_the_register_does_not_know_and_missing_primaries(reg):
    good = [
        _rec("X beats Y", "r1", (1, 2)),
        _rec("X beats Y [variant]", "r1", (1, 2)),
        _rec("ours", "real", (1, 2)),
    ]
    with pytest.raises(InputError, match="belongs to no entry"):
        claims.evaluate("testch", good + [_rec("a new claim", "r1", (1, 2))])
    # a rerun with other parameters: the primary reading was not run; the run finishes and says so
    a1 = claims.evaluate("testch", [_rec("X beats Y", "r2", (1, 2))] + good[1:])[0]
    assert a1["reason"] == "not run" and a1["verdict"] == "cannot be judged" and "'r1'" in a1["why"]
    assert [s["reading"] for s in a1["sensitivity"]] == ["r2", "r1"]
    assert claim_problems(a1) == [] and register_problems(a1) == []
    assert (
        claims.evaluate("testch", [good[0], good[2]])[0]["verdict"] == "reproduced"
    )  # a row not run
    recs = claims.evaluate("testch", good[:2])  # no row of the book's entry: e.g. no real data
    a4 = recs[-1]
    assert a4["reason"] == "not run" and a4["status"] == "judged" and claim_problems(a4) == []
    assert register_problems(a4) == []


# ------------------------------------------------------------------ the register holds each boundary once
@pytest.mark.parametrize(
    "change, field, values",
    [
        ({"boundary": 0.5}, "boundary", "0.0 in the register but 0.5"),
        ({"boundary": 1e-6}, "boundary", "0.0 in the register but 1e-06"),
        ({"boundary": None}, "boundary", "0.0 in the register but None"),
        ({"holds_when": "below"}, "holds_when", "'above' in the register but 'below'"),
        ({"unit": "arcmin"}, "unit", "'deg' in the register but 'arcmin'"),
        ({"unit": ""}, "unit", "'deg' in the register but ''"),
    ],
)
def test_evaluate_refuses_a_primary_row_off_its_registers_boundary_side_or_unit(
    reg, change, field, values
):
    rows = [dict(_rec("X beats Y", "r1", (1, 2)), **change), _rec("ours", "real", (1, 2))]
    with pytest.raises(InputError) as err:
        claims.evaluate("testch", rows)
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith(f"claims_test.csv, A01: {field} is {values} in its primary row")
    assert "'X beats Y' (r1)" in msg


def test_a_primary_row_on_its_registers_boundary_side_and_unit_passes(reg):
    rows = [
        _rec("X beats Y", "r1", (1, 2)),
        # another reading may judge against another boundary (a margin, another threshold)
        dict(_rec("X beats Y", "r2", (1, 2), boundary=0.5, side="below"), unit="%"),
        _rec("ours", "real", (1, 2), boundary=1e-13),
    ]
    # a boundary of 0 has no relative neighbourhood: any other number disagrees with it
    with pytest.raises(InputError, match="A04: boundary is 0.0 in the register but 1e-13"):
        claims.evaluate("testch", rows)
    rows[2] = _rec("ours", "real", (1, 2))
    a1 = claims.evaluate("testch", rows)[0]
    assert a1["verdict"] == "reproduced" and len(a1["sensitivity"]) == 1


def test_the_boundary_agrees_within_a_relative_1e_9_and_a_unit_may_be_one_of_several(monkeypatch):
    es = _parse(_row(boundary="0.0003", unit="ug or %"))
    monkeypatch.setitem(claims.REGISTERS, "testch", ("test",))
    monkeypatch.setattr(claims, "load_register", lambda name: es)
    near = dict(_rec("X beats Y", "r1", (1, 2), boundary=0.0003 * (1 + 1e-12)), unit="%")
    assert claims.evaluate("testch", [near])[0]["boundary"] == near["boundary"]
    assert claims.evaluate("testch", [dict(near, unit="ug")])[0]["unit"] == "ug"
    with pytest.raises(InputError, match="boundary is 0.0003 in the register but 0.0003003"):
        claims.evaluate("testch", [dict(near, boundary=0.0003003)])
    with pytest.raises(InputError, match="unit is 'ug or %' in the register but 'ug or %'"):
        claims.evaluate("testch", [dict(near, unit="ug or %")])


def test_a_primary_row_without_a_statistic_or_boundary_carries_nothing_to_compare(reg):
    not_run = dict(
        _rec("X beats Y", "r1", (1, 2)),
        estimate=None,
        interval=None,
        boundary=None,
        holds_when=None,
        unit="",
        reproduced=None,
        verdict="cannot be judged",
        basis="no statistic",
    )
    a1 = claims.evaluate("testch", [not_run, _rec("ours", "real", (1, 2))])[0]
    assert a1["row_claim"] == "X beats Y" and a1["boundary"] is None


@pytest.fixture
def one_register(monkeypatch):
    es = _parse(
        _row(rows="X beats Y ; X beats Y [variant]"),
        _row(id="A02", headline="", rows="Z", primary_claim="Z", boundary="5e-05", unit="ug or %"),
    )
    monkeypatch.setattr(claims, "REGISTERS", {"testch": ("test",)})
    monkeypatch.setattr(claims, "load_register", lambda name: es)
    return es


def test_claim_of_takes_boundary_side_and_unit_from_the_register(one_register):
    est = verdicts.exact(1.5)
    c = claims.Claim.of("A01", "X beats Y", "p", reading="r1", statistic="s", estimate=est)
    assert (c.boundary, c.holds_when, c.unit, c.verdict) == (0.0, "above", "deg", "reproduced")
    assert c == claims.Claim(
        "X beats Y",
        "p",
        reading="r1",
        statistic="s",
        estimate=est,
        boundary=0.0,
        holds_when="above",
        unit="deg",
    )
    # a value given as well must be the register's (the boundary within a relative 1e-9)
    same = claims.Claim.of(
        "A02",
        "Z",
        "p",
        reading="r1",
        statistic="s",
        estimate=est,
        boundary=5e-05 * (1 + 1e-12),
        unit="%",
    )
    assert same.unit == "%" and same.boundary == pytest.approx(5e-05)
    (rec,) = [r for r in claims.evaluate("testch", [c.record(), same.record()]) if r["id"] == "A02"]
    assert rec["unit"] == "%"


@pytest.mark.parametrize(
    "entry_id, claim, given, match",
    [
        ("A01", "X beats Y", {"boundary": 0.5}, "A01: boundary=0.5 given .* the register's is 0.0"),
        ("A01", "X beats Y", {"boundary": None}, "A01: boundary=None given"),
        ("A01", "X beats Y", {"holds_when": "below"}, "holds_when='below' given .* is 'above'"),
        ("A01", "X beats Y", {"unit": "rad"}, "unit='rad' given .* the register's is 'deg'"),
        ("A02", "Z", {}, "A02: the register lists the units 'ug or %': give the row's unit"),
        ("A02", "Z", {"unit": "mg"}, "unit='mg' given .* the register's is 'ug or %'"),
        ("A01", "Z", {}, "A01: row 'Z' is not one of its rows"),
        ("A09", "X beats Y", {}, "entry 'A09': found 0 times"),
    ],
)
def test_claim_of_refuses_a_value_the_register_does_not_hold(
    one_register, entry_id, claim, given, match
):
    with pytest.raises(InputError, match=match):
        claims.Claim.of(entry_id, claim, "p", statistic="s", estimate=verdicts.exact(1.0), **given)


def _stored_rows(chapter):
    """The results rows a chapter's stored results file was evaluated from: each record's primary row
    (its ``claim`` the row's) and its sensitivity rows."""
    recs = json.loads((ROOT / "notebooks" / "results" / f"{chapter}.json").read_text("utf-8"))
    rows = []
    for r in recs["claims"]:
        if r.get("row_claim") is not None:
            rows.append({**r, "claim": r["row_claim"]})
        rows.extend(r.get("sensitivity") or [])
    return recs["claims"], rows


@pytest.mark.parametrize("chapter", sorted(claims.REGISTERS))
def test_every_stored_primary_row_uses_its_registers_boundary_side_and_unit(chapter):
    """The stored results, evaluated again against today's registers: a register whose boundary, side or
    unit drifts from the rows the chapter wrote (or a row that drifts from it) stops here."""
    stored, rows = _stored_rows(chapter)
    again = claims.evaluate(chapter, rows)
    key = ("id", "data", "row_claim", "primary_reading", "boundary", "holds_when", "unit")
    assert [tuple(r.get(k) for k in key) for r in again] == [
        tuple(r.get(k) for k in key) for r in stored
    ]


# ------------------------------------------------------------------ every entry is shown by its chapter
CHAPTERS = sorted(claims.REGISTERS)


def _glance_html(chapter):
    nb = json.loads((ROOT / "notebooks" / f"{chapter}.ipynb").read_text(encoding="utf-8"))
    for cell in nb["cells"]:
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            if out.get("metadata", {}).get("scrapbook", {}).get("name") == f"{chapter}_glance":
                return data.get("application/papermill.record/text/html", "")
    return ""


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_every_register_entry_is_in_the_results_file_and_the_chapters_opening(chapter):
    res = json.loads(
        (ROOT / "notebooks" / "results" / f"{chapter}.json").read_text(encoding="utf-8")
    )
    sim = [c for c in res["claims"] if claims.data_of(c) == "simulated"]
    real = [
        c for c in res["claims"] if claims.data_of(c) == "real"
    ]  # counted apart: one more per entry
    ids = [c.get("id") for c in sim]
    noted = [c["id"] for c in res.get("inconsistencies", [])]
    html = _glance_html(chapter)
    by_id = {c.get("id"): c for c in sim}
    assert len({c["id"] for c in real}) == len(real) and {c["id"] for c in real} <= set(ids)
    assert res["claims"] == sim + real  # the real records after the others
    for c in real:
        assert all(claims.data_of(s) == "real" for s in c["sensitivity"])
    for e in claims.entries(chapter):
        where = noted if e.status == "noted" else ids
        if (
            e.status == "judged" and e.id in by_id
        ):  # with the chapter's defaults every primary row is run
            assert by_id[e.id].get("reason") != "not run", (
                f"{chapter}: {e.id}'s primary reading not run"
            )
            written = {by_id[e.id].get("row_claim")} | {
                s["claim"] for s in by_id[e.id]["sensitivity"]
            }
            assert set(e.rows) <= written, f"{chapter}: {e.id} lists rows the chapter did not write"
        assert where.count(e.id) == 1, (
            f"{chapter}: register entry {e.id} ({e.claim}) is not in the results file"
        )
        assert f">{e.id}<" in html, (
            f"{chapter}: register entry {e.id} ({e.claim}) is not in the chapter's opening"
        )
    assert len(ids) == len(set(ids))


def test_verdict_counts_text_spreads_the_rows_verdicts():
    rec = {
        "across": {
            "rows": 4,
            "same": 2,
            "verdicts": {
                "reproduced": 2,
                "not reproduced": 0,
                "cannot be judged": 1,
                "no difference": 1,
            },
        }
    }
    assert claims.verdict_counts_text(rec) == (
        "4 rows: 2 reproduced, 1 cannot be judged, 1 no difference"
    )
    one = {"across": {"rows": 1, "same": 1, "verdicts": {"not reproduced": 1}}}
    assert claims.verdict_counts_text(one) == "1 row: 1 not reproduced"
    assert claims.verdict_counts_text({"across": {"rows": 0, "same": 0, "verdicts": {}}}) == ""
