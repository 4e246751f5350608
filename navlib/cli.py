"""Command line: ``python -m navlib COMMAND ...`` (also installed as ``navlib``).

Commands:
  examples
      list the example files shipped with navlib, each with one command that runs on it; diagnose and loop
      take --example NAME instead of FILE.csv, from any folder.
  simulate-compass OUT.csv [--seed N] [--noise-ut X] [--overwrite]
      write paper A's two simulated turntable sweeps (train = sweep 1, test = sweep 2).
  diagnose SYSTEM FILE.csv [--example NAME] [--model EFFECT,EFFECT] [--effects FILE.py] [--json] [--alpha A]
      fit the model, then name the effect it lacks (or say the residuals are noise, or name the structure
      no effect explains).
  loop SYSTEM FILE.csv --model START [--effects FILE.py] [--json] [--report DIR] [--alpha A]
      the whole loop: diagnose, add the named effect, repeat until the residuals are consistent with noise
      or nothing more can be named.  --json prints {"steps": [...], "final": {...}}; --report DIR writes
      loop.png (the loop as a staircase: one step per effect added, log error axis, held-out rms, the
      noise floor as a band; below it the measurement against the models and the residuals; 750 px wide)
      and loop.md (never over existing files).  The folder is claimed before the work (a marker file
      loop.incomplete, created atomically): a second loop writing into it stops with one line.
  rates SYSTEM [--trials N] [--noise X,X] [--ratio R,R] [--workers N] [--scheduler ADDR] [--json]
      how far to trust the loop on your set-up: the share of simulated trials in which a hidden effect of
      each size is named (detection), nothing-hidden data are called noise (false alarms) and, for the
      compass, an error outside the catalogue names no catalogued effect; 95 % Wilson intervals.
      --noise in the system's unit (compass deg, drift deg/h, magnetometer uT, accelerometer mg).
  compare SYSTEM FILE.csv [--methods ID,ID] [--split RULE] [--seeds N] [--json] [--report DIR] [--workers N]
      which of the papers' compensation methods works best on your file: each fitted on part of it and
      scored on the rest (every row held out once), over seeds, with 95 % intervals, the paired differences
      to the best method and the book's verdict.  RULE: sweep, heading or random (--seed S).  --report DIR
      writes compare.md and compare.png (error against heading per method).  SYSTEM: compass.
  field --site LAT,LON[,HEIGHT_M] [--date YYYY-MM-DD] [--json]
      the Earth's main field from IGRF-14 (ppigrf, offline): north, east, down, intensity, dip, declination
      (a southern or western site as --site -33.9,18.4 or --site=-33.9,18.4; at a geographic pole north, east
      and the declination are undefined: null in --json, with a note).
      loop magnetometer_free ... --site LAT,LON[,HEIGHT_M] --date D compares the local field the loop
      estimates with it and flags a local anomaly when they differ beyond the uncertainty; without
      --site the file's columns lat_deg, lon_deg (height_m, date) say where and when, if it has them.
  calibrate magnetometer FILE.csv [--model hard_iron,scale,soft_iron] --out CAL.json [--site ...] [--date D]
      fit the reference-free magnetometer model (no attitude needed) and write the correction in magcal's
      convention, m_corrected = (m - b) A, with the expected field strength and every parameter's
      uncertainty (navlib.workbench.calibration).
  apply CAL.json FILE.csv --out CORRECTED.csv
      correct the field columns of FILE with a calibration (never over an existing file).  The calibration
      is checked key by key first (A 3x3, b_ut 3 finite numbers, A's condition number at most 10, ...), and
      the corrected field's median strength against expected_field_strength_ut: beyond 25 % refused (nothing
      written), beyond 10 % a warning line (navlib.workbench.calibration: COND_LIMIT, FIELD_*_REL).

rates and compare run on dask.distributed (navlib.engine): --workers N local worker processes (default: the
cores of this machine; 1 runs in this process), or --scheduler tcp://HOST:PORT (or the environment
variable NAVLIB_SCHEDULER) for a cluster started with `dask scheduler` and `dask worker`.  An address that
does not connect within 5 s, or then does not send dask's handshake within 5 s more (a silent port, another
protocol, random bytes), stops the command with one line (navlib.engine.probe_scheduler).

SYSTEM is compass, drift, magnetometer, magnetometer_free or accelerometer:
  compass columns: true_heading_deg, measured_heading_deg; optional temperature_c, time_s, sweep.
  drift columns: latitude_error_deg, drift_deg_h; optional temperature_c, temperature_change_c.
  magnetometer columns: mag_x_ut, mag_y_ut, mag_z_ut, q_w, q_x, q_y, q_z (reference attitude, body FRD to
  NED); optional time_s, gyr_*_dps, pos_*_m.
  magnetometer_free columns: mag_x_ut, mag_y_ut, mag_z_ut (no attitude); optional acc_x_ms2, acc_y_ms2,
  acc_z_ms2 (still or slow), time_s, temperature_c, and the site: lat_deg, lon_deg, height_m (one
  site per file: spread at most 0.1 deg and 500 m) and date (ISO 8601, within a year).
  accelerometer columns (a tumble test): temperature_c, position_deg (dividing-head grid, 15 deg),
  output_mg (output / nominal scale factor), unit; optional set_point_c.  Extra columns are ignored.
  A file of several units: --unit NAME fits one.

--effects FILE.py adds your own effects (every navlib.workbench.effects.Effect defined in the file whose
system matches), usable in --model and named by diagnose like catalogued ones.

Bad input exits with status 2 and one line on stderr; no traceback.  That includes a broken --effects file
(it fails at import, calls sys.exit, defines two effects with one name, or a contribution raises or
returns text, NaN, infinity or the wrong shape: the line names the file and the effect) and a --report
folder that exists with a report in it or cannot be written (checked before the fit).  Effects the data
cannot test are listed ("not tested: ..." lines; "untested" in --json).  ``python -m navlib --debug ...``
shows the full traceback of any error (for bug reports).  The parser needs nothing but the standard
library: ``--help`` answers before the workbench is loaded (:mod:`navlib.commands` holds the commands).  Output into a closed pipe (``| head -1``) ends
quietly, with status 141 like a process stopped by SIGPIPE.  Ctrl-C prints one line ("interrupted") and
exits with status 130, like a process stopped by SIGINT; an output folder it stopped half-written keeps its
marker file (loop.incomplete) saying it is incomplete, and the line names it (a folder
nothing was written into yet is removed again: it never looks complete).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
from typing import Callable

from .errors import InputError, UserCodeError
from .names import (
    CALIBRATION_MODEL,
    COMPARE_BIN_DEG,
    COMPARE_DEFAULT_METHODS,
    COMPARE_LS_TOLERANCE_DEG,
    COMPARE_SEEDS,
    COMPARE_SPLITS,
    COMPARE_SYSTEM_NAMES,
    EXAMPLES,
    FIELD_DATE,
    RATE_NOISE,
    RATE_RATIOS,
    RATE_SYSTEM_NAMES,
    RATE_UNITS,
    SYSTEM_NAMES,
    WORKERS_HELP,
)


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, like every other bad input
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="navlib", description="navbook's library: simulators and compensation tools")
    ap.add_argument("--debug", action="store_true", help="show the full traceback of any error")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sim = sub.add_parser("simulate-compass", help="write paper A's two simulated turntable sweeps")
    sim.add_argument("out", help="CSV file to write (never overwritten unless --overwrite)")
    sim.add_argument(
        "--seed",
        type=int,
        default=2024,
        help="seed of the simulated compass's noise (default 2024)",
    )
    sim.add_argument(
        "--noise-ut", type=float, default=None, help="magnetometer noise, uT (1 sigma)"
    )
    sim.add_argument(
        "--overwrite", action="store_true", help="replace OUT if it exists (default: refuse)"
    )
    for name, helptext in (
        ("diagnose", "which physical effect is the model missing?"),
        ("loop", "the whole loop: diagnose, add the effect, repeat"),
    ):
        cmd = sub.add_parser(name, help=helptext, description=helptext)
        cmd.add_argument("system", choices=SYSTEM_NAMES)
        cmd.add_argument(
            "file", nargs="?", default=None, help="measurement CSV (or --example NAME)"
        )
        cmd.add_argument(
            "--example",
            default=None,
            choices=sorted(EXAMPLES),
            help="a file shipped with navlib instead of FILE (navlib examples lists them)",
        )
        cmd.add_argument("--model", default="", help="comma-separated effects already in the model")
        cmd.add_argument("--effects", default=None, help="Python file defining your own effects")
        cmd.add_argument("--json", action="store_true", help="print one JSON object")
        cmd.add_argument(
            "--alpha",
            type=float,
            default=None,
            help="family-wise false-alarm level (default 0.025)",
        )
        cmd.add_argument(
            "--unit",
            default=None,
            metavar="NAME",
            help="accelerometer: the unit (column 'unit') to fit when the file holds several",
        )
        if name == "loop":
            cmd.add_argument(
                "--report", default=None, help="folder for loop.png and loop.md (never overwritten)"
            )
            _site_options(
                cmd,
                required=False,
                site_help="magnetometer_free: the estimated local field is compared with IGRF-14 there (a "
                "local anomaly is flagged); overrides the file's lat_deg, lon_deg, height_m "
                "columns",
            )
    sub.add_parser(
        "examples",
        help="list the example files shipped with navlib, one command each",
        description="the example files shipped with navlib: system, where the file is, and one "
        "command that runs on it (--example NAME works from any folder)",
    )
    fld = sub.add_parser(
        "field",
        help="the Earth's field from IGRF-14 at a site and date",
        description="the IGRF-14 main field (ppigrf, offline) at a site: north, east, down, "
        "intensity (uT), dip and declination (deg)",
    )
    _site_options(fld, required=True, date_help=f"date of the field (default {FIELD_DATE})")
    fld.add_argument("--json", action="store_true", help="print one JSON object")
    cal = sub.add_parser(
        "calibrate",
        help="fit a magnetometer calibration without reference attitude",
        description="fit the reference-free magnetometer model (system magnetometer_free: the "
        "field magnitude and, with an "
        "accelerometer, dip constant) and write the correction m_corrected = "
        "(m - b) A with its uncertainties as JSON",
    )
    cal.add_argument("sensor", choices=["magnetometer"])
    cal.add_argument(
        "file", help="measurement CSV (mag_*_ut; optional acc_*_ms2, time_s, temperature_c)"
    )
    cal.add_argument(
        "--model",
        default=",".join(CALIBRATION_MODEL),
        help=f"comma-separated effects (default {','.join(CALIBRATION_MODEL)}: the full ellipsoid)",
    )
    cal.add_argument("--out", required=True, help="calibration JSON to write (never overwritten)")
    _site_options(
        cal,
        required=False,
        site_help="the fitted field strength is compared with IGRF-14 there; overrides the file's "
        "lat_deg, lon_deg, height_m columns",
    )
    app = sub.add_parser(
        "apply",
        help="apply a calibration to a measurement file",
        description="correct the field columns of FILE with a calibration of `navlib calibrate`",
    )
    app.add_argument("calibration", help="calibration JSON written by `navlib calibrate`")
    app.add_argument("file", help="measurement CSV with the columns the calibration needs")
    app.add_argument("--out", required=True, help="corrected CSV to write (never overwritten)")
    rates = sub.add_parser(
        "rates",
        help="detection, false-alarm and out-of-catalogue rates of the loop",
        description="detection, false-alarm and out-of-catalogue rates of the workbench's loop "
        "on simulated data at your noise level and effect sizes (95 % Wilson "
        "intervals)",
    )
    rates.add_argument("system", choices=RATE_SYSTEM_NAMES)
    rates.add_argument(
        "--trials",
        type=int,
        default=20,
        help="trials per hidden effect, size and noise (default 20)",
    )
    rates.add_argument(
        "--noise",
        default=None,
        help="noise levels (1 sigma, comma-separated) in the system's unit (default "
        + ", ".join(f"{k} {v:g} {RATE_UNITS[k]}" for k, v in RATE_NOISE.items())
        + ")",
    )
    rates.add_argument(
        "--ratio",
        default=None,
        help="effect sizes as multiples of the noise (default "
        + ",".join(f"{r:g}" for r in RATE_RATIOS)
        + ")",
    )
    rates.add_argument(
        "--null-trials",
        type=int,
        default=None,
        help="nothing-hidden trials per noise level (default twice --trials)",
    )
    # ---- compare: the papers' methods on the user's file (navlib.workbench.compare)
    cmp_ = sub.add_parser(
        "compare",
        help="which of the papers' compensation methods works best on your file",
        description="fit the papers' compensation methods on part of your file and score them "
        "on the rest (every row held out once), over seeds: held-out rms with "
        "95 % intervals, the paired differences to the best method and the book's "
        "verdict on each",
    )
    cmp_.add_argument("system", choices=COMPARE_SYSTEM_NAMES)
    cmp_.add_argument("file", nargs="?", default=None, help="measurement CSV (or --example NAME)")
    cmp_.add_argument(
        "--example",
        default=None,
        choices=sorted(n for n, e in EXAMPLES.items() if e[0] in COMPARE_SYSTEM_NAMES),
        help="a file shipped with navlib instead of FILE",
    )
    cmp_.add_argument(
        "--methods",
        default=None,
        metavar="ID,ID",
        help="comma-separated method ids (default, compass: "
        + ",".join(COMPARE_DEFAULT_METHODS["compass"])
        + "; DE-BP and ADE-BP in paper A's "
        "primary reading, the full DE stage then trainlm); a default method that cannot be "
        "fitted on the split is left out with a 'not run' line, a named one is refused",
    )
    cmp_.add_argument(
        "--split",
        default=None,
        choices=COMPARE_SPLITS,
        help="sweep: train on the other sweeps, test on each (column 'sweep'); heading: alternate "
        "heading bins of --bin-deg, both ways; random: two random halves of the rows (--seed), "
        "both ways (default: sweep when the file has 2 sweeps or more, else heading)",
    )
    cmp_.add_argument(
        "--seed",
        type=int,
        default=0,
        help="entropy of every random draw: the random split and every run (default 0)",
    )
    cmp_.add_argument(
        "--seeds",
        type=int,
        default=COMPARE_SEEDS,
        help=f"runs of every stochastic method, the same seeds for all; 6 or more give a 95 %% "
        f"interval (default {COMPARE_SEEDS})",
    )
    cmp_.add_argument(
        "--bin-deg",
        type=float,
        default=COMPARE_BIN_DEG,
        help=f"--split heading: width of the heading bins, deg; 360 must hold an even number of "
        f"them (default {COMPARE_BIN_DEG:g})",
    )
    cmp_.add_argument(
        "--ls-tolerance",
        type=float,
        default=COMPARE_LS_TOLERANCE_DEG,
        metavar="DEG",
        help=f"8-position LS: it uses the training reading nearest to each of 0, 45, ..., 315 deg "
        f"true heading, which must lie within DEG of it, at most 22.5 "
        f"(default {COMPARE_LS_TOLERANCE_DEG:g})",
    )
    cmp_.add_argument(
        "--margin",
        type=float,
        default=None,
        help="equivalence margin of the verdicts, in the system's unit: a difference to the best "
        "whose interval lies within +-margin is 'no difference' (default: none)",
    )
    cmp_.add_argument("--json", action="store_true", help="print one JSON object")
    cmp_.add_argument(
        "--report",
        default=None,
        help="folder for compare.md and compare.png (claimed before the work, never overwritten)",
    )
    cmp_.add_argument("--workers", type=int, default=None, help=WORKERS_HELP)
    cmp_.add_argument(
        "--scheduler",
        default=None,
        help="address of a dask scheduler, e.g. tcp://127.0.0.1:8786 (default $NAVLIB_SCHEDULER)",
    )
    rates.add_argument("--workers", type=int, default=None, help=WORKERS_HELP)
    rates.add_argument(
        "--scheduler",
        default=None,
        help="address of a dask scheduler, e.g. tcp://127.0.0.1:8786 (default $NAVLIB_SCHEDULER)",
    )
    rates.add_argument("--json", action="store_true", help="print one JSON object")
    return ap


def _site_options(cmd, required: bool, site_help: str = "", date_help: str = "") -> None:
    """--site and --date; ``site_help``/``date_help`` say what the command does with them."""
    cmd.add_argument(
        "--site",
        required=required,
        default=None,
        metavar="LAT,LON[,HEIGHT_M]",
        help="geodetic latitude and longitude (deg) and height above the WGS84 ellipsoid (m, default 0)"
        + (f"; {site_help}" if site_help else ""),
    )
    cmd.add_argument(
        "--date",
        default=None,
        metavar="YYYY-MM-DD",
        help=date_help or f"date of the field (default: the file's date column, else {FIELD_DATE})",
    )


#: Exit status after output into a closed pipe: what a shell reports for a process stopped by SIGPIPE.
BROKEN_PIPE = 141
#: Exit status after Ctrl-C (SIGINT): what a shell reports for a process stopped by SIGINT.
INTERRUPTED = 130


def _command(name: str):
    """The function of command ``name`` in :mod:`navlib.commands`, loaded once a command runs (the workbench
    and its numerical libraries take about a second to import; the parser and ``--help`` need none of it)."""
    return importlib.import_module(".commands", __package__).COMMANDS[name]


_NEGATIVE = re.compile(r"^-\.?\d")


def site_argument(argv: list[str]) -> list[str]:
    """``--site -33.9,18.4`` (a southern or western site, the documented form) as ``--site=-33.9,18.4``:
    argparse takes a value that starts with '-' and is not a plain negative number for an option and
    would refuse it.  Nothing after a ``--`` is touched."""
    out = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--":
            return out + list(argv[i:])
        if a == "--site" and i + 1 < len(argv) and _NEGATIVE.match(str(argv[i + 1])):
            out.append(f"--site={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(site_argument(list(sys.argv[1:] if argv is None else argv)))
    return run_command(args, lambda a: _command(a.command)(a), "navlib")


def run_command(args, dispatch: Callable[[argparse.Namespace], int], prog: str) -> int:
    """Run ``dispatch(args)`` (``args.command`` names the command, ``args.debug`` asks for tracebacks) by
    the command line's conventions: bad input (:class:`navlib.errors.InputError`, a user file's
    :class:`navlib.errors.UserCodeError`, an ``OSError``) is one line ``PROG COMMAND: error: ...`` and
    status 2; a bug is one line and status 1; Ctrl-C is one line and status 130; output into a closed pipe
    stops quietly (status 141); ``--debug`` lets every error through with its traceback.  Other command
    lines built on navlib (the book's tooling) use it too."""
    try:
        if args.debug:  # let every error through with its traceback
            status = dispatch(args)
        else:
            status = _run(args, dispatch, prog)
        sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
    except BrokenPipeError:
        # the reader went away (``| head -1``): stop quietly; stdout goes to devnull so that Python's
        # final flush does not complain again (the recipe of the Python documentation, signal module)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return BROKEN_PIPE
    except KeyboardInterrupt as err:
        if args.debug:  # the traceback shows where it was
            raise
        # Ctrl-C: one line (and the output folder it left incomplete, if any: navlib.data.tables.FolderClaim)
        print(f"{prog} {args.command}: interrupted{_notes(err)}", file=sys.stderr)
        # CPython remembers a KeyboardInterrupt that passed through an exec() of a string (fastjsonschema
        # compiles nbformat's schema that way) and, under ``python -m``, ends the process by SIGINT after
        # main returned, as if nobody had handled it; an exec of a string that completes resets that memory
        # (run_eval_code_obj in CPython's pythonrun.c).  It was handled here: the status is 130.
        exec("pass", {})
        return INTERRUPTED
    return status


def _notes(err: BaseException) -> str:
    """The exception's notes (e.g. an output folder left incomplete) as the end of its one line."""
    notes = [" ".join(str(n).split()) for n in getattr(err, "__notes__", ())]
    return "".join(f"; {n}" for n in notes if n)


def _run(args, dispatch, prog: str) -> int:
    try:
        return dispatch(args)
    except BrokenPipeError:
        raise
    except (InputError, UserCodeError) as err:
        print(f"{prog} {args.command}: error: {err}{_notes(err)}", file=sys.stderr)
        return 2
    except OSError as err:
        where = f"{err.filename}: " if err.filename else ""
        print(
            f"{prog} {args.command}: error: {where}{err.strerror or err}{_notes(err)}",
            file=sys.stderr,
        )
        return 2
    except Exception as err:  # a bug, not bad input: one line; --debug shows the traceback
        print(
            f"{prog} {args.command}: internal error: {type(err).__name__}: {err}".splitlines()[0]
            + " (run with --debug for the traceback)"
            + _notes(err),
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":
    sys.exit(main())
