"""The book's fold extension (book/_ext/navbook_fold.py): a section's evidence behind one closed fold."""

import sys
from pathlib import Path

import pytest

sphinx = pytest.importorskip("sphinx.application")
pytest.importorskip("myst_parser")

EXT = Path(__file__).resolve().parents[2] / "book" / "_ext"

PAGE = """# Chapter

Opening paragraph.

## First section

The finding, in one paragraph.

```{evidence}
```

How it was found.

```{figure} img.png
:name: fig-one

A captioned figure.
```

| a | b |
|---|---|
| 1 | 2 |

### A subsection

More evidence.

## Second section

A summary with no evidence marker stays open, and so does what follows.

```{evidence} How the filter was tuned
```

Tuning detail.

## Third section

Nothing folded here.
"""


def build(tmp_path, text, builder="html"):
    src, out = tmp_path / "src", tmp_path / "out"
    src.mkdir()
    (src / "conf.py").write_text(
        "extensions = ['myst_parser', 'navbook_fold']\nnumfig = True\n"
        "myst_enable_extensions = ['colon_fence']\n"
    )
    (src / "index.md").write_text(text)
    # a 1 x 1 PNG for the figure
    (src / "img.png").write_bytes(
        bytes.fromhex(
            "89504e470d0a1a0a0000000d4948445200000001000000010806000000"
            "1f15c4890000000d4944415478da63f8cfc0f01f0005000201a2d8e1d50000000049454e44ae426082"
        )
    )
    sys.path.insert(0, str(EXT))
    try:
        app = sphinx.Sphinx(
            str(src),
            str(src),
            str(out),
            str(tmp_path / "doctrees"),
            builder,
            status=None,
            warning=None,
            freshenv=True,
        )
        app.build()
    finally:
        sys.path.remove(str(EXT))
    return app, out


def test_fold_holds_the_rest_of_its_section_only(tmp_path):
    app, out = build(tmp_path, PAGE)
    html = (out / "index.html").read_text()
    assert html.count('<details class="navbook-evidence">') == 2
    first = html.split('<details class="navbook-evidence">')[1].split("</details>")[0]
    assert "The evidence: 1 figure, 1 table, 1 subsection</summary>" in first
    assert (
        "How it was found." in first
        and "More evidence." in first
        and "A captioned figure." in first
    )
    # the summary stays outside, the next section is not swallowed
    assert "The finding, in one paragraph." not in first and "Second section" not in first
    second = html.split('<details class="navbook-evidence">')[2].split("</details>")[0]
    assert "<summary>How the filter was tuned</summary>" in second and "Tuning detail." in second
    assert "Third section" not in second and "Nothing folded here." in html
    # numbering and the page's table of contents are those of the unfolded page
    assert "Fig. 1" in html
    assert 'href="#a-subsection"' in html


def test_marker_outside_a_section_is_reported(tmp_path):
    text = PAGE.replace(
        "## Third section\n\nNothing folded here.\n",
        "## Third section\n\n:::{note}\n```{evidence}\n```\n:::\n",
    )
    app, out = build(tmp_path, text)
    assert app._warncount >= 1
    assert "navbook-evidence" in (out / "index.html").read_text()


def test_other_builders_show_the_page_unfolded(tmp_path):
    app, out = build(tmp_path, PAGE, builder="text")
    txt = (out / "index.txt").read_text()
    assert "How it was found." in txt and "More evidence." in txt and "Tuning detail." in txt
    assert "The evidence" not in txt and "How the filter was tuned" not in txt


# ------------------------------------------------------------------ book/_ext/navbook_attrdoc.py
def test_a_constant_description_split_by_napoleon_is_made_whole():
    sys.path.insert(0, str(EXT))
    try:
        from navbook_attrdoc import rejoin
    finally:
        sys.path.remove(str(EXT))
    napoleon = pytest.importorskip("sphinx.ext.napoleon")
    text = [
        "The output must change by 1000 mg per g within this factor (paper D's units: 1001.7 and",
        "1002.2 mg/g); outside it the output is in another unit.",
    ]
    lines = napoleon.NumpyDocstring(list(text), napoleon.Config(), what="data", name="X").lines()
    assert any(ln.startswith(":type: ") for ln in lines)  # napoleon splits it
    rejoin(lines)
    assert not any(ln.startswith(":type: ") for ln in lines)
    assert " ".join(" ".join(lines).split()) == " ".join(" ".join(text).split())
    plain = ["No colon on this line", "but one: on the next."]
    lines = napoleon.NumpyDocstring(list(plain), napoleon.Config(), what="data", name="X").lines()
    before = list(lines)
    rejoin(lines)
    assert lines == before
