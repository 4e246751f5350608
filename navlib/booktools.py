"""Build helpers for the book: execute notebooks with papermill, strip volatile metadata, check the HTML.

``python -m navlib.booktools execute --out book/_generated notebooks/*.ipynb`` executes each notebook into
the book's generated folder (one progress line per notebook) and stops with a non-zero exit at the first
failing notebook; ``--in-place`` re-executes the stored notebooks instead (how the outputs that nbval checks
are regenerated).  ``check-html DIR`` fails if a built page loads anything from the network or shows an
execution error.
"""
from __future__ import annotations

import argparse
import re
import sys
import tempfile
import time
from pathlib import Path

VOLATILE_NB_KEYS = ("papermill",)
VOLATILE_CELL_KEYS = ("papermill", "execution", "collapsed", "scrolled")


def strip_metadata(nb) -> None:
    """Remove timing and run-specific metadata so a re-executed notebook diffs only where outputs changed.
    Execution counts stay: nbval treats a cell without one as never run (they are sequential anyway)."""
    for key in VOLATILE_NB_KEYS:
        nb.metadata.pop(key, None)
    for cell in nb.cells:
        for key in VOLATILE_CELL_KEYS:
            cell.metadata.pop(key, None)


def missing_figures(nb) -> list[int]:
    """Indices of code cells that call ``plt.show()`` but carry no image output."""
    bad = []
    for i, cell in enumerate(nb.cells):
        if cell.cell_type == "code" and "plt.show()" in cell.source:
            if not any("image/png" in out.get("data", {}) for out in cell.get("outputs", [])):
                bad.append(i)
    return bad


def execute(notebooks: list[Path], out_dir: Path | None, in_place: bool,
            parameters: dict | None = None) -> int:
    import nbformat
    import papermill as pm

    for i, nb_path in enumerate(notebooks, 1):
        nb_path = Path(nb_path).resolve()
        target = nb_path if in_place else (out_dir / nb_path.name)
        target.parent.mkdir(parents=True, exist_ok=True)
        print(f"[{i}/{len(notebooks)}] executing {nb_path.name} -> {target}", flush=True)
        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            tmp_out = Path(tmp) / nb_path.name
            try:
                pm.execute_notebook(str(nb_path), str(tmp_out), cwd=str(nb_path.parent),
                                    parameters=parameters or {}, kernel_name="python3",
                                    progress_bar=False, log_output=False)
            except pm.PapermillExecutionError as err:
                lines = [ln for ln in str(err).strip().splitlines() if ln.strip()]
                print(f"FAILED {nb_path.name}: cell {err.exec_count}: {lines[-1] if lines else err.ename}",
                      file=sys.stderr)
                return 1
            nb = nbformat.read(tmp_out, as_version=4)
            missing = missing_figures(nb)
            if missing:
                print(f"FAILED {nb_path.name}: cell {missing[0]} calls plt.show() but produced no figure "
                      f"(is MPLBACKEND set to a non-inline backend?)", file=sys.stderr)
                return 1
            strip_metadata(nb)
            nbformat.write(nb, target)
        print(f"    done in {time.perf_counter() - t0:.1f} s", flush=True)
    return 0


REMOTE = re.compile(r"""(?:src|href)\s*=\s*["'](?:https?:)?//(?!localhost)""", re.I)


def check_html(html_dir: Path) -> int:
    """Fail if any built page references a remote script/style/image, or shows a notebook traceback."""
    problems = []
    for page in sorted(html_dir.rglob("*.html")):
        text = page.read_text(encoding="utf-8", errors="replace")
        for m in re.finditer(r"<(script|link|img)\b[^>]*>", text, re.I):
            if REMOTE.search(m.group(0)):
                problems.append(f"{page.relative_to(html_dir)}: loads from the network: {m.group(0)[:120]}")
        if "Traceback (most recent call last)" in text or 'class="output traceback' in text:
            problems.append(f"{page.relative_to(html_dir)}: shows an execution error")
    for p in problems[:20]:
        print(p, file=sys.stderr)
    if problems:
        print(f"check-html: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(f"check-html: {len(list(html_dir.rglob('*.html')))} pages, nothing loaded from the network")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m navlib.booktools")
    sub = ap.add_subparsers(dest="cmd", required=True)
    ex = sub.add_parser("execute", help="execute notebooks with papermill")
    ex.add_argument("notebooks", nargs="+", type=Path)
    g = ex.add_mutually_exclusive_group(required=True)
    g.add_argument("--out", type=Path, help="folder for the executed copies")
    g.add_argument("--in-place", action="store_true", help="re-execute the stored notebooks")
    ch = sub.add_parser("check-html", help="check built pages load nothing remote")
    ch.add_argument("html_dir", type=Path)
    args = ap.parse_args(argv)
    if args.cmd == "execute":
        return execute(args.notebooks, args.out, args.in_place)
    return check_html(args.html_dir)


if __name__ == "__main__":
    sys.exit(main())
