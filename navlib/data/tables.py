"""Reading measurement tables (CSV) with validation that names the file, column and row of every fault.

A table is described by a list of :class:`Column` specs.  :func:`read_table` returns a
``pandas.DataFrame`` holding the described columns as floats (plus any extra columns as text, untouched)
or raises :class:`navlib.errors.InputError` with a single line such as::

    sweep.csv: column 'true_heading_deg', row 7 (file line 8): 'abc' is not a number

Rows are counted from 1 over the data rows; the file line is the line of the file the row starts on (the
header line, blank lines and quoted line breaks counted).

The header is read here, not by pandas (which renames a repeated name ``a`` to ``a.1`` and so hides it):
a name that appears twice is refused.  The file is decoded as UTF-8 (a byte-order mark is skipped, UTF-16
with a byte-order mark is read too); bytes that are not UTF-8 text are kept, and only refused where they
sit in a cell of a described column.  Columns the table does not describe are never checked: a NaN, text
or a stray byte there does not stop the reading.
"""

from __future__ import annotations

import csv
import difflib
import io
import os
import re
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, TextIO

import numpy as np
import pandas as pd

from ..errors import InputError

#: Default limit of a checked column without its own range: ``|x| <= LIMIT``.  No quantity in navlib's
#: files comes near it in its unit, and squares and sums of values within it cannot overflow a float.
LIMIT = 1e12

_FLOAT_MAX = float(np.finfo(float).max)
_BAD_BYTES = re.compile("[\udc80-\udcff]")  # bytes that were not UTF-8 (kept by surrogateescape)


@dataclass(frozen=True)
class Column:
    """One column of a table: its name, unit (for messages and the data dictionary), whether it must be
    present, and the closed range ``[lo, hi]`` its values must lie in (``-LIMIT..LIMIT`` where not given).

    ``checked=False`` marks an *informational* column that the table's users read if they can but no model
    relies on: its cells are converted to numbers where they parse (NaN elsewhere) and never refused.
    ``text=True`` marks a column of names (e.g. an accelerometer's ``unit``): its presence is checked when
    it is required, its cells are kept as text and checked by the loader that reads it.  ``meaning`` says
    what the column holds, for the data dictionary of each file schema
    (:func:`schema_table`)."""

    name: str
    unit: str = ""
    required: bool = True
    lo: float | None = None
    hi: float | None = None
    integer: bool = False
    checked: bool = True
    meaning: str = ""
    text: bool = False


def where(path: str | os.PathLike, column: str, row: int, frame: pd.DataFrame | None = None) -> str:
    """The location prefix used in messages: ``file: column 'c', row r (file line l)``; ``row`` is
    0-based over data rows.  The file line is ``row + 2`` (one header line) plus the blank lines and quoted
    line breaks before the row, which :func:`read_table` records in ``frame.attrs["line_jumps"]`` when a
    file has any."""
    line = row + 2
    for start, extra in frame.attrs.get("line_jumps", ()) if frame is not None else ():
        if row >= start:
            line = row + 2 + extra
    return f"{Path(path).name}: column '{column}', row {row + 1} (file line {line})"


def _jumps(lines: list[int]) -> tuple[tuple[int, int], ...]:
    """``(first row, extra lines)`` wherever the file line of a row stops being ``row + 2`` plus the
    previous extra: a short record of the blank lines and quoted line breaks (usually empty)."""
    extra = np.asarray(lines, dtype=np.int64) - (np.arange(len(lines)) + 2)
    change = np.flatnonzero(np.diff(extra, prepend=0))
    return tuple((int(r), int(extra[r])) for r in change)


def show(text: str) -> str:
    """``text`` for a one-line message: bytes that are not UTF-8 as ``\\xNN``, control characters escaped."""
    text = str(text).encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    return "".join(
        ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in text
    )


#: The most data rows a table may have: every workbench step is linear in the rows (issue 34: a calibration
#: of 30,000 rows takes about 6 s and 140 MB, a diagnosis of 30,000 rows about 25 s and 0.8 GB on 2 cores),
#: so 200,000 rows cost minutes and several GB; a larger file is refused before it is parsed.
MAX_ROWS = 200_000


def _decode(p: Path, kind: str, max_rows: int | None = MAX_ROWS) -> str:
    """The file's text.  Compressed, archived or binary files are refused by name; a file of more than
    ``max_rows`` lines after its header is refused before it is parsed; UTF-16 with a byte-order mark is
    decoded; otherwise UTF-8 (BOM skipped) with undecodable bytes kept as surrogates."""
    try:
        data = p.read_bytes()
    except OSError as err:
        raise InputError(f"{p}: cannot be read ({err.strerror or type(err).__name__})") from None
    if data[:2] == b"\x1f\x8b":
        raise InputError(
            f"{p.name}: is gzip-compressed; decompress it (gunzip) and give the CSV {kind}"
        )
    if data[:4] == b"PK\x03\x04":
        raise InputError(
            f"{p.name}: is a zip archive (an Excel workbook?); save or extract it as a CSV {kind}"
        )
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        try:
            text = data.decode("utf-16")
        except UnicodeDecodeError as err:
            raise InputError(
                f"{p.name}: starts as UTF-16 text but byte {err.start} is not UTF-16"
            ) from None
        _check_size(p, text.count("\n") + (not text.endswith("\n")) - 1, max_rows)
        return text
    nul = data.find(b"\x00")
    if nul >= 0:
        raise InputError(f"{p.name}: is a binary file (a NUL byte at byte {nul}), not a CSV {kind}")
    _check_size(p, data.count(b"\n") + (not data.endswith(b"\n")) - 1, max_rows)
    return data.decode("utf-8-sig", errors="surrogateescape")


def _check_size(p: Path, lines: int, max_rows: int | None) -> None:
    """Refuse a file of more than ``max_rows`` lines after its header (None: no limit)."""
    if max_rows is not None and lines > max_rows:
        raise InputError(
            f"{p.name}: {lines:,} lines after the header; navlib reads at most {max_rows:,} rows (the "
            f"cost of every step grows with the rows: minutes and gigabytes at that size): keep "
            f"every k-th row or split the file"
        )


def _parse(p: Path, text: str, kind: str) -> tuple[list[str], list[list[str]], list[int]]:
    """Header, data rows (each padded to the header's width) and the file line each row starts on."""
    reader = csv.reader(io.StringIO(text, newline=""), skipinitialspace=True)
    header, rows, lines = None, [], []
    last = 0  # the line the previous record ended on
    try:
        for fields in reader:
            start, last = last + 1, reader.line_num
            if not fields or (len(fields) == 1 and not fields[0].strip()):  # a blank line
                continue
            if header is None:
                header = [f.strip() for f in fields]
                continue
            if len(fields) > len(header):
                if any(f.strip() for f in fields[len(header) :]):
                    raise InputError(
                        f"{p.name}: line {start}: {len(fields)} fields, the header has "
                        f"{len(header)} (a separator inside a value? quote the value)"
                    )
                fields = fields[: len(header)]
            elif len(fields) < len(header):
                fields = fields + [""] * (len(header) - len(fields))
            rows.append(fields)
            lines.append(start)
    except csv.Error as err:
        raise InputError(
            f"{p.name}: line {reader.line_num}: not a readable CSV {kind} ({err})"
        ) from None
    if header is None:
        raise InputError(f"{p.name}: file is empty, expected a CSV {kind} with a header line")
    return header, rows, lines


def _names(p: Path, header: list[str]) -> list[str]:
    """Column names: unnamed columns become ``Unnamed: i``; a name given twice is refused."""
    names, seen = [], {}
    for i, name in enumerate(header):
        if name == "":
            names.append(f"Unnamed: {i}")
            continue
        if name in seen:
            raise InputError(
                f"{p.name}: column '{show(name)}' appears more than once in the header "
                f"(columns {seen[name] + 1} and {i + 1}); remove or rename one"
            )
        seen[name] = i
        names.append(name)
    return names


def _problem(cell: str) -> str:
    """Why a cell that did not give a finite number was refused."""
    if cell == "":
        return "is empty"
    if _BAD_BYTES.search(cell):
        return f"'{show(cell)}' is not a number (it holds bytes that are not UTF-8 text)"
    if cell.lower().lstrip("+-") in {"nan", "inf", "infinity"}:
        return f"'{show(cell)}' is not a finite number"
    try:
        value = float(cell)
    except ValueError:
        return f"'{show(cell)}' is not a number"
    if not np.isfinite(value):
        return f"'{show(cell)}' overflows a floating-point number (beyond {_FLOAT_MAX:.3g})"
    return f"'{show(cell)}' is not a number"


def _numbers(cells: pd.Series) -> np.ndarray:
    """Cells as floats (NaN where a cell is not a number; a literal beyond the float range is +-inf)."""
    return pd.to_numeric(cells, errors="coerce").to_numpy(dtype=float, na_value=np.nan)


_SEPARATORS = {";": "';'", "\t": "a tab", "|": "'|'"}


def read_table(
    path: str | os.PathLike,
    columns: list[Column],
    *,
    min_rows: int = 1,
    kind: str = "table",
    max_rows: int | None = MAX_ROWS,
) -> pd.DataFrame:
    """Read and validate a CSV table.

    Checks, in order: the file exists, is a regular file and text (not compressed, archived or binary) and parses as CSV; no
    column name appears twice in the header; every required column is present (a near-miss name, or a
    separator other than the comma, is pointed out); every value in a described (checked) column is a
    finite number (no text, empty cell, NaN, infinity or a literal that overflows a float), whole if the
    column is ``integer``, and within the column's range (``-LIMIT..LIMIT``, 1e12, where the column gives
    none); there are at least ``min_rows`` rows and, counted before parsing, at most ``max_rows`` (default
    :data:`MAX_ROWS`; None: no limit).  Optional columns that are absent are simply not in the
    result; informational columns (``checked=False``) and columns the list does not describe are not
    checked (described informational ones become floats with NaN where a cell is not a number, others stay
    text, with any byte that is not UTF-8 replaced by U+FFFD).  Where blank lines or quoted line breaks move
    rows off ``row + 2``, ``frame.attrs["line_jumps"]`` records it (see :func:`where`).
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{p}: no such file")
    if p.is_dir():
        raise InputError(f"{p}: is a folder, expected a CSV {kind}")
    if not p.is_file():  # a device or a pipe (/dev/zero would never end)
        raise InputError(f"{p}: is not a regular file, expected a CSV {kind}")
    header, rows, lines = _parse(p, _decode(p, kind, max_rows), kind)
    names = _names(p, header)
    for col in columns:
        if col.required and col.name not in names:
            near = difflib.get_close_matches(col.name, names, n=1, cutoff=0.6)
            hint = f"; did you mean to name '{show(near[0])}' '{col.name}'?" if near else ""
            sep = [w for s, w in _SEPARATORS.items() if len(names) == 1 and s in header[0]]
            if sep:
                hint += (
                    f"; the file seems to use {sep[0]} as the separator, a CSV {kind} uses commas"
                )
            found = ", ".join(show(n) for n in names)
            found = found if len(found) <= 300 else found[:300] + " ..."
            raise InputError(
                f"{p.name}: missing column '{col.name}' ({_what(col)}); found {found}{hint}"
            )
    located = pd.DataFrame(index=pd.RangeIndex(len(rows)))
    jumps = _jumps(lines)
    if jumps:
        located.attrs["line_jumps"] = jumps
    cells = dict(zip(names, map(list, zip(*rows)))) if rows else {name: [] for name in names}
    described = {col.name: col for col in columns}
    out = {}
    for name in names:
        text = [v.strip() for v in cells[name]]
        col = described.get(name)
        if col is None or col.text:  # not described or names: kept as text, never checked
            if any(_BAD_BYTES.search(v) for v in text):
                text = [
                    v.encode("utf-8", "surrogateescape").decode("utf-8", "replace") for v in text
                ]
            out[name] = pd.Series(text, dtype=str)
            continue
        values = _numbers(pd.Series(text, dtype=object))
        if col.checked:
            _check(p, col, text, values, located)
        out[name] = values
    frame = pd.DataFrame(out, index=pd.RangeIndex(len(rows)))
    if jumps:
        frame.attrs["line_jumps"] = jumps
    frame.attrs["source"] = p.name  # later messages about the data name the file
    if len(frame) < min_rows:
        raise InputError(
            f"{p.name}: {len(frame)} data row{'s' if len(frame) != 1 else ''}, "
            f"a {kind} needs at least {min_rows}"
        )
    return frame


def _what(col: Column) -> str:
    """How a missing column is described: its unit, or for a text column what it names."""
    if col.text:
        return col.meaning or "text"
    return col.unit or "no unit"


def schema_table(columns) -> pd.DataFrame:
    """A file schema as a data dictionary: one row per described column, in the order the schema lists
    them, with ``column``, ``unit`` (``-`` where it has none; ``text`` for a column of names),
    ``required`` (``yes``/``no``), ``limits`` (the closed range a checked column's values must lie in,
    ``whole`` for whole numbers; ``not checked`` for an informational column) and ``meaning``.  It is
    derived from the very :class:`Column` list a loader gives :func:`read_table`, so it lists exactly what
    the loader requires."""
    rows = []
    for c in columns:
        if c.text:
            limits = "text, not empty" if c.required else "text"
        elif not c.checked:
            limits = "not checked"
        else:
            lo = "" if c.lo is None else f"{c.lo:g}"
            hi = "" if c.hi is None else f"{c.hi:g}"
            limits = f"{lo}..{hi}" if (lo or hi) else "finite"
            if c.integer:
                limits += ", whole"
        rows.append(
            {
                "column": c.name,
                "unit": "text" if c.text else (c.unit or "-"),
                "required": "yes" if c.required else "no",
                "limits": limits,
                "meaning": c.meaning,
            }
        )
    return pd.DataFrame(rows, columns=["column", "unit", "required", "limits", "meaning"])


def _check(
    p: Path, col: Column, text: list[str], values: np.ndarray, located: pd.DataFrame
) -> None:
    """A checked column's values: finite, whole if asked, within the range."""
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        r = int(bad[0])
        raise InputError(f"{where(p, col.name, r, located)}: {_problem(text[r])}")
    if col.integer:
        frac = np.flatnonzero(values != np.round(values))
        if frac.size:
            r = int(frac[0])
            raise InputError(
                f"{where(p, col.name, r, located)}: {show(text[r])} is not a whole number"
            )
    lo = -LIMIT if col.lo is None else col.lo
    hi = LIMIT if col.hi is None else col.hi
    outside = np.flatnonzero((values < lo) | (values > hi))
    if outside.size:
        r = int(outside[0])
        unit = f" {col.unit}" if col.unit else ""
        raise InputError(
            f"{where(p, col.name, r, located)}: {show(text[r])} is outside {lo:g}..{hi:g}{unit}"
        )


def require_variation(frame: pd.DataFrame, columns, path, what: str = "the model") -> None:
    """Refuse a column that does not vary (a stuck sensor, a channel not connected, a constant written for
    a missing one): one line naming the file, the column and its value."""
    for c in columns:
        if c in frame and len(frame) > 1:
            v = frame[c].to_numpy(float)
            if np.all(v == v[0]):
                raise InputError(
                    f"{Path(path).name}: column '{c}' is {v[0]:g} in all {len(v)} rows; {what} "
                    f"needs it to vary (a stuck sensor or an unconnected channel?)"
                )


def write_new(
    path: str | os.PathLike,
    write: Callable[[TextIO], object],
    *,
    overwrite: bool = False,
    exists: str = "already exists; not overwritten",
    newline: str | None = None,
) -> Path:
    """The one overwrite rule of navlib: create ``path`` (and its folder) and let ``write(fh)`` fill it,
    never replacing an existing file unless ``overwrite`` is set; user data and earlier outputs are not
    overwritten by accident.  The check and the creation are one step (``open(path, "x")``), so no file
    that appears in between is replaced, nor one a symbolic link points to.  A ``write`` that raises (an
    error, Ctrl-C) removes the half-written file: nothing is left that looks like a complete output.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    write : callable
        Writes the content to the open text file (UTF-8) it is given.
    overwrite : bool
        Replace an existing file.
    exists : str
        What the one-line :class:`~navlib.errors.InputError` says after the path when the file exists.
    newline : str, optional
        Passed to ``open`` (``""`` for a CSV writer that ends its own lines).

    Returns
    -------
    pathlib.Path
        The path written.
    """
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    try:
        fh = open(p, "w" if overwrite else "x", encoding="utf-8", newline=newline)
    except FileExistsError:
        raise InputError(f"{p}: {exists}") from None
    try:
        with fh:
            write(fh)
    except BaseException:  # an error or Ctrl-C half-way: no file that looks complete
        p.unlink(missing_ok=True)
        raise
    return p


def write_new_csv(
    frame: pd.DataFrame,
    path: str | os.PathLike,
    *,
    overwrite: bool = False,
    float_format: str = "%.10g",
) -> Path:
    """Write ``frame`` to ``path`` but never replace an existing file unless ``overwrite`` is set
    (:func:`write_new`): user data and earlier outputs are not overwritten by accident."""
    return write_new(
        path,
        lambda fh: frame.to_csv(fh, index=False, float_format=float_format),
        overwrite=overwrite,
        newline="",
        exists="already exists; not overwritten (choose another name or pass overwrite)",
    )


class FolderClaim:
    """An output folder claimed by one writer (:func:`claim_folder`).  As a context manager: when the block
    ends normally the marker file is removed (the folder is complete); when it ends with an exception (an
    error, Ctrl-C) and nothing but the marker is in the folder, the marker and the folders the claim created
    are removed (the folder is as it was found); when something was written, the marker stays and says the
    folder is incomplete (its text: why and when), and the exception gets a note naming it, which the
    command line adds to its one line."""

    def __init__(self, folder: Path, marker: Path, created: list[Path], what: str):
        self.folder, self.marker, self.created, self.what = folder, marker, created, what
        self.before: set[str] = set()  # what the folder held when it was claimed (not ours)

    def __enter__(self) -> "FolderClaim":
        return self

    def __exit__(self, etype, err, tb) -> bool:
        if etype is None:
            self.release()
        else:
            self.abandon(err)
        return False

    def release(self) -> None:
        """The work is complete: remove the marker."""
        self.marker.unlink(missing_ok=True)

    def _remove_created(self) -> None:
        for d in reversed(self.created):
            try:
                d.rmdir()
            except OSError:  # not empty (someone else's files) or already gone
                break

    def abandon(self, err: BaseException | None = None) -> None:
        """The work stopped: leave the folder as found if nothing was written into it since the claim, else
        mark it incomplete."""
        try:
            written = [
                p for p in self.folder.iterdir() if p != self.marker and p.name not in self.before
            ]
        except OSError:
            return
        if not written:
            self.marker.unlink(missing_ok=True)
            self._remove_created()
            return
        why = (
            "interrupted (Ctrl-C)"
            if isinstance(err, KeyboardInterrupt)
            else f"stopped by an error ({type(err).__name__}: {' '.join(str(err).split())[:200]})"
            if err is not None
            else "stopped"
        )
        when = pd.Timestamp.now().isoformat(timespec="seconds")
        try:
            self.marker.write_text(
                f"{self.what}: {why} at {when}.  This folder is INCOMPLETE: what is here was "
                f"written before it stopped, and what marks a complete run is missing.\n",
                encoding="utf-8",
            )
        except OSError:
            return
        if err is not None:
            err.add_note(f"{self.folder} is incomplete ({self.marker.name} says so)")


def claim_folder(
    folder: str | os.PathLike, marker: str, *, what: str, label: str, empty: bool
) -> FolderClaim:
    """Claim the output folder ``folder`` for one writer before any work is done (the rule of
    :func:`write_new` for a folder of outputs).

    The folder is created where missing (its missing parents too); an existing one must be a folder and,
    with ``empty``, hold nothing.  Then the marker file ``folder/marker`` is created with ``O_CREAT |
    O_EXCL``: of two writers that reach this point together only one succeeds; the other gets a one-line
    :class:`~navlib.errors.InputError` (``label`` and the folder: another run is writing there) before it has
    written anything.  The marker holds ``what``, the process id and the start time while the work runs
    (:class:`FolderClaim` removes it at the end, or leaves it saying the folder is incomplete).

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder.
    marker : str
        The marker's file name inside ``folder`` (e.g. ``"grid.incomplete"``).
    what : str
        Who writes (``"navbook grid"``), for the marker's text.
    label : str
        What the user gave (``"grid --out"``), the start of every message.
    empty : bool
        Require an existing folder to be empty.

    Returns
    -------
    FolderClaim
        Use it as a context manager around the work.
    """
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{label} {folder}: is a file, not a folder")
    missing = []
    p = folder
    while not p.exists() and p != p.parent:
        missing.append(p)
        p = p.parent
    created: list[Path] = []
    claim = FolderClaim(folder, folder / marker, created, what)
    for d in reversed(missing):
        try:
            d.mkdir()
            created.append(d)
        except FileExistsError:  # another writer made it in between: the marker decides
            pass
        except OSError as err:
            claim._remove_created()
            raise InputError(
                f"{label} {folder}: cannot create the folder ({err.strerror or err})"
            ) from None
    if not folder.is_dir():
        claim._remove_created()
        raise InputError(f"{label} {folder}: is a file, not a folder")
    if claim.marker.exists():
        raise InputError(
            f"{label} {folder}: another run is writing there ({marker} exists; if no run is, the "
            f"folder is incomplete: choose another)"
        )
    if empty and any(folder.iterdir()):
        claim._remove_created()
        raise InputError(
            f"{label} {folder}: the folder is not empty (outputs go only into a new or empty folder, "
            f"never over earlier outputs)"
        )
    try:
        fd = os.open(claim.marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    except FileExistsError:
        raise InputError(
            f"{label} {folder}: another run is writing there ({marker} exists; if no run is, the "
            f"folder is incomplete: choose another)"
        ) from None
    except OSError as err:
        claim._remove_created()
        raise InputError(f"{label} {folder}: cannot write there ({err.strerror or err})") from None
    claim.before = {p.name for p in folder.iterdir()} - {marker}
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(
            f"{what} is writing this folder (process {os.getpid()}, started "
            f"{pd.Timestamp.now().isoformat(timespec='seconds')}); it is complete once this file is gone.\n"
        )
    return claim


def staging_folder(target: str | os.PathLike) -> Path:
    """A new, empty, hidden folder beside ``target`` (in its parent when ``target`` does not exist, else
    inside it: on the same file system either way) to write outputs into before :func:`publish` moves them
    into ``target`` at once.  The caller removes it when done (``shutil.rmtree``)."""
    target = Path(target)
    if target.exists() and not target.is_dir():
        raise InputError(f"{target}: is a file, not a folder")
    where = target if target.is_dir() else target.parent
    where.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=f".{target.name}.partial-", dir=where))


def _place(src: Path, dst: Path) -> None:
    """``src`` at ``dst``, never over an existing file: a hard link, or a copy where links are not allowed."""
    try:
        os.link(src, dst)
    except FileExistsError:
        raise
    except OSError:  # no hard links here (some network file systems)
        with open(src, "rb") as fin, open(dst, "xb") as fout:
            shutil.copyfileobj(fin, fout)


def publish(staging: str | os.PathLike, target: str | os.PathLike) -> dict[Path, Path]:
    """Move the finished outputs in ``staging`` (:func:`staging_folder`) into ``target``, all or none, never
    over an existing file.  A missing ``target`` is the staging folder renamed (one atomic step); into an
    existing one each file is linked in place (an existing file there stops it: the files placed so far and
    the folders made for them are removed again, and a one-line InputError names the file).  Returns
    ``{staging file: its path in target}``."""
    staging, target = Path(staging), Path(target)
    files = sorted(p for p in staging.rglob("*") if p.is_file())
    where = {p: target / p.relative_to(staging) for p in files}
    if not target.exists():
        try:
            os.rename(staging, target)
            return where
        except OSError:  # it appeared meanwhile: placed file by file below
            pass
    placed: list[Path] = []
    made: list[Path] = []
    try:
        for src, dst in where.items():
            missing = []
            d = dst.parent
            while not d.exists():
                missing.append(d)
                d = d.parent
            for m in reversed(missing):
                m.mkdir()
                made.append(m)
            _place(src, dst)
            placed.append(dst)
    except BaseException as err:
        for p in placed:
            p.unlink(missing_ok=True)
        for m in reversed(made):
            try:
                m.rmdir()
            except OSError:
                pass
        if isinstance(err, FileExistsError):
            raise InputError(
                f"{dst}: already exists; not overwritten (choose another folder); nothing written"
            ) from None
        raise
    return where
