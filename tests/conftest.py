"""Test-run order: the longest test files first.

``make test-lib`` runs the files in two processes (pytest-xdist ``--dist loadfile
--no-loadscope-reorder``), handing out whole files in collection order; a long file handed out last
would run alone while the other process idles.  Listed here, longest first (measured with
``--durations``), so the processes finish together; every other file follows in name order.  The order
changes no result: every test is independent of the others.
"""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from navlib import engine

ROOT = Path(__file__).resolve().parent.parent

LONGEST_FIRST = (
    "test_workbench_correlated.py",
    "test_diagnose.py",
    "test_engine.py",
    "test_workbench_screen.py",
    "test_celestial.py",
    "test_workbench_free.py",
    "test_workbench_loop.py",
    "test_compass_study.py",
    "test_install.py",
)


def pytest_collection_modifyitems(items):
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(Path(str(item.fspath)).name, len(rank)))


@pytest.fixture(scope="module")
def remote(tmp_path_factory):
    """A cluster started as separate processes on 127.0.0.1: ``dask scheduler`` and ``dask worker`` (2
    single-threaded worker processes); stopped after the module (test_engine, test_compare)."""
    folder = tmp_path_factory.mktemp("cluster")
    sched_file = folder / "scheduler.json"
    # the workers import this checkout's navlib and navbook, and this module for its helper functions
    path = [str(ROOT), str(ROOT / "book"), str(ROOT / "tests"), os.environ.get("PYTHONPATH", "")]
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(p for p in path if p),
        OPENBLAS_NUM_THREADS="1",
        OMP_NUM_THREADS="1",
    )
    env.pop(engine.ENV_SCHEDULER, None)
    procs = [
        subprocess.Popen(
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
    ]
    try:
        t0 = time.time()
        while not sched_file.exists() and time.time() - t0 < 60:
            time.sleep(0.2)
        address = json.loads(sched_file.read_text())["address"]
        procs.append(
            subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "distributed.cli.dask_worker",
                    address,
                    "--nworkers",
                    "2",
                    "--nthreads",
                    "1",
                    "--host",
                    "127.0.0.1",
                    "--no-dashboard",
                ],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        c = engine.client(scheduler=address)
        c.wait_for_workers(2, timeout=60)
        yield address
    finally:
        for key in [k for k in engine._CLIENTS if k[0] == "remote"]:
            c = engine._CLIENTS[key]
            try:
                c.shutdown()  # stops the scheduler and its workers
            except (OSError, RuntimeError, TimeoutError):
                pass
            engine._close(key)
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
