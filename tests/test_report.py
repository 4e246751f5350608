"""navlib.report: tables that fit, claims, results files and the landing page's counts."""
import json

import numpy as np
import pandas as pd
import pytest

from navlib import report
from navlib.errors import InputError


def wide_frame():
    return pd.DataFrame({"method": ["ADE-BP", "DE-BP"], "median rms (deg)": [0.123456, 10.0],
                         "what the paper says, a long text column": ["x " * 60, "short"],
                         "ok": [True, False]})


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
    assert other.split('id="')[1][:12] != a.split('id="')[1][:12]     # two tables, two ids


def test_claim_validation_and_glance():
    with pytest.raises(InputError, match="reproduced"):
        report.Claim("c", "p", "o", "yes")
    with pytest.raises(InputError, match="Claim.ours"):
        report.Claim("c", "p", " ", True)
    g = report.glance([report.Claim("c", "p", "o", None, why="no data")])
    assert list(g.frame.columns) == ["claim", "reading", "paper", "ours", "verdict"]
    assert g.frame.loc[0, "verdict"] == "cannot be judged: no data"


def test_write_and_read_results_round_trip(tmp_path):
    rms = np.array([1.0, 2.0, 3.0, 4.0])
    path = report.write_results("compass", claims=[report.Claim("c", "p", "o", False)], unit="deg",
                                methods={"ADE-BP": report.method_stats(rms, -rms, rms)}, folder=tmp_path)
    assert repr(path) == "results written: compass.json"
    res = report.read_results(tmp_path)["compass"]
    assert res["methods"]["ADE-BP"]["median_rms_deg"] == 2.5 and res["methods"]["ADE-BP"]["n_seeds"] == 4
    assert res["methods"]["ADE-BP"]["median_min_deg"] == -2.5
    assert res["claims"][0]["verdict"] == "not reproduced"
    assert json.loads(path.read_text())["unit"] == "deg"


def test_write_results_refuses_bad_input(tmp_path):
    claim = report.Claim("c", "p", "o", True)
    with pytest.raises(InputError, match="unit"):
        report.write_results("compass", claims=[claim], methods={"m": {"median_rms": 1.0}}, folder=tmp_path)
    with pytest.raises(InputError, match="at least one claim"):
        report.write_results("compass", claims=[], folder=tmp_path)
    with pytest.raises(InputError, match="chapter name"):
        report.write_results("my chapter", claims=[claim], folder=tmp_path)


def test_claims_summary_counts_per_chapter_and_reading():
    res = {"a": {"claims": [{"reproduced": True, "reading": "r1"}, {"reproduced": False, "reading": "r1"},
                            {"reproduced": None, "reading": "r2"}]}}
    s = report.claims_summary(res).set_index("reading")
    assert s.loc["r1", "claims"] == 2 and s.loc["r1", "reproduced"] == 1 and s.loc["r1", "not reproduced"] == 1
    assert s.loc["r2", "cannot be judged"] == 1 and s.loc["r2", "reproduced"] == 0


def test_table_html_escapes_text_and_lets_identifiers_wrap():
    tab = report.table(pd.DataFrame({"needs_columns": ["temperature_change_c", "<b>x</b>"]}), index=False)
    h = tab._repr_html_()
    assert "temperature_<wbr>change_<wbr>c" in h and "needs_<wbr>columns" in h
    assert "&lt;b&gt;x" in h and "<b>x</b>" not in h
    assert "temperature_change_c" in repr(tab)            # the text twin (nbval) is unchanged
