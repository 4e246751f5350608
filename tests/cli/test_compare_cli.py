"""``navlib compare`` on the command line (issue 36): BROAD's real level sweeps (trial 05) and a file of
``navlib simulate-compass``, the JSON (snake_case keys, no NaN) and text, the report, bad input as one line
with exit status 2, and ``--help`` without the workbench."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pandas as pd
import pytest

from navlib import cli
from navlib.methods import compass_methods as cm
from navlib.paths import ROOT
from navlib.workbench import compare as C

BROAD05 = ROOT.parent / "shared" / "realdata" / "broad" / "level" / "broad_trial05_level.csv"
SNAKE = re.compile(r"^[a-z][a-z0-9_]*$")


def _strict(text: str):
    """JSON that Python's strict parser accepts (NaN or Infinity raise)."""

    def bad(name):
        raise ValueError(f"not JSON: {name}")

    return json.loads(text, parse_constant=bad)


def _keys(obj):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield k
            yield from _keys(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _keys(v)


def run(capsys, *args):
    capsys.readouterr()
    status = cli.main([str(a) for a in args])
    out = capsys.readouterr()
    return status, out.out, out.err


@pytest.fixture(scope="module")
def sim_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("cli") / "sim.csv"
    assert cli.main(["simulate-compass", str(path), "--seed", "5"]) == 0
    return path


@pytest.mark.skipif(
    not BROAD05.exists(),
    reason=f"BROAD's real level sweeps are not here ({BROAD05}): "
    "python -m navlib.data.broad makes them from BROAD's .mat files",
)
@pytest.mark.slow
def test_broad_trial_05_with_the_default_methods(capsys, tmp_path):
    """The real file: two sweeps, so the sweep split; its gaps (no reading near 135 and 225 deg in sweep 2)
    leave the 8-position LS out of the default list with the reason; every other method runs."""
    status, out, err = run(
        capsys, "compare", "compass", BROAD05, "--seeds", "6", "--workers", "1", "--json"
    )
    assert status == 0, err
    r = _strict(out)
    assert all(SNAKE.match(k) for k in _keys(r))
    frame = pd.read_csv(BROAD05)
    assert r["rows"] == len(frame) and r["split"]["rule"] == "sweep" and r["seeds"] == 6
    assert [f["test"] for f in r["split"]["folds"]] == ["sweep 1", "sweep 2"]
    assert sum(f["test_rows"] for f in r["split"]["folds"]) == len(frame)
    assert [d["method"] for d in r["not_run"]] == list(cm.LS_MODELS)
    assert "none near 135, 225 deg" in r["not_run"][0]["why"]
    ran = [m["method"] for m in r["methods"]]
    assert set(ran) == set(C.COMPASS_DEFAULT) - set(cm.LS_MODELS) and ran[0] == r["best"]
    rms = [m["rms"]["value"] for m in r["methods"]]
    assert rms == sorted(rms) and [m["rank"] for m in r["methods"]] == list(range(1, len(rms) + 1))
    for m in r["methods"]:
        assert m["runs"] == (6 if m["stochastic"] else 1) and len(m["rms_per_run"]) == m["runs"]
        assert m["rms"]["lo"] <= m["rms"]["value"] <= m["rms"]["hi"]
        assert (m["versus_best"] is None) == (m["method"] == r["best"])
    unc = next(m for m in r["methods"] if m["method"] == "uncompensated")
    err_deg = frame.heading_error_deg.to_numpy()
    assert unc["rms"]["value"] == pytest.approx(float((err_deg**2).mean() ** 0.5), abs=1e-3)
    # the text: the same table, the not-run line, no index column
    status, out, _ = run(
        capsys,
        "compare",
        "compass",
        BROAD05,
        "--seeds",
        "6",
        "--workers",
        "1",
        "--methods",
        "uncompensated,physical,elm",
    )
    assert status == 0 and "split by sweep, 2 folds" in out and "held-out rms" in out
    assert re.search(r"^ *physical model +1 ", out, re.M) and "not run" not in out


def test_a_simulated_sweep_file_with_a_report(capsys, sim_file, tmp_path):
    rep = tmp_path / "rep"
    status, out, err = run(
        capsys,
        "compare",
        "compass",
        sim_file,
        "--methods",
        "uncompensated,ls8,physical,elm",
        "--seeds",
        "6",
        "--split",
        "heading",
        "--workers",
        "1",
        "--report",
        rep,
    )
    assert status == 0, err
    assert "split by heading, 2 folds" in out and f"report: {rep / 'compare.md'}" in out
    md = (rep / "compare.md").read_text()
    assert (
        md.count("\n| ") == 5 and "| LS 8-position (Smith, 5 terms) | 1 |" in md
    )  # header + 4 methods
    assert (rep / "compare.png").stat().st_size > 10000
    status, _, err = run(
        capsys, "compare", "compass", sim_file, "--methods", "physical", "--report", rep
    )
    assert (
        status == 2
        and "compare.md: already exists; not overwritten" in err
        and len(err.splitlines()) == 1
    )
    status, out, err = run(
        capsys,
        "compare",
        "compass",
        sim_file,
        "--methods",
        "physical,uncompensated",
        "--split",
        "random",
        "--seed",
        "4",
        "--json",
        "--workers",
        "1",
    )
    r = _strict(out)
    assert (
        status == 0
        and r["split"]["rule"] == "random"
        and r["seed"] == 4
        and r["best"] == "physical"
    )
    assert r["methods"][1]["versus_best"]["finding"] == "best is better"


@pytest.mark.parametrize(
    "edit, args, words",
    [
        (
            lambda f: f.drop(columns="measured_heading_deg"),
            (),
            ["missing column 'measured_heading_deg'"],
        ),
        (
            lambda f: f[f.sweep == 1].drop(columns="sweep"),
            ("--split", "sweep"),
            ["--split sweep needs at least 2 sweeps", "has 1"],
        ),
        (
            lambda f: f[(f.true_heading_deg < 120) | (f.true_heading_deg > 150)],
            ("--methods", "ls8_planar"),
            ["method ls8_planar", "needs 8 headings", "has 7 (none near 135 deg)"],
        ),
        (None, ("--methods", "elm,magic"), ["unknown method 'magic'", "known: uncompensated, ls8"]),
        (None, ("--seeds", "0"), ["--seeds=0"]),
        (None, ("--split", "heading", "--bin-deg", "50"), ["--bin-deg=50"]),
        (None, ("--ls-tolerance", "-1"), ["--ls-tolerance"]),
        (None, ("--margin", "0"), ["--margin"]),
    ],
)
def test_bad_input_is_one_line_naming_it(capsys, sim_file, tmp_path, edit, args, words):
    path = sim_file
    if edit is not None:
        path = tmp_path / "edited.csv"
        edit(pd.read_csv(sim_file)).to_csv(path, index=False)
    status, out, err = run(capsys, "compare", "compass", path, "--workers", "1", *args)
    assert status == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    for w in words:
        assert w in err, (w, err)


def test_no_file_and_unknown_system(capsys):
    status, _, err = run(capsys, "compare", "compass")
    assert status == 2 and "give a measurement FILE" in err
    capsys.readouterr()
    with pytest.raises(SystemExit) as stop:  # the parser's one line
        cli.main(["compare", "gyro", "x.csv"])
    err = capsys.readouterr().err
    assert (
        stop.value.code == 2
        and "invalid choice: 'gyro'" in err
        and len(err.strip().splitlines()) == 1
    )


def test_help_loads_no_workbench_and_shows_the_defaults():
    code = (
        "import sys, contextlib, io\nfrom navlib import cli\nbuf = io.StringIO()\n"
        "with contextlib.redirect_stdout(buf):\n"
        "    try: cli.main(['compare', '--help'])\n    except SystemExit: pass\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('pandas', 'scipy', 'numba', 'matplotlib',"
        " 'torch') or m.startswith('navlib.workbench') or m.startswith('navlib.methods'))\n"
        "print(','.join(heavy))\nprint(buf.getvalue())\n"
    )
    p = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
    )
    assert p.returncode == 0, p.stderr
    heavy, _, text = p.stdout.partition("\n")
    assert heavy == ""
    flat = " ".join(text.split())
    for option in (
        "--methods",
        "--split",
        "--seed ",
        "--seeds",
        "--bin-deg",
        "--ls-tolerance",
        "--margin",
        "--json",
        "--report",
        "--workers",
        "--scheduler",
    ):
        assert option in flat
    assert "default 10" in flat and "default 15" in flat and "default 5" in flat
    assert ",".join(C.COMPASS_DEFAULT) in text.replace("\n", "").replace(" ", "")
