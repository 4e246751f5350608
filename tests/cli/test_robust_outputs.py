"""Output folders are claimed atomically before any work (issue 35, item 3): of two ``grid`` runs on one
empty ``--out``, or two ``loop --report DIR`` runs on one folder, one writes and the other stops with one
line before writing anything; a run that stops before writing leaves the folder as it found it, one that
stops after writing leaves its marker saying the folder is incomplete."""

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

from navbook import cli as book_cli, grid

from navlib import cli, commands, engine
from navlib.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
ENV = {
    **{k: v for k, v in os.environ.items() if k != engine.ENV_SCHEDULER},
    "PYTHONPATH": os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p),
}


def tiny_notebook(path: Path, parameters: str = "n = 2", body: str = "print(n)") -> Path:
    """A notebook with the parameters cell ``parameters`` and one cell ``body``."""
    nbformat = pytest.importorskip("nbformat")
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell(parameters)
    cell.metadata["tags"] = ["parameters"]
    nb.cells = [cell, nbformat.v4.new_code_cell(body)]
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    nbformat.write(nb, str(path))
    return path


def _wait_for(path: Path, timeout_s: float = 60.0) -> None:
    t0 = time.monotonic()
    while not path.exists():
        if time.monotonic() - t0 > timeout_s:
            pytest.fail(f"{path} never appeared")
        time.sleep(0.02)


FAKE = {"notebook": json.dumps({"cells": []}), "results": {}, "error": None, "seconds": 0.0}


def test_a_second_grid_on_the_same_folder_stops_before_writing(tmp_path, monkeypatch, capsys):
    pytest.importorskip("papermill")
    nb = tiny_notebook(tmp_path / "tiny.ipynb")
    out = tmp_path / "out"
    go = threading.Event()

    def held_run(notebook_json, name, parameters, cwd):  # the first grid's runs wait for the test
        assert go.wait(60)
        return FAKE

    monkeypatch.setattr(grid, "run_point", held_run)
    first = {}
    t = threading.Thread(
        target=lambda: first.setdefault("rows", grid.run_grid(nb, ["n=1,2"], out, workers=1))
    )
    t.start()
    try:
        _wait_for(out / grid.MARKER)
        assert sorted(p.name for p in out.iterdir()) == [grid.MARKER]
        capsys.readouterr()
        assert (
            book_cli.main(["grid", str(nb), "--param", "n=3", "--out", str(out), "--workers", "1"])
            == 2
        )
        err = capsys.readouterr().err.strip()
        assert (
            len(err.splitlines()) == 1 and f"grid --out {out}: another run is writing there" in err
        ), err
        assert sorted(p.name for p in out.iterdir()) == [grid.MARKER]  # the second wrote nothing
    finally:
        go.set()
        t.join(60)
    assert [r["n"] for r in first["rows"]] == [1, 2]
    assert sorted(p.name for p in out.iterdir()) == ["grid.csv", "tiny_001.ipynb", "tiny_002.ipynb"]


@pytest.mark.slow
def test_two_grid_processes_started_together_one_writes(tmp_path):
    """Two real ``navbook grid`` processes on one new folder: one succeeds, the other exits 2 with one line,
    and the folder holds the winner's runs only (grid.csv, notebooks, no marker)."""
    pytest.importorskip("papermill")
    nb = tiny_notebook(tmp_path / "tiny.ipynb")
    out = tmp_path / "out"
    values = {"a": "1", "b": "5,6"}
    procs = {
        k: subprocess.Popen(
            [
                sys.executable,
                "-m",
                "navbook",
                "grid",
                str(nb),
                "--param",
                f"n={v}",
                "--out",
                str(out),
                "--workers",
                "1",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=ENV,
        )
        for k, v in values.items()
    }
    done = {k: (p.communicate(timeout=300), p.returncode) for k, p in procs.items()}
    winners = [k for k, (_, rc) in done.items() if rc == 0]
    losers = [k for k, (_, rc) in done.items() if rc != 0]
    assert len(winners) == 1 and len(losers) == 1, done
    (_, err), rc = done[losers[0]]
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert "another run is writing there" in err or "the folder is not empty" in err, err
    rows = pd.read_csv(out / "grid.csv")
    assert [str(v) for v in rows["n"]] == values[winners[0]].split(",")
    assert sorted(p.name for p in out.iterdir()) == ["grid.csv"] + [
        f"tiny_{k:03d}.ipynb" for k in range(1, len(rows) + 1)
    ]


def test_a_grid_that_fails_before_writing_leaves_no_folder(tmp_path, monkeypatch, capsys):
    """A scheduler that never answers: the folder the grid created is removed again; an existing empty one
    stays empty."""
    pytest.importorskip("papermill")
    import socket

    nb = tiny_notebook(tmp_path / "tiny.ipynb")
    monkeypatch.setattr(engine, "PROBE_TIMEOUT_S", 0.3)
    with socket.create_server(("127.0.0.1", 0)) as silent:
        address = f"127.0.0.1:{silent.getsockname()[1]}"
        for out, existed in ((tmp_path / "new" / "out", False), (tmp_path / "empty", True)):
            if existed:
                out.mkdir()
            capsys.readouterr()
            assert (
                book_cli.main(
                    ["grid", str(nb), "--param", "n=3", "--out", str(out), "--scheduler", address]
                )
                == 2
            )
            err = capsys.readouterr().err.strip()
            assert len(err.splitlines()) == 1 and "sent no dask handshake" in err, err
            assert out.is_dir() == existed and (not existed or not any(out.iterdir()))
        assert not (tmp_path / "new").exists()  # nor the parent it created


def test_a_grid_stopped_after_a_run_says_the_folder_is_incomplete(tmp_path, monkeypatch, capsys):
    pytest.importorskip("papermill")
    nb = tiny_notebook(tmp_path / "tiny.ipynb")
    out = tmp_path / "out"
    calls = []

    def second_fails(notebook_json, name, parameters, cwd):
        calls.append(name)
        if len(calls) == 2:
            raise InputError("the second run's input is bad")
        return FAKE

    monkeypatch.setattr(grid, "run_point", second_fails)
    assert (
        book_cli.main(["grid", str(nb), "--param", "n=1,2", "--out", str(out), "--workers", "1"])
        == 2
    )
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.endswith(
        f"; {out} is incomplete ({grid.MARKER} says so)"
    ), err
    assert sorted(p.name for p in out.iterdir()) == [grid.MARKER, "tiny_001.ipynb"]  # no grid.csv
    assert (
        "INCOMPLETE" in (out / grid.MARKER).read_text()
        and "InputError" in (out / grid.MARKER).read_text()
    )


@pytest.fixture(scope="module")
def compass_file(tmp_path_factory):
    p = tmp_path_factory.mktemp("loop") / "sweeps.csv"
    assert cli.main(["simulate-compass", str(p), "--seed", "5"]) == 0
    return p


def test_a_second_loop_report_into_the_same_folder_stops_before_any_work(
    tmp_path, compass_file, monkeypatch, capsys
):
    rep = tmp_path / "rep"
    go, entered = threading.Event(), threading.Event()
    real = commands.loop

    def held_loop(*a, **k):
        entered.set()
        assert go.wait(60)
        return real(*a, **k)

    monkeypatch.setattr(commands, "loop", held_loop)
    first = {}
    args = ["loop", "compass", str(compass_file), "--model", "misalignment", "--report", str(rep)]
    t = threading.Thread(target=lambda: first.setdefault("rc", cli.main(args)))
    t.start()
    try:
        assert entered.wait(60)
        assert sorted(p.name for p in rep.iterdir()) == [commands.REPORT_MARKER]
        entered.clear()
        capsys.readouterr()
        assert cli.main(args) == 2
        err = capsys.readouterr().err.strip()
        assert (
            len(err.splitlines()) == 1 and f"--report {rep}: another run is writing there" in err
        ), err
        assert not entered.is_set()  # refused before the loop began
        assert sorted(p.name for p in rep.iterdir()) == [commands.REPORT_MARKER]
    finally:
        go.set()
        t.join(120)
    assert first["rc"] == 0
    assert sorted(p.name for p in rep.iterdir()) == ["loop.md", "loop.png"]


def test_a_loop_that_fails_leaves_the_report_folder_as_it_found_it(tmp_path, capsys):
    new = tmp_path / "a" / "rep"
    assert cli.main(["loop", "compass", str(tmp_path / "missing.csv"), "--report", str(new)]) == 2
    assert "no such file" in capsys.readouterr().err and not (tmp_path / "a").exists()
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    assert cli.main(["loop", "compass", str(tmp_path / "missing.csv"), "--report", str(mine)]) == 2
    assert [p.name for p in mine.iterdir()] == ["notes.txt"] and (
        mine / "notes.txt"
    ).read_text() == "mine"
