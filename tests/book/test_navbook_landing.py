"""The landing page (summary, verdict box, readings), the one source of counts, the verdict labels with
their case, and the presentation checks of check-html added with issue 24."""

import json

import nbformat
import pandas as pd
import pytest

from navbook import api_pages, claim_boxes, html_checks, landing, report, results_check
from navlib import verdicts
from navlib.errors import InputError


# ------------------------------------------------------------------ helpers
def _claim(
    text,
    reproduced,
    reading="as printed",
    source="paper",
    floor=None,
    by_construction=False,
    estimate=True,
):
    """A claim whose interval gives ``reproduced`` by the rule (boundary 1, holds below); with a floor,
    an interval beyond the boundary but within the floor."""
    interval = {True: [0.2, 0.5], False: [1.5, 2.0], None: [0.5, 1.5]}[reproduced]
    if floor is not None:
        interval = [1.05, 1.15]
    est = (
        verdicts.Estimate(sum(interval) / 2, *interval, "median over runs", 20)
        if estimate
        else None
    )
    return report.Claim(
        text,
        "0.2 deg",
        reading=reading,
        source=source,
        statistic="rms, deg",
        estimate=est,
        boundary=1.0 if estimate else None,
        holds_when="below" if estimate else None,
        unit="deg",
        floor=floor,
        by_construction=by_construction,
        why="we set it" if by_construction else ("" if estimate else "the paper prints no rms"),
    )


def _nb(path, chapter, title):
    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_markdown_cell(f"# {title}\n\nIntro."))
    nb.cells.append(nbformat.v4.new_code_cell(f'report.write_results("{chapter}", claims=claims)'))
    nbformat.write(nb, path)
    return path


CLAIMS = [
    _claim("a", True, "1: pure DE"),
    _claim("b", False, "1: pure DE"),
    _claim("c", None, "2: DE + trainlm, val. stop"),
    _claim(
        "d",
        True,
        "2: DE + trainlm, val. stop",
        floor=verdicts.Floor(1.2, "noise 3 ug", "noise < 2 ug"),
    ),
    _claim("e", None, "document B", by_construction=True),
    _claim("f", None, "document B", estimate=False),
    _claim("rate", True, "ours", source="book"),
]


def _results():
    return {
        "compass": {"chapter": "compass", "claims": [c.record() for c in CLAIMS]},
        "gyro": {"chapter": "gyro", "claims": [_claim("g", False).record()]},
    }


# ------------------------------------------------------------------ verdict labels
def test_each_case_of_cannot_be_judged_gets_its_own_label():
    labels = [c.verdict_label for c in CLAIMS]
    assert labels == [
        "reproduced",
        "not reproduced",
        "cannot be judged: our interval contains the boundary",
        "cannot be judged: within our noise floor",
        "cannot be judged: by construction of our simulator",
        "cannot be judged: the paper gives no number",
        "reproduced",
    ]
    assert [c.record()["reason"] for c in CLAIMS] == [
        None,
        None,
        "straddles",
        "noise floor",
        "by construction",
        "no statistic",
        None,
    ]
    assert [c.record()["verdict"] for c in CLAIMS][2:6] == [
        "cannot be judged"
    ] * 4  # the three values stay
    assert (
        verdicts.reason_category("no statistic", "no 95 % interval: quantile_ci needs 6 runs")
        == "too few runs"
    )
    assert set(verdicts.VERDICT_DEFINITIONS) >= {
        f"cannot be judged: {v[0]}" for v in verdicts.REASONS.values()
    }
    with pytest.raises(InputError, match="basis='guess'"):
        verdicts.reason_category("guess")
    assert all(results_check.claim_problems(c.record()) == [] for c in CLAIMS)
    edited = dict(CLAIMS[3].record(), reason="straddles")  # a reason edited by hand
    assert results_check.claim_problems(edited) == [
        "reason 'straddles', the basis 'noise floor' and the why give 'noise floor'"
    ]


# ------------------------------------------------------------------ landing page
def test_reading_labels_are_readable():
    assert (
        landing.reading_label("2: DE + trainlm, val. stop")
        == "DE + trainlm, validation stop (reading 2)"
    )
    assert landing.reading_label("document B") == "Document B"
    assert landing.reading_label("held-out runs") == "Held-out runs"


def test_verdict_sentence_follows_the_counts():
    c = dict(zip(landing.COUNTED, (61, 97, 53)))
    assert landing.verdict_sentence(c).startswith(
        "Mixed, more not reproduced than reproduced: 61 of the paper's 211 claims"
    )
    assert landing.verdict_sentence(dict(zip(landing.COUNTED, (13, 25, 7)))).startswith(
        "Mostly not reproduced: 25 of the paper's 45 claims do not"
    )
    assert landing.verdict_sentence(dict(zip(landing.COUNTED, (5, 0, 2)))).startswith(
        "Mostly reproduced: 5 of the paper's 7"
    )
    recs = [_claim("x", None, floor=verdicts.Floor(1.2, "noise", "less")).record()] * 3
    s = landing.verdict_sentence(dict(zip(landing.COUNTED, (1, 0, 3))), claims=recs)
    assert (
        s.startswith("Mostly cannot be judged: 3 of the paper's 4")
        and "(all within our noise floor)" in s
    )


def test_landing_page_summary_in_sidebar_order_with_bars_and_verdict_box(tmp_path):
    gyro = _nb(tmp_path / "gyro.ipynb", "gyro", "Axial gyro drift: RBF")
    compass = _nb(tmp_path / "compass.ipynb", "compass", "Electronic compass: LS and BP")
    celestial = _nb(tmp_path / "celestial.ipynb", "celestial", "INS/celestial")
    toc = tmp_path / "_toc.yml"
    toc.write_text(
        "root: intro\nchapters:\n  - file: _generated/compass\n  - file: _generated/gyro\n"
        "  - file: _generated/celestial\n"
    )
    order = landing.chapter_order([gyro, celestial, compass], toc)
    assert [p.stem for p in order] == ["compass", "gyro", "celestial"]
    sources = {"compass": ("Electronic compass", "paper A")}
    md = landing.status_markdown(_results(), order, sources)
    rows = [ln for ln in md.split("\n* - ")[1:]]  # the list-table's rows after the header
    assert len(rows) == 2 + 1 and rows[0].startswith("chapter and source")
    rows = rows[1:]
    assert (
        len(rows) == 2
        and "Electronic compass </_generated/compass>" in rows[0]
        and "paper A" in rows[0]
    )
    assert "Axial gyro drift: RBF </_generated/gyro>" in rows[1]  # no short title: the notebook's
    # counts: compass paper 1 reproduced (a), 1 not (b), 4 cannot be judged (c, d, e, f); book 1 / 0 / 0
    assert "paper's: 1 / 1 / 4<br>book's own: 1 / 0 / 0" in rows[0]
    assert "paper's: 0 / 1 / 0<br>book's own: –" in rows[1]
    assert (
        rows[0].count("<rect") == 3
        and 'aria-label="1 reproduced, 1 not reproduced, 4 cannot be judged"' in rows[0]
    )
    assert (
        "Mostly cannot be judged: 4 of the paper's 6 claims cannot be judged, 1 reproduce"
        in rows[0]
    )
    assert "In all, **1 of 7** of the papers' claims reproduce" in md
    assert (
        "(what-the-verdicts-mean)=" in md and "**cannot be judged: within our noise floor**" in md
    )
    assert (
        "Not yet summarised (no results file): {doc}`INS/celestial </_generated/celestial>`" in md
    )
    by_reading = landing.readings_markdown(_results(), order, sources)
    assert by_reading.index(
        "::::{dropdown} Electronic compass: 7 rows (claims under readings), 4 readings"
    ) < by_reading.index("gyro")
    assert (
        "| DE + trainlm, validation stop (reading 2) | 2 | 0 | 0 | 2 (1 our interval contains the boundary, "
        "1 within our noise floor) |" in by_reading
    )
    assert (
        "| Document B | 2 | 0 | 0 | 2 (1 by construction of our simulator, 1 the paper gives no number) |"
        in by_reading
    )
    assert "| Ours (the book's own claims) | 1 | 1 | 0 | 0 |" in by_reading
    assert "2: DE" not in by_reading  # no raw keys


def test_write_status_reads_the_toc_and_the_sources(tmp_path, capsys):
    book = tmp_path / "book"
    (book / "_generated" / "results").mkdir(parents=True)
    (book / "_toc.yml").write_text(
        "chapters:\n  - file: _generated/gyro\n  - file: _generated/compass\n"
    )
    (book / "chapters.csv").write_text("chapter,short_title,source\ncompass,Compass,paper A\n")
    for chap, title in (("compass", "Electronic compass"), ("gyro", "Gyro")):
        _nb(book / "_generated" / f"{chap}.ipynb", chap, title)
        (book / "_generated" / "results" / f"{chap}.json").write_text(json.dumps(_results()[chap]))
    out = book / "_generated" / "status.md"
    assert landing.write_status(book / "_generated" / "results", book / "_generated", out) == 0
    md = out.read_text()
    assert md.index("</_generated/gyro>") < md.index("{doc}`Compass </_generated/compass>`<span")
    assert (book / "_generated" / "status_readings.md").exists()
    (book / "chapters.csv").write_text("chapter,title\ncompass,Compass\n")
    with pytest.raises(InputError, match="needs the columns"):
        landing.write_status(book / "_generated" / "results", book / "_generated", out)


# ------------------------------------------------------------------ one source of counts
def _chapter_page(glance):
    return (
        f'<html><body><h1>Compass</h1><div class="admonition"><p class="admonition-title">Results at a '
        f'glance</p>{glance._repr_html_()}</div><div class="cell docutils container"><pre>x = 1</pre>'
        f"</div></body></html>"
    )


def test_landing_and_glance_counts_come_from_one_claim_list():
    results = _results()
    shown = html_checks.landing_counts(landing.status_markdown(results, []) or "")
    assert shown == {}  # no notebooks: no rows
    md = landing.status_markdown({"compass": results["compass"]}, [], None)
    assert "No chapter" in md
    marks = html_checks.landing_counts(
        '<span class="navbook-counts" data-chapter="compass" '
        'data-page="_generated/compass.html" data-paper="1 1 4" data-book="1 0 0"></span>'
    )
    assert marks["_generated/compass.html"]["paper"] == (1, 1, 4, 0)
    counts = landing.claim_counts(results)["compass"]
    assert tuple(counts["paper"].values()) == (1, 1, 4, 0) and tuple(counts["book"].values()) == (
        1,
        0,
        0,
        0,
    )
    full = _chapter_page(report.glance(CLAIMS))
    assert html_checks.glance_counts(full) == {"paper": (1, 1, 4, 0), "book": (1, 0, 0, 0)}
    assert html_checks.count_problems(marks, {"_generated/compass.html": full}) == []
    subset = _chapter_page(
        report.glance(CLAIMS[:3] + CLAIMS[-1:])
    )  # a glance that leaves claims out
    problems = html_checks.count_problems(marks, {"_generated/compass.html": subset})
    assert len(problems) == 1 and problems[0][1].startswith(
        "counts differ: the glance box shows the paper's claims as 1 of 3 reproduced / 1 not / 1"
    )
    assert html_checks.count_problems(marks, {})[0][1].startswith(
        "counts differ: the landing page counts"
    )


def test_the_glance_box_folds_long_lists_by_reading_and_labels_the_case():
    many = [_claim(f"c{i}", None, reading=f"r{i % 3}") for i in range(report.GLANCE_OPEN_ROWS + 1)]
    h = report.glance(many)._repr_html_()
    assert h.count("<details>") == 3 and "cannot be judged: our interval contains the boundary" in h
    assert report.VERDICTS_HREF in h
    short = report.glance(CLAIMS)._repr_html_()
    assert "<details>" not in short and "cannot be judged: within our noise floor" in short
    # the plain text (what nbval compares) is the tables' text, unchanged
    assert repr(report.glance(CLAIMS)) == "\n\n".join(
        repr(t) for t in report.glance(CLAIMS).tables()
    )


# ------------------------------------------------------------------ the presentation checks
def page(body, heading="Results"):
    return f"<html><body><article><h2>{heading}</h2>{body}</article></body></html>"


OUT = '<div class="cell_output docutils container"><div class="output text_html">{}</div></div>'


def test_check_page_flags_wide_code_unless_folded():
    wide = "<pre>" + "x = 1  # " + "z" * html_checks.MAX_CODE_CHARS + "</pre>"
    assert html_checks.check_page(page(f'<div class="highlight">{wide}</div>'))[0].startswith(
        f"wide code line of {html_checks.MAX_CODE_CHARS + 9} characters"
    )
    assert html_checks.check_page(page("<pre>" + "z" * html_checks.MAX_CODE_CHARS + "</pre>")) == []
    assert (
        html_checks.check_page(
            page(f"<details class='hide above-input'><summary>Show</summary>{wide}</details>")
        )
        == []
    )


def test_check_page_flags_index_name_rows_and_snake_case_headers():
    named = pd.DataFrame(
        {"median_rms_deg": [1.0], "b": [2.0]}, index=pd.Index(["x"], name="method")
    )
    problems = html_checks.check_page(page(OUT.format(named.to_html())))
    assert [p.split(" '")[0] for p in problems] == ["snake_case header", "index-name row"]
    styled = named.style.to_html()  # pandas' Styler: class index_name
    assert any(
        p.startswith("index-name row 'method'")
        for p in html_checks.check_page(page(OUT.format(styled)))
    )
    clean = report.table(
        named.reset_index().rename(columns={"median_rms_deg": "median RMS (deg)"}), index=False
    )
    assert html_checks.check_page(page(OUT.format(clean._repr_html_()))) == []
    # a table outside a cell output (the landing page's markdown tables, the API) is not a result table
    assert html_checks.check_page(page(named.to_html())) == []


def test_check_html_fails_only_beyond_the_baseline(tmp_path, capsys):
    wide = "<pre>" + "z" * 100 + "</pre>"
    (tmp_path / "intro.html").write_text(page(wide + wide))
    assert html_checks.check_html(tmp_path) == 1
    base = tmp_path / "baseline.json"
    base.write_text(json.dumps({"pages": {"intro.html": {"wide code line": 2}}}))
    assert html_checks.check_html(tmp_path, baseline=base) == 0
    assert "known, to fix: intro.html: 2 wide code line" in capsys.readouterr().err
    base.write_text(json.dumps({"pages": {"intro.html": {"wide code line": 1}}}))
    assert html_checks.check_html(tmp_path, baseline=base) == 1
    base.write_text(json.dumps({"pages": {"intro.html": {"wide code line": 5}}}))
    (tmp_path / "intro.html").write_text(
        page(wide + '<script src="https://cdn.example/x.js"></script>')
    )
    assert html_checks.check_html(tmp_path, baseline=base) == 1  # the old checks have no baseline


def test_the_committed_baseline_names_only_known_kinds():
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "book" / html_checks.BASELINE_FILE
    known = html_checks.load_baseline(path)
    assert known and all(set(kinds) <= set(html_checks.LAYOUT_KINDS) for kinds in known.values())


# ------------------------------------------------------------------ API pages
def test_api_pages_one_per_layer_build_internals_last():
    mods = [
        "navlib.verdicts",
        "navbook.landing",
        "navbook.report",
        "navlib.sensors.nope",
        "navbook.grid",
    ]
    pages = api_pages.api_pages(mods)
    assert list(pages)[-2:] == ["api_internals", "api_modules"]  # every layer, the tooling last
    assert {f"api_{name}" for name, _, _ in api_pages.API_LAYERS} | {"api_modules"} == set(pages)
    assert (
        "navbook.landing" in pages["api_internals"]
        and "navbook.landing" not in pages["api_foundations"]
    )
    assert pages["api_foundations"].count(".. automodule:: ") == 1
    assert (
        "| {py:mod}`navlib.verdicts` | One rule for every verdict in the book. |"
        in pages["api_foundations"]
    )
    assert "(not importable here" in pages["api_sensors"]
    assert "No module of navlib belongs here yet" in pages["api_cli"]
    overview = pages["api_modules"]
    assert (
        overview.index("api_sensors")
        < overview.index("api_foundations")
        < overview.index("api_internals")
    )
    assert "api_cli" not in overview  # an empty layer is not listed
    assert (
        api_pages.api_layer("navlib.data.tables") == "data"
        and api_pages.api_layer("navlib.newthing") == "foundations"
    )


def test_module_summary_is_the_first_sentence_as_myst(monkeypatch):
    import sys
    import types

    fake = types.ModuleType("navlib._fake_summary")
    fake.__doc__ = (
        "Paper C (Yu et al. 2012) with :func:`navlib.verdicts.decide` and ``x ... y``. More text."
    )
    monkeypatch.setitem(sys.modules, "navlib._fake_summary", fake)
    assert (
        api_pages.module_summary("navlib._fake_summary")
        == "Paper C (Yu et al. 2012) with `navlib.verdicts.decide` and `x ... y`."
    )
    fake.__doc__ = "Run ``" + "word " * 60 + "``. Next."
    cut = api_pages.module_summary("navlib._fake_summary")
    assert cut.endswith("` ...") and cut.count("`") == 2 and len(cut) < 210


def test_write_results_warns_about_claims_no_glance_box_showed(tmp_path, monkeypatch):
    monkeypatch.setattr(claim_boxes, "_GLANCED", set())
    report.glance(CLAIMS[:2])
    with pytest.warns(UserWarning, match="5 of the 7 claims are in no glance box"):
        report.write_results("compass", claims=CLAIMS, folder=tmp_path)
    report.glance(CLAIMS)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        report.write_results("compass", claims=CLAIMS, folder=tmp_path, overwrite=True)
