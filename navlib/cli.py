"""Command line: ``python -m navlib COMMAND ...`` (also installed as ``navlib``).

Commands:
  simulate-compass OUT.csv [--seed N] [--noise-ut X] [--overwrite]
      write paper A's two simulated turntable sweeps (train = sweep 1, test = sweep 2).
  diagnose SYSTEM FILE.csv [--model EFFECT,EFFECT] [--effects FILE.py] [--json] [--alpha A]
      fit the model, then name the effect it lacks (or say the residuals are noise, or name the structure
      no effect explains).
  loop SYSTEM FILE.csv --model START [--effects FILE.py] [--json] [--report DIR] [--alpha A]
      the whole loop: diagnose, add the named effect, repeat until the residuals are consistent with noise
      or nothing more can be named.  --json prints {"steps": [...], "final": {...}}; --report DIR writes
      loop.png (the loop as a staircase: one step per effect added, log error axis, held-out rms, the
      noise floor as a band; below it the measurement against the models and the residuals; 750 px wide)
      and loop.md (never over existing files).
  rates SYSTEM [--trials N] [--noise X,X] [--ratio R,R] [--workers N] [--scheduler ADDR] [--json]
      how far to trust the loop on your set-up: the share of simulated trials in which a hidden effect of
      each size is named (detection), nothing-hidden data are called noise (false alarms) and, for the
      compass, an error outside the catalogue names no catalogued effect; 95 % Wilson intervals.
      --noise in the system's unit (compass deg, drift deg/h, magnetometer uT, accelerometer mg).
  field --site LAT,LON[,HEIGHT_M] [--date YYYY-MM-DD] [--json]
      the Earth's main field from IGRF-14 (ppigrf, offline): north, east, down, intensity, dip, declination.
      loop magnetometer_free ... --site LAT,LON[,HEIGHT_M] --date D compares the local field the loop
      estimates with it and flags a local anomaly when they differ beyond the uncertainty; without
      --site the file's columns lat_deg, lon_deg (height_m, date) say where and when, if it has them.
  calibrate magnetometer FILE.csv [--model hard_iron,scale,soft_iron] --out CAL.json [--site ...] [--date D]
      fit the reference-free magnetometer model (no attitude needed) and write the correction in magcal's
      convention, m_corrected = (m - b) A, with the expected field strength and every parameter's
      uncertainty (navlib.workbench.calibration).
  apply CAL.json FILE.csv --out CORRECTED.csv
      correct the field columns of FILE with a calibration (never over an existing file).
  grid NOTEBOOK --param NAME=V1,V2 [--param ...] --out DIR [--workers N] [--scheduler ADDR]
      one run of a chapter notebook per point of the parameter grid (papermill), each with its own results
      file; DIR (new or empty) gets the executed notebooks, results/ and grid.csv (parameters, method
      statistics, claim verdicts).  Needs papermill.

rates and grid run on dask.distributed (navlib.engine): --workers N local worker processes (default: the
cores of this machine; 1 runs in this process), or --scheduler tcp://HOST:PORT (or the environment
variable NAVLIB_SCHEDULER) for a cluster started with `dask scheduler` and `dask worker`.

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
shows the full traceback of any error (for bug reports).  Output into a closed pipe (``| head -1``) ends
quietly, with status 141 like a process stopped by SIGPIPE.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from dataclasses import replace

from . import engine
from .data.tables import write_new_csv
from .errors import InputError, UserCodeError
from .sensors.compass import PAPER_A_EARTH, CompassErrors, simulate_train_test
from .workbench import SYSTEMS, get_system, load_effects
from .workbench.diagnose import diagnose
from .workbench.effects import resolve
from .workbench.fit import fit_model
from .workbench.loop import check_report_folder, loop, write_report
from .workbench.calibration import DEFAULT_MODEL, apply_file, calibrate_file
from .workbench.magnetometer_free import FREE_EFFECTS
from .workbench.rates import DEFAULT_RATIOS, RATE_SYSTEMS, rates


class _Parser(argparse.ArgumentParser):
    def error(self, message):                       # one line, exit 2, like every other bad input
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="navlib", description="navbook's library: simulators and compensation tools")
    ap.add_argument("--debug", action="store_true", help="show the full traceback of any error")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sim = sub.add_parser("simulate-compass", help="write paper A's two simulated turntable sweeps")
    sim.add_argument("out", help="CSV file to write (never overwritten unless --overwrite)")
    sim.add_argument("--seed", type=int, default=2024)
    sim.add_argument("--noise-ut", type=float, default=None, help="magnetometer noise, uT (1 sigma)")
    sim.add_argument("--overwrite", action="store_true")
    for name, helptext in (("diagnose", "which physical effect is the model missing?"),
                           ("loop", "the whole loop: diagnose, add the effect, repeat")):
        cmd = sub.add_parser(name, help=helptext, description=helptext)
        cmd.add_argument("system", choices=sorted(SYSTEMS))
        cmd.add_argument("file", help="measurement CSV")
        cmd.add_argument("--model", default="", help="comma-separated effects already in the model")
        cmd.add_argument("--effects", default=None, help="Python file defining your own effects")
        cmd.add_argument("--json", action="store_true", help="print one JSON object")
        cmd.add_argument("--alpha", type=float, default=None, help="family-wise false-alarm level (default 0.025)")
        cmd.add_argument("--unit", default=None, metavar="NAME",
                         help="accelerometer: the unit (column 'unit') to fit when the file holds several")
        if name == "loop":
            cmd.add_argument("--report", default=None, help="folder for loop.png and loop.md (never overwritten)")
            _site_options(cmd, required=False)
    fld = sub.add_parser("field", help="the Earth's field from IGRF-14 at a site and date",
                         description="the IGRF-14 main field (ppigrf, offline) at a site: north, east, down, "
                                     "intensity (uT), dip and declination (deg)")
    _site_options(fld, required=True)
    fld.add_argument("--json", action="store_true", help="print one JSON object")
    cal = sub.add_parser("calibrate", help="fit a magnetometer calibration without reference attitude",
                         description="fit the reference-free magnetometer model (field magnitude and, with an "
                                     "accelerometer, dip constant) and write the correction m_corrected = "
                                     "(m - b) A with its uncertainties as JSON")
    cal.add_argument("sensor", choices=["magnetometer"])
    cal.add_argument("file", help="measurement CSV (mag_*_ut; optional acc_*_ms2, time_s, temperature_c)")
    cal.add_argument("--model", default=",".join(DEFAULT_MODEL),
                     help=f"comma-separated effects (default {','.join(DEFAULT_MODEL)}: the full ellipsoid)")
    cal.add_argument("--out", required=True, help="calibration JSON to write (never overwritten)")
    _site_options(cal, required=False)
    app = sub.add_parser("apply", help="apply a calibration to a measurement file",
                         description="correct the field columns of FILE with a calibration of `navlib calibrate`")
    app.add_argument("calibration", help="calibration JSON written by `navlib calibrate`")
    app.add_argument("file", help="measurement CSV with the columns the calibration needs")
    app.add_argument("--out", required=True, help="corrected CSV to write (never overwritten)")
    rates = sub.add_parser("rates", help="detection, false-alarm and out-of-catalogue rates of the loop",
                           description="detection, false-alarm and out-of-catalogue rates of the workbench's loop "
                                       "on simulated data at your noise level and effect sizes (95 % Wilson "
                                       "intervals)")
    rates.add_argument("system", choices=sorted(RATE_SYSTEMS))
    rates.add_argument("--trials", type=int, default=20, help="trials per hidden effect, size and noise (default 20)")
    rates.add_argument("--noise", default=None,
                       help="noise levels (1 sigma, comma-separated) in the system's unit (compass deg, drift deg/h, "
                            "magnetometer uT, accelerometer mg)")
    rates.add_argument("--ratio", default=None, help="effect sizes as multiples of the noise (default 3,10)")
    rates.add_argument("--null-trials", type=int, default=None,
                       help="nothing-hidden trials per noise level (default twice --trials)")
    grid = sub.add_parser("grid", help="run a chapter notebook over a grid of its parameters",
                          description="one papermill run of NOTEBOOK per point of the grid, each with its own "
                                      "results file; DIR gets the executed notebooks and grid.csv")
    grid.add_argument("notebook", help="a notebook with a cell tagged 'parameters'")
    grid.add_argument("--param", action="append", default=[], metavar="NAME=V1,V2",
                      help="a parameter and its values (repeat for more parameters)")
    grid.add_argument("--out", required=True, help="new or empty folder for the outputs")
    for cmd in (rates, grid):
        cmd.add_argument("--workers", type=int, default=None,
                         help="local worker processes (default: the cores of this machine; 1 = this process)")
        cmd.add_argument("--scheduler", default=None,
                         help="address of a dask scheduler, e.g. tcp://127.0.0.1:8786 (default $NAVLIB_SCHEDULER)")
    rates.add_argument("--json", action="store_true", help="print one JSON object")
    return ap


def _site_options(cmd, required: bool) -> None:
    cmd.add_argument("--site", required=required, default=None, metavar="LAT,LON[,HEIGHT_M]",
                     help="geodetic latitude and longitude (deg) and height above the WGS84 ellipsoid (m, default 0)"
                          + ("" if required else "; magnetometer_free: the estimated local field is compared "
                             "with IGRF-14 there (a local anomaly is flagged); overrides the file's lat_deg, "
                             "lon_deg, height_m columns"))
    cmd.add_argument("--date", default=None, metavar="YYYY-MM-DD",
                     help="date of the field (default: the file's date column, else 2025-01-01)")


def _site_values(args):
    """``(site, date)`` of --site/--date: ``(lat, lon[, height_m])`` or None, the date text or None."""
    site = None
    if args.site is not None:
        site = _numbers("--site", args.site, None)
        if len(site) not in (2, 3):
            raise InputError(f"parameter --site={args.site!r}: give LAT,LON or LAT,LON,HEIGHT_M")
    return site, args.date


def _site(args):
    """The :class:`navlib.sensors.earth_field.Site` of --site/--date (``field``: --site required)."""
    from .sensors.earth_field import Site
    v, date = _site_values(args)
    return Site(v[0], v[1], v[2] if len(v) == 3 else 0.0, *((date,) if date is not None else ()))


def _field(args) -> int:
    from .sensors.earth_field import igrf_field
    site = _site(args)
    f = igrf_field(site).to_dict()
    if args.json:
        print(json.dumps({"model": "IGRF-14 (ppigrf)", "lat_deg": site.lat_deg, "lon_deg": site.lon_deg,
                          "height_m": site.height_m, "date": site.date, **f}))
    else:
        print(f"IGRF-14 at {site.lat_deg:g}, {site.lon_deg:g}, {site.height_m:g} m on {site.date}: "
              f"north {f['north_ut']:.3f}, east {f['east_ut']:.3f}, down {f['down_ut']:.3f}, intensity "
              f"{f['intensity_ut']:.3f} uT; dip {f['dip_deg']:.3f} deg, declination {f['declination_deg']:.3f} deg")
    return 0


def _simulate_compass(args) -> int:
    errors = CompassErrors()
    if args.noise_ut is not None:
        errors = replace(errors, noise_ut=args.noise_ut)
    frame = simulate_train_test(errors, PAPER_A_EARTH, seed=args.seed)
    path = write_new_csv(frame, args.out, overwrite=args.overwrite)
    print(f"wrote {len(frame)} readings ({frame.sweep.nunique()} sweeps) to {path}")
    return 0


def _prepare(args):
    """Validate names before reading the data; load user effects and the file; fit the start model."""
    system = get_system(args.system)
    users = load_effects(args.effects, system.name, system.catalogue) if args.effects else ()
    available = {**system.catalogue, **{e.name: e for e in users}}
    names = [e.name for e in resolve(available, args.model.split(","), None, system.name)]
    unit = getattr(args, "unit", None)
    if unit is not None and system.name != "accelerometer":
        raise InputError(f"parameter --unit={unit!r}: only the accelerometer system has units")
    data = system.load(args.file) if unit is None else system.load(args.file, unit=unit)
    return system, users, names, data


def _diagnose(args) -> int:
    system, users, names, data = _prepare(args)
    d = diagnose(fit_model(system, data, names, user_effects=users), alpha=args.alpha)
    if args.json:
        out = d.to_dict()
        out["candidates"] = [{"effect": c["effect"], "rms": c["rms"], "loo_rms": c["loo_rms"],
                              "variance_explained": c["variance_explained"], "p_value": c["p_value"],
                              "test": c["test"], "significant": c["significant"]} for c in out["candidates"]]
        out["untested"] = [{"effect": k, "why": v} for k, v in d.untestable.items()]
        print(json.dumps(out, allow_nan=False, default=float))
    else:
        print(d.report())
    return 0


def _loop(args) -> int:
    if args.report:
        check_report_folder(args.report)            # refuse before the work, not after it
    site, date = _site_values(args)
    system = get_system(args.system)
    if (site is not None or date is not None) and system.final_check is None:
        raise InputError(f"parameter {'--site' if site is not None else '--date'}: the system {system.name} makes no "
                         f"field check ({', '.join(n for n, s in SYSTEMS.items() if s.final_check is not None)} do)")
    system, users, names, data = _prepare(args)
    result = loop(system, data, names, user_effects=users, alpha=args.alpha)
    # the system's own end-of-loop report (e.g. the local field against IGRF at the site)
    check, lines = system.final_check(result, site, date) if system.final_check is not None else (None, [])
    if args.report:
        png, md = write_report(result, args.report, source=str(args.file))
    if args.json:
        out = result.to_dict()
        if check is not None:
            out["field"] = check
        print(json.dumps(out, allow_nan=False, default=float))
    else:
        print(result.steps_table().to_string(float_format=lambda x: f"{x:.4g}"))
        print()
        print(result.final_diagnosis.message)
        for u in result.untested:
            print(f"not tested: {u['effect']} ({u['why']})")
        if lines:
            print("\n".join(lines))
        if args.report:
            print(f"report: {md} and {png}")
    return 0


def _calibrate(args) -> int:
    names = [e.name for e in resolve(FREE_EFFECTS, args.model.split(","), None, "magnetometer_free")]
    site, date = _site_values(args)
    path, cal = calibrate_file(args.file, names, args.out, site=site, date=date)
    mc = cal["magcal"]
    print(f"model: {' + '.join(cal['model'])}   rows: {cal['rows']}   residual rms: {cal['residual_rms_ut']:.4g} uT")
    print(f"expected field strength: {mc['expected_field_strength_ut']:.4g} "
          f"+- {cal['expected_field_strength_ut']['std']:.2g} uT" +
          (f"   dip: {cal['dip_deg']:.2f} deg" if "dip_deg" in cal else ""))
    print("b (uT): " + ", ".join(f"{v:.4g} +- {e:.2g}" for v, e in zip(mc["b_ut"], mc["b_std_ut"])))
    print("A: " + "; ".join(", ".join(f"{v:.5f}" for v in row) for row in mc["A"]))
    if "field" in cal:
        from .workbench.calibration import field_lines
        print("\n".join(field_lines(cal["field"])))
    print(f"wrote {path}")
    return 0


def _apply(args) -> int:
    path, n = apply_file(args.calibration, args.file, args.out)
    print(f"wrote {n} corrected rows to {path}")
    return 0


def _numbers(option: str, text: str | None, default):
    if text is None:
        return default
    out = []
    for part in text.split(","):
        try:
            out.append(float(part))
        except ValueError:
            raise InputError(f"parameter {option}={part.strip()!r}: not a number") from None
    return tuple(out)


def _workers(args) -> int:
    return engine.default_workers() if args.workers is None else args.workers


def _rates(args) -> int:
    r = rates(args.system, trials=args.trials, noises=_numbers("--noise", args.noise, None),
              ratios=_numbers("--ratio", args.ratio, DEFAULT_RATIOS), null_trials=args.null_trials,
              workers=_workers(args), scheduler=args.scheduler)
    if args.json:
        print(json.dumps(r.to_dict(), allow_nan=False, default=float))
    else:
        print(r.text())
    return 0


def _grid(args) -> int:
    from .grid import run_grid                      # papermill and the notebook machinery: only here
    rows = run_grid(args.notebook, args.param, args.out, workers=_workers(args), scheduler=args.scheduler)
    failed = [r for r in rows if r["status"].startswith("failed")]
    print(f"{len(rows)} runs, {len(rows) - len(failed)} ok; {os.path.join(args.out, 'grid.csv')}")
    for r in failed:
        print(f"run {r['run']}: {r['status']}", file=sys.stderr)
    return 1 if failed else 0


COMMANDS = {"simulate-compass": _simulate_compass, "diagnose": _diagnose, "loop": _loop, "rates": _rates,
            "grid": _grid, "calibrate": _calibrate, "apply": _apply, "field": _field}


#: Exit status after output into a closed pipe: what a shell reports for a process stopped by SIGPIPE.
BROKEN_PIPE = 141


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        if args.debug:                              # let every error through with its traceback
            status = COMMANDS[args.command](args)
        else:
            status = _run(args)
        sys.stdout.flush()                          # a closed pipe shows here, not at interpreter exit
    except BrokenPipeError:
        # the reader went away (``| head -1``): stop quietly; stdout goes to devnull so that Python's
        # final flush does not complain again (the recipe of the Python documentation, signal module)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return BROKEN_PIPE
    return status


def _run(args) -> int:
    try:
        return COMMANDS[args.command](args)
    except BrokenPipeError:
        raise
    except (InputError, UserCodeError) as err:
        print(f"navlib {args.command}: error: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        where = f"{err.filename}: " if err.filename else ""
        print(f"navlib {args.command}: error: {where}{err.strerror or err}", file=sys.stderr)
        return 2
    except Exception as err:                        # a bug, not bad input: one line; --debug shows the traceback
        print(f"navlib {args.command}: internal error: {type(err).__name__}: {err}".splitlines()[0]
              + " (run with --debug for the traceback)", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
