"""The command line's surface (issue 34): the parser needs no workbench (``--help`` is fast), its lists of
names equal the library's registries, every ``--json`` key is snake_case and text tables have no index
row."""

import json
import re
import subprocess
import sys

import pytest

from navlib import cli
from navlib import names as cli_names
from navlib.paths import ROOT
from navlib.sensors.earth_field import Site
from navlib.workbench import SYSTEMS
from navlib.workbench import calibration, rates

ENV_PATH = str(ROOT)
SNAKE = re.compile(r"^[a-z][a-z0-9_]*$")


def test_the_parser_names_equal_the_library_registries():
    assert cli_names.SYSTEM_NAMES == tuple(sorted(SYSTEMS))
    assert cli_names.RATE_SYSTEM_NAMES == tuple(sorted(rates.RATE_SYSTEMS))
    assert cli_names.CALIBRATION_MODEL == tuple(calibration.DEFAULT_MODEL)
    assert cli_names.RATE_RATIOS == tuple(rates.DEFAULT_RATIOS)
    assert cli_names.RATE_NOISE == rates.DEFAULT_NOISE
    assert set(cli_names.RATE_UNITS) == set(rates.RATE_SYSTEMS)
    for name, unit in cli_names.RATE_UNITS.items():
        assert unit == SYSTEMS[name].unit, name
    assert cli_names.FIELD_DATE == Site(0.0, 0.0).date


def test_help_loads_no_workbench():
    """``--help`` of every command in a fresh interpreter imports neither the workbench, pandas nor scipy."""
    code = (
        "import sys, contextlib, io\n"
        "from navlib import cli\n"
        "names = ['--help'] + [[c, '--help'] for c in ('simulate-compass', 'diagnose', 'loop', 'field', "
        "'calibrate', 'apply', 'rates', 'grid')]\n"
        "for a in names:\n"
        "    with contextlib.redirect_stdout(io.StringIO()):\n"
        "        try: cli.main(a if isinstance(a, list) else [a])\n"
        "        except SystemExit: pass\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('pandas', 'scipy', 'numba', 'matplotlib')"
        " or m.startswith('navlib.workbench'))\n"
        "print(','.join(heavy))\n"
    )
    p = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": ENV_PATH, "PATH": "/usr/bin:/bin"},
    )
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "", p.stdout


def _keys(obj, path="$"):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield f"{path}.{k}", k
            yield from _keys(v, f"{path}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _keys(v, f"{path}[{i}]")


@pytest.fixture(scope="module")
def compass_file(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "sweeps.csv"
    assert cli.main(["simulate-compass", str(out), "--seed", "3"]) == 0
    return out


@pytest.mark.parametrize(
    "args",
    [
        ["field", "--site", "50,10", "--json"],
        ["diagnose", "compass", "{f}", "--json"],
        ["loop", "compass", "{f}", "--json"],
        [
            "rates",
            "compass",
            "--trials",
            "1",
            "--null-trials",
            "1",
            "--noise",
            "0.1",
            "--ratio",
            "10",
            "--workers",
            "1",
            "--json",
        ],
    ],
)
def test_every_json_key_is_snake_case(args, compass_file, capsys):
    capsys.readouterr()
    assert cli.main([a.format(f=compass_file) for a in args]) == 0
    out = json.loads(capsys.readouterr().out)
    bad = [p for p, k in _keys(out) if not SNAKE.match(str(k))]
    assert not bad, bad[:5]


def test_the_loop_table_has_no_index_row(compass_file, capsys):
    capsys.readouterr()
    assert cli.main(["loop", "compass", str(compass_file)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[0] == "step" and "model" in lines[0]
    assert lines[1].split()[0] == "0"  # the first step, not a lone 'step' index header


def test_every_shipped_example_runs_from_any_folder(tmp_path, monkeypatch, capsys):
    """``navlib examples`` lists each shipped file with one command; each command runs from another folder."""
    monkeypatch.chdir(tmp_path)
    assert cli.main(["examples"]) == 0
    listed = capsys.readouterr().out
    for name, (system, file, command) in cli_names.EXAMPLES.items():
        assert name in listed and command in listed
        args = command.split()[1:]
        assert cli.main(args) == 0, command
        capsys.readouterr()


@pytest.mark.parametrize(
    "args, says",
    [
        (["loop", "compass", "compass_sweeps.csv"], "--example compass_sweeps"),
        (["loop", "compass", "nothing_here.csv"], "navlib examples"),
        (["loop", "drift", "--example", "compass_sweeps"], "a compass file, not drift"),
        (["loop", "compass", "x.csv", "--example", "compass_sweeps"], "not both"),
        (["diagnose", "compass"], "give a measurement FILE or --example NAME"),
    ],
)
def test_a_missing_file_or_a_wrong_example_is_one_line(args, says, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and says in err, err
