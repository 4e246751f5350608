"""Claims judged on real measurements (``Claim.data == "real"``, issue 36): validated, written into the
results file, folded by the claims-register evaluator into records of their own, and counted apart from
the simulated claims by the glance box, the closing box, the landing page and ``status``; ``check-results``
compares the field, and a results file written before it existed reads as simulated."""

import io
import json
from html import unescape

import nbformat
import pytest

from navbook import html_checks, landing, report, results_check
from navlib import claims, verdicts
from navlib.errors import InputError

HEADER = ",".join(claims.COLUMNS)


def _claim(
    text="X beats Y", interval=(0.2, 0.5), reading="r1", data="simulated", source="paper", key=""
):
    e = verdicts.Estimate(sum(interval) / 2, *interval, "paired difference", 10)
    return report.Claim(
        text,
        "p",
        reading=reading,
        source=source,
        statistic="rms Y - rms X, deg",
        estimate=e,
        boundary=0.0,
        holds_when="above",
        unit="deg",
        data=data,
        key=key,
    )


def _register():
    import csv

    out = io.StringIO()
    w = csv.DictWriter(out, fieldnames=claims.COLUMNS)
    w.writeheader()
    base = dict.fromkeys(claims.COLUMNS, "")
    base.update(
        id="A01",
        origin="paper",
        headline="yes",
        kind="comparison",
        status="judged",
        claim="X beats Y",
        quote="X is better",
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
    w.writerow(base)
    w.writerow(
        dict(
            base,
            id="A02",
            headline="",
            claim="Z beats Y",
            rows="Z beats Y",
            primary_claim="Z beats Y",
        )
    )
    return claims.parse_register(io.StringIO(out.getvalue()), "claims_test.csv")


@pytest.fixture
def reg(monkeypatch):
    es = _register()
    monkeypatch.setitem(claims.REGISTERS, "testch", ("test",))
    monkeypatch.setattr(claims, "load_register", lambda name: es)
    return es


def test_a_claim_says_what_it_was_judged_on_and_an_invalid_value_is_refused():
    assert _claim().data == "simulated" and _claim().record()["data"] == "simulated"
    assert _claim(data="real").record()["data"] == "real"
    with pytest.raises(InputError, match="Claim.data='measured': must be 'simulated' or 'real'"):
        _claim(data="measured")
    assert results_check.claim_problems(_claim(data="real").record()) == []
    assert results_check.claim_problems(dict(_claim().record(), data="field")) == [
        "data 'field': must be 'simulated' or 'real'"
    ]


def test_the_same_claim_on_real_data_is_a_record_of_its_own_counted_apart(reg):
    rows = [
        _claim(interval=(1, 2)),
        _claim(interval=(-2, -1), data="real"),
        _claim(reading="r1; other sessions", interval=(-1, 1), data="real"),
        _claim("Z beats Y"),
    ]
    recs = claims.evaluate("testch", [c.record() for c in rows])
    assert [(r["id"], r["data"]) for r in recs] == [
        ("A01", "simulated"),
        ("A02", "simulated"),
        ("A01", "real"),
    ]
    sim, _, real = recs
    assert (
        sim["verdict"] == "reproduced" and sim["sensitivity"] == []
    )  # the simulated record as before
    assert real["verdict"] == "not reproduced" and real["claim"] == sim["claim"] == "X beats Y"
    assert [s["reading"] for s in real["sensitivity"]] == ["r1; other sessions"]
    assert claims.headlines(recs) == [sim]
    assert all(
        results_check.claim_problems(r) == [] and results_check.register_problems(r) == []
        for r in recs
    )
    without = claims.evaluate("testch", [c.record() for c in rows if c.data == "simulated"])
    assert without == [
        {k: v for k, v in r.items()} for r in recs[:2]
    ]  # real rows change nothing else
    # the chapter's boxes count them apart, under their own title
    answer = report.glance(rows, chapter="testch")
    html = unescape(answer._repr_html_())
    assert "The paper's claims: 2 of 2 reproduced" in html
    assert "The paper's claims on real data: 0 of 1 reproduced, 1 not reproduced" in html
    assert html_checks.glance_counts(
        f'<p class="admonition-title">Results at a glance</p>{html}'
    ) == {"paper": (2, 0, 0, 0)}
    shown = repr(report.showed(rows, chapter="testch"))
    assert (
        "The paper's claims: 2 of 2 reproduced" in shown
        and "The paper's claims on real data: 0 of 1" in shown
    )
    plain = report.glance(rows)  # a chapter without a register
    assert [t.caption.split(":")[0] for t in plain.tables()] == [
        "The paper's claims",
        "The paper's claims on real data",
    ]


def test_write_results_takes_the_same_claim_and_reading_once_per_kind_of_data(tmp_path, reg):
    rows = [_claim(), _claim(data="real")]
    path = report.write_results("testch", claims=rows, folder=tmp_path, register=True)
    res = json.loads(path.read_text())
    assert [(c["id"], c["data"]) for c in res["claims"]] == [
        ("A01", "simulated"),
        ("A02", "simulated"),
        ("A01", "real"),
    ]
    with pytest.raises(InputError, match="appears twice under reading 'r1' on real data"):
        report.write_results("testch", claims=rows + [_claim(data="real")], folder=tmp_path / "x")


def _results(data_of_b="real"):
    return {
        "compass": {
            "chapter": "compass",
            "claims": [
                _claim("a", (1, 2)).record(),
                _claim("b", (-1, 1)).record(),
                _claim("a", (1, 2), data="real").record(),
                _claim("b", (-2, -1), data=data_of_b).record(),
            ],
        }
    }


def test_landing_page_and_status_count_real_data_claims_apart(tmp_path):
    res = _results()
    assert tuple(landing.claim_counts(res)["compass"]["paper"].values()) == (1, 0, 1, 0)
    assert tuple(landing.claim_counts(res, "real")["compass"]["paper"].values()) == (1, 1, 0, 0)
    with pytest.raises(InputError, match="data='both'"):
        landing.claim_counts(res, "both")
    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_code_cell('report.write_results("compass", claims=c)'))
    nbformat.write(nb, tmp_path / "compass.ipynb")
    nb = tmp_path / "compass.ipynb"
    md = landing.status_markdown(res, [nb])
    assert 'data-paper="1 0 1 0"' in md  # the glance box's count: simulated only
    assert (
        "paper's: 1 / 0 / 1<br>book's own: –<br>paper's claims on real data: 1 of 2 reproduced, 1 not "
        "reproduced, 0 cannot be judged" in md
    )
    assert "**1 of 2** of the papers' claims reproduce" in md
    assert (
        "counted apart from the claims above" in md
        and "the papers' claims on real data: 1 of 2" in md
    )
    by_reading = landing.readings_markdown(res, [nb])
    assert (
        "| R1 | 2 | 1 | 0 |" in by_reading and "| R1 (on real data) | 2 | 1 | 1 | 0 |" in by_reading
    )


def test_check_results_compares_the_field_and_old_files_read_as_simulated():
    fresh, ref = _results(), _results()
    assert results_check.compare_results(fresh, ref, "compass.json") == []
    assert results_check.validate_results(fresh["compass"], "compass.json") == []
    moved = _results(data_of_b="simulated")["compass"]
    moved["claims"][3] = dict(moved["claims"][3], claim="b")
    problems = results_check.compare_results(moved, ref["compass"], "compass.json")
    assert any(
        "claims[3].data 'simulated' differs from the reference 'real'" in p for p in problems
    )
    old = {
        "chapter": "compass",
        "claims": [
            {k: v for k, v in c.items() if k != "data"} for c in fresh["compass"]["claims"][:2]
        ],
    }
    new = {"chapter": "compass", "claims": fresh["compass"]["claims"][:2]}
    assert (
        results_check.compare_results(new, old, "compass.json") == []
        and results_check.validate_results(old, "compass.json") == []
    )
    assert tuple(landing.claim_counts({"compass": old})["compass"]["paper"].values()) == (
        1,
        0,
        1,
        0,
    )
    assert claims.data_of({}) == "simulated"
