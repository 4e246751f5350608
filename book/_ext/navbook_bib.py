"""Sphinx extension of the book: bibliography labels in author-year form ("Yu et al., 2012").

sphinxcontrib-bibtex cites author-year in the text (``bibtex_reference_style: author_year``) but labels
the reference list with pybtex's default "alpha" labels (``[YZSXd.]``).  The pybtex style ``navbook``
registered here is pybtex's plain style with author-year labels: the last name of a single author, "A and
B" for two, "A et al." for more, then the year ("n.d." when the source has none); a letter is appended
where two works would share a label.
"""
from collections import Counter

from pybtex.plugin import register_plugin
from pybtex.style.formatting.plain import Style as PlainStyle
from pybtex.style.labels import BaseLabelStyle


def _last(person) -> str:
    return " ".join(person.last_names).replace("{", "").replace("}", "")


def author_year(entry) -> str:
    persons = entry.persons.get("author") or entry.persons.get("editor") or []
    if not persons:
        name = entry.key
    elif len(persons) == 1:
        name = _last(persons[0])
    elif len(persons) == 2 and not any(p.last_names == ["others"] for p in persons):
        name = f"{_last(persons[0])} and {_last(persons[1])}"
    else:
        name = f"{_last(persons[0])} et al."
    return f"{name}, {entry.fields.get('year', 'n.d.')}"


class AuthorYearLabelStyle(BaseLabelStyle):
    def format_labels(self, sorted_entries):
        labels = [author_year(e) for e in sorted_entries]
        counts, seen = Counter(labels), Counter()
        for label in labels:
            if counts[label] > 1:
                seen[label] += 1
                yield f"{label}{chr(ord('a') + seen[label] - 1)}"
            else:
                yield label


class NavbookStyle(PlainStyle):
    default_label_style = AuthorYearLabelStyle


register_plugin("pybtex.style.formatting", "navbook", NavbookStyle)


def setup(app):
    return {"parallel_read_safe": True, "parallel_write_safe": True}
