"""The chapter's results file (:func:`write_results`: claims, method statistics, tables of records) and
its readers, for the landing page and the checks."""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any, Iterable, Mapping

import pandas as pd

from navlib import claims as registry
from navlib.claims import Claim
from navlib.data.tables import write_new
from navlib.errors import InputError
from navlib.formatting import plain

from . import claim_boxes
from .claim_boxes import register_records


#: The environment variable that says where results files go (the book's build sets it to its own folder).
RESULTS_ENV = "NAVBOOK_RESULTS_DIR"
METHOD_KEYS = ("median_rms", "p10_rms", "p90_rms", "median_min", "median_max")


def results_dir() -> Path:
    """The folder results files go to: ``$NAVBOOK_RESULTS_DIR`` if it is set and not empty, else ``results/``
    in the current directory (library use; never a folder of the installed package).  ``make test``
    sets the variable to ``book/_generated/results``; ``python -m navbook execute`` (``make book``,
    ``make notebooks``) sets it to a temporary folder for each notebook and copies the files written there
    to ``book/_generated/results`` (or ``notebooks/results``)."""
    env = os.environ.get(RESULTS_ENV)
    return Path(env) if env else Path.cwd() / "results"


def write_results(
    chapter: str,
    *,
    claims: Iterable[Claim],
    unit: str | None = None,
    methods: Mapping[str, Mapping[str, Any]] | None = None,
    extra: Mapping[str, Any] | None = None,
    folder: str | os.PathLike | None = None,
    overwrite: bool = False,
    tables: Mapping[str, Iterable[Mapping[str, Any]]] | None = None,
    register: bool = False,
    worlds: list[Mapping[str, Any]] | None = None,
) -> Path:
    """Write ``<folder>/<chapter>.json`` (``folder`` defaults to :func:`results_dir`)::

        {"chapter": ..., "unit": ..., "methods": {label: {"median_rms_<unit>", "p10_rms_<unit>",
         "p90_rms_<unit>", "median_min_<unit>", "median_max_<unit>", "n_seeds"}},
         "claims": [{"claim", "paper", "ours", "reproduced", "verdict", "reading",
                     "why"}],
         "extra": {...}}

    ``methods`` maps a display label to :func:`~navlib.claims.method_stats`-style keys (without unit suffix); the unit
    (e.g. ``deg``, ``mg``, ``arcsec``) is appended to each statistic's name.  Values are rounded to 6
    significant digits.  ``tables`` adds top-level lists of records (e.g. ``"robustness"``: one
    ``{"compass", "claim", "reading", "verdict"}`` per simulated compass, claim and reading); their names
    must not be one of the keys above.  ``register=True`` (a chapter with a claims register,
    :mod:`navlib.claims`) stores one record per register entry instead of one per claim and reading: the
    primary row's fields, the register's words and place, the other rows as its ``sensitivity`` list
    (``worlds``: the rows' verdicts on other drawn simulators, ``{"compass", "claim", "reading",
    "verdict"}``, summarised in each record's ``across``), and the paper's contradictions as
    ``inconsistencies``.  An existing file (an earlier run's) is never replaced unless
    ``overwrite=True``: the call stops with one line naming it.  Returns the path written; it displays as ``results written:
    <chapter>.json``, the same in every run, so a notebook cell that ends with this call shows no
    run-specific folder."""
    if not chapter.isidentifier():
        raise InputError(f"chapter name {chapter!r}: use letters, digits and underscores")
    out: dict[str, Any] = {"chapter": chapter}
    if methods:
        if not unit:
            raise InputError("write_results: methods need a unit (e.g. unit='deg')")
        out["unit"] = unit
        out["methods"] = {}
        for label, stats in methods.items():
            entry = {}
            for k, v in stats.items():
                key = k if k == "n_seeds" or k.endswith(f"_{unit}") else f"{k}_{unit}"
                entry[key] = plain(v)
            out["methods"][str(label)] = entry
    claims = list(claims)
    if not claims:
        raise InputError(f"write_results({chapter!r}): a chapter states at least one claim")
    if not all(isinstance(c, Claim) for c in claims):
        raise InputError(f"write_results({chapter!r}): claims must be navlib.claims.Claim objects")
    keys = [(c.claim, c.reading) for c in claims]
    both = [(c.claim, c.reading, c.data) for c in claims]
    if len(set(both)) != len(both):
        dup = next(k for k in both if both.count(k) > 1)
        raise InputError(
            f"write_results({chapter!r}): claim {dup[0]!r} appears twice under reading {dup[1]!r}"
            + (" on real data" if dup[2] == "real" else "")
        )
    records = register_records(claims, chapter if register else None, worlds)
    out["claims"] = records if records is not None else [c.record() for c in claims]
    if records is not None:
        out["inconsistencies"] = registry.inconsistencies(chapter)
    unseen = [k for k in both if k not in claim_boxes._GLANCED]
    if (
        claim_boxes._GLANCED and unseen
    ):  # a chapter that shows a glance box, but not all of its claims
        warnings.warn(
            f"write_results({chapter!r}): {len(unseen)} of the {len(keys)} claims are in no glance "
            f"box (first: {unseen[0][0]!r}, {unseen[0][1]!r}); the landing page counts every claim "
            f"written: pass them all to report.glance",
            stacklevel=2,
        )
    if extra:
        out["extra"] = {
            str(k): plain(v) if not isinstance(v, (list, tuple)) else [plain(x) for x in v]
            for k, v in extra.items()
        }
    for name, table_rows in (tables or {}).items():
        if (
            name in ("chapter", "unit", "methods", "claims", "extra", "inconsistencies")
            or not str(name).isidentifier()
        ):
            raise InputError(
                f"write_results({chapter!r}): table name {name!r} is reserved or not an identifier"
            )
        out[str(name)] = [{str(k): plain(v) for k, v in dict(r).items()} for r in table_rows]
    d = Path(folder) if folder is not None else results_dir()
    text = json.dumps(out, indent=1, ensure_ascii=False, allow_nan=False) + "\n"
    path = d / f"{chapter}.json"
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InputError(f"{d}: cannot create the results folder ({err.strerror})") from None
    try:
        write_new(
            path,
            lambda fh: fh.write(text),
            overwrite=overwrite,
            exists=f"a results file is already there (an earlier run's); remove it, write elsewhere "
            f"(folder=... or ${RESULTS_ENV}) or pass overwrite=True",
        )
    except OSError as err:
        raise InputError(f"{path}: cannot write the results file ({err.strerror})") from None
    return _WrittenPath(path)


class _WrittenPath(type(Path())):
    """A :class:`pathlib.Path` whose display names only the file (stable across runs and machines)."""

    def __repr__(self) -> str:
        return f"results written: {self.name}"


def read_results(folder: str | os.PathLike | None = None) -> dict[str, dict]:
    """Every results file in ``folder`` (default :func:`results_dir`), keyed by chapter."""
    d = Path(folder) if folder is not None else results_dir()
    out = {}
    for p in sorted(d.glob("*.json")):
        try:
            out[p.stem] = json.loads(p.read_text(encoding="utf-8"))
        except json.JSONDecodeError as err:
            raise InputError(f"{p.name}: not valid JSON ({err.msg}, line {err.lineno})") from None
    return out


def read_result(path: str | os.PathLike) -> dict:
    """One results file (:func:`write_results`), e.g. to build a chapter's tables from what it wrote."""
    p = Path(path)
    try:
        return json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{p}: no results file there") from None
    except json.JSONDecodeError as err:
        raise InputError(f"{p.name}: not valid JSON ({err.msg}, line {err.lineno})") from None


def claims_summary(results: Mapping[str, dict]) -> pd.DataFrame:
    """Per chapter, source (the paper's claims or the book's own), data (``simulated`` or ``real``: the
    claims judged on real measurements apart) and reading: claims reproduced, not reproduced, cannot be
    judged (for the landing page)."""
    rows = []
    for chapter, res in results.items():
        for c in res.get("claims", []):
            rows.append(
                {
                    "chapter": chapter,
                    "source": c.get("source", "paper"),
                    "data": registry.data_of(c),
                    "reading": c.get("reading", "as printed"),
                    "reproduced": c.get("reproduced"),
                }
            )
    cols = [
        "chapter",
        "source",
        "data",
        "reading",
        "claims",
        "reproduced",
        "not reproduced",
        "cannot be judged",
    ]
    if not rows:
        return pd.DataFrame(columns=cols)
    df = pd.DataFrame(rows)
    g = df.groupby(["chapter", "source", "data", "reading"], sort=False)["reproduced"]
    return pd.DataFrame(
        {
            "claims": g.size(),
            "reproduced": g.apply(lambda s: int((s == True).sum())),  # noqa: E712
            "not reproduced": g.apply(lambda s: int((s == False).sum())),  # noqa: E712
            "cannot be judged": g.apply(lambda s: int(s.isna().sum())),
        }
    ).reset_index()[cols]
