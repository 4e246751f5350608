"""A ``--scheduler`` address that is not a dask scheduler stops the command with one line, quickly (issue 35,
item 2): a port that accepts and never answers, one that answers random bytes or another protocol, one that
hangs up.  The servers are started here on 127.0.0.1 and stopped after each test; the probe's timeout is set
small (``engine.PROBE_TIMEOUT_S``), so the bound checked is generous."""

import json
import os
import socket
import struct
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from navlib import cli, engine
from navlib.errors import InputError

SMALL_TIMEOUT_S = 0.5
BOUND_S = 15.0  # the brief's bound for the default timeouts; the small one is far below


class Server:
    """A TCP server on 127.0.0.1 that accepts every connection and does ``answer(conn)`` with it."""

    def __init__(self, answer):
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.sock.settimeout(0.1)
        self.address = f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"
        self.answer = answer
        self.conns = []
        self.accepted = 0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        while not self.stop.is_set():
            try:
                conn, _ = self.sock.accept()
            except socket.timeout:
                continue
            self.accepted += 1
            self.conns.append(conn)
            self.answer(conn)

    def close(self):
        self.stop.set()
        self.thread.join(timeout=5)
        for c in self.conns:
            c.close()
        self.sock.close()


def _silent(conn):
    pass  # keeps the connection open, says nothing


def _bytes(data):
    return lambda conn: conn.sendall(data)


def _hang_up(conn):
    conn.close()


ANSWERS = {
    "silent": (_silent, "sent no dask handshake within 0.5 s"),
    "random bytes": (
        _bytes(np.random.default_rng(35).bytes(64)),
        "not dask's handshake (a first message of",
    ),
    "http": (
        _bytes(b"HTTP/1.1 400 Bad Request\r\n\r\n"),
        "not dask's handshake (a first message of",
    ),
    "frames that do not add up": (
        _bytes(struct.pack("QQQ", 40, 1, 1000) + bytes(24)),
        "do not add up",
    ),
    "too many frames": (_bytes(struct.pack("QQ", 40, 10**9) + bytes(32)), "do not add up"),
    "a few bytes, then silence": (_bytes(b"\x01\x02"), "sent no dask handshake within 0.5 s"),
    "hangs up": (_hang_up, "closed the connection without a dask handshake"),
}


@pytest.fixture
def server(request):
    s = Server(ANSWERS[request.param][0])
    s.says = ANSWERS[request.param][1]
    yield s
    s.close()


@pytest.fixture
def small_timeout(monkeypatch):
    monkeypatch.setattr(engine, "PROBE_TIMEOUT_S", SMALL_TIMEOUT_S)
    monkeypatch.delenv(engine.ENV_SCHEDULER, raising=False)


@pytest.mark.parametrize("server", list(ANSWERS), indirect=True)
def test_a_peer_that_is_not_a_scheduler_is_one_line(server, small_timeout, capsys):
    says = server.says
    t0 = time.monotonic()
    rc = cli.main(
        ["rates", "drift", "--trials", "1", "--null-trials", "1", "--scheduler", server.address]
    )
    took = time.monotonic() - t0
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert err.startswith(f"navlib rates: error: scheduler {server.address}: ") and says in err, err
    assert took < BOUND_S and server.accepted >= 1
    assert not any(k[0] == "remote" for k in engine._CLIENTS)  # no client was left behind


@pytest.mark.parametrize("server", ["silent"], indirect=True)
def test_the_default_timeouts_are_within_the_bound(server, monkeypatch):
    """The probe's two waits (connect, first answer) together stay within 15 s."""
    assert 2 * engine.PROBE_TIMEOUT_S <= BOUND_S
    with pytest.raises(InputError, match="within 0.2 s"):
        engine.probe_scheduler(server.address, timeout=0.2)


def test_a_closed_port_is_one_line(small_timeout, capsys):
    with socket.create_server(("127.0.0.1", 0)) as s:
        port = s.getsockname()[1]  # bound, then closed: nobody listens there
    rc = cli.main(["rates", "drift", "--trials", "1", "--scheduler", f"127.0.0.1:{port}"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "cannot connect" in err, err


def test_a_real_scheduler_passes_the_probe(tmp_path):
    sched_file = tmp_path / "scheduler.json"
    env = {k: v for k, v in os.environ.items() if k != engine.ENV_SCHEDULER}
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "distributed.cli.dask_scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--no-dashboard",
            "--scheduler-file",
            str(sched_file),
        ],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        t0 = time.time()
        while not sched_file.exists() and time.time() - t0 < 60:
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        for _ in range(50):  # the file is written as the scheduler starts listening
            try:
                engine.probe_scheduler(address)
                break
            except InputError as err:
                if "cannot connect" not in str(err):
                    raise
                time.sleep(0.1)
        else:
            pytest.fail("the scheduler never listened")
    finally:
        p.terminate()
        p.wait(timeout=30)
