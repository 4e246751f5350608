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
      loop.png and loop.md (never over existing files).

SYSTEM is compass, drift, magnetometer or accelerometer:
  compass columns: true_heading_deg, measured_heading_deg; optional temperature_c, time_s, sweep.
  drift columns: latitude_error_deg, drift_deg_h; optional temperature_c, temperature_change_c.
  magnetometer columns: mag_x_ut, mag_y_ut, mag_z_ut, q_w, q_x, q_y, q_z (reference attitude, body FRD to
  NED); optional time_s, gyr_*_dps, pos_*_m.
  accelerometer columns (one unit's tumble test): temperature_c, position_deg (dividing-head grid, 15 deg),
  output_mg (output / nominal scale factor), unit; optional set_point_c.  Extra columns are ignored.

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

from .data.tables import write_new_csv
from .errors import InputError, UserCodeError
from .sensors.compass import CompassErrors, simulate_train_test
from .workbench import SYSTEMS, get_system, load_effects
from .workbench.diagnose import diagnose
from .workbench.effects import resolve
from .workbench.fit import fit_model
from .workbench.loop import check_report_folder, loop, write_report


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
        if name == "loop":
            cmd.add_argument("--report", default=None, help="folder for loop.png and loop.md (never overwritten)")
    return ap


def _simulate_compass(args) -> int:
    errors = CompassErrors()
    if args.noise_ut is not None:
        errors = replace(errors, noise_ut=args.noise_ut)
    frame = simulate_train_test(errors, seed=args.seed)
    path = write_new_csv(frame, args.out, overwrite=args.overwrite)
    print(f"wrote {len(frame)} readings ({frame.sweep.nunique()} sweeps) to {path}")
    return 0


def _prepare(args):
    """Validate names before reading the data; load user effects and the file; fit the start model."""
    system = get_system(args.system)
    users = load_effects(args.effects, system.name, system.catalogue) if args.effects else ()
    available = {**system.catalogue, **{e.name: e for e in users}}
    names = [e.name for e in resolve(available, args.model.split(","), None, system.name)]
    data = system.load(args.file)
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
    system, users, names, data = _prepare(args)
    result = loop(system, data, names, user_effects=users, alpha=args.alpha)
    if args.report:
        png, md = write_report(result, args.report, source=str(args.file))
    if args.json:
        print(json.dumps(result.to_dict(), allow_nan=False, default=float))
    else:
        print(result.steps_table().to_string(float_format=lambda x: f"{x:.4g}"))
        print()
        print(result.final_diagnosis.message)
        for u in result.untested:
            print(f"not tested: {u['effect']} ({u['why']})")
        if args.report:
            print(f"report: {md} and {png}")
    return 0


COMMANDS = {"simulate-compass": _simulate_compass, "diagnose": _diagnose, "loop": _loop}


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
