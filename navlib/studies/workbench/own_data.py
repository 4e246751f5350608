"""The chapter's "Bring your own data": per system the columns its loader reads, the first rows of a sample
file, the one command that runs the loop on it, and the report that command writes.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ...errors import InputError, check_param
from ...paths import DATA_DIR, ROOT
from ...workbench.effects import columns_table
from ...workbench.fit import load
from ...workbench.loop import loop, write_report
from .parameters import OWN_DATA_COMMAND_OPTIONS, OWN_DATA_FILES, SAMPLE_ROWS


@dataclass
class OwnData:
    """One system's part of "Bring your own data": the columns its loader reads (``columns``,
    :func:`navlib.workbench.effects.columns_table`), the first rows of a sample file (``sample``: one
    row per column of the schema the file holds, one column per row of the file, the cells as written; None
    where the file is absent), the file as a path relative to the repository's folder (``file``) and the
    command that runs the loop on it with a report (``command``)."""

    system: str
    columns: pd.DataFrame
    sample: pd.DataFrame | None
    file: str
    command: str


def _shown_path(path: Path) -> str:
    """A sample file as the reader types it from the repository's folder: ``data/NAME`` for a shipped
    file, ``../shared/realdata/...`` for the third-party recordings."""
    if path.parent == DATA_DIR:
        return f"data/{path.name}"
    try:
        return str(Path("..") / path.relative_to(ROOT.parent))
    except ValueError:
        return str(path)


def shell_command(words, width: int = 80) -> str:
    """``words`` as one shell command, continued with a backslash onto indented lines where a line would
    pass ``width`` characters (a command shown in the book stays within the column)."""
    lines, line = [], ""
    for w in words:
        if line and len(line) + 1 + len(w) > width:
            lines.append(line + " \\")
            line = "    " + w
        else:
            line = f"{line} {w}" if line else w
    return "\n".join(lines + [line])


def wrap_report(text: str, width: int = 88) -> str:
    """A report's text with lines longer than ``width`` wrapped (tables and short lines as written)."""
    return "\n".join(
        textwrap.fill(ln, width) if len(ln) > width and not ln.startswith("|") else ln
        for ln in text.splitlines()
    )


def own_data(system: str, rows: int = SAMPLE_ROWS) -> OwnData:
    """The columns table, ``rows`` sample rows of ``OWN_DATA_FILES`` and the one command
    (``navlib loop SYSTEM FILE --report DIR``) for ``system`` on the sample file, with the options of
    :data:`~navlib.studies.workbench.parameters.OWN_DATA_COMMAND_OPTIONS` it needs."""
    check_param("rows", rows, lo=1, integer=True)
    if system not in OWN_DATA_FILES:
        raise InputError(f"parameter system={system!r}: one of {', '.join(OWN_DATA_FILES)}")
    path = OWN_DATA_FILES[system]
    cols = columns_table(system)
    sample = None
    if path.is_file():
        head = pd.read_csv(path, nrows=rows, dtype=str, keep_default_na=False)
        names = [c for c in cols["column"] if c in head.columns]
        sample = head[names].T
        sample.columns = [f"row {i + 1}" for i in range(len(head))]
        sample.index.name = "column"
    shown = _shown_path(path)
    return OwnData(
        system,
        cols,
        sample,
        shown,
        shell_command(
            [
                "navlib",
                "loop",
                system,
                shown,
                *OWN_DATA_COMMAND_OPTIONS.get(system, []),
                "--report",
                f"out_{system}/",
            ]
        ),
    )


def own_data_report(folder, system: str = "compass", start_model=()) -> tuple[Path, Path]:
    """What ``navlib loop SYSTEM FILE --report FOLDER`` writes for the sample file of ``system``
    (``OWN_DATA_FILES``): the system's loader, :func:`navlib.workbench.loop.loop` from ``start_model``
    and the CLI's own :func:`navlib.workbench.loop.write_report` (never over existing files).  Returns the
    paths of ``loop.png`` and ``loop.md``."""
    path = OWN_DATA_FILES[system]
    result = loop(system, load(system, path), list(start_model))
    return write_report(result, folder, source=_shown_path(path))
