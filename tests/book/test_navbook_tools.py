import json
import os
from pathlib import Path

import nbformat
import pytest

from navbook.execute import missing_figures, strip_metadata
from navbook.html_checks import check_html


def test_check_html_flags_remote_assets(tmp_path):
    (tmp_path / "ok.html").write_text('<script src="_static/mathjax/tex-chtml.js"></script>')
    assert check_html(tmp_path) == 0
    (tmp_path / "bad.html").write_text(
        '<script src="https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex.js"></script>'
    )
    assert check_html(tmp_path) == 1


def test_check_html_flags_tracebacks(tmp_path):
    (tmp_path / "p.html").write_text("<pre>Traceback (most recent call last):</pre>")
    assert check_html(tmp_path) == 1


def test_strip_metadata_removes_timings():
    nb = nbformat.v4.new_notebook()
    nb.metadata["papermill"] = {"duration": 1.0}
    cell = nbformat.v4.new_code_cell("1")
    cell.metadata["papermill"] = {"duration": 0.1}
    cell.metadata["execution"] = {"iopub.status.busy": "x"}
    cell.execution_count = 3
    nb.cells.append(cell)
    strip_metadata(nb)
    assert "papermill" not in nb.metadata and cell.metadata == {}
    assert cell.execution_count == 3  # nbval needs execution counts to compare outputs


def test_missing_figures_detects_plot_cells_without_images():
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell("plt.plot([1]); plt.show()")
    nb.cells.append(cell)
    assert missing_figures(nb) == [0]
    cell.outputs = [nbformat.v4.new_output("display_data", data={"image/png": "iVBOR"})]
    assert missing_figures(nb) == []


def test_execute_fails_loudly_on_a_failing_notebook(tmp_path, capsys):
    from navbook.execute import execute

    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_code_cell("x = 1"))
    nb.cells.append(nbformat.v4.new_code_cell("raise ValueError('parameter NP=3: must be >= 4')"))
    path = tmp_path / "bad.ipynb"
    nbformat.write(nb, path)
    out = tmp_path / "out"
    assert execute([path], out, in_place=False) == 1
    assert "FAILED bad.ipynb" in capsys.readouterr().err
    assert not (out / "bad.ipynb").exists()  # no half-executed notebook lands in the book


# ------------------------------------------------------------------ the presentation checks of check-html
from navbook.api_pages import api_markdown, navlib_modules  # noqa: E402
from navbook.html_checks import MAX_PRE_CHARS, check_page  # noqa: E402
from navbook.results_check import check_results, compare_results, validate_results  # noqa: E402

OUT = '<div class="cell_output docutils container">{}</div>'
PRE = '<div class="output stream highlight-myst-ansi notranslate"><div class="highlight"><pre>{}</pre></div></div>'


def page(body, heading="Results"):
    return f"<html><body><article><section><h2>{heading}<a class='headerlink'>#</a></h2>{body}</section></article></body></html>"


def test_check_page_accepts_a_clean_page():
    body = (
        OUT.format(PRE.format("x" * MAX_PRE_CHARS))
        + '<figure id="fig-a"><div class="cell_output docutils container"><img alt="errors" src="a.png"/></div>'
        "<figcaption><p>Caption.</p></figcaption></figure>"
        '<div class="cell tag_nbval-ignore-output">3.2 s</div>'
    )
    assert check_page(page(body)) == []


def test_check_page_flags_a_wide_output_line_and_says_where():
    problems = check_page(
        page(OUT.format(PRE.format("short\n" + "y" * (MAX_PRE_CHARS + 1))), "Table 3")
    )
    assert len(problems) == 1
    assert f"{MAX_PRE_CHARS + 1} characters" in problems[0] and "Table 3" in problems[0]


def test_check_page_tells_wide_code_input_from_wide_output():
    code = '<div class="cell_input"><div class="highlight"><pre>' + "z" * 150 + "</pre></div></div>"
    assert [p.split(" of ")[0] for p in check_page(page(code))] == ["wide code line"]
    problems = check_page(page(code + OUT.format(PRE.format("&lt;" * 120))))
    assert [p.split(" of ")[0] for p in problems] == ["wide code line", "output line"]


def test_check_page_flags_uncaptioned_figures():
    bare_output_image = OUT.format('<img alt="../_images/x.png" src="../_images/x.png"/>')
    assert any("without a caption" in p for p in check_page(page(bare_output_image)))
    figure_no_caption = '<figure id="fig-b"><img src="b.png"/></figure>'
    problems = check_page(page(figure_no_caption))
    assert len(problems) == 1 and "fig-b" in problems[0]


def test_check_page_flags_visible_nbval_markers_not_tags():
    code = '<div class="cell_input"><pre><span class="c1"># NBVAL_IGNORE_OUTPUT</span>\nt = 1</pre></div>'
    problems = check_page(page(code))
    assert len(problems) == 1 and "NBVAL_IGNORE_OUTPUT" in problems[0]
    assert check_page(page('<script>var s = "NBVAL_x";</script>')) == []


def test_check_html_reports_page_and_problem(tmp_path, capsys):
    (tmp_path / "chapter.html").write_text(page(OUT.format(PRE.format("w" * 200))))
    assert check_html(tmp_path) == 1
    assert "chapter.html: output line of 200 characters" in capsys.readouterr().err


# ------------------------------------------------------------------ landing page and API list
def _nb(path, write_call, title="Electronic compass"):
    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_markdown_cell(f"# {title}\n\nIntro."))
    nb.cells.append(nbformat.v4.new_code_cell(write_call))
    nbformat.write(nb, path)
    return path


def _claim(text, reproduced, reading="as printed", source="paper"):
    """A stored claim whose interval gives ``reproduced`` by the rule (boundary 1, holds below)."""
    interval = {True: [0.2, 0.5], False: [1.5, 2.0], None: [0.5, 1.5]}[reproduced]
    from navbook import report
    from navlib import verdicts

    c = report.Claim(
        text,
        "-0.22..0.20 deg",
        reading=reading,
        source=source,
        statistic="rms, deg",
        estimate=verdicts.Estimate(sum(interval) / 2, *interval, "median over runs", 20),
        boundary=1.0,
        holds_when="below",
        unit="deg",
    )
    return c.record()


def test_api_markdown_lists_every_navlib_module():
    mods = navlib_modules()
    assert {
        "navlib.angles",
        "navlib.claims",
        "navbook.report",
        "navbook.landing",
        "navlib.studies.compass",
    } <= set(mods)
    assert not [
        m
        for m in mods
        if m in ("navlib.report", "navlib.booktools", "navlib.grid", "navbook.booktools")
    ]
    assert "navlib.__main__" not in mods
    md = api_markdown(mods)
    assert md.count(".. automodule:: ") == len(mods)


# ------------------------------------------------------------------ results check
def _results(rms=4.2, verdict=False):
    return {
        "chapter": "compass",
        "unit": "deg",
        "methods": {
            "ADE-BP": {
                "median_rms_deg": rms,
                "p10_rms_deg": 3.0,
                "p90_rms_deg": 5.0,
                "median_min_deg": -9.0,
                "median_max_deg": 8.0,
                "n_seeds": 20,
            }
        },
        "claims": [_claim("ADE-BP beats DE-BP", verdict)],
    }


def test_validate_results_checks_the_schema():
    assert validate_results(_results(), "compass.json") == []
    bad = _results()
    del bad["methods"]["ADE-BP"]["p90_rms_deg"]
    bad["claims"][0]["reproduced"] = "yes"
    bad["unit"] = "mg"
    problems = " ".join(validate_results(bad, "compass.json"))
    assert "reproduced must be" in problems and "lacks 'p90_rms_mg'" in problems
    assert validate_results({"chapter": "compass", "claims": []}, "compass.json")


@pytest.mark.parametrize(
    "field,value,message",
    [
        ("source", "ours", "source"),
        ("rule", "eyeball", "rule"),
        ("interval", [2.0, 1.0], "interval"),
        ("holds_when", "left", "holds_when"),
        ("boundary", None, "boundary"),
        ("statistic", "", "statistic"),
        ("estimate", 9.0, "outside its interval"),
        ("decided_by", "noise", "decided_by"),
        ("floor", {"value": 0.1}, "floor"),
        ("ours", "", "ours"),
    ],
)
def test_validate_results_names_each_bad_claim_field(field, value, message):
    res = _results()
    res["claims"][0][field] = value
    problems = " ".join(validate_results(res, "compass.json"))
    assert message in problems and "claims[0]" in problems


@pytest.mark.parametrize("verdict", [True, False, None])
def test_a_hand_edited_verdict_is_rejected(verdict):
    """Each claim's verdict is derived again from its interval, boundary and side."""
    res = _results(verdict=verdict)
    assert validate_results(res, "compass.json") == []
    for other in {True, False, None} - {verdict}:
        edited = json.loads(json.dumps(res))
        edited["claims"][0]["reproduced"] = other
        edited["claims"][0]["verdict"] = {
            True: "reproduced",
            False: "not reproduced",
            None: "cannot be judged",
        }[other]
        edited["claims"][0]["why"] = "edited by hand"
        assert any("does not follow" in p for p in validate_results(edited, "compass.json"))


def test_a_floor_on_the_wrong_side_makes_a_stored_claim_undecidable():
    res = _results(verdict=False)  # interval beyond the boundary
    c = res["claims"][0]
    c.update(estimate=1.1, interval=[1.05, 1.15])  # ... but within the floor 1.2
    c["floor"] = {"value": 1.2, "assumption": "sensor noise 3 ug", "needs": "noise below 2.5 ug"}
    assert any("does not follow" in p for p in validate_results(res, "compass.json"))
    c["floor"]["interval"] = [1.3, 1.1]
    assert any("floor interval" in p for p in validate_results(res, "compass.json"))
    c["floor"]["interval"] = [1.1, 1.3]
    c.update(
        reproduced=None,
        verdict="cannot be judged",
        basis="noise floor",
        reason="noise floor",
        why="floor",
    )
    assert validate_results(res, "compass.json") == []
    c["why"] = ""
    assert any("without a why" in p for p in validate_results(res, "compass.json"))


def test_compare_results_tolerance_and_verdicts():
    ref = _results(4.2)
    assert compare_results(_results(4.2 * (1 + 1e-4)), ref, "c") == []
    assert any("median_rms_deg" in p for p in compare_results(_results(4.3), ref, "c"))
    assert any("verdict" in p for p in compare_results(_results(4.2, verdict=True), ref, "c"))
    fewer_seeds = _results()
    fewer_seeds["methods"]["ADE-BP"]["n_seeds"] = 5
    assert any("n_seeds" in p for p in compare_results(fewer_seeds, ref, "c"))


def test_check_results_fails_without_reference_and_passes_with_it(tmp_path, capsys):
    nb = _nb(tmp_path / "compass.ipynb", 'report.write_results("compass", claims=claims)')
    fresh, ref = tmp_path / "fresh", tmp_path / "ref"
    fresh.mkdir()
    ref.mkdir()
    (fresh / "compass.json").write_text(json.dumps(_results()))
    assert check_results(fresh, ref, [nb]) == 1
    assert "missing reference" in capsys.readouterr().err
    (ref / "compass.json").write_text(json.dumps(_results()))
    assert check_results(fresh, ref, [nb]) == 0
    (fresh / "compass.json").unlink()  # a stale fresh folder cannot pass
    assert check_results(fresh, ref, [nb]) == 1


def test_check_results_fails_for_a_notebook_that_writes_no_results(tmp_path, capsys):
    nb = _nb(tmp_path / "gyro.ipynb", "x = 1")
    assert check_results(tmp_path, tmp_path, [nb]) == 1
    assert "writes no results file" in capsys.readouterr().err


def test_execute_in_place_stores_the_results_file_beside_the_notebook(tmp_path, monkeypatch):
    """The kernel writes its results file where execute tells it (a temporary folder in
    $NAVBOOK_RESULTS_DIR, not a library default such as the notebook folder's ./results or the book's
    folder); execute copies it beside the notebook and restores the caller's environment."""
    from navbook.execute import execute
    from navbook.report import RESULTS_ENV

    monkeypatch.delenv(RESULTS_ENV, raising=False)
    nb = nbformat.v4.new_notebook()
    nb.cells.append(
        nbformat.v4.new_code_cell(
            "import os\n"
            "from navbook import report\n"
            "from navlib import verdicts\n"
            "p = report.write_results('demo_chapter', claims=[report.Claim('c', 'p', statistic='x, deg', "
            "estimate=verdicts.exact(0.5), boundary=1.0, holds_when='below')])\n"
            f"print(os.environ.get({RESULTS_ENV!r}))\n"
            "print(p.resolve())"
        )
    )
    path = tmp_path / "demo.ipynb"
    nbformat.write(nb, path)
    assert execute([path], None, in_place=True) == 0
    stored = json.loads((tmp_path / "results" / "demo_chapter.json").read_text())
    assert stored["claims"][0]["reproduced"] is True
    told, wrote = nbformat.read(path, as_version=4).cells[0].outputs[0]["text"].split()
    assert (
        told != "None" and Path(wrote) == Path(told).resolve() / "demo_chapter.json"
    )  # where it was told
    assert Path(told).resolve() != (tmp_path / "results").resolve()  # not its ./results
    assert not Path(told).exists()  # a temporary folder
    assert RESULTS_ENV not in os.environ  # restored


def test_check_html_reads_source_listings_only_for_network_assets(tmp_path):
    listing = tmp_path / "_modules" / "navbook"
    listing.mkdir(parents=True)
    (listing / "html_checks.html").write_text(
        '<pre>if "Traceback (most recent call last)" in text: # NBVAL_</pre>'
    )
    assert check_html(tmp_path) == 0
    (listing / "cli.html").write_text('<script src="https://cdn.example/x.js"></script>')
    assert check_html(tmp_path) == 1


def test_chapter_pages_must_open_with_results_at_a_glance(tmp_path, capsys):
    from navbook.html_checks import check_chapter_opening

    glance = '<div class="admonition"><p class="admonition-title">Results at a glance</p><table></table></div>'
    cell = '<div class="cell docutils container"><pre>n_seeds = 20</pre></div>'
    assert check_chapter_opening(page(glance + cell)) == []
    assert "after a code cell" in check_chapter_opening(page(cell + glance))[0]
    assert "without a 'Results at a glance'" in check_chapter_opening(page(cell))[0]
    chapters = tmp_path / "_generated"
    chapters.mkdir()
    (chapters / "gyro.html").write_text(page(cell))
    (tmp_path / "intro.html").write_text(page("<p>no glance needed</p>"))
    assert check_html(tmp_path) == 1
    err = capsys.readouterr().err
    assert "_generated/gyro.html: chapter without" in err and "intro.html" not in err


def test_chapter_pages_must_close_with_what_the_chapter_showed():
    from navbook.html_checks import check_chapter_closing

    def box(title, paper, book=None):
        tallies = (
            f"<p>The paper's claims: {paper[0]} of {sum(paper)} reproduced, {paper[1]} not reproduced, "
            f"{paper[2]} cannot be judged</p>"
        )
        if book:
            tallies += (
                f"<p>The book's own claims: {book[0]} of {sum(book)} reproduced, {book[1]} not "
                f"reproduced, {book[2]} cannot be judged</p>"
            )
        return f'<div class="admonition"><p class="admonition-title">{title}</p>{tallies}</div>'

    cell = '<div class="cell docutils container"><pre>x = 1</pre></div>'
    glance = box("Results at a glance", (2, 1, 3), (1, 0, 0))
    good = page(glance + cell + box("What this chapter showed", (2, 1, 3), (1, 0, 0)))
    assert check_chapter_closing(good) == []
    assert "without a 'What this chapter showed'" in check_chapter_closing(page(glance + cell))[0]
    late = page(glance + box("What this chapter showed", (2, 1, 3), (1, 0, 0)) + cell)
    assert "not at the chapter's end" in check_chapter_closing(late)[0]
    other = page(glance + cell + box("What this chapter showed", (3, 0, 3), (1, 0, 0)))
    assert "counts" in check_chapter_closing(other)[0]
    no_book = page(glance + cell + box("What this chapter showed", (2, 1, 3)))
    assert "counts" in check_chapter_closing(no_book)[0]


def test_compare_results_checks_intervals_except_for_a_volatile_timing():
    ref = _results()
    moved = json.loads(json.dumps(ref))
    moved["claims"][0]["interval"] = [0.2, 0.6]
    assert any("interval" in p for p in compare_results(moved, ref, "c"))
    vol_ref, vol = json.loads(json.dumps(ref)), json.loads(json.dumps(moved))
    vol_ref["claims"][0]["volatile"] = vol["claims"][0]["volatile"] = True
    assert compare_results(vol, vol_ref, "c") == []  # a timing's numbers may move
    flipped = json.loads(json.dumps(vol))
    flipped["claims"][0].update(
        _claim("ADE-BP beats DE-BP", True, reading=ref["claims"][0]["reading"])
    )
    flipped["claims"][0]["volatile"] = True
    assert any(
        "verdict" in p for p in compare_results(flipped, vol_ref, "c")
    )  # its verdict may not
    assert any("volatile" in p for p in compare_results(vol, ref, "c"))


def test_compare_results_compares_tables_of_records_exactly(tmp_path):
    """write_results(tables=...) writes top-level lists (the compass chapter's "robustness"); a changed or
    missing record is a difference from the reference."""
    from navbook import report

    claim = report.Claim(
        "c",
        "p",
        statistic="x, deg",
        estimate=None,
        boundary=0.0,
        holds_when="above",
        why="no statistic",
    )
    rows = [{"compass": "C1", "claim": "c", "reading": "r", "verdict": "reproduced"}]
    path = report.write_results(
        "demo", claims=[claim], folder=tmp_path, tables={"robustness": rows}
    )
    res = json.loads(path.read_text())
    assert res["robustness"] == rows
    other = json.loads(path.read_text())
    other["robustness"][0]["verdict"] = "not reproduced"
    assert any("robustness" in p for p in compare_results(other, res, "demo"))
    assert compare_results(json.loads(path.read_text()), res, "demo") == []
    with pytest.raises(Exception, match="reserved"):
        report.write_results("demo2", claims=[claim], folder=tmp_path, tables={"claims": rows})


def test_api_page_check_finds_split_descriptions_and_commands_that_would_not_run():
    from navbook.html_checks import check_api_page

    ok = (
        "<dl><dt>loop SYSTEM FILE.csv --model START [--json] [--report DIR]</dt>"
        "<dd><p>the whole loop</p></dd><dt>field --site LAT,LON [--date YYYY-MM-DD] [--json]</dt></dl>"
    )
    assert check_api_page(ok, cli_page=True) == []
    dash = ok.replace("[--json] [--report", "[\u2013json] [--report")
    assert any("typographic" in p for p in check_api_page(dash, cli_page=True))
    quote = ok.replace("--model START", "--model \u201cSTART\u201d")
    assert any("typographic" in p for p in check_api_page(quote, cli_page=True))
    unknown = ok.replace("[--report DIR]", "[--reprot DIR]")
    assert any("no option --reprot" in p for p in check_api_page(unknown, cli_page=True))
    split = '<dt class="field-odd">Type<span class="colon">:</span></dt><dd>The output must</dd>'
    assert check_api_page(split) == ["1 description(s) split into a 'Type:' field"]
    assert check_api_page(ok) == []  # commands are checked on the CLI page only


def test_commands_on_the_cli_page_are_run_with_help():
    """Each command the page shows runs ``python -m navlib COMMAND --help`` in a new process: a command
    that fails, or whose help lacks an option the page shows, is a problem."""
    from navbook.html_checks import _help_problems

    assert _help_problems({"loop": {"--json", "--report"}, "field": {"--site"}}) == []
    assert _help_problems({"loop": {"--json", "--jsonl"}}) == [
        "'navlib loop --help' does not show --jsonl, which the page shows"
    ]
    bad = _help_problems({"no-such-command": {"--json"}})
    assert len(bad) == 1 and "failed (exit 2)" in bad[0]
