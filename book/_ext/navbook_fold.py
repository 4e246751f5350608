"""Sphinx extension of the book: a section's evidence behind one fold, under its summary.

A chapter section opens with its finding in a paragraph or two (the summary, prose glued from the
results); a line holding only

    ```{evidence}
    ```

ends the summary.  Everything after it up to the end of the section (text, figures, tables, code cells and
subsections) is shown in the HTML as one closed fold, ``<details class="navbook-evidence">``, whose label
counts what it holds ("The evidence: 3 figures, 2 tables"; an argument replaces the words "The evidence").
A chapter then reads as its opening, then one summary per section, and a reader opens the evidence they
want.

The wrapping is done when a page is written (``doctree-resolved``), after figure numbers, the page's table
of contents and cross-references are settled: numbering and links are those of the unfolded page (a
browser opens a fold when a link or a search lands inside it).  Other builders drop the marker and show
the page unfolded.  A marker that is not directly in a section is an error naming the page.
"""
from __future__ import annotations

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

LOG = logging.getLogger(__name__)
DEFAULT_LABEL = "The evidence"


class evidence_marker(nodes.Element):
    """Where a section's summary ends (removed when the page is written)."""


class evidence_fold(nodes.Element):
    """The rest of a section, shown as one closed ``<details>`` (HTML only)."""


class EvidenceDirective(SphinxDirective):
    """``{evidence}``: the section's summary ends here; the rest of the section goes behind one fold."""

    optional_arguments = 1
    final_argument_whitespace = True
    has_content = False
    option_spec = {"open": directives.flag}

    def run(self):
        node = evidence_marker()
        node["label"] = self.arguments[0].strip() if self.arguments else DEFAULT_LABEL
        node["open"] = "open" in self.options
        self.set_source_info(node)
        return [node]


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def fold_label(fold: nodes.Element, label: str) -> str:
    """The fold's label: ``label`` and what the fold holds (figures, tables, code cells, subsections)."""
    figures = sum(1 for _ in fold.findall(nodes.figure))
    figures += sum(1 for n in fold.findall(nodes.container)
                   if "cell_output" in n.get("classes", ()) and any(True for _ in n.findall(nodes.image))
                   and not any(True for _ in n.findall(nodes.figure)))
    tables = sum(1 for _ in fold.findall(nodes.table))
    tables += sum(1 for n in fold.findall(nodes.raw) if "<table" in n.astext())
    sections = sum(1 for _ in fold.findall(nodes.section))
    parts = [_plural(figures, "figure") if figures else "", _plural(tables, "table") if tables else "",
             _plural(sections, "subsection") if sections else ""]
    parts = [p for p in parts if p]
    return f"{label}: {', '.join(parts)}" if parts else label


def wrap_evidence(app, doctree, docname):
    """Move every node after each ``{evidence}`` marker, up to the end of its section, into a fold."""
    html = app.builder.format == "html"
    for marker in list(doctree.findall(evidence_marker)):
        parent = marker.parent
        if not isinstance(parent, nodes.section):
            LOG.warning("%s: an {evidence} marker must stand directly in a section (not inside %s)",
                        docname, type(parent).__name__, location=marker)
            parent.remove(marker)
            continue
        at = parent.index(marker)
        rest = parent.children[at + 1:]
        parent.remove(marker)
        if not html or not rest:
            continue
        for child in rest:
            parent.remove(child)
        fold = evidence_fold()
        fold["open"] = marker["open"]
        fold.extend(rest)
        fold["label"] = fold_label(fold, marker["label"])
        parent.append(fold)


def visit_fold_html(self, node):
    opened = " open" if node["open"] else ""
    self.body.append(f'<details class="navbook-evidence"{opened}>'
                     f'<summary>{self.encode(node["label"])}</summary>\n<div class="navbook-evidence-body">\n')


def depart_fold_html(self, node):
    self.body.append("</div>\n</details>\n")


def _skip(self, node):
    raise nodes.SkipNode


def setup(app):
    app.add_node(evidence_marker, html=(_skip, None), latex=(_skip, None), text=(_skip, None))
    app.add_node(evidence_fold, html=(visit_fold_html, depart_fold_html))
    app.add_directive("evidence", EvidenceDirective)
    app.connect("doctree-resolved", wrap_evidence)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
