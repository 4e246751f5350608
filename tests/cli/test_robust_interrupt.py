"""Ctrl-C (issue 35, item 5): the command line prints one line ("interrupted") and exits 130 instead of a
traceback; an output folder it stopped half-written keeps its marker saying it is incomplete (and the line
names it), a folder nothing was written into yet is removed again.  ``--debug`` lets the traceback through."""

import os
import signal
import subprocess
import sys
import time

import pytest

from navbook import cli as book_cli, grid

from navlib import cli, commands
from navlib.data import broad
from test_robust_outputs import ENV, FAKE, tiny_notebook

SLOW = "import time\ntime.sleep(float(n))"


def _ctrl_c_as_at_a_terminal():
    """In the child before exec: SIGINT back to its default action.  A shell starts a background job (``make
    test &``, CI runners) with SIGINT ignored, the ignoring is inherited, and Python then installs no
    KeyboardInterrupt handler: the command would rightly sleep through the signal.  Likewise a blocked signal."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(
        signal.SIG_UNBLOCK, {signal.SIGINT}
    )  # and not blocked either (also inherited)


def _wait_for(path, proc, timeout_s=120.0):
    t0 = time.monotonic()
    while not path.exists():
        if proc.poll() is not None:
            pytest.fail(f"the command ended before {path.name} appeared: {proc.communicate()}")
        if time.monotonic() - t0 > timeout_s:
            proc.kill()
            pytest.fail(f"{path} never appeared")
        time.sleep(0.05)


@pytest.mark.parametrize(
    "values, wait_for, left",
    [
        ("60", grid.MARKER, None),  # interrupted in the first run: no folder
        (
            "0.1,60",
            "slow_001.ipynb",
            [grid.MARKER, "slow_001.ipynb"],
        ),  # after one run: marked incomplete
    ],
)
@pytest.mark.slow
def test_sigint_to_a_running_grid_is_one_line_and_status_130(tmp_path, values, wait_for, left):
    pytest.importorskip("papermill")
    nb = tiny_notebook(tmp_path / "slow.ipynb", parameters="n = 1.0", body=SLOW)
    out = tmp_path / "out"
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "navbook",
            "grid",
            str(nb),
            "--param",
            f"n={values}",
            "--out",
            str(out),
            "--workers",
            "1",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ENV,
        start_new_session=True,
        preexec_fn=_ctrl_c_as_at_a_terminal,
    )
    try:
        _wait_for(out / wait_for, p)
        os.killpg(p.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the kernel gets it too
        _, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == cli.INTERRUPTED and len(err.strip().splitlines()) == 1, err
    if left is None:
        assert err.strip() == "navbook grid: interrupted" and not out.exists()
    else:
        assert (
            err.strip() == f"navbook grid: interrupted; {out} is incomplete ({grid.MARKER} says so)"
        )
        assert sorted(x.name for x in out.iterdir()) == left and not (out / "grid.csv").exists()
        assert "interrupted (Ctrl-C)" in (out / grid.MARKER).read_text()


def test_keyboard_interrupt_in_process(tmp_path, monkeypatch, capsys):
    pytest.importorskip("papermill")
    nb = tiny_notebook(tmp_path / "tiny.ipynb")
    out = tmp_path / "out"
    calls = []

    def second_interrupted(notebook_json, name, parameters, cwd):
        calls.append(name)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return FAKE

    monkeypatch.setattr(grid, "run_point", second_interrupted)
    args = ["grid", str(nb), "--param", "n=1,2", "--out", str(out), "--workers", "1"]
    assert book_cli.main(args) == 130
    assert (
        capsys.readouterr().err
        == f"navbook grid: interrupted; {out} is incomplete ({grid.MARKER} says so)\n"
    )
    # --debug: the traceback shows where it was
    calls.clear()
    with pytest.raises(KeyboardInterrupt):
        book_cli.main(
            [
                "--debug",
                "grid",
                str(nb),
                "--param",
                "n=1,2",
                "--out",
                str(tmp_path / "debug"),
                "--workers",
                "1",
            ]
        )


def test_an_interrupted_loop_leaves_no_report_folder(tmp_path, monkeypatch, capsys):
    src = tmp_path / "c.csv"
    assert cli.main(["simulate-compass", str(src)]) == 0

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(commands, "loop", interrupted)
    capsys.readouterr()
    assert cli.main(["loop", "compass", str(src), "--report", str(tmp_path / "rep")]) == 130
    assert (
        capsys.readouterr().err == "navlib loop: interrupted\n" and not (tmp_path / "rep").exists()
    )


def test_the_broad_converter_interrupted_is_one_line(tmp_path, monkeypatch, capsys):
    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(broad, "convert", interrupted)
    assert broad.main(["--in", str(tmp_path), "--out", str(tmp_path / "out")]) == 130
    assert capsys.readouterr().err == "interrupted; nothing written\n"


@pytest.mark.parametrize("stop", [KeyboardInterrupt, OSError])
def test_a_file_interrupted_while_written_is_removed(tmp_path, stop):
    """tables.write_new (every CSV and JSON output of navlib): a write stopped half-way leaves no file."""
    from navlib.data.tables import write_new

    def half(fh):
        fh.write("time_s,mag_x_ut\n1,2\n")
        raise stop

    with pytest.raises(stop):
        write_new(tmp_path / "out.csv", half)
    assert not (tmp_path / "out.csv").exists()
    (tmp_path / "mine.csv").write_text("mine")  # an existing file is still refused, kept
    with pytest.raises(Exception, match="already exists"):
        write_new(tmp_path / "mine.csv", half)
    assert (tmp_path / "mine.csv").read_text() == "mine"
