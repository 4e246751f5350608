"""Command line: ``python -m navlib COMMAND ...`` (also installed as ``navlib``).

Commands:
  simulate-compass OUT.csv [--seed N] [--noise-ut X] [--overwrite]
      write paper A's two simulated turntable sweeps (train = sweep 1, test = sweep 2).
  diagnose {compass,drift} FILE.csv [--model EFFECT,EFFECT] [--json] [--alpha A]
      fit the model, then name the catalogued effect it lacks (or say the residuals are noise).
      compass columns: true_heading_deg, measured_heading_deg; optional temperature_c, time_s, sweep.
      drift columns: latitude_error_deg, drift_deg_h; optional temperature_c, temperature_change_c.
      Extra columns are ignored.

Bad input exits with status 2 and one line on stderr; no traceback.
"""
from __future__ import annotations

import argparse
import sys

from .errors import InputError


class _Parser(argparse.ArgumentParser):
    def error(self, message):                       # one line, exit 2, like every other bad input
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="navlib", description="navbook's library: simulators and compensation tools")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sim = sub.add_parser("simulate-compass", help="write paper A's two simulated turntable sweeps")
    sim.add_argument("out", help="CSV file to write (never overwritten unless --overwrite)")
    sim.add_argument("--seed", type=int, default=2024)
    sim.add_argument("--noise-ut", type=float, default=None, help="magnetometer noise, uT (1 sigma)")
    sim.add_argument("--overwrite", action="store_true")
    dg = sub.add_parser("diagnose", help="which physical effect is the model missing?",
                        description="Fit a model of named effects to measurements and rank the missing ones.")
    dg.add_argument("system", choices=["compass", "drift"])
    dg.add_argument("file", help="measurement CSV")
    dg.add_argument("--model", default="", help="comma-separated effects already in the model")
    dg.add_argument("--json", action="store_true", help="print one JSON object")
    dg.add_argument("--alpha", type=float, default=None, help="family-wise false-alarm level (default 0.025)")
    return ap


def _simulate_compass(args) -> int:
    from dataclasses import replace

    from .data.tables import write_new_csv
    from .sensors.compass import CompassErrors, simulate_train_test

    errors = CompassErrors()
    if args.noise_ut is not None:
        errors = replace(errors, noise_ut=args.noise_ut)
    frame = simulate_train_test(errors, seed=args.seed)
    path = write_new_csv(frame, args.out, overwrite=args.overwrite)
    print(f"wrote {len(frame)} readings ({frame.sweep.nunique()} sweeps) to {path}")
    return 0


def _diagnose(args) -> int:
    import json

    from .workbench.diagnose import diagnose
    from .workbench.effects import check_effects
    from .workbench.fit import fit_model, load

    model = check_effects(args.system, args.model.split(","))    # unknown names fail before reading
    data = load(args.system, args.file)
    fit = fit_model(args.system, data, model)
    d = diagnose(fit, alpha=args.alpha)
    if args.json:
        out = d.to_dict()
        out["candidates"] = [{"effect": c["effect"], "rms": c["rms"], "loo_rms": c["loo_rms"],
                              "variance_explained": c["variance_explained"], "p_value": c["p_value"],
                              "test": c["test"], "significant": c["significant"]} for c in out["candidates"]]
        print(json.dumps(out, allow_nan=False, default=float))
    else:
        print(d.report())
    return 0


COMMANDS = {"simulate-compass": _simulate_compass, "diagnose": _diagnose}


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return COMMANDS[args.command](args)
    except InputError as err:
        print(f"navlib {args.command}: error: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(f"navlib {args.command}: error: {err.filename or ''}: {err.strerror}", file=sys.stderr)
        return 2
    except Exception as err:                        # a bug, not bad input: still one line, no traceback
        print(f"navlib {args.command}: internal error: {type(err).__name__}: {err}".splitlines()[0],
              file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
