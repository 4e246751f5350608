"""The commands of ``navlib`` (:mod:`navlib.cli` parses the command line and calls one of these with its
arguments): each reads the user's files, runs the workbench or a simulator and prints or writes the result.
Bad input raises :class:`navlib.errors.InputError` (the CLI prints one line and exits 2)."""

from __future__ import annotations

import contextlib
import json
import os
import sys
from pathlib import Path
from dataclasses import replace

from . import engine
from .data.tables import claim_folder, write_new_csv
from .errors import InputError
from .names import EXAMPLES
from .paths import data_path
from .sensors.compass import PAPER_A_EARTH, CompassErrors, simulate_train_test
from .workbench import SYSTEMS, get_system, load_effects
from .workbench.diagnose import diagnose
from .workbench.effects import resolve
from .workbench.fit import fit_model
from .workbench.loop import check_report_folder, loop, write_report
from .workbench.calibration import apply_file, calibrate_file
from .workbench.magnetometer_free import FREE_EFFECTS, SYSTEM as FREE_SYSTEM, site_of
from .workbench.rates import DEFAULT_RATIOS, rates
from .sensors.earth_field import Site
from .workbench.local_field import field_lines, model_field


def _site_values(args):
    """``(site, date)`` of --site/--date: ``(lat, lon[, height_m])`` or None, the date text or None; each
    checked here, before any work, against the limits of :class:`navlib.sensors.earth_field.Site` (one line
    naming the option)."""
    site = None
    if args.site is not None:
        site = _numbers("--site", args.site, None)
        if len(site) not in (2, 3):
            raise InputError(f"parameter --site={args.site!r}: give LAT,LON or LAT,LON,HEIGHT_M")
        for i, what in enumerate(("latitude", "longitude", "height")[: len(site)]):
            one = [0.0, 0.0, 0.0]
            one[i] = site[i]
            try:
                Site(*one)
            except InputError as err:
                raise InputError(
                    f"parameter --site={args.site!r}: the {what} {str(err).split(': ', 1)[-1]}"
                ) from None
    if args.date is not None:
        try:
            Site(0.0, 0.0, 0.0, args.date)
        except InputError as err:
            raise InputError(
                f"parameter --date={args.date!r}: {str(err).split(': ', 1)[-1]}"
            ) from None
    return site, args.date


def _site(args):
    """The :class:`navlib.sensors.earth_field.Site` of --site/--date (``field``: --site required)."""
    v, date = _site_values(args)
    return Site(v[0], v[1], v[2] if len(v) == 3 else 0.0, *((date,) if date is not None else ()))


def _field(args) -> int:
    site = _site(args)
    f = model_field(site)  # at a pole: no north, east or declination, and a note
    if args.json:
        print(
            json.dumps(
                {
                    "model": "IGRF-14 (ppigrf)",
                    "lat_deg": site.lat_deg,
                    "lon_deg": site.lon_deg,
                    "height_m": site.height_m,
                    "date": site.date,
                    **f,
                },
                allow_nan=False,
            )
        )
    else:
        where = (
            f"IGRF-14 at {site.lat_deg:g}, {site.lon_deg:g}, {site.height_m:g} m on {site.date}: "
        )
        if f["declination_deg"] is None:
            print(
                where + f"horizontal {f['horizontal_ut']:.3f}, down {f['down_ut']:.3f}, intensity "
                f"{f['intensity_ut']:.3f} uT; dip {f['dip_deg']:.3f} deg; declination undefined ({f['note']})"
            )
        else:
            print(
                where
                + f"north {f['north_ut']:.3f}, east {f['east_ut']:.3f}, down {f['down_ut']:.3f}, intensity "
                f"{f['intensity_ut']:.3f} uT; dip {f['dip_deg']:.3f} deg, declination {f['declination_deg']:.3f} deg"
            )
    return 0


def _simulate_compass(args) -> int:
    errors = CompassErrors()
    if args.noise_ut is not None:
        errors = replace(errors, noise_ut=args.noise_ut)
    frame = simulate_train_test(errors, PAPER_A_EARTH, seed=args.seed)
    path = write_new_csv(frame, args.out, overwrite=args.overwrite)
    print(f"wrote {len(frame)} readings ({frame.sweep.nunique()} sweeps) to {path}")
    return 0


def _examples(args) -> int:
    for name, (system, file, command) in EXAMPLES.items():
        print(f"{name}  ({system})  {data_path(file)}\n    {command}")
    return 0


def _measurement_file(args) -> str:
    """The file a command reads: FILE or the shipped example ``--example NAME`` (exactly one of them, and
    the example of the command's system); a missing FILE gets a hint."""
    example = getattr(args, "example", None)
    if example is not None:
        if args.file is not None:
            raise InputError(f"give a measurement FILE or --example {example}, not both")
        system, file, _ = EXAMPLES[example]
        if system != args.system:
            raise InputError(
                f"parameter --example={example}: a {system} file, not {args.system} "
                f"(navlib examples lists the shipped files)"
            )
        return str(data_path(file))
    if args.file is None:
        raise InputError(
            "give a measurement FILE or --example NAME (navlib examples lists the shipped files)"
        )
    if not os.path.exists(args.file):
        shipped = [n for n, (_, f, _) in EXAMPLES.items() if f == os.path.basename(args.file)]
        hint = (
            f"; the file shipped with navlib is --example {shipped[0]}"
            if shipped
            else "; navlib examples lists the files shipped with navlib"
        )
        raise InputError(f"{args.file}: no such file{hint}")
    return args.file


def _prepare(args):
    """Validate names before reading the data; load user effects and the file (FILE or --example).
    Returns ``(system, users, names, data, file)``."""
    system = get_system(args.system)
    file = _measurement_file(args)
    users = load_effects(args.effects, system.name, system.catalogue) if args.effects else ()
    available = {**system.catalogue, **{e.name: e for e in users}}
    names = [e.name for e in resolve(available, args.model.split(","), None, system.name)]
    unit = getattr(args, "unit", None)
    if unit is not None and system.name != "accelerometer":
        raise InputError(f"parameter --unit={unit!r}: only the accelerometer system has units")
    data = system.load(file) if unit is None else system.load(file, unit=unit)
    return system, users, names, data, file


def _diagnose(args) -> int:
    system, users, names, data, _ = _prepare(args)
    d = diagnose(fit_model(system, data, names, user_effects=users), alpha=args.alpha)
    if args.json:
        out = d.to_dict()
        out["candidates"] = [
            {
                "effect": c["effect"],
                "rms": c["rms"],
                "loo_rms": c["loo_rms"],
                "variance_explained": c["variance_explained"],
                "p_value": c["p_value"],
                "test": c["test"],
                "significant": c["significant"],
            }
            for c in out["candidates"]
        ]
        out["untested"] = [{"effect": k, "why": v} for k, v in d.untestable.items()]
        print(json.dumps(out, allow_nan=False, default=float))
    else:
        print(d.report())
    return 0


#: The marker file ``loop --report DIR`` keeps in DIR while it works (:func:`navlib.data.tables.claim_folder`):
#: a second loop writing its report into the same folder stops before any work; a loop stopped between the
#: report's two files leaves it, saying the report is incomplete.
REPORT_MARKER = "loop.incomplete"


def _loop(args) -> int:
    if args.report:
        check_report_folder(args.report)  # refuse before the work, not after it
    site, date = _site_values(args)
    system = get_system(args.system)
    if (site is not None or date is not None) and system.final_check is None:
        raise InputError(
            f"parameter {'--site' if site is not None else '--date'}: the system {system.name} makes no "
            f"field check ({', '.join(n for n, s in SYSTEMS.items() if s.final_check is not None)} do)"
        )
    claim = (
        claim_folder(
            args.report, REPORT_MARKER, what="navlib loop --report", label="--report", empty=False
        )
        if args.report
        else contextlib.nullcontext()
    )
    with claim:  # one report per folder: claimed before the work
        if args.report:
            check_report_folder(args.report)  # again, under the claim: a report finished meanwhile
        system, users, names, data, file = _prepare(args)
        if system is FREE_SYSTEM:  # where and when, checked before the loop, not after it
            site_of(data, site, date, Path(file).name)
        result = loop(system, data, names, user_effects=users, alpha=args.alpha)
        # the system's own end-of-loop report (e.g. the local field against IGRF at the site)
        check, lines = (
            system.final_check(result, site, date) if system.final_check is not None else (None, [])
        )
        if args.report:
            png, md = write_report(result, args.report, source=file)
    if args.json:
        out = result.to_dict()
        if check is not None:
            out["field"] = check
        print(json.dumps(out, allow_nan=False, default=float))
    else:
        print(
            result.steps_table()
            .reset_index()
            .to_string(index=False, float_format=lambda x: f"{x:.4g}")
        )
        print()
        print(result.final_diagnosis.message)
        for u in result.untested:
            print(f"not tested: {u['effect']} ({u['why']})")
        if lines:
            print("\n".join(lines))
        rem = result.remaining()
        if rem is not None and not result.consistent_with_noise:
            print(f"what remains: {rem[1]}")
        if args.report:
            print(f"report: {md} and {png}")
    return 0


def _calibrate(args) -> int:
    names = [
        e.name for e in resolve(FREE_EFFECTS, args.model.split(","), None, "magnetometer_free")
    ]
    site, date = _site_values(args)
    path, cal = calibrate_file(args.file, names, args.out, site=site, date=date)
    mc = cal["magcal"]
    print(
        f"system: magnetometer_free (no reference attitude)   model: {' + '.join(cal['model'])}   rows: {cal['rows']}   residual rms: {cal['residual_rms_ut']:.4g} uT"
    )
    print(
        f"expected field strength: {mc['expected_field_strength_ut']:.4g} "
        f"+- {cal['expected_field_strength_ut']['std']:.2g} uT"
        + (f"   dip: {cal['dip_deg']:.2f} deg" if "dip_deg" in cal else "")
    )
    print("b (uT): " + ", ".join(f"{v:.4g} +- {e:.2g}" for v, e in zip(mc["b_ut"], mc["b_std_ut"])))
    print("A: " + "; ".join(", ".join(f"{v:.5f}" for v in row) for row in mc["A"]))
    if "field" in cal:
        print("\n".join(field_lines(cal["field"])))
    print(f"wrote {path}")
    for w in cal.get("warnings", ()):
        print(f"navlib calibrate: warning: {w}", file=sys.stderr)
    return 0


def _apply(args) -> int:
    path, n, warnings = apply_file(args.calibration, args.file, args.out)
    print(f"wrote {n} corrected rows to {path}")
    for w in warnings:
        print(f"navlib apply: warning: {w}", file=sys.stderr)
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
    r = rates(
        args.system,
        trials=args.trials,
        noises=_numbers("--noise", args.noise, None),
        ratios=_numbers("--ratio", args.ratio, DEFAULT_RATIOS),
        null_trials=args.null_trials,
        workers=_workers(args),
        scheduler=args.scheduler,
    )
    if args.json:
        print(json.dumps(r.to_dict(), allow_nan=False, default=float))
    else:
        print(r.text())
    return 0


def _compare(args) -> int:
    """``navlib compare``: the papers' methods fitted and scored on the user's file (the workbench's
    :mod:`navlib.workbench.compare`, imported here: it loads the networks, and with them torch)."""
    from .workbench.compare import claimed_report, compare, write_report  # noqa: PLC0415  # lazy: torch

    file = _measurement_file(args)
    with claimed_report(args.report) if args.report else contextlib.nullcontext() as paths:
        result = compare(
            args.system,
            file,
            methods=args.methods,
            split=args.split,
            seeds=args.seeds,
            seed=args.seed,
            margin=args.margin,
            workers=_workers(args),
            scheduler=args.scheduler,
            ls_tolerance_deg=args.ls_tolerance,
            bin_deg=args.bin_deg,
        )
        out = result.to_dict()
        if paths:
            md, png = write_report(result, paths)
            out["report"] = {"markdown": str(md), "figure": str(png)}
    if args.json:
        print(json.dumps(out, allow_nan=False))
    else:
        print(result.text())
        if paths:
            print(f"report: {md} and {png}")
    return 0


#: Command name -> function (the commands ``navlib.cli.build_parser`` offers).
COMMANDS = {
    "examples": _examples,
    "simulate-compass": _simulate_compass,
    "diagnose": _diagnose,
    "loop": _loop,
    "rates": _rates,
    "calibrate": _calibrate,
    "apply": _apply,
    "field": _field,
    "compare": _compare,
}
