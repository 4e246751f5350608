"""Command line: ``python -m navlib COMMAND ...`` (also installed as ``navlib``).

Commands:
  simulate-compass OUT.csv [--seed N] [--noise-ut X] [--overwrite]
      write paper A's two simulated turntable sweeps (train = sweep 1, test = sweep 2).

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
    return ap


def _simulate_compass(args) -> int:
    from dataclasses import replace

    from .compass import CompassErrors, simulate_train_test
    from .tables import write_new_csv

    errors = CompassErrors()
    if args.noise_ut is not None:
        errors = replace(errors, noise_ut=args.noise_ut)
    frame = simulate_train_test(errors.validate(), seed=args.seed)
    path = write_new_csv(frame, args.out, overwrite=args.overwrite)
    print(f"wrote {len(frame)} readings ({frame.sweep.nunique()} sweeps) to {path}")
    return 0


COMMANDS = {"simulate-compass": _simulate_compass}


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


if __name__ == "__main__":
    sys.exit(main())
