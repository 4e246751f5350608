"""The book's command line, ``python -m navbook COMMAND`` (the Makefile's steps, and a chapter over a grid).

Commands::

  execute NOTEBOOK... (--out DIR | --in-place)
      execute chapters with papermill (``--in-place``: the stored notebooks,
      results to notebooks/results)
  compile
      compile the numba kernels once (cached on disk)
  status RESULTS_DIR --notebooks DIR --out FILE [--toc FILE]
      the landing page's table from the results files
  api-modules --out FILE
      the API reference pages
  check-html HTML_DIR [--baseline FILE]
      check the built pages
  check-results NOTEBOOK... --fresh DIR --reference DIR [--rtol R] [--atol A]
      fresh results files against the committed references
  screenshots HTML_DIR OUT_DIR [--width PX] [--chromium PATH]
      every page rendered with headless Chromium
  grid NOTEBOOK --param NAME=V1,V2 [--param ...] --out DIR
       [--workers N] [--scheduler ADDR]
      one run of a chapter notebook per point of the parameter grid
      (papermill), each with its own results file; DIR (new or empty) gets
      the executed notebooks, results/ and grid.csv (parameters, method
      statistics, claim verdicts).  DIR is claimed before the first run (a
      marker file grid.incomplete, created atomically, removed after
      grid.csv): a second grid on DIR stops with one line, and a grid stopped
      by an error or Ctrl-C leaves the marker saying DIR is incomplete.
      --workers N: local worker processes (default the cores of this machine;
      1 in this process); --scheduler tcp://HOST:PORT or $NAVLIB_SCHEDULER:
      a dask cluster.

Bad input is one line ``navbook COMMAND: error: ...`` and status 2, Ctrl-C one line and status 130 (the
conventions of ``navlib``'s command line, :func:`navlib.cli.run_command`); ``--debug`` shows tracebacks.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from navlib import engine
from navlib.cli import run_command
from navlib.names import WORKERS_HELP

from .api_pages import write_api
from .execute import execute
from .grid import run_grid
from .html_checks import BASELINE_FILE, check_html
from .landing import write_status
from .results_check import ATOL, RTOL, check_results
from .screenshots import screenshots


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, like every other bad input
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(
        prog="navbook", description="the book's tooling: execute, check, landing page, grid"
    )
    ap.add_argument("--debug", action="store_true", help="show the full traceback of any error")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    ex = sub.add_parser("execute", help="execute notebooks with papermill")
    ex.add_argument("notebooks", nargs="+", type=Path)
    g = ex.add_mutually_exclusive_group(required=True)
    g.add_argument(
        "--out", type=Path, help="folder for the executed copies (results go to OUT/results)"
    )
    g.add_argument(
        "--in-place",
        action="store_true",
        help="re-execute the stored notebooks; store results in notebooks/results",
    )
    ch = sub.add_parser("check-html", help="check the built pages")
    ch.add_argument("html_dir", type=Path)
    ch.add_argument(
        "--baseline",
        type=Path,
        default=None,
        help="known problems per page (JSON; default: check_html_baseline.json in the book "
        "folder, two levels above HTML_DIR, if present)",
    )
    st = sub.add_parser(
        "status", help="write the landing page's status table from the results files"
    )
    st.add_argument("results_dir", type=Path)
    st.add_argument(
        "--notebooks", type=Path, required=True, help="folder of the executed notebooks"
    )
    st.add_argument("--out", type=Path, required=True)
    st.add_argument(
        "--toc",
        type=Path,
        default=None,
        help="the book's _toc.yml (chapter order; default: _toc.yml in OUT's parent folder)",
    )
    api = sub.add_parser("api-modules", help="write the API page's automodule list")
    api.add_argument("--out", type=Path, required=True)
    cr = sub.add_parser(
        "check-results", help="compare fresh results files with the committed references"
    )
    cr.add_argument("notebooks", nargs="+", type=Path)
    cr.add_argument("--fresh", type=Path, required=True)
    cr.add_argument("--reference", type=Path, required=True)
    cr.add_argument("--rtol", type=float, default=RTOL)
    cr.add_argument("--atol", type=float, default=ATOL)
    sub.add_parser("compile", help="compile the numba kernels once (cached on disk)")
    sc = sub.add_parser("screenshots", help="render every page with headless Chromium")
    sc.add_argument("html_dir", type=Path)
    sc.add_argument("out_dir", type=Path)
    sc.add_argument("--width", type=int, default=1400)
    sc.add_argument("--chromium", default=None)
    grid = sub.add_parser(
        "grid",
        help="run a chapter notebook over a grid of its parameters",
        description="one papermill run of NOTEBOOK per point of the grid, each with its own "
        "results file; DIR gets the executed notebooks and grid.csv",
    )
    grid.add_argument("notebook", help="a notebook with a cell tagged 'parameters'")
    grid.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=V1,V2",
        help="a parameter and its values (repeat for more parameters)",
    )
    grid.add_argument("--out", required=True, help="new or empty folder for the outputs")
    grid.add_argument("--workers", type=int, default=None, help=WORKERS_HELP)
    grid.add_argument(
        "--scheduler",
        default=None,
        help="address of a dask scheduler, e.g. tcp://127.0.0.1:8786 (default $NAVLIB_SCHEDULER)",
    )
    return ap


def _grid(args) -> int:
    workers = engine.default_workers() if args.workers is None else args.workers
    rows = run_grid(args.notebook, args.param, args.out, workers=workers, scheduler=args.scheduler)
    failed = [r for r in rows if r["status"].startswith("failed")]
    print(f"{len(rows)} runs, {len(rows) - len(failed)} ok; {os.path.join(args.out, 'grid.csv')}")
    for r in failed:
        print(f"run {r['run']}: {r['status']}", file=sys.stderr)
    return 1 if failed else 0


def _compile(args) -> int:
    from .kernels import compile_kernels  # noqa: PLC0415  # lazy: a study and torch (2 s), for this command only

    return compile_kernels()


def _check_html(args) -> int:
    default = Path(args.html_dir).absolute().parents[1] / BASELINE_FILE
    return check_html(
        args.html_dir, baseline=args.baseline or (default if default.exists() else None)
    )


#: Command name -> function.
COMMANDS = {
    "execute": lambda a: execute(a.notebooks, a.out, a.in_place),
    "check-html": _check_html,
    "status": lambda a: write_status(a.results_dir, a.notebooks, a.out, a.toc),
    "api-modules": lambda a: write_api(a.out),
    "compile": _compile,
    "check-results": lambda a: check_results(a.fresh, a.reference, a.notebooks, a.rtol, a.atol),
    "screenshots": lambda a: screenshots(a.html_dir, a.out_dir, a.width, a.chromium),
    "grid": _grid,
}


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(list(sys.argv[1:] if argv is None else argv))
    return run_command(args, lambda a: COMMANDS[a.command](a), "navbook")
