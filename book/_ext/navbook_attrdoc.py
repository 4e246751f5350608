"""Sphinx extension of the book: a module constant's description stays whole on the API pages.

napoleon reads the first line of a data or attribute docstring as ``type: description``: it splits the
line at its first colon, keeps the part after it as the description and emits the part before it as a
``:type:`` field.  A ``#:`` comment such as "(paper D's units: 1001.7 and 1002.2 mg/g)" then showed half a
sentence under "Type:".  navlib's doc comments are prose, never ``type: text``, so after napoleon has run
(``autodoc-process-docstring`` at a lower priority than napoleon's) such a split is undone: the ``:type:``
field goes and its text is put back in front of the first line with its colon.
"""
from __future__ import annotations

#: Runs after napoleon's handler (connected at Sphinx's default priority, 500).
PRIORITY = 600


def rejoin(lines: list[str]) -> None:
    """Undo napoleon's ``type: description`` split of a data, attribute or property docstring's first line."""
    fields = [i for i, ln in enumerate(lines) if ln.startswith(":type: ")]
    if len(fields) != 1 or not lines:
        return
    i = fields[0]
    before = lines[i][len(":type: "):].strip()
    del lines[i]
    while i > 0 and i - 1 < len(lines) and not lines[i - 1].strip():
        del lines[i - 1]
        i -= 1
    first = next((k for k, ln in enumerate(lines) if ln.strip()), None)
    if first is None:
        lines.append(before)
    else:
        lines[first] = f"{before}: {lines[first].lstrip()}"


def keep_whole(app, what, name, obj, options, lines):
    if what in ("data", "attribute", "property"):
        rejoin(lines)


def setup(app):
    app.connect("autodoc-process-docstring", keep_whole, priority=PRIORITY)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
