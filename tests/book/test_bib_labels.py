"""The references page's author-year labels (book/_ext/navbook_bib.py)."""

import sys

from pybtex.database import Entry, Person

from navlib.paths import ROOT

sys.path.insert(0, str(ROOT / "book" / "_ext"))
import navbook_bib  # noqa: E402


def entry(authors, year=None):
    e = Entry("article", fields={"year": year} if year else {})
    for a in authors:
        e.add_person(Person(a), "author")
    return e


def test_author_year_labels():
    assert navbook_bib.author_year(entry(["Marquardt, Donald W."], "1963")) == "Marquardt, 1963"
    assert (
        navbook_bib.author_year(entry(["Nguyen, Derrick", "Widrow, Bernard"], "1990"))
        == "Nguyen and Widrow, 1990"
    )
    assert (
        navbook_bib.author_year(entry(["Yu, X.", "Wei, X.", "Li, Y."], "2012")) == "Yu et al., 2012"
    )
    assert navbook_bib.author_year(entry(["Sun, Hongchi", "others"], "2019")) == "Sun et al., 2019"
    assert navbook_bib.author_year(entry(["Yue, Hai-bo"])) == "Yue, n.d."


def test_equal_labels_get_letters():
    style = navbook_bib.AuthorYearLabelStyle()
    labels = list(
        style.format_labels(
            [
                entry(["Fu, H.", "Wen, Y.", "Miao, F."]),
                entry(["Fu, H.", "Li, Q.", "Wu, Z."]),
                entry(["Li, X."], "2002"),
            ]
        )
    )
    assert labels == ["Fu et al., n.d.a", "Fu et al., n.d.b", "Li, 2002"]
