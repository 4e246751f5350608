"""navlib.report: tables that fit, claims, results files and the landing page's counts."""

import json

import numpy as np
import pandas as pd
import pytest

from navbook import glue, report

from navlib import verdicts
from navlib.errors import InputError


def wide_frame():
    return pd.DataFrame(
        {
            "method": ["ADE-BP", "DE-BP"],
            "median rms (deg)": [0.123456, 10.0],
            "what the paper says, a long text column": ["x " * 60, "short"],
            "ok": [True, False],
        }
    )


def test_table_text_twin_is_no_wider_than_plain_width_and_rounded():
    tab = report.table(wide_frame(), formats={"median rms (deg)": "{:.2f}"}, caption="Table 1")
    lines = repr(tab).splitlines()
    assert lines[0] == "Table 1"
    assert max(len(ln) for ln in lines) <= report.PLAIN_WIDTH
    assert "0.12" in repr(tab) and "0.123456" not in repr(tab)
    assert "yes" in repr(tab)


def test_table_html_has_the_book_class_a_stable_id_and_no_index_when_asked():
    a = report.table(wide_frame(), index=False)._repr_html_()
    b = report.table(wide_frame(), index=False)._repr_html_()
    assert 'class="navbook-table"' in a and a == b
    other = report.table(wide_frame().iloc[:1], index=False)._repr_html_()
    assert other.split('id="')[1][:12] != a.split('id="')[1][:12]  # two tables, two ids


def _claim(interval=(0.2, 0.5), source="paper", **kw):
    e = verdicts.Estimate(sum(interval) / 2, *interval, "median over runs", 20)
    return report.Claim(
        "c",
        "p",
        source=source,
        statistic="rms, deg",
        estimate=e,
        boundary=1.0,
        holds_when="below",
        unit="deg",
        **kw,
    )


def test_claim_validation():
    with pytest.raises(InputError, match="source"):
        _claim(source="mine")
    with pytest.raises(InputError, match="holds_when"):
        report.Claim(
            "c", "p", statistic="x", estimate=verdicts.exact(1.0), boundary=0.0, holds_when="up"
        )
    with pytest.raises(InputError, match="boundary"):
        report.Claim("c", "p", statistic="x", estimate=verdicts.exact(1.0), holds_when="above")
    with pytest.raises(InputError, match="statistic"):
        report.Claim("c", "p", estimate=verdicts.exact(1.0), boundary=0.0, holds_when="above")
    with pytest.raises(InputError, match="why"):
        report.Claim("c", "p")  # no statistic and no reason
    with pytest.raises(InputError, match="by construction"):
        _claim(by_construction=True)
    with pytest.raises(InputError, match="decided_by"):
        _claim(decided_by="noise")
    with pytest.raises(InputError, match="Claim.claim"):
        report.Claim(" ", "p", why="x")


def test_claim_verdict_follows_from_interval_boundary_and_floor():
    assert _claim((0.2, 0.5)).verdict == "reproduced"
    assert _claim((1.5, 2.0)).verdict == "not reproduced"
    c = _claim((0.5, 1.5))
    assert c.verdict == "cannot be judged" and "contains the boundary" in c.reason
    fl = verdicts.Floor(1.2, "sensor noise 3 ug", "noise below 2.5 ug")
    floored = _claim((1.05, 1.15), floor=fl)  # beyond the boundary 1, within the floor 1.2
    assert floored.verdict == "cannot be judged" and floored.basis == "noise floor"
    assert "sensor noise 3 ug" in floored.reason and "noise below 2.5 ug" in floored.reason
    assert _claim((1.5, 2.0), floor=fl).verdict == "not reproduced"  # worse than the noise excuses
    assert _claim((0.2, 0.5), floor=fl).verdict == "reproduced"  # the data crossed the floor
    built = _claim((0.2, 0.5), by_construction=True, why="the simulator was set to it")
    assert built.verdict == "cannot be judged" and built.basis == "by construction"
    none = report.Claim("c", "p", why="Table 5 prints no drift")
    assert none.verdict == "cannot be judged" and none.rule == "no statistic" and none.reason


def test_glance_shows_interval_and_boundary_and_the_book_apart():
    g = report.glance([_claim((0.2, 0.5)), _claim((0.5, 1.5), source="book")])
    paper, book = g.tables()
    assert list(paper.frame.columns) == report.GLANCE_COLUMNS
    assert paper.frame.loc[0, report.GLANCE_COLUMNS[3]] == "0.35 [0.2, 0.5] deg"
    assert paper.frame.loc[0, "boundary"] == "< 1 deg"
    assert "1 of 1 reproduced" in paper.caption and "The paper's claims" in paper.caption
    assert "The book's own claims" in book.caption and book.frame.loc[0, "verdict"].startswith(
        "cannot be"
    )
    assert "The book's own claims" in repr(g) and "The book's own claims" in g._repr_html_()
    assert len(report.glance([_claim()]).tables()) == 1


def test_write_and_read_results_round_trip(tmp_path):
    rms = np.array([1.0, 2.0, 3.0, 4.0])
    path = report.write_results(
        "compass",
        claims=[_claim((1.5, 2.0), decided_by=("noise 0.04 uT",))],
        unit="deg",
        methods={"ADE-BP": report.method_stats(rms, -rms, rms)},
        folder=tmp_path,
    )
    assert repr(path) == "results written: compass.json"
    res = report.read_results(tmp_path)["compass"]
    assert (
        res["methods"]["ADE-BP"]["median_rms_deg"] == 2.5
        and res["methods"]["ADE-BP"]["n_seeds"] == 4
    )
    assert res["methods"]["ADE-BP"]["median_min_deg"] == -2.5
    c = res["claims"][0]
    assert c["verdict"] == "not reproduced" and c["interval"] == [1.5, 2.0] and c["boundary"] == 1.0
    assert (
        c["holds_when"] == "below"
        and c["source"] == "paper"
        and c["decided_by"] == ["noise 0.04 uT"]
    )
    assert c["rule"] == "median over runs" and c["n"] == 20
    assert json.loads(path.read_text())["unit"] == "deg"
    from navbook.results_check import validate_results

    assert validate_results(res, "compass.json") == []


def test_write_results_refuses_bad_input(tmp_path):
    claim = _claim()
    with pytest.raises(InputError, match="unit"):
        report.write_results(
            "compass", claims=[claim], methods={"m": {"median_rms": 1.0}}, folder=tmp_path
        )
    with pytest.raises(InputError, match="at least one claim"):
        report.write_results("compass", claims=[], folder=tmp_path)
    with pytest.raises(InputError, match="chapter name"):
        report.write_results("my chapter", claims=[claim], folder=tmp_path)
    with pytest.raises(InputError, match="twice"):
        report.write_results("compass", claims=[claim, claim], folder=tmp_path)


def test_results_go_where_the_caller_says_and_never_over_an_earlier_run(tmp_path, monkeypatch):
    claim = _claim((1.5, 2.0))
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("NAVBOOK_RESULTS_DIR", raising=False)
    assert report.results_dir() == tmp_path / "results"  # library use: ./results
    first = report.write_results("compass", claims=[claim])
    assert first == tmp_path / "results" / "compass.json"
    before = first.read_text()
    with pytest.raises(InputError, match="compass.json: a results file is already there") as err:
        report.write_results("compass", claims=[_claim((0.1, 0.2))])
    assert "\n" not in str(err.value) and "overwrite=True" in str(err.value)
    assert first.read_text() == before  # the earlier run's file is intact
    report.write_results("compass", claims=[_claim((0.1, 0.2))], overwrite=True)
    assert json.loads(first.read_text())["claims"][0]["interval"] == [0.1, 0.2]
    book = tmp_path / "book_results"
    monkeypatch.setenv("NAVBOOK_RESULTS_DIR", str(book))  # the build says where
    assert report.results_dir() == book
    assert report.write_results("compass", claims=[claim]) == book / "compass.json"
    assert set(report.read_results()) == {"compass"}
    (tmp_path / "a_file").write_text("x")
    with pytest.raises(InputError, match="cannot create the results folder"):
        report.write_results("compass", claims=[claim], folder=tmp_path / "a_file" / "sub")


def test_claims_summary_counts_per_chapter_source_and_reading():
    res = {
        "a": {
            "claims": [
                {"reproduced": True, "reading": "r1", "source": "paper"},
                {"reproduced": False, "reading": "r1", "source": "paper"},
                {"reproduced": None, "reading": "r2", "source": "paper"},
                {"reproduced": True, "reading": "r1", "source": "book"},
            ]
        }
    }
    s = report.claims_summary(res).set_index(["source", "reading"])
    assert s.loc[("paper", "r1"), "claims"] == 2 and s.loc[("paper", "r1"), "reproduced"] == 1
    assert s.loc[("paper", "r1"), "not reproduced"] == 1
    assert (
        s.loc[("paper", "r2"), "cannot be judged"] == 1
        and s.loc[("paper", "r2"), "reproduced"] == 0
    )
    assert s.loc[("book", "r1"), "claims"] == 1


def test_glue_claims_glues_verdict_and_detail(monkeypatch):
    glued = {}
    monkeypatch.setattr(glue, "_glue", lambda name, obj: glued.__setitem__(name, obj))
    report.glue_claims([_claim((1.5, 2.0), key="d_rmse"), _claim()])
    assert glued == {
        "d_rmse": "not reproduced",
        "d_rmse_detail": "not reproduced: ours 1.75 [1.5, 2] deg, boundary < 1 deg",
    }


def test_table_html_escapes_text_and_lets_identifiers_wrap():
    tab = report.table(
        pd.DataFrame({"needs_columns": ["temperature_change_c", "<b>x</b>"]}), index=False
    )
    h = tab._repr_html_()
    assert "temperature_<wbr>change_<wbr>c" in h and "needs_<wbr>columns" in h
    assert "&lt;b&gt;x" in h and "<b>x</b>" not in h
    assert "temperature_change_c" in repr(tab)  # the text twin (nbval) is unchanged


# ----------------------------------------------------------------------------------------------- fold, parameters, showed
def test_a_folded_table_is_a_dropdown_with_the_same_text():
    df = pd.DataFrame({"rms_deg": [0.1234]})
    open_ = report.table(df, caption="Secondary numbers")
    folded = report.table(df, caption="Secondary numbers", fold=True)
    assert repr(open_) == repr(folded)
    h = folded._repr_html_()
    assert h.startswith('<details class="navbook-fold"><summary>Secondary numbers</summary>')
    assert h.endswith("</details>") and "<caption>" not in h
    assert "<details" not in open_._repr_html_()
    assert "<summary>Open me</summary>" in report.table(df, fold="Open me")._repr_html_()
    with pytest.raises(InputError, match="fold=True needs a caption"):
        report.table(df, fold=True)


@pytest.mark.parametrize(
    "name, unit",
    [
        ("noise_ut", "uT"),
        ("gyro_arw_deg_rt_h", "deg/sqrt(h)"),
        ("drift_deg_h", "deg/h"),
        ("t_start_c", "degC"),
        ("imu_rate_hz", "Hz"),
        ("n_seeds", ""),
        ("alpha", ""),
        ("duration_s", "s"),
    ],
)
def test_unit_of_reads_the_name_suffix(name, unit):
    assert report.unit_of(name) == unit


CELL = """# first: a comment block
# over two lines
first_ut = 0.5
second = "x"   # beside it
# a pair under one comment
lo_deg, hi_deg = -1.0, 2.0
shares_it = 3

pair_a = 1
pair_b = 2

lonely = [1, 2]
"""


def test_parameter_rows_read_names_defaults_and_comments():
    rows = report.parameter_rows(CELL)
    assert [r["name"] for r in rows] == [
        "first_ut",
        "second",
        "lo_deg",
        "hi_deg",
        "shares_it",
        "pair_a",
        "pair_b",
        "lonely",
    ]
    by = {r["name"]: r for r in rows}
    assert by["first_ut"]["meaning"] == "first: a comment block over two lines"
    assert by["first_ut"]["default"] == 0.5
    assert by["second"]["meaning"] == "beside it"
    assert by["lo_deg"]["default"] == -1.0 and by["hi_deg"]["default"] == 2.0
    assert by["hi_deg"]["meaning"] == by["shares_it"]["meaning"] == "a pair under one comment"
    assert by["pair_b"]["meaning"] == by["pair_a"]["meaning"] == ""
    assert by["lonely"]["default"] == [1, 2]
    with pytest.raises(InputError, match="line 1"):
        report.parameter_rows("x = = 1")


def test_parameter_table_shows_this_runs_values_beside_the_defaults(tmp_path):
    nb = tmp_path / "ch.ipynb"
    nb.write_text(
        json.dumps(
            {
                "cells": [
                    {"cell_type": "markdown", "metadata": {}, "source": "# t"},
                    {
                        "cell_type": "code",
                        "metadata": {"tags": ["parameters"]},
                        "source": CELL.splitlines(True),
                    },
                ]
            }
        )
    )
    t = report.parameter_table(nb, {"first_ut": 0.5, "second": "y"})
    f = t.frame.set_index("parameter")
    assert f.loc["first_ut", "value"] == "0.5" and f.loc["first_ut", "unit"] == "uT"
    assert f.loc["second", "value"] == "'y' (default 'x')"
    assert f.loc["lonely", "value"] == "[1, 2]" and f.loc["lonely", "unit"] == "–"
    assert "8 parameters, 1 changed" in t.fold and "<details" in t._repr_html_()
    assert "all at their defaults" in report.parameter_table(nb, {}).fold
    nb2 = tmp_path / "none.ipynb"
    nb2.write_text(
        json.dumps({"cells": [{"cell_type": "code", "metadata": {}, "source": "x = 1"}]})
    )
    with pytest.raises(InputError, match="no cell tagged 'parameters'"):
        report.parameter_table(nb2, {})
    with pytest.raises(InputError, match="no such notebook"):
        report.parameter_table(tmp_path / "missing.ipynb", {})
    (tmp_path / "bad.ipynb").write_text("{not json")
    with pytest.raises(InputError, match="not a notebook"):
        report.parameter_table(tmp_path / "bad.ipynb", {})


def test_showed_summarises_each_claim_over_its_readings():
    def c(name, reading, value, source="paper"):
        return report.Claim(
            name,
            "p",
            reading=reading,
            source=source,
            statistic="d, deg",
            estimate=verdicts.Estimate(value, value - 0.1, value + 0.1, "median over runs", 20),
            boundary=0.0,
            holds_when="above",
            unit="deg",
        )

    claims = [
        c("A beats B", "r1", 1.0),
        c("A beats B", "r2", -1.0),
        c("A beats B", "r3", 0.05),
        c("C beats D", "r1", 1.0),
        c("C beats D", "r2", 2.0),
        c("ours", "-", 0.0, "book"),
    ]
    s = report.showed(claims)
    text = repr(s)
    assert "The paper's claims: 3 of 5 reproduced, 1 not reproduced, 1 cannot be judged" in text
    assert "(1 our interval contains the boundary)" in " ".join(text.split())
    rows = dict(s._rows(s.parts[0][1]).values)
    assert (
        rows["A beats B"]
        == "reproduced in 1, not reproduced in 1, cannot be judged in 1 of 3 readings"
    )
    assert rows["C beats D"] == "reproduced in all 2 readings"
    assert dict(s._rows(s.parts[1][1]).values)["ours"].startswith("cannot be judged (1 ")
    # the claim records of a results file give the same box
    recs = [cl.record() for cl in claims]
    assert repr(report.showed(recs)) == text
    assert "The book's own claims" in s._repr_html_()
    with pytest.raises(InputError, match="claim record"):
        report.showed([{"claim": "x"}])


def test_glue_claims_judges_a_row_with_its_register_entrys_margin(monkeypatch):
    """A04's rows carry the register's 0.01 deg margin: an interval within it is glued as the results
    file records it (no difference), not as the margin-free row would say (reproduced)."""
    from navlib import claims as registry

    row = "BP beats 8-position LS [planar 5 par.]"
    assert registry.row_margin(row) == 0.01
    assert registry.row_margin("a row no register lists") is None
    glued = {}
    monkeypatch.setattr(glue, "_glue", lambda name, obj: glued.__setitem__(name, obj))
    e = verdicts.Estimate(0.004, 0.0009, 0.0082, "paired difference", 20)
    c = report.Claim(
        row,
        "p",
        statistic="rms LS - rms BP, deg",
        estimate=e,
        boundary=0.0,
        holds_when="above",
        unit="deg",
        key="k",
    )
    assert c.verdict == "reproduced"
    report.glue_claims([c])
    assert glued["k"] == "no difference"


def test_claim_table_shows_each_claim_with_its_register_margin():
    row = "BP beats 8-position LS [planar 5 par.]"
    e = verdicts.Estimate(0.004, 0.0009, 0.0082, "paired difference", 20)
    within = report.Claim(
        row, "p", statistic="d, deg", estimate=e, boundary=0.0, holds_when="above", unit="deg"
    )
    t = report.claim_table([within, _claim((1.5, 2.0))], extra=("reading", "source"))
    assert list(t.columns) == [
        "claim",
        "reading",
        "source",
        "ours: value [95 % interval]",
        "boundary",
        "verdict",
    ]
    assert t.verdict.tolist() == ["no difference", "not reproduced"]
    assert t["ours: value [95 % interval]"][1] == "1.75 [1.5, 2] deg"
