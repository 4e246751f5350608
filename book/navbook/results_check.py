"""Check the chapters' results files (``python -m navbook check-results``): each file's schema, every
stored verdict against the one rule, and a fresh run against the committed reference.

``check-results --fresh DIR --reference DIR NOTEBOOK...``
    Compare the results files a fresh run wrote with the committed references, within tolerance.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from navlib import claims as claims_mod
from navlib import verdicts
from navlib.errors import InputError

from .execute import results_chapter

#: Tolerances of ``check-results`` (a number passes if ``|fresh - ref| <= ATOL + RTOL * |ref|``).
RTOL = 1e-3
ATOL = 1e-9


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


CLAIM_TEXT_KEYS = ("claim", "paper", "ours", "reading")


def claim_problems(c: dict) -> list[str]:
    """Schema problems of one stored claim, and whether its verdict follows from its interval, boundary,
    side, noise floor and by-construction flag by the one rule (:func:`navlib.verdicts.decide`): a
    verdict set by hand fails here."""
    p = []
    for k in CLAIM_TEXT_KEYS:
        if not isinstance(c.get(k), str) or not c.get(k).strip():
            p.append(f"{k} missing or empty")
    if c.get("source") not in verdicts.SOURCES:
        p.append(f"source {c.get('source')!r}: must be 'paper' or 'book'")
    if "data" in c and c["data"] not in verdicts.DATA:  # files written before the field have none
        p.append(f"data {c.get('data')!r}: must be 'simulated' or 'real'")
    rule = c.get("rule")
    if rule not in verdicts.RULES:
        p.append(f"rule {rule!r}: must be one of {sorted(verdicts.RULES)}")
    interval, boundary, side = c.get("interval"), c.get("boundary"), c.get("holds_when")
    if rule == "no statistic":
        if interval is not None:
            p.append("rule 'no statistic' with an interval")
    else:
        if not (
            isinstance(interval, list)
            and len(interval) == 2
            and all(_is_num(v) for v in interval)
            and interval[0] <= interval[1]
        ):
            p.append(f"interval {interval!r}: must be [lo, hi] with lo <= hi")
            interval = None
        if not _is_num(boundary):
            p.append(f"boundary {boundary!r}: must be a number")
            boundary = None
        if side not in verdicts.SIDES:
            p.append(f"holds_when {side!r}: must be 'above' or 'below'")
            side = None
        est = c.get("estimate")
        if not _is_num(est):
            p.append(f"estimate {est!r}: must be a number")
        elif interval is not None and not (
            interval[0] - 1e-12 * abs(est) <= est <= interval[1] + 1e-12 * abs(est)
        ):
            p.append(f"estimate {est} lies outside its interval {interval}")
        if not isinstance(c.get("statistic"), str) or not c["statistic"].strip():
            p.append("statistic missing: say what the interval is of, with its unit")
    floor = c.get("floor")
    floor_value = None
    if floor is not None:
        fi = floor.get("interval") if isinstance(floor, dict) else None
        if not (
            isinstance(floor, dict)
            and _is_num(floor.get("value"))
            and all(
                isinstance(floor.get(k), str) and floor[k].strip() for k in ("assumption", "needs")
            )
        ):
            p.append("floor must be null or {value, interval, assumption, needs}")
        elif fi is not None and not (
            isinstance(fi, list)
            and len(fi) == 2
            and all(_is_num(v) for v in fi)
            and fi[0] <= floor["value"] <= fi[1]
        ):
            p.append(f"floor interval {fi!r}: must be [lo, hi] around the floor's value")
        else:
            floor_value = tuple(fi) if fi is not None else floor["value"]
    if not isinstance(c.get("volatile", False), bool):
        p.append("volatile must be true or false")
    if not isinstance(c.get("by_construction"), bool):
        p.append("by_construction must be true or false")
    dec = c.get("decided_by")
    if not (isinstance(dec, list) and all(isinstance(d, str) and d.strip() for d in dec)):
        p.append("decided_by must be a list of texts (possibly empty)")
    if "reproduced" not in c or c["reproduced"] not in (True, False, None):
        p.append("reproduced must be true, false or null")
    elif not p:
        try:
            margin = c.get("margin")
            if margin is not None and not _is_num(margin):
                return p + [f"margin {margin!r}: a number or null"]
            want, basis = verdicts.decide(
                interval, boundary, side, floor_value, c["by_construction"], margin
            )
        except InputError as err:
            return p + [str(err)]
        if c["reproduced"] is not want:
            p.append(
                f"verdict {c.get('verdict')!r} does not follow from interval {interval}, boundary "
                f"{boundary} ({side}), floor {floor_value}, margin {margin}: the rule gives "
                f"{verdicts.verdict_name(want, basis)!r}"
            )
        if c.get("verdict") != verdicts.verdict_name(c["reproduced"], c.get("basis")):
            p.append(f"verdict {c.get('verdict')!r} disagrees with reproduced={c['reproduced']}")
        if c.get("basis") != basis:
            p.append(f"basis {c.get('basis')!r}, the rule gives {basis!r}")
        elif "reason" in c:  # files written before the field have none
            want_reason = verdicts.reason_category(basis, c.get("why") or "")
            if c["reason"] != want_reason:
                p.append(
                    f"reason {c['reason']!r}, the basis {basis!r} and the why give {want_reason!r}"
                )
    if c.get("reproduced") is None and not (isinstance(c.get("why"), str) and c["why"].strip()):
        p.append("cannot be judged without a why")
    return p


REGISTER_KEYS = ("id", "quote", "where", "primary_reading")


def register_problems(c: dict) -> list[str]:
    """Problems of a claims-register record (one with ``sensitivity``, :func:`navlib.claims.evaluate`):
    the register's fields present (a paper's claim needs its words, where they are and the primary
    reading), a list of sensitivity records, a status the register knows."""
    if "sensitivity" not in c:
        return []
    p = []
    for k in REGISTER_KEYS:
        if not (isinstance(c.get(k), str) and c[k].strip()) and not (
            k == "quote" and c.get("source") == "book"
        ):
            p.append(f"{k} missing or empty (the claims register)")
    if not isinstance(c.get("sensitivity"), list):
        p.append("sensitivity must be a list of claim records")
    if c.get("status") not in ("judged", "open", "not checkable"):
        p.append(f"status {c.get('status')!r}: judged, open or not checkable")
    elif (c["status"] == "judged") == (
        c.get("rule") == "no statistic" and c.get("reason") in ("not yet computed", "not checkable")
    ) or (c.get("reason") == "not run" and c["status"] != "judged"):
        p.append(f"status {c['status']!r} disagrees with its reason {c.get('reason')!r}")
    return p


def flat_claims(res: dict) -> list[dict]:
    """Every judged row of a results file: each claim record and its sensitivity records."""
    out = []
    for c in res.get("claims") or []:
        out.append(c)
        out.extend(c.get("sensitivity") or [])
    return out


def validate_results(res: dict, name: str) -> list[str]:
    """Schema problems of one results file (see ``navbook.report.write_results``)."""
    p = []
    if not isinstance(res, dict):
        return [f"{name}: not a JSON object"]
    if res.get("chapter") != Path(name).stem:
        p.append(f"{name}: 'chapter' is {res.get('chapter')!r}, expected {Path(name).stem!r}")
    claims = res.get("claims")
    if not isinstance(claims, list) or not claims:
        p.append(f"{name}: 'claims' must be a non-empty list")
        claims = []
    for i, c in enumerate(claims):
        if not isinstance(c, dict):
            p.append(f"{name}: claims[{i}] is not an object")
            continue
        p += [
            f"{name}: claims[{i}] ({c.get('claim')!r}, {c.get('reading')}): {q}"
            for q in claim_problems(c) + register_problems(c)
        ]
        for j, s in enumerate(c.get("sensitivity") or []):
            p += [
                f"{name}: claims[{i}].sensitivity[{j}] ({s.get('claim')!r}, {s.get('reading')}): {q}"
                for q in (claim_problems(s) if isinstance(s, dict) else ["not an object"])
            ]
    methods = res.get("methods")
    if methods is not None:
        unit = res.get("unit")
        if not isinstance(unit, str) or not unit:
            p.append(f"{name}: 'methods' given without a 'unit'")
            unit = "?"
        if not isinstance(methods, dict) or not methods:
            p.append(f"{name}: 'methods' must be a non-empty object")
            methods = {}
        required = [f"{k}_{unit}" for k in ("median_rms", "p10_rms", "p90_rms")] + ["n_seeds"]
        optional = {f"median_min_{unit}", f"median_max_{unit}"}
        for label, stats in methods.items():
            if not isinstance(stats, dict):
                p.append(f"{name}: methods[{label!r}] is not an object")
                continue
            for k in required:
                if k not in stats:
                    p.append(f"{name}: methods[{label!r}] lacks {k!r}")
            for k, v in stats.items():
                if k not in required and k not in optional:
                    p.append(f"{name}: methods[{label!r}] has an unknown key {k!r}")
                elif k == "n_seeds" and not (
                    isinstance(v, int) and not isinstance(v, bool) and v > 0
                ):
                    p.append(f"{name}: methods[{label!r}].n_seeds must be a positive integer")
                elif k != "n_seeds" and not (v is None or _is_num(v)):
                    p.append(f"{name}: methods[{label!r}].{k} must be a number or null")
    return p


def _close(a, b, rtol: float, atol: float) -> bool:
    if a is None or b is None:
        return a is b
    if not (math.isfinite(a) and math.isfinite(b)):
        return a == b
    return abs(a - b) <= atol + rtol * abs(b)


def compare_results(
    fresh: dict, ref: dict, name: str, rtol: float = RTOL, atol: float = ATOL
) -> list[str]:
    """Differences between a fresh results file and its committed reference: the same methods and
    statistics (numbers within ``atol + rtol * |reference|``, seed counts equal), the same claims (texts,
    source, rule, side) with the same verdicts, estimates, intervals and boundaries (within the same
    tolerance; a ``volatile`` claim, a timing, is compared on its verdict, texts and boundary only), the
    same top-level tables of records (``write_results(tables=...)``, compared exactly), and the same
    ``extra`` keys (their values are free-form, timings among them, and are not compared)."""
    p = []
    fm, rm = fresh.get("methods") or {}, ref.get("methods") or {}
    if fresh.get("unit") != ref.get("unit"):
        p.append(f"{name}: unit {fresh.get('unit')!r}, reference {ref.get('unit')!r}")
    if set(fm) != set(rm):
        p.append(f"{name}: methods {sorted(fm)} differ from the reference's {sorted(rm)}")
    for label in sorted(set(fm) & set(rm)):
        for k in sorted(set(fm[label]) | set(rm[label])):
            a, b = fm[label].get(k, "missing"), rm[label].get(k, "missing")
            if k == "n_seeds" or not (_is_num(a) or a is None) or not (_is_num(b) or b is None):
                ok = a == b
            else:
                ok = _close(a, b, rtol, atol)
            if not ok:
                p.append(
                    f"{name}: methods[{label!r}].{k} = {a}, reference {b} "
                    f"(tolerance {rtol:g} relative + {atol:g})"
                )
    fc, rc = flat_claims(fresh), flat_claims(ref)

    def ids_of(res):  # a record judged on real data is its entry's id marked "(real)"
        return [
            c.get("id") if claims_mod.data_of(c) == "simulated" else f"{c.get('id')} (real)"
            for c in res.get("claims") or []
        ]

    ids = ids_of(fresh), ids_of(ref)
    if ids[0] != ids[1]:
        p.append(f"{name}: claim ids {ids[0]} differ from the reference's {ids[1]}")
    if len(fc) != len(rc):
        p.append(f"{name}: {len(fc)} claims, reference {len(rc)}")
    for i, (a, b) in enumerate(zip(fc, rc)):
        for k in ("claim", "reading", "paper", "source", "rule", "holds_when", "by_construction"):
            if a.get(k) != b.get(k):
                p.append(
                    f"{name}: claims[{i}].{k} {a.get(k)!r} differs from the reference {b.get(k)!r}"
                )
        if claims_mod.data_of(a) != claims_mod.data_of(b):  # a missing field is "simulated"
            p.append(
                f"{name}: claims[{i}].data {claims_mod.data_of(a)!r} differs from the reference "
                f"{claims_mod.data_of(b)!r}"
            )
        if a.get("reproduced") != b.get("reproduced"):
            p.append(
                f"{name}: claim {a.get('claim')!r} ({a.get('reading')}): verdict "
                f"{a.get('reproduced')}, reference {b.get('reproduced')}"
            )
        if a.get("volatile") != b.get("volatile"):
            p.append(
                f"{name}: claims[{i}].volatile {a.get('volatile')!r} differs from the reference "
                f"{b.get('volatile')!r}"
            )
        if a.get("volatile") and b.get("volatile"):
            # a timing: its numbers follow this machine's clock; its verdict must still be the reference's
            x, y = a.get("boundary"), b.get("boundary")
            if not (_is_num(x) and _is_num(y) and _close(x, y, rtol, atol)):
                p.append(f"{name}: claims[{i}].boundary = {x}, reference {y}")
            continue
        for k in ("estimate", "boundary"):
            x, y = a.get(k), b.get(k)
            if (_is_num(x) and _is_num(y) and not _close(x, y, rtol, atol)) or (
                _is_num(x) != _is_num(y)
            ):
                p.append(
                    f"{name}: claims[{i}].{k} = {x}, reference {y} (tolerance {rtol:g} relative)"
                )
        x, y = a.get("interval"), b.get("interval")
        if (x is None) != (y is None) or (
            x is not None
            and y is not None
            and not (
                len(x) == len(y) == 2
                and all(
                    _is_num(u) and _is_num(v) and _close(u, v, rtol, atol) for u, v in zip(x, y)
                )
            )
        ):
            p.append(
                f"{name}: claims[{i}].interval = {x}, reference {y} (tolerance {rtol:g} relative)"
            )
    base = {"chapter", "unit", "methods", "claims", "extra"}
    for key in sorted(
        (set(fresh) | set(ref)) - base
    ):  # tables (write_results tables=), inconsistencies          # tables of records (write_results tables=)
        if fresh.get(key) != ref.get(key):
            p.append(
                f"{name}: table {key!r} differs from the reference's "
                f"({len(fresh.get(key) or [])} records, reference {len(ref.get(key) or [])})"
            )
    fe, re_ = fresh.get("extra") or {}, ref.get("extra") or {}
    if set(fe) != set(re_):
        p.append(f"{name}: extra keys {sorted(fe)} differ from the reference's {sorted(re_)}")
    # extra values are free-form (timings among them): only their presence is compared
    return p


def check_results(
    fresh_dir: Path, ref_dir: Path, notebooks: list[Path], rtol: float = RTOL, atol: float = ATOL
) -> int:
    """Check every chapter notebook's fresh results file (written by the nbval run) against its committed
    reference in ``ref_dir``; print each problem; 1 if any."""
    fresh_dir, ref_dir = Path(fresh_dir), Path(ref_dir)
    problems, checked = [], []
    chapters = {}
    for nb in notebooks:
        nb = Path(nb)
        chapter = results_chapter(nb)
        if chapter is None:
            problems.append(
                f"{nb}: writes no results file: its last code cell must call "
                f"report.write_results('<chapter>', claims=...)"
            )
            continue
        chapters[chapter] = nb
        ref_path, fresh_path = ref_dir / f"{chapter}.json", fresh_dir / f"{chapter}.json"
        if not ref_path.exists():
            problems.append(
                f"{ref_path}: missing reference for {nb}: regenerate it with "
                f"'.venv/bin/python -m navbook execute --in-place {nb}' (or make "
                f"notebooks) and commit it"
            )
            continue
        if not fresh_path.exists():
            problems.append(
                f"{fresh_path}: {nb} wrote no fresh results: run the notebooks first "
                f"(make test-notebooks)"
            )
            continue
        try:
            ref = json.loads(ref_path.read_text(encoding="utf-8"))
            fresh = json.loads(fresh_path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as err:
            problems.append(f"{chapter}.json: not valid JSON ({err.msg}, line {err.lineno})")
            continue
        problems += [f"reference {q}" for q in validate_results(ref, f"{chapter}.json")]
        problems += [f"fresh {q}" for q in validate_results(fresh, f"{chapter}.json")]
        problems += compare_results(fresh, ref, f"{chapter}.json", rtol, atol)
        checked.append(chapter)
    for stray in sorted(ref_dir.glob("*.json")) if ref_dir.is_dir() else []:
        if stray.stem not in chapters:
            problems.append(
                f"{stray}: no notebook writes chapter {stray.stem!r}: delete the file or fix the "
                f"chapter name"
            )
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        print(f"check-results: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(
        f"check-results: {len(checked)} chapter(s) reproduce their stored results "
        f"({', '.join(checked)}; numbers within {rtol:g} relative + {atol:g} absolute, verdicts equal)"
    )
    return 0
